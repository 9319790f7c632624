"""The bit-accurate fixed-point model (SPEC §5): one formats table, integer arithmetic."""

from evclust.fixed.formats import Constant, Format, FormatTable, build_formats, render_table
from evclust.fixed.header import verilog_header

__all__ = ["Constant", "Format", "FormatTable", "build_formats", "render_table", "verilog_header"]

"""evclust formats [--params P.toml] [--width W --height H] [--verilog rtl/evclust_params.vh] [--rdl RDL] [--c-header H]
[--registers MD] [--ipxact XML] [--html DIR] [--enums DIR] [--generate ROOT]"""

from __future__ import annotations

import math
from pathlib import Path

from evclust.errors import EvclustError, atomic_output


def add_parser(sub) -> None:
    p = sub.add_parser(
        "formats",
        help="print the fixed-point formats table (and write the RTL parameter header)",
        description=(
            "Print the fixed model's formats: every input, state field, intermediate and constant with its Q "
            "notation, range, LSB, rounding and overflow, and each constant's exact and quantised value. "
            "The default is the reference configuration the committed RTL is made from (evclust.fixed.generate.REFERENCE: "
            "the traffic preset on its sensor). --verilog writes the RTL parameter header from the same table, --generate "
            "every file the reference table drives."
        ),
    )
    p.add_argument("--params", metavar="P", help="parameter file (.toml) or preset (default: the reference preset)")
    p.add_argument("--width", type=int, help="sensor width, px (default: the reference configuration's)")
    p.add_argument("--height", type=int, help="sensor height, px (default: the reference configuration's)")
    p.add_argument("--t-frame-us", type=float, default=None, help="frame period, µs (default: the parameters', else 50000)")
    p.add_argument("--verilog", metavar="VH", help="write the Verilog parameter header here")
    p.add_argument(
        "--generate",
        metavar="ROOT",
        help="write every file the reference configuration's table drives under this repository top "
        "(the RTL header, the enumerations, the register map's files: make params)",
    )
    p.add_argument("--enums", metavar="DIR", help="write the RTL's enumerations here, one include per module (<module>_enums.vh)")
    p.add_argument("--rdl", metavar="RDL", help="write the register map in SystemRDL here")
    p.add_argument("--c-header", metavar="H", help="write the register map as a C header here (a driver's; PeakRDL-cheader)")
    p.add_argument("--registers", metavar="MD", help="write the register map as a Markdown document here (PeakRDL-markdown)")
    p.add_argument("--ipxact", metavar="XML", help="write the register map as IP-XACT here (PeakRDL-ipxact)")
    p.add_argument("--html", metavar="DIR", help="write the register map as HTML pages into this folder (PeakRDL-html)")
    p.add_argument(
        "--write-for",
        metavar="P",
        help="print the register writes (address, value) that program parameter set P "
        "(.toml or preset) into the RTL built for these parameters",
    )
    p.set_defaults(run=run)


def run(args) -> int:
    from evclust.events.format import MAX_SENSOR_SIDE
    from evclust.fixed.generate import REFERENCE

    reference = args.params is None and args.width is None and args.height is None and args.t_frame_us is None
    args.width = REFERENCE[1] if args.width is None else args.width
    args.height = REFERENCE[2] if args.height is None else args.height
    if not (1 <= args.width <= MAX_SENSOR_SIDE and 1 <= args.height <= MAX_SENSOR_SIDE):
        raise EvclustError(f"sensor {args.width}x{args.height}: width and height must be 1 to {MAX_SENSOR_SIDE} px (x and y are 16-bit)")
    if args.t_frame_us is not None and not 0 < args.t_frame_us < math.inf:
        raise EvclustError(f"--t-frame-us {args.t_frame_us}: the frame period must be a positive, finite number of µs")
    from evclust.clusterer import load_params
    from evclust.fixed import build_formats, render_table, verilog_header

    params, origin = load_params(args.params or REFERENCE[0])
    t_frame = args.t_frame_us or params.t_frame_us or REFERENCE[3]
    table = build_formats(params, args.width, args.height, t_frame)
    print(f"formats for {origin} on {args.width}x{args.height}, T_frame {t_frame:g} µs")
    print(render_table(table))
    from evclust.fixed import registers

    outputs = {"rdl": args.rdl, "c_header": args.c_header, "markdown": args.registers, "ipxact": args.ipxact}
    texts = {"verilog": verilog_header(table)} if args.verilog else {}
    if any(outputs.values()) or args.html:
        from evclust.fixed import rdl

        texts |= rdl.generated(table)
    for kind, path in {"verilog": args.verilog, **outputs}.items():
        if path:
            with atomic_output(path) as tmp:
                tmp.write_text(texts[kind])
            print(f"{path}: written")
    if args.enums:
        from evclust.fixed import enums

        for module in enums.ENUMS:
            path = Path(args.enums) / enums.header_name(module)
            with atomic_output(path) as tmp:
                tmp.write_text(enums.header(module))
            print(f"{path}: written")
    if args.generate:
        from evclust.fixed import generate

        if not reference:
            raise EvclustError(
                "--generate writes the reference configuration's files; leave out --params, --width, --height and --t-frame-us"
            )
        for path in generate.write(args.generate, table):
            print(f"{path}: written")
    if args.html:
        rdl.write_html(table, args.html)
        print(f"{args.html}/index.html: written")
    if args.write_for:
        other, _ = load_params(args.write_for)
        runtime = registers.runtime_table(table, other, other.t_frame_us or t_frame)
        for address, word in registers.register_writes(table, runtime):
            print(f"0x{address:03x} 0x{word:08x}")
    return 0

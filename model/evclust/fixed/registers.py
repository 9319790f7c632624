"""The register map of a build: its run-time constants and its status counters (docs/REGISTERS.md).

Build-time, fixed in the generated header: N, the palette size, the sensor, every format (widths
and fraction bits), the decay table, the interval warm-up's gains, and the structural switches
(merging, creation support and its cell size, β as shifts, the histogram depth). Run-time,
written over the register bus: every constant the fixed model quantises from a [clusterer]
table, the palette, τ, the filter-step period, the background and the algorithm's switches.
A run-time value must fit its build-time format; `runtime_table` refuses one that does not.

The same table drives the RTL (`evclust_params.vh`: CFG_* word indices and the reset values),
the SystemRDL register map (rdl.py, and from it with PeakRDL the C header a driver includes, the
register map document and IP-XACT), and `register_writes`, which a testbench or a driver uses to
program a parameter set.
"""

from __future__ import annotations

import dataclasses

from evclust.errors import EvclustError
from evclust.fixed.formats import OPTIONAL_CONSTANTS, Constant, FormatTable, build_formats, quantise_constant, table_options

ID_VALUE = 0x4556434C  # "EVCL"
VERSION = 2  # 2: no saturation counters for size_target and speed_sq, which cannot overflow
# Control and status, then the counters, then the configuration (32-bit words, byte addresses).
REG_ID, REG_VERSION, REG_CTRL, REG_STATUS, REG_IRQ_ENABLE, REG_BUILD = 0x000, 0x004, 0x008, 0x00C, 0x010, 0x014
CTRL_CLEAR, CTRL_CLEAR_COUNTERS = 1, 2  # write-1 pulses
STATUS_IDLE, STATUS_SATURATED, STATUS_DROPPED = 1, 2, 4  # idle; sticky flags, write 1 to clear
COUNTERS_BASE = 0x040
CONFIG_BASE = 0x100

# The fixed model's saturating signals (the `_store` sites of fixed_model.py), in counter order.
SATURATING_SIGNALS = ("activity", "centre_step", "mcm_step", "events_in_interval", "gamma", "v_int", "v_mcm")
ACTION_COUNTERS = ("events", "updates", "creates", "evictions", "drops", "unsupported", "expiries", "exits", "merges", "records")
COUNTERS = ACTION_COUNTERS + tuple(f"sat_{name}" for name in SATURATING_SIGNALS)
COUNTER_INC_BITS = 2  # the core adds at most 2 to a counter per cycle (x and y saturating together)

# Run-time constants in register order (stable across builds); palette entries follow the options.
CONSTANT_ORDER = (
    "beta_pos", "beta_size", "beta_vel_mcm", "beta_vel_int", "beta_lum", "beta_chro", "beta_bg",
    "size_gain", "inv_t_half", "gamma_global", "gamma_per_activity", "frame_per_tau", "inv_p", "luma_weight",
    "r_init", "r_min", "r_max", "seek_margin", "exit_margin", "a_min", "a_valid", "v_min_sq", "v_exit_sq",
    "cos_sq_exit", "mixing_tolerance", "seek_scale", "merge_scale", "merge_v_tol", "merge_v_rel", "noise_gate",
    "support_window",
    # The object layer.
    "inv_t_frame", "object_gate", "object_link_along", "object_v_tol", "object_v_rel", "object_inv_track", "object_inv_rate",
    "object_inv_velocity", "object_inv_size", "object_inv_colour", "object_birth_us", "object_coast_us", "object_keep_us",
)  # fmt: skip
# Options (formats.py `table_options`) that are run-time: mux selects and values. The others are structural.
RUNTIME_OPTIONS = ("FILTER_EVERY", "TAU_US", "GAMMA_MODE", "WARM_START", "MCM_CORRECT", "VOTE_CONTRAST", "MIXING", "BG_FIXED",
                   "BACKGROUND_MASK", "BG_INIT_Y", "BG_INIT_CB", "BG_INIT_CR")  # fmt: skip
BUILD_OPTIONS = ("MERGE", "CREATE_SUPPORT", "SUPPORT_CELL_BITS", "VI_CAP", "OBJECTS", "N_OBJECTS", "UPDATE_DELAY",
                 "ACTIVITY_REFERENCE", "REFERENCE_HALVINGS")  # fmt: skip
OPTION_DOCS = {
    "FILTER_EVERY": "events between filter steps", "TAU_US": "τ, µs", "GAMMA_MODE": "γ: 0 global, 1 from activity, 2 counted",
    "WARM_START": "interval velocity warm start", "MCM_CORRECT": "MCM bias correction", "VOTE_CONTRAST": "palette votes weighted by contrast",
    "MIXING": "palette assignment by mixing", "BG_FIXED": "background fixed (no learning)",
    "BACKGROUND_MASK": "palette entries that are background, one bit each", "BG_INIT_Y": "initial background Y",
    "BG_INIT_CB": "initial background Cb", "BG_INIT_CR": "initial background Cr",
}  # fmt: skip


@dataclasses.dataclass(frozen=True)
class Field:
    name: str  # upper case, as in the header: BETA_POS, TAU_US, PALETTE_3_CB
    width: int
    word: int  # index of its first 32-bit word in the configuration block
    reset: int  # the build's value
    doc: str

    @property
    def address(self) -> int:
        return CONFIG_BASE + 4 * self.word

    @property
    def words(self) -> int:
        return -(-self.width // 32)


def _option_width(table: FormatTable, name: str) -> int:
    options = dict(table.options)
    if name == "FILTER_EVERY":
        return max(1, options["FILTER_EVERY"].bit_length())  # the RTL's EVERY_W
    if name == "TAU_US":
        return table.formats["tau_phase"].word_bits
    if name == "GAMMA_MODE":
        return 2
    if name == "BACKGROUND_MASK":
        return table.palette_size
    if name.startswith("BG_INIT_"):
        return table.formats["background"].word_bits
    return 1


def config_fields(table: FormatTable) -> tuple[Field, ...]:
    """The configuration registers of a build, in address order."""
    rows = []
    for name in CONSTANT_ORDER:
        const = table.constants.get(name)
        if const is None:
            assert name in OPTIONAL_CONSTANTS, name
            rows.append((name.upper(), 1, 0, "not in this build: 0"))
        else:
            rows.append((name.upper(), const.fmt.word_bits, const.raw, f"{const.fmt.q} {const.fmt.doc}"))
    options = dict(table.options)
    for name in RUNTIME_OPTIONS:
        rows.append((name, _option_width(table, name), options[name], OPTION_DOCS[name]))
    for j in range(table.palette_size):
        for channel in ("y", "cb", "cr"):
            const = table.constants[f"palette_{j}_{channel}"]
            rows.append((const.name.upper(), const.fmt.word_bits, const.raw, const.fmt.doc))
    fields, word = [], 0
    for name, width, reset, doc in rows:
        fields.append(Field(name, width, word, reset, doc))
        word += fields[-1].words
    return tuple(fields)


def config_words(table: FormatTable) -> int:
    last = config_fields(table)[-1]
    return last.word + last.words


def runtime_table(build: FormatTable, params, t_frame_us: float) -> FormatTable:
    """The formats of `build` with the constants and run-time options of `params`: what the RTL
    built from `build` computes once `params` is written to its registers. Refuses a parameter
    set that changes something build-time or whose value does not fit its build-time format."""
    p = params.resolved(t_frame_us)
    fresh = build_formats(p, build.width, build.height, t_frame_us, beta_shift_only=build.beta_shift_only)
    built_options, new_options = dict(build.options), dict(fresh.options)
    checks = {"n_clusters": (build.n_clusters, p.n_clusters), "palette size": (build.palette_size, len(p.palette)),
              "hist_bits": (build.formats["hist"].int_bits, p.hist_bits)}  # fmt: skip
    checks |= {name.lower(): (built_options[name], new_options[name]) for name in BUILD_OPTIONS}
    for what, (built, wanted) in checks.items():
        if built != wanted:
            raise EvclustError(f"clusterer: {what} is {wanted}, but the RTL was built with {built}; it is build-time (rebuild the header)")
    constants = {}
    for name, const in build.constants.items():
        new = fresh.constants.get(name)
        value = new.value if new is not None else 0.0
        raw = quantise_constant(value, const.fmt, name, f"clusterer ({name}, build format)") if value else 0
        constants[name] = Constant(name, const.fmt, value, raw)
    for name, const in fresh.constants.items():
        if name not in constants and const.raw != 0:
            raise EvclustError(f"clusterer ({name}): {const.value:g}, but this build has no register for it (it was 0 when the RTL was "
                               "built); rebuild the header with it non-zero")  # fmt: skip
    options = dict(table_options(p, build.formats["background"]))
    for name in RUNTIME_OPTIONS:
        width = _option_width(build, name)
        if not 0 <= options[name] < 1 << width:
            raise EvclustError(f"clusterer: {name.lower()} = {options[name]} does not fit its build-time register ({width} bits)")
    return dataclasses.replace(build, constants=constants, options=tuple(options.items()))


def register_values(table: FormatTable) -> dict[str, int]:
    """Field name -> raw value of a (run-time) table."""
    options = dict(table.options)
    values = {}
    for field in config_fields(table):
        const = table.constants.get(field.name.lower())
        values[field.name] = const.raw if const is not None else options.get(field.name, 0)
    return values


def register_writes(build: FormatTable, table: FormatTable) -> list[tuple[int, int]]:
    """(byte address, 32-bit word) writes that program `table` (from `runtime_table`) into the RTL built from `build`."""
    values = register_values(table)
    writes = []
    for field in config_fields(build):
        value = values[field.name]
        if not 0 <= value < 1 << field.width:
            raise EvclustError(f"register {field.name}: {value} does not fit {field.width} bits")
        for i in range(field.words):
            writes.append((field.address + 4 * i, (value >> (32 * i)) & 0xFFFFFFFF))
    return writes


def counter_address(name: str) -> int:
    return COUNTERS_BASE + 4 * COUNTERS.index(name)


def model_counters(stats: dict, records: int) -> dict[str, int]:
    """The counters as the fixed model's run statistics give them (modulo 2^32, as the RTL keeps them)."""
    created = stats["created"]
    counts = {
        "events": stats["events"], "updates": stats["events"] - created - stats["dropped"] - stats["unsupported"],
        "creates": created, "evictions": stats["evicted"], "drops": stats["dropped"], "unsupported": stats["unsupported"],
        "expiries": stats["expired"], "exits": stats["exited"], "merges": stats["merged"], "records": records,
    }  # fmt: skip
    for name in SATURATING_SIGNALS:
        counts[f"sat_{name}"] = stats["saturations"].get(name, 0)
    return {name: value & 0xFFFFFFFF for name, value in counts.items()}


def verilog_lines(table: FormatTable) -> list[str]:
    """The register map's part of evclust_params.vh."""
    fields = config_fields(table)
    words = config_words(table)
    out = [f"localparam integer CFG_WORDS = {words};  // the configuration block: 32-bit words from 0x{CONFIG_BASE:03x}"]
    for field in fields:
        out.append(f"localparam integer CFG_{field.name} = {field.word};  // word index; bits [{field.width - 1}:0]")
        out.append(f"localparam integer CFG_{field.name}_W = {field.width};")
    resets = []
    for field in fields:
        for i in range(field.words):
            resets.append((field.reset >> (32 * i)) & 0xFFFFFFFF)
    body = ", ".join(f"32'd{v}" for v in reversed(resets))
    out.append(f"localparam [{32 * words - 1}:0] CFG_RESET = {{{body}}};  // the build's parameter set")
    out.append(f"localparam integer N_COUNTERS = {len(COUNTERS)};")
    out.append(f"localparam integer COUNTER_INC_W = {COUNTER_INC_BITS};")
    for i, name in enumerate(COUNTERS):
        out.append(f"localparam integer COUNT_{name.upper()} = {i};")
    out.append(f"localparam [31:0] REG_ID_VALUE = 32'h{ID_VALUE:08x};")
    out.append(f"localparam integer REG_VERSION_VALUE = {VERSION};")
    return out


def verilog_field_lines(table: FormatTable) -> list[str]:
    """With EVCLUST_CONFIG_FIELDS defined, evclust_params.vh declares the configuration block's
    fields as named wires of their own widths, read from the including module's `cfg_used`: the
    register map types them, so no module slices the flat block by hand."""
    out = ["// verilator lint_off UNUSEDSIGNAL"]
    for field in config_fields(table):
        out.append(f"wire [CFG_{field.name}_W-1:0] cfg_{field.name.lower()} = cfg_used[32 * CFG_{field.name} +: CFG_{field.name}_W];")
    for channel in ("Y", "CB", "CR"):  # the palette packed, entry j in bits [8j +: 8]
        entries = ", ".join(f"cfg_palette_{j}_{channel.lower()}" for j in reversed(range(table.palette_size)))
        out.append(f"wire [8*PALETTE_SIZE-1:0] cfg_palette_{channel.lower()} = {{{entries}}};")
    out.append("// verilator lint_on UNUSEDSIGNAL")
    return out

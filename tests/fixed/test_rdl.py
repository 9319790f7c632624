"""The register map in SystemRDL (evclust.fixed.rdl): the committed RDL, C header, Markdown map
and IP-XACT are what the generator writes from the register table now, and they say what
registers.py says. The RTL is checked against the RDL by tb/evclust_regs."""

from __future__ import annotations

import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from evclust.fixed.generate import reference_table
from evclust.fixed import generate, rdl, registers

from testkit import run_cli

ROOT = Path(__file__).resolve().parents[2]
FILES = generate.REGISTER_MAP_FILES


@pytest.fixture(scope="module")
def generated() -> dict[str, str]:
    return rdl.generated(reference_table())


@pytest.mark.parametrize("kind", FILES)
def test_the_committed_register_map_files_are_generated_from_the_table(generated, kind):
    assert (ROOT / FILES[kind]).read_text() == generated[kind], f"{FILES[kind]} stale: run `make params`"


def test_the_rdl_is_ascii_and_says_what_the_register_table_says(generated):
    assert generated["rdl"].isascii()
    root = rdl.compile_rdl(generated["rdl"])
    regs = {reg.inst_name: reg for reg in root.top.registers()}
    table = reference_table()
    fields = registers.config_fields(table)
    expected = {f"CFG_{f.name}": (f.address, f.width, f.reset) for f in fields}
    expected |= {f"COUNT_{name.upper()}": (registers.counter_address(name), 32, 0) for name in registers.COUNTERS}
    expected |= {"ID": (registers.REG_ID, 32, registers.ID_VALUE), "VERSION": (registers.REG_VERSION, 32, registers.VERSION)}
    for name, (address, width, reset) in expected.items():
        value = regs[name].get_child_by_name("VALUE")
        assert (regs[name].absolute_address, value.width, value.get_property("reset")) == (address, width, reset), name
        assert regs[name].get_property("regwidth") == 32 * -(-width // 32), name
    others = {
        "CTRL": registers.REG_CTRL,
        "STATUS": registers.REG_STATUS,
        "IRQ_ENABLE": registers.REG_IRQ_ENABLE,
        "BUILD": registers.REG_BUILD,
    }
    assert {name: regs[name].absolute_address for name in others} == others
    assert set(regs) == set(expected) | set(others)
    assert regs["CTRL"].get_child_by_name("CLEAR").lsb == registers.CTRL_CLEAR.bit_length() - 1
    assert regs["STATUS"].get_child_by_name("DROPPED").lsb == registers.STATUS_DROPPED.bit_length() - 1
    assert regs["BUILD"].get_child_by_name("N_CLUSTERS").get_property("reset") == table.n_clusters


def test_the_c_header_compiles_and_its_addresses_are_the_register_maps(tmp_path):
    compiler = shutil.which("gcc") or shutil.which("g++")
    assert compiler, "a C compiler checks the driver's header"
    table = reference_table()
    fields = registers.config_fields(table)
    first, last = fields[0].name, fields[-1].name
    probe = tmp_path / "probe.c"
    probe.write_text(
        '#include <stddef.h>\n#include <stdio.h>\n#include "evclust_regs.h"\nint main(void) {\n'
        f'    printf("%zx %zx %zx %x\\n", offsetof(evclust_regs_t, CFG_{first}), offsetof(evclust_regs_t, CFG_{last}),\n'
        "           offsetof(evclust_regs_t, COUNT_RECORDS), (unsigned) EVCLUST_REGS__BUILD__N_CLUSTERS_reset);\n"
        "    return 0;\n}\n"
    )
    std = ["-std=gnu11"]  # PeakRDL-cheader's default C standard
    subprocess.run([compiler, *std, "-Wall", "-Werror", "-I", str(ROOT / "rtl"), "-o", str(tmp_path / "probe"), str(probe)], check=True)
    out = subprocess.run([str(tmp_path / "probe")], capture_output=True, text=True, check=True).stdout.split()
    # Independent of the generator: the block starts at 0x100 and each field takes whole 32-bit words.
    words = sum(-(-f.width // 32) for f in fields)
    assert [int(v, 16) for v in out] == [0x100, 0x100 + 4 * (words - 1), 0x40 + 4 * registers.COUNTERS.index("records"), table.n_clusters]


def test_the_ipxact_lists_every_register_at_its_address():
    ns = {"ipxact": "http://www.accellera.org/XMLSchema/IPXACT/1685-2014"}
    tree = ET.parse(ROOT / FILES["ipxact"])
    offsets = {reg.findtext("ipxact:name", namespaces=ns): int(reg.findtext("ipxact:addressOffset", namespaces=ns)[2:], 16)
               for reg in tree.iterfind(".//ipxact:register", ns)}  # fmt: skip
    assert offsets["ID"] == registers.REG_ID
    assert offsets["COUNT_RECORDS"] == registers.counter_address("records")
    assert {f"CFG_{f.name}": f.address for f in registers.config_fields(reference_table())}.items() <= offsets.items()


def test_formats_verb_writes_the_register_map_files(tmp_path, capsys, generated):
    paths = {kind: tmp_path / Path(name).name for kind, name in FILES.items()}
    code, _, err = run_cli(capsys, "formats", "--rdl", str(paths["rdl"]), "--c-header", str(paths["c_header"]),
                           "--registers", str(paths["markdown"]), "--ipxact", str(paths["ipxact"]))  # fmt: skip
    assert code == 0, err
    for kind, path in paths.items():
        assert path.read_text() == generated[kind], kind


def test_an_rdl_the_compiler_refuses_is_a_one_line_error():
    from evclust.errors import EvclustError

    with pytest.raises(EvclustError, match="systemrdl-compiler refused it"):
        rdl.compile_rdl("addrmap evclust_regs { no_such_t R; };\n")

"""Generated documents stay current: each records, in one comment line, fingerprints of the inputs
it was made from (evclust.stamps: the formats, the RTL, the fixed and the float model by what they
do), and fails here, naming the input and the make target, when one has changed since."""

from __future__ import annotations

from pathlib import Path

import pytest

from evclust import stamps
from evclust.errors import EvclustError
from evclust.documents import NEW_BENCHMARKS, write_section


@pytest.mark.parametrize("doc", stamps.DOCUMENTS, ids=lambda d: d.name)
def test_the_document_is_made_from_the_current_inputs(doc):
    problems = stamps.check([doc])
    assert not problems, problems[0]


def test_the_fingerprints_are_twelve_hex_digits_and_repeat():
    first = stamps.fingerprints()
    assert list(first) == list(stamps.INPUTS)
    assert all(len(v) == stamps.DIGITS and int(v, 16) >= 0 for v in first.values())
    assert stamps.float_fingerprint()[: stamps.DIGITS] == first["float"]  # the probe is deterministic


def test_a_stale_or_unstamped_document_fails_with_its_input_and_target(tmp_path):
    whole = stamps.Document("W", "w.md", None, None, ("formats", "float"), "make w")
    part = stamps.Document("S", "s.md", "<!-- s:start -->", "<!-- s:end -->", ("rtl",), "make s")
    now = {"formats": "a" * 12, "rtl": "b" * 12, "fixed": "c" * 12, "float": "d" * 12}
    (tmp_path / "w.md").write_text(stamps.stamped(whole, "# W\n\ntext\n", stamps.stamp_line(whole, now)))
    write_section(tmp_path / "s.md", "<!-- s:start -->\ntable\n<!-- s:end -->\n", part.start, part.end, stamp=stamps.stamp_line(part, now))
    assert stamps.check([whole, part], now, tmp_path) == []
    assert (tmp_path / "w.md").read_text().startswith("<!-- inputs: formats=aaaaaaaaaaaa float=dddddddddddd -->\n# W\n")

    later = now | {"float": "e" * 12}
    assert stamps.check([whole, part], later, tmp_path) == ["w.md (W): made from other float than now; regenerate it with make w"]

    # a regenerated section replaces its stamp, not adds a second one
    write_section(tmp_path / "s.md", "<!-- s:start -->\ntable 2\n<!-- s:end -->\n", part.start, part.end,
                  stamp=stamps.stamp_line(part, later | {"rtl": "f" * 12}))  # fmt: skip
    assert (tmp_path / "s.md").read_text().count("<!-- inputs:") == 1
    assert stamps.check([part], now, tmp_path) == ["s.md (S): made from other rtl than now; regenerate it with make s"]

    (tmp_path / "w.md").write_text("# W\n\nedited by hand\n")
    assert stamps.check([whole], now, tmp_path) == ["w.md (W): no input stamp; regenerate it with make w"]


def test_restamping_keeps_the_document_and_changes_only_its_stamp(tmp_path):
    part = stamps.Document("S", "s.md", "<!-- s:start -->", "<!-- s:end -->", ("rtl",), "make s")
    (tmp_path / "s.md").write_text("# Top\n\n<!-- s:start -->\n## S\n\nrows\n<!-- s:end -->\n\nafter\n")
    stamps.stamp_document(part, {"rtl": "1" * 12}, tmp_path)
    stamps.stamp_document(part, {"rtl": "2" * 12}, tmp_path)
    want = "# Top\n\n<!-- s:start -->\n<!-- inputs: rtl=222222222222 -->\n## S\n\nrows\n<!-- s:end -->\n\nafter\n"
    assert (tmp_path / "s.md").read_text() == want


def test_the_readmes_tables_are_their_sources_tables_now():
    from evclust import readme

    assert readme.stale(stamps.REPO / "README.md") == []


def test_a_readme_table_is_its_sources_rows_and_columns_and_follows_it(tmp_path):
    from evclust import readme
    from evclust.errors import EvclustError

    source = stamps.Document("SRC", "src.md", None, None, ("rtl",), "make src")
    text = "# Src\n\n## Figures\n\n| name | a | b / c |\n|---|---:|---:|\n| x | 1 | 2 / 3 |\n| y | 4 | 5 / 6 |\n\n## Other\n\n| q |\n|---|\n| z |\n"
    (tmp_path / "src.md").write_text(stamps.stamped(source, text, stamps.stamp_line(source, {"rtl": "a" * 12})))
    table = readme.Table("t", "src.md", "SRC", "## Figures", (readme.Column("name"), readme.Column("b / c", "c", 1)), ("y",))
    want = "| name | c |\n|---|---:|\n| y | 6 |"
    assert readme.extract(table, text) == want
    assert readme.extract(table._replace(columns=None, rows=None), text).split("\n")[-1] == "| y | 4 | 5 / 6 |"
    with pytest.raises(EvclustError, match="no column 'd'"):
        readme.extract(table._replace(columns=(readme.Column("d"),)), text)
    with pytest.raises(EvclustError, match="no row 'w'"):
        readme.extract(table._replace(rows=("w",)), text)

    # The README's section carries the source's stamp; it goes stale when the source changes.
    (tmp_path / "README.md").write_text("# R\n\n<!-- readme:t:start -->\n<!-- readme:t:end -->\n")
    old_tables, old_names = readme.TABLES, dict(stamps.BY_NAME)
    readme.TABLES = (table,)
    stamps.BY_NAME["SRC"] = source
    try:
        readme.write(tmp_path / "README.md", tmp_path)
        assert (tmp_path / "README.md").read_text() == (
            "# R\n\n<!-- readme:t:start -->\n<!-- inputs: rtl=aaaaaaaaaaaa -->\n" + want + "\n<!-- readme:t:end -->\n"
        )
        assert readme.stale(tmp_path / "README.md", tmp_path) == []
        (tmp_path / "src.md").write_text((tmp_path / "src.md").read_text().replace("| 5 / 6 |", "| 5 / 7 |"))
        assert readme.stale(tmp_path / "README.md", tmp_path) == [
            f"{tmp_path / 'README.md'}: the t table is not what src.md says now: run `python -m evclust.readme --write README.md`"
        ]
    finally:
        readme.TABLES = old_tables
        stamps.BY_NAME.clear()
        stamps.BY_NAME.update(old_names)


def test_the_plan_runs_each_stale_documents_command_once_in_the_tables_order_then_the_readme():
    by_name = stamps.BY_NAME
    # The datasheet and the timing section share `make timing`; the README's tables come last.
    plan = stamps.regeneration_plan([by_name["RTL:datasheet"], by_name["VERIFICATION:coverage"], by_name["BENCHMARKS:timing"],
                                     by_name["REPORT"]])  # fmt: skip
    assert plan == ["make report", "make timing", "make coverage", stamps.README_TABLES]
    assert stamps.regeneration_plan([]) == []
    # bench/rtl reads make timing's Fmax: it runs after it, though the table lists it first
    plan = stamps.regeneration_plan([by_name["BENCHMARKS:rtl"], by_name["BENCHMARKS:timing"]])
    assert plan == ["make timing", f"{stamps.PY} bench/rtl.py --write docs/BENCHMARKS.md", stamps.README_TABLES]


def test_two_at_a_time_a_command_waits_for_the_one_it_reads(tmp_path, monkeypatch):
    monkeypatch.setattr(stamps, "AFTER", {"[ -e made ] && touch read": ("sleep 1; touch made",)})
    stamps.regenerate(["[ -e made ] && touch read", "sleep 1; touch made", "true"], tmp_path, jobs=2)
    assert (tmp_path / "read").exists()


def test_every_documents_command_is_a_make_target_or_a_script_of_the_repository():
    targets = {line.split(":")[0] for line in (stamps.REPO / "Makefile").read_text().splitlines() if line[:1].isalpha() and ":" in line}
    for doc in stamps.DOCUMENTS:
        for command in doc.target.split(" && "):
            words = command.split()
            if words[0] == "make":
                assert words[1] in targets, (doc.name, command)
            else:
                assert words[0] in (stamps.PY, ".venv/bin/evclust"), (doc.name, command)
                assert words[0] == ".venv/bin/evclust" or (stamps.REPO / words[1]).is_file(), (doc.name, command)


def test_regenerating_stops_at_the_first_failing_command(tmp_path):
    commands = ["echo one > one.txt", "exit 3", "echo three > three.txt"]
    with pytest.raises(EvclustError, match=r"`exit 3` failed \(exit status 3\); not run: echo three > three\.txt"):
        stamps.regenerate(commands, tmp_path)
    assert (tmp_path / "one.txt").exists() and not (tmp_path / "three.txt").exists()


def test_regenerating_two_at_a_time_runs_them_together_and_the_readme_after_all(tmp_path):
    # each of the first two waits for the other's file: one at a time, the first would wait forever
    wait = "for i in $(seq 100); do [ -e {0} ] && break; sleep 0.05; done; [ -e {0} ]"
    commands = [f"touch a; {wait.format('b')}", f"touch b; {wait.format('a')}", "echo c > c", stamps.README_TABLES]
    old = stamps.README_TABLES
    try:
        stamps.README_TABLES = commands[-1] = "ls a b c > readme.txt"
        stamps.regenerate(commands, tmp_path, jobs=2)
    finally:
        stamps.README_TABLES = old
    assert (tmp_path / "readme.txt").read_text().split() == ["a", "b", "c"]
    assert sorted(p.name for p in (tmp_path / "build" / "regenerate").iterdir()) == ["1.log", "2.log", "3.log"]


def test_a_failure_two_at_a_time_waits_for_the_running_and_starts_nothing_more(tmp_path):
    # the first ends after the second has failed: the third must not start in its place
    wait = "for i in $(seq 200); do [ -e failed ] && break; sleep 0.05; done"
    commands = [f"{wait}; sleep 1; echo one > one.txt", "touch failed; exit 3", "echo three > three.txt"]
    with pytest.raises(
        EvclustError, match=r"`touch failed; exit 3` failed \(exit status 3\); see .*2\.log; not run: echo three > three\.txt"
    ):
        stamps.regenerate(commands, tmp_path, jobs=2)
    assert (tmp_path / "one.txt").exists() and not (tmp_path / "three.txt").exists()


def _write_sections(path: str, name: str, times: int) -> None:
    for i in range(times):
        write_section(Path(path), f"<!-- {name}:start -->\n{name} {i}\n<!-- {name}:end -->\n", f"<!-- {name}:start -->",
                      f"<!-- {name}:end -->")  # fmt: skip


def test_two_writers_of_one_document_lose_no_section(tmp_path):
    import multiprocessing

    path = tmp_path / "BENCHMARKS.md"
    context = multiprocessing.get_context("spawn")
    writers = [context.Process(target=_write_sections, args=(str(path), name, 200)) for name in ("one", "two")]
    for w in writers:
        w.start()
    for w in writers:
        w.join(60)
    assert [w.exitcode for w in writers] == [0, 0]
    text = path.read_text()
    assert text.startswith(NEW_BENCHMARKS)
    assert "one 199" in text and "two 199" in text
    assert text.count("<!-- one:start -->") == 1 and text.count("<!-- two:start -->") == 1


def test_the_rtl_is_fingerprinted_as_its_tools_read_it():
    read = stamps.verilog_as_read
    code = "module m;\n  wire a = 1'b1;\nendmodule\n"
    # Comments, indentation and blank lines are not read: the fingerprint keeps.
    assert read(code) == read("// why m\nmodule m;  /* one\nwire */\n\n\twire   a = 1'b1; // a's why\nendmodule")
    # A change of code is read.
    assert read(code) != read(code.replace("1'b1", "1'b0"))
    # A "//" inside a string is no comment; the tools' directives are read; a `define ends at its line.
    assert read('initial $display("a // b /* c */"); // x') == 'initial $display("a // b /* c */");'
    assert read("wire w; // verilator lint_off WIDTH") == "wire w; // verilator lint_off WIDTH"
    assert read("// synthesis translate_off\nx") == "// synthesis translate_off\nx"
    assert read("`define M 1 /* one\ntwo */\nwire w = `M;") == "`define M 1\nwire w = `M;"


def test_the_rtl_as_the_fingerprint_reads_it_is_the_same_design_to_icarus(tmp_path):
    """What the fingerprint drops changes nothing Icarus builds: the repository's RTL, read so,
    compiles to the same netlist (Icarus' object addresses and source lines aside)."""
    import re
    import shutil
    import subprocess

    if shutil.which("iverilog") is None:
        pytest.fail("iverilog is not on PATH (the machine's Icarus Verilog is a requirement)")
    read_dir = tmp_path / "read"
    read_dir.mkdir()
    for path in sorted((stamps.REPO / "rtl").glob("*.v*")):
        text = path.read_text()
        (read_dir / path.name).write_text(text if path.name == "evclust_params.vh" else stamps.verilog_as_read(text) + "\n")

    def netlist(folder: Path) -> list[str]:
        out = tmp_path / f"{folder.name}.vvp"
        sources = sorted(str(p) for p in folder.glob("*.v"))
        subprocess.run(["iverilog", "-g2005", f"-I{folder}", "-s", "evclust_axis", "-o", str(out), *sources], check=True,
                       capture_output=True)  # fmt: skip
        lines = [ln for ln in out.read_text().splitlines() if not ln.startswith(":file_names") and not ln.startswith('    "')]
        # addresses, and the (file, line) pairs of scopes and parameters
        lines = [re.sub(r"0x[0-9a-f]+", "0x", ln) for ln in lines]
        lines = [re.sub(r'^(P_0x \.param/\w+ "\w+") \d+ \d+ \d+,', r"\1", ln) for ln in lines]
        return [re.sub(r'^(S_0x \.scope [\w.]+, "[^"]*" "[^"]*") \d+ \d+(, \d+ \d+ \d+)?', r"\1", ln) for ln in lines]

    original, as_read = netlist(stamps.REPO / "rtl"), netlist(read_dir)
    assert len(original) > 10_000 and original == as_read

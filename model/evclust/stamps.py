"""Input stamps of the generated documents: each document (or section of one) records, in one HTML
comment line, fingerprints of the inputs it was made from, and tests/test_documents.py fails when
an input changed since, naming the document, the input and the make target that regenerates it.

The inputs are fingerprinted by what they do, not by their source text, so a refactor that keeps
the behaviour keeps the stamps (as the golden vectors' staleness check compares outputs):

  formats  sha256 of the generated header rtl/evclust_params.vh (a test keeps it current with the
           formats table)
  rtl      sha256 over the RTL's sources (rtl/*.v, rtl/*.vh but the generated header), by name, each
           as its tools read it: without comments (but the tools' own directives, `// verilator
           lint_off`, `// synthesis translate_off`), blank lines and indentation, so that a comment
           or a reflow of the Verilog does not make two hours of documents stale
  fixed    sha256 over the golden vectors' manifests' sha256 entries (vectors/*/manifest.json; the
           vectors' staleness test keeps them equal to what the fixed model writes now)
  simulator  the simulator's behaviour: a small scene simulated without and with every sensor
           effect, its events hashed, and the built-in scenes as parsed
  float    the float model's behaviour (on the simulator's): the simulator's probe, each run through
           the float model with the configurations the documents use (the defaults, each preset,
           the defaults at update_delay 1 and 2), object layer included; its records (as float32,
           so that another machine's last-place rounding does not count) hashed with the events.
  reference  the activity against a reference time (ClustererParams.activity_reference), which
           neither probe above runs: the float and fixed models' records on the float probe's
           events with the mode on, at update_delay 0 and 2.
  sweep    the filter step's sweep beside the events (ClustererParams.sweep_slots_per_event),
           which no probe above runs: the float and fixed models' records on the float probe's
           events at one slot an event, with the paper's update and with D = 2 against a reference time.

    python -m evclust.stamps                       # the current fingerprints and every document's state
    python -m evclust.stamps --plan                # the commands that regenerate every stale document, each once
    python -m evclust.stamps --regenerate [--jobs 2]  # run them (two at a time), then the README's tables
    python -m evclust.stamps --stamp NAME --made-at COMMIT
        stamps a document made at COMMIT without regenerating it, only where each of its inputs'
        fingerprints at COMMIT equals today's (the probes run on COMMIT's model in a
        subprocess); otherwise it refuses and names the input that changed.

This module runs the float and fixed models, so it sits above evclust.fixed and evclust.simulator; the
RTL's coverage table (evclust.rtl.coverage) writes its stamp, so it sits below evclust.rtl. It
reads the RTL and the vectors as files and imports neither evclust.rtl nor evclust.vectors.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import NamedTuple

from evclust.errors import EvclustError

REPO = Path(__file__).resolve().parents[2]
HEADER = "rtl/evclust_params.vh"
INPUTS = ("formats", "rtl", "fixed", "simulator", "float", "reference", "sweep")
DIGITS = 12  # hex digits of each fingerprint in a stamp
STAMP_RE = re.compile(r"<!-- inputs: ((?:[a-z]+=[0-9a-f]+ ?)+) -->")


class Document(NamedTuple):
    """A generated document, or the section of one between two markers (start is None: the
    whole file, its stamp on the first line)."""

    name: str
    path: str
    start: str | None
    end: str | None
    inputs: tuple[str, ...]
    target: str  # the shell command, run at the repository's top, that regenerates it


def _bench(name: str, inputs: tuple[str, ...], target: str) -> Document:
    return Document(f"BENCHMARKS:{name}", "docs/BENCHMARKS.md", f"<!-- bench:{name}:start -->", f"<!-- bench:{name}:end -->",
                    inputs, target)  # fmt: skip


# Every generated document and what it is made from: the one table the test and the generators read.
# Not here: BENCHMARKS' runtime-config section (written by hand, a record of a before/after
# comparison), its event_io and startup sections (they time the event-file code and the command
# line's start-up, none of these inputs), docs/REGISTERS.md and rtl/evclust_params.vh (checked
# byte for byte by their own tests), the README's tables (copied from the documents here with their
# stamps by evclust.readme, and checked against them).
# fmt: off
PY = ".venv/bin/python"
DOCUMENTS = (
    Document("REPORT", "docs/report/REPORT.md", None, None, ("formats", "rtl", "fixed", "float"), "make report"),
    Document("RESULTS", "docs/RESULTS.md", None, None, ("formats", "fixed", "float"), "make results"),
    Document("RESULTS:video", "docs/RESULTS.md", "<!-- results:video:start -->", "<!-- results:video:end -->", ("float",),
             "make results-video"),
    Document("GENERALIZATION", "docs/GENERALIZATION.md", None, None, ("formats", "fixed", "float"), "make generalize"),
    Document("PIPELINE", "docs/PIPELINE.md", None, None, ("float", "fixed", "reference", "sweep"), "make generalize"),
    Document("ABLATION", "docs/ABLATION.md", None, None, ("float",), "make ablation"),
    _bench("simulator", ("simulator",), f"{PY} bench/simulator.py --write docs/BENCHMARKS.md"),
    _bench("clusterer", ("formats", "fixed", "float"), f"{PY} bench/clusterer.py --write docs/BENCHMARKS.md"),
    _bench("rtl", ("formats", "rtl", "fixed"), f"{PY} bench/rtl.py --write docs/BENCHMARKS.md"),
    _bench("synth", ("formats", "rtl"), "make synth"),
    _bench("synth-defaults", ("formats", "rtl"), f"{PY} synth/synth.py --defaults --n 16 --write docs/BENCHMARKS.md"),
    _bench("timing", ("formats", "rtl"), "make timing"),
    _bench("area", ("formats", "rtl"), "make area"),
    _bench("activity-reference", ("formats", "rtl", "reference"), f"{PY} synth/activity_reference.py --write docs/BENCHMARKS.md"),
    _bench("peers", ("simulator",), "make bench-peers"),
    _bench("recordings", ("float",), f"make recordings && {PY} bench/recordings.py --write docs/BENCHMARKS.md"),
    Document("RTL:datasheet", "docs/RTL.md", "<!-- datasheet:timing:start -->", "<!-- datasheet:timing:end -->", ("formats", "rtl"),
             "make timing"),
    Document("VERIFICATION:coverage", "docs/VERIFICATION.md", "<!-- coverage:begin -->", "<!-- coverage:end -->",
             ("formats", "rtl", "fixed"), "make coverage"),
    Document("TUNING:ablation", "docs/TUNING.md", "<!-- ablation:start -->", "<!-- ablation:end -->", ("formats", "rtl", "float"),
             "make ablation"),
)
# fmt: on
BY_NAME = {d.name: d for d in DOCUMENTS}


# -- the fingerprints ------------------------------------------------------------------------------


def _sha(chunks) -> str:
    h = hashlib.sha256()
    for chunk in chunks:
        h.update(chunk if isinstance(chunk, bytes) else chunk.encode())
        h.update(b"\0")
    return h.hexdigest()


class Files:
    """The repository's files, now (the working tree) or at a commit (git show)."""

    def __init__(self, commit: str | None = None, root: Path = REPO):
        self.commit, self.root = commit, root

    def _git(self, *args: str) -> str:
        return subprocess.run(["git", *args], cwd=self.root, capture_output=True, text=True, check=True).stdout

    def names(self, folder: str, suffixes: tuple[str, ...]) -> list[str]:
        if self.commit is None:
            found = [str(p.relative_to(self.root)) for p in (self.root / folder).rglob("*") if p.is_file()]
        else:
            found = self._git("ls-tree", "-r", "--name-only", self.commit, "--", folder).split()
        return sorted(n for n in found if n.endswith(suffixes))

    def read(self, name: str) -> bytes:
        if self.commit is None:
            return (self.root / name).read_bytes()
        return subprocess.run(["git", "show", f"{self.commit}:{name}"], cwd=self.root, capture_output=True, check=True).stdout


def formats_fingerprint(files: Files) -> str:
    return hashlib.sha256(files.read(HEADER)).hexdigest()


# A Verilog source's strings and comments, in one scan so that a "//" inside a string is no comment.
_VERILOG_LEXEMES = re.compile(r'"(?:\\.|[^"\\\n])*"|//[^\n]*|/\*.*?\*/', re.S)
# Comments that a tool reads: they change what is linted, simulated or synthesised.
_DIRECTIVE = re.compile(r"(//|/\*)\s*(verilator|synopsys|synthesis|pragma|yosys|translate_(on|off))\b")


def verilog_as_read(text: str) -> str:
    """The Verilog without what no tool reads: comments (but directives) become a space, each
    line's runs of blanks one space, blank lines go. Line breaks stay (a `define ends at one)."""

    def lexeme(match: re.Match) -> str:
        s = match.group(0)
        if s.startswith('"') or _DIRECTIVE.match(s):
            return s
        return " " + "\n" * s.count("\n")  # a block comment's line breaks stay: a `define may span them

    lines = (" ".join(line.split()) for line in _VERILOG_LEXEMES.sub(lexeme, text).split("\n"))
    return "\n".join(line for line in lines if line)


def rtl_fingerprint(files: Files) -> str:
    names = [n for n in files.names("rtl", (".v", ".vh")) if n != HEADER and n.count("/") == 1]
    return _sha(part for n in names for part in (n, verilog_as_read(files.read(n).decode())))


def fixed_fingerprint(files: Files) -> str:
    chunks = []
    for name in (n for n in files.names("vectors", ("/manifest.json",)) if n.count("/") == 2):
        manifest = json.loads(files.read(name))
        chunks += [name.split("/")[1], *(f"{k}={v}" for k, v in sorted(manifest["sha256"].items()))]
    return _sha(chunks)


# The probe's scene: small, coloured objects that enter, cross, turn and leave over a textured
# background, sampled between frames; simulated once as the ideal sensor and once with every effect.
PROBE_SCENE = """
name = "stamp_probe"
width = 96
height = 64
fps = 25
frames = 24
substeps = 2
seed = 5
[background]
kind = "texture"
colour = [90, 100, 110]
contrast = 6
scale = 3
[[objects]]
id = 1
label = "red"
size = [14, 10]
colour = [200, 30, 30]
patches = [{ offset = [3, 0], size = [5, 6], colour = [40, 40, 60] }]
start = [-6.0, 20.0]
legs = [{ frames = 24, velocity = [5.0, 0.5] }]
[[objects]]
id = 2
label = "blue"
shape = "ellipse"
size = [12, 12]
colour = [30, 60, 210]
start = [80.0, 50.0]
start_frame = 3
legs = [{ frames = 10, velocity = [-3.0, -1.0] }, { frames = 11, velocity = [-1.0, -3.0] }]
[[objects]]
id = 3
label = "white"
size = [8, 20]
colour = [235, 235, 230]
start = [40.0, 70.0]
start_frame = 6
legs = [{ frames = 18, velocity = [0.0, -4.5] }]
"""


def _rounded(rows) -> bytes:
    """Records as float32: a last-place difference of a float64 (another CPU's libm or SIMD path)
    does not change them, a change of the model's behaviour does."""
    import numpy as np

    return np.ascontiguousarray(rows, dtype=np.float32).tobytes()


def _probe_scenes():
    from evclust.scenes import scene_from_toml
    from evclust.simulator import EFFECTS

    ideal = scene_from_toml(PROBE_SCENE, "stamp probe")
    effects = scene_from_toml(PROBE_SCENE + "".join(f"[effects.{name}]\n" for name in EFFECTS), "stamp probe, every effect")
    return (("ideal", ideal), ("effects", effects))


def probe_events() -> list[tuple[str, bytes]]:
    """The simulator probe's outputs, each labelled: the built-in scenes as parsed, the probe
    scene's events. Only long-standing interfaces are used, so that `--made-at` can run this on
    an earlier commit's simulator."""
    import numpy as np

    from evclust.scenes import builtin_scenes, load_scene
    from evclust.simulator import simulate_scene

    out = [(f"scene {name}", load_scene(name).spec.model_dump_json().encode()) for name in builtin_scenes()]
    for label, scene in _probe_scenes():
        out.append((f"events {label}", np.ascontiguousarray(simulate_scene(scene).events).tobytes()))
    return out


def probe_records() -> list[tuple[str, bytes]]:
    """The float probe's outputs, each labelled: the simulator probe's, each scene's events
    followed by the float model's records on them."""
    import numpy as np

    from evclust.clusterer import ClustererParams, FloatClusterer, load_params, preset_names
    from evclust.clusterer.objects import FloatObjects
    from evclust.events import EVENT_DTYPE

    simulated = probe_events()
    out = [(label, data) for label, data in simulated if not label.startswith("events ")]
    events = {label.split(" ", 1)[1]: data for label, data in simulated if label.startswith("events ")}
    configs = [("defaults", ClustererParams())] + [(name, load_params(name)[0]) for name in preset_names()]
    configs += [(f"defaults D={d}", ClustererParams(update_delay=d)) for d in (1, 2)]
    for label, scene in _probe_scenes():
        out.append((f"events {label}", events[label]))
        src = scene.source
        for name, params in configs:
            model = FloatClusterer(params, src.width, src.height, src.t_frame_us)
            rows = model.feed(np.frombuffer(events[label], dtype=EVENT_DTYPE))
            out.append((f"{label} {name} clusters", _rounded(rows)))
            if params.objects:
                objects = FloatObjects(model.params, src.width, src.height, src.t_frame_us)
                out.append((f"{label} {name} objects", _rounded(objects.feed(rows, model.steps))))
    return out


def _hash(parts) -> str:
    return _sha(part for label, data in parts for part in (label, data))


def _both_models_on_probe(configs) -> list[tuple[str, bytes]]:
    """The float and fixed models' records on the probe's events, each labelled "<scene> <tag>
    <model>", for `configs`: (tag, ClustererParams) pairs (float records as float32)."""
    import numpy as np

    from evclust.clusterer import FloatClusterer
    from evclust.events import EVENT_DTYPE
    from evclust.fixed.model import FixedClusterer

    events = {label.split(" ", 1)[1]: data for label, data in probe_events() if label.startswith("events ")}
    out = []
    for label, scene in _probe_scenes():
        src = scene.source
        for tag, params in configs:
            for name, model in (("float", FloatClusterer), ("fixed", FixedClusterer)):
                rows = model(params, src.width, src.height, src.t_frame_us).feed(np.frombuffer(events[label], dtype=EVENT_DTYPE))
                out.append((f"{label} {tag} {name}", _rounded(rows) if name == "float" else np.ascontiguousarray(rows).tobytes()))
    return out


def probe_reference_records() -> list[tuple[str, bytes]]:
    """The activity against a reference time (ClustererParams.activity_reference), which no other
    probe runs: the float and fixed models' records on the probe's events, at D = 0 and 2."""
    from evclust.clusterer import ClustererParams

    return _both_models_on_probe([(f"D={d}", ClustererParams(activity_reference=True, update_delay=d, objects=False)) for d in (0, 2)])


def probe_sweep_records() -> list[tuple[str, bytes]]:
    """The sweep beside the events (ClustererParams.sweep_slots_per_event), which no other probe
    runs: the float and fixed models' records on the probe's events at one slot an event, with the
    paper's update (D = 0) and the pipelined core's (D = 2, the activity against a reference time)."""
    from evclust.clusterer import ClustererParams

    return _both_models_on_probe([
        (f"D={d}", ClustererParams(sweep_slots_per_event=1, update_delay=d, activity_reference=reference, objects=False))
        for d, reference in ((0, False), (2, True))
    ])  # fmt: skip


def sweep_fingerprint(files: Files | None = None) -> str:
    """The sweep probe's hash, run here, or (files at a commit) on that commit's models."""
    if files is None or files.commit is None:
        return _hash(probe_sweep_records())
    return _at_commit(files, "sweep_fingerprint", "sweep")


def reference_fingerprint(files: Files | None = None) -> str:
    """The activity-reference probe's hash, run here, or (files at a commit) on that commit's models."""
    if files is None or files.commit is None:
        return _hash(probe_reference_records())
    return _at_commit(files, "reference_fingerprint", "reference")


def simulator_fingerprint(files: Files | None = None) -> str:
    """The simulator probe's hash, run here, or (files at a commit) on that commit's simulator."""
    if files is None or files.commit is None:
        return _hash(probe_events())
    return _at_commit(files, "simulator_fingerprint", "simulator")


def float_fingerprint(files: Files | None = None) -> str:
    """The float probe's hash, run here, or (files at a commit) on that commit's model."""
    if files is None or files.commit is None:
        return _hash(probe_records())
    return _at_commit(files, "float_fingerprint", "float")


def _at_commit(files: Files, function: str, what: str) -> str:
    """A probe run in a subprocess on the commit's model (git archive), this module's code."""
    with tempfile.TemporaryDirectory(prefix="evclust-stamp-") as tmp:
        archive = subprocess.run(["git", "archive", files.commit, "model"], cwd=files.root, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        probe = (
            "import importlib.util, sys\n"
            f"spec = importlib.util.spec_from_file_location('evclust_stamp_probe', {str(Path(__file__))!r})\n"
            "m = importlib.util.module_from_spec(spec); spec.loader.exec_module(m)\n"
            f"print(m.{function}())\n"
        )
        env = dict(os.environ, PYTHONPATH=str(Path(tmp) / "model"), NUMBA_CACHE_DIR=str(Path(tmp) / "numba"))
        run = subprocess.run([sys.executable, "-c", probe], cwd=tmp, env=env, capture_output=True, text=True)
        if run.returncode != 0:
            errors = [line for line in run.stderr.splitlines() if re.match(r"[\w.]+(Error|Exception)\b", line)]
            last = (errors or run.stderr.strip().splitlines() or ["no output"])[-1]
            raise EvclustError(f"the {what} probe does not run on {files.commit}'s model: {last}")
        return run.stdout.strip().splitlines()[-1]


FINGERPRINTS = {
    "formats": formats_fingerprint,
    "rtl": rtl_fingerprint,
    "fixed": fixed_fingerprint,
    "simulator": simulator_fingerprint,
    "float": float_fingerprint,
    "reference": reference_fingerprint,
    "sweep": sweep_fingerprint,
}


def fingerprints(inputs=INPUTS, commit: str | None = None) -> dict[str, str]:
    """The inputs' fingerprints (12 hex digits each), now or at a commit."""
    if commit is None:
        return {name: _current(name) for name in inputs}
    files = Files(commit)
    return {name: FINGERPRINTS[name](files)[:DIGITS] for name in inputs}


@functools.cache
def _current(name: str) -> str:
    """An input's fingerprint now, once per process (a generator stamps once, at its end)."""
    return FINGERPRINTS[name](Files())[:DIGITS]


def stamp_for(name: str) -> str:
    """The stamp line a generator writes into the document `name` of DOCUMENTS."""
    return stamp_line(BY_NAME[name])


# -- stamps in documents ---------------------------------------------------------------------------


def stamp_line(doc: Document, values: dict[str, str] | None = None) -> str:
    """The document's stamp: its inputs' fingerprints (now, unless given)."""
    values = values if values is not None else fingerprints(doc.inputs)
    return "<!-- inputs: " + " ".join(f"{name}={values[name][:DIGITS]}" for name in doc.inputs) + " -->"


def stamped(doc: Document, text: str, line: str | None = None) -> str:
    """`text` (the whole document, or its section from start marker to end marker) with its stamp
    line added or replaced: the first line of a whole document, the line after a section's start."""
    line = line or stamp_line(doc)
    if doc.start is None:
        lines = text.split("\n")
        if lines and STAMP_RE.fullmatch(lines[0]):
            lines = lines[1:]
        return "\n".join([line, *lines])
    if not text.startswith(doc.start):
        raise EvclustError(f"{doc.name}: the section does not begin with {doc.start}")
    body = text[len(doc.start) :].lstrip("\n")
    first, _, rest = body.partition("\n")
    if STAMP_RE.fullmatch(first):
        body = rest
    return f"{doc.start}\n{line}\n{body}"


def read_stamp(doc: Document, text: str) -> dict[str, str] | None:
    """The fingerprints a document records (None: no stamp where it belongs, or no section)."""
    if doc.start is None:
        first = text.split("\n", 1)[0]
    else:
        if doc.start not in text or doc.end not in text:
            return None
        first = text.split(doc.start, 1)[1].lstrip("\n").split("\n", 1)[0]
    match = STAMP_RE.fullmatch(first)
    return dict(pair.split("=") for pair in match.group(1).split()) if match else None


def stale(documents=DOCUMENTS, current: dict[str, str] | None = None, root: Path = REPO) -> list[tuple[Document, str]]:
    """(document, why) for each document whose stamp is missing or records an input that has changed since."""
    current = current if current is not None else fingerprints()
    found = []
    for doc in documents:
        path = root / doc.path
        if not path.is_file():
            found.append((doc, "missing"))
            continue
        stamp = read_stamp(doc, path.read_text())
        if stamp is None:
            found.append((doc, "no input stamp"))
            continue
        changed = [name for name in doc.inputs if stamp.get(name) != current[name]]
        if changed:
            found.append((doc, f"made from other {', '.join(changed)} than now"))
    return found


def check(documents=DOCUMENTS, current: dict[str, str] | None = None, root: Path = REPO) -> list[str]:
    """One line per stale document: what is wrong with it and what regenerates it."""
    return [f"{doc.path} ({doc.name}): {why}; regenerate it with {doc.target}" for doc, why in stale(documents, current, root)]


README_TABLES = f"{PY} -m evclust.readme --write README.md"  # the README's tables, copied from the documents
# A command that reads another's results runs after it: bench/rtl's sustained rate takes make
# timing's Fmax from build/timing/results.json.
AFTER = {f"{PY} bench/rtl.py --write docs/BENCHMARKS.md": ("make timing",)}
# Each command's wall time on this machine (2 cores, from the documents' own recorded runs), in
# minutes: only to start the longest first when commands run at once.
MINUTES = {"make timing": 100, "make area": 4, "make ablation": 30, "make report": 20, "make coverage": 20, "make generalize": 25, "make synth": 8,
           f"{PY} synth/synth.py --defaults --n 16 --write docs/BENCHMARKS.md": 6}  # fmt: skip


def regeneration_plan(documents) -> list[str]:
    """The commands that regenerate `documents`, each once, in DOCUMENTS' order but each after the
    commands it reads (AFTER), then the README's tables (copied from them)."""
    commands = list(dict.fromkeys(doc.target for doc in DOCUMENTS if doc in documents))
    for command, before in AFTER.items():
        if command in commands and any(b in commands for b in before):
            commands.remove(command)
            commands.insert(max(commands.index(b) for b in before if b in commands) + 1, command)
    return [*commands, README_TABLES] if commands else []


def regenerate(commands: list[str], root: Path = REPO, jobs: int = 1) -> None:
    """Run the commands at the repository's top, `jobs` at a time in the plan's order, the README's
    tables (the plan's last) after all the others. They may share a document (write_section
    locks it) and a build (the co-simulation's and synthesis' caches lock theirs). With more
    than one job each command's output goes to build/regenerate/<k>.log. The first failure
    stops the commands not yet started; those running are waited for."""
    *others, last = commands if commands and commands[-1] == README_TABLES else (*commands, None)
    logs = root / "build" / "regenerate"
    running: dict[subprocess.Popen, tuple[int, str, float]] = {}
    queue = list(enumerate(others, 1))
    if jobs > 1:  # the longest first, so that the last to finish is a short one
        queue.sort(key=lambda item: -MINUTES.get(item[1], 0))
    failed = None
    while queue or running:
        while len(running) < max(1, jobs) and failed is None:
            waiting = {c for _, c in queue} | {c for _, c, _ in running.values()}
            ready = [item for item in queue if not any(b in waiting for b in AFTER.get(item[1], ()))]
            if not ready:
                break
            k, command = ready[0]
            queue.remove(ready[0])
            print(f"evclust.stamps: [{k}/{len(commands)}] {command}", flush=True)
            out = None
            if jobs > 1:
                logs.mkdir(parents=True, exist_ok=True)
                out = open(logs / f"{k}.log", "w")
            running[subprocess.Popen(command, shell=True, cwd=root, stdout=out, stderr=out)] = (k, command, time.monotonic())
            if out is not None:
                out.close()  # the child has its own copy of the file
        if failed is not None and not running:
            break
        for process in _ended(running):  # all that ended, so that a failure is seen before the next start
            k, command, start = running.pop(process)
            took = time.monotonic() - start
            print(f"evclust.stamps: [{k}/{len(commands)}] done in {took:.0f} s (exit status {process.returncode})", flush=True)
            if process.returncode != 0 and failed is None:
                failed = (command, process.returncode, k)
    if failed is not None:
        command, code, k = failed
        not_run = [c for _, c in queue] + ([last] if last else [])
        where = f"; see {logs / f'{k}.log'}" if jobs > 1 else ""
        left = f"; not run: {', '.join(not_run)}" if not_run else ""
        raise EvclustError(f"`{command}` failed (exit status {code}){where}{left}")
    if last:
        print(f"evclust.stamps: [{len(commands)}/{len(commands)}] {last}", flush=True)
        done = subprocess.run(last, shell=True, cwd=root)
        if done.returncode != 0:
            raise EvclustError(f"`{last}` failed (exit status {done.returncode})")


def _ended(running) -> list[subprocess.Popen]:
    """The running commands that have ended, once at least one has."""
    while True:
        ended = [process for process in running if process.poll() is not None]
        if ended:
            return ended
        time.sleep(0.5)


def stamp_document(doc: Document, values: dict[str, str] | None = None, root: Path = REPO) -> None:
    """Add or refresh a document's stamp in place, nothing else."""
    path = root / doc.path
    text = path.read_text()
    if doc.start is None:
        path.write_text(stamped(doc, text, stamp_line(doc, values)))
        return
    if doc.start not in text or doc.end not in text:
        raise EvclustError(f"{path}: no {doc.start} ... {doc.end} section to stamp")
    head, rest = text.split(doc.start, 1)
    section, tail = rest.split(doc.end, 1)
    path.write_text(head + stamped(doc, doc.start + section, stamp_line(doc, values)) + doc.end + tail)


def _content(doc: Document, text: str) -> str | None:
    """The document (or its section) without its stamp: what its generator wrote."""
    if doc.start is not None:
        if doc.start not in text or doc.end not in text:
            return None
        text = doc.start + text.split(doc.start, 1)[1].split(doc.end, 1)[0]
    return "\n".join(line for line in text.split("\n") if not STAMP_RE.fullmatch(line))


def vouch(doc: Document, commit: str, root: Path = REPO) -> dict[str, str]:
    """The document's inputs' fingerprints if it is as it was at `commit` (where it was made) and
    each input's fingerprint is the same at `commit` as now; otherwise a one-line refusal."""
    then_text = Files(commit, root).read(doc.path).decode()
    if _content(doc, then_text) is None or _content(doc, then_text) != _content(doc, (root / doc.path).read_text()):
        raise EvclustError(f"{doc.name}: {doc.path} is not as it was at {commit}: it was not made there, or was edited since")
    now = fingerprints(doc.inputs)
    for name in sorted(doc.inputs, key=lambda n: n in ("simulator", "float")):  # the probes last: they cost most
        try:
            then = fingerprints((name,), commit)[name]
        except EvclustError as exc:
            raise EvclustError(f"{doc.name}: {exc}; regenerate it with {doc.target}") from None
        if then != now[name]:
            raise EvclustError(f"{doc.name}: {name} changed since {commit}; regenerate it with {doc.target}")
    return now


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m evclust.stamps", description=__doc__.split("\n\n")[0])
    ap.add_argument("--stamp", metavar="NAME", choices=sorted(BY_NAME), help="stamp this document without regenerating it")
    ap.add_argument("--made-at", metavar="COMMIT", help="the commit at which the document was generated (required with --stamp)")
    ap.add_argument("--plan", action="store_true", help="print the commands that regenerate every stale document, each once")
    ap.add_argument("--regenerate", action="store_true", help="run them (an RTL change: about two and a half hours on 2 cores)")
    ap.add_argument("--jobs", type=int, default=1, help="with --regenerate: commands at a time (output to build/regenerate/<k>.log)")
    args = ap.parse_args(argv)
    try:
        if args.plan or args.regenerate:
            commands = regeneration_plan([doc for doc, _ in stale()])
            if not commands:
                print("every document is current")
                return 0
            if args.plan:
                print("\n".join(commands))
                return 0
            regenerate(commands, jobs=args.jobs)
            left = check()
            print("\n".join(left or ["every document is current"]))
            return 1 if left else 0
        if args.stamp:
            if not args.made_at:
                ap.error("--stamp needs --made-at COMMIT: the commit whose inputs the document was made from")
            doc = BY_NAME[args.stamp]
            commit = subprocess.run(["git", "rev-parse", "--short=12", args.made_at], cwd=REPO, capture_output=True, text=True,
                                    check=True).stdout.strip()  # fmt: skip
            values = vouch(doc, commit)
            stamp_document(doc, values)
            print(f"{doc.path} ({doc.name}): stamped; its inputs ({', '.join(doc.inputs)}) are the same now as at {commit}")
            return 0
        current = fingerprints()
        print(" ".join(f"{k}={v}" for k, v in current.items()))
        for line in check(current=current) or ["every document is current"]:
            print(line)
        return 0
    except (EvclustError, subprocess.CalledProcessError) as exc:
        print(f"evclust.stamps: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())

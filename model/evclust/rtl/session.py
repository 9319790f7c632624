"""The RTL as a clusterer model (`evclust track --model rtl`): the same interface as the float and
fixed models (feed events, get record rows back), with the events going through evclust_core
under Verilator.

The simulator runs the cocotb test `serve` (evclust.rtl.harness) in a thread of
this process's making; the two sides talk over a pair of named pipes, one line per batch: this
side writes a batch of event words to an .npy file and its path to the request pipe, the
testbench streams it through the core and answers with the path of the record words. An empty
line ends the session, and the testbench answers with the status counters.
"""

from __future__ import annotations

import json
import os
import tempfile
import threading
from pathlib import Path

import numpy as np

from evclust.clusterer.layout import OBJECT_RECORD_COLUMNS
from evclust.errors import EvclustError
from evclust.fixed.header import verilog_header
from evclust.fixed.model import FixedClusterer
from evclust.rtl.sources import require_rtl_semantics
from evclust.vectors.pack import event_words, object_rows, record_rows

SIMULATOR = "verilator"  # the fast one; `make cosim SIM=icarus` covers the other


class RtlClusterer:
    """evclust_core built for these parameters, fed batch by batch."""

    model = "rtl"
    feed_size = 1 << 15  # events per batch: the progress bar moves every second or so

    def __init__(self, params, width: int, height: int, t_frame_us: float, has_colour: bool = True, sim: str = SIMULATOR):
        from evclust.rtl.cosim import build, run

        if not has_colour:
            raise EvclustError("--model rtl: the RTL clusters colour events; this stream has none (use --model fixed)")
        require_rtl_semantics(params)
        # The fixed model gives the build: its formats table is the RTL's header.
        self.table = FixedClusterer(params, width, height, t_frame_us).table
        self.params = params.resolved(t_frame_us)
        header = verilog_header(self.table)
        build(sim, header)  # before the session's clock starts: a build takes seconds
        self._dir = Path(tempfile.mkdtemp(prefix="evclust-rtl-"))
        self._requests, self._answers = self._dir / "requests", self._dir / "answers"
        os.mkfifo(self._requests)
        os.mkfifo(self._answers)
        config = {"requests": str(self._requests), "answers": str(self._answers), "n_clusters": self.params.n_clusters,
                  "filter_every": self.params.filter_every}  # fmt: skip
        self._failure: BaseException | None = None

        def serve():
            try:
                run(sim, header, "serve", config)
            except BaseException as exc:  # reported by the next feed or stats
                self._failure = exc
                self._unblock()

        self._thread = threading.Thread(target=serve, name="evclust-rtl", daemon=True)
        self._thread.start()
        self._send = open(self._requests, "w")
        self._receive = open(self._answers)
        self._batch = 0
        self._counters: dict | None = None
        self.steps = np.zeros(0, np.int64)  # (the object unit needs no step times: it has the core's)
        self._objects = np.zeros((0, OBJECT_RECORD_COLUMNS))  # the object unit's records of the last batch

    def _unblock(self) -> None:
        # The simulator died: open the pipes' other ends so that this side's open/readline returns.
        for path, mode in ((self._requests, os.O_RDONLY), (self._answers, os.O_WRONLY)):
            try:
                os.close(os.open(path, mode | os.O_NONBLOCK))
            except OSError:
                pass

    def _answer(self) -> str:
        line = self._receive.readline()
        if not line:
            raise EvclustError(f"--model rtl: the simulation ended early: {self._failure or 'no answer'}")
        return line.strip()

    def feed(self, events: np.ndarray) -> np.ndarray:
        """Record rows (as the fixed model's) of the filter steps these events complete."""
        path = self._dir / f"batch-{self._batch}.npy"
        self._batch += 1
        np.save(path, np.array([str(w) for w in event_words(events, self.table)]))
        self._send.write(f"{path}\n")
        self._send.flush()
        answer, object_answer = (Path(p) for p in self._answer().split())
        words = np.load(answer).tolist()
        object_words = np.load(object_answer).tolist()
        answer.unlink()
        object_answer.unlink()
        path.unlink()
        rows = self._whole_time(record_rows(words, self.table), events)
        self._objects = self._whole_time(object_rows(object_words, self.table), events)
        return rows

    @staticmethod
    def _whole_time(rows: np.ndarray, events: np.ndarray) -> np.ndarray:
        """The RTL's records hold the time's low 32 bits; their event is of this batch or just
        before, so the whole time is the latest event's minus their difference mod 2^32."""
        if rows.size and events.size:
            latest = int(events["t"][-1])
            low = rows[:, 0].astype(np.int64)
            rows[:, 0] = latest - ((latest - low) & 0xFFFFFFFF)
        return rows

    def object_layer(self) -> RtlObjects:
        """The object unit's records of each batch, as the other models' object layers give theirs."""
        return RtlObjects(self)

    def stats(self) -> dict:
        """The status counters read from the register file; ends the session."""
        if self._counters is None:
            self._send.write("\n")
            self._send.flush()
            self._counters = json.loads(self._answer())
            self._send.close()
            self._receive.close()
            self._thread.join()
            for path in self._dir.iterdir():
                path.unlink()
            self._dir.rmdir()
        c = self._counters
        saturations = {name[4:]: c[name] for name in c if name.startswith("sat_") and c[name]}
        return {"events": c["events"], "steps": c["events"] // self.params.filter_every, "created": c["creates"], "evicted": c["evictions"], "dropped": c["drops"],
                "expired": c["expiries"], "exited": c["exits"], "merged": c["merges"], "unsupported": c["unsupported"],
                "saturations": saturations, "counters": c}  # fmt: skip


class RtlObjects:
    """The RTL's object unit as an object layer: its records of the last batch fed to the core."""

    def __init__(self, rtl: RtlClusterer):
        self.rtl = rtl

    def feed(self, rows: np.ndarray, steps: np.ndarray) -> np.ndarray:
        return self.rtl._objects

    def stats(self) -> dict:
        return {}

"""The RTL as a clusterer model (`evclust track --model rtl`): the same interface as the float and
fixed models (feed events, get record rows back), with the events going through evclust_core
under Verilator.

The simulator runs the cocotb test `serve` (tb/evclust_core/test_evclust_core.py) in a thread of
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

from evclust.errors import EvclustError
from evclust.fixed.formats import verilog_header
from evclust.fixed.model import FixedClusterer
from evclust.vectors.pack import event_words, record_rows

SIMULATOR = "verilator"  # the fast one; `make cosim SIM=icarus` covers the other


class RtlClusterer:
    """evclust_core built for these parameters, fed batch by batch."""

    model = "rtl"
    feed_size = 1 << 15  # events per batch: the progress bar moves every second or so

    def __init__(self, params, width: int, height: int, t_frame_us: float, has_colour: bool = True, sim: str = SIMULATOR):
        from evclust.rtl.cosim import build, run

        if not has_colour:
            raise EvclustError("--model rtl: the RTL clusters colour events; this stream has none (use --model fixed)")
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
        answer = Path(self._answer())
        words = np.load(answer).tolist()
        answer.unlink()
        path.unlink()
        rows = record_rows(words, self.table)
        if rows.size and events.size:
            # The RTL's record holds the time's low 32 bits; its event is of this batch or just
            # before, so the whole time is the latest event's minus their difference mod 2^32.
            latest = int(events["t"][-1])
            low = rows[:, 0].astype(np.int64)
            rows[:, 0] = latest - ((latest - low) & 0xFFFFFFFF)
        return rows

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

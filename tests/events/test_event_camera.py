"""Event-camera files (AEDAT4, EVT2/EVT3) against second libraries and the EVT3 word layout.

Each round trip compares t, x, y and p bit for bit with a library that is not the one evclust
reads and writes through (faery): dv-processing (iniVation's own) for AEDAT4, the aedat decoder,
evlib for EVT, and EVT3 words packed here by hand from Prophesee's format description.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta, EventReader, event_writer, read_events, sort_events, write_events

W, H = 346, 260  # a DAVIS346's sensor
META = EventMeta(width=W, height=H, source="unit", t_frame_us=20000.0)


def camera_events(n=5000, seed=1, t0=1_700_000_000_000_000):
    """DVS events as a camera gives them: absolute µs timestamps (Unix epoch), many ties."""
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, EVENT_DTYPE)
    ev["t"] = t0 + np.sort(rng.integers(0, 200_000, n)).astype(np.uint64)
    ev["x"] = rng.integers(0, W, n)
    ev["y"] = rng.integers(0, H, n)
    ev["p"] = rng.choice([-1, 1], n)
    return sort_events(ev)


def assert_dvs_equal(got_t, got_x, got_y, got_p, ev):
    assert np.array_equal(np.asarray(got_t, np.uint64), ev["t"])
    assert np.array_equal(np.asarray(got_x, np.int64), ev["x"].astype(np.int64))
    assert np.array_equal(np.asarray(got_y, np.int64), ev["y"].astype(np.int64))
    assert np.array_equal(np.asarray(got_p, np.int64), ev["p"].astype(np.int64))


def test_aedat4_written_by_dv_processing_reads_bit_exact(tmp_path):
    dv = pytest.importorskip("dv_processing", reason="dv-processing is a test dependency")
    ev = camera_events()
    path = tmp_path / "dv.aedat4"
    writer = dv.io.MonoCameraWriter(str(path), dv.io.MonoCameraWriter.EventOnlyConfig("DAVIS346_unit", (W, H)))
    store = dv.EventStore()
    for t, x, y, p in zip(ev["t"].tolist(), ev["x"].tolist(), ev["y"].tolist(), ev["p"].tolist()):
        store.push_back(t, x, y, p > 0)
    writer.writeEvents(store)
    del writer  # closes the file
    got, meta = read_events(path)
    assert (meta.width, meta.height, meta.has_colour) == (W, H, False)
    assert_dvs_equal(got["t"], got["x"], got["y"], got["p"], ev)
    assert not got["Y"].any() and not got["Cb"].any() and not got["Cr"].any()


def test_aedat4_written_here_reads_bit_exact_in_dv_processing_and_aedat(tmp_path):
    dv = pytest.importorskip("dv_processing", reason="dv-processing is a test dependency")
    aedat = pytest.importorskip("aedat", reason="aedat is a test dependency")
    ev = camera_events(seed=2)
    path = tmp_path / "ours.aedat4"
    write_events(path, ev, META)

    recording = dv.io.MonoCameraRecording(str(path))
    assert tuple(recording.getEventResolution()) == (W, H)
    batches = []
    while (batch := recording.getNextEventBatch()) is not None:
        batches.append(batch.numpy())
    dv_ev = np.concatenate(batches)
    assert_dvs_equal(dv_ev["timestamp"], dv_ev["x"], dv_ev["y"], np.where(dv_ev["polarity"], 1, -1), ev)

    packets = [p["events"] for p in aedat.Decoder(str(path)) if "events" in p]
    ae = np.concatenate(packets)
    assert_dvs_equal(ae["t"], ae["x"], ae["y"], np.where(ae["on"], 1, -1), ev)


def test_aedat4_keeps_the_metadata_evclust_wrote(tmp_path):
    path = tmp_path / "m.aedat4"
    write_events(path, camera_events(n=10), META)
    reader = EventReader(path)
    assert reader.count == 10
    assert (reader.meta.source, reader.meta.t_frame_us, reader.meta.has_colour) == ("unit", 20000.0, False)


@pytest.mark.parametrize("version, evlib_name", [("evt3", "EVT3"), ("evt2", "EVT2")])
def test_evt_written_here_reads_bit_exact_in_evlib(tmp_path, version, evlib_name):
    evlib = pytest.importorskip("evlib", reason="evlib is a test dependency")
    ev = camera_events(seed=3, t0=123_456)  # EVT stores time from the recording's start
    path = tmp_path / "ours.raw"
    write_events(path, ev, META, evt_version=version)
    assert evlib.detect_format(str(path))[0] == evlib_name
    df = evlib.load_events(str(path), sort=False).collect()
    t_us = df["t"].dt.total_microseconds().to_numpy()
    assert_dvs_equal(t_us, df["x"].to_numpy(), df["y"].to_numpy(), df["polarity"].to_numpy(), ev)
    back, meta = read_events(path)  # and back through faery
    assert (meta.width, meta.height) == (W, H) and np.array_equal(back, ev)


def _evt3_words(events):
    """EVT3 16-bit words, packed from the format description: TIME_HIGH (0x8) and TIME_LOW (0x6)
    carry t's upper and lower 12 bits, EVT_ADDR_Y (0x0) the row, EVT_ADDR_X (0x2) the column
    with the polarity in bit 11."""
    words = []
    for t, x, y, p in events:
        words += [(0x8 << 12) | (t >> 12) & 0xFFF, (0x6 << 12) | t & 0xFFF, (0x0 << 12) | y, (0x2 << 12) | (int(p > 0) << 11) | x]
    return struct.pack(f"<{len(words)}H", *words)


def test_evt3_packed_by_hand_reads_as_packed_with_ties_put_in_order(tmp_path):
    # Readout order: within t = 5000 the camera sends row 7 before row 3; SPEC §2 wants y then x.
    packed = [(4095, 10, 3, 1), (5000, 200, 7, -1), (5000, 20, 3, 1), (5000, 5, 3, -1), (70000, 345, 259, 1)]
    path = tmp_path / "hand.raw"
    path.write_bytes(f"% evt 3.0\n% format EVT3;width={W};height={H}\n% end\n".encode() + _evt3_words(packed))
    got, meta = read_events(path)
    assert (meta.width, meta.height, meta.has_colour) == (W, H, False)
    want = [(4095, 10, 3, 1), (5000, 5, 3, -1), (5000, 20, 3, 1), (5000, 200, 7, -1), (70000, 345, 259, 1)]
    assert list(zip(got["t"].tolist(), got["x"].tolist(), got["y"].tolist(), got["p"].tolist())) == want


@pytest.mark.parametrize("suffix", [".aedat4", ".raw", ".h5", ".npz"])
def test_chunked_reading_gives_the_whole_stream(tmp_path, suffix):
    ev = camera_events(n=3000, seed=4, t0=0)
    path = tmp_path / f"c{suffix}"
    with event_writer(path, META) as writer:  # written in uneven chunks
        for lo, hi in ((0, 1), (1, 1000), (1000, 1000), (1000, 3000)):
            writer.write(ev[lo:hi])
    chunks = list(EventReader(path).chunks(size=256))
    assert len(chunks) > 3 and all(c.size for c in chunks)
    got = np.concatenate(chunks)
    fields = ("t", "x", "y", "p") if suffix in (".aedat4", ".raw") else EVENT_DTYPE.names
    for name in fields:
        assert np.array_equal(got[name], ev[name]), name


def test_colour_is_dropped_writing_a_camera_format(tmp_path):
    ev = camera_events(n=50, t0=0)
    ev["Y"] = 200
    path = tmp_path / "c.aedat4"
    write_events(path, ev, META)
    got, meta = read_events(path)
    assert not meta.has_colour and not got["Y"].any()


@pytest.mark.parametrize(
    "content, fault",
    [
        (b"garbage" * 50, "not a readable event-camera file"),
        (b"#!AER-DAT4.0\r\n\x00\x00", "not a readable event-camera file"),
    ],
)
def test_malformed_aedat4_fails_with_one_line(tmp_path, content, fault):
    path = tmp_path / "bad.aedat4"
    path.write_bytes(content)
    with pytest.raises(EvclustError) as err:
        read_events(path)
    assert str(err.value).startswith(str(path)) and fault in str(err.value) and "\n" not in str(err.value)


def test_evt3_outside_its_declared_sensor_is_refused(tmp_path):
    path = tmp_path / "big.raw"
    path.write_bytes(b"% evt 3.0\n% format EVT3;width=64;height=48\n% end\n" + _evt3_words([(10, 100, 3, 1)]))
    with pytest.raises(EvclustError, match=r"big.raw: not a readable event-camera file \(x overflow \(x=100"):
        read_events(path)


def test_a_stream_going_back_in_time_is_refused_and_no_file_is_left(tmp_path):
    ev = camera_events(n=20, t0=0)
    path = tmp_path / "out.aedat4"
    with pytest.raises(EvclustError, match=r"record 10: t=.* is before the previous"):
        with event_writer(path, META) as writer:
            writer.write(ev[10:])
            writer.write(ev[:10])
    assert list(tmp_path.iterdir()) == []

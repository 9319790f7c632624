"""Event files: round trips, DVS-only files, and one clear line for every fault."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta, read_events, sort_events, write_events

META = EventMeta(width=32, height=24, source="unit", t_frame_us=40000.0)


def some_events(n=200, seed=0):
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, EVENT_DTYPE)
    ev["t"] = np.sort(rng.integers(0, 10**6, n))
    ev["x"] = rng.integers(0, 32, n)
    ev["y"] = rng.integers(0, 24, n)
    ev["p"] = rng.choice([-1, 1], n)
    for name in ("Y", "Cb", "Cr"):
        ev[name] = rng.integers(0, 256, n)
    return sort_events(ev)


@pytest.mark.parametrize("suffix", [".npz", ".h5", ".hdf5"])
def test_round_trip_keeps_every_field_and_the_metadata(tmp_path, suffix):
    ev = some_events()
    path = tmp_path / f"ev{suffix}"
    write_events(path, ev, META)
    back, meta = read_events(path)
    assert back.dtype == EVENT_DTYPE and np.array_equal(back, ev)
    assert meta == META


def test_dvs_only_hdf5_reads_with_colour_off(tmp_path):
    ev = some_events()
    path = tmp_path / "dvs.h5"
    with h5py.File(path, "w") as f:
        for name in ("t", "x", "y", "p"):
            f.create_dataset(f"events/{name}", data=ev[name])
        f.attrs["width"], f.attrs["height"] = 32, 24
    back, meta = read_events(path)
    assert not meta.has_colour and np.array_equal(back["t"], ev["t"]) and not back["Y"].any()


def test_sort_orders_ties_by_y_then_x():
    ev = np.zeros(4, EVENT_DTYPE)
    ev["t"] = [5, 5, 5, 1]
    ev["y"] = [2, 1, 1, 9]
    ev["x"] = [0, 7, 3, 9]
    got = sort_events(ev)
    assert list(zip(got["t"], got["y"], got["x"])) == [(1, 9, 9), (5, 1, 3), (5, 1, 7), (5, 2, 0)]


def _broken(field, index, value):
    ev = some_events()
    ev[field][index] = value
    return ev


@pytest.mark.parametrize(
    "events, fault",
    [
        (_broken("t", 50, 0), "record 50: t=0 us is before the previous"),
        (_broken("x", 7, 32), "record 7: x=32 is outside the 32x24 sensor"),
        (_broken("y", 9, 400), "record 9: y=400 is outside"),
        (_broken("p", 3, 0), "record 3: polarity 0"),
    ],
)
@pytest.mark.parametrize("suffix", [".npz", ".h5"])
def test_faulty_streams_are_refused_naming_file_record_and_fault(tmp_path, events, fault, suffix):
    path = tmp_path / f"bad{suffix}"
    # Written without validation, as a foreign tool would.
    if suffix == ".npz":
        np.savez(path, events=events, meta=np.array(META.to_json()))
    else:
        with h5py.File(path, "w") as f:
            for name in EVENT_DTYPE.names:
                f.create_dataset(f"events/{name}", data=events[name])
            f.attrs["width"], f.attrs["height"] = META.width, META.height
    with pytest.raises(EvclustError) as err:
        read_events(path)
    assert str(err.value).startswith(str(path)) and fault in str(err.value) and "\n" not in str(err.value)


def test_ties_out_of_order_are_refused(tmp_path):
    ev = np.zeros(2, EVENT_DTYPE)
    ev["t"], ev["y"], ev["p"] = [3, 3], [5, 1], [1, 1]
    path = tmp_path / "ties.npz"
    np.savez(path, events=ev, meta=np.array(META.to_json()))
    with pytest.raises(EvclustError, match="record 1: events at the same t=3 us are not ordered by y then x"):
        read_events(path)


@pytest.mark.parametrize(
    "make, fault",
    [
        (lambda p: p.write_bytes(b"not a zip file at all"), "not a readable event file"),
        (lambda p: np.savez(p, other=np.zeros(3)), "no 'events' array"),
        (lambda p: np.savez(p, events=np.zeros(3)), "not a structured array"),
        (
            lambda p: np.savez(p, events=np.zeros(3, [("t", "u8"), ("x", "u2")]), meta=np.array(META.to_json())),
            "missing event field(s) y, p",
        ),
        (
            lambda p: np.savez(
                p, events=np.zeros(3, [("t", "u8"), ("x", "u2"), ("y", "u2"), ("p", "i1"), ("q", "u1")]), meta=np.array(META.to_json())
            ),
            "unknown event field(s) q",
        ),
        (
            lambda p: np.savez(p, events=np.zeros(3, [("t", "f8"), ("x", "u2"), ("y", "u2"), ("p", "i1")]), meta=np.array(META.to_json())),
            "field t has type float64",
        ),
        (lambda p: np.savez(p, events=some_events()), "the file gives no sensor size: give it with --sensor-size WxH"),
    ],
)
def test_malformed_files_fail_with_one_line(tmp_path, make, fault):
    path = tmp_path / "x.npz"
    make(path)
    with pytest.raises(EvclustError) as err:
        read_events(path)
    assert fault in str(err.value) and "\n" not in str(err.value)


def test_unknown_suffix_and_missing_file(tmp_path):
    with pytest.raises(EvclustError, match="unknown event file type '.evt'"):
        read_events(tmp_path / "x.evt")
    with pytest.raises(EvclustError, match="no such event file"):
        read_events(tmp_path / "absent.npz")


def test_a_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def half_write(f, **arrays):
        f.write(b"PK partial")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savez", half_write)
    with pytest.raises(OSError):
        write_events(tmp_path / "out.npz", some_events(), META)
    assert list(tmp_path.iterdir()) == []


def test_writing_records_of_another_dtype_is_refused(tmp_path):
    with pytest.raises(EvclustError, match="records of dtype .* are not events"):
        write_events(tmp_path / "out.npz", np.zeros(3, [("t", "u8")]), META)
    assert list(tmp_path.iterdir()) == []

"""DAT, Event Stream, AEDAT 2.0 and text event files: round trips, second readers, hostile files.

Second readers: faery's stream API (its own y flip) for .es, faery's CSV decoder for .txt and
.csv, and bytes packed here by hand from the format descriptions (Prophesee's DAT page, jAER's
DVS128 extractor) for .dat and .aedat: known events, so count, first and last are analytic.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest

from evclust.errors import EvclustError
from evclust.events import EVENT_DTYPE, EventMeta, EventReader, read_events, sort_events, write_events

W, H = 120, 90
META = EventMeta(width=W, height=H, source="unit", t_frame_us=20000.0)


def events(n=2000, seed=5, w=W, h=H, t0=0):
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, EVENT_DTYPE)
    ev["t"] = t0 + np.sort(rng.integers(0, 500_000, n)).astype(np.uint64)
    ev["x"] = rng.integers(0, w, n)
    ev["y"] = rng.integers(0, h, n)
    ev["p"] = rng.choice([-1, 1], n)
    return sort_events(ev)


def dvs(ev):
    return list(zip(ev["t"].tolist(), ev["x"].tolist(), ev["y"].tolist(), ev["p"].tolist()))


def one_line(exc_info, *fragments):
    text = str(exc_info.value)
    assert "\n" not in text, text
    for fragment in fragments:
        assert fragment in text, (fragment, text)


@pytest.mark.parametrize("suffix, size", [(".dat", None), (".es", None), (".txt", (W, H)), (".csv", (W, H))])
def test_round_trip_is_exact(tmp_path, suffix, size):
    ev = events()
    path = tmp_path / f"e{suffix}"
    write_events(path, ev, META)
    back, meta = read_events(path, sensor_size=size)
    assert (meta.width, meta.height, meta.has_colour) == (W, H, False)
    assert dvs(back) == dvs(ev)


def test_aedat2_round_trip_on_a_dvs128(tmp_path):
    ev = events(w=128, h=128)
    path = tmp_path / "e.aedat"
    write_events(path, ev, EventMeta(width=128, height=128, source="unit"))
    back, meta = read_events(path)
    assert (meta.width, meta.height) == (128, 128) and dvs(back) == dvs(ev)


# ------------------------------------------------------------------------------------------------
# DAT


def _dat_bytes(packed, header=b"% Data file containing CD events\n% Version 2\n% Width 64\n% Height 48\n"):
    """DAT 2 CD events from Prophesee's description: type 0x0C, size 8, then per event a 32-bit t
    and a 32-bit word with x in bits 0-13, y in 14-27 and the polarity in 28-31."""
    body = b"".join(struct.pack("<II", t, (p << 28) | (y << 14) | x) for t, x, y, p in packed)
    return header + bytes([0x0C, 8]) + body


def test_dat_packed_by_hand_reads_as_packed(tmp_path):
    packed = [(5, 0, 0, 1), (7, 63, 47, 0), (7, 2, 47, 1), (4_000_000_000, 10, 20, 0)]
    path = tmp_path / "hand.dat"
    path.write_bytes(_dat_bytes(packed))
    got, meta = read_events(path)
    assert (meta.width, meta.height) == (64, 48)
    assert dvs(got) == [(5, 0, 0, 1), (7, 2, 47, 1), (7, 63, 47, -1), (4_000_000_000, 10, 20, -1)]  # ties put in y, x order


def test_dat_written_here_has_the_described_layout(tmp_path):
    ev = events(n=50)
    path = tmp_path / "e.dat"
    write_events(path, ev, META)
    data = path.read_bytes()
    body = data[data.index(b"% Height 90\n") + len(b"% Height 90\n") :]
    assert body[:2] == bytes([0x0C, 8])
    words = np.frombuffer(body[2:], dtype=[("t", "<u4"), ("w", "<u4")])
    assert words.size == ev.size and np.array_equal(words["t"], ev["t"])
    assert np.array_equal(words["w"] & 0x3FFF, ev["x"]) and np.array_equal((words["w"] >> 14) & 0x3FFF, ev["y"])
    assert np.array_equal(words["w"] >> 28, (ev["p"] > 0).astype(np.uint32))


def test_dat_without_a_size_needs_sensor_size_and_is_checked_against_it(tmp_path):
    path = tmp_path / "nosize.dat"
    path.write_bytes(_dat_bytes([(5, 10, 3, 1), (9, 70, 3, 1)], header=b"% Version 2\n"))
    with pytest.raises(EvclustError) as err:
        read_events(path)
    one_line(err, "nosize.dat", "no sensor size", "--sensor-size WxH")
    got, meta = read_events(path, sensor_size=(80, 4))
    assert (meta.width, meta.height) == (80, 4) and dvs(got) == [(5, 10, 3, 1), (9, 70, 3, 1)]
    with pytest.raises(EvclustError) as err:
        read_events(path, sensor_size=(64, 4))
    one_line(err, "record 1: x=70 is outside the 64x4 sensor", "t=9 us, x=70, y=3, p=+1")


def test_dat_refuses_a_stream_past_its_32_bit_clock_and_leaves_no_file(tmp_path):
    ev = events(n=10, t0=(1 << 32) - 100)
    with pytest.raises(EvclustError) as err:
        write_events(tmp_path / "long.dat", ev, META)
    one_line(err, "32-bit")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------------------
# Event Stream


def test_es_written_here_reads_the_same_through_faery_stream_api(tmp_path):
    faery = pytest.importorskip("faery")
    ev = events(seed=6, t0=1_000_000)
    path = tmp_path / "e.es"
    write_events(path, ev, META)
    stream = faery.events_stream_from_file(path)
    assert tuple(stream.dimensions()) == (W, H)
    got = np.concatenate([p for p in stream if len(p)])
    assert dvs(ev) == list(zip(got["t"].tolist(), got["x"].tolist(), got["y"].tolist(), np.where(got["on"], 1, -1).tolist()))


# ------------------------------------------------------------------------------------------------
# AEDAT 2.0


def _aedat2_bytes(records):
    """jAER DVS128 records: big-endian address (bit 0 = 1 for OFF, bits 1-7 the mirrored column,
    bits 8-14 the row from the bottom), big-endian timestamp."""
    header = b"#!AER-DAT2.0\r\n# This is a raw AE data file - do not edit\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n"
    return header + b"".join(struct.pack(">II", address, t) for address, t in records)


def test_aedat2_packed_by_hand_reads_as_jaer_decodes_it(tmp_path):
    # Pixel (column c, row r from the bottom) at address (r << 8) | (c << 1) | off.
    records = [
        ((0 << 8) | (127 << 1) | 0, 10),  # ON, jAER x = 127 - 127 = 0, jAER y = 0 -> row 127 from the top
        (0x8000, 11),  # a sync event: skipped
        ((127 << 8) | (0 << 1) | 1, 12),  # OFF, jAER x = 127, jAER y = 127 -> row 0
        ((5 << 8) | (100 << 1) | 1, 4_294_967_290),
        ((6 << 8) | (101 << 1) | 0, 20),  # the 32-bit clock wrapped
    ]
    path = tmp_path / "hand.aedat"
    path.write_bytes(_aedat2_bytes(records))
    got, meta = read_events(path)
    assert (meta.width, meta.height, meta.has_colour) == (128, 128, False)
    assert dvs(got) == [(10, 0, 127, 1), (12, 127, 0, -1), (4_294_967_290, 27, 122, -1), ((1 << 32) + 20, 26, 121, 1)]


def _aedat31_bytes(packets, header=b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DVS128\r\n#!END-HEADER\r\n", overflow=0):
    """cAER packets from libcaer's common.h and polarity.h: a 28-byte little-endian header, then
    8-byte polarity events (data: bit 0 valid, bit 1 ON, bits 2-16 y, bits 17-31 x; timestamp)."""
    out = header
    for kind, events in packets:
        size = 8
        out += struct.pack("<hhiiiiii", kind, 1, size, 4, overflow, len(events), len(events), len(events))
        out += b"".join(struct.pack("<Ii", data, t) for data, t in events)
    return out


def test_aedat31_packed_by_hand_reads_as_libcaer_decodes_it(tmp_path):
    def pol(x, y, on, valid=1):
        return (x << 17) | (y << 2) | (on << 1) | valid

    packets = [
        (1, [(pol(0, 0, 1), 5), (pol(127, 127, 0), 9), (pol(3, 4, 1, valid=0), 9)]),  # the invalid one is skipped
        (2, [(0x1234, 10)]),  # a frame or special packet: skipped
        (1, [(pol(10, 20, 0), 12)]),
    ]
    path = tmp_path / "cam.aedat"
    path.write_bytes(_aedat31_bytes(packets))
    got, meta = read_events(path)
    assert (meta.width, meta.height, meta.has_colour) == (128, 128, False)
    assert dvs(got) == [(5, 0, 0, 1), (9, 127, 127, -1), (12, 10, 20, -1)]
    wrapped = tmp_path / "wrapped.aedat"
    wrapped.write_bytes(_aedat31_bytes([(1, [(pol(1, 1, 1), 7)])], overflow=2))
    assert dvs(read_events(wrapped)[0]) == [((2 << 31) | 7, 1, 1, 1)]
    unknown = tmp_path / "unknown.aedat"
    unknown.write_bytes(_aedat31_bytes(packets, header=b"#!AER-DAT3.1\r\n#Source 1: Prototype\r\n#!END-HEADER\r\n"))
    with pytest.raises(EvclustError) as err:
        read_events(unknown)
    one_line(err, "unknown.aedat: the file gives no sensor size")
    assert dvs(read_events(unknown, sensor_size=(200, 128))[0]) == dvs(got)


@pytest.mark.parametrize(
    "content, fragments",
    [
        (_aedat2_bytes([(2, 10)]) + b"\x00\x01\x02", ("the last event is cut short (3 of its 8 bytes)",)),
        (b"#!AER-DAT5.0\r\n" + b"\x00" * 28, ("AEDAT '5.0' is not read",)),
        (b"#!AER-DAT3.1\r\n#Source 1: DVS128\r\n" + b"\x00" * 28, ("without its '#!END-HEADER' line",)),
        (_aedat31_bytes([(1, [((3 << 17) | (2 << 2) | 3, 5)])])[:-3], ("ends inside the packet at byte",)),
        (b"not an aedat file at all", ("not an AEDAT file",)),
    ],
)
def test_aedat_hostile_files_are_refused_in_one_line(tmp_path, content, fragments):
    path = tmp_path / "bad.aedat"
    path.write_bytes(content)
    with pytest.raises(EvclustError) as err:
        read_events(path)
    one_line(err, "bad.aedat", *fragments)


def test_aedat_suffix_holding_aedat4_is_read_by_faery(tmp_path):
    ev = events(n=100)
    write_events(tmp_path / "e.aedat4", ev, META)
    (tmp_path / "e.aedat4").rename(tmp_path / "dv.aedat")
    back, meta = read_events(tmp_path / "dv.aedat")
    assert (meta.width, meta.height) == (W, H) and dvs(back) == dvs(ev)


def test_aedat2_writer_refuses_a_sensor_larger_than_the_dvs128(tmp_path):
    with pytest.raises(EvclustError) as err:
        write_events(tmp_path / "big.aedat", events(n=5), EventMeta(width=346, height=260))
    one_line(err, "346x260", "128x128")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "name, word, what",
    [("e.dat", 8, "event"), ("e2.raw", 4, "EVT word"), ("e3.raw", 2, "EVT word")],
)
def test_a_prophesee_file_cut_inside_a_word_is_refused_in_one_line(tmp_path, name, word, what):
    # DAT records are 8 bytes, EVT 2.0 words 4, EVT 3.0 words 2 (Prophesee's format pages); a file
    # whose binary part is not a whole number of them was cut short, however its decoder copes.
    path = tmp_path / name
    write_events(path, events(n=300), META, **({} if name == "e.dat" else {"evt_version": "evt2" if name == "e2.raw" else "evt3"}))
    whole = path.read_bytes()
    assert read_events(path)[0].size == 300
    for cut in range(1, word):
        path.write_bytes(whole[:-cut])
        with pytest.raises(EvclustError) as err:
            read_events(path)
        one_line(err, name, f"ends inside its last {what} ({word - cut} of its {word} bytes)", "truncated")
        assert path.read_bytes() == whole[:-cut]


def test_an_evt3_header_naming_its_version_only_in_its_format_line_is_checked_too(tmp_path):
    # Metavision 4 names the version as '% format EVT3;width=...;height=...' (faery writes that
    # line beside '% evt 3.0'); without the '% evt' line the word size comes from it.
    path = tmp_path / "e.raw"
    write_events(path, events(n=300), META)
    whole = path.read_bytes()
    assert b"% format EVT3;" in whole and b"% evt 3.0\n" in whole
    path.write_bytes(whole.replace(b"% evt 3.0\n", b"", 1)[:-1])
    with pytest.raises(EvclustError) as err:
        read_events(path)
    one_line(err, "e.raw", "ends inside its last EVT word (1 of its 2 bytes)")


# ------------------------------------------------------------------------------------------------
# Text: the Event Camera Dataset's t x y p, and CSV


def test_ecd_text_known_events_with_seconds_rounded_to_the_microsecond(tmp_path):
    path = tmp_path / "events.txt"
    path.write_text("# comment\n0.000000000 33 39 1\n\n0.000011001 158 145 0\n1.5000004 0 0 1\n1468939993.067416019 239 179 0\n")
    got, meta = read_events(path, sensor_size=(240, 180))
    assert (meta.width, meta.height, meta.has_colour) == (240, 180, False)
    assert dvs(got) == [(0, 33, 39, 1), (11, 158, 145, -1), (1_500_000, 0, 0, 1), (1_468_939_993_067_416, 239, 179, -1)]


@pytest.mark.parametrize("suffix", [".txt", ".csv"])
def test_text_written_here_reads_the_same_in_faery_csv_decoder(tmp_path, suffix):
    csv = pytest.importorskip("faery").csv
    ev = events(seed=7)
    path = tmp_path / f"e{suffix}"
    write_events(path, ev, META)
    header, separator, scale = (False, ord(" "), 1e6) if suffix == ".txt" else (True, ord(","), 0.0)
    with csv.Decoder(path, (W, H), header, separator, 0, 1, 2, 3, scale, 0, b"1", b"0", False) as decoder:
        got = np.concatenate(list(decoder))
    assert dvs(ev) == list(zip(got["t"].tolist(), got["x"].tolist(), got["y"].tolist(), np.where(got["on"], 1, -1).tolist()))


def test_csv_columns_found_by_name_in_any_order(tmp_path):
    path = tmp_path / "e.csv"
    path.write_text("polarity, y ,x,timestamp,extra,Y\n1,3,4,100,z,200\n-1,0,7,250,z,10\n")
    got, _ = read_events(path, sensor_size=(8, 4))
    assert dvs(got) == [(100, 4, 3, 1), (250, 7, 0, -1)]
    seconds = tmp_path / "s.csv"
    seconds.write_text("t_s,x,y,on\n0.25,1,1,0\n")
    assert dvs(read_events(seconds, sensor_size=(8, 4))[0]) == [(250_000, 1, 1, -1)]


def test_text_files_that_say_their_size_in_their_own_way_need_no_sensor_size(tmp_path):
    import cv2

    # faery's CSV names the coordinate columns x@W, y@H.
    (tmp_path / "f.csv").write_text("t,x@320,y@240,on\n5,319,239,1\n")
    got, meta = read_events(tmp_path / "f.csv")
    assert (meta.width, meta.height) == (320, 240) and dvs(got) == [(5, 319, 239, 1)]
    # The Event Camera Dataset: images.txt beside events.txt lists the frames; the first one's size is the sensor's.
    (tmp_path / "images").mkdir()
    assert cv2.imwrite(str(tmp_path / "images" / "frame_00000000.png"), np.zeros((180, 240), np.uint8))
    (tmp_path / "images.txt").write_text("0.000000000 images/frame_00000000.png\n")
    (tmp_path / "events.txt").write_text("0.1 239 179 0\n")
    got, meta = read_events(tmp_path / "events.txt")
    assert (meta.width, meta.height) == (240, 180) and dvs(got) == [(100_000, 239, 179, -1)]
    with pytest.raises(EvclustError) as err:
        read_events(tmp_path / "events.txt", sensor_size=(346, 260))
    one_line(err, "--sensor-size 346x260 disagrees with the file's 240x180")
    (tmp_path / "images" / "frame_00000000.png").write_bytes(b"not a picture")
    with pytest.raises(EvclustError) as err:
        read_events(tmp_path / "events.txt")
    one_line(err, "frame_00000000.png", "not a readable image", "--sensor-size")
    (tmp_path / "bad.csv").write_text("t,x@wide,y,p\n1,2,3,1\n")
    with pytest.raises(EvclustError) as err:
        read_events(tmp_path / "bad.csv", sensor_size=(8, 8))
    one_line(err, "bad.csv", "'x@wide'", "not a whole number")


@pytest.mark.parametrize(
    "name, content, options, fragments",
    [
        ("e.txt", "0.1 1 2 1\n0.2 x 2 1\n", {}, ("line 2", "x 'x' is not a number")),
        ("e.txt", "0.1 1 2 1\n0.2 1 2\n", {}, ("line 2", "3 fields, expected at least 4")),
        ("e.txt", "0.1 1 2 1\n# note\n0.2 1 2 2\n", {}, ("line 3", "p=2 is not a polarity")),
        ("e.txt", "0.1 1 2 -1\n", {"polarity": "01"}, ("line 1", "'01' convention")),
        ("e.txt", "0.1 1 2 0\n", {"polarity": "pm1"}, ("line 1", "'pm1' convention")),
        ("e.txt", "-0.5 1 2 1\n", {}, ("line 1", "not a time from 0 on")),
        ("e.txt", "0.1 1 2 1\n0.2 40 2 1\n", {}, ("line 2", "x=40 is outside the 32x24 sensor", "t=200000 us, x=40, y=2")),
        ("e.txt", "0.2 1 2 1\n0.1 1 2 1\n", {}, ("record 1: t=100000 us is before the previous",)),
        ("e.txt", b"0.1 1 2 1\n\xff\xfe\n", {}, ("not a text file",)),
        ("e.csv", "t,x,y\n1,2,3\n", {}, ("line 1", "names no p column", "p pol polarity on")),
        ("e.csv", "t,x,y,p\n1,2,3,1\n2.5,2,3,1\n", {}, ("line 3", "t '2.5' is not a number (whole µs)")),
    ],
)
def test_hostile_text_files_are_refused_in_one_line_naming_the_line(tmp_path, name, content, options, fragments):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(EvclustError) as err:
        read_events(path, sensor_size=(32, 24), **options)
    one_line(err, name, *fragments)


def test_text_without_sensor_size_and_polarity_option_on_a_binary_format(tmp_path):
    path = tmp_path / "events.txt"
    path.write_text("0.1 1 2 1\n")
    with pytest.raises(EvclustError) as err:
        EventReader(path)
    one_line(err, "events.txt: the file gives no sensor size: give it with --sensor-size WxH")
    write_events(tmp_path / "e.dat", events(n=3), META)
    with pytest.raises(EvclustError) as err:
        EventReader(tmp_path / "e.dat", polarity="01")
    one_line(err, "e.dat", "--polarity 01 is for text files")
    with pytest.raises(EvclustError) as err:
        EventReader(tmp_path / "e.dat", sensor_size=(640, 480))
    one_line(err, "--sensor-size 640x480 disagrees with the file's 120x90")


def test_text_is_read_in_chunks_with_line_numbers_carried_across(tmp_path):
    ev = events(n=700)
    path = tmp_path / "e.txt"
    write_events(path, ev, META)
    chunks = list(EventReader(path, sensor_size=(W, H)).chunks(size=256))
    assert len(chunks) == 3 and dvs(np.concatenate(chunks)) == dvs(ev)
    lines = path.read_text().splitlines()
    lines[600] = "0.5 1 2 7"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(EvclustError) as err:
        list(EventReader(path, sensor_size=(W, H)).chunks(size=256))
    one_line(err, "line 601", "p=7")


# ------------------------------------------------------------------------------------------------
# EVT without a size in its header (Prophesee Gen3 and some Gen4 recordings)


def _evt3_nosize(packed):
    words = []
    for t, x, y, p in packed:
        words += [(0x8 << 12) | (t >> 12) & 0xFFF, (0x6 << 12) | t & 0xFFF, y, (0x2 << 12) | (int(p > 0) << 11) | x]
    return b"% evt 3.0\n% end\n" + struct.pack(f"<{len(words)}H", *words)


def test_evt_without_a_size_is_read_with_sensor_size_and_checked_against_it(tmp_path):
    path = tmp_path / "gen3.raw"
    path.write_bytes(_evt3_nosize([(10, 5, 3, 1), (20, 300, 7, -1)]))
    with pytest.raises(EvclustError) as err:
        read_events(path)
    one_line(err, "gen3.raw: the file gives no sensor size: give it with --sensor-size WxH")
    got, meta = read_events(path, sensor_size=(304, 240))
    assert (meta.width, meta.height) == (304, 240) and dvs(got) == [(10, 5, 3, 1), (20, 300, 7, -1)]
    with pytest.raises(EvclustError) as err:
        read_events(path, sensor_size=(240, 180))
    one_line(err, "record 1: x=300 is outside the 240x180 sensor", "t=20 us, x=300, y=7, p=-1")

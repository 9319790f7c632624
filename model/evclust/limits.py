"""Sizes and counts a run accepts before it allocates or starts: bounds against a careless or
hostile input that would otherwise allocate for ever or run for days. Each is a default a user
raises explicitly with an environment variable, EVCLUST_MAX_<NAME>."""

from __future__ import annotations

import os

from evclust.errors import EvclustError

DEFAULTS = {
    "SENSOR_PIXELS": 1 << 25,  # an 8K sensor, 7680 x 4320, fits
    "FRAMES": 10_000_000,  # a day and a half at 80 frames/s
    "OBJECT_AREA": 1 << 25,  # px² of one object of a synthetic scene
}


def limit(name: str) -> int:
    """The bound called `name` (a key of DEFAULTS), or EVCLUST_MAX_<name> where the user set it."""
    variable = f"EVCLUST_MAX_{name}"
    raw = os.environ.get(variable)
    if raw is None:
        return DEFAULTS[name]
    try:
        value = int(raw)
    except ValueError:
        raise EvclustError(f"{variable}={raw!r}: expected a whole number") from None
    if value < 1:
        raise EvclustError(f"{variable}={raw!r}: expected a positive number")
    return value


def check(name: str, value: float, what: str) -> None:
    """EvclustError naming `what` when `value` is over the bound, and how to raise it."""
    bound = limit(name)
    if value > bound:
        raise EvclustError(f"{what}: {value:,.0f} is over the limit of {bound:,} (set EVCLUST_MAX_{name} to allow more)")

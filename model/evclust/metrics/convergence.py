"""How long an estimate takes to settle on a new value (the velocity methods' convergence)."""

from __future__ import annotations

import numpy as np


def converged_after(t_us, estimate, target, tolerance, window):
    """First time after which the estimate, averaged over `window` records, stays within
    `tolerance`·|target| of `target`; None if it never does."""
    kernel = np.ones(window) / window
    smooth = np.stack([np.convolve(estimate[:, j], kernel, mode="valid") for j in range(2)], 1)
    t_us = t_us[window - 1 :]
    bad = np.linalg.norm(smooth - target, axis=1) > tolerance * np.linalg.norm(target)
    if bad.size == 0 or bad[-1]:
        return None
    last_bad = np.flatnonzero(bad)
    return t_us[0] if last_bad.size == 0 else t_us[last_bad[-1] + 1]

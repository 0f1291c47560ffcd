"""The white noise on a smooth signal, from its high-order differences (robust to a few outliers and kinks)."""
from __future__ import annotations

import math

import numpy as np

#: Orders of the differences and the variance each multiplies white noise by: ``C(2k, k)``.
ORDERS = ((2, 6.0), (3, 20.0), (4, 70.0))


def white_noise_sd(x: np.ndarray) -> float:
    """Standard deviation of the white noise on a smooth signal ``x`` (n,): the smallest of the robust estimates
    ``1.4826 MAD(diff^k x) / sqrt(C(2k, k))`` for k = 2, 3, 4 (0 when ``x`` is too short)."""
    x = np.asarray(x, float)
    best = math.inf
    for k, norm in ORDERS:
        if x.size > k + 4:
            d = np.diff(x, k)
            best = min(best, 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(norm))
    return best if math.isfinite(best) else 0.0

"""The white noise on a smooth signal, from its high-order differences (robust to a few outliers and kinks)."""
from __future__ import annotations

import math

import numpy as np

#: Orders of the differences and the variance each multiplies white noise by: ``C(2k, k)``.
ORDERS = ((2, 6.0), (3, 20.0), (4, 70.0))
#: Share of rows that repeat the row before to the bit from which a signal whose differences read no noise is taken
#: as read in steps of a resolution (a load cell logged to 0.01 N, its noise a few mN: most rows repeat the last).
REPEATS_QUANTIZED = 0.1
#: ... and that changes in at least this many rows (a signal without noise that holds a value, then steps to another,
#: is not read in steps: it has no noise to read).
QUANTIZED_MOVES = 10


def white_noise_sd(x: np.ndarray) -> float:
    """Standard deviation of the white noise on a smooth signal ``x`` (n,): the smallest of the robust estimates
    ``1.4826 MAD(diff^k x) / sqrt(C(2k, k))`` for k = 2, 3, 4 (0 when ``x`` is too short).

    A signal read in steps coarser than its noise (a load cell logged to 0.01 N with a few mN of noise) mostly
    repeats its last reading, and those estimates read 0. There (the estimate 0, and at least
    :data:`REPEATS_QUANTIZED` of the rows repeating the row before, and :data:`QUANTIZED_MOVES` rows changing) the
    reading's own error is the noise: uniform within half a step either side, ``q / sqrt(12)`` for the step ``q`` (the
    smallest change between rows). A signal without noise that does not repeat (a ramp), or that holds its values and
    steps between them a few times, still reads 0."""
    x = np.asarray(x, float)
    best = math.inf
    for k, norm in ORDERS:
        if x.size > k + 4:
            d = np.diff(x, k)
            best = min(best, 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(norm))
    if not math.isfinite(best):
        return 0.0
    if best == 0.0:
        d1 = np.diff(x)
        moves = np.abs(d1[d1 != 0.0])
        if moves.size >= QUANTIZED_MOVES and np.mean(d1 == 0.0) >= REPEATS_QUANTIZED:
            return float(moves.min()) / math.sqrt(12.0)
    return best

"""The monotone cubic interpolant (Fritsch-Carlson, the PCHIP of Fritsch & Butland
1984) of the rotor's table: C1, no overshoot, and its local extrema only at the
table's rows, so the table's largest Cp is the curve's (rotor.py)."""

from __future__ import annotations

import numpy as np


def _slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The derivative at each row: 0 where the data turns or is flat, else the
    weighted harmonic mean of the neighbouring secants; the ends by the shape-
    preserving three-point formula."""
    h = np.diff(x)
    delta = np.diff(y) / h
    d = np.zeros_like(y)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    same = delta[:-1] * delta[1:] > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    d[1:-1] = np.where(same, mean, 0.0)
    d[0] = _end(h[0], h[1], delta[0], delta[1])
    d[-1] = _end(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end(h0: float, h1: float, m0: float, m1: float) -> float:
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3 * m0):
        return 3 * m0
    return d


class Pchip:
    """y(x) through the rows (x strictly increasing, at least 3 rows); ``__call__``
    and :meth:`derivative` take x inside [x[0], x[-1]] (the caller refuses others)."""

    def __init__(self, x, y):
        self.x, self.y = np.asarray(x, float), np.asarray(y, float)
        self.d = _slopes(self.x, self.y)

    def _piece(self, x):
        x = np.asarray(x, float)
        i = np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, len(self.x) - 2)
        h = self.x[i + 1] - self.x[i]
        return x, i, h, (x - self.x[i]) / h

    def __call__(self, x):
        x, i, h, t = self._piece(x)
        h00, h10 = (1 + 2 * t) * (1 - t) ** 2, t * (1 - t) ** 2
        h01, h11 = t * t * (3 - 2 * t), t * t * (t - 1)
        return (h00 * self.y[i] + h10 * h * self.d[i] + h01 * self.y[i + 1]
                + h11 * h * self.d[i + 1])

    def derivative(self, x):
        x, i, h, t = self._piece(x)
        d00, d10 = 6 * t * (t - 1) / h, (1 - t) * (1 - 3 * t)
        d01, d11 = -6 * t * (t - 1) / h, t * (3 * t - 2)
        return d00 * self.y[i] + d10 * self.d[i] + d01 * self.y[i + 1] + d11 * self.d[i + 1]

"""The designs of a study: one row of parameter values per run.

``grid``: every combination of ``count`` equally spaced values per parameter (the first
parameter varies slowest). ``random``: ``count`` designs uniform within the bounds.
``lhs``: a Latin hypercube of ``count`` designs (each parameter's range cut into
``count`` equal strata, one design in each, the strata paired at random). Random and LHS
designs come from NumPy's PCG64 generator seeded with the study's ``seed``: the same
study gives the same designs on every machine.
"""

from __future__ import annotations

import itertools

import numpy as np

from .studyfile import Sampling

__all__ = ["designs"]


def _grid(lows: np.ndarray, highs: np.ndarray, count: int) -> np.ndarray:
    axes = [
        np.linspace(lo, hi, count) if count > 1 else np.array([lo])
        for lo, hi in zip(lows, highs, strict=True)
    ]
    return np.array(list(itertools.product(*axes)), dtype=float)


def _random(
    lows: np.ndarray, highs: np.ndarray, count: int, rng: np.random.Generator
) -> np.ndarray:
    return lows + (highs - lows) * rng.random((count, len(lows)))


def _lhs(lows: np.ndarray, highs: np.ndarray, count: int, rng: np.random.Generator) -> np.ndarray:
    u = np.empty((count, len(lows)))
    for j in range(len(lows)):
        u[:, j] = (rng.permutation(count) + rng.random(count)) / count
    return lows + (highs - lows) * u


def designs(sampling: Sampling, lows: list[float], highs: list[float]) -> np.ndarray:
    """The (designs x parameters) values of a sampling within [lows, highs]."""
    lo, hi = np.asarray(lows, dtype=float), np.asarray(highs, dtype=float)
    if sampling.method == "grid":
        return _grid(lo, hi, sampling.count)
    rng = np.random.Generator(np.random.PCG64(sampling.seed))
    return _DRAWN[sampling.method](lo, hi, sampling.count, rng)


_DRAWN = {"random": _random, "lhs": _lhs}

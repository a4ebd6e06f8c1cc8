"""The figures of a run from its series: peak, RMS, mean, min, max, the fluctuation
(max - min) / mean, the drop (max - min) / max, and the work per revolution (the
integral of the series over the crank angle, per revolution: a torque's energy per
cycle). The fluctuation is defined for a series with a positive mean (a speed), the
drop for one with a positive maximum; elsewhere the run's row says so.

Each series is sampled at the run's points (kinetostatic: equally spaced crank angles
over one revolution; driven: the communication points from ``settle`` on). RMS and mean
are over the samples for a kinetostatic run (equal angle steps) and over time for a
driven one (equal time steps): each is the average the run's own grid gives.
"""

from __future__ import annotations

import math

import numpy as np

from .studyfile import Figure

__all__ = ["figure_value", "series_names", "UndefinedFigure"]


def _series(figure: Figure, series: dict) -> np.ndarray:
    if len(figure.of) == 1:
        return series[figure.of[0]]
    return np.hypot(series[figure.of[0]], series[figure.of[1]])


class UndefinedFigure(ValueError):
    """A figure that has no value over its series (a fluctuation about a mean that is
    not positive, say)."""


def _fluctuation(v: np.ndarray, phi: np.ndarray | None) -> float:
    mean = float(np.mean(v))
    if not mean > 0:
        raise UndefinedFigure(f"fluctuation needs a series with a positive mean (mean {mean:.6g})")
    return float((np.max(v) - np.min(v)) / mean)


def _drop(v: np.ndarray, phi: np.ndarray | None) -> float:
    top = float(np.max(v))
    if not top > 0:
        raise UndefinedFigure(f"drop needs a series whose maximum is positive (max {top:.6g})")
    return float((top - np.min(v)) / top)


def _work_per_revolution(v: np.ndarray, phi: np.ndarray | None) -> float:
    if phi is None:  # one revolution at equally spaced angles: the periodic mean
        return float(np.mean(v)) * 2 * math.pi
    turned = abs(phi[-1] - phi[0])
    if not turned > 0:
        return math.nan
    area = float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(phi)))
    return area * 2 * math.pi / turned


_STATS = {
    "peak": lambda v, phi: float(np.max(np.abs(v))),
    "rms": lambda v, phi: float(np.sqrt(np.mean(v * v))),
    "mean": lambda v, phi: float(np.mean(v)),
    "min": lambda v, phi: float(np.min(v)),
    "max": lambda v, phi: float(np.max(v)),
    "fluctuation": _fluctuation,
    "drop": _drop,
    "work_per_revolution": _work_per_revolution,
}


def figure_value(figure: Figure, series: dict, phi: np.ndarray | None) -> float:
    """The figure of one run; ``phi`` is the unwrapped crank angle (rad) at the samples,
    None for one revolution at equally spaced angles. UndefinedFigure where the figure
    has no value over this series."""
    return _STATS[figure.stat](_series(figure, series), phi)


def series_names(figures: tuple) -> tuple:
    """Every series the figures read, in a fixed order."""
    return tuple(dict.fromkeys(n for f in figures for n in f.of))

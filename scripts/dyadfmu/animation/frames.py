"""The frames of an animation: the mechanism as drawn at each instant of a run (a pose of
:func:`dyadfmu.report.drivers_drawing.pose`, from the FMU's outputs and inputs at that
instant), the reason where the run has no answer, and the curves shown beside it.

A curve is an output of the FMU, or a pair reaction's magnitude (``slot.R_mk`` for the
outputs ``slot.R_mk.x`` and ``slot.R_mk.y``). By default: every driver's effort and every
pair reaction's magnitude."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..report import drivers_drawing as dd

DrawingError = dd.DrawingError


@dataclass(frozen=True)
class Run:
    """A mechanism FMU's values over a run: the instants (s), at each one every output and
    input by name (None where there is no answer) and the reason where there is none, and
    one line saying where it comes from."""

    times: np.ndarray
    rows: list
    reasons: list
    source: str

    def __post_init__(self) -> None:
        if not len(self.times) == len(self.rows) == len(self.reasons):
            raise ValueError("a run needs as many rows and reasons as instants")


@dataclass(frozen=True)
class Curve:
    """A curve beside the mechanism: its name, unit and value at each instant (NaN where
    the run has no answer)."""

    name: str
    unit: str
    values: np.ndarray


@dataclass(frozen=True)
class Frames:
    """Everything an animation shows: the run, a pose per instant (None where the run
    has no answer), each point's label, each body's colour, the curves, the drivers'
    efforts (outputs), coordinates (inputs) and the pair positions drawn (outputs)."""

    identifier: str
    run: Run
    poses: list
    labels: dict
    colours: dict
    curves: tuple
    efforts: tuple
    coordinates: tuple
    positions: tuple

    @property
    def answered(self) -> list[int]:
        """The instants with a pose."""
        return [k for k, p in enumerate(self.poses) if p is not None]


def _units(mechanism: dd.Mechanism) -> dict:
    return {v.name: v.unit or "" for v in mechanism.slave.md.modelVariables}


def reaction_names(mechanism: dd.Mechanism) -> list[str]:
    """Every pair reaction the FMU outputs as .x and .y (``crank.R_O``, ``slot.R_mk``)."""
    reals = set(mechanism.reals)
    stems = [n[:-2] for n in mechanism.reals if n.endswith(".x") and ".R_" in n]
    return [s for s in stems if f"{s}.y" in reals]


def curve_names(mechanism: dd.Mechanism) -> list[str]:
    """What a curve can show: every Real output and every pair reaction's magnitude."""
    return [*reaction_names(mechanism), *mechanism.reals]


def _curve(mechanism: dd.Mechanism, run: Run, name: str, units: dict) -> Curve:
    def value(row: dict | None) -> float:
        if row is None:
            return math.nan
        if name in units:
            return float(row[name])
        return math.hypot(row[f"{name}.x"], row[f"{name}.y"])

    unit = units.get(name, units.get(f"{name}.x", ""))
    return Curve(name, unit, np.array([value(r) for r in run.rows]))


def curves(mechanism: dd.Mechanism, run: Run, names: list | None) -> tuple:
    """The curves ``names`` (by default every driver's effort and every pair reaction's
    magnitude the run holds); a DrawingError naming one the FMU has not, or the run."""
    known = curve_names(mechanism)
    held = set(next(r for r in run.rows if r is not None))
    reactions = [n for n in reaction_names(mechanism) if f"{n}.x" in held and f"{n}.y" in held]
    chosen = names or [d.effort for d in mechanism.scene.drivers] + reactions
    for name in chosen:
        if name not in known:
            raise DrawingError(
                f"--curve {name}: not an output of {mechanism.path.name} nor a pair reaction "
                f"(its reactions: {', '.join(reaction_names(mechanism)) or 'none'})"
            )
        if name not in held and name not in reactions:
            raise DrawingError(f"--curve {name}: not in {run.source}")
    units = {n: u for n, u in _units(mechanism).items() if n in mechanism.reals}
    return tuple(_curve(mechanism, run, n, units) for n in dict.fromkeys(chosen))


def frames(mechanism: dd.Mechanism, run: Run, names: list | None = None) -> Frames:
    """The run's frames: a pose of every instant with an answer, each cylinder's barrel
    drawn at a fixed length over the run."""
    rows = [r for r in run.rows if r is not None]
    if not rows:
        raise DrawingError(f"no instant of {run.source} has an answer: {run.reasons[0]}")
    coordinates = [{d.input(0): r[d.input(0)] for d in mechanism.scene.drivers} for r in rows]
    lengths = dd.barrels(mechanism, coordinates)
    span = float(run.times[-1] - run.times[0]) or 1.0
    poses = [
        None if row is None else dd.pose(mechanism, row, lengths, float(t - run.times[0]) / span)
        for t, row in zip(run.times, run.rows, strict=True)
    ]
    first = next(p for p in poses if p is not None)
    return Frames(
        identifier=mechanism.scene.identifier,
        run=run,
        poses=poses,
        labels=dd.point_labels(first, mechanism.scene),
        colours=dd.body_colours(mechanism.scene),
        curves=curves(mechanism, run, names),
        efforts=tuple(d.effort for d in mechanism.scene.drivers),
        coordinates=tuple(d.input(0) for d in mechanism.scene.drivers),
        positions=tuple(
            f"{n[:-2]}.{axis}"
            for n in mechanism.drawn_outputs()
            if n.endswith(".position.x")
            for axis in "xy"
        ),
    )

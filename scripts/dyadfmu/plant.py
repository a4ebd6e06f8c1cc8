"""A plant over a time grid in one call: ``dyadfmu.forward(fmu, time, inputs)``.

A plant is an FMU of a scene with ``dynamics = "forward"`` (modelDescription/scenes/
README.md, "Plants"): the drivers' efforts (or a motor's voltage) and the loads in, the
motion integrated inside each ``doStep``, every output at the state reached. ``forward``
instantiates it, holds each input law over each communication step (its value at the
step's start) or, with ``interpolate=True`` (FMI 2), follows it linearly between the grid's
points, and returns every output at every communication point as NumPy arrays.
Where the motion has no answer (a toggle, a chain that stops assembling) the plant stops
at the last point that has one: the trajectory ends there and says why.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import paths
from .fmi.slave import Slave, SlaveError

__all__ = ["Trajectory", "forward"]

#: An input law: a number, a function of time (s), or one value per point of the grid.
Law = float | Callable[[float], float] | np.ndarray

_DISCARD = 2


@dataclass
class Trajectory:
    """The plant's outputs at the communication points it reached, and its inputs there
    (a law's value at that point; where the run stopped, the value the plant had there:
    held, the step's start value; interpolated, the line's value at the stop).

    ``trajectory["crank.angle"]`` is an output's (or an input's) array, one value per
    point of ``time``; ``units`` gives each one's unit ("" where it has none).
    ``stopped`` is None if the run reached the grid's end, else why it stopped earlier
    (``time[-1]`` is then where the plant's motion last had an answer)."""

    time: np.ndarray
    values: dict[str, np.ndarray]
    units: dict[str, str]
    stopped: str | None = None
    names: list[str] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.values:
            raise KeyError(f"{name!r} is not among the trajectory's variables: {self.names}")
        return self.values[name]


def forward(
    fmu: str | Path,
    time: np.ndarray | list,
    inputs: Mapping[str, Law] | None = None,
    parameters: Mapping[str, float] | None = None,
    *,
    version: int = 3,
    progress: Callable[[float], None] | None = None,
    interpolate: bool = False,
) -> Trajectory:
    """Runs a plant over the communication points `time` (s, increasing, from the start).

    `fmu` is a built plant's identifier (``"slider_crank_motor"``: build/fmus/, FMI
    `version` 2 or 3) or the path of a .fmu. `inputs` maps input names to laws: a
    number, a function of t, or an array with one value per point of `time`; each is held
    over a step at its value at the step's start, or with `interpolate` (FMI 2 only: its
    input derivatives) followed along the line to its value at the step's end, which the
    plant integrates exactly (a law linear over each step, an array's polyline, is then
    the input itself; a smooth one is second order in the step instead of first); an
    input left out keeps its start value. `parameters` are set before initialisation (the
    states' ``*_start``, the tolerances ``solver.rtol`` and ``solver.atol``, a motor's
    numbers). `progress`, if given, is called with the time reached after every step.

    Raises ValueError naming the bad argument; FileNotFoundError if the FMU is not built;
    dyadfmu.fmi.slave.SlaveError if the FMU refuses a call (its message says why)."""
    path = Path(fmu) if Path(str(fmu)).suffix == ".fmu" else paths.built_fmu(str(fmu), version)
    grid = _grid(time)
    slave = Slave(path, label=path.stem)
    try:
        _check_plant(slave)
        if interpolate and slave.version != 2:
            raise ValueError(
                f"interpolate: {path.name} is an FMI {slave.version} FMU; following an input "
                "between the points takes FMI 2's input derivatives (version=2)"
            )
        laws = _laws(slave, grid, dict(inputs or {}), interpolate)
        _check_parameters(slave, dict(parameters or {}))
        return _run(slave, grid, laws, dict(parameters or {}), progress, interpolate)
    finally:
        slave.close()


def _grid(time: np.ndarray | list) -> np.ndarray:
    grid = np.asarray(time, dtype=float)
    if grid.ndim != 1 or grid.size < 2:
        raise ValueError(f"time: a 1-D grid of at least 2 points is needed, got shape {grid.shape}")
    if not np.all(np.isfinite(grid)):
        raise ValueError(f"time: not finite at index {int(np.argmin(np.isfinite(grid)))}")
    steps = np.diff(grid)
    if np.any(steps <= 0):
        k = int(np.argmin(steps > 0))
        raise ValueError(f"time: not increasing from time[{k}] = {grid[k]} to {grid[k + 1]} s")
    return grid


def _check_plant(slave: Slave) -> None:
    if "solver.rtol" not in slave.names:
        raise ValueError(
            f"{slave.path.name} is not a plant: forward() runs the FMU of a scene with "
            'dynamics = "forward" (one that integrates its motion: it has solver.rtol)'
        )


def _causality(slave: Slave, causality: str) -> list[str]:
    return [v.name for v in slave.md.modelVariables if v.causality == causality]


def _laws(slave: Slave, grid: np.ndarray, inputs: dict, interpolate: bool) -> dict[str, np.ndarray]:
    """Each input's values at the grid's points (the last one unused where held)."""
    known = _causality(slave, "input")
    laws = {}
    for name, law in inputs.items():
        if name not in known:
            raise ValueError(f"inputs: {name!r} is not an input of {slave.path.name}: {known}")
        laws[name] = _values(name, law, grid, interpolate)
    return laws


def _values(name: str, law: Law, grid: np.ndarray, interpolate: bool = False) -> np.ndarray:
    if callable(law):
        values = np.array([float(law(float(t))) for t in grid])
    else:
        values = np.asarray(law, dtype=float)
        if values.ndim == 0:
            values = np.full(grid.shape, float(values))
        if values.shape != grid.shape:
            raise ValueError(
                f"inputs[{name!r}]: one value per point of time ({grid.size}) is needed, "
                f"got shape {values.shape}"
            )
    bad = ~np.isfinite(values if interpolate else values[:-1])
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"inputs[{name!r}] is {values[k]} at t = {grid[k]} s")
    if interpolate:
        with np.errstate(over="ignore"):
            steep = ~np.isfinite(np.diff(values) / np.diff(grid))
        if np.any(steep):
            k = int(np.argmax(steep))
            raise ValueError(
                f"inputs[{name!r}]: its rate from t = {grid[k]} to {grid[k + 1]} s overflows double"
            )
    return values


def _check_parameters(slave: Slave, parameters: dict) -> None:
    known = _causality(slave, "parameter")
    for name in parameters:
        if name not in known:
            raise ValueError(
                f"parameters: {name!r} is not a parameter of {slave.path.name}: {known}"
            )


def _run(
    slave: Slave,
    grid: np.ndarray,
    laws: dict[str, np.ndarray],
    parameters: dict,
    progress: Callable[[float], None] | None,
    interpolate: bool = False,
) -> Trajectory:
    reals = tuple(
        v.name
        for v in slave.md.modelVariables
        if v.causality in ("input", "output") and slave.types[v.name] in ("Real", "Float64")
    )
    names = tuple(laws)
    rows, times, stopped = [], [], None
    if names:
        slave.set(names, [laws[n][0] for n in names])
    slave.initialize(parameters, start_time=float(grid[0]))
    times.append(float(grid[0]))
    rows.append(_row(slave, reals))
    for k in range(grid.size - 1):
        if names:
            slave.set(names, [laws[n][k] for n in names])
        if names and interpolate:
            h = grid[k + 1] - grid[k]
            slave.set_rates(names, [(laws[n][k + 1] - laws[n][k]) / h for n in names])
        try:
            slave.do_step(float(grid[k]), float(grid[k + 1] - grid[k]))
        except SlaveError as e:
            if e.status != _DISCARD:
                raise
            stopped = e.message or str(e)
            times.append(_last_successful_time(slave))
            rows.append(_row(slave, reals))
            break
        times.append(float(grid[k + 1]))
        rows.append(_row(slave, reals))
        if progress is not None:
            progress(float(grid[k + 1]))
    table = np.array(rows)
    values = {n: table[:, j] for j, n in enumerate(reals)}
    held = np.arange(len(times))  # the law's point that holds at each row
    if stopped is not None:
        held[-1] -= 1  # inside the step that stopped
    for name, law in laws.items():
        values[name] = law[held]
        if stopped is not None and interpolate:  # where the line had come to
            k = held[-1]
            share = (times[-1] - grid[k]) / (grid[k + 1] - grid[k])
            values[name][-1] = law[k] + share * (law[k + 1] - law[k])
    if "status" in slave.names:
        values["status"] = table[:, -1]
    units = {v.name: v.unit or "" for v in slave.md.modelVariables if v.name in values}
    return Trajectory(np.array(times), values, units, stopped, list(values))


def _row(slave: Slave, reals: tuple) -> list:
    row = list(slave.get(reals))
    if "status" in slave.names:
        row.append(float(slave.get_status()))
    return row


def _last_successful_time(slave: Slave) -> float:
    """Where a discarded step stopped (FMI 2: fmi2LastSuccessfulTime; FMI 3: the time)."""
    if slave.version == 2:
        last_successful_time = 2  # fmi2StatusKind fmi2LastSuccessfulTime
        return float(slave.fmu.getRealStatus(last_successful_time))
    (time,) = _causality(slave, "independent")
    return float(slave.fmu.getFloat64([slave.vr[time]])[0])

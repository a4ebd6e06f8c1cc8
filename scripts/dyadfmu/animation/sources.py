"""Where an animation's run comes from (each a :class:`.frames.Run`):

- :func:`motion_law`: a scene's mechanism FMU driven by a motion law: each ranged driver
  moves at a constant rate from its min to its max (by default the first crank one turn)
  over a duration, the others at their start values, the loads at their start values;
- :func:`harness`: a shipped mechanism FMU over the harness's own motion of its driver
  (:func:`dyadfmu.cosim.mechanism_fmus.setup`: constant or varying speed), run with
  :func:`dyadfmu.fmi.rows.run_table`, so that each row holds the inputs and outputs of
  one instant;
- :func:`recorded`: a CSV file of a run in any simulator (fmpy's ``write_csv``, ``dyadfmu
  rows``), with a time column, the pair positions and the drivers' coordinates (inputs;
  the loads are 0 where not recorded). A row whose ``status`` column is not 0 is an
  instant with no answer; a file without the columns the drawing needs, with NaN in rows
  that claim an answer, or of another FMU is refused in one line saying what is missing.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..report import cylinder_drawing as cd
from ..report import drivers_drawing as dd
from .frames import DrawingError, Run


def motion_law(mechanism: dd.Mechanism, ranges: dict, duration: float, count: int) -> Run:
    """``count`` instants over ``duration`` s of the drivers' motion over ``ranges``
    (input -> (min, max)), at constant rates; an instant without an answer keeps why."""
    shares = np.linspace(0.0, 1.0, count)
    speeds = dd.rates(ranges, duration) if mechanism.rated else None
    rows, reasons = dd.evaluate(mechanism, ranges, shares, cd.loads_given(mechanism, None), speeds)
    moved = ", ".join(f"{n} from {lo:.4g} to {hi:.4g}" for n, (lo, hi) in ranges.items())
    return Run(shares * duration, rows, reasons, f"{moved} at a constant rate in {duration:g} s")


def harness(name: str, fmi: int, motion: str, revolutions: float, count: int) -> tuple:
    """The shipped mechanism FMU ``name`` over the harness's motion of its driver:
    (its scene file, its FMU, the recorded columns)."""
    from ..cosim import mechanism_fmus
    from ..fmi.rows import run_table

    steps = max(int(round((count - 1) / revolutions)), 4)
    co, _, _ = mechanism_fmus.setup(name, fmi, motion=motion, revolutions=revolutions, steps=steps)
    rows = run_table(co.path, {"time": co.time, **co.inputs}, start_values=co.start_values)
    columns = {n: np.asarray(rows.table[n], dtype=float) for n in rows.table.dtype.names}
    return mechanism_fmus.scene_file(name), co.path, columns


def read_csv(path: Path) -> dict:
    """The columns of a CSV file with a header row of names (name -> values)."""
    from fmpy.util import read_csv as fmpy_read_csv

    try:
        table = fmpy_read_csv(str(path))
    except Exception as e:  # fmpy raises whatever numpy does on a malformed file
        raise DrawingError(f"{path}: not a CSV table with a header row of names ({e})") from None
    if table.dtype.names is None or table.ndim != 1:
        raise DrawingError(f"{path}: not a CSV table with a header row of names")
    return {n: np.atleast_1d(np.asarray(table[n], dtype=float)) for n in table.dtype.names}


def _listed(names: list, most: int = 3) -> str:
    more = len(names) - most
    return ", ".join(names[:most]) + (f" and {more} more" if more > 0 else "")


def _check_columns(mechanism: dd.Mechanism, columns: dict, where: str) -> list:
    """The columns the drawing needs, all there; a DrawingError saying which are missing."""
    variables = set(mechanism.reals) | set(mechanism.inputs)
    if "time" not in columns:
        raise DrawingError(f"{where}: no column 'time'")
    if not variables & set(columns):
        raise DrawingError(
            f"{where} is not a recording of {mechanism.path.name}: none of its columns "
            f"({_listed(sorted(set(columns) - {'time'}))}) is a variable of it"
        )
    outputs = [n for n in mechanism.drawn_outputs() if n.endswith(".position.x")]
    positions = [f"{n[:-2]}.{axis}" for n in outputs for axis in "xy"]
    missing = [n for n in positions if n not in columns]
    if missing:
        raise DrawingError(
            f"{where} has no pair positions of {mechanism.scene.identifier} "
            f"({_listed(missing)}): record the FMU's outputs"
        )
    drivers = [d.input(0) for d in mechanism.scene.drivers]
    missing = [n for n in [*drivers, *mechanism.drawn_outputs()] if n not in columns]
    if missing:
        kind = "input" if missing[0] in drivers else "output"
        raise DrawingError(
            f"{where} has no {_listed(missing)} (the FMU's {kind}): record every input and "
            "output ('dyadfmu rows' does)"
        )
    return positions + drivers + mechanism.drawn_outputs()


def _check_rows(columns: dict, needed: list, where: str) -> np.ndarray:
    """Which rows have an answer (status 0, or no status column); a DrawingError for the
    first row with NaN that claims one, or for a time that does not increase."""
    time = columns["time"]
    if len(time) < 2 or not np.all(np.isfinite(time)) or np.any(np.diff(time) <= 0):
        raise DrawingError(f"{where}: the times must be at least two finite, increasing values")
    status = columns.get("status", np.zeros_like(time))
    answered = status == 0
    nan = np.column_stack([np.isnan(columns[n]) for n in needed])
    wrong = np.flatnonzero(answered & nan.any(axis=1))
    if len(wrong):
        k = int(wrong[0])
        name = needed[int(np.flatnonzero(nan[k])[0])]
        raise DrawingError(
            f"{where}: {len(wrong)} rows with NaN and status 0 (the first on line {k + 2}, "
            f"t = {time[k]:.6g} s, in {name})"
        )
    return answered


def recorded(mechanism: dd.Mechanism, columns: dict, where: str) -> Run:
    """The run of a recording's columns (name -> values) of the mechanism's FMU; the loads
    not recorded are 0."""
    needed = _check_columns(mechanism, columns, where)
    answered = _check_rows(columns, needed, where)
    loads = dict.fromkeys(mechanism.load_inputs(), 0.0)
    status = columns.get("status")
    rows, reasons = [], []
    for k, ok in enumerate(answered):
        if ok:
            rows.append({**loads, **{n: float(v[k]) for n, v in columns.items()}})
            reasons.append(None)
        else:
            rows.append(None)
            reasons.append(f"status {status[k]:g} in the recording")
    return Run(columns["time"], rows, reasons, f"{where}, {len(rows)} rows")


def one_turn(scene: dd.DriversScene, mechanism: dd.Mechanism | None = None) -> dict:
    """The first crank's turn from its start angle (the FMU's, given the mechanism):
    {input: (start, start + 2 pi)}; a DrawingError where the scene has no crank."""
    crank = next((d for d in scene.drivers if d.kind == "crank"), None)
    if crank is None:
        raise DrawingError(
            f"{scene.path.name}: no crank to turn; give the motion with --range INPUT MIN MAX"
        )
    start = float(mechanism.coordinates()[crank.input(0)]) if mechanism else 0.0
    return {crank.input(0): (start, start + 2.0 * math.pi)}

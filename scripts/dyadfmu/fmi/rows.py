"""An FMU run over a table of inputs whose every row holds the inputs and the outputs of one
instant.

fmpy's ``simulate_fmu`` sets the inputs at t, steps to t + h and reads the outputs there:
an algebraic FMU's row t + h then holds the outputs of the inputs of t, and its first two
rows are equal. :func:`run_table` sets the inputs of t, reads the outputs (an algebraic
FMU evaluates them from those inputs, a plant from its state at t and those inputs),
records both, and only then steps to the next row's time. Inputs are held over each step
(a plant integrates with them constant), as fmpy holds them.
"""

from __future__ import annotations

import math
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .slave import Slave, SlaveError, unpacked

__all__ = ["Rows", "RowsError", "run_table", "default_grid"]

#: The variable types read as integers (FMI 2, FMI 3).
_INTEGER_TYPES = ("Integer", "Int32", "Enumeration", "Int64")


class RowsError(ValueError):
    """A table the FMU cannot run (the message names the column or the row), or a step the
    FMU refused; ``rows`` holds what was recorded before it (None before the first row)."""

    def __init__(self, message: str, rows: Rows | None = None) -> None:
        super().__init__(message)
        self.rows = rows


@dataclass
class Rows:
    """The recorded run: ``table`` a structured array (``time``, every input, then the
    chosen outputs, as fmpy returns it) and ``units`` (column -> unit, "" where none).
    Indexing and ``len`` go to the table."""

    table: np.ndarray
    units: dict = field(default_factory=dict)

    def __getitem__(self, key: object) -> object:
        return self.table[key]

    def __len__(self) -> int:
        return len(self.table)

    @property
    def names(self) -> tuple:
        """The columns, ``time`` first."""
        return self.table.dtype.names


def default_grid(path: Path | str) -> np.ndarray:
    """The communication points of the FMU's DefaultExperiment (start to stop by step)."""
    md = unpacked(path)[0]
    run = md.defaultExperiment
    start = float(run.startTime or 0.0)
    stop, step = float(run.stopTime or 1.0), float(run.stepSize or 1.0e-3)
    count = int(round((stop - start) / step))
    return start + step * np.arange(count + 1)


def _columns(table: object) -> dict:
    """name -> 1-d float array of a structured array or a mapping of columns."""
    if isinstance(table, np.ndarray) and table.dtype.names:
        given = {n: table[n] for n in table.dtype.names}
    elif isinstance(table, Mapping):
        given = {str(n): v for n, v in table.items()}
    else:
        raise RowsError(
            "the input table must be a structured array or a mapping of columns, "
            f"not {type(table).__name__}"
        )
    columns = {}
    for name, values in given.items():
        try:
            columns[name] = np.atleast_1d(np.asarray(values, dtype=float))
        except (TypeError, ValueError):
            raise RowsError(f"column '{name}' is not numbers") from None
    return columns


def _checked_time(columns: dict) -> np.ndarray:
    if "time" not in columns:
        raise RowsError(f"the input table has no 'time' column (its columns: {_listed(columns)})")
    time = columns["time"]
    if time.ndim != 1 or len(time) == 0:
        raise RowsError("the input table's 'time' must be a column of at least one value (s)")
    for row, t in enumerate(time):
        if not math.isfinite(t):
            raise RowsError(f"the input table's 'time' in row {row} is {t}, not a finite time")
        if row and not t > time[row - 1]:
            raise RowsError(
                f"the input table's 'time' must increase: row {row} is {t:.17g} s after "
                f"{time[row - 1]:.17g} s"
            )
    return time


def _listed(names: object) -> str:
    names = list(names)
    return ", ".join(names[:12]) + (f" and {len(names) - 12} more" if len(names) > 12 else "")


def _checked_inputs(slave: Slave, columns: dict, length: int) -> dict:
    """The table's columns but time, each an input or a tunable parameter of the FMU."""
    settable = [
        v.name
        for v in slave.md.modelVariables
        if v.causality == "input" or (v.causality == "parameter" and v.variability == "tunable")
    ]
    given = {n: c for n, c in columns.items() if n != "time"}
    for name, column in given.items():
        if name not in settable:
            raise RowsError(
                f"column '{name}' is not an input or a tunable parameter of "
                f"{slave.path.name}; they are: {_listed(settable)}"
            )
        if column.shape != (length,):
            raise RowsError(f"column '{name}' has {column.size} values, 'time' has {length}")
    return given


def _chosen_outputs(slave: Slave, outputs: list | None) -> list:
    found = [v.name for v in slave.md.modelVariables if v.causality == "output"]
    if outputs is None:
        return found
    for name in outputs:
        if name not in slave.names:
            raise RowsError(f"'{name}' is not a variable of {slave.path.name}")
    return list(outputs)


def _reader(slave: Slave, names: list):
    """A function that reads the named variables as floats, Reals in one call."""
    integers = [n for n in names if slave.types.get(n) in _INTEGER_TYPES]
    reals = tuple(n for n in names if n not in integers)
    at = {n: k for k, n in enumerate(names)}

    def read() -> np.ndarray:
        values = np.empty(len(names))
        if reals:
            values[[at[n] for n in reals]] = slave.get(reals)
        for n in integers:
            values[at[n]] = slave.get(n)
        return values

    return read


def run_table(
    fmu: Path | str,
    inputs: object = None,
    outputs: list | None = None,
    start_values: dict | None = None,
) -> Rows:
    """Run an FMU (FMI 2 or 3 co-simulation) over a table of inputs; every row holds the
    time, every input of the FMU and the outputs, all of the same instant.

    ``inputs``: a structured array (fmpy's form) or a mapping of columns, with ``time``
    (s, increasing) and any of the FMU's inputs and tunable parameters; an input not given
    keeps its start value. None runs the DefaultExperiment's grid on the start values.
    ``outputs``: names to record (default: every output). ``start_values``: parameters.
    Raises :class:`RowsError` naming a bad column or row, or the time and reason of a step
    the FMU refused (with the rows before it)."""
    try:
        slave = Slave(fmu)
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, SlaveError) as exc:
        raise RowsError(f"{fmu}: not an FMU that loads here ({exc})") from None
    try:
        return _run(slave, inputs, outputs, start_values)
    finally:
        slave.close()


def _run(slave: Slave, inputs: object, outputs: list | None, start_values: dict | None) -> Rows:
    columns = _columns(inputs) if inputs is not None else {"time": default_grid(slave.path)}
    time = _checked_time(columns)
    given = _checked_inputs(slave, columns, len(time))
    recorded = [v.name for v in slave.md.modelVariables if v.causality == "input"]
    recorded += [n for n in given if n not in recorded]
    chosen = [n for n in _chosen_outputs(slave, outputs) if n not in recorded]
    names = ["time", *recorded, *chosen]
    table = np.full(len(time), np.nan, dtype=[(n, float) for n in names])
    read = _reader(slave, names[1:])
    for name in start_values or {}:
        if name not in slave.names:
            raise RowsError(f"start value of '{name}': not a variable of {slave.path.name}")
    try:
        slave.initialize(start_values, start_time=float(time[0]))
    except SlaveError as exc:
        raise RowsError(f"{slave.path.name} refused to initialise: {exc}") from None
    for row, t in enumerate(time):
        try:
            if row:
                slave.do_step(float(time[row - 1]), float(t) - float(time[row - 1]))
            if given:
                slave.set(tuple(given), [c[row] for c in given.values()])
        except SlaveError as exc:
            done = Rows(table[:row].copy(), _units(slave, names))
            raise RowsError(f"at t = {t:.9g} s (row {row}): {exc}", done) from None
        table[row] = (float(t), *read())
    return Rows(table, _units(slave, names))


def _units(slave: Slave, names: list) -> dict:
    unit = {v.name: v.unit or "" for v in slave.md.modelVariables}
    return {n: "s" if n == "time" else unit.get(n, "") for n in names}

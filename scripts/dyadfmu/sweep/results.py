"""A study's results: one row per design (its index, parameter values, figures, the
digits its reactions keep, status and the FMU's message), the best feasible designs by
the objective, and the Pareto front of the objective against a constraint's figure.
Written as CSV (text, every number to 17 significant digits).

A design is feasible where its status is ``ok`` (every sample of it ran with the FMU's
status 0 and kept the study's ``min_digits``) and its figures meet every constraint."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .studyfile import Study

__all__ = ["Table", "table_of", "best_designs", "pareto_front", "write_csv"]


@dataclass
class Table:
    """``values`` (designs x parameters), ``figures`` (designs x figures), per-design
    ``status`` and ``message``, and ``digits`` (the digits each design's reactions keep,
    -log10 of its worst eps x amplification; NaN where unknown); column names in
    ``parameters`` and ``figure_names``."""

    parameters: list
    figure_names: list
    values: np.ndarray
    figures: np.ndarray
    status: list
    message: list
    digits: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.digits is None:
            self.digits = np.full(len(self.status), np.nan)

    def column(self, name: str) -> np.ndarray:
        """A parameter's or a figure's column."""
        if name in self.parameters:
            return self.values[:, self.parameters.index(name)]
        return self.figures[:, self.figure_names.index(name)]

    def __len__(self) -> int:
        return len(self.status)


def table_of(study: Study, designs: np.ndarray, outcomes: list) -> Table:
    """The table of the designs and their [(index, Outcome)] (in index order)."""
    if [k for k, _ in outcomes] != list(range(len(designs))):
        raise ValueError("one outcome per design, in order, is expected")
    figures = np.array([o.figures for _, o in outcomes], dtype=float).reshape(len(designs), -1)
    digits = [math.nan if o.digits is None else o.digits for _, o in outcomes]
    return Table(
        [p.name for p in study.parameters],
        [f.name for f in study.figures],
        np.asarray(designs, dtype=float),
        figures,
        [o.status for _, o in outcomes],
        [o.message for _, o in outcomes],
        np.array(digits, dtype=float),
    )


def feasible(table: Table, study: Study) -> np.ndarray:
    """Which designs ran (status ok: every sample with the FMU's status 0, and enough
    digits) and meet every constraint (its min and its max)."""
    ok = np.array([s == "ok" for s in table.status], dtype=bool)
    for c in study.objective.constraints:
        ok &= c.met(table.column(c.figure))
    return ok & np.isfinite(table.column(study.objective.minimize))


def best_designs(table: Table, study: Study) -> list:
    """The indices of the best feasible designs, best first (ties by index)."""
    ok = np.flatnonzero(feasible(table, study))
    objective = table.column(study.objective.minimize)
    order = sorted(ok, key=lambda k: (objective[k], k))
    return [int(k) for k in order[: study.objective.best]]


def pareto_front(
    a: np.ndarray, b: np.ndarray, mask: np.ndarray, b_higher_is_better: bool = False
) -> list:
    """Indices (by a increasing) of the designs under ``mask`` that no other one beats
    in both ``a`` and ``b`` (lower is better in each, but higher in ``b`` where
    ``b_higher_is_better``: a figure a constraint bounds from below)."""
    b = -np.asarray(b, dtype=float) if b_higher_is_better else b
    order = sorted(np.flatnonzero(mask), key=lambda k: (a[k], b[k], k))
    front, lowest = [], math.inf
    for k in order:
        if b[k] < lowest:
            front.append(int(k))
            lowest = b[k]
    return front


def _cell(x: float) -> str:
    return repr(float(x)) if math.isfinite(x) else "nan"


def write_csv(table: Table, path: Path) -> None:
    """The table as CSV: design, parameters, figures, digits, status, message."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        header = ["design", *table.parameters, *table.figure_names, "digits", "status", "message"]
        w.writerow(header)
        for k in range(len(table)):
            w.writerow(
                [
                    k,
                    *map(_cell, table.values[k]),
                    *map(_cell, table.figures[k]),
                    _cell(table.digits[k]),
                    table.status[k],
                    table.message[k],
                ]
            )

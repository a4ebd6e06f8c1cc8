"""A study's results: one row per design (its index, parameter values, figures, status
and the FMU's message), the best feasible designs by the objective, and the Pareto
front of the objective against a constraint's figure. Written as CSV (text, every
number to 17 significant digits)."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .studyfile import Study

__all__ = ["Table", "table_of", "best_designs", "pareto_front", "write_csv"]


@dataclass
class Table:
    """``values`` (designs x parameters), ``figures`` (designs x figures), per-design
    ``status`` and ``message``; column names in ``parameters`` and ``figure_names``."""

    parameters: list
    figure_names: list
    values: np.ndarray
    figures: np.ndarray
    status: list
    message: list

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
    return Table(
        [p.name for p in study.parameters],
        [f.name for f in study.figures],
        np.asarray(designs, dtype=float),
        figures,
        [o.status for _, o in outcomes],
        [o.message for _, o in outcomes],
    )


def feasible(table: Table, study: Study) -> np.ndarray:
    """Which designs ran and meet every constraint."""
    ok = np.array([s == "ok" for s in table.status], dtype=bool)
    for c in study.objective.constraints:
        ok &= table.column(c.figure) <= c.maximum
    return ok & np.isfinite(table.column(study.objective.minimize))


def best_designs(table: Table, study: Study) -> list:
    """The indices of the best feasible designs, best first (ties by index)."""
    ok = np.flatnonzero(feasible(table, study))
    objective = table.column(study.objective.minimize)
    order = sorted(ok, key=lambda k: (objective[k], k))
    return [int(k) for k in order[: study.objective.best]]


def pareto_front(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> list:
    """Indices (by a increasing) of the designs under ``mask`` that no other one beats
    in both ``a`` and ``b`` (lower is better in each)."""
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
    """The table as CSV: design, parameters, figures, status, message."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["design", *table.parameters, *table.figure_names, "status", "message"])
        for k in range(len(table)):
            w.writerow(
                [
                    k,
                    *map(_cell, table.values[k]),
                    *map(_cell, table.figures[k]),
                    table.status[k],
                    table.message[k],
                ]
            )

"""Plots and the report of a design study (:mod:`dyadfmu.sweep`): the objective over
one parameter, a heat map over two (a grid) or a scatter coloured by the objective, the
Pareto front of the objective against the first constraint's figure, and a Markdown
summary with the best designs.

Every axis and colour scale whose values span more than LOG_DECADES decades is
logarithmic (symmetric logarithmic where the signs mix or zero is among them): a
peak torque from 1e-3 to 1e6 N m on a linear axis would show one point and a flat line.

Names from the study file and units from its FMU reach the Markdown as literal text
(:func:`dyadfmu.report.markdown.text`): a study file is untrusted input."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..sweep.results import Table, best_designs, feasible, pareto_front
from ..sweep.studyfile import Constraint, Study
from .markdown import provenance as markdown_provenance
from .markdown import table as markdown_table
from .markdown import text as markdown_text

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure


def _pyplot():
    """matplotlib's pyplot on the Agg backend, imported when a plot is drawn: a study run
    with --no-plots does not wait for it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


__all__ = ["plot_study", "study_figure", "report_text", "scale_of", "LOG_DECADES"]

#: Values whose magnitudes span more decades than this are drawn on a logarithmic scale.
LOG_DECADES = 3.0


def _is_grid(table: Table) -> bool:
    x, y = table.values[:, 0], table.values[:, 1]
    return len(np.unique(x)) * len(np.unique(y)) == len(table)


def _label(name: str, units: dict) -> str:
    return f"{name} [{units[name]}]" if units.get(name, "1") != "1" else name


def _axis_label(name: str, units: dict) -> str:
    """A plot's label: the unit comes from an FMU, and matplotlib reads $...$ as
    mathematics."""
    return _label(name, units).replace("$", r"\$")


def scale_of(values: np.ndarray) -> tuple[str, float]:
    """(scale, linear threshold) for values drawn on an axis or a colour bar: "log" where
    the finite magnitudes span more than LOG_DECADES decades and every value is positive,
    "symlog" where they span that and the signs mix or zero is among them (linear within
    the smallest magnitude), else "linear"."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    magnitude = np.abs(v[v != 0])
    if len(magnitude) < 2 or magnitude.max() <= 10**LOG_DECADES * magnitude.min():
        return "linear", 0.0
    return ("log" if np.all(v > 0) else "symlog"), float(magnitude.min())


def _set_scale(ax: Axes, which: str, values: np.ndarray) -> None:
    """The x or y axis of `ax` on the scale its values need."""
    scale, threshold = scale_of(values)
    setter = ax.set_xscale if which == "x" else ax.set_yscale
    if scale == "symlog":
        setter("symlog", linthresh=threshold)
    elif scale == "log":
        setter("log")


def _norm(values: np.ndarray) -> Normalize | None:
    """The colour scale of `values`: logarithmic where scale_of says so, else None."""
    from matplotlib import colors

    scale, threshold = scale_of(values)
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if scale == "log":
        return colors.LogNorm(vmin=finite.min(), vmax=finite.max())
    if scale == "symlog":
        return colors.SymLogNorm(linthresh=threshold, vmin=finite.min(), vmax=finite.max())
    return None


def _heat_map(ax: Axes, table: Table, z: np.ndarray, label: str) -> None:
    xs, ys = np.unique(table.values[:, 0]), np.unique(table.values[:, 1])
    grid = np.full((len(ys), len(xs)), np.nan)
    for k in range(len(table)):
        grid[np.searchsorted(ys, table.values[k, 1]), np.searchsorted(xs, table.values[k, 0])] = z[
            k
        ]
    mesh = ax.pcolormesh(xs, ys, grid, shading="nearest", cmap="viridis", norm=_norm(z))
    _pyplot().colorbar(mesh, ax=ax, label=label)


def _design_plot(ax: Axes, table: Table, study: Study, ok: np.ndarray, units: dict) -> None:
    ran = np.array([s == "ok" for s in table.status], dtype=bool)
    z = np.where(ran, table.column(study.objective.minimize), np.nan)
    x = table.values[:, 0]
    _set_scale(ax, "x", x)
    if table.values.shape[1] == 1:
        order = np.argsort(x)
        ax.plot(x[order], z[order], "-", color="0.5")
        ax.plot(x[ok], z[ok], "o", ms=3, color="C0", label="feasible")
        ax.set_ylabel(_axis_label(study.objective.minimize, units))
        _set_scale(ax, "y", z)
        ax.legend(fontsize=8)
    else:
        _set_scale(ax, "y", table.values[:, 1])
        if _is_grid(table):
            _heat_map(ax, table, z, _axis_label(study.objective.minimize, units))
        else:
            points = ax.scatter(x, table.values[:, 1], c=z, s=12, cmap="viridis", norm=_norm(z))
            _pyplot().colorbar(points, ax=ax, label=_axis_label(study.objective.minimize, units))
        out = ~ok
        ax.plot(x[out], table.values[out, 1], "x", color="w", ms=5, label="infeasible or failed")
        ax.legend(fontsize=8, loc="lower right")
        ax.set_ylabel(_axis_label(table.parameters[1], units))
    ax.set_xlabel(_axis_label(table.parameters[0], units))


def _pareto_plot(ax: Axes, table: Table, study: Study, units: dict) -> None:
    constraint = study.objective.constraints[0]
    other = constraint.figure
    a, b = table.column(study.objective.minimize), table.column(other)
    ran = np.array([s == "ok" for s in table.status]) & np.isfinite(a) & np.isfinite(b)
    ax.scatter(a[ran], b[ran], s=8, color="0.6", label="designs")
    front = pareto_front(a, b, ran, constraint.higher_is_better)
    ax.plot(a[front], b[front], "o-", ms=4, color="C3", label="Pareto front")
    bounds = [v for v in (constraint.minimum, constraint.maximum) if v is not None]
    for k, bound in enumerate(bounds):
        ax.axhline(bound, color="C0", ls="--", label=f"{other} limit" if k == 0 else None)
    _set_scale(ax, "x", a[ran])
    _set_scale(ax, "y", np.concatenate([b[ran], bounds]))
    ax.set_xlabel(_axis_label(study.objective.minimize, units))
    ax.set_ylabel(_axis_label(other, units))
    ax.legend(fontsize=8)


def study_figure(table: Table, study: Study, units: dict | None = None) -> Figure:
    """The study's figure: designs against the objective, and the Pareto front where the
    study has a constraint (the caller saves and closes it)."""
    units = units or {}
    ok = feasible(table, study)
    panels = 2 if study.objective.constraints else 1
    plt = _pyplot()
    fig, axes = plt.subplots(1, panels, figsize=(6.5 * panels, 5), squeeze=False)
    _design_plot(axes[0][0], table, study, ok, units)
    for k in best_designs(table, study)[:1]:
        if table.values.shape[1] >= 2:
            axes[0][0].plot(*table.values[k, :2], "r*", ms=14, label="best")
    if panels == 2:
        _pareto_plot(axes[0][1], table, study, units)
    # the file's name as plain text: matplotlib would read $...$ in it as mathematics
    title = study.name.replace("$", r"\$")
    fig.suptitle(f"{title}: {len(table)} designs, {int(ok.sum())} feasible")
    fig.tight_layout()
    return fig


def plot_study(table: Table, study: Study, path: Path, units: dict | None = None) -> Path:
    """The study's figure (study_figure) written to `path` as PNG."""
    fig = study_figure(table, study, units)
    try:
        fig.savefig(path, dpi=110)
    finally:
        _pyplot().close(fig)
    return path


def _constraint_text(c: Constraint) -> str:
    """A constraint as the report writes it: 'f <= 2', 'f >= 1', '1 <= f <= 2'."""
    name = markdown_text(c.figure)
    if c.minimum is not None and c.maximum is not None:
        return f"{c.minimum:g} <= {name} <= {c.maximum:g}"
    if c.minimum is not None:
        return f"{name} >= {c.minimum:g}"
    return f"{name} <= {c.maximum:g}"


def _digits_line(table: Table, study: Study) -> str:
    """What the report says of the round-off: the fewest digits a design keeps."""
    known = table.digits[np.isfinite(table.digits)]
    if not len(known):
        return (
            "Round-off: the FMU has no amplification output, so the digits its reactions "
            "keep are not checked."
        )
    flagged = sum(s == "inaccurate" for s in table.status)
    return (
        f"Round-off: the designs' reactions keep {known.min():.1f} to {known.max():.1f} "
        "digits (-log10 of the worst eps x amplification over each design's samples); "
        f"{flagged} design{'s' * (flagged != 1)} with fewer than `min_digits` "
        f"{study.min_digits:g} {'are' if flagged != 1 else 'is'} `inaccurate`, not ok."
    )


def report_text(
    table: Table, study: Study, seconds: float, workers: str, units: dict | None = None
) -> str:
    """The study's Markdown summary: what ran, the statuses, the best designs."""
    units = units or {}
    statuses = {s: table.status.count(s) for s in dict.fromkeys(table.status)}
    lines = [
        f"# Study {markdown_text(study.name)}",
        "",
        markdown_provenance(f"dyadfmu sweep {study.name}.toml"),
        "",
        markdown_text(study.description),
        "",
        f"{len(table)} designs ({study.sampling.method}) run in {seconds:.1f} s on "
        f"{markdown_text(workers)} "
        "(not counting a local cluster's start): "
        f"{len(table) / max(seconds, 1e-9):.1f} runs/s. Statuses: "
        + ", ".join(f"{markdown_text(s)} {n}" for s, n in statuses.items())
        + ".",
        "",
        _digits_line(table, study),
        "",
        f"Best designs by {markdown_text(study.objective.minimize)}"
        + (
            " subject to " + ", ".join(_constraint_text(c) for c in study.objective.constraints)
            if study.objective.constraints
            else ""
        )
        + ":",
        "",
    ]
    header = ["design", *(_label(n, units) for n in table.parameters + table.figure_names)]
    rows = []
    best = best_designs(table, study)
    for k in best:
        cells = [f"{v:.6g}" for v in (*table.values[k], *table.figures[k])]
        digits = f"{table.digits[k]:.1f}" if np.isfinite(table.digits[k]) else "-"
        rows.append([str(k), *cells, digits])
    lines += markdown_table([*header, "digits"], rows, "r" * (len(header) + 1))
    if not best:
        lines += ["", "No design ran and met every constraint: the table above is empty."]
    return "\n".join(lines) + "\n"

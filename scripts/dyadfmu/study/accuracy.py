"""The accuracy and speed study: every way of computing the reactions, against
40+ digit ground truth, on well-conditioned, near-singular and extreme inputs.

Methods: the C core (double and float), a generic 6x6 solve in C with GSL (LU
and SVD), NumPy's batched solve (the harness reference), and the FMU stepped
from C and from Python (fmpy). Ground truth: mpmath solving the generic
Newton-Euler system from exactly the same double inputs.
"""

from __future__ import annotations

import csv
import math
import tempfile
import time as clock
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import paths
from ..reference import newton_euler
from . import bench, speed
from . import configurations as cfg

EPS = {"double": 2.0**-52, "float": 2.0**-23}
METHODS = ("core", "core_float", "gsl_lu", "gsl_svd", "numpy")
LABELS = {
    "core": "C core (double)",
    "core_float": "C core (float)",
    "gsl_lu": "GSL LU 6x6 (C)",
    "gsl_svd": "GSL SVD 6x6 (C)",
    "numpy": "NumPy solve (batched)",
    "fmu_c": "FMU stepped from C",
    "fmu_fmpy": "FMU stepped from fmpy",
}


@dataclass
class Sizes:
    """How many configurations, steps and repetitions the study takes."""

    timing: int  # random configurations timed per type
    truth: int  # of them compared with mpmath
    per_decade: int  # near-singular sweep points per decade
    instances: int  # near-singular sweeps per type
    extreme: int  # extreme configurations per type, and cancelling ones
    fmu_c_steps: int
    fmpy_steps: int
    callgrind: int  # solves counted under callgrind
    repeat: int


FULL = Sizes(100_000, 2000, 4, 4, 2000, 100_000, 2000, 2000, 101)
QUICK = Sizes(10_000, 150, 1, 2, 150, 10_000, 300, 500, 21)


def _truth(dyad: str, rows: np.ndarray) -> np.ndarray:
    out = np.empty((len(rows), len(cfg.OUTPUT_COLUMNS)))
    for k, row in enumerate(rows):
        try:
            result = newton_euler.solve_mp(dyad, *cfg.reference_args(dyad, row), dps=50)
            out[k] = cfg.outputs_of(result, dyad)
        except np.linalg.LinAlgError:
            out[k] = np.nan
    return out


#: Output columns that are forces (N) and moments (N m): errors are scaled
#: within each group, since a moment is not comparable with a force.
FORCES = slice(0, 9)
MOMENTS = slice(9, 12)


#: The input sets, in the order of the report.
SETS = ("random", "sweep", "extreme", "cancelling")


def _errors(values: np.ndarray, truth: np.ndarray):
    """Normwise error of each configuration: the largest |method - truth| of the
    forces relative to the largest force reaction, and likewise for the reactive
    moments, whichever is worse; and the worst componentwise relative error."""
    with np.errstate(invalid="ignore", divide="ignore"):
        diff = np.abs(values - truth)
        normwise = np.zeros(len(truth))
        for group in (FORCES, MOMENTS):
            scale = np.max(np.abs(truth[:, group]), axis=1)
            group_error = np.max(diff[:, group], axis=1) / scale
            normwise = np.fmax(normwise, np.where(scale > 0, group_error, 0.0))
        normwise = np.where(
            np.isfinite(values).all(axis=1) | ~np.isfinite(truth).all(axis=1), normwise, np.inf
        )
        nonzero = np.abs(truth) > 0
        component = np.where(nonzero, diff / np.where(nonzero, np.abs(truth), 1.0), 0.0)
        componentwise = np.max(component, axis=1)
    return normwise, componentwise


def _silent_non_finite(values: np.ndarray, status: np.ndarray) -> int:
    """Configurations with an inf or NaN output and status ok."""
    return int(np.sum((status == 0) & ~np.all(np.isfinite(values), axis=1)))


@dataclass
class Results:
    """What the study measured: every point, one summary row per (method, type) on the
    random set, the worst contract ratio and the silent non-finite outputs per (method,
    type, set), and the run's sizes and wall time."""

    sizes: Sizes
    quick: bool
    points: list = field(default_factory=list)
    summary: list = field(default_factory=list)
    contract: dict = field(default_factory=dict)
    silent: dict = field(default_factory=dict)
    elapsed: float = 0.0
    speed: tuple = ((), ())  # speed.measure's (per type, per scene) figures


@dataclass
class _Inputs:
    """One dyad type's input sets, the rows compared with ground truth and that truth, and
    the problem's amplification as the C core (double) reports it."""

    dyad: str
    sets: dict
    truth_rows: dict
    truth: dict
    amplification: dict = field(default_factory=dict)


def _inputs(dyad: str, t_index: int, sizes: Sizes, log: Callable) -> _Inputs:
    log(f"{dyad}: generating inputs")
    sets = {
        "random": cfg.random_set(dyad, sizes.timing, seed=10 + t_index),
        "sweep": cfg.sweep_set(dyad, sizes.per_decade, sizes.instances, seed=20 + t_index),
        "extreme": cfg.extreme_set(dyad, sizes.extreme, seed=30 + t_index),
        "cancelling": cfg.cancelling_set(dyad, sizes.extreme, seed=40 + t_index),
    }
    truth_rows = dict(sets, random=sets["random"][: sizes.truth])
    log(
        f"{dyad}: ground truth (mpmath, 50 digits) for "
        f"{sum(len(r) for r in truth_rows.values())} configurations"
    )
    truth = {name: _truth(dyad, rows) for name, rows in truth_rows.items()}
    return _Inputs(dyad, sets, truth_rows, truth)


def _numpy_set(dyad: str, rows: np.ndarray, set_name: str, sizes: Sizes) -> tuple:
    """(values, status, seconds per configuration) of NumPy's batched solve."""
    args = cfg.batched_reference_args(dyad, rows)
    runs = []
    for _ in range(min(sizes.repeat, 5) if set_name == "random" else 1):
        t0 = clock.perf_counter()
        with np.errstate(all="ignore"):
            result = newton_euler.solve(dyad, *args)
        runs.append((clock.perf_counter() - t0) / len(rows))
    values = cfg.outputs_of(result, dyad)
    status = np.where(np.all(np.isfinite(values), axis=1), 0, 1)
    return values, status, float(np.median(runs))


def _solve_set(
    build: Path, method: str, data: _Inputs, set_name: str, sizes: Sizes, work: Path
) -> tuple:
    """(values, status, seconds per configuration, amplification) of one method on one
    input set; the float core is measured against its own amplification."""
    rows = data.sets[set_name]
    if method == "numpy":
        return (*_numpy_set(data.dyad, rows, set_name, sizes), data.amplification[set_name])
    result, seconds = bench.bench_method(
        build, method, data.dyad, rows, work, sizes.repeat if set_name == "random" else 0
    )
    n = len(data.truth_rows[set_name])
    if method == "core":
        data.amplification[set_name] = result[:n, 15]
    amp = result[:n, 15] if method == "core_float" else data.amplification[set_name]
    return result[:, :12], result[:, 12], seconds, amp


def _score(
    results: Results, method: str, data: _Inputs, set_name: str, solved: tuple, timing: float
) -> None:
    """The errors of one method on one set against ground truth, into the results."""
    values, status, _, amp = solved
    dyad, truth = data.dyad, data.truth[set_name]
    n = len(data.truth_rows[set_name])
    normwise, componentwise = _errors(values[:n], truth)
    eps = EPS["float" if method == "core_float" else "double"]
    ok = (status[:n] == 0) & np.isfinite(truth).all(axis=1)
    ratio = cfg.contract_ratio(values[:n][ok], truth[ok], amp[ok], eps)
    results.contract[(method, dyad, set_name)] = float(np.max(ratio)) if ratio.size else math.nan
    results.silent[(method, dyad, set_name)] = _silent_non_finite(values, status)
    for k in range(n):
        results.points.append(
            (set_name, dyad, method, k, amp[k], normwise[k], componentwise[k], int(status[k]))
        )
    if set_name == "random":
        results.summary.append(
            {
                "method": method,
                "type": dyad,
                "median": float(np.median(normwise[ok])),
                "worst": float(np.max(normwise[ok])),
                "componentwise": float(np.max(componentwise[ok])),
                "seconds": timing,
            }
        )


def _measure_method(
    results: Results, build: Path, method: str, data: _Inputs, sizes: Sizes, work: Path
) -> None:
    timing = math.nan
    for set_name in data.sets:
        solved = _solve_set(build, method, data, set_name, sizes, work)
        if set_name == "random":
            timing = solved[2]
        _score(results, method, data, set_name, solved, timing)
    if method != "numpy":
        results.summary[-1]["instructions"] = bench.instructions(
            build, method, data.dyad, data.sets["random"][: sizes.callgrind], work
        )


def _time_fmus(
    results: Results, build: Path, dyad: str, sizes: Sizes, work: Path, log: Callable
) -> None:
    """The FMUs stepped from C and from fmpy; they carry the C core's errors."""
    core_error = next(s for s in results.summary if s["method"] == "core" and s["type"] == dyad)
    for method in ("fmu_c", "fmu_fmpy"):
        for version in (2, 3):
            log(f"{dyad}: {LABELS[method]} (FMI {version})")
            if method == "fmu_c":
                seconds = bench.fmu_from_c(build, dyad, version, sizes.fmu_c_steps, work)
            else:
                seconds = bench.fmu_from_fmpy(dyad, version, sizes.fmpy_steps, work)
            results.summary.append(
                {
                    "method": f"{method}{version}",
                    "type": dyad,
                    "median": core_error["median"],
                    "worst": core_error["worst"],
                    "componentwise": core_error["componentwise"],
                    "seconds": seconds,
                    "instructions": math.nan,
                }
            )


def run(
    out: Path, quick: bool = False, build: Path | None = None, log: Callable = print
) -> Results:
    """Runs the whole study and writes points.csv and summary.csv to `out`; the report
    (:func:`dyadfmu.report.study.write`) is written from the results."""
    sizes = QUICK if quick else FULL
    build = build or paths.build_dir()
    out.mkdir(parents=True, exist_ok=True)
    results = Results(sizes, quick)
    started_all = clock.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for t_index, dyad in enumerate(cfg.TYPES):
            data = _inputs(dyad, t_index, sizes, log)
            for method in METHODS:
                log(f"{dyad}: {LABELS[method]}")
                _measure_method(results, build, method, data, sizes, work)
            _time_fmus(results, build, dyad, sizes, work, log)
        results.speed = speed.measure(build, work, quick, log)
    results.elapsed = clock.perf_counter() - started_all
    _write_points(out / "points.csv", results.points)
    _write_summary_csv(out / "summary.csv", results.summary)
    return results


def _write_csv(path: Path, header: list[str], rows: list[list]) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows(rows)


def _write_points(path: Path, points: list[tuple]) -> None:
    header = "set type method index amplification error componentwise_error status".split()
    rows = [
        [p[0], p[1], p[2], p[3], f"{p[4]:.6e}", f"{p[5]:.6e}", f"{p[6]:.6e}", p[7]] for p in points
    ]
    _write_csv(path, header, rows)


def _write_summary_csv(path: Path, summary: list[dict]) -> None:
    header = [
        "method",
        "type",
        "median_error",
        "worst_error",
        "worst_componentwise_error",
        "seconds_per_config",
        "instructions_per_solve",
    ]
    rows = [
        [
            s["method"],
            s["type"],
            f"{s['median']:.3e}",
            f"{s['worst']:.3e}",
            f"{s['componentwise']:.3e}",
            f"{s['seconds']:.4e}",
            f"{s.get('instructions', math.nan):.0f}",
        ]
        for s in summary
    ]
    _write_csv(path, header, rows)

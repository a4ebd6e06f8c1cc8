"""The accuracy and speed study: every way of computing the reactions, against
40+ digit ground truth, on well-conditioned, near-singular and extreme inputs.

Methods: the C core (double and float), a generic 6x6 solve in C with GSL (LU
and SVD), NumPy's batched solve (the harness reference), and the FMU stepped
from C and from Python (fmpy). Ground truth: mpmath solving the generic
Newton-Euler system from exactly the same double inputs.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time as clock
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import configurations as cfg
from . import reference
from .harness import build_dir, fmu_path

EPS = {"double": 2.0 ** -52, "float": 2.0 ** -23}
METHODS = ("core", "core_float", "gsl_lu", "gsl_svd", "numpy")
LABELS = {"core": "C core (double)", "core_float": "C core (float)",
          "gsl_lu": "GSL LU 6x6 (C)", "gsl_svd": "GSL SVD 6x6 (C)",
          "numpy": "NumPy solve (batched)", "fmu_c": "FMU stepped from C",
          "fmu_fmpy": "FMU stepped from fmpy"}


@dataclass
class Sizes:
    timing: int            # random configurations timed per type
    truth: int             # of them compared with mpmath
    per_decade: int        # near-singular sweep points per decade
    instances: int         # near-singular sweeps per type
    extreme: int           # extreme configurations per type, and cancelling ones
    fmu_c_steps: int
    fmpy_steps: int
    callgrind: int         # solves counted under callgrind
    repeat: int


FULL = Sizes(100_000, 2000, 4, 4, 2000, 100_000, 2000, 2000, 101)
QUICK = Sizes(10_000, 150, 1, 2, 150, 10_000, 300, 500, 21)


def _bench_binary(build: Path, real: str) -> Path:
    name = "dyad_bench" if real == "double" else "dyad_bench_float"
    path = build / "tests" / "bench" / name
    if not path.is_file():
        raise FileNotFoundError(f"{path} is missing: configure with GSL installed "
                                "(libgsl-dev) and build (scripts/run-study does)")
    return path


def _run_bench(binary: Path, args: list[str]) -> dict:
    done = subprocess.run([str(binary), *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary.name} {' '.join(args)} failed: {done.stderr.strip()}")
    return json.loads(done.stdout.strip().splitlines()[-1])


#: Configurations timed per pass: the solve, not the memory bus, is measured
#: (1000 inputs and results fit the caches; the whole set is still solved once
#: for the errors).
TIMED_CHUNK = 1000


def _bench_method(build: Path, method: str, dyad: str, rows: np.ndarray, work: Path,
                  repeat: int) -> tuple[np.ndarray, float]:
    """All rows solved once (for their errors), then a cache-sized chunk timed
    `repeat` times (the median); repeat 0: not timed."""
    real = "float" if method == "core_float" else "double"
    binary = _bench_binary(build, real)
    inputs, outputs = work / "inputs.bin", work / "outputs.bin"
    rows.astype("<f8").tofile(inputs)
    args = ["--type", dyad, "--method", "core" if real == "float" else method,
            "--inputs", str(inputs)]
    _run_bench(binary, args + ["--outputs", str(outputs), "--repeat", "1"])
    result = np.fromfile(outputs, dtype="<f8").reshape(len(rows), 16)
    if repeat == 0:
        return result, math.nan
    info = _run_bench(binary, args + ["--count", str(min(TIMED_CHUNK, len(rows))),
                                      "--repeat", str(repeat)])
    return result, float(info["seconds_per_config"])


def _instructions(build: Path, method: str, dyad: str, rows: np.ndarray, work: Path) -> float:
    """Instructions per solve under callgrind, counting the solve loop only."""
    if shutil.which("valgrind") is None:
        return math.nan
    real = "float" if method == "core_float" else "double"
    inputs = work / "callgrind.bin"
    rows.astype("<f8").tofile(inputs)
    done = subprocess.run(
        ["valgrind", "--tool=callgrind", "--toggle-collect=bench_loop_*",
         f"--callgrind-out-file={work / 'callgrind.out'}", str(_bench_binary(build, real)),
         "--type", dyad, "--method", "core" if real == "float" else method,
         "--inputs", str(inputs), "--repeat", "1"], capture_output=True, text=True)
    match = re.search(r"Collected\s*:\s*(\d+)", done.stderr)
    return int(match.group(1)) / len(rows) if match else math.nan


def _fmu_rows(dyad: str, count: int, seed: int):
    """Inputs for stepping an FMU: its start values with smooth variations."""
    from fmpy import read_model_description

    path = fmu_path(dyad, 2)
    md = read_model_description(str(path))
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * math.pi, count)
    rows = np.empty((count, len(inputs)))
    for k, v in enumerate(inputs):
        if v.unit == "rad":
            swing = 0.3
        elif v.unit == "m":                 # a sliding length: stays positive
            swing = 0.3 * float(v.start)
        else:
            swing = 0.2 * (abs(float(v.start)) + 1.0)
        rows[:, k] = float(v.start) + swing * np.sin(t + rng.uniform(0, 2 * math.pi))
    return md, inputs, outputs, rows


def _fmu_from_c(build: Path, dyad: str, version: int, count: int, work: Path) -> float:
    md, inputs, outputs, rows = _fmu_rows(dyad, count, seed=version)
    platform = "linux64" if version == 2 else "x86_64-linux"
    binary = build / "fmus" / "stage" / f"dyad_{dyad.lower()}_fmi{version}" / "binaries" / \
        platform / f"dyad_{dyad.lower()}.so"
    rows.astype("<f8").tofile(work / "fmu_inputs.bin")
    info = _run_bench(_bench_binary(build, "double"), [
        "--method", "fmu", "--fmu", str(binary), "--fmi", str(version), "--token", md.guid,
        "--fmu-inputs", str(work / "fmu_inputs.bin"),
        "--in-vrs", ",".join(str(v.valueReference) for v in inputs),
        "--out-vrs", ",".join(str(v.valueReference) for v in outputs), "--repeat", "3"])
    return float(info["seconds_per_config"])


def _fmu_from_fmpy(dyad: str, version: int, count: int, work: Path) -> float:
    import zipfile

    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    md, inputs, outputs, rows = _fmu_rows(dyad, count, seed=version)
    unzipdir = work / f"fmu{version}"
    with zipfile.ZipFile(fmu_path(dyad, version)) as archive:
        archive.extractall(unzipdir)
    cls = FMU2Slave if version == 2 else FMU3Slave
    fmu = cls(guid=md.guid, unzipDirectory=str(unzipdir),
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="timing")
    fmu.instantiate()
    if version == 2:
        fmu.setupExperiment(startTime=0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    in_vrs = [v.valueReference for v in inputs]
    out_vrs = [v.valueReference for v in outputs]
    set_values = fmu.setReal if version == 2 else fmu.setFloat64
    get_values = fmu.getReal if version == 2 else fmu.getFloat64
    started = clock.perf_counter()
    for k, row in enumerate(rows):
        set_values(in_vrs, list(row))
        fmu.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
        get_values(out_vrs)
    seconds = (clock.perf_counter() - started) / len(rows)
    fmu.terminate()
    fmu.freeInstance()
    return seconds


def _truth(dyad: str, rows: np.ndarray) -> np.ndarray:
    out = np.empty((len(rows), len(cfg.OUTPUT_COLUMNS)))
    for k, row in enumerate(rows):
        try:
            result = reference.solve_mp(dyad, *cfg.reference_args(dyad, row), dps=50)
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
        normwise = np.where(np.isfinite(values).all(axis=1) | ~np.isfinite(truth).all(axis=1),
                            normwise, np.inf)
        nonzero = np.abs(truth) > 0
        component = np.where(nonzero, diff / np.where(nonzero, np.abs(truth), 1.0), 0.0)
        componentwise = np.max(component, axis=1)
    return normwise, componentwise


def _silent_non_finite(values: np.ndarray, status: np.ndarray) -> int:
    """Configurations with an inf or NaN output and status ok."""
    return int(np.sum((status == 0) & ~np.all(np.isfinite(values), axis=1)))


def run(out: Path, quick: bool = False, build: Path | None = None, log=print) -> Path:
    """Runs the whole study and writes report.md, points.csv and the plots to `out`."""
    sizes = QUICK if quick else FULL
    build = build or build_dir()
    out.mkdir(parents=True, exist_ok=True)
    points = []           # every measured point
    summary = []          # one row per (method, type) on the random set
    contract = {}         # worst cfg.contract_ratio per method and set
    silent = {}
    started_all = clock.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for t_index, dyad in enumerate(cfg.TYPES):
            log(f"{dyad}: generating inputs")
            sets = {"random": cfg.random_set(dyad, sizes.timing, seed=10 + t_index),
                    "sweep": cfg.sweep_set(dyad, sizes.per_decade, sizes.instances,
                                           seed=20 + t_index),
                    "extreme": cfg.extreme_set(dyad, sizes.extreme, seed=30 + t_index),
                    "cancelling": cfg.cancelling_set(dyad, sizes.extreme, seed=40 + t_index)}
            truth_rows = dict(sets, random=sets["random"][:sizes.truth])
            log(f"{dyad}: ground truth (mpmath, 50 digits) for "
                f"{sum(len(r) for r in truth_rows.values())} configurations")
            truth = {name: _truth(dyad, rows) for name, rows in truth_rows.items()}
            # the problem's amplification, as the C core (double) reports it; the float
            # core is measured against its own
            amplification = {}

            for method in METHODS:
                log(f"{dyad}: {LABELS[method]}")
                timing = math.nan
                for set_name, rows in sets.items():
                    if method == "numpy":
                        args = cfg.batched_reference_args(dyad, rows)
                        runs = []
                        for _ in range(min(sizes.repeat, 5) if set_name == "random" else 1):
                            t0 = clock.perf_counter()
                            with np.errstate(all="ignore"):
                                result = reference.solve(dyad, *args)
                            runs.append((clock.perf_counter() - t0) / len(rows))
                        values = cfg.outputs_of(result, dyad)
                        status = np.where(np.all(np.isfinite(values), axis=1), 0, 1)
                        seconds = float(np.median(runs))
                        amp = amplification[set_name]
                    else:
                        result, seconds = _bench_method(build, method, dyad, rows, work,
                                                        sizes.repeat if set_name == "random"
                                                        else 0)
                        values, status = result[:, :12], result[:, 12]
                        if method == "core":
                            amplification[set_name] = result[:len(truth_rows[set_name]), 15]
                        amp = result[:len(truth_rows[set_name]), 15] \
                            if method == "core_float" else amplification[set_name]
                    if set_name == "random":
                        timing = seconds
                    n = len(truth_rows[set_name])
                    normwise, componentwise = _errors(values[:n], truth[set_name])
                    eps = EPS["float" if method == "core_float" else "double"]
                    ok = (status[:n] == 0) & np.isfinite(truth[set_name]).all(axis=1)
                    ratio = cfg.contract_ratio(values[:n][ok], truth[set_name][ok], amp[ok], eps)
                    contract[(method, dyad, set_name)] = float(np.max(ratio)) if ratio.size \
                        else math.nan
                    silent[(method, dyad, set_name)] = _silent_non_finite(values, status)
                    for k in range(n):
                        points.append((set_name, dyad, method, k, amp[k], normwise[k],
                                       componentwise[k], int(status[k])))
                    if set_name == "random":
                        summary.append({"method": method, "type": dyad,
                                        "median": float(np.median(normwise[ok])),
                                        "worst": float(np.max(normwise[ok])),
                                        "componentwise": float(np.max(componentwise[ok])),
                                        "seconds": timing})
                if method != "numpy":
                    summary[-1]["instructions"] = _instructions(
                        build, method, dyad, sets["random"][:sizes.callgrind], work)
            core_error = next(s for s in summary if s["method"] == "core" and s["type"] == dyad)
            for method, function in (("fmu_c", _fmu_from_c), ("fmu_fmpy", _fmu_from_fmpy)):
                for version in (2, 3):
                    log(f"{dyad}: {LABELS[method]} (FMI {version})")
                    steps = sizes.fmu_c_steps if method == "fmu_c" else sizes.fmpy_steps
                    if method == "fmu_c":
                        seconds = function(build, dyad, version, steps, work)
                    else:
                        seconds = function(dyad, version, steps, work)
                    summary.append({"method": f"{method}{version}", "type": dyad,
                                    "median": core_error["median"], "worst": core_error["worst"],
                                    "componentwise": core_error["componentwise"],
                                    "seconds": seconds, "instructions": math.nan})
    elapsed = clock.perf_counter() - started_all
    _write_points(out / "points.csv", points)
    _write_summary_csv(out / "summary.csv", summary)
    from . import study_report

    figures = study_report.plots(out, points, summary)
    report = study_report.markdown(out, summary, contract, silent, sizes, quick, elapsed,
                                   figures)
    log(f"report written to {report} ({elapsed:.0f} s)")
    return report


def _write_points(path: Path, points) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["set", "type", "method", "index", "amplification", "error",
                         "componentwise_error", "status"])
        for p in points:
            writer.writerow([p[0], p[1], p[2], p[3], f"{p[4]:.6e}", f"{p[5]:.6e}",
                             f"{p[6]:.6e}", p[7]])


def _write_summary_csv(path: Path, summary) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["method", "type", "median_error", "worst_error",
                         "worst_componentwise_error", "seconds_per_config",
                         "instructions_per_solve"])
        for s in summary:
            writer.writerow([s["method"], s["type"], f"{s['median']:.3e}", f"{s['worst']:.3e}",
                             f"{s['componentwise']:.3e}", f"{s['seconds']:.4e}",
                             f"{s.get('instructions', math.nan):.0f}"])

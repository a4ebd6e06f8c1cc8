"""The benchmark binary of the C build (tests/bench: the core, GSL's solves, an FMU
stepped from C) run on files of inputs, callgrind's instruction counts, and the FMUs
timed from C and from Python."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import time as clock
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.slave import Slave


def fmu_path(dyad: str, version: int, build: Path | None = None) -> Path:
    """The generic FMU of a dyad type in `build` (default: paths.built_fmu's)."""
    return paths.built_fmu(f"dyad_{dyad.lower()}", version, build)


def bench_binary(build: Path, real: str) -> Path:
    """The benchmark program of the build, in double or float."""
    name = "dyad_bench" if real == "double" else "dyad_bench_float"
    path = build / "tests" / "bench" / name
    if not path.is_file():
        raise FileNotFoundError(
            f"{path} is missing: configure with GSL installed "
            "(libgsl-dev) and build (scripts/run-study does)"
        )
    return path


def bench_arguments(dyad: str, method: str, inputs: Path) -> list[str]:
    """The benchmark program's arguments naming the dyad, the method and the inputs file
    (``core_float`` is the ``core`` method of the float program)."""
    method = "core" if method == "core_float" else method
    return ["--type", dyad, "--method", method, "--inputs", str(inputs)]


def run_bench(binary: Path, args: list[str]) -> dict:
    """Run the benchmark program; its last line of output as JSON."""
    done = subprocess.run([str(binary), *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary.name} {' '.join(args)} failed: {done.stderr.strip()}")
    return json.loads(done.stdout.strip().splitlines()[-1])


#: Configurations timed per pass: the solve, not the memory bus, is measured
#: (1000 inputs and results fit the caches; the whole set is still solved once
#: for the errors).
TIMED_CHUNK = 1000


def bench_method(
    build: Path, method: str, dyad: str, rows: np.ndarray, work: Path, repeat: int
) -> tuple[np.ndarray, float]:
    """All rows solved once (for their errors), then a cache-sized chunk timed
    `repeat` times (the median); repeat 0: not timed."""
    real = "float" if method == "core_float" else "double"
    binary = bench_binary(build, real)
    inputs, outputs = work / "inputs.bin", work / "outputs.bin"
    rows.astype("<f8").tofile(inputs)
    args = bench_arguments(dyad, method, inputs)
    run_bench(binary, args + ["--outputs", str(outputs), "--repeat", "1"])
    result = np.fromfile(outputs, dtype="<f8").reshape(len(rows), 16)
    if repeat == 0:
        return result, math.nan
    info = run_bench(
        binary, args + ["--count", str(min(TIMED_CHUNK, len(rows))), "--repeat", str(repeat)]
    )
    return result, float(info["seconds_per_config"])


def instructions(build: Path, method: str, dyad: str, rows: np.ndarray, work: Path) -> float:
    """Instructions per solve under callgrind, counting the solve loop only."""
    if shutil.which("valgrind") is None:
        return math.nan
    real = "float" if method == "core_float" else "double"
    inputs = work / "callgrind.bin"
    rows.astype("<f8").tofile(inputs)
    done = subprocess.run(
        [
            "valgrind",
            "--tool=callgrind",
            "--toggle-collect=bench_loop_*",
            f"--callgrind-out-file={work / 'callgrind.out'}",
            str(bench_binary(build, real)),
            *bench_arguments(dyad, method, inputs),
            "--repeat",
            "1",
        ],
        capture_output=True,
        text=True,
    )
    match = re.search(r"Collected\s*:\s*(\d+)", done.stderr)
    return int(match.group(1)) / len(rows) if match else math.nan


def fmu_rows(dyad: str, count: int, seed: int, build: Path | None = None) -> tuple:
    """Inputs for stepping an FMU (of `build`): its start values with smooth variations."""
    path = fmu_path(dyad, 2, build)
    md = read_model_description(str(path))
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * math.pi, count)
    rows = np.empty((count, len(inputs)))
    for k, v in enumerate(inputs):
        if v.unit == "rad":
            swing = 0.3
        elif v.unit == "m":  # a sliding length: stays positive
            swing = 0.3 * float(v.start)
        else:
            swing = 0.2 * (abs(float(v.start)) + 1.0)
        rows[:, k] = float(v.start) + swing * np.sin(t + rng.uniform(0, 2 * math.pi))
    return md, inputs, outputs, rows


def fmu_step_arguments(
    binary: Path, version: int, token: str, data: Path, inputs: list, outputs: list
) -> list[str]:
    """The benchmark's arguments that step an FMU binary from C (--method fmu): one doStep
    per row of `data` (rows of the `inputs` variables), reading back the `outputs`."""
    return [
        "--method",
        "fmu",
        "--fmu",
        str(binary),
        "--fmi",
        str(version),
        "--token",
        token,
        "--fmu-inputs",
        str(data),
        "--in-vrs",
        ",".join(str(v.valueReference) for v in inputs),
        "--out-vrs",
        ",".join(str(v.valueReference) for v in outputs),
    ]


def fmu_from_c(build: Path, dyad: str, version: int, count: int, work: Path) -> float:
    """Seconds per doStep of the dyad FMU's binary stepped from C by the benchmark."""
    md, inputs, outputs, rows = fmu_rows(dyad, count, seed=version, build=build)
    binary = paths.stage_binary(build, f"dyad_{dyad.lower()}", version)
    rows.astype("<f8").tofile(work / "fmu_inputs.bin")
    args = fmu_step_arguments(binary, version, md.guid, work / "fmu_inputs.bin", inputs, outputs)
    info = run_bench(bench_binary(build, "double"), args + ["--repeat", "3"])
    return float(info["seconds_per_config"])


def fmu_from_fmpy(dyad: str, version: int, count: int, work: Path) -> float:
    """Seconds per doStep of the dyad FMU driven from Python through fmpy (set the inputs,
    step, get the real outputs)."""
    md, inputs, outputs, rows = fmu_rows(dyad, count, seed=version)
    fmu = Slave(fmu_path(dyad, version), instance_name="timing")
    fmu.initialize()
    in_names = tuple(v.name for v in inputs)
    out_names = tuple(v.name for v in outputs)
    started = clock.perf_counter()
    for k, row in enumerate(rows):
        fmu.set(in_names, row)
        fmu.do_step(k * 1e-3, 1e-3)
        fmu.get(out_names)
    seconds = (clock.perf_counter() - started) / len(rows)
    fmu.close()
    return seconds

"""What the kinematics inside buy: for each mechanism FMU, the inputs its user must give
before (every link's motion, ``kinematics = "external"``) and after (the driver's motion
and the loads), its worst errors against the reference on each assembly branch, and its
work per doStep with the kinematics and without them.

Work per doStep is counted by ``valgrind --tool=callgrind`` around the stepping loop of
``tests/bench/dyad_bench --method fmu`` (set the inputs, doStep, get the real outputs). The
kinematics' share is the inclusive count of the generated ``kinematics`` function (both of
its passes: the motion, and the unit-rate pass behind J and dJ/dq), or where the compiler
inlined it, of its calls into the core; "without" is the rest.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..cosim import mechanism_fmus as mf
from ..cosim import multidriver_fmus as mdf
from ..mechanisms import multidriver
from ..study import bench

GENERATOR = paths.GENERATOR


def inputs_before(name: str) -> list[str]:
    """The inputs the scene's FMU would take with every link's motion an input."""
    scene = multidriver.scene_path(name) if name in mdf.NAMES else mf.scene_file(name)
    done = subprocess.run(
        [
            sys.executable,
            str(GENERATOR),
            str(scene),
            "--external-inputs",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout.split()


def _callgrind(args: list[str], work: Path) -> tuple[int, int]:
    """(instructions of the stepping loop, of them the generated kinematics)."""
    out = work / "callgrind.out"
    done = subprocess.run(
        [
            "valgrind",
            "--tool=callgrind",
            "--toggle-collect=bench_loop_*",
            f"--callgrind-out-file={out}",
            *args,
        ],
        capture_output=True,
        text=True,
    )
    total = re.search(r"Collected\s*:\s*(\d+)", done.stderr)
    annotated = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out)],
        capture_output=True,
        text=True,
    ).stdout
    inside = re.findall(r"^\s*([\d,]+)\s.*\?\?\?:kinematics[.\s]", annotated, re.MULTILINE)
    if not inside:  # the generated function inlined into evaluate: its calls into the core
        pattern = r"^\s*([\d,]+)\s.*\?\?\?:(?:dyad_kinematics_|dyad_point_on_link)"
        inside = re.findall(pattern, annotated, re.MULTILINE)
    kinematics = sum(int(x.replace(",", "")) for x in inside)
    return (int(total.group(1)) if total else 0), kinematics


def instructions(name: str, build: Path, work: Path, rows: int = 200) -> tuple[float, float]:
    """(instructions per doStep, of them the kinematics) of the FMI 2 mechanism FMU, over
    one driver cycle (several drivers: one period of their motion)."""
    if shutil.which("valgrind") is None or shutil.which("callgrind_annotate") is None:
        return math.nan, math.nan
    if name in mdf.NAMES:
        co = mdf.setup(name, 2, revolutions=1.0, steps=rows, build=build)
    else:
        co = mf.setup(name, 2, revolutions=1.0, steps=rows, build=build)[0]
    md = read_model_description(str(co.path))
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    data = np.stack([co.inputs[v.name] for v in inputs], axis=1)
    file = work / f"{name}.bin"
    data.astype("<f8").tofile(file)
    binary = paths.stage_binary(build, name, 2)
    args = [str(bench.bench_binary(build, "double"))]
    args += bench.fmu_step_arguments(binary, 2, md.guid, file, inputs, outputs)
    args += ["--repeat", "1"]
    total, kinematics = _callgrind(args, work)
    return total / len(data), kinematics / len(data)


#: The mechanism FMUs' table's header.
HEADER = (
    "mechanism FMU",
    "branch",
    "inputs before",
    "inputs after",
    "worst kinematic error",
    "worst other error",
    "instr./doStep",
    "with kinematics",
    "without",
)


def row(
    name: str,
    branch: int,
    inputs: tuple[int | str, int],
    kinematic: tuple[str, float],
    other: tuple[str, float],
    work: tuple[float, float],
) -> list[str]:
    """One row of the table: the FMU and branch, its inputs (before, after), its worst
    kinematic and other errors (output, error), its instructions per doStep (in all, in
    the kinematics)."""
    total, inside = work
    return [
        name,
        f"{branch:+d}",
        str(inputs[0]),
        str(inputs[1]),
        f"{kinematic[1]:.1e} ({kinematic[0]})",
        f"{other[1]:.1e} ({other[0]})",
        f"{total:.0f}",
        f"{inside:.0f}",
        f"{total - inside:.0f}",
    ]


def _count_before(name: str, log: Callable) -> int | str:
    """How many inputs the scene would take with external kinematics, or "-" where the
    generator cannot list them (logged with its last line)."""
    try:
        return len(inputs_before(name))
    except subprocess.CalledProcessError as error:
        last = (error.stderr or "").strip().splitlines()[-1:] or ["no message"]
        log(f"{name}: the generator lists no external-kinematics inputs: {last[0]}")
        return "-"


def rows(build: Path, quick: bool = False, log: Callable = print) -> list:
    """The mechanism FMUs' table: a header row, then one row per FMU and branch."""
    table = [list(HEADER)]
    revolutions, steps = (1.0, 180) if quick else (2.0, 360)
    with tempfile.TemporaryDirectory(prefix="dyadfmu_mechanisms_") as tmp:
        for name in mf.MECHANISM_FMUS:
            log(f"mechanism FMU {name}")
            before = _count_before(name, log)
            work = instructions(name, build, Path(tmp))
            for branch in (1, -1) if name in mf.BRANCHES else (1,):
                run = mf.run(name, 2, branch, "varying", revolutions, steps, build)
                kin = run.worst_of(True) if any(map(mf.is_kinematic, run.errors)) else ("-", 0.0)
                inputs = (before, len(run.inputs))
                table.append(row(name, branch, inputs, kin, run.worst_of(False), work))
        for name in mdf.NAMES:
            log(f"mechanism FMU {name} (several drivers)")
            before = _count_before(name, log)
            work = instructions(name, build, Path(tmp))
            result = mdf.compare(name, 2, count=40 if quick else 200, build=build)
            inputs = (before, len(mdf.working_inputs(name, 1)))
            table.append(row(name, 1, inputs, *_worst_split(result.errors), work))
    return table


def _worst_split(errors: dict) -> tuple[tuple[str, float], tuple[str, float]]:
    """The worst kinematic error and the worst other one, each (output, error); ("-", 0)
    where there is none."""
    split = []
    for kinematic in (True, False):
        chosen = {k: v for k, v in errors.items() if mf.is_kinematic(k) == kinematic}
        name = max(chosen, key=chosen.get) if chosen else "-"
        split.append((name, chosen.get(name, 0.0)))
    return split[0], split[1]


REPORT_TEXT = (
    'Mechanism FMUs (`kinematics = "internal"`): the inputs a user gives before (every '
    'link\'s motion, as the scene with `kinematics = "external"` takes them) and after (the '
    "driver's motion and the loads), the worst error over two driver cycles at a varying "
    "speed against the NumPy kinematics and Newton-Euler reference (kinematic outputs "
    "relative to their own peak, the others to the largest peak of their unit), on each "
    "assembly branch, and callgrind's instructions per doStep (FMI 2, set the inputs, "
    "doStep, get the real outputs): in all, in the generated kinematics (both passes: the "
    "motion, and the unit-rate pass behind J and dJ/dq) and without them. The scenes with "
    "several drivers (no J: their inertia matrix M(q) instead) are "
    "compared at random points of their working ranges (every driver's coordinate, rate "
    "and acceleration and the loads drawn at once), their instructions over one period "
    "of their drivers' motion:"
)

__all__ = ["HEADER", "REPORT_TEXT", "inputs_before", "instructions", "row", "rows"]

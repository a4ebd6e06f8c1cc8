"""The footprint of the tailored scene FMUs against the generic per-type FMUs they replace:
variables, binary and code size, callgrind instructions and time per doStep.

Work per doStep is counted by ``valgrind --tool=callgrind`` around the stepping loop of
``tests/bench/dyad_bench --method fmu`` (set the inputs, doStep, get the real outputs),
and timed in one run of the same program (median of several passes). The generic FMUs are
stepped through their own start values with smooth variations (as in the accuracy and
speed study); the tailored ones through the scene's own kinematics.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..cosim import scenes
from . import bench

if TYPE_CHECKING:
    from collections.abc import Callable

    from fmpy.model_description import ModelDescription


@dataclass
class Footprint:
    """An FMU's variables, binary and code size, instructions and time per doStep."""

    inputs: int
    parameters: int
    outputs: int
    binary_bytes: int
    text_bytes: int
    instructions: float  # per doStep (set inputs, doStep, get outputs)
    seconds: float  # per doStep, median of the passes

    @property
    def variables(self) -> int:
        """Inputs, parameters and outputs together."""
        return self.inputs + self.parameters + self.outputs


def _text_size(path: Path) -> int:
    """Bytes of code (the .text section), from `size -A`; 0 if size is missing."""
    if shutil.which("size") is None:
        return 0
    done = subprocess.run(["size", "-A", str(path)], capture_output=True, text=True)
    match = re.search(r"^\.text\s+(\d+)", done.stdout, re.MULTILINE)
    return int(match.group(1)) if match else 0


def _step(
    build: Path,
    identifier: str,
    version: int,
    md: ModelDescription,
    rows: np.ndarray,
    work: Path,
    repeat: int,
) -> tuple[float, float]:
    """(instructions, seconds) per doStep of an FMU binary over `rows` of its inputs."""
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    outputs = [
        v for v in md.modelVariables if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    data = work / f"{identifier}_{version}.bin"
    rows.astype("<f8").tofile(data)
    binary = paths.stage_binary(build, identifier, version)
    args = bench.fmu_step_arguments(binary, version, md.guid, data, inputs, outputs)
    program = bench.bench_binary(build, "double")
    info = bench.run_bench(program, args + ["--repeat", str(repeat)])
    instructions = math.nan
    if shutil.which("valgrind") is not None:
        done = subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                "--toggle-collect=bench_loop_*",
                f"--callgrind-out-file={work / 'callgrind.out'}",
                str(program),
                *args,
                "--repeat",
                "1",
            ],
            capture_output=True,
            text=True,
        )
        match = re.search(r"Collected\s*:\s*(\d+)", done.stderr)
        if match:
            instructions = int(match.group(1)) / len(rows)
    return instructions, float(info["seconds_per_config"])


def _counts(md: ModelDescription) -> tuple[int, int, int]:
    causes = [v.causality for v in md.modelVariables]
    return causes.count("input"), causes.count("parameter"), causes.count("output")


def tailored(
    name: str, build: Path, version: int, work: Path, rows_count: int, repeat: int
) -> Footprint:
    """The footprint of a scene's tailored FMU, stepped through its own kinematics."""
    path = scenes.fmu_path(name, version, build)
    md = read_model_description(str(path))
    source = scenes.Source(name)
    motion = source.motion("constant", 1.0)
    t = (np.arange(rows_count) + 0.5) * motion.duration / rows_count
    kin = source.kinematics(t, motion)
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    inputs = source.inputs(kin, names)
    rows = np.stack([inputs[n] for n in names], axis=1) if names else np.zeros((rows_count, 0))
    instructions, seconds = _step(build, name, version, md, rows, work, repeat)
    binary = paths.stage_binary(build, name, version)
    return Footprint(*_counts(md), binary.stat().st_size, _text_size(binary), instructions, seconds)


def generic(
    dyad: str, build: Path, version: int, work: Path, rows_count: int, repeat: int
) -> Footprint:
    """The footprint of the generic FMU of a dyad type."""
    identifier = f"dyad_{dyad.lower()}"
    md, _, _, rows = bench.fmu_rows(dyad, rows_count, seed=version, build=build)
    if version != 2:
        md = read_model_description(str(scenes.fmu_path(identifier, version, build)))
    instructions, seconds = _step(build, identifier, version, md, rows, work, repeat)
    binary = paths.stage_binary(build, identifier, version)
    return Footprint(*_counts(md), binary.stat().st_size, _text_size(binary), instructions, seconds)


def measure(
    build: Path, version: int = 2, rows_count: int = 500, repeat: int = 21, log: Callable = print
) -> list:
    """[(scene, tailored Footprint, [generic Footprint per dyad])]."""
    results = []
    with tempfile.TemporaryDirectory(prefix="dyadfmu_scenes_") as tmp:
        work = Path(tmp)
        cache = {}
        for name in scenes.NAMES:
            log(f"measuring {name} (FMI {version})")
            mine = tailored(name, build, version, work, rows_count, repeat)
            full = []
            for dyad in scenes.FULL_OF[name]:
                if dyad not in cache:
                    cache[dyad] = generic(dyad, build, version, work, rows_count, repeat)
                full.append(cache[dyad])
            results.append((name, mine, full))
    return results

"""How close each way of calling the core comes to its floor, in one run: per dyad type the
closed forms' floating-point operations (counted atop ``src/dyad_<type>.c``) against those
the solve executes, its instructions, those of one FMU step from C (FMI 2 and 3) against
the bare core call inside it, those of a row of ``dyad_solve_batch``, and the time of a
row of :func:`dyadfmu.solve` from NumPy; and the step of every built-in scene FMU against
its model's evaluation. Instruction counts are callgrind's; times are the best of a few.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import time as clock
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.model_description import ModelDescription

from .. import paths
from ..batch import FIELDS, solve
from ..sweep.rows import LANES as LANE_NAMES
from . import bench, flops
from . import configurations as cfg
from . import floor as counted_floor

#: The speed targets: an FMU step and the solve's operations within twice their floor,
#: and this many rows a second from NumPy (RRR).
STEP_TARGET = 2.0
FLOPS_TARGET = 2.0
ROWS_PER_SECOND_TARGET = 10e6
#: A whole mechanism from NumPy (dyadfmu.evaluate) against the stacked NumPy solve.
NUMPY_RATIO_TARGET = 20.0
#: ... and against the time of the flops a scalar evaluation executes for the job (at the
#: RRR solve's rate): the lanes of the baseline CPU within this, those of AVX2 under 1.
BASELINE_FLOOR_TARGET = 1.5
#: Rows per timed call of dyadfmu.solve: inputs and outputs (about 4 MB) fit the caches,
#: so that the solve is timed and not the memory bus (as the study times the core).
NUMPY_ROWS = 10_000


@dataclass
class Step:
    """Instructions of one FMU step from C (set every input, doStep, get every Real
    output), inside it of the model's evaluation and of its angles' directions, and of
    the bare core call the step is held against: for a dyad the core's public solve
    (dyad_solve, which checks its input: the FMU checks each value where it is set and
    so evaluates without that check), for a scene its evaluation."""

    step: float
    evaluate: float
    directions: float
    bare: float
    #: a step whose get reads only the efforts and the pair reactions (a mechanism FMU
    #: leaves its effective inertia to their first read); NaN where not measured
    partial: float = math.nan

    @property
    def ratio(self) -> float:
        """Step over the bare core call."""
        return self.step / self.bare

    @property
    def ratio_with_directions(self) -> float:
        """Step over the core call from the FMU's own inputs: the angles' directions and
        the bare call."""
        return self.step / (self.bare + self.directions)


@dataclass
class TypeSpeed:
    """One dyad type's figures."""

    dyad: str
    closed_form_flops: int
    solve_flops: float
    solve_instructions: float
    steps: dict[int, Step] = field(default_factory=dict)
    batch_instructions: float = math.nan
    #: dyadfmu.solve's time per row, keyed by whether the outputs were reused (out=)
    numpy_seconds_per_row: dict[bool, float] = field(default_factory=dict)


@dataclass
class SceneSpeed:
    """One built-in scene FMU's step against its evaluation, per FMI version; for the
    mechanisms of BATCH_SCENES, ``dyadfmu.evaluate``'s CPU seconds per sample, by (batch
    size, whether every Real output is asked, else the efforts and reactions alone), and
    by (batch size, "numpy") the stacked NumPy solve of a chain (the yardstick), by (batch
    size, "avx2" or "baseline") the efforts and reactions in those lanes (this CPU's widest
    where not said), and by (batch size, "into", "avx2 into" or "baseline into") the same
    into an earlier call's arrays; ``flops``:
    the floating-point operations a step executes per sample, by whether every Real output
    is read (else the efforts and reactions alone)."""

    scene: str
    steps: dict[int, Step] = field(default_factory=dict)
    samples: dict = field(default_factory=dict)
    flops: dict[bool, float] = field(default_factory=dict)
    #: the widest lanes this CPU runs, where ``samples`` has (size, False) (LANES)
    lanes: str = "baseline"
    #: a plant (dynamics = "forward"): its step integrates its motion over many
    #: evaluations, so the step-to-evaluation rule is not its (dyadfmu plants measures it)
    plant: bool = False
    #: the job's closed-form floor per sample, counted (study.floor), where it is written
    counted: counted_floor.Floor | None = None


#: The mechanisms whose batch over arrays (dyadfmu.evaluate) is timed, and the batch sizes
#: (the quick study: the first two).
BATCH_SCENES = ("slider_crank", "four_bar", "shaper", "lift", "tipper")
BATCH_SIZES = (73, 10_000, 1_000_000)


def numpy_yardstick_seconds(scene: str, count: int, rounds: int) -> float:
    """CPU seconds per sample of the harness's stacked NumPy solve of a mechanism over
    ``count`` samples of a turn: its kinematics and the Newton-Euler equations of every
    body, one ``np.linalg.solve`` over the samples (a chain's ``chains.Chain.reference``,
    a built-in crank and dyad's ``driven.builtin_outputs``), the best of ``rounds``."""
    from ..cosim import mechanism_fmus
    from ..mechanisms import driven

    mechanism = mechanism_fmus.mechanism_of(scene)
    motion = mechanism.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration, count)
    if mechanism_fmus.MECHANISM_FMUS[scene][0] == "chain":
        solve_all = lambda: mechanism.reference(mechanism.kinematics(t, motion))  # noqa: E731
    else:
        text = mechanism_fmus.scene_file(scene).read_text(encoding="utf-8")
        kind = tomllib.loads(text)
        solve_all = lambda: driven.builtin_outputs(  # noqa: E731
            mechanism, mechanism.kinematics(t, motion), kind
        )
    best = math.inf
    for _ in range(rounds):
        started = clock.process_time()
        solve_all()
        best = min(best, clock.process_time() - started)
    return best / count


#: The lanes an FMU binary carries for x86-64 (fmu/README.md), by the name DYADFMU_LANES
#: takes (sweep/rows.py) and the CPU flag each needs (/proc/cpuinfo), the widest last.
LANES = dict(zip(LANE_NAMES, ("", "avx2", "avx512f"), strict=True))


def widest_lanes() -> str:
    """The widest of LANES this CPU runs (Linux: /proc/cpuinfo's flags; elsewhere, or on
    another CPU than x86-64, "baseline")."""
    try:
        flags = Path("/proc/cpuinfo").read_text().split()
    except OSError:
        return "baseline"
    if "flags" not in flags:  # not x86
        return "baseline"
    return [name for name, flag in LANES.items() if not flag or flag in flags][-1]


def batch_seconds(scene: str, count: int, kinds: dict, rounds: int) -> dict:
    """CPU seconds per sample of ``dyadfmu.evaluate`` on ``scene`` over ``count`` samples
    of its inputs swinging about their start values (step_rows), for each of ``kinds``:
    its key's (every, lanes, into), the best of ``rounds`` calls, the kinds called in turn
    in each round (a slow spell of this shared machine then slows one call of each, not
    every call of one). ``every``: every Real output asked, else the efforts and reactions
    alone. ``lanes``: in those of LANES at most (DYADFMU_LANES), else ("") in the widest
    this CPU runs. ``into``: each call writes into an earlier call's arrays (``out=``), as
    a sweep of many batches does, instead of new ones (whose pages the system clears on
    their first write)."""
    from ..mechanism_batch import evaluate

    md = read_model_description(str(paths.built_fmu(scene, 2)))
    inputs, outputs, rows = step_rows(md, count, seed=11)
    given = {v.name: rows[:, k] for k, v in enumerate(inputs)}
    asked = {e: [v.name for v in (outputs if e else efforts_and_reactions(outputs))]
             for e in (False, True)}  # fmt: skip
    evaluate(scene, {n: a[:1] for n, a in given.items()}, asked[True])  # loaded before timing
    # the arrays of an earlier call, for the kinds that write into them: one per outputs asked
    reused = sorted({every for every, _, into in kinds.values() if into})
    out = {every: evaluate(scene, given, asked[every]) for every in reused}
    best = dict.fromkeys(kinds, math.inf)
    saved = os.environ.pop("DYADFMU_LANES", None)
    try:
        for _ in range(rounds):
            for name, (every, lanes, into) in kinds.items():
                os.environ["DYADFMU_LANES"] = lanes
                started = clock.process_time()
                evaluate(scene, given, asked[every], out=out[every] if into else None)
                best[name] = min(best[name], clock.process_time() - started)
    finally:
        os.environ.pop("DYADFMU_LANES", None)
        if saved is not None:
            os.environ["DYADFMU_LANES"] = saved
    return {name: seconds / count for name, seconds in best.items()}


def rows_seconds(scene: str, count: int, rounds: int) -> float:
    """CPU seconds per sample of the FMU binary's rows entry (``dyadfmu_evaluate_rows``, a
    set and a get per row) over the samples batch_seconds times, asking the efforts and
    reactions: the best of ``rounds`` calls."""
    from ..sweep.rows import rows_entry

    entry = rows_entry(paths.built_fmu(scene, 2))
    inputs, outputs, rows = step_rows(entry.md, count, seed=11)
    x_names = tuple(v.name for v in inputs)
    asked = tuple(v.name for v in efforts_and_reactions(outputs))
    best = math.inf
    for _ in range(rounds):
        started = clock.process_time()
        entry.evaluate((), np.empty((count, 0)), x_names, rows, asked)
        best = min(best, clock.process_time() - started)
    return best / count


def opening_comment(dyad: str, root: Path | None = None) -> tuple[Path, str]:
    """The type's source file and its opening comment as one line of text."""
    source = (root or paths.ROOT) / "src" / f"dyad_{dyad.lower()}.c"
    header = source.read_text().split("*/", 1)[0]
    return source, " ".join(line.strip().lstrip("*").strip() for line in header.splitlines())


def closed_form_flops(dyad: str, root: Path | None = None) -> int:
    """The closed forms' count stated atop the type's source file ("Closed forms: N flops")."""
    source, text = opening_comment(dyad, root)
    match = re.search(r"Closed forms: (\d+) flops", text)
    if match is None:
        raise ValueError(f"{source}: no 'Closed forms: N flops' in its opening comment")
    return int(match.group(1))


def _callgrind(program: list[str], work: Path, toggle: str, per_instruction: bool) -> Path:
    out = work / "speed.callgrind"
    options = [f"--toggle-collect={toggle}"]
    options += ["--dump-instr=yes", "--dump-line=no"] if per_instruction else []
    done = subprocess.run(
        [
            "valgrind",
            "--tool=callgrind",
            *options,
            f"--callgrind-out-file={out}",
            *program,
        ],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0 or "Collected" not in done.stderr:
        raise RuntimeError(f"callgrind of {program[0]} failed: {done.stderr[-800:]}")
    return out


def _collected(out: Path) -> int:
    match = re.search(r"^(?:summary|totals):\s*(\d+)", out.read_text(), re.MULTILINE)
    return int(match.group(1)) if match else 0


def inclusive(out: Path, function: str) -> int:
    """Instructions inside `function` and what it calls, over a callgrind output."""
    done = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out)],
        capture_output=True,
        text=True,
    )
    pattern = re.compile(r"^\s*([\d,]+)\s.*:" + re.escape(function) + r"(\.part\.\d+)? ")
    return sum(
        int(m.group(1).replace(",", ""))
        for m in map(pattern.match, done.stdout.splitlines())
        if m is not None
    )


def core_counts(build: Path, dyad: str, rows: np.ndarray, work: Path) -> tuple[float, float]:
    """(floating-point operations, instructions) per solve of the core."""
    inputs = work / "speed_core.bin"
    rows.astype("<f8").tofile(inputs)
    program = [str(bench.bench_binary(build, "double"))]
    program += bench.bench_arguments(dyad, "core", inputs) + ["--repeat", "1"]
    out = _callgrind(program, work, "bench_loop_*", per_instruction=True)
    return flops.operations(out) / len(rows), _collected(out) / len(rows)


def step_rows(md: ModelDescription, count: int, seed: int) -> tuple[list, list, np.ndarray]:
    """An FMU's inputs, Real outputs and `count` rows of inputs swinging smoothly about
    their start values (an angle by 0.3 rad, a length by 10 %, others by 20 %): within
    the working range of the scenes' cylinders, whose chains close over a stroke of a
    few tens of percent of their length (an excavator's three)."""
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    outputs = [
        v for v in md.modelVariables if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * math.pi, count)
    rows = np.empty((count, len(inputs)))
    for k, v in enumerate(inputs):
        start = float(v.start) if v.start is not None else 0.0
        if v.unit == "rad":
            swing = 0.3
        elif v.unit == "m":
            swing = 0.1 * start
        else:
            swing = 0.2 * (abs(start) + 1.0)
        rows[:, k] = start + swing * np.sin(t + rng.uniform(0, 2 * math.pi))
    return inputs, outputs, rows


def efforts_and_reactions(outputs: list) -> list:
    """The outputs a step reading torques and bearing loads reads: every driver's effort
    (``*.torque``, ``*.force``) and every pair reaction (``*.R_*``)."""
    return [v for v in outputs if ".R_" in v.name or v.name.endswith((".torque", ".force"))]


def _step_instructions(
    build: Path,
    identifier: str,
    version: int,
    md: ModelDescription,
    rows: np.ndarray,
    work: Path,
    read: Callable[[list], list] | None = None,
) -> tuple[float, float]:
    """(instructions per step, of the evaluation inside it) over `rows`, the get reading
    every Real output or those ``read`` chooses of them."""
    inputs, outputs, _ = step_rows(md, 1, seed=version)
    outputs = read(outputs) if read else outputs
    data = work / "speed_fmu.bin"
    rows.astype("<f8").tofile(data)
    binary = paths.stage_binary(build, identifier, version)
    program = [str(bench.bench_binary(build, "double"))]
    program += bench.fmu_step_arguments(binary, version, md.guid, data, inputs, outputs)
    out = _callgrind(program + ["--repeat", "1"], work, "bench_loop_*", per_instruction=False)
    return _collected(out) / len(rows), inclusive(out, "evaluate") / len(rows)


def step_flops(build: Path, identifier: str, count: int, work: Path, every: bool) -> float:
    """Floating-point operations an FMU step from C executes (FMI 2, libm's among them),
    its get reading every Real output or the efforts and reactions alone: per sample, the
    arithmetic of the batch's job."""
    md = read_model_description(str(paths.built_fmu(identifier, 2, build)))
    inputs, outputs, rows = step_rows(md, count, seed=2)
    outputs = outputs if every else efforts_and_reactions(outputs)
    data = work / "speed_fmu.bin"
    rows.astype("<f8").tofile(data)
    binary = paths.stage_binary(build, identifier, 2)
    program = [str(bench.bench_binary(build, "double"))]
    program += bench.fmu_step_arguments(binary, 2, md.guid, data, inputs, outputs)
    out = _callgrind(program + ["--repeat", "1"], work, "bench_loop_*", per_instruction=True)
    return flops.operations(out) / len(rows)


def step_counts(build: Path, identifier: str, version: int, count: int, work: Path) -> Step:
    """Instructions per step of an FMU's binary from C, of its evaluation inside the step,
    and of its angles' directions: what the step costs more where every angle changes
    than where the angles are held (the layer converts an angle only when it changed)."""
    md = read_model_description(str(paths.built_fmu(identifier, version, build)))
    inputs, _, rows = step_rows(md, count, seed=version)
    step, evaluate = _step_instructions(build, identifier, version, md, rows, work)
    held = rows.copy()
    angles = [k for k, v in enumerate(inputs) if v.unit == "rad"]
    held[:, angles] = rows[0, angles]
    step_held, _ = _step_instructions(build, identifier, version, md, held, work)
    found = Step(step=step, evaluate=evaluate, directions=step - step_held, bare=evaluate)
    if any(v.name.endswith(".J") or v.name.startswith("M.") for v in md.modelVariables):
        read = efforts_and_reactions
        found.partial, _ = _step_instructions(build, identifier, version, md, rows, work, read)
    return found


def batch_keywords(rows: np.ndarray) -> dict[str, np.ndarray]:
    """The study's rows (dyad_input's 35 columns in order) as :func:`dyadfmu.solve`'s
    keywords."""
    out, c = {}, 0
    for name, width in FIELDS:
        out[name] = rows[:, c : c + width] if width == 2 else rows[:, c]
        c += width
    return out


def batch_instructions(build: Path, dyad: str, rows: np.ndarray, work: Path) -> float:
    """Instructions per row of one dyad_solve_batch call over `rows`, laid out as
    :func:`dyadfmu.solve` passes NumPy arrays (the benchmark's method batch)."""
    inputs = work / "speed_batch.bin"
    rows.astype("<f8").tofile(inputs)
    program = [str(bench.bench_binary(build, "double"))]
    program += bench.bench_arguments(dyad, "batch", inputs) + ["--repeat", "1"]
    out = _callgrind(program, work, "bench_loop_*", per_instruction=False)
    return _collected(out) / len(rows)


def numpy_seconds_per_row(dyad: str, rows: np.ndarray, repeat: int, reuse: bool) -> float:
    """Best time per row of :func:`dyadfmu.solve` over `rows` (arrays made beforehand), its
    outputs new on every call or, with `reuse`, written into the last call's (``out=``)."""
    keywords = {k: np.ascontiguousarray(v) for k, v in batch_keywords(rows).items()}
    out = solve(dyad, **keywords)  # warm: the library loaded, the pages touched
    best = math.inf
    for _ in range(repeat):
        started = clock.perf_counter()
        solve(dyad, out=out if reuse else None, **keywords)
        best = min(best, clock.perf_counter() - started)
    return best / len(rows)


def builtin_scenes(root: Path | None = None) -> list[str]:
    """The identifiers of the scene FMUs built from modelDescription/scenes/*.toml, the dyads
    excluded."""
    folder = (root or paths.ROOT) / "modelDescription" / "scenes"
    return sorted(p.stem for p in folder.glob("*.toml") if not p.stem.startswith("dyad_"))


def is_plant(scene: str, root: Path | None = None) -> bool:
    """Whether the scene file says dynamics = "forward" (its FMU integrates its motion)."""
    path = (root or paths.ROOT) / "modelDescription" / "scenes" / f"{scene}.toml"
    with path.open("rb") as handle:
        return tomllib.load(handle).get("scene", {}).get("dynamics") == "forward"


def _time_numpy(types: list[TypeSpeed], rows_of: dict, quick: bool) -> None:
    """dyadfmu.solve's best time per row, over rounds that visit every type in turn: a
    spell in which this shared machine runs slow (it happens, for a second or so) spoils
    one round of one type, not the figure."""
    for _ in range(2 if quick else 5):
        for figures in types:
            many = np.resize(rows_of[figures.dyad], (NUMPY_ROWS, len(cfg.COLUMNS)))
            for reuse in (False, True):
                seconds = numpy_seconds_per_row(figures.dyad, many, 21 if quick else 41, reuse)
                best = figures.numpy_seconds_per_row.get(reuse, math.inf)
                figures.numpy_seconds_per_row[reuse] = min(best, seconds)


def measure(
    build: Path, work: Path, quick: bool, log: Callable = print
) -> tuple[list[TypeSpeed], list[SceneSpeed]]:
    """Every figure of the speed table, per type and per built-in scene."""
    if shutil.which("valgrind") is None:
        raise RuntimeError("valgrind is missing (apt-get install valgrind): the speed table")
    steps, batch_rows = (300, 2000) if quick else (2000, 20_000)
    types, rows_of = [], {}
    for t_index, dyad in enumerate(cfg.TYPES):
        log(f"speed: {dyad}")
        rows = rows_of[dyad] = cfg.random_set(dyad, max(batch_rows, 2000), seed=100 + t_index)
        solve_flops, solve_instructions = core_counts(build, dyad, rows[:2000], work)
        figures = TypeSpeed(dyad, closed_form_flops(dyad), solve_flops, solve_instructions)
        for version in (2, 3):
            step = step_counts(build, f"dyad_{dyad.lower()}", version, steps, work)
            figures.steps[version] = replace(step, bare=solve_instructions)
        figures.batch_instructions = batch_instructions(build, dyad, rows[:batch_rows], work)
        types.append(figures)
    log("speed: dyadfmu.solve timed")
    _time_numpy(types, rows_of, quick)
    scenes = []
    for scene in builtin_scenes():
        log(f"speed: scene {scene}")
        scenes.append(
            SceneSpeed(
                scene,
                {v: step_counts(build, scene, v, steps, work) for v in (2, 3)},
                plant=is_plant(scene),
            )
        )
        if scene in counted_floor.MECHANISMS:
            scenes[-1].counted = counted_floor.floor(scene)
        if scene in BATCH_SCENES:
            _batch_figures(scenes[-1], build, steps, work, quick)
    if not quick:
        # A second pass minutes after the first, each figure the better of the two: a slow
        # spell of this shared machine (seconds long) can spoil every round of one scene's
        # batch, or of the solve whose rate the floors take, but not both passes.
        log("speed: a second pass of the timings")
        _time_numpy(types, rows_of, quick)
        for figures in scenes:
            if figures.scene in BATCH_SCENES:
                _time_batch(figures, quick)
    return types, scenes


def _batch_figures(figures: SceneSpeed, build: Path, steps: int, work: Path, quick: bool) -> None:
    """A mechanism's batch over arrays (BATCH_SCENES): the flops a step executes, and
    dyadfmu.evaluate, the rows entry and the stacked NumPy solve timed per sample."""
    for every in (False, True):
        figures.flops[every] = step_flops(build, figures.scene, steps, work, every)
    figures.lanes = widest_lanes()
    _time_batch(figures, quick)


def _time_batch(figures: SceneSpeed, quick: bool) -> None:
    """figures.samples: each way of calling the mechanism's batch, CPU seconds per sample,
    the better of this call's figure and an earlier call's."""
    scene = figures.scene
    narrower = list(LANES)[: list(LANES).index(figures.lanes)]
    rounds = 5  # the best of five: one or two calls of a million samples met slow spells
    kinds = {False: (False, "", False), True: (True, "", False), "into": (False, "", True)}
    for lanes in narrower:
        kinds[lanes] = (False, lanes, False)
        kinds[f"{lanes} into"] = (False, lanes, True)
    timed = {}
    for count in BATCH_SIZES[:2] if quick else BATCH_SIZES:
        for kind, seconds in batch_seconds(scene, count, kinds, rounds).items():
            timed[count, kind] = seconds
        timed[count, "rows"] = rows_seconds(scene, count, rounds)
        if count <= 10_000:  # the stacked solve's matrices: 1e6 x 9 x 9 is 650 MB
            timed[count, "numpy"] = numpy_yardstick_seconds(scene, count, rounds)
    for key, seconds in timed.items():
        figures.samples[key] = min(seconds, figures.samples.get(key, math.inf))

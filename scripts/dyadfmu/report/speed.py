"""The study report's speed tables: each way of calling the core against its floor
(:mod:`dyadfmu.study.speed`), with the targets marked met or not, and their CSV."""

from __future__ import annotations

import csv
import math
from collections.abc import Callable
from pathlib import Path

from ..study.speed import (
    BASELINE_FLOOR_TARGET,
    FLOPS_TARGET,
    LANES,
    NUMPY_RATIO_TARGET,
    ROWS_PER_SECOND_TARGET,
    STEP_TARGET,
    SceneSpeed,
    TypeSpeed,
)
from . import markdown as markup


def _mark(met: bool) -> str:
    return "met" if met else "**not met**"


def _both(two: float, three: float, digits: int = 2) -> str:
    """An FMI 2 figure and its FMI 3 twin."""
    return f"{two:.{digits}f} / {three:.{digits}f}"


def _per_row(seconds: float) -> str:
    return f"{seconds * 1e9:.0f} ns ({1 / seconds / 1e6:.1f} M/s)"


#: The dyad types' table: its header and alignment.
TYPE_HEADER = (
    "type",
    "closed-form flops",
    "flops per solve (ratio)",
    "instructions per solve",
    "per FMU step, FMI 2 / 3",
    "its evaluation",
    "step / solve",
    "step / (solve + directions)",
    "per batch row",
    "NumPy per row, new outputs",
    "NumPy per row, out=",
)
#: The scenes' table: its header.
SCENE_HEADER = (
    "scene",
    "per step, FMI 2 / 3",
    "evaluation",
    "directions",
    "step / evaluation",
    "step / (evaluation + directions)",
    "per step reading efforts and reactions only, FMI 2 / 3",
)


def _type_rows(types: list[TypeSpeed]) -> list[str]:
    rows = []
    for t in types:
        two, three = t.steps[2], t.steps[3]
        rows.append(
            [
                t.dyad,
                str(t.closed_form_flops),
                f"{t.solve_flops:.0f} ({t.solve_flops / t.closed_form_flops:.2f})",
                f"{t.solve_instructions:.0f}",
                _both(two.step, three.step, 0),
                f"{two.evaluate:.0f}",
                _both(two.ratio, three.ratio),
                _both(two.ratio_with_directions, three.ratio_with_directions),
                f"{t.batch_instructions:.0f}",
                _per_row(t.numpy_seconds_per_row[False]),
                _per_row(t.numpy_seconds_per_row[True]),
            ]
        )
    return markup.table(TYPE_HEADER, rows, "-" + "r" * (len(TYPE_HEADER) - 1))


def _scene_rows(scenes: list[SceneSpeed]) -> list[str]:
    rows = []
    for s in scenes:
        two, three = s.steps[2], s.steps[3]
        rows.append(
            [
                s.scene,
                _both(two.step, three.step, 0),
                f"{two.evaluate:.0f}",
                f"{two.directions:.0f}",
                _both(two.ratio, three.ratio),
                _both(two.ratio_with_directions, three.ratio_with_directions),
                _partial(two, three),
            ]
        )
    return markup.table(SCENE_HEADER, rows, "-" + "r" * (len(SCENE_HEADER) - 1))


#: The table of whole mechanisms over arrays: its header.
BATCH_HEADER = (
    "mechanism",
    "samples",
    "flops per sample: efforts and reactions / every output (their time at the RRR solve's rate)",
    "efforts and reactions, CPU per sample, this CPU's widest lanes (to that time)",
    "the same in AVX2's / the baseline's lanes (to that time)",
    "the same three into an earlier call's arrays (out=)",
    "every output, CPU per sample (to that time)",
    "efforts and reactions through the rows entry, CPU per sample",
    "stacked NumPy Newton-Euler, CPU per sample (its ratio)",
    "counted closed-form floor per sample: with the dyads' closed forms as stated "
    "/ the minimal evaluation's, flops (their time at that rate; the widest lanes' time to each)",
)
#: How the report names each of the lanes (study.speed.LANES).
LANE_NAMES = {"baseline": "the baseline's", "avx2": "AVX2's", "avx512": "AVX-512's"}


def _lane_kinds(s: SceneSpeed, into: bool = False) -> dict[str, object]:
    """Per lanes timed, widest first, the key of their time in ``s.samples``: the widest
    this CPU runs under False (or "into"), the others under their names."""
    names = list(LANES)[: list(LANES).index(s.lanes) + 1]
    kinds = {name: f"{name} into" if into else name for name in names}
    kinds[s.lanes] = "into" if into else False
    return dict(reversed(kinds.items()))


def _ns(seconds: float) -> str:
    return "-" if math.isnan(seconds) else f"{seconds * 1e9:.0f} ns"


def _to_floor(seconds: float, floor: float) -> str:
    return f"{_ns(seconds)} ({seconds / floor:.1f}x)" if floor > 0 else _ns(seconds)


def _batch_rows(types: list[TypeSpeed], scenes: list[SceneSpeed]) -> list[str]:
    """dyadfmu.evaluate per sample, where it was timed, against the flops a step executes
    for the job at the rate the RRR solve executes its own; none timed: no table."""
    rate = _rate(types)
    rows = []
    for s in scenes:
        some_flops, every_flops = s.flops.get(False, math.nan), s.flops.get(True, math.nan)
        floor = {False: some_flops / rate, True: every_flops / rate}
        work = f"{some_flops:.0f} / {every_flops:.0f} ({_ns(floor[False])} / {_ns(floor[True])})"
        for count in sorted({c for c, _ in s.samples}):
            numpy = s.samples.get((count, "numpy"), math.nan)
            some = s.samples[count, False]
            yardstick = "-" if math.isnan(numpy) else f"{_ns(numpy)} ({numpy / some:.1f}x)"
            narrower = [
                s.samples.get((count, kind), math.nan)
                for kind in _narrower(s, ("avx2", "baseline"))
            ]
            into = [s.samples.get((count, k), math.nan) for k in _lane_kinds(s, into=True).values()]
            times = [_to_floor(some, floor[False])]
            times.append(" / ".join(_to_floor(t, floor[False]) for t in narrower))
            times.append(" / ".join(_to_floor(t, floor[False]) for t in into))
            times.append(_to_floor(s.samples[count, True], floor[True]))
            times += [_ns(s.samples.get((count, "rows"), math.nan)), yardstick]
            times.append(_counted_cell(s, rate, some))
            rows.append([s.scene, f"{count:,}", work, *times])
    if not rows:
        return []
    return ["", *markup.table(BATCH_HEADER, rows, "-" + "r" * (len(BATCH_HEADER) - 1))]


def _counted_cell(s: SceneSpeed, rate: float, seconds: float) -> str:
    """The counted floor (study.floor) of a mechanism, the stated and the minimal, and
    their time at ``rate`` (flops per second); the batch's time to each."""
    if s.counted is None:
        return "-"
    stated, minimal = s.counted.stated_total / rate, s.counted.total / rate
    return (
        f"{s.counted.stated_total} / {s.counted.total} ({_ns(stated)} / {_ns(minimal)}; "
        f"{seconds / stated:.1f}x / {seconds / minimal:.1f}x)"
    )


def _partial(two: object, three: object) -> str:
    """A step reading only efforts and reactions, and its share of the whole step."""
    if math.isnan(two.partial):
        return "-"
    return f"{_both(two.partial, three.partial, 0)} ({two.partial / two.step:.2f})"


def _targets(types: list[TypeSpeed], scenes: list[SceneSpeed]) -> list[str]:
    steps = [s for t in types for s in t.steps.values()]
    steps += [s for scene in scenes if not scene.plant for s in scene.steps.values()]
    flops = max(t.solve_flops / t.closed_form_flops for t in types)
    worst_step = max(s.ratio for s in steps)
    worst_with_directions = max(s.ratio_with_directions for s in steps)
    rrr = next(t for t in types if t.dyad == "RRR")
    rate = 1 / rrr.numpy_seconds_per_row[True]
    return [
        "",
        f"- Solve within {FLOPS_TARGET:g}x its closed forms' operations: worst "
        f"{flops:.2f}x, {_mark(flops <= FLOPS_TARGET)}.",
        f"- FMU step within {STEP_TARGET:g}x the bare core call (a dyad's solve, a scene's "
        "evaluation; a plant's step integrates its motion, `dyadfmu plants` measures it): "
        f"worst {worst_step:.2f}x, {_mark(worst_step <= STEP_TARGET)}; counting the "
        f"directions of the angle inputs (dyadfmu/angle.h) with the call, worst "
        f"{worst_with_directions:.2f}x, {_mark(worst_with_directions <= STEP_TARGET)}.",
        f"- RRR from NumPy (outputs reused): {rate / 1e6:.1f} M rows/s against "
        f"{ROWS_PER_SECOND_TARGET / 1e6:g} M, "
        f"{_mark(rate >= ROWS_PER_SECOND_TARGET)}.",
        *_numpy_ratio_target(scenes),
        *_floor_targets(types, scenes),
        *_counted_targets(types, scenes),
    ]


def _narrower(s: SceneSpeed, names: tuple[str, ...]) -> list[object]:
    """The keys in ``s.samples`` of the lanes ``names`` (each its own where it is not the
    widest this CPU runs, False where it is, and none where it is wider)."""
    kinds = _lane_kinds(s)
    return [kinds.get(name, "none") for name in names]


def _rate(types: list[TypeSpeed]) -> float:
    """Flops per CPU second of the RRR solve from NumPy (outputs reused); NaN without it."""
    rrr = next((t for t in types if t.dyad == "RRR"), None)
    return rrr.solve_flops / rrr.numpy_seconds_per_row[True] if rrr else math.nan


Worst = dict[tuple[str, bool], tuple[float, str]]


def _worst(timed: list[SceneSpeed], floor_of: Callable[[SceneSpeed], float]) -> Worst:
    """Per (lanes, into) the worst mechanism's batch time (efforts and reactions, at the
    largest batch timed) over its floor's time ``floor_of``, and where."""
    worst: Worst = {}
    for s in timed:
        count = max(c for c, k in s.samples if k is False)
        for into in (False, True):
            for name, kind in _lane_kinds(s, into).items():
                ratio = s.samples.get((count, kind), math.nan) / floor_of(s)
                worst[name, into] = max(
                    worst.get((name, into), (0.0, "")), (ratio, f"{s.scene}, {count:,} samples")
                )
    return worst


def _figure(worst: Worst, name: str, into: bool = False) -> str:
    ratio, where = worst.get((name, into), (math.nan, ""))
    return f"{ratio:.2f}x ({where})" if where else "not timed (this CPU has none)"


def _ratio(worst: Worst, name: str) -> float:
    return worst.get((name, False), (math.nan, ""))[0]


def _lane_targets(worst: Worst, widest: str, against: str) -> list[str]:
    """The target lines against one floor: the baseline's lanes within
    BASELINE_FLOOR_TARGET, AVX2's under 1, this CPU's widest (where wider) under 1 too,
    and the same into an earlier call's arrays."""
    lines = [
        f"- A whole mechanism's batch (the efforts and reactions) against {against}: in the "
        f"baseline's lanes within {BASELINE_FLOOR_TARGET:g}x, worst "
        f"{_figure(worst, 'baseline')}, {_mark(_ratio(worst, 'baseline') <= BASELINE_FLOOR_TARGET)}"
        f"; in AVX2's under 1x, worst {_figure(worst, 'avx2')}, "
        f"{_mark(_ratio(worst, 'avx2') < 1)}."
    ]
    if list(LANES).index(widest) > list(LANES).index("avx2"):
        lines.append(
            f"  In this CPU's widest, {LANE_NAMES[widest]}, under 1x: worst "
            f"{_figure(worst, widest)}, {_mark(_ratio(worst, widest) < 1)}."
        )
    into = ", ".join(
        f"{LANE_NAMES[name]} {_figure(worst, name, True)}"
        for name in reversed(list(LANES))
        if (name, True) in worst
    )
    lines.append(f"  Into an earlier call's arrays (`out=`), worst: {into}.")
    return lines


def _timed(scenes: list[SceneSpeed]) -> list[SceneSpeed]:
    return [s for s in scenes if any(k is False for _, k in s.samples)]


def _floor_targets(types: list[TypeSpeed], scenes: list[SceneSpeed]) -> list[str]:
    """The target lines of a whole mechanism's batch (efforts and reactions) against the
    time of the flops a scalar evaluation executes for them, at the largest batch timed:
    the baseline's lanes within BASELINE_FLOOR_TARGET, AVX2's under 1, and this CPU's
    widest (where wider than AVX2) against 1 too; the worst mechanism of each."""
    timed = [s for s in _timed(scenes) if s.flops.get(False)]
    rate = _rate(types)
    if math.isnan(rate) or not timed:
        return []
    worst = _worst(timed, lambda s: s.flops[False] / rate)
    widest = max((s.lanes for s in timed), key=list(LANES).index)
    against = "the time of the flops a scalar evaluation executes for them"
    return _lane_targets(worst, widest, against)


def _counted_targets(types: list[TypeSpeed], scenes: list[SceneSpeed]) -> list[str]:
    """The same target lines against the counted closed-form floor (study.floor: the
    stated count, the dyads' closed forms as stated atop src/) at the same rate, and
    the worst batch against the minimal evaluation's count beside them."""
    timed = [s for s in _timed(scenes) if s.counted is not None]
    rate = _rate(types)
    if math.isnan(rate) or not timed:
        return []
    worst = _worst(timed, lambda s: s.counted.stated_total / rate)
    widest = max((s.lanes for s in timed), key=list(LANES).index)
    against = "the time of its counted closed-form floor (`dyadfmu.study.floor`)"
    minimal = _worst(timed, lambda s: s.counted.total / rate)
    return [
        *_lane_targets(worst, widest, against),
        f"  Against the minimal evaluation's count instead, worst: the baseline's "
        f"{_figure(minimal, 'baseline')}, AVX2's {_figure(minimal, 'avx2')}.",
    ]


def _numpy_ratio_target(scenes: list[SceneSpeed]) -> list[str]:
    """The target line of a whole mechanism from NumPy against the stacked NumPy solve,
    at the largest batch the yardstick ran: the worst mechanism; none where none ran."""
    ratios = {}
    for s in scenes:
        counts = [c for c, kind in s.samples if kind == "numpy"]
        if counts:
            count = max(counts)
            ratios[s.scene] = (s.samples[count, "numpy"] / s.samples[count, False], count)
    if not ratios:
        return []
    worst = min(ratios, key=lambda name: ratios[name][0])
    ratio, count = ratios[worst]
    return [
        f"- A whole mechanism from NumPy (`dyadfmu.evaluate`, the efforts and reactions) "
        f"at least {NUMPY_RATIO_TARGET:g}x faster than the stacked NumPy solve: worst "
        f"{ratio:.1f}x ({worst}, {count:,} samples), {_mark(ratio >= NUMPY_RATIO_TARGET)}."
    ]


def markdown(types: list[TypeSpeed], scenes: list[SceneSpeed]) -> list[str]:
    """The report's section on speed against the floors."""
    if not types:
        return []
    return [
        "",
        "## Speed against the floors",
        "",
        "Instructions are callgrind's: per solve of the core, per FMU step from C (every input "
        "set, doStep, every Real output read), held against the bare core call: for a dyad "
        "the core's `dyad_solve`, which checks its input (the FMU checks each value where it "
        "is set, and its evaluation inside the step solves without that check), for a scene "
        "its evaluation. The directions are the unit vectors of the angles that changed. Per "
        "row of "
        "`dyad_solve_batch` (one call over rows laid out as `dyadfmu.solve` passes them). "
        "Flops: adds, "
        "subtracts, multiplies, divides and square roots executed, against the closed forms' "
        "count atop `src/dyad_<type>.c`. Time per row: the best call of `dyadfmu.solve` on "
        "contiguous arrays of 10,000 rows (they fit the caches), over rounds that visit "
        "every type in turn (this shared machine has slow spells), its outputs new on every "
        "call or written into the last call's (`out=`). A mechanism FMU computes its "
        "effective inertia (J, M(q), the efforts at zero acceleration: a kinematic pass of "
        "their own) only when they are read: its step is also counted with a get of the "
        "drivers' efforts and the pair reactions alone. A whole mechanism over NumPy arrays "
        "(`dyadfmu.evaluate`, through the FMU binary's columns entry): the CPU time per sample, "
        "the best of five calls, asking the efforts and the reactions or every output, in "
        "the widest lanes this CPU runs and capped at AVX2's and the baseline's "
        "(`DYADFMU_LANES`, fmu/README.md), each way of a size called once a round in turn; "
        "without `--quick`, these times and those of `dyadfmu.solve` are each the better of "
        "two passes minutes apart; "
        "the same samples through its rows entry (a set and "
        "a get per sample); against "
        "the harness's stacked NumPy solve of the mechanism (its kinematics and every body's "
        "Newton-Euler equations, one `np.linalg.solve` over the samples), the yardstick. Beside "
        "them the flops an FMU step executes for the job (callgrind, libm's among them) and "
        "their time at the rate `dyadfmu.solve` executes the RRR solve's own (flops per CPU "
        "second): a time near it says the evaluation is bound by the arithmetic it does. "
        "Last, the job's closed-form floor counted per mechanism (`dyadfmu.study.floor`, "
        "checked against the Newton-Euler reference): the stated count, with each dyad's "
        "closed forms as stated atop `src/dyad_<type>.c`, and a minimal evaluation's, their "
        "time at the same rate.",
        "",
        *_type_rows(types),
        "",
        *_scene_rows(scenes),
        *_batch_rows(types, scenes),
        *_targets(types, scenes),
    ]


def write_csv(path: Path, types: list[TypeSpeed], scenes: list[SceneSpeed]) -> None:
    """speed.csv: one row per type and FMI version, and per scene and FMI version."""
    with path.open("w", newline="") as handle:
        out = csv.writer(handle)
        out.writerow(
            [
                "what",
                "fmi",
                "closed_form_flops",
                "flops_per_solve",
                "instructions_per_solve",
                "instructions_per_step",
                "instructions_per_evaluation",
                "instructions_per_step_in_directions",
                "instructions_per_batch_row",
                "numpy_seconds_per_row",
                "numpy_seconds_per_row_out",
                "instructions_per_step_reading_efforts_and_reactions",
            ]
        )
        for t in types:
            for version, s in t.steps.items():
                out.writerow(
                    [t.dyad, version, t.closed_form_flops, f"{t.solve_flops:.1f}"]
                    + [f"{t.solve_instructions:.1f}", f"{s.step:.1f}", f"{s.evaluate:.1f}"]
                    + [f"{s.directions:.1f}", f"{t.batch_instructions:.1f}"]
                    + [f"{t.numpy_seconds_per_row[False]:.4g}"]
                    + [f"{t.numpy_seconds_per_row[True]:.4g}", ""]
                )
        for scene in scenes:
            for version, s in scene.steps.items():
                out.writerow(
                    [scene.scene, version, "", "", "", f"{s.step:.1f}", f"{s.evaluate:.1f}"]
                    + [f"{s.directions:.1f}", "", "", ""]
                    + ["" if math.isnan(s.partial) else f"{s.partial:.1f}"]
                )

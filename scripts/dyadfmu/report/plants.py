"""What a plant's integration costs: the forward FMUs (``dynamics = "forward"``) driven
by a torque or by a motor's voltage, with the slow motor (L / R near a millisecond) and
the stiff one (L / R = 1e-6 s, its current on its slow manifold), the method the plant
chooses and the Rosenbrock method kept throughout (``solver.explicit_limit = 0``). For
each case: internal steps, evaluations of the equation of motion and Jacobians per
millisecond of motion, and under callgrind the instructions of an evaluation, of a
Jacobian, of the inverse scene's evaluation inside them (the inverse step), and per
millisecond of motion; then the evaluations per millisecond against the communication
step. Writes
``<out>/plants/report.md``, ``points.csv`` and ``cost_vs_step.png``.

Command line (the ``dyadfmu plants`` subcommand calls :func:`main`)::

    python -m dyadfmu.report.plants [--quick] [--out DIR] [--build DIR]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
import shutil
import subprocess
import sys
import tempfile
import time as clock
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

from fmpy import read_model_description

from .. import paths
from ..fmi.slave import Slave
from . import markdown as markup

#: Communication steps of the cost sweep [s].
STEPS = (1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: The communication step of the cost table [s].
TABLE_STEP = 1e-3
#: The issue's targets, evaluations per ms: torque-driven, motor with L = 1e-3 H.
TARGETS = {"torque": 30.0, "motor": 200.0}


@dataclass(frozen=True)
class Case:
    """A plant run: the FMU, its inputs and parameters held over `stop` seconds."""

    label: str
    identifier: str
    inputs: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)
    stop: float = 1.0
    #: the target it is held to (a key of TARGETS), if any
    target: str = ""
    #: the crank whose turns the cost is also counted over
    crank: str = "crank"


#: slider_crank_motor's armature resistance [ohm] (its scene file's [motor])
SLIDER_CRANK_RESISTANCE = 0.725
#: leg_motor's (its scene file's [motor])
LEG_RESISTANCE = 1.2
#: the leg's rear hip torque that holds it with its foot loaded at mid-range [N m]
LEG_LOAD = {"foot.force.x": 0.0, "foot.force.y": 30.0}

#: The cases the comparison of methods reads.
SLOW = "slider-crank, motor L/R 1.4 ms, 290 V from rest"
RODASP_THROUGHOUT = "the same, RODASP throughout"
STIFF = "slider-crank, motor L/R 1 us, 290 V from rest"

CASES = (
    Case(
        "slider-crank, 2 N.m from 100 rad/s",
        "slider_crank_forward",
        {"crank.torque": 2.0},
        {"crank.omega_start": 100.0},
        target="torque",
    ),
    Case(
        SLOW,
        "slider_crank_motor",
        {"crank.motor.voltage": 290.0},
        target="motor",
    ),
    Case(
        RODASP_THROUGHOUT,
        "slider_crank_motor",
        {"crank.motor.voltage": 290.0},
        {"solver.explicit_limit": 0.0},
    ),
    Case(
        STIFF,
        "slider_crank_motor",
        {"crank.motor.voltage": 290.0},
        {"crank.motor.inductance": SLIDER_CRANK_RESISTANCE * 1e-6},
    ),
    Case(
        "leg, front hip's motor L/R 0.83 ms, 12 V",
        "leg_motor",
        {"front.motor.voltage": 12.0, **LEG_LOAD},
        {"front.motor.current_start": 12.0 / LEG_RESISTANCE},
        stop=0.1,
        target="motor",
        crank="front",
    ),
    Case(
        "leg, front hip's motor L/R 1 us, 12 V",
        "leg_motor",
        {"front.motor.voltage": 12.0, **LEG_LOAD},
        {
            "front.motor.current_start": 12.0 / LEG_RESISTANCE,
            "front.motor.inductance": LEG_RESISTANCE * 1e-6,
        },
        stop=0.1,
        crank="front",
    ),
)


def drive(fmu: str, case: dict, step: float, stop: float) -> dict:
    """Run the plant over `stop` seconds at communication steps of `step`: its counters
    at the end, per millisecond of motion, and its crank's turns."""
    slave = Slave(fmu)
    angle = f"{case['crank']}.angle"
    try:
        if case["inputs"]:
            slave.set(tuple(case["inputs"]), list(case["inputs"].values()))
        slave.initialize(case["parameters"])
        (start,) = slave.get((angle,))
        steps = int(round(stop / step))
        for k in range(steps):
            slave.do_step(k * step, step)
        names = ("solver.steps", "solver.evaluations", angle)
        counted = dict(zip(names, slave.get(names), strict=True))
    finally:
        slave.close()
    ms = 1e3 * steps * step
    return {
        "steps_per_ms": counted[names[0]] / ms,
        "evaluations_per_ms": counted[names[1]] / ms,
        "turns": abs(counted[angle] - start) / (2 * math.pi),
    }


def _callgrind_calls(out: Path) -> dict[str, int]:
    """Calls of each function in a callgrind output file, by the function's name."""
    names: dict[str, str] = {}
    calls: dict[str, int] = {}
    callee = ""
    for line in out.read_text(errors="replace").splitlines():
        found = re.match(r"c?fn=\((\d+)\)(?: (.*))?", line)
        if found:
            if found.group(2):
                names[found.group(1)] = found.group(2)
            if line.startswith("cfn="):
                callee = names.get(found.group(1), "")
        elif line.startswith("calls=") and callee:
            calls[callee] = calls.get(callee, 0) + int(line[6:].split()[0])
    return calls


def _inclusive(out: Path) -> dict[str, int]:
    """Inclusive instructions of each function of the FMU's binary, by name."""
    text = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    found: dict[str, int] = {}
    for count, name in re.findall(r"^\s*([\d,]+)\s.*\?\?\?:(\w+)[\s.]", text, re.MULTILINE):
        found.setdefault(name, int(count.replace(",", "")))
    return found


def instructions(fmu: str, case: Case, stop: float, work: Path) -> dict:
    """Under callgrind: instructions per evaluation, per Jacobian, per inverse step and
    per ms of motion, and Jacobians per ms (NaN without valgrind)."""
    figures = dict.fromkeys(
        ("per_evaluation", "per_jacobian", "per_inverse_step", "per_ms", "jacobians_per_ms"),
        math.nan,
    )
    if shutil.which("valgrind") is None or shutil.which("callgrind_annotate") is None:
        return figures
    out = work / "callgrind.out"
    code = (
        "import json, sys; from dyadfmu.report.plants import drive; "
        "drive(sys.argv[1], json.loads(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]))"
    )
    subprocess.run(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, "-c"]
        + [code, fmu, json.dumps(asdict(case)), str(TABLE_STEP), str(stop)],
        capture_output=True,
        check=True,
    )
    calls, inclusive = _callgrind_calls(out), _inclusive(out)
    scene = f"{case.identifier}_evaluate"
    ms = 1e3 * stop
    for key, name in (("per_evaluation", "rhs"), ("per_jacobian", "jacobian")):
        if calls.get(name):
            figures[key] = inclusive.get(name, math.nan) / calls[name]
    if calls.get(scene):
        figures["per_inverse_step"] = inclusive.get(scene, math.nan) / calls[scene]
    figures["per_ms"] = inclusive.get("fmu_do_step", math.nan) / ms
    figures["jacobians_per_ms"] = calls.get("jacobian", 0) / ms
    return figures


def _stop(case: Case, quick: bool) -> float:
    return min(case.stop, 0.2) if quick else case.stop


def measure(
    build: Path | None, quick: bool, log: Callable[[str], None]
) -> tuple[list[dict], list[dict]]:
    """(the cost table's rows at TABLE_STEP, the sweep's rows over STEPS)."""
    table, sweep = [], []
    with tempfile.TemporaryDirectory() as folder:
        for number, case in enumerate(CASES, start=1):
            fmu = str(paths.built_fmu(case.identifier, 2, build))
            stop = _stop(case, quick)
            log(f"[{number}/{len(CASES)}] {case.label}: {stop:g} s of motion")
            row = {"case": case.label, "fmu": case.identifier, "stop": stop}
            row.update(drive(fmu, asdict(case), TABLE_STEP, stop))
            row.update(instructions(fmu, case, stop, Path(folder)))
            table.append(row)
            for step in STEPS if not quick else STEPS[1:]:
                point = {"case": case.label, "step": step}
                sweep.append(point | drive(fmu, asdict(case), step, stop))
    return table, sweep


def _f(value: float, digits: int = 1) -> str:
    return "n/a" if not math.isfinite(value) else f"{value:,.{digits}f}"


def _table_lines(table: list[dict]) -> list[str]:
    header = (
        "case",
        "crank turns",
        "steps/ms",
        "evaluations/ms",
        "Jacobians/ms",
        "instr./evaluation",
        "instr./Jacobian",
        "instr./inverse step",
        "instr./ms of motion",
    )
    rows = [
        [
            r["case"],
            _f(r["turns"], 2),
            _f(r["steps_per_ms"], 2),
            _f(r["evaluations_per_ms"]),
            _f(r["jacobians_per_ms"], 2),
            _f(r["per_evaluation"], 0),
            _f(r["per_jacobian"], 0),
            _f(r["per_inverse_step"], 0),
            _f(r["per_ms"], 0),
        ]
        for r in table
    ]
    return markup.table(header, rows, "lrrrrrrrr")


def _target_lines(table: list[dict]) -> list[str]:
    """Each target against what its case measured."""
    lines = []
    for r, case in zip(table, CASES, strict=True):
        if case.target:
            bound = TARGETS[case.target]
            held = "met" if r["evaluations_per_ms"] <= bound else "NOT met"
            lines.append(
                f"- {markup.text(case.label)}: {r['evaluations_per_ms']:.1f} evaluations per ms "
                f"(target at most {bound:g}): {held}."
            )
    by = {c.label: r for c, r in zip(CASES, table, strict=True)}
    slow, kept, stiff = (by[label] for label in (SLOW, RODASP_THROUGHOUT, STIFF))
    held = "met" if stiff["evaluations_per_ms"] <= slow["evaluations_per_ms"] else "NOT met"
    lines.append(
        f"- The stiff motor (L/R 1 us) takes {stiff['evaluations_per_ms']:.1f} evaluations "
        f"per ms ({_f(stiff['per_ms'], 0)} instructions), the slow motor "
        f"{slow['evaluations_per_ms']:.1f} ({_f(slow['per_ms'], 0)}): DOP853 takes both, "
        "the stiff circuit's current on its slow manifold (an evaluation there adds a "
        "directional derivative of the inverse scene, for the manifold's third term), and "
        "RODASP only through a transient where the current is off it and the transient's "
        "closed form does not hold (here the start from rest). Target, no more "
        f"evaluations than on the slow motor: {held}. RODASP throughout on the slow motor: "
        f"{kept['evaluations_per_ms']:.1f} ({_f(kept['per_ms'], 0)} instructions)."
    )
    return lines


def plot(path: Path, sweep: list[dict]) -> Path:
    """Evaluations per ms against the communication step, one line per case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    for case in CASES:
        points = [p for p in sweep if p["case"] == case.label]
        xs = [p["step"] for p in points]
        ax.loglog(xs, [p["evaluations_per_ms"] for p in points], "o-", label=case.label)
    ax.set_xlabel("communication step [s]")
    ax.set_ylabel("evaluations per ms of motion")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _sweep_lines(sweep: list[dict]) -> list[str]:
    steps = sorted({p["step"] for p in sweep})
    header = ("case", *(f"{s:g} s" for s in steps))
    rows = []
    for case in CASES:
        cost = {p["step"]: p["evaluations_per_ms"] for p in sweep if p["case"] == case.label}
        rows.append([case.label, *(_f(cost.get(s, math.nan)) for s in steps)])
    return markup.table(header, rows, "l" + "r" * len(steps))


def default_tolerances(fmu: str) -> str:
    """The plant's default tolerances as its model description gives them."""
    md = read_model_description(fmu)
    start = {v.name: v.start for v in md.modelVariables}
    return f"solver.rtol = {start['solver.rtol']}, solver.atol = {start['solver.atol']}"


def markdown(
    path: Path, table: list[dict], sweep: list[dict], figure: Path, took: float, tolerances: str
) -> Path:
    """The report; `tolerances` the plants' defaults, as :func:`default_tolerances`."""
    lines = [
        "# What a plant's integration costs",
        "",
        markup.provenance("dyadfmu plants"),
        "",
        f"Default tolerances ({tolerances}); inputs held; {took:.0f} s to measure. "
        "An evaluation is one of the equation of motion q'' = M^-1 (efforts - h): the "
        "inverse scene's evaluation at zero acceleration and an N x N solve, and where a "
        "stiff circuit's current follows its slow manifold one directional derivative of "
        "the inverse scene along the motion (for the manifold's third term), and where a "
        "transient is closed in its formula, its directional derivatives counted as "
        "evaluations; a Jacobian is "
        "the inverse scene's directional derivatives along each driver's position and "
        "rate (RODASP only). Instructions are callgrind's, inclusive.",
        "",
        f"## At communication steps of {TABLE_STEP:g} s",
        "",
        *_table_lines(table),
        "",
        *_target_lines(table),
        "",
        "## Evaluations per ms against the communication step",
        "",
        "Each communication step ends an internal step, so a step shorter than the ones "
        "the tolerance asks for sets the cost.",
        "",
        *_sweep_lines(sweep),
        "",
        markup.image("evaluations per ms against the communication step", figure.name),
        "",
    ]
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def write_csv(path: Path, sweep: list[dict]) -> Path:
    """The sweep's points as CSV."""
    with path.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(
            f, fieldnames=("case", "step", "steps_per_ms", "evaluations_per_ms", "turns")
        )
        writer.writeheader()
        writer.writerows(sweep)
    return path


def parser() -> argparse.ArgumentParser:
    """The options of 'dyadfmu plants'."""
    p = argparse.ArgumentParser(
        prog="dyadfmu plants",
        description="Measure what the forward FMUs' integration costs: internal steps, "
        "evaluations and Jacobians per ms of motion, callgrind's instructions per "
        "evaluation, per Jacobian and per ms, for a torque-driven slider-crank and plants "
        "with a slow and a stiff motor; writes OUT/plants/report.md, points.csv and "
        "cost_vs_step.png.",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="at most 0.2 s of motion per case and no 1e-5 s steps (45 s of CPU time, most "
        "of it under callgrind; the full study 52 s)",
    )
    p.add_argument("--out", type=Path, default=Path("out"), help="output directory (default: out)")
    p.add_argument(
        "--build",
        type=Path,
        default=None,
        help="CMake build directory holding fmus/ (default: build/ of the checkout)",
    )
    return p


#: The path arguments, checked before any work (dyadfmu.paths.parse_checked).
PATHS = (("--out", "out", paths.OUT), ("--build", "build", paths.FOLDER))


def main(argv: list[str] | None = None) -> int:
    """Run 'dyadfmu plants' with `argv`: the measurements, the report, a summary."""
    args = paths.parse_checked(parser(), argv, PATHS)
    start = clock.perf_counter()
    try:
        table, sweep = measure(args.build, args.quick, lambda s: print(s, file=sys.stderr))
    except FileNotFoundError as e:
        print(f"dyadfmu plants: {e}", file=sys.stderr)
        return 2
    folder = Path(args.out) / "plants"
    folder.mkdir(parents=True, exist_ok=True)
    figure = plot(folder / "cost_vs_step.png", sweep)
    tolerances = default_tolerances(str(paths.built_fmu(CASES[0].identifier, 2, args.build)))
    took = clock.perf_counter() - start
    report = markdown(folder / "report.md", table, sweep, figure, took, tolerances)
    points = write_csv(folder / "points.csv", sweep)
    print("\n".join(_target_lines(table)))
    print("written:")
    for path in (report, points, figure):
        print(f"  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

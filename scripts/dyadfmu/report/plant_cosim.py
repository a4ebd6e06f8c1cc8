"""The co-simulation report's section on plants: each machine of
:data:`dyadfmu.cosim.plant_study.MACHINES` with its motor inside the plant (a), with the
motor as its own FMU (b) and as the drive FMU with the inverse mechanism FMU, stabilised
(c), all against the machine as one ODE: the errors in crank angle, speed and the joint
reactions against the communication step and the run's CPU time, and (a) against its
relative tolerance (the slider-crank). A machine with two drivers (the leg) has no (c).
Writes ``plant_vs_step.png`` beside the report and gives its lines and its points. The
quick study runs the slider-crank only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..cosim import force_study
from ..cosim import plant_study as study
from ..fmi.slave import SlaveError
from . import markdown as markup

#: The communication step of the tolerance sweep [s].
RTOL_STEP = 1e-2
#: The issue's target for (a): angle and speed within this fraction of travel and peak.
TARGET = 1e-8
_QUICK_STEPS = (1e-2, 1e-3)
_QUICK_RTOLS = (1e-8, 1e-10)


def _reference_grid(steps: tuple, m: study.PlantMachine) -> np.ndarray:
    n = int(round(m.t_end / min(steps)))
    return m.t_end * np.arange(n + 1) / n


def _reference_rtol(quick: bool) -> float:
    return 1e-10 if quick else 1e-12


def _reference(label: str, steps: tuple, quick: bool, m: study.PlantMachine) -> study.Reference:
    """The machine as one ODE: Radau where the circuit is stiff, else DOP853."""
    stiff = study.CIRCUITS.get(label) is not None
    grid, rtol = _reference_grid(steps, m), _reference_rtol(quick)
    return study.reference(label, grid, "Radau" if stiff else "DOP853", rtol, m)


def _point(
    m: study.PlantMachine, coupling: str, step: float, rtol: float, run: object, ref: object
) -> dict:
    e = study.errors(run, ref)
    return {"machine": m.name, "coupling": coupling, "step": step, "rtol": rtol, **e} | {
        "cpu_time": run.cpu_time
    }


#: The separate motor FMU's couplings: the inputs held over the step, or with their rates.
SPLIT = {False: "(b) motor FMU + plant, held", True: "(b) motor FMU + plant, with rates"}


def _split_points(
    label: str, steps: tuple, ref: study.Reference, m: study.PlantMachine
) -> list[dict]:
    """(b) at each step, held and with rates; a run the plant refuses (its motion run away
    under a torque held too long) is kept with infinite errors and the plant's reason."""
    found = []
    for rates, coupling in SPLIT.items():
        for step in steps:
            try:
                run = study.split_run(label, step, rates, m)
            except SlaveError as e:
                lost = dict.fromkeys(("angle", "speed", "angle_rad", "reactions"), math.inf)
                found.append(
                    {"machine": m.name, "coupling": coupling, "step": step, "rtol": math.nan}
                    | lost
                    | {"cpu_time": math.nan, "failed": str(e)}
                )
                continue
            found.append(_point(m, coupling, step, math.nan, run, ref))
    return found


def _machine_points(m: study.PlantMachine, quick: bool, log: Callable[[str], None]) -> list:
    """(a) per circuit and step, (a) per rtol (the slider-crank), (b) and (c) per step."""
    steps = _QUICK_STEPS if quick else study.STEPS
    circuits = list(study.CIRCUITS)[:1] if quick else list(study.CIRCUITS)
    found = []
    for label in circuits:
        log(f"{m.name}, motor {label}: the reference over {m.t_end:g} s and the plant")
        ref = _reference(label, steps, quick, m)
        for step in steps:
            run = study.run(label, step, m=m)
            found.append(_point(m, f"(a) motor {label}", step, math.nan, run, ref))
        if label != circuits[0]:
            continue
        if m == study.SLIDER_CRANK:
            for rtol in _QUICK_RTOLS if quick else study.RTOLS:
                run = study.run(label, RTOL_STEP, rtol, m=m)
                found.append(_point(m, f"(a) motor {label}", RTOL_STEP, rtol, run, ref))
        log(f"{m.name}: motor FMU and plant, motor {label}")
        found += _split_points(label, steps, ref, m)
    if not m.mechanism:
        return found  # several drivers: no drive FMU turns them, no (c)
    log(f"{m.name}: drive FMU and mechanism FMU, the reference with L = 0")
    ref = _reference(study.LINEAR, steps, quick, m)
    for step in steps if m.linear_plant else ():
        run = study.run(study.LINEAR, step, m=m)
        found.append(_point(m, f"(a) motor {study.LINEAR}", step, math.nan, run, ref))
    for step in steps:
        run = study.drive_run(step, m=m)
        found.append(_point(m, "(c) drive + inverse FMU", step, math.nan, run, ref))
    return found


#: The force law's couplings: its value at each communication point with its rate (the
#: plant's interpolation is then the law), or held over the step.
FORCE = {True: "(a) force law with its rate", False: "force law held over the step"}


def _force_points(m: force_study.ForceMachine, log: Callable[[str], None]) -> list[dict]:
    """The lift under its force law at each step, with the force's rate and held."""
    log(f"{m.name}, force law: the reference over {m.t_end:g} s and the plant")
    ref = force_study.reference(_reference_grid(study.STEPS, m), _reference_rtol(False), m)
    return [
        _point(m, coupling, step, math.nan, force_study.run(step, rates, m), ref)
        for rates, coupling in FORCE.items()
        for step in study.STEPS
    ]


def points(quick: bool, log: Callable[[str], None]) -> list[dict]:
    """Every run of the section, machine by machine (the quick study: the slider-crank;
    the full one also the lift under a force law)."""
    machines = [study.SLIDER_CRANK] if quick else list(study.MACHINES.values())
    found = [p for m in machines for p in _machine_points(m, quick, log)]
    return found if quick else found + _force_points(force_study.LIFT, log)


def _run_of(name: str) -> float:
    """The duration [s] of the machine ``name``'s run."""
    m = study.MACHINES.get(name)
    return m.t_end if m else force_study.LIFT.t_end


def _e(x: float) -> str:
    return f"{x:.1e}"


def _cell(p: dict) -> str:
    if "failed" in p:
        return "refused"
    return f"{_e(p['angle'])} / {_e(p['speed'])}"


def _machines(found: list[dict]) -> list[str]:
    return list(dict.fromkeys(p["machine"] for p in found))


def _reaction_cell(p: dict) -> str:
    return "refused" if "failed" in p else _e(p["reactions"])


def _step_table(found: list[dict], cell: Callable[[dict], str] = _cell) -> list[str]:
    rows = [p for p in found if math.isnan(p["rtol"])]
    steps = sorted({p["step"] for p in rows}, reverse=True)
    table = []
    for name in _machines(rows):
        mine = [p for p in rows if p["machine"] == name]
        for coupling in sorted(dict.fromkeys(p["coupling"] for p in mine), key=lambda c: c[:3]):
            by_step = {p["step"]: p for p in mine if p["coupling"] == coupling}
            table.append([name, coupling, *(cell(by_step[h]) for h in steps)])
    header = ["machine", "coupling", *(f"{h:g} s" for h in steps)]
    return markup.table(header, table, "--" + "r" * len(steps))


def _rtol_table(found: list[dict]) -> list[str]:
    rows = [p for p in found if not math.isnan(p["rtol"])]
    table = [
        [f"{p['rtol']:.0e}", _e(p["angle"]), _e(p["speed"]), f"{p['cpu_time']:.3f}"] for p in rows
    ]
    header = ["solver.rtol = solver.atol", "angle / travel", "speed / peak", "CPU time (s)"]
    return markup.table(header, table, "rrrr")


def _targets(found: list[dict]) -> list[str]:
    out = []
    inside = [p for p in found if p["coupling"].startswith("(a)") and math.isnan(p["rtol"])]
    for name, coupling in dict.fromkeys((p["machine"], p["coupling"]) for p in inside):
        sel = [p for p in inside if (p["machine"], p["coupling"]) == (name, coupling)]
        worst = max(max(p["angle"], p["speed"]) for p in sel)
        verdict = "met" if worst <= TARGET else "NOT met"
        out.append(
            f"- {name}, {coupling}, default tolerances: at most {worst:.1e} of the angle "
            "travelled or "
            f"of the peak speed at every communication step from {max(p['step'] for p in sel):g}"
            f" to {min(p['step'] for p in sel):g} s (target {TARGET:.0e}): {verdict}."
        )
    rt = [p for p in found if not math.isnan(p["rtol"])]
    if len(rt) > 1:
        falls = all(b["angle"] < a["angle"] for a, b in zip(rt, rt[1:], strict=False))
        first, last = rt[0], rt[-1]
        out.append(
            f"- {first['machine']}, (a) against rtol: the angle error goes from "
            f"{first['angle']:.1e} at {first['rtol']:.0e} to {last['angle']:.1e} at "
            f"{last['rtol']:.0e}"
            + (", falling at every step." if falls else ", not falling at every step.")
        )
    return out + _reaction_targets(inside)


def _reaction_targets(inside: list[dict]) -> list[str]:
    """(a)'s reactions, machine by machine: the largest error over every circuit and step."""
    out = []
    for name in _machines(inside):
        sel = [p for p in inside if p["machine"] == name]
        worst = max(sel, key=lambda p: p["reactions"])
        out.append(
            f"- {name}, (a), joint reactions: at most {worst['reactions']:.1e} of the largest "
            f"reaction's peak at every step and circuit (the largest: {worst['coupling']} at "
            f"{worst['step']:g} s)."
        )
    return out


#: The issue's target for (b) with rates: the crank angle's error at 1 ms steps [rad].
SPLIT_TARGET = 1e-3


def _split_targets(found: list[dict]) -> list[str]:
    """(b)'s observed order between its two finest steps, its error at 1 ms, and the runs
    the plant refused, machine by machine."""
    return [line for name in _machines(found) for line in _split_lines(found, name)]


def _split_lines(found: list[dict], name: str) -> list[str]:
    out = []
    found = [p for p in found if p["machine"] == name]
    for rates, coupling in SPLIT.items():
        sel = [p for p in found if p["coupling"] == coupling and math.isfinite(p["angle"])]
        sel.sort(key=lambda p: -p["step"])
        if len(sel) < 2:
            continue
        a, b = sel[-2], sel[-1]
        order = math.log(a["angle"] / b["angle"]) / math.log(a["step"] / b["step"])
        text = f"- {name}, {coupling}: the angle error falls at order {order:.2f} from "
        text += f"{a['step']:g} to {b['step']:g} s"
        at_ms = [p for p in sel if p["step"] == 1e-3]
        if at_ms:
            text += f"; {at_ms[0]['angle_rad']:.1e} rad at 1 ms"
            if rates:
                held = "met" if at_ms[0]["angle_rad"] <= SPLIT_TARGET else "NOT met"
                text += f" (target at most {SPLIT_TARGET:g} rad): {held}"
        out.append(text + ".")
    for p in (p for p in found if "failed" in p):
        reason = p["failed"].split("(", 1)[-1].split(" (", 1)[0]
        where = f"{name}, {p['coupling']} at {p['step']:g} s"
        out.append(f"- {where}: refused by the plant: {markup.text(reason)}.")
    return out


def plot(path: Path, found: list[dict]) -> Path:
    """Angle error against the communication step and against the run's CPU time, one row
    of two panels per machine."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [p for p in found if math.isnan(p["rtol"])]
    names = _machines(rows)
    fig, grid = plt.subplots(len(names), 2, figsize=(12, 4.2 * len(names)), squeeze=False)
    for name, axes in zip(names, grid, strict=True):
        _plot_machine(axes, [p for p in rows if p["machine"] == name])
        axes[0].set_title(f"{name}: run over {_run_of(name):g} s", fontsize=10)
    fig.suptitle(
        f"Each machine's run against the machine as one ODE (dashed: {TARGET:.0e})",
        fontsize=11,
    )
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.3 / fig.get_figheight()))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_machine(axes: object, rows: list[dict]) -> None:
    for coupling in dict.fromkeys(p["coupling"] for p in rows):
        sel = sorted(
            (p for p in rows if p["coupling"] == coupling and math.isfinite(p["angle"])),
            key=lambda p: p["step"],
        )
        y = [max(p["angle"], 1e-16) for p in sel]
        axes[0].loglog([p["step"] for p in sel], y, "o-", label=coupling)
        axes[1].loglog([max(p["cpu_time"], 1e-4) for p in sel], y, "o-", label=coupling)
    for ax, xlabel in zip(axes, ("communication step (s)", "CPU time of the run (s)"), strict=True):
        ax.axhline(TARGET, color="gray", ls="--", lw=0.8)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("driver angle error / angle travelled")
        ax.grid(which="both", alpha=0.3)
    axes[0].legend(fontsize=8)


def _linear(found: list[dict]) -> list[study.PlantMachine]:
    """The machines of ``found`` with a plant whose motor has no inductance."""
    machines = [study.MACHINES[n] for n in _machines(found) if n in study.MACHINES]
    return [m for m in machines if m.linear_plant]


def _machine_table(found: list[dict]) -> list[str]:
    """Each machine of the section: its FMUs, its supply, its run and its motor."""
    table = []
    for name in (n for n in _machines(found) if n in study.MACHINES):
        m = study.MACHINES[name]
        motor = study.circuit(next(iter(study.CIRCUITS)), m=m)
        gain = motor.torque_constant * motor.ratio
        table.append(
            [
                name,
                markup.code(m.plant),
                markup.code(m.rotor_plant),
                markup.code(m.mechanism) if m.mechanism else "none: two drivers",
                ", ".join(f"{d} {q:.4g}" for d, q in zip(m.drivers, m.start, strict=True)),
                f"{m.voltage:g}",
                f"{m.t_end:g}",
                f"{gain * m.voltage / motor.resistance:g}",
                f"{m.voltage / gain:g}",
                f"{motor.ratio**2 * motor.rotor_inertia:g}",
                f"{study.fit_error(m):.1e}",
            ]
        )
    header = [
        "machine",
        "(a) plant",
        "(b) plant",
        "(c) mechanism FMU",
        "at rest (rad)",
        "supply (V)",
        "run (s)",
        "stall torque (N.m)",
        "no-load speed (rad/s)",
        "rotor at the crank (kg.m2)",
        "series fit",
    ]
    return markup.table(header, table, "-----rrrrrr")


def _force_lines(found: list[dict]) -> list[str]:
    """What the lift's rows are, where the study has them."""
    m = force_study.LIFT
    if m.name not in _machines(found):
        return []
    hold = force_study.holding_force(m)
    return [
        "",
        f"The {m.name} ({markup.code(m.plant)}, its ram's force in, no motor: no (b) or (c)) "
        f"under the force law F(t) = F_hold ({m.hold:g} {'-' if m.slope < 0 else '+'} "
        f"{abs(m.slope):g} t / s), F_hold = "
        f"{hold:.1f} N the force that holds the ram at rest at {m.start:g} m with its loads "
        f"off: the platform rises and slows down over {m.t_end:g} s. (a) the force with its "
        "rate at each communication point (FMI 2 input derivatives: the plant's "
        "interpolation is then the law itself), and held over the step. Its reference: the "
        "harness's effort J(x) x'' + h(x, x') = F(t) itself (no series), SciPy's DOP853 at "
        f"rtol {_reference_rtol(False):.0e}.",
    ]


def lines(found: list[dict], figure: Path, quick: bool) -> list[str]:
    """The section's Markdown lines."""
    return [
        "",
        "## The motor inside the plant",
        "",
        "Each machine with its DC motor runs up from rest (at the angles of the table; the "
        "leg's rear hip free, no effort on it) under a constant supply. (a): the plant with "
        "the motor inside, the motor's circuit and the crank's motion integrated inside each "
        "doStep, default tolerances, with an armature of L/R 1.4 ms and a stiff one (L/R "
        "1 us); (b): the same motor as "
        "its own FMU `motor` (voltage and speed in, torque out, its circuit solved exactly "
        "over each step) and a plant with the crank's torque in (the rotor's inertia added "
        "to the crank's), exchanging speed and torque at each communication point, held "
        "over the step or with their first derivatives (FMI 2 input and output "
        "derivatives); (c): the drive FMU with the motor's linear characteristic (its L = 0 "
        "limit) and the inverse mechanism FMU, stabilised; (a) motor L = 0: a plant with that "
        "characteristic inside (its motor without inductance, the current no state), one to "
        "one with (c) against the same reference, where the machine has one ("
        + ", ".join(markup.code(m.linear_plant) for m in _linear(found))
        + "). Reference: the machine as one "
        "ODE from the harness's kinematics (J, J' and Q_g as Fourier series of "
        f"{study.SAMPLES} samples; with two drivers M(q) and h's terms in q as Chebyshev "
        "series in both drivers' angles; each within the 'series fit' of the harness), "
        "SciPy at rtol "
        f"{_reference_rtol(quick):.0e} (Radau where the circuit is stiff, else DOP853).",
        "",
        *_machine_table(found),
        *_force_lines(found),
        "",
        "Each cell: the largest crank angle error over the communication points / the angle "
        "travelled, then the largest speed error / the peak speed (with two drivers, the "
        "worse driver's).",
        "",
        *_step_table(found),
        "",
        "The joint reactions (every `*.R_*` output: the plant's, in (c) the mechanism FMU's) "
        "against the harness's Newton-Euler solve along the reference's motion, the harness's "
        "load models switched off as the FMUs' load inputs stay at zero; each cell: the "
        "largest error over the reactions and communication points / the largest reaction's "
        "peak.",
        "",
        *_step_table(found, _reaction_cell),
        "",
        f"(a) with the slider-crank's slow motor at {RTOL_STEP:g} s steps, against its tolerances:",
        "",
        *_rtol_table(found),
        "",
        markup.image("angle error against step and CPU time", figure.name),
        "",
        *_targets(found),
        *_split_targets(found),
    ]

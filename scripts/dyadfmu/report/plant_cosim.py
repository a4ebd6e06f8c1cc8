"""The co-simulation report's section on plants: the slider-crank's machine with its motor
inside the plant (a) against the drive FMU with the inverse mechanism FMU, stabilised (c),
both against the machine as one ODE (:mod:`dyadfmu.cosim.plant_study`): the errors in
crank angle and speed against the communication step and the run's CPU time, and (a)
against its relative tolerance. Writes ``plant_vs_step.png`` beside the report and gives
its lines and its points.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..cosim import plant_study as study
from ..fmi.slave import SlaveError
from . import markdown as markup

#: The communication step of the tolerance sweep [s].
RTOL_STEP = 1e-2
#: The issue's target for (a): angle and speed within this fraction of travel and peak.
TARGET = 1e-8
_QUICK_STEPS = (1e-2, 1e-3)
_QUICK_RTOLS = (1e-8, 1e-10)


def _reference_grid(steps: tuple) -> np.ndarray:
    n = int(round(study.T_END / min(steps)))
    return study.T_END * np.arange(n + 1) / n


def _reference_rtol(quick: bool) -> float:
    return 1e-10 if quick else 1e-12


def _reference(label: str, steps: tuple, quick: bool) -> tuple:
    """The machine as one ODE: Radau where the circuit is stiff, else DOP853."""
    stiff = study.CIRCUITS.get(label) is not None
    rtol = _reference_rtol(quick)
    return study.reference(label, _reference_grid(steps), "Radau" if stiff else "DOP853", rtol)


def _point(coupling: str, step: float, rtol: float, run: object, ref: tuple) -> dict:
    e = study.errors(run, ref)
    return {"coupling": coupling, "step": step, "rtol": rtol, **e, "cpu_time": run.cpu_time}


#: The separate motor FMU's couplings: the inputs held over the step, or with their rates.
SPLIT = {False: "(b) motor FMU + plant, held", True: "(b) motor FMU + plant, with rates"}


def _split_points(label: str, steps: tuple, ref: tuple) -> list[dict]:
    """(b) at each step, held and with rates; a run the plant refuses (its motion run away
    under a torque held too long) is kept with infinite errors and the plant's reason."""
    found = []
    for rates, coupling in SPLIT.items():
        for step in steps:
            try:
                run = study.split_run(label, step, rates)
            except SlaveError as e:
                lost = {"angle": math.inf, "speed": math.inf, "angle_rad": math.inf}
                found.append(
                    {"coupling": coupling, "step": step, "rtol": math.nan, **lost}
                    | {"cpu_time": math.nan, "failed": str(e)}
                )
                continue
            found.append(_point(coupling, step, math.nan, run, ref))
    return found


def points(quick: bool, log: Callable[[str], None]) -> list[dict]:
    """Every run of the section: (a) per circuit and step, (a) per rtol, (b) and (c) per
    step."""
    steps = _QUICK_STEPS if quick else study.STEPS
    circuits = list(study.CIRCUITS)[:1] if quick else list(study.CIRCUITS)
    found = []
    for label in circuits:
        log(f"plant, motor {label}: the reference over {study.T_END:g} s")
        ref = _reference(label, steps, quick)
        for step in steps:
            found.append(_point(f"(a) motor {label}", step, math.nan, study.run(label, step), ref))
        if label == circuits[0]:
            for rtol in _QUICK_RTOLS if quick else study.RTOLS:
                run = study.run(label, RTOL_STEP, rtol)
                found.append(_point(f"(a) motor {label}", RTOL_STEP, rtol, run, ref))
            log(f"motor FMU and plant, motor {label}")
            found += _split_points(label, steps, ref)
    log("drive FMU and mechanism FMU: the reference with L = 0")
    ref = _reference(study.LINEAR, steps, quick)
    for step in steps:
        found.append(_point("(c) drive + inverse FMU", step, math.nan, study.drive_run(step), ref))
    return found


def _e(x: float) -> str:
    return f"{x:.1e}"


def _cell(p: dict) -> str:
    if "failed" in p:
        return "refused"
    return f"{_e(p['angle'])} / {_e(p['speed'])}"


def _step_table(found: list[dict]) -> list[str]:
    rows = [p for p in found if math.isnan(p["rtol"])]
    steps = sorted({p["step"] for p in rows}, reverse=True)
    table = []
    for coupling in sorted(dict.fromkeys(p["coupling"] for p in rows), key=lambda c: c[:3]):
        by_step = {p["step"]: p for p in rows if p["coupling"] == coupling}
        cells = [_cell(by_step[h]) for h in steps]
        table.append([coupling, *cells])
    header = ["coupling", *(f"{h:g} s" for h in steps)]
    return markup.table(header, table, "-" + "r" * len(steps))


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
    for coupling in dict.fromkeys(p["coupling"] for p in inside):
        sel = [p for p in inside if p["coupling"] == coupling]
        worst = max(max(p["angle"], p["speed"]) for p in sel)
        verdict = "met" if worst <= TARGET else "NOT met"
        out.append(
            f"- {coupling}, default tolerances: at most {worst:.1e} of the angle travelled or "
            f"of the peak speed at every communication step from {max(p['step'] for p in sel):g}"
            f" to {min(p['step'] for p in sel):g} s (target {TARGET:.0e}): {verdict}."
        )
    rt = [p for p in found if not math.isnan(p["rtol"])]
    if len(rt) > 1:
        falls = all(b["angle"] < a["angle"] for a, b in zip(rt, rt[1:], strict=False))
        out.append(
            f"- (a) against rtol: the angle error goes from {rt[0]['angle']:.1e} at "
            f"{rt[0]['rtol']:.0e} to {rt[-1]['angle']:.1e} at {rt[-1]['rtol']:.0e}"
            + (", falling at every step." if falls else ", not falling at every step.")
        )
    return out


#: The issue's target for (b) with rates: the crank angle's error at 1 ms steps [rad].
SPLIT_TARGET = 1e-3


def _split_targets(found: list[dict]) -> list[str]:
    """(b)'s observed order between its two finest steps, its error at 1 ms, and the runs
    the plant refused."""
    out = []
    for rates, coupling in SPLIT.items():
        sel = [p for p in found if p["coupling"] == coupling and math.isfinite(p["angle"])]
        sel.sort(key=lambda p: -p["step"])
        if len(sel) < 2:
            continue
        a, b = sel[-2], sel[-1]
        order = math.log(a["angle"] / b["angle"]) / math.log(a["step"] / b["step"])
        text = f"- {coupling}: the angle error falls at order {order:.2f} from {a['step']:g} to "
        text += f"{b['step']:g} s"
        at_ms = [p for p in sel if p["step"] == 1e-3]
        if at_ms:
            text += f"; {at_ms[0]['angle_rad']:.1e} rad at 1 ms"
            if rates:
                held = "met" if at_ms[0]["angle_rad"] <= SPLIT_TARGET else "NOT met"
                text += f" (target at most {SPLIT_TARGET:g} rad): {held}"
        out.append(text + ".")
    for p in (p for p in found if "failed" in p):
        reason = p["failed"].split("(", 1)[-1].split(" (", 1)[0]
        out.append(
            f"- {p['coupling']} at {p['step']:g} s: refused by the plant: {markup.text(reason)}."
        )
    return out


def plot(path: Path, found: list[dict]) -> Path:
    """Angle error against the communication step and against the run's CPU time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    rows = [p for p in found if math.isnan(p["rtol"])]
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
        ax.set_ylabel("crank angle error / angle travelled")
        ax.grid(which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(
        f"The slider-crank's run-up over {study.T_END:g} s against the machine as one ODE "
        f"(dashed: {TARGET:.0e})",
        fontsize=11,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def lines(found: list[dict], figure: Path, quick: bool) -> list[str]:
    """The section's Markdown lines."""
    return [
        "",
        "## The motor inside the plant",
        "",
        f"The slider-crank with its DC motor runs up from rest at {study.START_ANGLE:g} rad "
        f"under {study.VOLTAGE:g} V for {study.T_END:g} s. (a): the plant "
        f"`{study.PLANT}`, the motor's circuit and the crank's motion integrated inside each "
        "doStep, default tolerances; (c): the drive FMU with the motor's linear "
        "characteristic (its L = 0 limit) and the inverse mechanism FMU, stabilised. "
        "Reference: the machine as one ODE from the harness's kinematics (J, J' and Q_g as "
        f"Fourier series of {study.SAMPLES} samples, within {study.fit_error():.1e} of the "
        "harness), SciPy at rtol "
        f"{_reference_rtol(quick):.0e} "
        "(Radau where the circuit is stiff, else DOP853). Each cell: the largest crank angle "
        "error over the communication points / the angle travelled, then the largest speed "
        "error / the peak speed. (b): the same motor as its own FMU `motor` (voltage and "
        "speed in, torque out, its circuit solved exactly over each step) and the plant "
        f"`{study.ROTOR_PLANT}` (torque in; the rotor's inertia added to the crank's), "
        "exchanging speed and torque at each communication point, held over the step or "
        "with their first derivatives (FMI 2 input and output derivatives).",
        "",
        *_step_table(found),
        "",
        f"(a) with the slow motor at {RTOL_STEP:g} s steps, against its tolerances:",
        "",
        *_rtol_table(found),
        "",
        markup.image("angle error against step and CPU time", figure.name),
        "",
        *_targets(found),
        *_split_targets(found),
    ]

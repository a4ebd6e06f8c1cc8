"""The co-simulation study: the drive FMU coupled to a dyad FMU by the master of
:mod:`dyadfmu.cosim.master`, both schemes, over inertia ratios and communication steps, against
the monolithic machine; writes ``<out>/cosim/report.md``, ``points.csv`` and
``error_vs_time.png``.

With ``--scene FILE.toml`` it turns a user's own mechanism instead
(:mod:`dyadfmu.report.scene_cosim`).

Command line (the ``dyadfmu cosim`` subcommand calls :func:`main`)::

    python -m dyadfmu.report.cosim [--quick] [--out DIR] [--fmi-version {2,3}]
    python -m dyadfmu.report.cosim --scene FILE.toml [--fmi {2,3}] [--motor NAME] ... --out DIR
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time as clock
from collections.abc import Callable
from pathlib import Path

from .. import paths
from ..cosim import master as cosim
from ..cosim import mechanism_drive, scene_drive
from . import markdown as markup
from . import plant_cosim, scene_cosim

#: Inertia ratios (mean J over a revolution, crank included, / rotor inertia).
RATIOS = (0.1, 1.0, 10.0, 100.0)
#: Communication steps [s].
STEPS = (1e-2, 1e-3, 1e-4, 1e-5)
QUICK_RATIOS = (1.0, 100.0)
QUICK_STEPS = (1e-2, 1e-3)
#: Tolerances of the monolithic reference (Radau): full and quick study.
REFERENCE_TOLERANCES = {False: (1e-10, 1e-12), True: (1e-8, 1e-10)}
#: Errors of diverged runs are drawn at this height of the plot.
DIVERGED_Y = 30.0

MARKERS = {"explicit": "o", "stabilised": "s"}
RATIO_COLORS = {0.1: "tab:blue", 1.0: "tab:green", 10.0: "tab:orange", 100.0: "tab:red"}

FIELDS = (
    "mechanism",
    "dyad",
    "ratio",
    "rotor_inertia",
    "scheme",
    "fmi_version",
    "step",
    "t_end",
    "steps",
    "wall_time",
    "speed_error",
    "reaction_error",
    "angle_error",
    "speed_error_at",
    "reaction_error_at",
    "diverged",
    "diverged_at",
    "reason",
    "lag_factor_max",
    "lag_factor_geometric",
    "motor_time_constant",
    "lag_factor_effective",
    "affine_residual",
    "reference_wall_time",
    "drive",
)


def _log(verbose: bool, text: str):
    if verbose:
        print(text, file=sys.stderr, flush=True)


def _point(
    name: str,
    ratio: float,
    s: cosim.Setup,
    scheme: str,
    h: float,
    fmi_version: int,
    r: cosim.CosimRun,
    ref: cosim.Reference,
) -> dict:
    """One run of the study as a row of :data:`FIELDS`."""
    lag = cosim.explicit_lag_factor(s.mech, s.motor, h)
    e = cosim.errors(r, ref)
    return {
        "mechanism": name,
        "dyad": s.mech.dyad,
        "ratio": ratio,
        "rotor_inertia": s.motor.rotor_inertia,
        "scheme": scheme,
        "fmi_version": fmi_version,
        "step": h,
        "t_end": s.t_end,
        "steps": r.steps,
        "wall_time": r.wall_time,
        "speed_error": e["speed"],
        "reaction_error": e["reaction"],
        "angle_error": e["angle"],
        "speed_error_at": e["speed_at"],
        "reaction_error_at": e["reaction_at"],
        "diverged": r.diverged,
        "diverged_at": r.diverged_at,
        "reason": r.reason,
        "lag_factor_max": lag["max"],
        "lag_factor_geometric": lag["geometric"],
        "motor_time_constant": lag["time_constant"],
        "lag_factor_effective": lag["effective"],
        "affine_residual": r.affine_residual,
        "reference_wall_time": ref.wall_time,
        "drive": r.drive_label,
    }


def _machine_points(
    name: str,
    ratio: float,
    s: cosim.Setup,
    ref: cosim.Reference,
    steps: tuple[float, ...],
    fmi_version: int,
    drive: Callable | None,
    verbose: bool,
) -> list[dict]:
    """Every scheme at every step on one machine."""
    rows = []
    for scheme in cosim.SCHEMES:
        for h in steps:
            r = cosim.run_setup(s, scheme, h, fmi_version, drive=drive)
            rows.append(_point(name, ratio, s, scheme, h, fmi_version, r, ref))
            _log(
                verbose,
                f"  {scheme:10s} h {h:.0e}: {r.wall_time:7.2f} s, speed "
                f"{rows[-1]['speed_error']:.2e}, reactions "
                f"{rows[-1]['reaction_error']:.2e}"
                + (f", DIVERGED at {r.diverged_at:.4g} s" if r.diverged else ""),
            )
    return rows


def study_points(
    quick: bool = False,
    fmi_version: int = 2,
    drive: Callable | None = None,
    mechanisms: tuple[str, ...] = cosim.STUDY_MECHANISMS,
    ratios: tuple[float, ...] | None = None,
    steps: tuple[float, ...] | None = None,
    verbose: bool = False,
) -> tuple[list[dict], dict]:
    """Every run of the study as a row of :data:`FIELDS`, and {(mechanism, ratio):
    :class:`dyadfmu.cosim.master.Reference`} (evaluated on the finest step's grid)."""
    ratios = tuple(ratios or (QUICK_RATIOS if quick else RATIOS))
    steps = tuple(sorted(steps or (QUICK_STEPS if quick else STEPS), reverse=True))
    rtol, atol = REFERENCE_TOLERANCES[bool(quick)]
    rows, refs = [], {}
    for name in mechanisms:
        for ratio in ratios:
            s = cosim.setup(name, ratio)
            # warm-up: one step, untimed, so that no run pays for the first library load
            cosim.run_setup(s, "stabilised", s.t_end, fmi_version, drive=drive)
            ref = cosim.reference_for(s, min(steps), rtol=rtol, atol=atol)
            refs[(name, ratio)] = ref
            _log(verbose, f"{name} ratio {ratio:g}: reference in {ref.wall_time:.1f} s")
            rows += _machine_points(name, ratio, s, ref, steps, fmi_version, drive, verbose)
    return rows, refs


# ---------------------------------------------------------------------------
# outputs
# ---------------------------------------------------------------------------
def write_csv(path: Path, rows: list) -> Path:
    """The study's points as CSV."""
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        for row in rows:
            w.writerow({k: ("" if row[k] is None else row[k]) for k in FIELDS})
    return path


def _panel(ax: object, rows: list, name: str, key: str, label: str) -> None:
    """One error against run time, a marker per run (diverged runs above the line)."""
    from matplotlib.ticker import NullFormatter

    for r in rows:
        if r["mechanism"] != name:
            continue
        color = RATIO_COLORS.get(r["ratio"], "k")
        x = max(r["wall_time"], 1e-4)
        if r["diverged"]:
            ax.loglog(x, DIVERGED_Y, MARKERS[r["scheme"]], mfc="none", mec=color, ms=9)
            ax.loglog(x, DIVERGED_Y, "x", color=color, ms=7)
        else:
            y = max(r[key], 1e-12)
            ax.loglog(x, y, MARKERS[r["scheme"]], color=color, ms=7, alpha=0.85)
    ax.axhline(DIVERGED_Y / 2, color="gray", lw=0.6, ls="--")
    ax.text(
        0.01,
        DIVERGED_Y * 0.6,
        "above: diverged (run stopped)",
        fontsize=7,
        color="gray",
        transform=ax.get_yaxis_transform(),
    )
    ax.set_ylim(top=DIVERGED_Y * 3)
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("wall-clock time of the run (s)")
    ax.set_ylabel(label)
    ax.set_title(f"{name}: {label.split(' /')[0]}", fontsize=10)
    ax.grid(which="both", alpha=0.3)


def _legend_handles(ax: object, rows: list) -> list:
    handles = []
    for scheme, marker in MARKERS.items():
        handles.append(ax.plot([], [], marker, color="gray", label=scheme)[0])
    for ratio, color in RATIO_COLORS.items():
        if any(r["ratio"] == ratio for r in rows):
            handles.append(ax.plot([], [], "s", color=color, label=f"ratio {ratio:g}")[0])
    handles.append(ax.plot([], [], "x", color="gray", label="diverged")[0])
    return handles


def plot(path: Path, rows: list) -> Path:
    """The speed error against wall time per step, one marker per run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["mechanism"] for r in rows))
    fig, axes = plt.subplots(len(names), 2, figsize=(12, 4.6 * len(names)), squeeze=False)
    steps = sorted({r["step"] for r in rows}, reverse=True)
    panels = (
        ("speed_error", "crank speed error / mean speed"),
        ("reaction_error", "|R_np| error / peak |R_np|"),
    )
    for i, name in enumerate(names):
        for j, (key, label) in enumerate(panels):
            _panel(axes[i][j], rows, name, key, label)
    handles = _legend_handles(axes[0][0], rows)
    fig.legend(handles=handles, fontsize=8, loc="lower center", ncol=len(handles))
    fig.suptitle(
        "Co-simulation drive FMU + dyad FMU against the monolithic machine "
        "(communication steps "
        + ", ".join(f"{h:.0e}" for h in steps)
        + " s: the finer, the longer the run)",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _e(x: float) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.2e}"


def _status(r: dict) -> markup.Markup:
    """A run's outcome: ok, or where and why it stopped (the reason may be an FMU's
    message: literal text)."""
    if not r["diverged"]:
        return markup.text("ok")
    return markup.Markup(f"**diverged** at {r['diverged_at']:.4g} s: {markup.text(r['reason'])}")


def _header(rows: list, quick: bool, elapsed: float, figure: Path, fmi_version: int) -> list[str]:
    drive = rows[0]["drive"] if rows else ""
    return [
        "# Co-simulation of the drive FMU with a dyad FMU",
        "",
        markup.provenance(f"scripts/run-cosim{' --quick' if quick else ''}"),
        "",
        f"{'Quick' if quick else 'Full'} study, FMI {fmi_version}, drive: "
        f"{markup.text(drive)}; {len(rows)} runs in {elapsed:.0f} s. Every figure is in "
        f"`points.csv`; the plot is {markup.code(figure.name)}.",
        "",
    ]


def _setup_section(names: list[str], quick: bool) -> list[str]:
    """How the two FMUs are coupled, the schemes, the start, and the machines' table head."""
    return [
        "## Setup",
        "",
        "The drive FMU carries the motor (linear torque-speed line), the rotor and the "
        "crank: its `inertia` is J_r + J_cO, the crank's inertia about O (about its "
        "centre of mass plus mass |com|^2). The dyad FMU carries the links m and n; its "
        "torque on the crank is tau = (D_n - O) x (-R_np) - M_np, affine in the crank "
        "acceleration: tau0 + tau1 eps, -tau1 = J(phi) - J_cO. Together they are the "
        "machine that `machine.monolithic` integrates as one ODE (Radau, rtol "
        f"{REFERENCE_TOLERANCES[bool(quick)][0]:g}, atol "
        f"{REFERENCE_TOLERANCES[bool(quick)][1]:g}), the reference, evaluated at the "
        "communication points; its reactions come from `reference.solve` at its states.",
        "",
        "- **explicit**: the dyad gets the crank state at t and the last acceleration the "
        "drive reported; load.torque = tau, load.inertia = 0.",
        "- **stabilised**: tau0 from the dyad at eps = 0, tau1 from its directional "
        "derivatives (seed d(inputs)/d(eps)); load.torque = tau0, load.inertia = -tau1, "
        "so the drive's acceleration closes the loop exactly at the communication point; "
        "the dyad is then evaluated at that acceleration.",
        "- Both hold the drive's inputs over the step (zero-order hold): the drive's "
        "RK4 is exact for what it is given, the error is that of the hold.",
        "",
        f"Start: crank angle {cosim.START_ANGLE:g} rad (away from the singular positions: "
        "conditioning 0.997 for the slider-crank, 0.82 for the four-bar, at least 0.94 "
        "and 0.73 over a revolution), the nominal speed. Simulated time: "
        + ", ".join(f"{n} {cosim.DURATIONS[n]:g} s" for n in names)
        + " (slider-crank: 5 revolutions at 3000 rpm; four-bar: 1.25 revolutions at "
        "300 rpm). Divergence: speed not finite or beyond "
        f"{cosim.DIVERGENCE_SPEED_FACTOR:g} x the no-load speed, a dyad status other than "
        "0, or a failing FMU call; the run stops and is marked.",
        "",
        "Inertia ratio = mean J(phi) over a revolution (crank included) / J_r. In the "
        "explicit scheme the error of the lagged acceleration is multiplied at each "
        "communication point by -rho(phi), rho = (J(phi) - J_cO) / (J_r + J_cO), and "
        "damped within the step by the motor's torque-speed slope by exp(-h / tau_m), "
        "tau_m = (J_r + J_cO) omega_0 / T_stall (`cosim.explicit_lag_factor`); "
        "max rho x exp(-h / tau_m) above 1 predicts divergence.",
        "",
    ]


#: The machines' table's header.
MACHINE_HEADER = (
    "mechanism",
    "ratio",
    "J_r (kg m2)",
    "J_cO (kg m2)",
    "rho max",
    "rho geom. mean",
    "tau_m (s)",
    "reference wall time (s)",
    "mean speed (rad/s)",
    "peak R_np (N)",
)
#: The runs' table's header.
RESULTS_HEADER = (
    "mechanism",
    "ratio",
    "scheme",
    "step (s)",
    "steps",
    "wall time (s)",
    "speed error",
    "reaction error",
    "rho max x exp(-h/tau_m)",
    "run",
)
#: The mechanism FMUs' table's header.
MECHANISM_HEADER = (
    "mechanism FMU",
    "step [s]",
    "steps",
    "max abs(phi error) [rad]",
    "max abs(omega error) / mean omega",
    "J vs crank.J",
    "affine",
    "wall time [s]",
)


def _machine_rows(rows: list, refs: dict, names: list[str], ratios: list[float]) -> list[str]:
    """One row per mechanism and inertia ratio: inertias, lag factors, the reference."""
    table = []
    for name in names:
        for ratio in ratios:
            r = next(x for x in rows if x["mechanism"] == name and x["ratio"] == ratio)
            ref = refs[(name, ratio)]
            jc = cosim.crank_inertia_about_pivot(cosim.setup(name, ratio).mech)
            table.append(
                [
                    name,
                    f"{ratio:g}",
                    f"{r['rotor_inertia']:.3e}",
                    f"{jc:.3e}",
                    f"{r['lag_factor_max']:.3g}",
                    f"{r['lag_factor_geometric']:.3g}",
                    f"{r['motor_time_constant']:.2e}",
                    f"{ref.wall_time:.1f}",
                    f"{ref.mean_speed:.2f}",
                    f"{ref.peak_reaction:.4g}",
                ]
            )
    return markup.table(MACHINE_HEADER, table)


def _results_section(rows: list) -> list[str]:
    """The table of every run."""
    lines = [
        "",
        "## Results",
        "",
        "Largest errors at the communication points reached: crank speed relative to "
        "the reference's mean speed, |R_np| relative to its peak (a diverged run's "
        "errors are over the points before it stopped).",
        "",
    ]
    table = []
    for r in rows:
        lag = f"{r['lag_factor_effective']:.3g}" if r["scheme"] == "explicit" else "-"
        table.append(
            [
                r["mechanism"],
                f"{r['ratio']:g}",
                r["scheme"],
                f"{r['step']:.0e}",
                str(r["steps"]),
                f"{r['wall_time']:.3f}",
                _e(r["speed_error"]),
                _e(r["reaction_error"]),
                lag,
                _status(r),
            ]
        )
    return lines + markup.table(RESULTS_HEADER, table)


def _advice() -> list[str]:
    """What the study means for a user of the dyad FMU in another simulator."""
    return [
        "",
        "## For a user of the dyad FMU in another simulator",
        "",
        "Do not feed the crank acceleration back explicitly when the links outweigh "
        "what the driving side carries (rho above 1 anywhere on the revolution): that "
        "exchange diverges, and a smaller step makes it worse (it removes the motor's "
        "damping within the step). Feed the effective inertia back instead: the dyad "
        "FMU's directional derivatives with the seed d(inputs)/d(eps) give "
        "d(R_np, M_np)/d(eps) exactly, hence the links' inertia at the crank "
        "-tau1 = J(phi) - J_cO; hand it to the drive as an inertia (mass-matrix) term, "
        "with the torque at eps = 0 as the load, so that the acceleration is solved "
        "with the loop closed, as the stabilised scheme does. Where the other "
        "simulator cannot take an inertia input, iterate the acceleration within each "
        "communication step (an implicit coupling, with rollback of the drive's "
        "state). Then choose the step for accuracy alone: holding the load over a "
        "step costs first order in h, so the step must resolve the load's variation "
        "(in this study 1e-4 s for about 1 % of speed on the slider-crank at 3000 rpm, "
        "1e-3 s on the four-bar at 300 rpm).",
    ]


#: the mechanism FMUs' communication steps [s] (quick: the first only)
MECHANISM_STEPS = {
    "slider_crank": (1e-3, 2.5e-4),
    "four_bar": (1e-3, 2.5e-4),
    "shaper": (1e-2, 2.5e-3),
}


def mechanism_section(quick: bool, fmi_version: int) -> list[str]:
    """The stabilised co-simulation on mechanism FMUs (cosim/mechanism_drive.py): the
    drive FMU and the whole mechanism in one FMU, J from its directional derivative."""
    runs = []
    for name, steps in MECHANISM_STEPS.items():
        for step in steps[:1] if quick else steps:
            r = mechanism_drive.run(name, step, fmi_version)
            runs.append((name, step, r, mechanism_drive.errors(r)))
    return mechanism_lines(runs)


def mechanism_lines(runs: list) -> list[str]:
    """The section on mechanism FMUs, its table one row per (name, step, run of
    :func:`dyadfmu.cosim.mechanism_drive.run`, its errors)."""
    lines = [
        "",
        "## The stabilised coupling on mechanism FMUs",
        "",
        "The drive FMU (motor and rotor) with the mechanism FMU of the slider-crank, the "
        "four-bar and the shaper (crank, links and weights inside, kinematics solved in C): "
        "the master reads the crank state from the drive, sets it on the mechanism FMU at "
        "zero acceleration, takes torque0 from its torque and J from its directional "
        "derivative d(torque)/d(crank.epsilon), and gives the drive load.torque = -torque0 "
        "and load.inertia = J. No kinematics in Python. Reference: the same machine as one "
        "ODE from the harness's kinematics (DOP853, rtol 1e-11). J vs crank.J: the "
        "derivative against the FMU's own effective inertia output; affine: |torque - "
        "(torque0 + J eps)| / |torque| at the solved eps.",
        "",
    ]
    table = []
    for name, step, r, e in runs:
        table.append(
            [
                name,
                f"{step:g}",
                str(len(r.t) - 1),
                _e(e["phi"]),
                _e(e["omega"]),
                _e(r.inertia_mismatch),
                _e(r.affine_residual),
                f"{r.wall_time:.2f}",
            ]
        )
    return lines + markup.table(MECHANISM_HEADER, table, "-" + "r" * 7)


def markdown(
    path: Path,
    rows: list,
    refs: dict,
    quick: bool,
    elapsed: float,
    figure: Path,
    fmi_version: int,
    mechanism_lines: tuple = (),
) -> Path:
    """The co-simulation report in Markdown."""
    names = list(dict.fromkeys(r["mechanism"] for r in rows))
    ratios = sorted({r["ratio"] for r in rows})
    steps = sorted({r["step"] for r in rows}, reverse=True)
    lines = _header(rows, quick, elapsed, figure, fmi_version) + _setup_section(names, quick)
    lines += _machine_rows(rows, refs, names, ratios) + _results_section(rows)
    lines += ["", markup.image("error against run time", figure.name), "", "## Findings", ""]
    lines += _findings(rows, steps)
    lines += list(mechanism_lines)
    lines += _advice()
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _divergence_findings(rows: list) -> list[str]:
    """Which runs diverged, against the prediction; where the explicit errors are."""
    out = []
    ex = [r for r in rows if r["scheme"] == "explicit"]
    st = [r for r in rows if r["scheme"] == "stabilised"]
    ex_div = [r for r in ex if r["diverged"]]
    st_div = [r for r in st if r["diverged"]]
    predicted = [r for r in ex if r["lag_factor_effective"] > 1]
    agree = sum((r["lag_factor_effective"] > 1) == bool(r["diverged"]) for r in ex)
    out.append(
        f"- Explicit: {len(ex_div)} of {len(ex)} runs diverged ("
        + (
            ", ".join(f"{r['mechanism']} ratio {r['ratio']:g} h {r['step']:.0e}" for r in ex_div)
            or "none"
        )
        + f"); max rho x exp(-h / tau_m) > 1 predicts {len(predicted)}, and the "
        f"prediction matches the outcome in {agree} of {len(ex)} runs. Where the crank "
        "is heavier than the links (rho below 1 everywhere) the explicit scheme cannot "
        "diverge, whatever the rotor; at steps long against tau_m the motor settles "
        "the crank within each step and damps the lag."
    )
    settled = [r for r in ex if not r["diverged"]]
    at_start = [r for r in settled if r["reaction_error_at"] == 0.0]
    if settled:
        out.append(
            f"- Explicit, runs that did not diverge: the largest reaction error is at "
            f"t = 0 in {len(at_start)} of {len(settled)}: the first exchange gives the "
            "dyad the drive's acceleration without load, and that error decays only by "
            "rho per step, so it does not shrink with h (the speed error does)."
        )
    out.append(
        f"- Stabilised: {len(st_div)} of {len(st)} runs diverged"
        + (
            ": "
            + "; ".join(f"{r['mechanism']} ratio {r['ratio']:g} h {r['step']:.0e}" for r in st_div)
            if st_div
            else ""
        )
        + "."
    )
    return out


def _order_findings(rows: list, steps: tuple[float, ...]) -> list[str]:
    """The stabilised scheme's speed error over the steps, and its observed order."""
    out = []
    st = [r for r in rows if r["scheme"] == "stabilised"]
    if len(steps) > 1:
        for name in dict.fromkeys(r["mechanism"] for r in rows):
            for ratio in sorted({r["ratio"] for r in rows}):
                sel = sorted(
                    (
                        r
                        for r in st
                        if r["mechanism"] == name and r["ratio"] == ratio and not r["diverged"]
                    ),
                    key=lambda r: -r["step"],
                )
                if len(sel) >= 2:
                    a, b = sel[-2], sel[-1]
                    order = (
                        math.log(a["speed_error"] / b["speed_error"])
                        / math.log(a["step"] / b["step"])
                        if a["speed_error"] > 0 and b["speed_error"] > 0
                        else math.nan
                    )
                    out.append(
                        f"- {name}, ratio {ratio:g}, stabilised: speed error "
                        + ", ".join(f"{r['speed_error']:.1e}" for r in sel)
                        + " for h = "
                        + ", ".join(f"{r['step']:.0e}" for r in sel)
                        + f" s (observed order {order:.2f} between the two finest)."
                    )
    return out


def _cost_findings(rows: list) -> list[str]:
    """Time per communication step, the reference's time, the slope's exactness."""
    out = []
    st = [r for r in rows if r["scheme"] == "stabilised"]
    for scheme in ("explicit", "stabilised"):
        sel = [r for r in rows if r["scheme"] == scheme and r["steps"] >= 100]
        if sel:
            per = sorted(r["wall_time"] / r["steps"] for r in sel)
            out.append(
                f"- Cost, {scheme}: {1e3 * per[len(per) // 2]:.2f} ms per communication "
                "step (median over runs of at least 100 steps; the master is Python: "
                "the closed-form kinematics, fmpy's calls, "
                + (
                    "one dyad solve"
                    if scheme == "explicit"
                    else "two dyad solves and a directional derivative"
                )
                + " per step). A run's wall time counts the FMUs' instantiation and "
                "initialisation (a few ms), not their unpacking."
            )
    mono = {(r["mechanism"], r["ratio"]): r["reference_wall_time"] for r in rows}
    for name in dict.fromkeys(r["mechanism"] for r in rows):
        times = [v for (n, _), v in mono.items() if n == name]
        out.append(
            f"- {name}: the monolithic reference took {min(times):.1f} to "
            f"{max(times):.1f} s per machine (Radau, dense output at the finest "
            "grid; it is the accuracy yardstick, not tuned for speed)."
        )
    res = max((r["affine_residual"] for r in st), default=0.0)
    out.append(
        f"- The directional derivative is the exact slope: the dyad's R_np at the "
        f"solved eps and R_np(0) + eps dR_np/deps differ by at most {res:.1e} "
        f"(relative)."
    )
    return out


def _findings(rows: list, steps: tuple[float, ...]) -> list[str]:
    return _divergence_findings(rows) + _order_findings(rows, steps) + _cost_findings(rows)


def run_study(
    out: Path,
    quick: bool = False,
    fmi_version: int = 2,
    drive: Callable | None = None,
    verbose: bool = False,
) -> dict:
    """Run the study and write ``<out>/cosim/report.md``, ``points.csv`` and
    ``error_vs_time.png``; returns {"report", "points", "plot": paths, "rows": rows}.
    ``drive`` (a factory of a drive slave) defaults to the drive FMU."""
    start = clock.perf_counter()
    if drive is None:
        cosim.drive_fmu_path(fmi_version)  # fail early and clearly
    folder = Path(out) / "cosim"
    folder.mkdir(parents=True, exist_ok=True)
    rows, refs = study_points(quick, fmi_version, drive, verbose=verbose)
    points = write_csv(folder / "points.csv", rows)
    figure = plot(folder / "error_vs_time.png", rows)
    mechanism_lines = mechanism_section(quick, fmi_version)
    found = plant_cosim.points(quick, lambda text: _log(verbose, text))
    plant_figure = plant_cosim.plot(folder / "plant_vs_step.png", found)
    mechanism_lines += plant_cosim.lines(found, plant_figure, quick)
    report = markdown(
        folder / "report.md",
        rows,
        refs,
        quick,
        clock.perf_counter() - start,
        figure,
        fmi_version,
        tuple(mechanism_lines),
    )
    return {
        "report": report,
        "points": points,
        "plot": figure,
        "plant_plot": plant_figure,
        "rows": rows,
        "plant_points": found,
    }


def parser() -> argparse.ArgumentParser:
    """The options of 'dyadfmu cosim'."""
    p = argparse.ArgumentParser(
        prog="dyadfmu cosim",
        description="Co-simulate the drive FMU with the dyad FMU of the slider-crank and the "
        "four-bar (explicit and stabilised coupling, inertia ratios 0.1 to 100, "
        "communication steps 1e-2 to 1e-5 s) against the monolithic machine, and the "
        "slider-crank, the four-bar, the shaper and a leg of two drivers with their motor "
        "inside the plant (the slider-crank's also without inductance), as a motor FMU beside "
        "the plant, and (one driver) as the drive FMU with the mechanism FMU, and the lift "
        "under a force law, in driver angle, speed and joint reactions "
        "(communication steps 1e-1 to 1e-5 s, the plant's rtol 1e-6 to 1e-11); "
        "writes OUT/cosim/report.md, points.csv, error_vs_time.png and plant_vs_step.png. "
        "With --scene, your own mechanism instead (see --scene).",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="steps 1e-2 and 1e-3 s, ratios 1 and 100, the slider-crank's slow motor only, "
        "looser references (about 15 s of CPU time; the full study about 3.8 minutes)",
    )
    p.add_argument("--out", type=Path, default=Path("out"), help="output directory (default: out)")
    p.add_argument(
        "--fmi-version",
        "--fmi",
        type=int,
        choices=(2, 3),
        default=2,
        help="FMI version of both FMUs (default: 2)",
    )
    p.add_argument("--verbose", action="store_true", help="print each run on stderr")
    p.add_argument(
        "--scene",
        type=Path,
        metavar="FILE.toml",
        help="instead of the study: turn the crank of your own scene (one crank, no other "
        "driver; its FMU built where it is stale) with the drive FMU in the stabilised "
        "coupling, the rotor inertia the mean of its crank.J over a revolution; writes "
        "OUT/<identifier>_cosim.csv (time, crank angle, speed, acceleration, torque and "
        "every pair reaction, units in the header) and OUT/<identifier>_cosim.png, and "
        "prints the mean speed, the speed ripple and the peak torque and reaction",
    )
    scene_drive.add_machine_options(p)
    return p


#: The path arguments, checked before any work (dyadfmu.paths.parse_checked).
PATHS = (("--out", "out", paths.OUT), ("--scene", "scene", paths.FILE))


def _options_problem(args: argparse.Namespace) -> str | None:
    """What is wrong with the options beyond each one's own type, or None: those of
    :func:`dyadfmu.cosim.scene_drive.options_problem`, and the study's --quick with --scene."""
    if args.scene is not None and args.quick:
        return "--quick is the study's, not a scene's"
    return scene_drive.options_problem(args)


def main(argv: list[str] | None = None) -> int:
    """Run 'dyadfmu cosim' with `argv`: the study, its report and a summary."""
    command = parser()
    args = paths.parse_checked(command, argv, PATHS)
    problem = _options_problem(args)
    if problem:
        command.error(problem)
    if args.scene is not None:
        return scene_cosim.main(args)
    try:
        result = run_study(
            args.out, quick=args.quick, fmi_version=args.fmi_version, verbose=args.verbose
        )
    except FileNotFoundError as e:
        print(f"dyadfmu cosim: {e}", file=sys.stderr)
        return 2
    rows = result["rows"]
    for kind in cosim.SCHEMES:
        sel = [r for r in rows if r["scheme"] == kind]
        ok = [r for r in sel if not r["diverged"]]
        best = min((r["speed_error"] for r in ok), default=math.nan)
        print(
            f"{kind}: {len(sel) - len(ok)} of {len(sel)} runs diverged; smallest speed "
            f"error {best:.1e}"
        )
    print("written:")
    for key in ("report", "points", "plot", "plant_plot"):
        print(f"  {result[key]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

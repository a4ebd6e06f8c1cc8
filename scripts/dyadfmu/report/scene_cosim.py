"""``dyadfmu cosim --scene FILE.toml``: a user's own mechanism turned by the drive FMU in
the stabilised co-simulation of :func:`dyadfmu.cosim.mechanism_drive.run_fmu`, its machine
derived from its own FMU (:mod:`dyadfmu.cosim.scene_drive`). Writes

- ``OUT/<identifier>_cosim.csv``: at each communication point the time, the crank's
  angle, speed and acceleration, its driving torque and every pair reaction output of the
  FMU, each column's unit in its header;
- ``OUT/<identifier>_cosim.png``: the crank's speed and torque over time and the
  magnitude of every pair reaction;

and prints the machine, the mean speed, the speed ripple, the peak torque and reaction
and the files."""

from __future__ import annotations

import argparse
import sys
import time as clock
from collections.abc import Callable
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from ..cosim import mechanism_drive, scene_drive
from ..fmi.slave import SlaveError

__all__ = ["reaction_outputs", "magnitudes", "run", "main"]

#: Progress on stderr: the first line after this many seconds of wall time, then one as often.
PROGRESS_EVERY = 3.0
#: The crank's columns: (the DriveRun field, the column's name, its unit).
CRANK_COLUMNS = (
    ("t", "t", "s"),
    ("phi", "crank.angle", "rad"),
    ("omega", "crank.omega", "rad/s"),
    ("epsilon", "crank.epsilon", "rad/s2"),
    ("torque", "crank.torque", "N.m"),
)


def reaction_outputs(fmu: Path) -> dict[str, str]:
    """The FMU's pair reaction outputs ({name: unit}): the pairs' forces R_.. (.x, .y, N)
    and a sliding pair's normal force N_.. (N) and reactive moment M_.. (N.m)."""
    found = {}
    for v in read_model_description(str(fmu)).modelVariables:
        parts = v.name.split(".")
        pair = parts[-2] if parts[-1] in ("x", "y") else parts[-1]
        if v.causality == "output" and pair[:2] in ("R_", "N_", "M_"):
            found[v.name] = v.unit or ""
    return found


def magnitudes(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """|R| of every pair reaction (.x with its .y) and |N|, |M| of the sliding pairs."""
    found = {}
    for name, values in columns.items():
        if name.endswith(".x") and f"{name[:-2]}.y" in columns:
            found[name[:-2]] = np.hypot(values, columns[f"{name[:-2]}.y"])
        elif not name.endswith((".x", ".y")):
            found[name] = np.abs(values)
    return found


def _unit(reaction: str) -> str:
    """A reaction magnitude's unit: N m for a sliding pair's moment M_.., else N."""
    return "N m" if reaction.rsplit(".", 1)[-1].startswith("M_") else "N"


def _say(text: str) -> None:
    print(f"dyadfmu cosim: {text}", file=sys.stderr, flush=True)


def _progress(t_end: float) -> Callable[[int, int], None]:
    """A line on stderr every PROGRESS_EVERY s of wall time: how far the run is."""
    started = clock.perf_counter()
    shown = [started]

    def report(k: int, n: int) -> None:
        now = clock.perf_counter()
        if now - shown[0] >= PROGRESS_EVERY:
            shown[0] = now
            print(
                f"dyadfmu cosim: {k * t_end / n:.4g} of {t_end:g} s simulated "
                f"({100 * k / n:.0f} %), {now - started:.0f} s of wall time",
                file=sys.stderr,
                flush=True,
            )

    return report


def write_csv(path: Path, r: mechanism_drive.DriveRun, units: dict[str, str]) -> Path:
    """The run's CSV: the crank's columns, then every reaction output, units in the header."""
    header = [f"{name} [{unit}]" for _, name, unit in CRANK_COLUMNS]
    header += [f"{name} [{units[name]}]" for name in r.extra]
    values = [getattr(r, field) for field, _, _ in CRANK_COLUMNS] + list(r.extra.values())
    np.savetxt(
        path,
        np.column_stack(values),
        fmt="%.12g",
        delimiter=",",
        header=",".join(header),
        comments="",
    )
    return path


def plot(path: Path, identifier: str, r: mechanism_drive.DriveRun) -> Path:
    """The crank's speed and torque over time and every pair reaction's magnitude."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(9.0, 9.0), sharex=True)
    axes[0].plot(r.t, r.omega, color="tab:blue")
    axes[0].set_ylabel("crank speed (rad/s)")
    axes[1].plot(r.t, r.torque, color="tab:red")
    axes[1].set_ylabel("driving torque (N m)")
    for name, values in magnitudes(r.extra).items():
        axes[2].plot(r.t, values, label=name, lw=1.0)
    axes[2].set_ylabel("|reaction| (N; N m for a moment)")
    axes[2].legend(fontsize=7, ncol=2)
    axes[2].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{identifier} turned by the drive FMU (stabilised coupling)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def summary(s: scene_drive.SceneMachine, r: mechanism_drive.DriveRun, files: list) -> list[str]:
    """The machine, mean speed, speed ripple, peak torque and reaction, the files."""
    motor, mean = s.machine.motor, float(np.mean(r.omega))
    ripple = float(np.max(r.omega) - np.min(r.omega))
    k_torque = int(np.argmax(np.abs(r.torque)))
    peaks = {name: values.max() for name, values in magnitudes(r.extra).items()}
    worst = max(peaks, key=peaks.get)
    k_worst = int(np.argmax(magnitudes(r.extra)[worst]))
    return [
        f"{s.identifier} ({s.fmu}): motor {motor.stall_torque:g} N m at stall, "
        f"{motor.no_load_speed:g} rad/s at no load, rotor {motor.rotor_inertia:.4g} kg m2 "
        "(the mean crank.J); start "
        f"{s.machine.omega0:.4g} rad/s; {s.machine.t_end:g} s in {len(r.t) - 1} steps of "
        f"{s.step:g} s ({r.wall_time:.2f} s of wall time)",
        f"mean speed {mean:.6g} rad/s ({mean * 30 / np.pi:.5g} rpm); speed ripple "
        f"{ripple:.4g} rad/s peak to peak ({100 * ripple / abs(mean):.3g} % of the mean)",
        f"peak torque {r.torque[k_torque]:.5g} N m at t = {r.t[k_torque]:.4g} s; peak "
        f"reaction |{worst}| {peaks[worst]:.5g} {_unit(worst)} at t = {r.t[k_worst]:.4g} s",
        "written:",
        *(f"  {path}" for path in files),
    ]


def run(
    scene_file: Path, args: argparse.Namespace, fmi_version: int, out: Path
) -> tuple[scene_drive.SceneMachine, mechanism_drive.DriveRun, list[Path]]:
    """Build where stale, derive the machine, co-simulate, write the CSV and the PNG."""
    s = scene_drive.prepare(scene_file, args, fmi_version, out, _say)
    units = reaction_outputs(s.fmu)
    r = mechanism_drive.run_fmu(
        s.fmu, s.machine, s.step, fmi_version, tuple(units), _progress(s.machine.t_end)
    )
    out.mkdir(parents=True, exist_ok=True)
    files = [
        write_csv(out / f"{s.identifier}_cosim.csv", r, units),
        plot(out / f"{s.identifier}_cosim.png", s.identifier, r),
    ]
    return s, r, files


def main(args: argparse.Namespace) -> int:
    """``dyadfmu cosim --scene``: run and print the summary; a refused scene is one line on
    stderr and status 1."""
    try:
        s, r, files = run(args.scene, args, args.fmi_version, args.out)
    except (scene_drive.SceneRefused, SlaveError) as refused:
        print(f"dyadfmu cosim: error: {refused}", file=sys.stderr)
        return 1
    print("\n".join(summary(s, r, files)))
    return 0

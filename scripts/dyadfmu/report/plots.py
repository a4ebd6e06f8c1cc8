"""Plots of a mechanism run: reactions over the crank angle (FMU and reference, with
the error underneath), the driving torque, and the mechanism drawn to scale
with its reaction vectors."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cosim.harness import MechanismResult  # noqa: E402
from . import drawing  # noqa: E402


def _abscissa(result: MechanismResult):
    """Crank angle in degrees, unwrapped, for the recorded rows; time where the
    crank oscillates (its angle would fold the curves)."""
    rows = result.extra["rows_kin"]
    angle = np.degrees(np.unwrap(rows["crank.angle"]))
    if np.all(np.diff(angle[np.argsort(result.sample)]) >= 0):
        return angle, "crank angle (deg)"
    return rows["t"], "time (s)"


def plot_reactions(result: MechanismResult, path: Path) -> Path:
    """Each output: FMU and reference over the crank angle, the error below."""
    x, label = _abscissa(result)
    order = np.argsort(x, kind="stable")
    names = [e.name for e in result.errors]
    units = result.extra["units"]
    fig, axes = plt.subplots(
        2 * len(names) + 1,
        1,
        figsize=(9, 2.1 * len(names) + 2.6),
        sharex=True,
        gridspec_kw={"height_ratios": [3, 1.2] * len(names) + [3]},
    )
    for k, name in enumerate(names):
        value_ax, error_ax = axes[2 * k], axes[2 * k + 1]
        fmu, ref = result.fmu[name][order], result.ref[name][order]
        value_ax.plot(x[order], fmu, color="tab:blue", lw=1.6, label="FMU")
        value_ax.plot(
            x[order], ref, color="tab:orange", lw=0, marker=".", ms=2.5, label="NumPy reference"
        )
        value_ax.set_ylabel(f"{name}\n({units.get(name, '')})")
        value_ax.grid(alpha=0.3)
        error_ax.plot(x[order], fmu - ref, color="tab:red", lw=0.9)
        error_ax.set_ylabel("error", fontsize=8)
        error_ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        error_ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8)
    torque_ax = axes[-1]
    torque_ax.plot(x[order], result.crank["torque"][order], color="tab:green")
    torque_ax.set_ylabel("driving torque\n(N.m)")
    torque_ax.set_xlabel(label)
    torque_ax.grid(alpha=0.3)
    mech = result.mechanism
    fig.suptitle(
        f"{mech.name} ({mech.dyad} dyad), FMI {result.fmi_version}: reactions from "
        f"the FMU and the NumPy reference; worst error "
        f"{result.worst_relative:.1e} of peak",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.99))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_mechanism(result: MechanismResult, angle_deg: float, path: Path) -> Path:
    """The mechanism at the recorded row nearest to the crank angle, to scale, with
    the reactions of the dyad and the frame's reaction on the crank."""
    rows = result.extra["rows_kin"]
    angle = np.degrees(np.mod(rows["crank.angle"], 2 * np.pi))
    distance = np.abs((angle - angle_deg + 180) % 360 - 180)
    distance[~result.valid] = np.inf
    row = int(np.argmin(distance))
    fmu = result.fmu
    reactions = {
        "R_mk": (fmu["R_mk.x"][row], fmu["R_mk.y"][row]),
        "R_np": (fmu["R_np.x"][row], fmu["R_np.y"][row]),
        "R_mn": (fmu["R_mn.x"][row], fmu["R_mn.y"][row]),
        "R_O": tuple(result.crank["R_O"][row]),
    }
    fig, ax = plt.subplots(figsize=(8, 6.5))
    scale = drawing.draw(ax, result.mechanism, result.kin, int(result.sample[row]), reactions)
    ax.set_title(
        f"{result.mechanism.name} at crank angle {angle[row]:.1f} deg: driving "
        f"torque {result.crank['torque'][row]:.4g} N.m (force scale {scale:.3g} N/m)",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path

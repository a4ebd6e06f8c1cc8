"""The tailored scene FMUs (modelDescription/scenes/*.toml) co-simulated with fmpy and checked
output by output against independent references.

Two kinds of scene:

* the multi-dyad chains ``shaper``, ``sixbar`` and ``rocker_slider``: kinematics, loads and
  the reference
  (one Newton-Euler system of the whole mechanism, crank included) come from
  :mod:`dyadfmu.mechanisms.chains`;
* the single-dyad scenes ``engine``, ``press`` and ``monitor``: kinematics and loads of the
  slider-crank and four-bar of :mod:`dyadfmu.mechanisms.builtin`, the dyad's reactions from
  :mod:`dyadfmu.reference.newton_euler` (its own 6x6 Newton-Euler solve) with the scene's
  effects (no inertia in a static scene, no weight without gravity), and the crank's equilibrium
  written out here.

The FMU's inputs are taken by name from the kinematics; its outputs are compared by name
with the reference. The driving torque of a chain is also checked against the energy
balance of the whole mechanism: M omega + P_loads = d(T + V)/dt.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.simulate import setup_for
from ..mechanisms import builtin, chains, driven
from ..mechanisms import geometry as geo
from ..mechanisms.motion import CrankMotion
from ..reference import newton_euler
from . import SCENE_NAMES
from .compare import (
    NEAR_SINGULAR,
    communication_grid,
    output_error,
    rows_of,
    simulate_matched,
)

SCENES_DIR = paths.SCENES_DIR

#: The tailored example scenes, in the order of the report.
NAMES = SCENE_NAMES

#: Single-dyad scenes: the mechanism whose kinematics they take, and which scene link is
#: the mechanism's link m and n.
SINGLE = {
    "engine": ("slider-crank", {"piston": "m", "rod": "n"}),
    "press": ("slider-crank", {"ram": "m", "rod": "n"}),
    "monitor": ("four-bar", {"rocker": "m", "coupler": "n"}),
}

#: The generic per-type FMUs a scene would need instead (one per dyad).
FULL_OF = {
    "press": ("RRT",),
    "monitor": ("RRR",),
    "engine": ("RRT",),
    "shaper": ("RTR", "RRT"),
    "sixbar": ("RRR", "RRR"),
    "rocker_slider": ("RRR", "RRT"),
}


def fmu_path(name: str, version: int, build: Path | None = None) -> Path:
    """build/fmus/<name>_fmi<version>.fmu, the tailored FMU of a scene."""
    return paths.built_fmu(name, version, build, how="scripts/run-scenes")


def scene_data(name: str) -> dict:
    """The parsed scene file modelDescription/scenes/<name>.toml."""
    with open(SCENES_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


# ---------------------------------------------------------------------------
# A scene's kinematics, FMU inputs and reference
# ---------------------------------------------------------------------------
class Source:
    """What drives one scene: its kinematics and its reference."""

    def __init__(self, name: str):
        self.name = name
        self.scene = scene_data(name)
        effects = self.scene.get("effects", {})
        self.inertia = bool(effects.get("inertia", False))
        self.gravity_on = bool(effects.get("gravity", False))
        g = self.scene.get("gravity", {})
        self.gravity = (
            (float(g.get("x", 0.0)), float(g.get("y", 0.0))) if self.gravity_on else (0.0, 0.0)
        )
        self.crank_name = self.scene.get("crank", {}).get("name", "crank")
        if name in SINGLE:
            mech_name, self.roles = SINGLE[name]
            self.mechanism = builtin.load(mech_name)
            self.chain = None
            self.dyad = self.scene["dyad"][0]
        else:
            self.chain = chains.load(name)
            self.mechanism = None

    def motion(self, kind: str, revolutions: float) -> CrankMotion:
        """The crank's motion of the scene's mechanism."""
        return (self.chain or self.mechanism).motion(kind, revolutions)

    def kinematics(self, t: np.ndarray, motion: CrankMotion) -> dict:
        """The kinematics under the scene's variable names at the times t."""
        if self.chain is not None:
            return self.chain.kinematics(t, motion)
        kin = self.mechanism.kinematics(t, motion)
        out = dict(kin)
        c = self.crank_name
        for key in ("angle", "omega", "epsilon"):
            out[f"{c}.{key}"] = kin[f"crank.{key}"]
        for link, role in self.roles.items():
            for key in ("angle", "omega", "epsilon", "length", "moment"):
                out[f"{link}.{key}"] = kin[f"{role}.{key}"]
            for key in ("accel_d", "force"):
                out[f"{link}.{key}"] = kin[f"{role}.{key}"]
                out[f"{link}.{key}.x"] = kin[f"{role}.{key}"][:, 0]
                out[f"{link}.{key}.y"] = kin[f"{role}.{key}"][:, 1]
        return out

    def inputs(self, kin: dict, names: list[str]) -> dict:
        """The FMU's input signals, by name."""
        missing = [n for n in names if n not in kin]
        if missing:
            raise KeyError(f"scene {self.name}: no kinematics for input(s) {missing}")
        return {n: np.asarray(kin[n], dtype=float).copy() for n in names}

    def reference(self, kin: dict) -> dict:
        """Every output the scene can have, by FMU name."""
        if self.chain is not None:
            return self.chain.reference(kin)
        return self._single_reference(kin)

    def conditioning(self, kin: dict) -> dict:
        """The reference conditioning of every dyad, by FMU output name."""
        if self.chain is not None:
            return {
                f"{d['name']}.conditioning": kin[f"{d['name']}.conditioning"]
                for d in self.scene["dyad"]
            }
        return {f"{self.dyad['name']}.conditioning": self.mechanism.conditioning(kin)}

    # ---- single dyad: reference.solve with the scene's effects, crank balance here
    def _link_input(self, kin: dict, link: str, table: dict) -> dict:
        n = len(kin["t"])
        zero, zero2 = np.zeros(n), np.zeros((n, 2))
        dynamic = self.inertia
        return {
            "dir": geo.unit(kin[f"{link}.angle"]),
            "length": np.asarray(kin[f"{link}.length"], dtype=float),
            "omega": kin[f"{link}.omega"] if dynamic else zero,
            "epsilon": kin[f"{link}.epsilon"] if dynamic else zero,
            "accel_d": kin[f"{link}.accel_d"] if dynamic else zero2,
            "com": tuple(table.get("com", (0.0, 0.0))),
            "mass": float(table.get("mass", 0.0)) if (self.inertia or self.gravity_on) else 0.0,
            "inertia": float(table.get("inertia", 0.0)) if self.inertia else 0.0,
            "force": kin[f"{link}.force"] if link in self._loaded("force") else zero2,
            "moment": kin[f"{link}.moment"] if link in self._loaded("moment") else zero,
        }

    def _loaded(self, key: str):
        return set(self.scene.get("loads", {}).get(key, []))

    def _single_reference(self, kin: dict) -> dict:
        d = self.dyad
        links = {t["name"]: t for t in self.scene["link"]}
        m = self._link_input(kin, d["m"], links[d["m"]])
        n = self._link_input(kin, d["n"], links[d["n"]])
        gk = geo.unit(kin["guide_k.angle"]) if "guide_k.angle" in kin else None
        gp = geo.unit(kin["guide_p.angle"]) if "guide_p.angle" in kin else None
        r = newton_euler.solve(d["type"], m, n, gk, gp, self.gravity)
        pre = f"{d['name']}."
        out = {}
        for pair in ("mk", "np", "mn"):
            out[f"{pre}R_{pair}.x"] = r[f"r_{pair}"][:, 0]
            out[f"{pre}R_{pair}.y"] = r[f"r_{pair}"][:, 1]
            out[f"{pre}N_{pair}"] = r[f"n_{pair}"]
            out[f"{pre}M_{pair}"] = r[f"m_{pair}"]
        # the crank (link p of the dyad, at its pin A = D_n): equilibrium about O
        crank = self.scene["crank"]
        c = self.crank_name
        phi, w, eps = kin[f"{c}.angle"], kin[f"{c}.omega"], kin[f"{c}.epsilon"]
        i_c = geo.unit(phi)
        j_c = geo.rot90(i_c)
        pin = float(crank["length"]) * i_c
        com = crank.get("com", (0.0, 0.0))
        r_s = com[0] * i_c + com[1] * j_c
        mass = float(crank.get("mass", 0.0)) if (self.inertia or self.gravity_on) else 0.0
        inertia = float(crank.get("inertia", 0.0)) if self.inertia else 0.0
        a_s = (
            (eps[:, None] * geo.rot90(r_s) - (w * w)[:, None] * r_s)
            if self.inertia
            else np.zeros_like(r_s)
        )
        own = mass * (np.asarray(self.gravity) - a_s)
        r_np = r["r_np"]
        moments = (
            geo.cross(pin, -r_np) + geo.cross(r_s, own) - inertia * (eps if self.inertia else 0.0)
        )
        out[f"{c}.torque"] = -moments
        r_o = r_np - own
        out[f"{c}.R_O.x"], out[f"{c}.R_O.y"] = r_o[:, 0], r_o[:, 1]
        return out

    # ---- energy of a chain
    def energy(self, kin: dict) -> np.ndarray:
        """Kinetic plus potential energy of the chain at every sample."""
        return self.chain.kinetic_energy(kin) + self.chain.potential_energy(kin)


# ---------------------------------------------------------------------------
# Co-simulation
# ---------------------------------------------------------------------------
@dataclass
class SceneRun:
    """A scene's tailored FMU co-simulated and compared with its reference."""

    name: str
    fmi_version: int
    source: Source
    kin: dict
    sample: np.ndarray
    fmu: dict
    ref: dict
    valid: np.ndarray
    errors: list
    seconds_fmu: float
    steps: int
    units: dict = field(default_factory=dict)
    energy_residual: float = math.nan  # worst |M w + P - dE/dt| / peak |M w|

    @property
    def worst_relative(self) -> float:
        """The largest relative error of any output."""
        return max(e.relative for e in self.errors)


def setup(
    name: str,
    fmi_version: int = 2,
    revolutions: float = 2.0,
    steps: int = 360,
    motion: str = "constant",
    build: Path | None = None,
) -> tuple:
    """The co-simulation of a scene's tailored FMU: (setup, source, crank motion,
    kinematics on the grid); its inputs are taken by name from the kinematics."""
    source = Source(name)
    crank_motion = source.motion(motion, revolutions)
    t = communication_grid(crank_motion.duration, revolutions, steps)
    kin = source.kinematics(t, crank_motion)
    path = fmu_path(name, fmi_version, build)
    md = read_model_description(str(path))
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    return setup_for(path, t, source.inputs(kin, names)), source, crank_motion, kin


def run(
    name: str,
    fmi_version: int = 2,
    revolutions: float = 2.0,
    steps: int = 360,
    motion: str = "constant",
    build: Path | None = None,
    progress: bool = False,
) -> SceneRun:
    """Co-simulate a scene's tailored FMU over `revolutions` crank turns at `steps`
    communication steps per turn and compare every output with the reference."""
    co, source, crank_motion, kin = setup(name, fmi_version, revolutions, steps, motion, build)
    t, outputs, units = co.time, co.outputs, co.units
    fmu, sample, seconds = simulate_matched(
        co, f"{name} FMI {fmi_version}", crank_motion.duration, progress
    )
    rows = rows_of(kin, sample, t)
    full_ref = source.reference(rows)
    full_ref.update(source.conditioning(rows))
    if any(n not in full_ref and n != "status" for n in outputs):
        # a mechanism FMU: its link motion, pair points, slides and the driver's
        # effective inertia, from the same kinematics
        series = driven.driver_motion_inputs(
            source.chain or source.mechanism, t, crank_motion, scene=SCENES_DIR / f"{name}.toml"
        )
        for key, value in series.outputs.items():
            full_ref.setdefault(key, np.asarray(value)[sample])
    ref = {n: np.asarray(full_ref[n]) for n in outputs if n in full_ref}

    cond = [fmu[n] for n in outputs if n.endswith("conditioning")]
    valid = fmu["status"] == 0
    for c in cond:
        valid &= c >= NEAR_SINGULAR
    errors = []
    for out in outputs:
        if out == "status" or out.endswith("amplification"):
            continue
        if out not in ref:
            raise KeyError(f"scene {name}: the reference has no output {out}")
        errors.append(output_error(out, units.get(out, ""), ref[out][valid], fmu[out][valid]))
    result = SceneRun(
        name, fmi_version, source, rows, sample, fmu, ref, valid, errors, seconds, len(t) - 1, units
    )
    torque = f"{source.crank_name}.torque"
    if source.chain is not None and torque in fmu:
        result.energy_residual = energy_balance(
            source, crank_motion, fmu["time"], fmu[torque], t[sample]
        )
    return result


def energy_balance(
    source: Source, motion: CrankMotion, time: np.ndarray, torque: np.ndarray, t_samples: np.ndarray
) -> float:
    """Worst |M omega + P_loads - d(T + V)/dt| over the run, relative to the peak driving
    power; dE/dt by 4th-order central differences of the reference energies."""
    w0 = float(np.max(np.abs(motion.omega(t_samples))))
    h = 1e-3 / w0
    energies = [source.energy(source.kinematics(t_samples + j * h, motion)) for j in (-2, -1, 1, 2)]
    rate = (energies[0] - 8 * energies[1] + 8 * energies[2] - energies[3]) / (12 * h)
    kin = source.kinematics(t_samples, motion)
    power = torque * kin[f"{source.crank_name}.omega"]
    loads = source.chain.load_power(kin)
    residual = power + loads - rate
    return float(np.max(np.abs(residual)) / np.max(np.abs(power)))


def summary(result: SceneRun) -> str:
    """One line on the run: steps, time, worst error, driving torque, energy balance."""
    text = (
        f"{result.name}, FMI {result.fmi_version}: {result.steps} steps in "
        f"{result.seconds_fmu:.3f} s; {len(result.errors)} outputs, worst relative error "
        f"{result.worst_relative:.2e}"
    )
    torque = result.fmu.get(f"{result.source.crank_name}.torque")
    if torque is not None:
        t = torque[result.valid]
        text += f"; driving torque {t.min():.4g} .. {t.max():.4g} N m"
    if not math.isnan(result.energy_residual):
        text += f"; energy balance {result.energy_residual:.1e} of the peak driving power"
    left = int((~result.valid).sum())
    if left:
        text += f"; {left} near-singular rows left out"
    return text


def reactions_of(result: SceneRun) -> dict:
    """The FMU's outputs, row by row as result.kin (for drawing)."""
    return {k: v for k, v in result.fmu.items() if k != "time"}


def drawing_indices(
    result: SceneRun, angles_deg: tuple[float, ...] = (30.0, 120.0, 210.0, 300.0)
) -> list:
    """The rows nearest to the given crank angles (first occurrence), for drawings."""
    phi = np.mod(np.asarray(result.kin[f"{result.source.crank_name}.angle"]), 2 * math.pi)
    picks = []
    for a in angles_deg:
        gap = np.abs(np.angle(np.exp(1j * (phi - math.radians(a)))))
        picks.append(int(np.argmin(gap)))
    return picks

"""Co-simulation of a mechanism's dyad FMU with fmpy, checked output by output
against the independent Newton-Euler reference.

A mechanism is one of the five of :mod:`dyadfmu.mechanisms.builtin`: its kinematics
and loads become the FMU's input signals, fmpy's ``simulate_fmu`` steps the FMU
over the run, and the reference solves the same recorded inputs with
``numpy.linalg.solve``.
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import paths
from ..fmi.simulate import CoSimSetup, setup_for
from ..mechanisms import builtin, crank
from ..reference import newton_euler
from .compare import (
    NEAR_SINGULAR,
    OutputError,
    communication_grid,
    output_error,
    rows_of,
    simulate_matched,
)

#: FMU output name -> (reference key, component or None).
OUTPUTS = {
    "R_mk.x": ("r_mk", 0),
    "R_mk.y": ("r_mk", 1),
    "R_np.x": ("r_np", 0),
    "R_np.y": ("r_np", 1),
    "R_mn.x": ("r_mn", 0),
    "R_mn.y": ("r_mn", 1),
    "N_mk": ("n_mk", None),
    "N_np": ("n_np", None),
    "N_mn": ("n_mn", None),
    "M_mk": ("m_mk", None),
    "M_np": ("m_np", None),
    "M_mn": ("m_mn", None),
}


def fmu_path(dyad: str, version: int, build: Path | None = None) -> Path:
    """build/fmus/dyad_<type>_fmi<version>.fmu, the generic FMU of a dyad type."""
    return paths.built_fmu(f"dyad_{dyad.lower()}", version, build)


def links_from_values(values: dict, dyad: str) -> tuple:
    """The reference's inputs from FMU variable values (inputs and parameters).

    `values` maps FMU variable names to arrays (or scalars); returns
    (m, n, guide_k, guide_p, gravity) for :func:`reference.solve`.
    """

    def get(name: str):
        return np.asarray(values[name], dtype=float) if name in values else 0.0

    def vec(x: str, y: str):
        x, y = np.broadcast_arrays(get(x), get(y))
        return np.stack([x, y], axis=-1)

    def direction(name: str):
        angle = get(name)
        return np.stack([np.cos(angle), np.sin(angle)], axis=-1)

    def link(g: str):
        return dict(
            dir=direction(f"link_{g}.angle"),
            length=get(f"link_{g}.length"),
            omega=get(f"link_{g}.omega"),
            epsilon=get(f"link_{g}.epsilon"),
            accel_d=vec(f"link_{g}.accel_d.x", f"link_{g}.accel_d.y"),
            com=vec(f"link_{g}.com.x", f"link_{g}.com.y"),
            mass=get(f"link_{g}.mass"),
            inertia=get(f"link_{g}.inertia"),
            force=vec(f"link_{g}.force.x", f"link_{g}.force.y"),
            moment=get(f"link_{g}.moment"),
        )

    pairs = newton_euler.PAIRS[dyad]
    guide_k = direction("guide_k.angle") if pairs[0] == "T" else None
    guide_p = direction("guide_p.angle") if pairs[2] == "T" else None
    return link("m"), link("n"), guide_k, guide_p, vec("gravity.x", "gravity.y")


def reference_outputs(ref: dict, names: list[str]) -> dict:
    """The reference's solution under the FMU's output names."""
    out = {}
    for name in names:
        if name in OUTPUTS:
            key, component = OUTPUTS[name]
            out[name] = ref[key][:, component] if component is not None else ref[key]
    return out


@dataclass
class MechanismResult:
    """One mechanism's dyad FMU co-simulated and compared with the reference."""

    mechanism: builtin.Mechanism
    fmi_version: int
    kin: dict  # kinematics on the sample grid
    sample: np.ndarray  # kinematic sample index of each recorded row
    fmu: dict  # recorded FMU variables, name -> array
    ref: dict  # reference under FMU output names
    valid: np.ndarray  # rows away from singular positions
    errors: list[OutputError]
    crank: dict  # driving torque and pivot reaction, from the FMU
    seconds_fmu: float
    seconds_reference: float
    steps: int
    extra: dict = field(default_factory=dict)

    @property
    def worst_relative(self) -> float:
        """The largest relative error of any output."""
        return max(e.relative for e in self.errors)


def mechanism_setup(
    name: str,
    fmi_version: int = 2,
    revolutions: float = 2.0,
    steps: int = 360,
    motion: str = "constant",
    build: Path | None = None,
) -> tuple:
    """The co-simulation of one mechanism's dyad FMU: (setup, mechanism, crank motion,
    kinematics on the grid)."""
    mech = builtin.load(name)
    crank_motion = mech.motion(motion, revolutions)
    t = communication_grid(crank_motion.duration, revolutions, steps)
    kin = mech.kinematics(t, crank_motion)
    setup = setup_for(
        fmu_path(mech.dyad, fmi_version, build), t, mech.fmu_inputs(kin), mech.fmu_parameters()
    )
    return setup, mech, crank_motion, kin


def _errors(setup: CoSimSetup, fmu: dict, ref: dict, valid: np.ndarray) -> list[OutputError]:
    return [
        output_error(out, setup.units.get(out, ""), ref[out][valid], fmu[out][valid])
        for out in setup.outputs
        if out in ref
    ]


def run_mechanism(
    name: str,
    fmi_version: int = 2,
    revolutions: float = 2.0,
    steps: int = 360,
    motion: str = "constant",
    build: Path | None = None,
    progress: bool = False,
) -> MechanismResult:
    """Co-simulate one mechanism's dyad FMU and compare it with the reference.

    steps: communication steps per crank revolution (or oscillation).
    """
    setup, mech, crank_motion, kin = mechanism_setup(
        name, fmi_version, revolutions, steps, motion, build
    )
    t, names = setup.time, list(setup.inputs)
    fmu, sample, seconds_fmu = simulate_matched(
        setup, f"{name} FMI {fmi_version}", crank_motion.duration, progress
    )

    started = clock.perf_counter()
    values = dict(setup.start_values)
    values.update({n: fmu[n] for n in names})
    ref_raw = newton_euler.solve(mech.dyad, *links_from_values(values, mech.dyad))
    seconds_reference = clock.perf_counter() - started
    ref = reference_outputs(ref_raw, setup.outputs)

    valid = (fmu["status"] == 0) & (fmu["conditioning"] >= NEAR_SINGULAR)
    r_np = np.stack([fmu["R_np.x"], fmu["R_np.y"]], axis=-1)
    rows_kin = rows_of(kin, sample, t)
    balance = crank.balance(mech, rows_kin, r_np, fmu.get("M_np"))
    return MechanismResult(
        mech,
        fmi_version,
        kin,
        sample,
        fmu,
        ref,
        valid,
        _errors(setup, fmu, ref, valid),
        balance,
        seconds_fmu,
        seconds_reference,
        len(t) - 1,
        extra={"rows_kin": rows_kin, "units": setup.units},
    )


def summary(result: MechanismResult) -> str:
    """One line on the run: steps, times, worst error, driving torque, rows left out."""
    mech = result.mechanism
    torque = result.crank["torque"][result.valid]
    return (
        f"{mech.name} ({mech.dyad}), FMI {result.fmi_version}: {result.steps} steps, "
        f"co-simulation {result.seconds_fmu:.3f} s, reference {result.seconds_reference:.4f} s; "
        f"worst relative error {result.worst_relative:.2e}; "
        f"driving torque {torque.min():.4g} .. {torque.max():.4g} N m; "
        f"{int((~result.valid).sum())} near-singular samples left out"
    )

"""The stabilised co-simulation of the drive FMU with a mechanism FMU: the motor and its
rotor in one FMU, the whole mechanism (crank, links, weights) in the other, and no
kinematics in Python.

The mechanism FMU's driving torque is affine in the crank's acceleration,
torque = torque0 + J eps, and both terms come from the FMU itself at each communication
point: torque0 is its torque at eps = 0, J its exact directional derivative
d(torque)/d(crank.epsilon). The drive FMU (inertia J_r, the rotor; no crank of its own)
then gets load.torque = -torque0 and load.inertia = J, so that its acceleration solves

    (J_r + J(phi)) eps = T_motor(omega) - torque0(phi, omega),

the machine's equation at the communication point; the mechanism FMU is set to that eps
and both FMUs step. The master reads and writes only the crank's angle, speed and
acceleration and the torque; every position, velocity and reaction is the FMU's.

The reference (:func:`reference`) integrates the same machine as one ODE,
(J_r + J) phi'' = T_motor(phi') + Q_g(phi) - J'(phi) phi'^2 / 2, with J, J' and the
generalised weight force Q_g from the harness's own kinematics
(:mod:`dyadfmu.mechanisms.driven`), by Radau at rtol 1e-11.

API: :data:`MACHINES`, :func:`run` (-> :class:`DriveRun`), :func:`run_fmu` (any mechanism
FMU with a :class:`Machine`), :func:`drive_parameters`, :func:`reference`, :func:`errors`.
"""

from __future__ import annotations

import math
import time as clock
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import paths
from ..fmi.slave import Slave, SlaveError
from ..mechanisms import driven
from ..reference import machine
from . import master, mechanism_fmus

__all__ = [
    "MACHINES",
    "DriveRun",
    "Machine",
    "machine_of",
    "run",
    "run_fmu",
    "drive_parameters",
    "reference",
    "errors",
    "whole_steps",
]

#: The mechanism FMUs of the study: the harness's motor for the mechanism (the shaper a
#: 100 N m motor of 7.5 rad/s no-load speed, as the quick-return's), the start speed
#: [rad/s] and the simulated time [s]. One drive FMU turns one crank through its J: the
#: scenes with several drivers (leg, three_drivers) are not among them, their drivers
#: coupled through M(q) would need a drive each and M's off-diagonal entries between them.
MACHINES = {
    "slider_crank": ("slider-crank", 314.16, 0.1),
    "four_bar": ("four-bar", 31.4, 0.25),
    "shaper": ("quick-return", 6.0, 1.0),
}
START_ANGLE = 0.5
_CRANK = ("crank.angle", "crank.omega", "crank.epsilon")


@dataclass(frozen=True)
class Machine:
    """Motor (rotor inertia = the mean J over a revolution), start state, duration."""

    name: str
    motor: machine.Motor
    omega0: float
    t_end: float


def machine_of(name: str) -> Machine:
    """The machine of :data:`MACHINES` for the mechanism FMU ``name``."""
    if name not in MACHINES:
        raise ValueError(f"no machine for {name!r}; expected one of {', '.join(MACHINES)}")
    motor_of, omega0, t_end = MACHINES[name]
    q = np.linspace(0.0, 2 * math.pi, 360, endpoint=False)
    J, _ = driven.effective_inertia(mechanism_fmus.mechanism_of(name), q)
    motor = machine.MOTORS[motor_of].with_rotor_inertia(float(np.mean(J)))
    return Machine(name, motor, omega0, t_end)


@dataclass
class DriveRun:
    """The co-simulation at its communication points: t, phi, omega, epsilon, the
    mechanism FMU's torque (N m) and J (kg m2, its directional derivative); the largest
    |J - crank.J| / crank.J (the derivative against the FMU's own output) and the largest
    |torque - (torque0 + J eps)| / |torque| (the affine split); ``extra``: the mechanism
    FMU's further outputs asked for (name -> values at the communication points)."""

    name: str
    step: float
    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    torque: np.ndarray
    inertia: np.ndarray
    inertia_mismatch: float
    affine_residual: float
    wall_time: float
    extra: dict[str, np.ndarray] = field(default_factory=dict)


def drive_parameters(m: Machine) -> dict[str, float]:
    """The drive FMU's parameters for the machine ``m``: its motor and rotor, no crank mass
    (the crank, with its weight, is the mechanism FMU's), the start angle and speed."""
    return {
        "motor.stall_torque": m.motor.stall_torque,
        "motor.no_load_speed": m.motor.no_load_speed,
        "inertia": m.motor.rotor_inertia,
        "crank.mass": 0.0,
        "start.angle": START_ANGLE,
        "start.speed": m.omega0,
    }


def _drive(m: Machine, fmi_version: int) -> Slave:
    d = Slave(master.drive_fmu_path(fmi_version), instance_name="drive")
    d.initialize(drive_parameters(m))
    return d


def _point(d: Slave, y: Slave, t: float, checks: list) -> tuple:
    """One communication point: (phi, omega, eps, torque, J)."""
    phi, omega = d.get(("crank.angle", "crank.omega"))
    y.set(_CRANK, (phi, omega, 0.0))
    torque0, j_out = y.get(("crank.torque", "crank.J"))
    (j,) = y.directional_derivative(("crank.torque",), ("crank.epsilon",), [1.0])
    d.set(("load.torque", "load.inertia"), (-torque0, j))
    eps = d.get("crank.epsilon")
    if not all(map(math.isfinite, (phi, omega, eps, torque0, j))):
        raise SlaveError("master", "communication point", 2, f"not finite at t = {t:g} s")
    y.set(("crank.epsilon",), (eps,))
    torque = y.get("crank.torque")
    checks[0] = max(checks[0], abs(j - j_out) / abs(j_out))
    checks[1] = max(checks[1], abs(torque - (torque0 + j * eps)) / max(abs(torque), 1e-300))
    return phi, omega, eps, torque, j


def whole_steps(t_end: float, step: float) -> int:
    """The number of communication steps ``step`` [s] in ``t_end`` [s], refused unless whole."""
    n = int(round(t_end / step))
    if n < 1 or abs(n * step - t_end) > 1e-9 * t_end:
        raise ValueError(f"{t_end} s is not a whole number of steps of {step!r} s")
    return n


def run(
    name: str,
    step: float,
    fmi_version: int = 2,
    m: Machine | None = None,
    outputs: tuple[str, ...] = (),
) -> DriveRun:
    """The stabilised co-simulation of ``name``'s machine (or ``m``, a machine of that
    mechanism FMU) with communication step ``step``, recording the mechanism FMU's
    ``outputs`` besides the crank's motion and torque."""
    fmu = paths.built_fmu(name, fmi_version, None, how="scripts/run-tests")
    return run_fmu(fmu, m or machine_of(name), step, fmi_version, outputs)


def run_fmu(
    fmu: Path,
    m: Machine,
    step: float,
    fmi_version: int = 2,
    outputs: tuple[str, ...] = (),
    progress: Callable[[int, int], None] | None = None,
) -> DriveRun:
    """The stabilised co-simulation of the machine ``m`` turning the crank of the mechanism
    FMU ``fmu`` (of this FMI version) with communication step ``step`` [s], recording the
    FMU's ``outputs`` besides the crank's motion and torque; ``progress(k, n)`` is called
    after each of the n steps."""
    n = whole_steps(m.t_end, step)
    started = clock.perf_counter()
    d = _drive(m, fmi_version)
    y = Slave(fmu, "mechanism")
    y.initialize()
    rows, checks, extra = [], [0.0, 0.0], []
    try:
        for k in range(n + 1):
            rows.append(_point(d, y, k * step, checks))
            extra.append(y.get(outputs) if outputs else ())
            if k < n:
                y.do_step(k * step, step)
                d.do_step(k * step, step)
                if progress is not None:
                    progress(k + 1, n)
    finally:
        d.close()
        y.close()
    a = np.array(rows)
    t = step * np.arange(len(rows))
    wall = clock.perf_counter() - started
    columns = dict(zip(outputs, np.array(extra, dtype=float).reshape(len(rows), -1).T, strict=True))
    return DriveRun(m.name, step, t, *a.T, checks[0], checks[1], wall, columns)


def reference(name: str, t: np.ndarray, m: Machine | None = None) -> tuple:
    """(phi, omega) of the machine (``name``'s, or ``m``) as one ODE on the grid t, from
    the harness's kinematics."""
    from scipy.integrate import solve_ivp

    m = m or machine_of(name)
    mech = mechanism_fmus.mechanism_of(name)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        J, dJ = driven.effective_inertia(mech, y[:1])
        Q = driven.generalized_gravity(mech, y[:1])
        T = m.motor.torque(y[1])
        return np.array(
            [y[1], (T + Q[0] - 0.5 * dJ[0] * y[1] ** 2) / (m.motor.rotor_inertia + J[0])]
        )

    sol = solve_ivp(
        rhs,
        (0.0, float(t[-1])),
        [START_ANGLE, m.omega0],
        method="DOP853",
        rtol=1e-11,
        atol=1e-12,
        t_eval=t,
    )
    return sol.y[0], sol.y[1]


def errors(result: DriveRun, m: Machine | None = None) -> dict:
    """Largest |phi - reference| [rad] and |omega - reference| / mean speed over the run
    (of ``result.name``'s machine, or ``m``)."""
    phi, omega = reference(result.name, result.t, m)
    return {
        "phi": float(np.max(np.abs(result.phi - phi))),
        "omega": float(np.max(np.abs(result.omega - omega)) / np.mean(np.abs(omega))),
    }

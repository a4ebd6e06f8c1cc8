"""A co-simulation master for a motor-driven mechanism: the drive FMU (motor, rotor and
crank, with states) coupled to the mechanism's dyad FMU (kinetostatic, no states)
through the crank's closed-form kinematics -- the machine of :mod:`dyadfmu.reference.machine`
split into two FMUs and stepped with fmpy's low-level classes (FMI 2 and FMI 3).

The coupling
------------
The drive FMU integrates

    (inertia + load.inertia) eps = T_motor(omega) + load.torque + r_c x m_c g

with ``inertia`` = J_r + J_cO: the rotor plus the crank about its pivot O
(J_cO = crank inertia about its centre of mass + crank mass |com|^2, the crank's share of
J(phi) in :mod:`dyadfmu.reference.machine`). The crank is the drive's; the dyad FMU brings only
the links m and n. Its reaction on the crank is -R_np at D_n (and -M_np where D_n slides
on the crank), so the dyad's torque on the crank about O is

    tau = (D_n - O) x (-R_np) - M_np.

The dyad's inputs (link angles, speeds, accelerations, loads) follow from the crank state
(phi, omega, eps) by :func:`dyadfmu.reference.machine.state_kinematics` and
``Mechanism.fmu_inputs``; they are affine in eps, hence so is tau:
tau(eps) = tau0 + tau1 eps, with -tau1 = J(phi) - J_cO the links' share of the reduced
inertia. Summing the two FMUs gives (J_r + J(phi)) eps + ... = T_motor + Q: the machine
that :func:`dyadfmu.reference.machine.monolithic` integrates as one ODE.

Two schemes per communication step [t, t + h]:

* ``explicit``: the dyad gets (phi, omega) at t and the last eps the drive reported;
  load.torque = tau(that eps), load.inertia = 0; drive.doStep. The eps the dyad sees lags
  one step: eps_k = (... + tau1 eps_{k-1}) / (J_r + J_cO), a fixed-point iteration with
  factor -(J(phi) - J_cO) / (J_r + J_cO) per step, damped within the step by the motor's
  torque-speed slope (:func:`explicit_lag_factor`). Where the links outweigh rotor plus
  crank and the step is short against the motor's time constant it diverges.
* ``stabilised``: tau0 from the dyad FMU at eps = 0, tau1 from its directional
  derivatives (unknowns R_np.x, R_np.y (and M_np), knowns the inputs, seed d(inputs)/d(eps)
  = the inputs at eps = 1 minus those at eps = 0, exact since they are affine);
  load.torque = tau0, load.inertia = -tau1; the drive's eps then closes the loop exactly
  at the communication point. The dyad is then set to the inputs at that eps (its
  reaction is the FMU's own output at the solved state) and both FMUs step.

Divergence (a run stops, is flagged, never raises): crank speed not finite or beyond
:data:`DIVERGENCE_SPEED_FACTOR` x the motor's no-load speed, a dyad status other than 0
(singular, invalid input, out of range), or an FMU call that fails (error or discard).

The monolithic reference (:func:`reference`) is :func:`dyadfmu.reference.machine.monolithic` with
the same motor, rotor inertia and start state, evaluated at the communication points,
with the reactions of :func:`dyadfmu.reference.newton_euler.solve` at its states.

API: :func:`run` (-> :class:`CosimRun`), :func:`run_setup`, :func:`reference`
(-> :class:`Reference`), :func:`reference_for`, :func:`errors`, :func:`setup`
(-> :class:`Setup`), :func:`drive_parameters`,
:func:`crank_inertia_about_pivot`, :func:`explicit_lag_factor`, :func:`drive_fmu_path`;
the FMUs run through :class:`dyadfmu.fmi.slave.Slave`.
"""

from __future__ import annotations

import math
import time as clock
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import paths
from ..fmi.slave import Slave, SlaveError
from ..mechanisms import builtin
from ..reference import machine, newton_euler
from . import harness

__all__ = [
    "SCHEMES",
    "STUDY_MECHANISMS",
    "DURATIONS",
    "START_ANGLE",
    "DIVERGENCE_SPEED_FACTOR",
    "DRIVE_OUTPUTS",
    "drive_fmu_path",
    "drive_available",
    "crank_inertia_about_pivot",
    "drive_parameters",
    "explicit_lag_factor",
    "Setup",
    "setup",
    "CosimRun",
    "run",
    "run_setup",
    "Reference",
    "reference",
    "reference_for",
    "errors",
]

#: The coupling schemes of :func:`run`.
SCHEMES = ("explicit", "stabilised")
#: The mechanisms of the study (any revolving-crank mechanism of NAMES runs).
STUDY_MECHANISMS = ("slider-crank", "four-bar")
#: Simulated time [s] per mechanism: the slider-crank turns 5 times at 3000 rpm in 0.1 s,
#: the four-bar about 1.25 times at 300 rpm in 0.25 s.
DURATIONS = {"slider-crank": 0.1, "four-bar": 0.25, "quick-return": 1.25, "scotch-yoke": 0.25}
#: Start angle [rad] of every run: the slider-crank's conditioning |i_n . i_k| is at least
#: 0.94 over a revolution (0.997 here), the four-bar's |sin(theta_m - theta_n)| at least
#: 0.73 (0.82 here); the start speed is the mechanism's nominal speed.
START_ANGLE = 0.5
#: A run has diverged once |omega| exceeds this many times the motor's no-load speed.
DIVERGENCE_SPEED_FACTOR = 20.0

#: The drive FMU's outputs the master reads after each step (crank state, motor torque).
DRIVE_OUTPUTS = ("crank.angle", "crank.omega", "crank.epsilon", "motor.torque")
_DRIVE_INPUTS = ("load.torque", "load.inertia")
_DYAD_STATUS = {0: "ok", 1: "singular", 2: "invalid input", 3: "out of range"}


# ---------------------------------------------------------------------------
# the FMUs
# ---------------------------------------------------------------------------
def drive_fmu_path(version: int, build: Path | None = None) -> Path:
    """build/fmus/drive_fmi<version>.fmu (FileNotFoundError while it is not built)."""
    return paths.built_fmu("drive", version, build, what="the drive FMU")


def drive_available(version: int = 2, build: Path | None = None) -> bool:
    """Whether the drive FMU of this FMI version is built."""
    try:
        drive_fmu_path(version, build)
    except FileNotFoundError:
        return False
    return True


# ---------------------------------------------------------------------------
# the machine split in two
# ---------------------------------------------------------------------------
def crank_inertia_about_pivot(mech: builtin.Mechanism) -> float:
    """J_cO [kg m2]: the crank's inertia about its centre of mass plus mass |com|^2 -- its
    constant share of J(phi) in :mod:`dyadfmu.reference.machine`
    (m |v_Sc|^2 + J_c at unit speed)."""
    c = mech.crank
    return float(c["inertia"] + c["mass"] * (c["com"][0] ** 2 + c["com"][1] ** 2))


def drive_parameters(
    mech: builtin.Mechanism, motor: machine.Motor, phi0: float, omega0: float
) -> dict:
    """The drive FMU's parameters for this mechanism's crank, the motor (with its rotor
    inertia) and the start state: ``inertia`` = J_r + J_cO."""
    return {
        "motor.stall_torque": motor.stall_torque,
        "motor.no_load_speed": motor.no_load_speed,
        "inertia": motor.rotor_inertia + crank_inertia_about_pivot(mech),
        "crank.mass": mech.crank["mass"],
        "crank.com.x": mech.crank["com"][0],
        "crank.com.y": mech.crank["com"][1],
        "gravity.x": mech.gravity[0],
        "gravity.y": mech.gravity[1],
        "start.angle": float(phi0),
        "start.speed": float(omega0),
    }


def explicit_lag_factor(
    mech: builtin.Mechanism, motor: machine.Motor, step: float = 0.0, samples: int = 720
) -> dict:
    """How the explicit scheme's lagged acceleration error propagates from one
    communication point to the next: it is multiplied by -rho(phi), rho = (J(phi) - J_cO) /
    (J_r + J_cO) (the links' inertia at the crank against the drive's), and damped within
    the step by the motor, whose torque-speed slope relaxes the drive's acceleration
    with the time constant tau_m = (J_r + J_cO) omega_0 / T_stall, by exp(-h / tau_m).

    Returns ``max``, ``mean``, ``geometric`` (mean) of rho over a revolution,
    ``time_constant`` tau_m [s], ``damping`` exp(-step / tau_m) and ``effective`` =
    max rho x damping: above 1 the error grows wherever rho is largest and the explicit
    run diverges (at fine steps whenever the links outweigh rotor plus crank somewhere
    on the revolution); below 1 it dies out."""
    phi = np.arange(samples) * (2.0 * math.pi / samples)
    J, _ = machine.reduced_inertia(mech, phi)
    jc = crank_inertia_about_pivot(mech)
    drive_inertia = motor.rotor_inertia + jc
    rho = (J - jc) / drive_inertia
    tau_m = drive_inertia * motor.no_load_speed / motor.stall_torque
    damping = math.exp(-float(step) / tau_m)
    return {
        "max": float(np.max(rho)),
        "mean": float(np.mean(rho)),
        "geometric": float(np.exp(np.mean(np.log(np.maximum(rho, 1e-300))))),
        "time_constant": float(tau_m),
        "damping": damping,
        "effective": float(np.max(rho)) * damping,
    }


@dataclass(frozen=True)
class Setup:
    """A machine to co-simulate: mechanism, motor (its rotor inertia set for ``ratio``),
    start state, simulated time."""

    mech: builtin.Mechanism
    motor: machine.Motor
    ratio: float | None
    phi0: float
    omega0: float
    t_end: float


def setup(
    name: str,
    ratio: float,
    t_end: float | None = None,
    phi0: float = START_ANGLE,
    omega0: float | None = None,
) -> Setup:
    """The study's machine: ``name``'s default motor with the rotor inertia of
    :func:`dyadfmu.reference.machine.rotor_inertia_for_ratio` (mean J / J_r = ratio), starting at
    phi0 with the nominal crank speed, over :data:`DURATIONS`."""
    mech = builtin.load(name)
    if machine.phi_range(mech) is not None:
        raise ValueError(f"{name}: the co-simulation needs a revolving crank")
    motor = machine.default_motor(mech).with_rotor_inertia(
        machine.rotor_inertia_for_ratio(mech, ratio)
    )
    w0 = float(mech.data["motion"]["omega"]) if omega0 is None else float(omega0)
    return Setup(
        mech,
        motor,
        float(ratio),
        float(phi0),
        w0,
        float(DURATIONS[name] if t_end is None else t_end),
    )


# ---------------------------------------------------------------------------
# the master
# ---------------------------------------------------------------------------
@dataclass
class CosimRun:
    """One co-simulation, at the communication points t_k = k h reached (arrays (N,)).

    phi, omega [rad, rad/s]: the drive's state; epsilon [rad/s2]: the drive's acceleration
    for that state and the load inputs set at t_k; r_np (N, 2) [N], m_np (N,) [N m]: the dyad
    FMU's reaction at t_k (explicit: at the lagged eps; stabilised: at the solved eps);
    load_torque, load_inertia: the drive's inputs over [t_k, t_k + h]; motor_torque [N m].
    wall_time [s]: instantiation, initialisation and stepping (FMUs already unpacked). diverged,
    diverged_at [s], reason: why the run stopped early. affine_residual: stabilised only,
    the largest |R_np(eps) - (R_np(0) + eps dR_np/deps)| relative to |R_np(eps)| (checks
    that the directional derivative is the exact slope)."""

    mechanism: str
    scheme: str
    fmi_version: int
    step: float
    t_end: float
    rotor_inertia: float
    ratio: float | None
    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    motor_torque: np.ndarray
    load_torque: np.ndarray
    load_inertia: np.ndarray
    r_np: np.ndarray
    m_np: np.ndarray
    wall_time: float
    diverged: bool
    diverged_at: float | None = None
    reason: str = ""
    affine_residual: float = 0.0
    drive_label: str = ""

    @property
    def steps(self) -> int:
        """Communication steps completed."""
        return max(len(self.t) - 1, 0)


def _cross(a: np.ndarray, b: np.ndarray):
    return a[0] * b[1] - a[1] * b[0]


class _Diverged(Exception):
    """A run that stops: the time and the reason."""

    def __init__(self, t: float, reason: str) -> None:
        super().__init__(reason)
        self.t, self.reason = t, reason


class _Coupling:
    """One communication point of a run: the crank state from the drive, the dyad's
    reaction on the crank, the drive's acceleration under it (module docstring)."""

    def __init__(
        self, mech: builtin.Mechanism, scheme: str, motor: machine.Motor, d: Slave, y: Slave
    ) -> None:
        self.mech, self.scheme, self.d, self.y = mech, scheme, d, y
        self.outputs = ("R_np.x", "R_np.y") + (("M_np",) if "M_np" in y.names else ())
        self.has_m = len(self.outputs) == 3
        self.limit = DIVERGENCE_SPEED_FACTOR * motor.no_load_speed
        self.inputs = None
        self.residual = 0.0

    def _crank_state(self, t: float) -> tuple:
        phi, omega, eps_prev, _ = self.d.get(DRIVE_OUTPUTS)
        if not math.isfinite(omega) or not math.isfinite(phi):
            raise _Diverged(
                t,
                f"crank state not finite (angle {phi:g} rad, speed {omega:g} "
                f"rad/s, drive status {self.d.get_status()})",
            )
        if abs(omega) > self.limit:
            raise _Diverged(
                t,
                f"crank speed {omega:.4g} rad/s beyond "
                f"{DIVERGENCE_SPEED_FACTOR:g} x the no-load speed "
                f"({self.limit:.4g} rad/s)",
            )
        return phi, omega, eps_prev

    def _dyad_failed(self, t: float, where: str) -> _Diverged:
        status = self.y.get_status()
        return _Diverged(
            t, f"dyad FMU status {status} ({_DYAD_STATUS.get(status, '?')}) at {where}"
        )

    def _moment(self, kin: dict, r: list) -> float:
        """The dyad's torque on the crank about O from the reaction r (or its slope)."""
        lever = kin["D_n"][0] - kin["O"][0]
        return _cross(lever, (-r[0], -r[1])) - (r[2] if self.has_m else 0.0)

    def _set_dyad(self, u: dict, row: int) -> np.ndarray:
        if self.inputs is None:
            self.inputs = tuple(u)
        values = np.array([u[name][row] for name in self.inputs])
        self.y.set(self.inputs, values)
        return values

    def _explicit_load(self, t: float, phi: float, omega: float, eps_prev: float) -> tuple:
        if not math.isfinite(eps_prev):
            raise _Diverged(t, f"crank acceleration not finite ({eps_prev:g} rad/s2)")
        kin = machine.state_kinematics(self.mech, phi, omega, eps_prev)
        self._set_dyad(self.mech.fmu_inputs(kin), 0)
        r = self.y.get(self.outputs)
        if not all(map(math.isfinite, r)):
            raise self._dyad_failed(t, f"conditioning {float(kin['conditioning'][0]):.3g}")
        return self._moment(kin, r), 0.0, r

    def _stabilised_load(self, t: float, phi: float, omega: float) -> tuple:
        kin = machine.state_kinematics(self.mech, (phi, phi), (omega, omega), (0.0, 1.0))
        u = self.mech.fmu_inputs(kin)
        u0 = self._set_dyad(u, 0)
        seed = np.array([u[name][1] for name in self.inputs]) - u0
        moving = seed != 0.0
        knowns = tuple(name for name, m in zip(self.inputs, moving, strict=True) if m)
        r0 = self.y.get(self.outputs)
        if not all(map(math.isfinite, r0)):
            raise self._dyad_failed(t, f"conditioning {float(kin['conditioning'][0]):.3g}")
        dr = self.y.directional_derivative(self.outputs, knowns, seed[moving])
        return self._moment(kin, r0), -self._moment(kin, dr), (u0, seed, r0, dr)

    def _drive_acceleration(self, t: float, tau: float, j_load: float) -> tuple:
        self.d.set(_DRIVE_INPUTS, (tau, j_load))
        eps, torque = self.d.get(("crank.epsilon", "motor.torque"))
        if not math.isfinite(eps):
            raise _Diverged(
                t,
                f"crank acceleration not finite (drive status "
                f"{self.d.get_status()}, load.inertia {j_load:.4g} kg.m2)",
            )
        return eps, torque

    def _stabilised_reaction(self, t: float, eps: float, slope: tuple) -> list:
        """The dyad set to the inputs at the solved eps; its reaction there, and how far it
        is from the linear prediction."""
        u0, seed, r0, dr = slope
        self.y.set(self.inputs, u0 + eps * seed)
        r = self.y.get(self.outputs)
        linear = [a + eps * b for a, b in zip(r0, dr, strict=True)]
        size = math.hypot(r[0], r[1])
        if size > 0 and all(map(math.isfinite, r)):
            self.residual = max(
                self.residual, math.hypot(r[0] - linear[0], r[1] - linear[1]) / size
            )
        if not all(map(math.isfinite, r)):
            raise self._dyad_failed(t, f"the solved acceleration {eps:.4g} rad/s2")
        return r

    def row(self, t: float) -> tuple:
        """(t, phi, omega, eps, T, tau, J_load, Rx, Ry, M) at the communication point t;
        :class:`_Diverged` where the run stops."""
        phi, omega, eps_prev = self._crank_state(t)
        if self.scheme == "explicit":
            tau, j_load, r = self._explicit_load(t, phi, omega, eps_prev)
            eps, torque = self._drive_acceleration(t, tau, j_load)
        else:
            tau, j_load, slope = self._stabilised_load(t, phi, omega)
            eps, torque = self._drive_acceleration(t, tau, j_load)
            r = self._stabilised_reaction(t, eps, slope)
        return (t, phi, omega, eps, torque, tau, j_load, r[0], r[1], r[2] if self.has_m else 0.0)


def _steps(scheme: str, step: float, t_end: float, fmi_version: int) -> int:
    """The number of communication steps of a run, its arguments checked."""
    if scheme not in SCHEMES:
        raise ValueError(f"unknown scheme {scheme!r}; expected one of {', '.join(SCHEMES)}")
    if not (step > 0 and math.isfinite(step) and t_end > 0 and math.isfinite(t_end)):
        raise ValueError(f"step and t_end must be positive numbers, got {step!r}, {t_end!r}")
    n = int(round(t_end / step))
    if n < 1 or abs(n * step - t_end) > 1e-9 * t_end:
        raise ValueError(f"t_end = {t_end!r} s is not a whole number of steps of {step!r} s")
    if fmi_version not in (2, 3):
        raise ValueError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    return n


def _fmu_factories(
    mech: builtin.Mechanism, fmi_version: int, drive: Callable | None, dyad: Callable | None
) -> tuple[Callable, Callable]:
    """The makers of the drive and dyad slaves: the given ones, else the built FMUs."""
    if drive is None:
        drive_path = drive_fmu_path(fmi_version)

        def drive(name: str) -> Slave:
            return Slave(drive_path, name, label=f"drive FMU (FMI {fmi_version})")

    if dyad is None:
        dyad_path = harness.fmu_path(mech.dyad, fmi_version)

        def dyad(name: str) -> Slave:
            return Slave(dyad_path, name, label=f"dyad FMU {mech.dyad} (FMI {fmi_version})")

    return drive, dyad


def _step_through(coupling: _Coupling, n: int, step: float, rows: list) -> None:
    """The n communication steps: a row at each point, then both FMUs step."""
    for k in range(n + 1):
        t = k * step
        rows.append(coupling.row(t))
        if k == n:
            break
        coupling.y.do_step(t, step)
        coupling.d.do_step(t, step)


def _close(slaves: list) -> None:
    for s in reversed(slaves):
        try:
            s.close()
        except Exception:  # pragma: no cover - freeing never hides the run's result
            pass


def _columns(rows: list) -> tuple:
    """t, phi, omega, eps, motor torque, tau, load inertia, R_np (N, 2), M_np of the rows."""
    a = np.array(rows, dtype=float).reshape(-1, 10)
    return (*(a[:, k] for k in range(7)), a[:, 7:9].copy(), a[:, 9])


def run(
    mech: builtin.Mechanism,
    scheme: str,
    step: float,
    t_end: float,
    motor: machine.Motor,
    phi0: float,
    omega0: float,
    fmi_version: int = 2,
    drive: Callable | None = None,
    dyad: Callable | None = None,
    ratio: float | None = None,
) -> CosimRun:
    """Co-simulate the drive FMU and the mechanism's dyad FMU from (phi0, omega0) at t = 0
    to t_end with the communication step ``step`` (t_end / step must be an integer within
    1e-9) and the scheme ``explicit`` or ``stabilised`` (module docstring).

    ``drive`` and ``dyad`` make the slaves, ``f(instance_name) -> slave``; by default the
    FMUs ``build/fmus/drive_fmi<v>.fmu`` and ``harness.fmu_path(mech.dyad, v)``
    (:class:`Slave`). Divergence stops the run and is reported in the result."""
    n = _steps(scheme, step, t_end, fmi_version)
    drive, dyad = _fmu_factories(mech, fmi_version, drive, dyad)
    rows, slaves, coupling = [], [], None  # rows: (t, phi, omega, eps, T, tau, J_load, Rx, Ry, M)
    diverged, diverged_at, reason = False, None, ""
    start = clock.perf_counter()
    try:
        slaves.append(drive("drive"))
        slaves.append(dyad("dyad"))
        d, y = slaves
        coupling = _Coupling(mech, scheme, motor, d, y)
        d.initialize(drive_parameters(mech, motor, phi0, omega0), 0.0)
        y.initialize(mech.fmu_parameters(), 0.0)
        _step_through(coupling, n, step, rows)
    except _Diverged as e:
        diverged, diverged_at, reason = True, e.t, e.reason
    except SlaveError as e:
        diverged, diverged_at = True, (rows[-1][0] if rows else 0.0)
        reason = str(e)
    finally:
        _close(slaves)
    wall = clock.perf_counter() - start
    return CosimRun(
        mech.name,
        scheme,
        int(fmi_version),
        float(step),
        float(t_end),
        motor.rotor_inertia,
        ratio,
        *_columns(rows),
        wall,
        diverged,
        diverged_at,
        reason,
        coupling.residual if coupling else 0.0,
        getattr(slaves[0], "label", "") if slaves else "",
    )


def run_setup(
    s: Setup,
    scheme: str,
    step: float,
    fmi_version: int = 2,
    drive: Callable | None = None,
    dyad: Callable | None = None,
) -> CosimRun:
    """:func:`run` on a :class:`Setup`."""
    return run(
        s.mech,
        scheme,
        step,
        s.t_end,
        s.motor,
        s.phi0,
        s.omega0,
        fmi_version,
        drive=drive,
        dyad=dyad,
        ratio=s.ratio,
    )


# ---------------------------------------------------------------------------
# the monolithic reference and the errors
# ---------------------------------------------------------------------------
@dataclass
class Reference:
    """:func:`dyadfmu.reference.machine.monolithic` at the times t (arrays (N,)), with the dyad's
    reactions there from :func:`dyadfmu.reference.newton_euler.solve` (r_np (N, 2), m_np (N,)).
    mean_speed: mean of omega over t; peak_reaction: largest |R_np|; wall_time [s] of
    the Radau solve and the reactions."""

    mechanism: str
    motor: machine.Motor
    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    r_np: np.ndarray
    m_np: np.ndarray
    mean_speed: float
    peak_reaction: float
    wall_time: float
    nfev: int = 0


def reference(
    mech: builtin.Mechanism,
    motor: machine.Motor,
    t_end: float,
    phi0: float,
    omega0: float,
    times: np.ndarray | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> Reference:
    """The monolithic machine from (phi0, omega0) evaluated at ``times`` (default: the
    solver's steps), Radau with rtol, atol, and its reactions."""
    start = clock.perf_counter()
    times = None if times is None else np.asarray(times, dtype=float)
    mono = machine.monolithic(
        mech, motor, t_end, phi0, omega0, rtol=rtol, atol=atol, t_eval=times, stop_at_range=False
    )
    kin = machine.state_kinematics(mech, mono.phi, mono.omega, mono.epsilon)
    sol = newton_euler.solve(mech.dyad, *mech.reference_inputs(kin))
    r_np = np.asarray(sol["r_np"], dtype=float)
    m_np = np.asarray(sol["m_np"], dtype=float)
    wall = clock.perf_counter() - start
    return Reference(
        mech.name,
        motor,
        mono.t,
        mono.phi,
        mono.omega,
        mono.epsilon,
        r_np,
        m_np,
        float(np.mean(mono.omega)),
        float(np.max(np.hypot(r_np[:, 0], r_np[:, 1]))),
        wall,
        mono.nfev,
    )


def reference_for(s: Setup, step: float, **kw: float) -> Reference:
    """The reference of a :class:`Setup` at the communication points of ``step``."""
    n = int(round(s.t_end / step))
    return reference(s.mech, s.motor, s.t_end, s.phi0, s.omega0, np.arange(n + 1) * step, **kw)


def errors(cosim: CosimRun, ref: Reference) -> dict:
    """Largest errors of a run against the reference at the run's communication points
    (those reached; each must be one of ref.t within 1e-9 s):

    speed: max |omega - omega_ref| / (mean reference speed); reaction: max |R_np -
    R_np_ref| / (peak |R_np_ref|); angle [rad]: max |phi - phi_ref|; speed_at, reaction_at
    [s]: where the largest errors are; points: how many were compared. A run that diverged has
    its errors over the points before it stopped."""
    if len(cosim.t) == 0:
        return {
            "speed": math.nan,
            "reaction": math.nan,
            "angle": math.nan,
            "speed_at": math.nan,
            "reaction_at": math.nan,
            "points": 0,
        }
    idx = np.searchsorted(ref.t, cosim.t - 1e-9)
    idx = np.minimum(idx, len(ref.t) - 1)
    if np.any(np.abs(ref.t[idx] - cosim.t) > 1e-9):
        raise ValueError("the reference is not evaluated at the run's communication points")
    dw = np.abs(cosim.omega - ref.omega[idx])
    dr = np.hypot(*(cosim.r_np - ref.r_np[idx]).T)
    return {
        "speed": float(np.max(dw) / abs(ref.mean_speed)),
        "reaction": float(np.max(dr) / ref.peak_reaction),
        "angle": float(np.max(np.abs(cosim.phi - ref.phi[idx]))),
        "speed_at": float(cosim.t[np.argmax(dw)]),
        "reaction_at": float(cosim.t[np.argmax(dr)]),
        "points": int(len(idx)),
    }

"""A machine: one of the mechanisms of :mod:`dyadfmu.mechanisms.builtin` driven at its crank by
a DC motor through a rigid shaft -- the groundwork for a motor-driven co-simulation.

The mechanism has one degree of freedom, the crank angle phi. Every velocity is linear
in the crank speed omega, v = omega dv/dphi, so its kinetic energy is

    KE = J(phi) omega^2 / 2,
    J(phi) = sum over crank, m, n of (m |dS/dphi|^2 + J_g (dtheta_g/dphi)^2)

(the reduced inertia, J_g about the link's centre of mass; the crank's own mass and
inertia included as in :func:`dyadfmu.mechanisms.crank.kinetic_energy`). The rotor of the motor
(inertia J_r) turns with the crank, and Lagrange's equation of the machine is

    (J_r + J(phi)) epsilon + J'(phi) omega^2 / 2 = T_motor(omega) + Q(phi, omega)

with Q the generalised force of the active loads and gravity (their power over omega).
The kinetostatic driving torque of :func:`dyadfmu.mechanisms.crank.balance` -- what a kinetostatic
dyad FMU hands to a motor -- is the left side without the rotor:
M_drive = J epsilon + J' omega^2 / 2 - Q.

Exact derivative of J: at unit crank speed and zero crank acceleration the
acceleration of a point is d/dt (omega dS/dphi) = omega^2 d2S/dphi2 + epsilon dS/dphi =
d2S/dphi2, and likewise a link's angular acceleration is d2theta/dphi2. Hence the
closed-form kinematics at (phi, omega = 1, epsilon = 0) give both dS/dphi (the
velocities) and d2S/dphi2 (the accelerations), and

    J'(phi) = 2 sum (m v_S . a_S + J_g omega_g epsilon_g)   at omega = 1, epsilon = 0,

with no numerical differentiation.

Generalised load at any speed, including omega = 0: the loads are evaluated at the
actual state (phi, omega) (they may depend on velocities) and their power is taken with
the unit-speed velocities: Q = sum (F . dS/dphi + M dtheta/dphi) + gravity terms. For
omega != 0 this equals load_power / omega exactly, and it stays finite at rest.

API: :class:`Motor`, :func:`state_kinematics`, :func:`reduced_inertia`,
:func:`generalized_load`, :func:`crank_torque_from_kinetostatics`,
:func:`mean_reduced_inertia`, :func:`rotor_inertia_for_ratio`, :func:`phi_range`,
:func:`monolithic` (-> :class:`MachineRun`), :data:`MOTORS` / :func:`default_motor`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..mechanisms import crank as crank_balance
from ..mechanisms.builtin import Mechanism
from ..mechanisms.motion import CrankMotion
from . import newton_euler

__all__ = [
    "Motor",
    "MOTORS",
    "default_motor",
    "state_kinematics",
    "reduced_inertia",
    "generalized_load",
    "machine_terms",
    "crank_torque_from_kinetostatics",
    "phi_range",
    "mean_reduced_inertia",
    "rotor_inertia_for_ratio",
    "MachineRun",
    "monolithic",
]

_LOAD_KEYS = ("m.force", "m.moment", "n.force", "n.moment")
#: Entries of the unit-speed kinematics that J, J' and Q use.
_UNIT_KEYS = (
    "v_S_c",
    "a_S_c",
    "crank.omega",
    "crank.epsilon",
    "v_S_m",
    "a_S_m",
    "m.omega",
    "m.epsilon",
    "v_S_n",
    "a_S_n",
    "n.omega",
    "n.epsilon",
)


# ---------------------------------------------------------------------------
# the motor
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Motor:
    """A DC motor at constant voltage with a linear torque-speed characteristic.

    stall_torque [N m] at omega = 0, no_load_speed [rad/s] where the torque vanishes
    (above it the motor brakes, as a generator), rotor_inertia J_r [kg m2].
    """

    stall_torque: float
    no_load_speed: float
    rotor_inertia: float

    def __post_init__(self):
        for name in ("stall_torque", "no_load_speed", "rotor_inertia"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise ValueError(f"Motor.{name}: expected a finite number, got {value!r}")
        if self.no_load_speed <= 0:
            raise ValueError(f"Motor.no_load_speed must be > 0, got {self.no_load_speed!r}")
        if self.rotor_inertia < 0:
            raise ValueError(f"Motor.rotor_inertia must be >= 0, got {self.rotor_inertia!r}")

    def torque(self, omega: np.ndarray) -> np.ndarray:
        """Motor torque [N m] at the shaft speed omega [rad/s]."""
        return self.stall_torque * (1.0 - np.asarray(omega, dtype=float) / self.no_load_speed)

    def with_rotor_inertia(self, rotor_inertia: float) -> Motor:
        """The same motor with another rotor inertia."""
        return Motor(self.stall_torque, self.no_load_speed, float(rotor_inertia))


#: Motor data per mechanism (stall torque N m, no-load speed rad/s, rotor inertia kg m2).
#: Sized from the mechanism's data (mechanisms.toml) at its nominal crank speed w_nom:
#: no-load speed a little above w_nom, stall torque well above the largest resisting
#: generalised torque -Q over the cycle (so the machine starts from rest anywhere and
#: never stalls), rotor inertia about the mechanism's mean reduced inertia (ratio 1).
#: The figures behind each choice are in the comments.
MOTORS = {
    # engine-like load: the gas force depends on phi only and does net positive work,
    # a mean Q of +33.5 N m (10.5 kW at w_nom = 314 rad/s, 3000 rpm); the compression
    # before TDC resists with up to 141 N m. A starter-generator: it starts the engine
    # from rest (stall torque 2.8 x that peak) and then brakes it, 400 (1 - w / 290) =
    # -33.5 N m at w = 314 rad/s.
    "slider-crank": Motor(stall_torque=400.0, no_load_speed=290.0, rotor_inertia=5.0e-3),
    # agitator at w_nom = 31.4 rad/s (300 rpm): mean resisting torque -Q 1.40 N m, peak
    # 3.07 N m; 12 (1 - w / 36) = 1.40 N m at w = 31.8 rad/s.
    "four-bar": Motor(stall_torque=12.0, no_load_speed=36.0, rotor_inertia=1.0e-3),
    # shaper at w_nom = 6.28 rad/s (60 rpm): mean -Q 16.2 N m, peak 37.5 N m on the
    # working stroke; 100 (1 - w / 7.5) = 16.2 N m at w = 6.29 rad/s.
    "quick-return": Motor(stall_torque=100.0, no_load_speed=7.5, rotor_inertia=2.0e-2),
    # pump at w_nom = 31.4 rad/s: mean -Q 31.4 N m, peak 53.0 N m; 250 (1 - w / 36) =
    # 31.4 N m at w = 31.5 rad/s.
    "scotch-yoke": Motor(stall_torque=250.0, no_load_speed=36.0, rotor_inertia=5.0e-3),
    # oscillating crank (peak speed 5.65 rad/s in its data): -Q from 10 to 38 N m over
    # the range at that speed. A DC motor turns one way only, so it drives a single
    # stroke across phi_range(mech) in 0.36 s from rest, at 4.3 to 5.5 rad/s.
    "trt-slot": Motor(stall_torque=120.0, no_load_speed=6.0, rotor_inertia=3.0e-2),
}


def default_motor(mech: Mechanism) -> Motor:
    """The motor of :data:`MOTORS` for this mechanism."""
    return MOTORS[mech.name]


# ---------------------------------------------------------------------------
# kinematics at given crank states
# ---------------------------------------------------------------------------
def _broadcast(*arrays: np.ndarray):
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in arrays))
    shape = arrays[0].shape
    return shape, [np.ascontiguousarray(a).reshape(-1) for a in arrays]


def _state_kinematics_flat(
    mech: Mechanism, phi: np.ndarray, omega: np.ndarray, epsilon: np.ndarray
):
    """Kinematics at 1-D arrays of crank states (same length)."""
    motion = CrankMotion(
        "state",
        lambda t: phi,
        lambda t: omega,
        lambda t: epsilon,
        duration=0.0,
        cycles=0.0,
        description="given crank states",
    )
    return mech.kinematics(np.zeros(phi.shape), motion)


def state_kinematics(
    mech: Mechanism, phi: np.ndarray, omega: np.ndarray, epsilon: np.ndarray
) -> dict:
    """The mechanism's kinematics and loads (the dict of ``Mechanism.kinematics``) at
    given crank states (phi [rad], omega [rad/s], epsilon [rad/s2]), broadcast together
    and flattened to 1-D arrays of N samples."""
    _, (phi, omega, epsilon) = _broadcast(phi, omega, epsilon)
    return _state_kinematics_flat(mech, phi, omega, epsilon)


def _sq(v: np.ndarray):
    return v[..., 0] ** 2 + v[..., 1] ** 2


def _dotv(a: np.ndarray, b: np.ndarray):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def _inertia_terms(mech: Mechanism, kin1: dict):
    """J and dJ/dphi from kinematics at omega = 1, epsilon = 0 (module docstring)."""
    c = mech.crank
    J = c["mass"] * _sq(kin1["v_S_c"]) + c["inertia"] * kin1["crank.omega"] ** 2
    dJ = (
        c["mass"] * _dotv(kin1["v_S_c"], kin1["a_S_c"])
        + c["inertia"] * kin1["crank.omega"] * kin1["crank.epsilon"]
    )
    for g in ("m", "n"):
        link = mech.links[g]
        J = J + link["mass"] * _sq(kin1[f"v_S_{g}"]) + link["inertia"] * kin1[f"{g}.omega"] ** 2
        dJ = (
            dJ
            + link["mass"] * _dotv(kin1[f"v_S_{g}"], kin1[f"a_S_{g}"])
            + link["inertia"] * kin1[f"{g}.omega"] * kin1[f"{g}.epsilon"]
        )
    return J, 2.0 * dJ


def _load_term(mech: Mechanism, kin1: dict, kin_w: dict):
    """Q from the unit-speed velocities of kin1 and the loads of kin_w."""
    merged = dict(kin1)
    for key in _LOAD_KEYS:
        merged[key] = kin_w[key]
    return crank_balance.load_power(mech, merged)


def machine_terms(
    mech: Mechanism, phi: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """J, J', Q at 1-D arrays phi, omega with one kinematics call of 2N samples."""
    n = phi.size
    kin = _state_kinematics_flat(
        mech, np.concatenate([phi, phi]), np.concatenate([np.ones(n), omega]), np.zeros(2 * n)
    )
    first = {k: kin[k][:n] for k in _UNIT_KEYS}
    second = {k: kin[k][n:] for k in _LOAD_KEYS}
    J, dJ = _inertia_terms(mech, first)
    Q = _load_term(mech, first, second)
    return J, dJ, Q


def reduced_inertia(mech: Mechanism, phi: np.ndarray) -> tuple:
    """(J, dJ/dphi) [kg m2, kg m2/rad] at the crank angles phi (any shape): twice the
    kinetic energy of crank, m and n at unit crank speed; the derivative is exact
    (closed-form accelerations at unit speed, see the module docstring)."""
    shape, (phi,) = _broadcast(phi)
    n = phi.size
    kin1 = _state_kinematics_flat(mech, phi, np.ones(n), np.zeros(n))
    J, dJ = _inertia_terms(mech, kin1)
    return J.reshape(shape), dJ.reshape(shape)


def generalized_load(mech: Mechanism, phi: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Generalised force Q [N m] of the active loads and gravity on crank and links at
    the crank states (phi, omega) (broadcast): their power at speed omega divided by
    omega, computed as the loads at (phi, omega) times the unit-speed velocities, which
    is the same for omega != 0 and the continuous limit at omega = 0."""
    shape, (phi, omega) = _broadcast(phi, omega)
    n = phi.size
    kin = _state_kinematics_flat(
        mech, np.concatenate([phi, phi]), np.concatenate([np.ones(n), omega]), np.zeros(2 * n)
    )
    first = {k: kin[k][:n] for k in _UNIT_KEYS}
    second = {k: kin[k][n:] for k in _LOAD_KEYS}
    return _load_term(mech, first, second).reshape(shape)


def crank_torque_from_kinetostatics(
    mech: Mechanism, phi: np.ndarray, omega: np.ndarray, epsilon: np.ndarray
) -> np.ndarray:
    """Driving torque [N m] the crank needs at the given crank states (broadcast): the
    dyad's reactions from :func:`dyadfmu.reference.newton_euler.solve` on the state's kinematics and
    loads, then the crank's moment balance (:func:`dyadfmu.mechanisms.crank.balance`). This is what
    a kinetostatic dyad FMU gives a motor (the rotor's own inertia not included)."""
    shape, (phi, omega, epsilon) = _broadcast(phi, omega, epsilon)
    kin = _state_kinematics_flat(mech, phi, omega, epsilon)
    ref = newton_euler.solve(mech.dyad, *mech.reference_inputs(kin))
    torque = crank_balance.balance(mech, kin, ref["r_np"], ref["m_np"])["torque"]
    return torque.reshape(shape)


# ---------------------------------------------------------------------------
# inertia ratio
# ---------------------------------------------------------------------------
def phi_range(mech: Mechanism) -> tuple[float, float] | None:
    """The crank angles the machine may take: None for a revolving crank; for the
    oscillating trt-slot crank, the range (lo, hi) swept by its data's motions (both
    kinds), inside which the mechanism is well conditioned (sin phi >= 0.2 is checked
    on load)."""
    if mech.dyad != "TRT":
        return None
    lo, hi = math.inf, -math.inf
    for kind in ("constant", "varying"):
        motion = mech.motion(kind, 1.0)
        phi = motion.phi(np.linspace(0.0, motion.duration, 4001))
        lo, hi = min(lo, float(phi.min())), max(hi, float(phi.max()))
    return lo, hi


def mean_reduced_inertia(mech: Mechanism, samples: int = 720) -> float:
    """Mean of J(phi) over a revolution (uniform in phi); for an oscillating crank over
    its :func:`phi_range`."""
    rng = phi_range(mech)
    if rng is None:
        phi = np.arange(samples) * (2.0 * math.pi / samples)  # periodic: exact mean
    else:  # trapezoid on the range
        phi = np.linspace(rng[0], rng[1], samples + 1)
    J, _ = reduced_inertia(mech, phi)
    if rng is None:
        return float(np.mean(J))
    return float((np.sum(J) - 0.5 * (J[0] + J[-1])) / samples)


def rotor_inertia_for_ratio(mech: Mechanism, ratio: float) -> float:
    """Rotor inertia J_r [kg m2] giving the ratio (mean J over a revolution) / J_r."""
    if not (ratio > 0 and math.isfinite(ratio)):
        raise ValueError(f"ratio must be a positive number, got {ratio!r}")
    return mean_reduced_inertia(mech) / ratio


# ---------------------------------------------------------------------------
# the monolithic machine
# ---------------------------------------------------------------------------
@dataclass
class MachineRun:
    """Solution of :func:`monolithic` at the output times (arrays (N,)).

    t [s], phi [rad], omega [rad/s], epsilon [rad/s2] (from the equation of motion at
    the output states), motor_torque [N m], load_torque Q [N m], inertia J(phi) [kg m2]
    (mechanism only), kinetic_energy (J_r + J) omega^2 / 2 [J], motor_work and load_work
    [J] (work done on the machine since t0 by the motor and by loads and gravity,
    integrated with the state), so that motor_work + load_work = kinetic_energy -
    kinetic_energy[0]. ``stopped`` is True when the run ended early at the limit of
    :func:`phi_range`; ``solution`` is scipy's OdeResult.
    """

    mechanism: str
    motor: Motor
    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    motor_torque: np.ndarray
    load_torque: np.ndarray
    inertia: np.ndarray
    kinetic_energy: np.ndarray
    motor_work: np.ndarray
    load_work: np.ndarray
    stopped: bool
    nfev: int
    solution: object = field(repr=False, default=None)

    def energy_residual(self) -> np.ndarray:
        """motor_work + load_work - (kinetic_energy - kinetic_energy[0]) [J]."""
        return self.motor_work + self.load_work - (self.kinetic_energy - self.kinetic_energy[0])


def _rhs_factory(mech: Mechanism, motor: Motor):
    Jr = motor.rotor_inertia

    def accel(phi: np.ndarray, omega: np.ndarray):
        J, dJ, Q = machine_terms(mech, phi, omega)
        T = motor.torque(omega)
        eps = (T + Q - 0.5 * dJ * omega * omega) / (Jr + J)
        return eps, T, Q, J

    def rates(phi: np.ndarray, omega: np.ndarray):
        eps, T, Q, _ = accel(phi, omega)
        return np.stack([omega, eps, T * omega, Q * omega])

    def rhs(t: float, y: np.ndarray):
        y = np.asarray(y, dtype=float)
        if y.ndim == 1:
            return rates(y[:1], y[1:2])[:, 0]
        return rates(y[0], y[1])

    def jac(t: float, y: np.ndarray):
        # central differences in phi and omega, one batched evaluation; the works do
        # not feed back (zero columns)
        phi, omega = float(y[0]), float(y[1])
        hp, hw = 1e-6, 1e-6 * max(1.0, abs(omega))
        f = rates(
            np.array([phi + hp, phi - hp, phi, phi]),
            np.array([omega, omega, omega + hw, omega - hw]),
        )
        out = np.zeros((4, 4))
        out[:, 0] = (f[:, 0] - f[:, 1]) / (2.0 * hp)
        out[:, 1] = (f[:, 2] - f[:, 3]) / (2.0 * hw)
        return out

    return rhs, jac, accel


def _range_events(rng: tuple[float, float]) -> list:
    """Terminal events of solve_ivp where phi leaves [rng[0], rng[1]]."""

    def below(t: float, y: np.ndarray) -> np.ndarray:
        return y[0] - rng[0]

    def above(t: float, y: np.ndarray) -> np.ndarray:
        return rng[1] - y[0]

    below.terminal = above.terminal = True
    below.direction = above.direction = -1.0
    return [below, above]


def _with_event_state(
    sol: object,
    t: np.ndarray,
    phi: np.ndarray,
    omega: np.ndarray,
    w_motor: np.ndarray,
    w_load: np.ndarray,
) -> tuple:
    """The output with the event state appended, so that the run's end is in it."""
    for tk, yk in zip(sol.t_events, sol.y_events, strict=True):
        if len(tk):
            t = np.append(t, tk[0])
            phi, omega = np.append(phi, yk[0][0]), np.append(omega, yk[0][1])
            w_motor, w_load = np.append(w_motor, yk[0][2]), np.append(w_load, yk[0][3])
    return t, phi, omega, w_motor, w_load


def monolithic(
    mech: Mechanism,
    motor: Motor,
    t_end: float,
    phi0: float,
    omega0: float,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_eval: np.ndarray | None = None,
    stop_at_range: bool = True,
    max_step: float = math.inf,
) -> MachineRun:
    """The machine as one ODE in (phi, omega), with the works as two quadrature states:

        phi' = omega,
        (J_r + J(phi)) omega' = T_motor(omega) + Q(phi, omega) - J'(phi) omega^2 / 2,
        W_motor' = T_motor omega,   W_load' = Q omega,

    from (phi0, omega0) at t = 0 to t_end [s], by ``scipy.integrate.solve_ivp`` with
    method "Radau" (vectorised right-hand side). Output at the solver's steps, or on the
    grid ``t_eval`` (dense output). For the oscillating trt-slot crank the run stops
    (``stopped``) when phi leaves :func:`phi_range` if ``stop_at_range``: a DC motor turns
    one way and would drive the slot towards phi = pi, where the slider runs off to
    infinity."""
    from scipy.integrate import solve_ivp

    if not (t_end > 0 and math.isfinite(t_end)):
        raise ValueError(f"t_end must be a positive number, got {t_end!r}")
    rng = phi_range(mech) if stop_at_range else None
    if rng is not None and not (rng[0] <= phi0 <= rng[1]):
        raise ValueError(f"phi0 = {phi0!r} is outside the admissible range {rng} of {mech.name}")
    rhs, jac, accel = _rhs_factory(mech, motor)
    events = _range_events(rng) if rng is not None else None
    sol = solve_ivp(
        rhs,
        (0.0, float(t_end)),
        [float(phi0), float(omega0), 0.0, 0.0],
        method="Radau",
        rtol=rtol,
        atol=atol,
        t_eval=t_eval,
        events=events,
        vectorized=True,
        jac=jac,
        max_step=max_step,
    )
    if sol.status < 0:
        raise RuntimeError(f"monolithic {mech.name}: {sol.message}")
    t, (phi, omega, w_motor, w_load) = sol.t, sol.y
    if rng is not None and sol.status == 1 and t_eval is not None:
        t, phi, omega, w_motor, w_load = _with_event_state(sol, t, phi, omega, w_motor, w_load)
    eps, T, Q, J = accel(phi, omega)
    kinetic = 0.5 * (motor.rotor_inertia + J) * omega * omega
    states = (t, phi, omega, eps, T, Q, J, kinetic, w_motor, w_load)
    return MachineRun(mech.name, motor, *states, bool(sol.status == 1), int(sol.nfev), sol)

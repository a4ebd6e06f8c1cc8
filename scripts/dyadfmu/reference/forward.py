"""The forward dynamics of a mechanism with several drivers as one ODE: the efforts in,
the motion out, from the whole-mechanism Newton-Euler reference of
:mod:`dyadfmu.mechanisms.multidriver` alone.

Its inverse dynamics give each driver's effort for a motion, efforts = M(q) q'' + h, with
M(q) and h(t, q, q') each solved for from the Newton-Euler system of every moving body
(:meth:`~.multidriver.MultiChain.inertia_matrix`, :meth:`~.multidriver.MultiChain.bias`;
never from a formula of the generated code). Given the efforts u(t, q, q') the
accelerations follow as

    q'' = M(q)^-1 (u - h(t, q, q')),

and the state y = (q, q', W) obeys y' = (q', q'', u . q' + P_loads): W is the work the
drivers and the loads have done since the start, integrated with the motion so that the
energy balance T + V - W = constant can be checked along it at the solver's own
accuracy (T, V from the reference's kinetic and potential energies, P_loads the loads'
power at the state). ``scipy.integrate.solve_ivp`` integrates it (DOP853 by default:
the mechanism without a motor is not stiff).

Example::

    leg = multidriver.load("leg")
    run = integrate(leg, holding(leg, {"front": -1.0, "rear": -2.0}), ...)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ..mechanisms.chains import Chain
from ..mechanisms.multidriver import MultiChain

__all__ = [
    "DCMotor",
    "MotorRun",
    "Trajectory",
    "accelerations",
    "chain_terms",
    "chain_terms_at",
    "integrate_chain",
    "energy",
    "holding",
    "integrate",
    "integrate_with_motors",
]

#: u(t, q, q') -> efforts (drivers,): the drivers' torques [N m] and forces [N]
EffortLaw = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Trajectory:
    """A forward run at the times ``t`` (T,): the drivers' coordinates ``q``, rates
    ``dq``, accelerations ``ddq`` and efforts ``u`` (T, drivers) in the chain's driver
    order, and ``work`` (T,), the drivers' and loads' work since the start [J]."""

    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    u: np.ndarray
    work: np.ndarray
    evaluations: int


def _state(
    chain: MultiChain, t: float, q: np.ndarray, dq: np.ndarray, loads: Mapping | None = None
) -> dict:
    """The reference's kinematics at one state, every acceleration zero; the [[load]]
    inputs ``loads`` or, left out, their models' values at t."""
    return chain.state(
        np.asarray(q, float)[None, :], np.asarray(dq, float)[None, :], loads=loads, t=t
    )


def accelerations(
    chain: MultiChain,
    t: float,
    q: np.ndarray,
    dq: np.ndarray,
    u: np.ndarray,
    loads: Mapping | None = None,
) -> np.ndarray:
    """q'' (drivers,) at (t, q, q') under the efforts u: M(q) q'' = u - h(t, q, q'), the
    [[load]] inputs ``loads`` or their models' values at t."""
    kin = _state(chain, t, q, dq, loads)
    M, h = chain.inertia_matrix(kin)[0], chain.bias(kin)[0]
    return np.linalg.solve(M, np.asarray(u, dtype=float) - h)


def energy(chain: MultiChain, t: float, q: np.ndarray, dq: np.ndarray) -> float:
    """T + V [J] at (t, q, q'): the reference's kinetic and potential energies."""
    kin = _state(chain, t, q, dq)
    return float(chain.kinetic_energy(kin)[0] + chain.potential_energy(kin)[0])


def _load_power(chain: MultiChain, kin: dict) -> float:
    return float(np.real(chain.load_power(kin))[0])


def integrate(
    chain: MultiChain,
    law: EffortLaw,
    q0: Mapping | np.ndarray,
    dq0: Mapping | np.ndarray,
    times: np.ndarray,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    method: str = "DOP853",
) -> Trajectory:
    """The motion from (q0, dq0) at ``times[0]`` under the efforts ``law``, reported at
    ``times`` (increasing); q0, dq0 as arrays in the driver order or {driver: value}.
    Raises RuntimeError where the solver fails (a chain that stops assembling)."""
    from scipy.integrate import solve_ivp

    n = len(chain.drivers)
    y0 = np.concatenate([_vector(chain, q0, "q0"), _vector(chain, dq0, "dq0"), [0.0]])
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 2 or np.any(np.diff(times) <= 0):
        raise ValueError("times: expected an increasing array of at least two instants [s]")
    count = [0]

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        count[0] += 1
        q, dq = y[:n], y[n : 2 * n]
        u = np.asarray(law(t, q, dq), dtype=float)
        kin = _state(chain, t, q, dq)
        M, h = chain.inertia_matrix(kin)[0], chain.bias(kin)[0]
        ddq = np.linalg.solve(M, u - h)
        if not np.all(np.isfinite(ddq)):
            raise RuntimeError(
                f"{chain.name}: no motion at t = {t:.6g} s, q = {q} (a chain "
                "that does not assemble there, or efforts not finite)"
            )
        return np.concatenate([dq, ddq, [u @ dq + _load_power(chain, kin)]])

    sol = solve_ivp(rhs, (times[0], times[-1]), y0, method, times, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(
            f"{chain.name}: the forward run failed at t = {sol.t[-1]:.6g} s: {sol.message}"
        )
    q, dq, work = sol.y[:n].T, sol.y[n : 2 * n].T, sol.y[-1]
    u = np.array([law(t, a, b) for t, a, b in zip(sol.t, q, dq, strict=True)], dtype=float)
    ddq = np.array(
        [accelerations(chain, t, a, b, f) for t, a, b, f in zip(sol.t, q, dq, u, strict=True)]
    )
    return Trajectory(sol.t, q, dq, ddq, u, work, count[0])


def chain_terms(chain: Chain, t: float, q: float, dq: float) -> tuple[float, float]:
    """J(q) and h(t, q, q') of a chain with one driver, effort = J q'' + h: its
    Newton-Euler effort at zero and at unit acceleration (the effort is affine in q''),
    with the chain's load models at the state."""
    J, h = chain_terms_at(chain, np.array([t]), np.array([q]), np.array([dq]))
    return float(J[0]), float(h[0])


def chain_terms_at(
    chain: Chain, t: np.ndarray, q: np.ndarray, dq: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`chain_terms` at N states at once (arrays (N,)): J and h, each (N,)."""
    count = len(q)
    at = (np.tile(np.asarray(x, dtype=float), 2) for x in (t, q, dq))
    kin = chain._solve(*at, np.repeat([0.0, 1.0], count))
    effort = np.real(chain.reference(kin)[chain.drive_output])
    return effort[count:] - effort[:count], effort[:count]


def integrate_chain(
    chain: Chain,
    effort: float,
    q0: float,
    dq0: float,
    times: np.ndarray,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    effort_rate: float = 0.0,
) -> Trajectory:
    """The motion of a chain with one driver under an ``effort`` [N m or N] that grows by
    ``effort_rate`` per second from ``times[0]`` (constant by default), from (q0, dq0) at
    ``times[0]``, reported at ``times``, by DOP853: q'' = (effort - h) / J. Raises
    RuntimeError where the solver fails."""
    from scipy.integrate import solve_ivp

    count = [0]
    times = np.asarray(times, dtype=float)

    def law(t: float) -> float:
        return float(effort) + float(effort_rate) * (t - times[0])

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        count[0] += 1
        J, h = chain_terms(chain, t, y[0], y[1])
        return np.array([y[1], (law(t) - h) / J])

    sol = solve_ivp(rhs, (times[0], times[-1]), [q0, dq0], "DOP853", times, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"{chain.name}: the forward run failed at t = {sol.t[-1]:.6g} s")
    q, dq = sol.y[0][:, None], sol.y[1][:, None]
    ddq = np.array([rhs(t, [a[0], b[0]])[1] for t, a, b in zip(sol.t, q, dq, strict=True)])
    u = np.array([law(t) for t in sol.t])[:, None]
    return Trajectory(sol.t, q, dq, ddq[:, None], u, np.zeros_like(sol.t), count[0])


def _vector(chain: MultiChain, value: Mapping | np.ndarray, what: str) -> np.ndarray:
    names = chain.driver_names
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - set(names))
        if unknown or len(value) != len(names):
            raise ValueError(f"{what}: expected a value for each of {', '.join(names)}")
        value = [value[n] for n in names]
    v = np.asarray(value, dtype=float)
    if v.shape != (len(names),) or not np.all(np.isfinite(v)):
        raise ValueError(f"{what}: expected {len(names)} finite values ({', '.join(names)})")
    return v


def holding(
    chain: MultiChain, target: Mapping, stiffness: float = 50.0, damping: float = 0.0
) -> EffortLaw:
    """A servo about ``target`` ({driver: coordinate}): u = h(t, target, 0) at rest plus
    M(target) (stiffness^2 (target - q) - damping q'), so that the motion is a lightly
    coupled oscillation about the target (damping 0 keeps it going)."""
    if not (math.isfinite(stiffness) and math.isfinite(damping)):
        raise ValueError("stiffness, damping: expected finite rates [1/s]")
    goal = _vector(chain, target, "target")
    kin = _state(chain, 0.0, goal, 0.0 * goal)
    M, rest = chain.inertia_matrix(kin)[0], chain.bias(kin)[0]
    gain = stiffness**2 * M
    damp = damping * M

    def law(t: float, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        return rest + gain @ (goal - q) - damp @ dq

    return law


@dataclass(frozen=True)
class DCMotor:
    """A DC motor geared to a crank: armature resistance [ohm], inductance [H], torque
    constant [N m/A] (in SI also the back-EMF constant [V s/rad]), rotor inertia
    [kg m2], viscous friction at the rotor [N m s/rad] and the gear ratio (rotor turns
    per crank turn). With the rotor at omega_m = ratio q' and the armature current i:

        inductance i' = V - resistance i - torque_constant omega_m,
        the crank's torque = ratio (torque_constant i - friction omega_m)
                             - ratio^2 rotor_inertia q''.
    """

    resistance: float
    inductance: float
    torque_constant: float
    rotor_inertia: float = 0.0
    friction: float = 0.0
    ratio: float = 1.0

    def __post_init__(self):
        for name in (
            "resistance",
            "inductance",
            "torque_constant",
            "rotor_inertia",
            "friction",
            "ratio",
        ):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise ValueError(f"DCMotor.{name}: expected a finite number, got {value!r}")
        for name in ("resistance", "inductance", "torque_constant", "ratio"):
            if getattr(self, name) <= 0:
                raise ValueError(f"DCMotor.{name}: expected > 0, got {getattr(self, name)!r}")
        for name in ("rotor_inertia", "friction"):
            if getattr(self, name) < 0:
                raise ValueError(f"DCMotor.{name}: expected >= 0, got {getattr(self, name)!r}")


@dataclass(frozen=True)
class MotorRun:
    """A run with motors: the :class:`Trajectory` (its ``u`` the drivers' efforts on
    the mechanism, a motor's torque at its crank), the armature currents ``current``
    (T, motors) [A] in the order of ``motors``, and the energy accounts [J] since the
    start: ``supplied`` (the supplies' V i, the other drivers' and the loads' work),
    ``dissipated`` (armature resistance and rotor friction), ``stored`` at each time
    (kinetic energy of mechanism and rotors, potential energy, the inductances'
    L i^2 / 2)."""

    run: Trajectory
    motors: tuple
    current: np.ndarray
    supplied: np.ndarray
    dissipated: np.ndarray
    stored: np.ndarray


def integrate_with_motors(
    chain: MultiChain,
    motors: Mapping[str, DCMotor],
    law: EffortLaw,
    q0: Mapping | np.ndarray,
    dq0: Mapping | np.ndarray,
    current0: Mapping[str, float],
    times: np.ndarray,
    rtol: float = 1e-11,
    atol: float = 1e-12,
    method: str = "Radau",
) -> MotorRun:
    """The motion from (q0, dq0, current0) at ``times[0]`` with a DC motor at each crank
    named in ``motors``; ``law`` gives, per driver in the chain's order, the supply
    voltage [V] of a driver with a motor and the effort of any other. SciPy's Radau
    integrates it (a small inductance makes it stiff); ``method`` names another of
    ``solve_ivp``'s (DOP853 is faster where the circuit's time constant L / R is not far
    below the steps the accuracy asks for)."""
    from scipy.integrate import solve_ivp

    names, n = chain.driver_names, len(chain.drivers)
    geared = _motor_drivers(chain, motors)
    k = len(geared)
    i0 = np.array([float(current0[names[a]]) for a in geared]) if k else np.zeros(0)
    y0 = np.concatenate([_vector(chain, q0, "q0"), _vector(chain, dq0, "dq0"), i0, [0, 0]])
    times = np.asarray(times, dtype=float)
    count = [0]

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        count[0] += 1
        q, dq, i = y[:n], y[n : 2 * n], y[2 * n : 2 * n + k]
        ddq, di, u, supplied, lost = _motor_step(chain, motors, geared, law, t, q, dq, i)
        return np.concatenate([dq, ddq, di, [supplied, lost]])

    sol = solve_ivp(rhs, (times[0], times[-1]), y0, method, times, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(
            f"{chain.name}: the forward run failed at t = {sol.t[-1]:.6g} s: {sol.message}"
        )
    q, dq, i = sol.y[:n].T, sol.y[n : 2 * n].T, sol.y[2 * n : 2 * n + k].T
    steps = [
        _motor_step(chain, motors, geared, law, t, a, b, c)
        for t, a, b, c in zip(sol.t, q, dq, i, strict=True)
    ]
    ddq = np.array([s[0] for s in steps])
    u = np.array([s[2] for s in steps])
    stored = np.array(
        [
            energy(chain, t, a, b) + _motor_energy(chain, motors, geared, b, c)
            for t, a, b, c in zip(sol.t, q, dq, i, strict=True)
        ]
    )
    run = Trajectory(sol.t, q, dq, ddq, u, sol.y[-2], count[0])
    return MotorRun(run, tuple(names[a] for a in geared), i, sol.y[-2], sol.y[-1], stored)


def _motor_drivers(chain: MultiChain, motors: Mapping[str, DCMotor]) -> list[int]:
    names = chain.driver_names
    for name in motors:
        if name not in names:
            raise ValueError(f"motors: {name!r} is no driver of {chain.name} ({', '.join(names)})")
        if chain.drivers[names.index(name)].kind != "crank":
            raise ValueError(f"motors: {name!r} is no crank; a DC motor turns a crank")
    return [a for a, name in enumerate(names) if name in motors]


def _motor_step(
    chain: MultiChain,
    motors: Mapping[str, DCMotor],
    geared: list[int],
    law: EffortLaw,
    t: float,
    q: np.ndarray,
    dq: np.ndarray,
    i: np.ndarray,
) -> tuple:
    """q'', i', the efforts on the mechanism, the power supplied and the power lost."""
    names = chain.driver_names
    command = np.asarray(law(t, q, dq), dtype=float)
    kin = _state(chain, t, q, dq)
    M, h = chain.inertia_matrix(kin)[0].copy(), chain.bias(kin)[0]
    drive, di = command.copy(), np.zeros(len(geared))
    supplied, lost = 0.0, 0.0
    for j, a in enumerate(geared):
        m = motors[names[a]]
        speed = m.ratio * dq[a]
        M[a, a] += m.ratio**2 * m.rotor_inertia
        drive[a] = m.ratio * (m.torque_constant * i[j] - m.friction * speed)
        di[j] = (command[a] - m.resistance * i[j] - m.torque_constant * speed) / m.inductance
        supplied += command[a] * i[j]
        lost += m.resistance * i[j] ** 2 + m.friction * speed**2
    ddq = np.linalg.solve(M, drive - h)
    if not np.all(np.isfinite(ddq)):
        raise RuntimeError(f"{chain.name}: no motion at t = {t:.6g} s, q = {q}")
    others = [a for a in range(len(names)) if a not in geared]
    supplied += sum(command[a] * dq[a] for a in others) + _load_power(chain, kin)
    u = drive.copy()
    for a in geared:
        m = motors[names[a]]
        u[a] -= m.ratio**2 * m.rotor_inertia * ddq[a]
    return ddq, di, u, supplied, lost


def _motor_energy(
    chain: MultiChain,
    motors: Mapping[str, DCMotor],
    geared: list[int],
    dq: np.ndarray,
    i: np.ndarray,
) -> float:
    """The rotors' kinetic energy and the inductances' L i^2 / 2 [J]."""
    names = chain.driver_names
    total = 0.0
    for j, a in enumerate(geared):
        m = motors[names[a]]
        total += 0.5 * m.rotor_inertia * (m.ratio * dq[a]) ** 2 + 0.5 * m.inductance * i[j] ** 2
    return total

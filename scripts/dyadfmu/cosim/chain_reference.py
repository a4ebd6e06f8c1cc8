"""A machine with two drivers and a DC motor at one of them as one ODE, for the plant
study (:mod:`dyadfmu.cosim.plant_study`): the reference its plants are measured against.

The harness (:mod:`dyadfmu.mechanisms.multidriver`) gives the drivers' efforts as
M(q) q'' + h(q, q'), each from the Newton-Euler system of every moving body. With the loads
off, h is exactly quadratic in the rates:

    h(q, q') = g(q) + c_00(q) q0'^2 + c_11(q) q1'^2 + c_01(q) q0' q1',

so M, g and the three c are functions of the positions alone. Each is a two-dimensional
Chebyshev series over the drivers' ``domain``, interpolating the harness at
:data:`DEGREE` x :data:`DEGREE` Chebyshev points (analytic in q where the chain
assembles: the series converge geometrically), so that one evaluation of the ODE costs
tens of microseconds, not the harness's milliseconds. ``fit_error`` states their largest
distance to the harness at other points. With the motor at driver ``a``:

    (M(q) + r^2 J_r e_a e_a^T) q'' = r (k i - c r q_a') e_a - h(q, q'),
    L i' = V - R i - k r q_a'     (i = (V - k r q_a') / R where L = 0).

The accelerations along the solution and the joint reactions come from the harness
itself at the solution's states (its own M and h, not the series).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.polynomial import chebyshev

from ..mechanisms import multidriver

__all__ = ["DEGREE", "ChainSeries", "Motion", "motion", "reactions", "series"]

#: Chebyshev points per driver of the series.
DEGREE = 48
#: Points of the harness's vectorised evaluations at a time (memory, not accuracy).
_CHUNK = 20000


class ChainSeries:
    """M(q), g(q) and the quadratic coefficients of h of ``chain`` (two drivers) as
    Chebyshev series over ``domain`` ((low, high) per driver, [rad] or [m])."""

    def __init__(self, chain: multidriver.MultiChain, domain: tuple) -> None:
        if len(chain.drivers) != 2 or len(domain) != 2:
            raise ValueError(f"{chain.name}: the series take two drivers and their two ranges")
        self.chain = chain
        self.low, self.high = (np.array(v, dtype=float) for v in zip(*domain, strict=True))
        x = np.cos(math.pi * (np.arange(DEGREE) + 0.5) / DEGREE)
        nodes = np.stack(np.meshgrid(x, x, indexing="ij"), -1).reshape(-1, 2)
        values = _terms(chain, self.positions(nodes)).reshape(DEGREE, DEGREE, -1)
        inverse = np.linalg.inv(chebyshev.chebvander(x, DEGREE - 1))
        self.coefficients = np.einsum("ia,jb,abk->ijk", inverse, inverse, values)
        probe = np.random.default_rng(11).uniform(-1.0, 1.0, (400, 2))
        truth = _terms(chain, self.positions(probe))
        fit = np.array([self._values(u) for u in probe])
        scale = np.max(np.abs(truth), axis=0).clip(min=1e-300)
        self.fit_error = float(np.max(np.abs(fit - truth) / scale))

    def positions(self, u: np.ndarray) -> np.ndarray:
        """The drivers' coordinates of the points u in [-1, 1]^2."""
        return self.low + 0.5 * (u + 1.0) * (self.high - self.low)

    def _values(self, u: np.ndarray) -> np.ndarray:
        v0 = chebyshev.chebvander(u[0], DEGREE - 1)[0]
        v1 = chebyshev.chebvander(u[1], DEGREE - 1)[0]
        return v1 @ (v0 @ self.coefficients.reshape(DEGREE, -1)).reshape(DEGREE, -1)

    def efforts(self, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """M (2, 2) and h (2,) at the positions q and rates dq."""
        u = 2.0 * (q - self.low) / (self.high - self.low) - 1.0
        v = self._values(u)
        quadratic = v[6:8] * dq[0] ** 2 + v[8:10] * dq[1] ** 2 + v[10:12] * dq[0] * dq[1]
        return v[:4].reshape(2, 2), v[4:6] + quadratic


def _terms(chain: multidriver.MultiChain, q: np.ndarray) -> np.ndarray:
    """(N, 12): M's four entries, g, c_00, c_11 and c_01 at the positions q (N, 2)."""
    count, h = len(q), []
    for rate in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)):
        kin = chain.state(q, np.tile(rate, (count, 1)))
        if not h:
            M = chain.inertia_matrix(kin)
        h.append(chain.bias(kin))
    g, c00, c11 = h[0], h[1] - h[0], h[2] - h[0]
    c01 = h[3] - h[0] - c00 - c11
    return np.concatenate([M.reshape(count, 4), g, c00, c11, c01], axis=1)


@functools.cache
def series(chain: multidriver.MultiChain, domain: tuple) -> ChainSeries:
    """The series of ``chain`` over ``domain`` (one fit per chain object and domain)."""
    return ChainSeries(chain, domain)


class Motion:
    """The reference's solution on its grid ``t``: positions ``q``, rates ``dq`` and the
    harness's accelerations ``ddq`` at them (each (T, 2))."""

    def __init__(self, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> None:
        self.t, self.q, self.dq, self.ddq = t, q, dq, ddq


def _rhs(fit: ChainSeries, motor: object, voltage: float, a: int):
    r, k, resistance = motor.ratio, motor.torque_constant, motor.resistance
    rotor = np.zeros((2, 2))
    rotor[a, a] = r * r * motor.rotor_inertia

    def current(y: np.ndarray) -> float:
        return y[4] if motor.inductance > 0 else (voltage - k * r * y[2 + a]) / resistance

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        M, h = fit.efforts(y[:2], y[2:4])
        i = current(y)
        u = np.zeros(2)
        u[a] = r * (k * i - motor.friction * r * y[2 + a])
        ddq = np.linalg.solve(M + rotor, u - h)
        if motor.inductance == 0:
            return np.concatenate([y[2:4], ddq])
        di = (voltage - resistance * i - k * r * y[2 + a]) / motor.inductance
        return np.concatenate([y[2:4], ddq, [di]])

    return rhs, rotor, current


def motion(
    fit: ChainSeries,
    motor: object,
    voltage: float,
    a: int,
    start: tuple,
    t: np.ndarray,
    method: str,
    rtol: float,
) -> Motion:
    """The chain at rest at ``start`` with the motor (``motor``: resistance, inductance,
    torque_constant, rotor_inertia, friction, ratio) at driver ``a`` under ``voltage``, on
    the grid t; refused where the motion leaves the series' domain."""
    from scipy.integrate import solve_ivp

    rhs, rotor, current = _rhs(fit, motor, voltage, a)
    y0 = [*start, 0.0, 0.0] + ([0.0] if motor.inductance > 0 else [])
    scale = np.array([1.0, 1.0, 1.0, 1.0, voltage / motor.resistance])[: len(y0)]
    span = (0.0, float(t[-1]))

    def margin(_t: float, y: np.ndarray) -> float:
        return float(np.min(np.concatenate([y[:2] - fit.low, fit.high - y[:2]])))

    margin.terminal = True
    sol = solve_ivp(rhs, span, y0, method, t, events=margin, rtol=rtol, atol=rtol * scale)
    if sol.status == 1:
        raise ValueError(
            f"the reference's motion leaves the domain of its series ({fit.low} .. "
            f"{fit.high}) at t = {sol.t_events[0][0]:.6g} s, at {sol.y_events[0][0][:2]}"
        )
    if not sol.success:
        raise RuntimeError(f"the reference ({method}) failed: {sol.message}")
    q, dq = sol.y[:2].T, sol.y[2:4].T
    ddq = np.empty_like(q)
    chain = fit.chain
    for ix in np.array_split(np.arange(len(t)), max(1, -(-len(t) // _CHUNK))):
        kin = chain.state(q[ix], dq[ix])
        M, h = chain.inertia_matrix(kin) + rotor, chain.bias(kin)
        u = np.zeros((len(ix), 2))
        i = current(sol.y[:, ix])
        r = motor.ratio
        u[:, a] = r * (motor.torque_constant * i - motor.friction * r * dq[ix, a])
        ddq[ix] = np.linalg.solve(M, (u - h)[..., None])[..., 0]
    return Motion(t, q, dq, ddq)


def reactions(chain: multidriver.MultiChain, m: Motion) -> dict[str, np.ndarray]:
    """The harness's joint reactions (every ``*.R_*`` output, as the FMUs name them)
    along the motion ``m``; refuses a chain whose loads are not zero."""
    parts: dict[str, list[np.ndarray]] = {}
    for ix in np.array_split(np.arange(len(m.t)), max(1, -(-len(m.t) // _CHUNK))):
        kin = chain.state(m.q[ix], m.dq[ix], m.ddq[ix], t=m.t[ix])
        for key in chain.load_inputs():
            if np.any(np.real(kin[key]) != 0):
                raise ValueError(f"{chain.name}: the harness applies the load {key}")
        for name, values in chain.fmu_outputs(kin).items():
            if ".R_" in name:
                parts.setdefault(name, []).append(np.real(values))
    return {name: np.concatenate(p) for name, p in parts.items()}

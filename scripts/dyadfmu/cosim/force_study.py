"""A machine driven by a force law, against the same machine as one ODE: the lift's plant
(``lift_forward``: the ram's force in) under a force that starts above what holds the
ram at rest and falls linearly,

    F(t) = F_hold (hold + slope t),    F_hold the harness's force at rest at ``start``,

so that the platform rises and slows down within the stroke. The plant is
given the force at each communication point, held over the step or with its rate (FMI 2's
input derivatives, with which its linear interpolation is the law itself). The reference
is the harness's effort J(x) x'' + h(x, x') = F(t) (:func:`dyadfmu.reference.forward.
chain_terms`), integrated by SciPy's DOP853; its accelerations and joint reactions on the
grid are the harness's at the solution's states. A hydraulic cylinder's model (the force
as a function of pressure and flow) is another FMU's job: no (b) or (c) here.

API: :data:`LIFT`, :func:`law`, :func:`reference`, :func:`run`.
"""

from __future__ import annotations

import functools
import math
import time as clock
from dataclasses import dataclass

import numpy as np

from .. import paths
from ..fmi.slave import Slave
from ..reference import forward
from . import mechanism_drive, plant_study

__all__ = ["LIFT", "ForceMachine", "law", "reference", "run"]


@dataclass(frozen=True)
class ForceMachine:
    """The plant ``plant`` whose ``driver`` (a ram) takes a force, its harness chain
    ``mechanism``, the ram's position at rest [m], the run [s], and the law's ``hold`` and
    ``slope`` [1/s] (times the holding force)."""

    name: str
    plant: str
    mechanism: str
    driver: str
    start: float
    t_end: float
    hold: float
    slope: float


LIFT = ForceMachine("lift", "lift_forward", "lift", "ram", 0.1, 1.0, 1.1, -0.2)


@functools.cache
def holding_force(m: ForceMachine = LIFT) -> float:
    """The force [N] that holds ``m``'s ram at rest at its start, its loads off."""
    return forward.chain_terms(plant_study.unloaded(m.mechanism), 0.0, m.start, 0.0)[1]


def law(m: ForceMachine = LIFT) -> tuple[float, float]:
    """F(0) [N] and F' [N/s] of ``m``'s force law."""
    hold = holding_force(m)
    return m.hold * hold, m.slope * hold


def _names(m: ForceMachine) -> tuple[str, str]:
    return f"{m.driver}.position", f"{m.driver}.velocity"


def run(step: float, rates: bool, m: ForceMachine = LIFT, version: int = 2) -> plant_study.PlantRun:
    """``m``'s plant under the force law at communication step ``step``: the force at each
    communication point held over the step, or (``rates``) with its rate."""
    n = mechanism_drive.whole_steps(m.t_end, step)
    force, rate = law(m)
    plant = Slave(paths.built_fmu(m.plant, version, how="scripts/run-tests"), "plant")
    reactions = plant_study.reaction_names(plant.md.modelVariables)
    names = (*_names(m), *reactions)
    rows = np.empty((n + 1, len(names)))
    effort = f"{m.driver}.force"
    started = clock.process_time()
    try:
        plant_study.inputs_at_zero(plant, effort)
        plant.set(effort, force)
        plant.initialize({f"{m.driver}.position_start": m.start})
        for k in range(n + 1):
            plant.set(effort, force + rate * k * step)
            if rates:
                plant.set_rates(effort, rate)
            rows[k] = plant.get(names)
            if k < n:
                plant.do_step(k * step, step)
    finally:
        plant.close()
    cpu = clock.process_time() - started
    t = step * np.arange(n + 1)
    found = {name: rows[:, 2 + j].copy() for j, name in enumerate(reactions)}
    return plant_study.PlantRun("force", step, math.nan, t, rows[:, 0], rows[:, 1], cpu, found)


def reference(t: np.ndarray, rtol: float = 1e-12, m: ForceMachine = LIFT) -> plant_study.Reference:
    """``m`` under its force law as one ODE on the grid t, and its joint reactions."""
    from scipy.integrate import solve_ivp

    chain = plant_study.unloaded(m.mechanism)
    force, rate = law(m)

    def rhs(time: float, y: np.ndarray) -> np.ndarray:
        J, h = forward.chain_terms(chain, time, y[0], y[1])
        return np.array([y[1], (force + rate * time - h) / J])

    span = (0.0, float(t[-1]))
    sol = solve_ivp(rhs, span, [m.start, 0.0], "DOP853", t, rtol=rtol, atol=rtol * 1e-2)
    if not sol.success:
        raise RuntimeError(f"the reference (DOP853) failed: {sol.message}")
    x, v = sol.y
    a = np.empty_like(x)
    for ix in np.array_split(np.arange(len(t)), max(1, -(-len(t) // 20000))):
        J, h = forward.chain_terms_at(chain, t[ix], x[ix], v[ix])
        a[ix] = (force + rate * t[ix] - h) / J
    return plant_study.Reference(t, x, v, a, plant_study.reactions(m, t, x, v, a))

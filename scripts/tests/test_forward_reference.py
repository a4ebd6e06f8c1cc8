"""The forward-dynamics reference (dyadfmu.reference.forward): the motion under given
efforts, from the Newton-Euler reference's M(q) and h alone.

- Its accelerations invert the reference's inverse dynamics: the efforts the reference
  balances a motion with give back that motion's accelerations.
- Along a run of its own, the drivers' and loads' work equals the change of kinetic and
  potential energy (T + V - W constant), to 1e-9 of the energy exchanged.
- Its arguments are checked, naming the one that is wrong.
"""

from __future__ import annotations

import numpy as np
import pytest
from dyadfmu.mechanisms import multidriver
from dyadfmu.reference import forward


@pytest.mark.parametrize("name", ("leg", "three_drivers", "carried_cylinders"))
def test_the_accelerations_invert_the_inverse_dynamics(name):
    chain = multidriver.load(name)
    kin = chain.working_points(4, seed=36)
    out = chain.reference(kin)
    worst = 0.0
    for k in range(len(kin["t"])):
        q, dq, ddq = (np.array([kin[d.coordinates[i]][k] for d in chain.drivers]) for i in range(3))
        u = np.array([out[d.effort][k] for d in chain.drivers])
        loads = {key: kin[key][k] for key in chain.load_inputs()}
        got = forward.accelerations(chain, kin["t"][k], q, dq, u, loads)
        worst = max(worst, float(np.max(np.abs(got - ddq)) / np.max(np.abs(ddq))))
    print(f"{name}: accelerations from the efforts within {worst:.1e} of their peak")
    assert worst < 1e-10


@pytest.mark.parametrize("name, duration", (("leg", 0.3), ("three_drivers", 0.1)))
def test_the_work_done_is_the_change_of_energy_along_a_run(name, duration):
    """A servo about mid-range, started off it: T + V - W stays constant."""
    chain = multidriver.load(name)
    low, high = np.array([chain.ranges[d] for d in chain.driver_names]).T
    middle = 0.5 * (low + high)
    law = forward.holding(chain, dict(zip(chain.driver_names, middle, strict=True)), stiffness=40.0)
    start = middle + 0.05 * (high - low)
    times = np.linspace(0.0, duration, 6)
    run = forward.integrate(chain, law, start, 0.0 * start, times, rtol=1e-11, atol=1e-11)
    energy = np.array(
        [forward.energy(chain, t, q, dq) for t, q, dq in zip(run.t, run.q, run.dq, strict=True)]
    )
    exchanged = np.ptp(energy)
    drift = np.ptp(energy - run.work)
    moved = np.max(np.abs(run.q - start), axis=0) / (high - low)
    print(
        f"{name}: T + V - W drifts {drift:.1e} J over {exchanged:.3g} J exchanged, "
        f"{run.evaluations} evaluations; each driver moved {np.round(moved, 3)} of its range"
    )
    assert np.all(moved > 0.02)  # the motion is no rest
    assert drift < 1e-9 * exchanged
    assert np.allclose(run.ddq[0], forward.accelerations(chain, 0.0, start, 0.0 * start, run.u[0]))


def test_the_arguments_are_checked_by_name():
    chain = multidriver.load("leg")
    with pytest.raises(ValueError, match="q0: expected a value for each of front, rear"):
        forward.integrate(chain, lambda t, q, dq: 0 * q, {"front": -1.0}, [0, 0], [0, 1])
    with pytest.raises(ValueError, match="dq0: expected 2 finite values"):
        forward.integrate(chain, lambda t, q, dq: 0 * q, [-1, -2], [0, np.nan], [0, 1])
    with pytest.raises(ValueError, match="times: expected an increasing array"):
        forward.integrate(chain, lambda t, q, dq: 0 * q, [-1, -2], [0, 0], [1, 0])
    with pytest.raises(ValueError, match="stiffness, damping"):
        forward.holding(chain, {"front": -1.0, "rear": -2.0}, stiffness=np.inf)


@pytest.mark.parametrize("inductance", (1e-3, 1e-6))
def test_with_motors_the_energy_supplied_is_stored_or_dissipated(inductance):
    """Both hips of the leg driven by DC motors at a voltage law: the supplies' work
    equals the mechanism's and rotors' kinetic and potential energy, the inductances'
    L i^2 / 2 and what the resistance and friction dissipate, with a small inductance
    (stiff) as with a large one."""
    chain = multidriver.load("leg")
    low, high = np.array([chain.ranges[d] for d in chain.driver_names]).T
    middle = 0.5 * (low + high)
    motor = forward.DCMotor(1.0, inductance, 0.5, rotor_inertia=1e-4, friction=1e-4, ratio=20.0)
    holding = chain.bias(chain.state(middle[None, :]))[0] / (motor.ratio * motor.torque_constant)

    def voltage(t, q, dq):
        return motor.resistance * holding + 40.0 * (middle - q)

    start = middle + 0.05 * (high - low)
    current = dict(zip(chain.driver_names, holding, strict=True))
    motors = {"front": motor, "rear": motor}
    # the stiff circuit (L / R = 1 us) needs Radau, and less time to show its balance
    stiff = inductance < 1e-4
    times = np.linspace(0.0, 0.02 if stiff else 0.05, 3)
    method = "Radau" if stiff else "DOP853"
    run = forward.integrate_with_motors(
        chain, motors, voltage, start, 0.0 * start, current, times, 1e-9, 1e-12, method
    )
    balance = run.stored + run.dissipated - run.supplied
    drift, scale = np.ptp(balance), np.max(np.abs(run.supplied))
    moved = np.max(np.abs(run.run.q - start))
    print(
        f"L = {inductance:g} H: drift {drift:.1e} J of {scale:.3g} J supplied, "
        f"{run.run.evaluations} evaluations, the hips moved {moved:.3g} rad"
    )
    assert moved > 1e-3
    assert drift < 1e-9 * scale

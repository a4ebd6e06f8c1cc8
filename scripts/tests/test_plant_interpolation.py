"""A plant's inputs followed along their first derivatives over a step and its outputs'
first derivatives: FMI 2's canInterpolateInputs with fmi2SetRealInputDerivatives, and
maxOutputDerivativeOrder 1 with fmi2GetRealOutputDerivatives and fmi3GetOutputDerivatives.

- A torque that grows linearly, given as its value and derivative at each communication
  point: the shaper's motion against the Newton-Euler reference's forward dynamics under
  the same law (dyadfmu.reference.forward, DOP853 at rtol 1e-12) within 1e-8 at any step;
  the same torque held over each step is far off, so the derivative is what is used.
- Every Real output's derivative against a three-point difference of the outputs along the
  motion (a step of 5e-7 s at rtol 1e-13), with a torque, a gas force and a voltage that
  all ramp; the motion's own (the angle's is the speed, the speed's the acceleration)
  exactly.
- A derivative holds until set again, an FMU state keeps it, and what is not a finite
  first derivative of an interpolated input is refused, naming it.
"""

from __future__ import annotations

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave, SlaveError
from dyadfmu.mechanisms import chains
from dyadfmu.reference import forward
from fmpy import read_model_description

#: The shaper's cutting force [N], constant, as in test_forward_scenes
SHAPER_LOAD = {"slider": {"model": "payload", "force": [-30.0, 0.0]}}
#: The crank torque's law: TORQUE + TORQUE_RATE t [N m]
TORQUE, TORQUE_RATE = 20.0, 400.0
STOP = 0.2


def _fmu(identifier: str, version: int = 2) -> str:
    try:
        return str(paths.built_fmu(identifier, version))
    except FileNotFoundError as missing:
        pytest.skip(str(missing))


@pytest.fixture(scope="module")
def shaper():
    chain = chains.load("shaper", data={"load": SHAPER_LOAD})
    times = np.linspace(0.0, STOP, 21)
    ref = forward.integrate_chain(chain, TORQUE, chain._phi0, 0.0, times, effort_rate=TORQUE_RATE)
    return chain, ref


def _shaper_run(chain, step: float, with_rate: bool) -> np.ndarray:
    """(angle, speed) every 0.01 s of the shaper plant stepped at `step`, the torque set
    at each communication point to the law's value there, and with its derivative or
    held."""
    pos, rate, _ = chain.coordinate_names
    slave = Slave(_fmu("shaper_forward"))
    rows = []
    try:
        slave.set(("slider.force.x", "slider.force.y"), (-30.0, 0.0))
        slave.initialize({f"{pos}_start": chain._phi0})
        n = int(round(STOP / step))
        every = max(1, int(round(0.01 / step)))
        for k in range(n):
            t = k * step
            slave.set(chain.drive_output, TORQUE + TORQUE_RATE * t)
            if with_rate:
                slave.set_rates(chain.drive_output, TORQUE_RATE)
            if k % every == 0:
                rows.append(slave.get((pos, rate)))
            slave.do_step(t, step)
        rows.append(slave.get((pos, rate)))
    finally:
        slave.close()
    return np.array(rows)


def _errors(ref, rows: np.ndarray) -> tuple[float, float]:
    every = max(1, (len(ref.t) - 1) // (len(rows) - 1))
    q, dq = ref.q[::every, 0], ref.dq[::every, 0]
    q_error = np.max(np.abs(rows[:, 0] - q)) / np.ptp(ref.q[:, 0])
    v_error = np.max(np.abs(rows[:, 1] - dq)) / np.max(np.abs(ref.dq))
    return q_error, v_error


@pytest.mark.parametrize("step", (1e-1, 1e-2, 1e-3))
def test_a_torque_ramp_is_followed_within_each_step(shaper, step):
    chain, ref = shaper
    q_error, v_error = _errors(ref, _shaper_run(chain, step, with_rate=True))
    print(f"ramp at {step:g} s: angle {q_error:.1e} of the travel, speed {v_error:.1e}")
    assert q_error < 1e-8 and v_error < 1e-8


def test_the_same_torque_held_over_each_step_is_first_order_off(shaper):
    chain, ref = shaper
    q_error, v_error = _errors(ref, _shaper_run(chain, 1e-2, with_rate=False))
    print(f"held at 0.01 s: angle {q_error:.1e} of the travel, speed {v_error:.1e}")
    assert q_error > 1e-4 and v_error > 1e-3


#: Plants with every input ramping (value, derivative per second), their parameters
RAMPS = {
    "slider_crank_forward": (
        {"crank.torque": (5.0, 300.0), "piston.force.x": (-300.0, 4.0e4)},
        {"crank.omega_start": 40.0},
    ),
    "slider_crank_motor": (
        {"crank.motor.voltage": (100.0, 2.0e3), "piston.force.x": (-50.0, -1.0e4)},
        {"crank.omega_start": 30.0},
    ),
    "leg_motor": ({}, {}),
    "slider_crank_linear_motor": (
        {"crank.motor.voltage": (100.0, 2.0e3), "piston.force.x": (-50.0, -1.0e4)},
        {"crank.omega_start": 30.0},
    ),
    "leg_mixed_motor": (
        {"front.motor.voltage": (2.0, 40.0), "rear.motor.voltage": (-1.0, 30.0)},
        {"front.omega_start": 1.0},
    ),
}
DELTA = 5e-7


def _real_outputs(fmu: str) -> list[str]:
    md = read_model_description(fmu)
    return [
        v.name
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]


def _start(slave: Slave, identifier: str, version: int) -> None:
    inputs, parameters = RAMPS[identifier]
    if inputs:
        slave.set(tuple(inputs), [v for v, _ in inputs.values()])
    slave.initialize({**parameters, "solver.rtol": 1e-13, "solver.atol": 1e-13})
    if inputs and version == 2:
        slave.set_rates(tuple(inputs), [r for _, r in inputs.values()])


@pytest.mark.parametrize("identifier", sorted(RAMPS))
def test_each_output_rate_is_the_slope_of_the_output(identifier):
    fmu = _fmu(identifier)
    names = _real_outputs(fmu)
    slave = Slave(fmu)
    try:
        _start(slave, identifier, 2)
        for k in range(5):
            slave.do_step(k * 1e-3, 1e-3)
        y0, rates = np.array(slave.get(tuple(names))), np.array(slave.output_rates(tuple(names)))
        slave.do_step(5e-3, DELTA)
        y1 = np.array(slave.get(tuple(names)))
        slave.do_step(5e-3 + DELTA, DELTA)
        y2 = np.array(slave.get(tuple(names)))
    finally:
        slave.close()
    slope = (-3 * y0 + 4 * y1 - y2) / (2 * DELTA)
    counts = [n.startswith("solver.") for n in names]
    assert np.all(rates[counts] == 0)
    scale = np.abs(rates) + 100.0 * np.abs(y0) + 1e-9
    error = np.abs(slope - rates) / scale
    error[counts] = 0
    worst = int(np.argmax(error))
    print(f"{identifier}: worst {names[worst]} {error[worst]:.1e} of |rate| + 100 |value|")
    assert np.all(np.isfinite(rates))
    assert error[worst] < 2e-6, names[worst]
    by = dict(zip(names, rates, strict=True))
    values = dict(zip(names, y0, strict=True))
    for driver in ("crank",) if identifier.startswith("slider") else ():
        assert by[f"{driver}.angle"] == values[f"{driver}.omega"]
        assert by[f"{driver}.omega"] == values[f"{driver}.epsilon"]


@pytest.mark.parametrize("identifier", sorted(RAMPS))
def test_fmi3_gives_the_same_output_rates(identifier):
    """Without input derivatives (FMI 3 has none), both versions agree bit for bit."""
    rates = []
    for version in (2, 3):
        fmu = _fmu(identifier, version)
        names = tuple(n for n in _real_outputs(_fmu(identifier, 2)))
        slave = Slave(fmu)
        try:
            inputs, parameters = RAMPS[identifier]
            if inputs:
                slave.set(tuple(inputs), [v for v, _ in inputs.values()])
            slave.initialize(parameters)
            slave.do_step(0.0, 1e-3)
            rates.append(slave.output_rates(names))
        finally:
            slave.close()
    assert np.array_equal(rates[0], rates[1])
    assert np.any(np.array(rates[0]) != 0)


def _steps_from(slave: Slave, t: float, n: int) -> list:
    for k in range(n):
        slave.do_step(t + k * 1e-3, 1e-3)
    return slave.get(("crank.angle", "crank.omega", "crank.torque"))


def test_a_derivative_holds_until_set_again_and_an_fmu_state_keeps_it():
    fmu = _fmu("slider_crank_forward")
    slave = Slave(fmu)
    try:
        slave.set("crank.torque", 5.0)
        slave.initialize({"crank.omega_start": 40.0})
        slave.set_rates("crank.torque", 300.0)
        state = slave.fmu.getFMUstate()
        ramped = _steps_from(slave, 0.0, 4)
        # the input moved along its derivative: 5 + 300 * 0.004 N m
        assert ramped[2] == pytest.approx(5.0 + 300.0 * 4e-3, rel=1e-14)
        slave.set_rates("crank.torque", 0.0)
        held = _steps_from(slave, 4e-3, 4)
        assert held[2] == ramped[2]
        slave.fmu.setFMUstate(state)
        assert _steps_from(slave, 0.0, 4) == ramped
        bytes_ = slave.fmu.serializeFMUstate(state)
        slave.set_rates("crank.torque", -1.0e3)
        slave.fmu.setFMUstate(slave.fmu.deSerializeFMUstate(bytes_))
        assert _steps_from(slave, 0.0, 4) == ramped
    finally:
        slave.close()


@pytest.mark.parametrize(
    "name, order, value, says",
    [
        ("crank.torque", 2, 1.0, "order 2"),
        ("crank.torque", 1, float("nan"), "derivative of crank.torque = nan (N.m/s)"),
        ("solver.rtol", 1, 1.0, "solver.rtol is not an input this FMU interpolates"),
        ("crank.angle", 1, 1.0, "crank.angle is not an input this FMU interpolates"),
    ],
)
def test_a_wrong_input_derivative_is_refused_naming_it(name, order, value, says):
    slave = Slave(_fmu("slider_crank_forward"))
    try:
        slave.initialize()
        with pytest.raises(SlaveError) as refused:
            slave._call(
                "setRealInputDerivatives",
                slave.fmu.setRealInputDerivatives,
                [slave.vr[name]],
                [order],
                [value],
            )
        assert says in refused.value.message
    finally:
        slave.close()


def test_a_derivative_that_carries_an_input_to_infinity_refuses_the_step():
    slave = Slave(_fmu("slider_crank_forward"))
    try:
        slave.set("crank.torque", 5.0)
        slave.initialize()
        slave.set_rates("crank.torque", 1e308)
        before = slave.get(("crank.angle", "crank.torque"))
        with pytest.raises(SlaveError) as refused:
            slave.do_step(0.0, 10.0)
        says = "crank.torque = 5 with its derivative 1e+308 per second is not finite 10 s on"
        assert says in refused.value.message
        assert slave.get(("crank.angle", "crank.torque")) == before
    finally:
        slave.close()


def test_an_algebraic_fmu_neither_interpolates_nor_differentiates():
    for version in (2, 3):
        md = read_model_description(_fmu("slider_crank", version))
        assert not md.coSimulation.canInterpolateInputs
        assert not md.coSimulation.maxOutputDerivativeOrder
    slave = Slave(_fmu("slider_crank"))
    try:
        slave.initialize()
        with pytest.raises(SlaveError) as refused:
            slave.output_rates(("crank.torque",))
        assert "maxOutputDerivativeOrder is 0" in refused.value.message
    finally:
        slave.close()


@pytest.mark.parametrize("identifier", sorted(RAMPS))
def test_a_plant_says_it_interpolates(identifier):
    md2 = read_model_description(_fmu(identifier, 2))
    assert md2.coSimulation.canInterpolateInputs
    assert md2.coSimulation.maxOutputDerivativeOrder == 1
    md3 = read_model_description(_fmu(identifier, 3))
    assert md3.coSimulation.maxOutputDerivativeOrder == 1

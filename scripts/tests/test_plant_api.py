"""dyadfmu.forward: a plant over a time grid in one call (dyadfmu/plant.py).

Against the FMU stepped by hand through the fmpy wrapper, bit for bit, with each input
law held over each step at its value at the step's start; a run into a toggle ends where
the FMU stopped, at its last successful time; bad arguments are refused naming them."""

from __future__ import annotations

import math

import dyadfmu
import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave, SlaveError

GRID = np.linspace(0.0, 0.05, 26)


def torque_law(t: float) -> float:
    """N.m: a ramp with a ripple, so that a law read at the wrong point shows."""
    return 2.0 + 40.0 * t + 0.5 * math.sin(300.0 * t)


def by_hand(version: int, torque: np.ndarray, parameters: dict) -> dict:
    """The slider-crank plant stepped on GRID with torque[k] over step k."""
    slave = Slave(paths.built_fmu("slider_crank_forward", version))
    outputs = ("crank.angle", "crank.omega", "crank.epsilon", "engine.R_mk.x")
    try:
        slave.set("crank.torque", torque[0])
        slave.initialize(parameters)
        rows = [slave.get(outputs)]
        for k in range(GRID.size - 1):
            slave.set("crank.torque", torque[k])
            slave.do_step(GRID[k], GRID[k + 1] - GRID[k])
            rows.append(slave.get(outputs))
    finally:
        slave.close()
    table = np.array(rows)
    return {n: table[:, j] for j, n in enumerate(outputs)}


@pytest.mark.parametrize("version", [2, 3])
def test_a_law_as_a_function_or_an_array_is_held_over_each_step(version):
    parameters = {"crank.omega_start": 20.0, "solver.rtol": 1e-9}
    torque = np.array([torque_law(t) for t in GRID])
    expected = by_hand(version, torque, parameters)
    for law in (torque_law, torque):
        run = dyadfmu.forward(
            "slider_crank_forward", GRID, {"crank.torque": law}, parameters, version=version
        )
        assert run.stopped is None
        assert np.array_equal(run.time, GRID)
        assert np.array_equal(run["crank.torque"], torque)
        for name, values in expected.items():
            assert np.array_equal(run[name], values), name
        assert run.units["crank.angle"] == "rad" and run.units["engine.R_mk.x"] == "N"
        assert np.all(run["status"] == 0)


def test_a_constant_law_and_the_start_values():
    run = dyadfmu.forward("slider_crank_forward", GRID, {"crank.torque": 3.0})
    assert np.all(run["crank.torque"] == 3.0)
    assert run["crank.angle"][0] == 0.0 and run["crank.omega"][0] == 0.0
    assert run["crank.omega"][-1] > 0, "a positive torque from rest turns the crank forward"
    progress = []
    dyadfmu.forward("slider_crank_forward", GRID, {}, progress=progress.append)
    assert progress == list(GRID[1:])


def test_a_run_into_a_toggle_ends_where_the_plant_stopped():
    """The lift's ram with no force falls into its toggle before 1 s: the trajectory
    ends at the FMU's last successful time, with the outputs there."""
    grid = np.linspace(0.0, 1.0, 11)
    run = dyadfmu.forward("lift_forward", grid, version=2)
    assert run.stopped is not None and "hoist" in run.stopped
    assert grid[-2] > run.time[-1] > grid[len(run.time) - 2]
    slave = Slave(paths.built_fmu("lift_forward", 2))
    try:
        slave.initialize()
        for k in range(len(run.time) - 2):
            slave.do_step(grid[k], grid[k + 1] - grid[k])
        with pytest.raises(SlaveError) as stop:
            slave.do_step(grid[len(run.time) - 2], grid[1])
        assert stop.value.status == 2
        assert slave.fmu.getRealStatus(2) == run.time[-1]
        assert slave.get("ram.position") == run["ram.position"][-1]
    finally:
        slave.close()
    assert all(len(values) == len(run.time) for values in run.values.values())


def test_an_interpolated_law_is_followed_between_the_points():
    """The lift's force law F(t) = F_hold (1.1 - 0.2 t / s) as a function over a 10 ms
    grid: with interpolate=True the plant follows it along each step and the ram's motion
    is the harness's to 1e-10 of its travel (1.0e-12); held, 2.9e-2 off, first order. An array
    on the grid is its polyline: the same run, bit for bit."""
    from dyadfmu.cosim import force_study

    m = force_study.LIFT
    force, rate = force_study.law(m)
    grid = np.linspace(0.0, m.t_end, 101)
    ref = force_study.reference(grid, 1e-12, m)
    travel = np.ptp(ref.phi)
    law = {"ram.force": lambda t: force + rate * t}
    start = {"ram.position_start": m.start}
    runs = {
        how: dyadfmu.forward("lift_forward", grid, law, start, version=2, interpolate=how)
        for how in (True, False)
    }
    off = {how: np.max(np.abs(r["ram.position"] - ref.phi)) / travel for how, r in runs.items()}
    print(f"lift: interpolated {off[True]:.1e}, held {off[False]:.1e} of the travel")
    assert off[True] < 1e-10 and off[False] > 1e-3
    along = dyadfmu.forward(
        "lift_forward",
        grid,
        {"ram.force": force + rate * grid},
        start,
        version=2,
        interpolate=True,
    )
    assert np.array_equal(along["ram.position"], runs[True]["ram.position"])
    assert np.array_equal(along["ram.force"], force + rate * grid)


def test_an_interpolated_run_that_stops_records_the_input_it_stopped_at():
    """The leg driven by supplies ramping over 1 s runs into a limit inside its one step:
    the last row's inputs are the lines' values where it stopped, the plant's own."""
    run = dyadfmu.forward(
        "leg_mixed_motor",
        [0.0, 1.0],
        {"front.motor.voltage": [0.0, 24.0], "rear.motor.voltage": [0.0, -24.0]},
        version=2,
        interpolate=True,
    )
    assert run.stopped is not None and 0.0 < run.time[-1] < 1.0
    assert run["front.motor.voltage"][-1] == pytest.approx(24.0 * run.time[-1], rel=1e-12)
    assert run["rear.motor.voltage"][-1] == pytest.approx(-24.0 * run.time[-1], rel=1e-12)


@pytest.mark.parametrize(
    ("call", "named"),
    [
        (lambda: dyadfmu.forward("slider_crank", GRID), "is not a plant"),
        (lambda: dyadfmu.forward("slider_crank_forward", GRID, {"crank.torqe": 1}), "crank.torqe"),
        (
            lambda: dyadfmu.forward("slider_crank_forward", GRID, {"crank.torque": np.zeros(3)}),
            "inputs['crank.torque']: one value per point",
        ),
        (
            lambda: dyadfmu.forward(
                "slider_crank_forward", GRID, {"crank.torque": lambda t: math.nan}
            ),
            "inputs['crank.torque'] is nan at t = 0.0 s",
        ),
        (lambda: dyadfmu.forward("slider_crank_forward", [0.0, 0.1, 0.1]), "not increasing"),
        (lambda: dyadfmu.forward("slider_crank_forward", [0.0]), "at least 2 points"),
        (
            lambda: dyadfmu.forward("slider_crank_forward", GRID, interpolate=True),
            "interpolate: slider_crank_forward_fmi3.fmu is an FMI 3 FMU",
        ),
        (
            lambda: dyadfmu.forward(
                "slider_crank_forward",
                GRID,
                {"crank.torque": np.append(np.zeros(GRID.size - 1), math.inf)},
                version=2,
                interpolate=True,
            ),
            "inputs['crank.torque'] is inf at t = ",
        ),
        (
            lambda: dyadfmu.forward(
                "slider_crank_forward",
                [0.0, 1.0, 2.0],
                {"crank.torque": [-1e308, 1e308, 0.0]},
                version=2,
                interpolate=True,
            ),
            "inputs['crank.torque']: its rate from t = 0.0 to 1.0 s overflows double",
        ),
        (
            lambda: dyadfmu.forward("slider_crank_forward", GRID, parameters={"crank.mass": 1}),
            "'crank.mass' is not a parameter",
        ),
    ],
)
def test_bad_arguments_are_refused_by_name(call, named):
    with pytest.raises(ValueError, match=None) as refused:
        call()
    assert named in str(refused.value)


def test_a_refused_parameter_value_is_the_fmus_error():
    with pytest.raises(SlaveError) as refused:
        dyadfmu.forward("slider_crank_forward", GRID, parameters={"solver.rtol": -1.0})
    assert "solver.rtol" in refused.value.message

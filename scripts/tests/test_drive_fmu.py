"""The drive FMU (a DC motor turning a crank, with states) through fmpy: validation,
its integration against SciPy's Radau at tight tolerances, independence of the
communication step, and bad inputs."""

import math

import numpy as np
import pytest
from dyadfmu.fmi.slave import Slave
from dyadfmu.paths import build_dir
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu
from scipy.integrate import solve_ivp

VERSIONS = (2, 3)


def drive_path(version):
    path = build_dir() / "fmus" / f"drive_fmi{version}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (scripts/run-tests does)")
    return path


PARAMS = {
    "motor.stall_torque": 12.0,
    "motor.no_load_speed": 36.0,
    "inertia": 2e-3,
    "crank.mass": 0.25,
    "crank.com.x": 0.02,
    "crank.com.y": 0.003,
    "gravity.x": 0.0,
    "gravity.y": -9.81,
    "start.angle": 0.3,
    "start.speed": 20.0,
}


def reference(t_end, load_torque, load_inertia, t_eval):
    """The same machine integrated by SciPy (Radau, rtol 1e-12)."""
    p = PARAMS

    def rhs(t, y):
        phi, omega = y
        c, s = math.cos(phi), math.sin(phi)
        rx, ry = (
            c * p["crank.com.x"] - s * p["crank.com.y"],
            s * p["crank.com.x"] + c * p["crank.com.y"],
        )
        gravity = p["crank.mass"] * (rx * p["gravity.y"] - ry * p["gravity.x"])
        motor = p["motor.stall_torque"] * (1 - omega / p["motor.no_load_speed"])
        return [omega, (motor + load_torque + gravity) / (p["inertia"] + load_inertia)]

    sol = solve_ivp(
        rhs,
        (0, t_end),
        [p["start.angle"], p["start.speed"]],
        method="Radau",
        rtol=1e-12,
        atol=1e-12,
        t_eval=t_eval,
    )
    return sol.y


@pytest.mark.parametrize("version", VERSIONS)
def test_drive_validates(version):
    assert validate_fmu(str(drive_path(version))) == []
    md = read_model_description(str(drive_path(version)))
    names = {v.name: v.causality for v in md.modelVariables}
    assert names["load.torque"] == "input" and names["load.inertia"] == "input"
    assert names["crank.omega"] == "output" and names["inertia"] == "parameter"


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("step", (1e-2, 1e-3))
def test_drive_integrates_like_radau(version, step):
    t = np.linspace(0, 0.5, 51)
    load = np.array(
        list(zip(t, -3 + 0 * t, 1e-3 + 0 * t, strict=True)),
        dtype=[("time", float), ("load.torque", float), ("load.inertia", float)],
    )
    result = simulate_fmu(
        str(drive_path(version)),
        stop_time=0.5,
        step_size=step,
        output_interval=0.01,
        start_values=PARAMS,
        input=load,
        output=["crank.angle", "crank.omega", "crank.epsilon", "status"],
    )
    phi, omega = reference(0.5, -3.0, 1e-3, result["time"])
    error_phi = np.max(np.abs(result["crank.angle"] - phi))
    error_omega = np.max(np.abs(result["crank.omega"] - omega)) / np.max(np.abs(omega))
    print(
        f"drive FMI {version}, step {step}: angle error {error_phi:.1e} rad, speed "
        f"{error_omega:.1e} relative"
    )
    assert np.all(result["status"] == 0)
    assert error_phi < 1e-7 and error_omega < 1e-7


def drive(version):
    """An instantiated drive FMU of either version (dyadfmu's fmpy wrapper)."""
    return Slave(drive_path(version), instance_name="drive")


@pytest.mark.parametrize("version", VERSIONS)
def test_drive_states_bad_inertia_and_reset(version, tmp_path):
    d = drive(version)
    for name, value in PARAMS.items():
        d.set(name, value)
    with pytest.raises(FMICallException):
        d.set("inertia", 0.0)  # must be positive
    d.initialize()
    assert d.get("crank.angle") == PARAMS["start.angle"]
    assert d.get("crank.omega") == PARAMS["start.speed"]
    d.do_step(0, 0.01)
    moved = d.get("crank.angle")
    assert moved > PARAMS["start.angle"]
    d.set("load.inertia", -1.0)  # loaded inertia no longer positive
    with pytest.raises(FMICallException):
        d.do_step(0.01, 0.01)
    assert d.get("status") == 2
    d.set("load.inertia", 0.0)  # usable again
    d.do_step(0.01, 0.01)
    assert d.get("status") == 0 and d.get("crank.angle") > moved
    d.fmu.reset()
    d.initialize()
    assert d.get("crank.angle") == 0.0  # the table's start value after reset
    d.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_a_demand_is_a_load_of_the_other_sign(version):
    """load.demand = x moves the crank as load.torque = -x does, bit for bit, and the two
    add (to round-off): a mechanism's crank.torque0 connects to load.demand as it is."""
    runs = []
    for loads in (
        {"load.torque": -1.7},
        {"load.demand": 1.7},
        {"load.torque": 0.3, "load.demand": 2.0},
    ):
        d = drive(version)
        for name, value in PARAMS.items():
            d.set(name, value)
        d.initialize()
        for name, value in loads.items():
            d.set(name, value)
        for k in range(20):
            d.do_step(0.01 * k, 0.01)
        runs.append(d.get(("crank.angle", "crank.omega", "crank.epsilon")))
        d.close()
    assert runs[0] == runs[1]
    assert runs[2] == pytest.approx(runs[0], rel=1e-12)  # 0.3 - 2.0 rounds as -1.7 may not
    assert runs[0][1] != PARAMS["start.speed"]


def _state(d):
    return d.get("crank.angle"), d.get("crank.omega")


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize(
    "inertia, step, next_step",
    ((2e-3, 1e16, 1e-3), (1e-12, 1.0, 1e-8), (1e-300, 1.0, None), (2e-3, 1e3, 1e-3)),
)
def test_drive_refuses_a_step_beyond_the_substep_cap(version, tmp_path, inertia, step, next_step):
    """A step that needs more than a million substeps (here up to 7e300, beyond every
    integer type) is refused with Error before any substep: the state stays where it
    was, and a step short enough then goes on from it."""
    d = drive(version)
    d.set("inertia", inertia)
    d.initialize()
    before = _state(d)
    with pytest.raises(FMICallException) as error:
        d.do_step(0, step)
    assert error.value.status == 3
    assert _state(d) == before
    if next_step is not None:
        d.do_step(0, next_step)
        assert d.get("status") == 0
        assert d.get("crank.angle") != before[0]
    d.close()


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize(
    "name, value",
    (
        ("load.torque", -1.7976931348623157e308),
        ("load.torque", 1.7976931348623157e308),
        ("motor.stall_torque", 1.7976931348623157e308),
    ),
)
def test_drive_reports_an_overflow_as_out_of_range(version, tmp_path, name, value):
    """Accepted values whose acceleration or motor torque overflow double give status 3
    and NaN for them, never status 0 beside an infinite output; the step is discarded
    and the state kept."""
    d = drive(version)
    parameter = name.startswith("motor.")
    if parameter:
        d.set(name, value)
    d.initialize()
    before = _state(d)
    if not parameter:
        d.set(name, value)
    assert d.get("status") == 3
    assert math.isnan(d.get("crank.epsilon")) and not math.isinf(d.get("motor.torque"))
    with pytest.raises(FMICallException):
        d.do_step(0, 0.01)
    assert _state(d) == before and all(math.isfinite(x) for x in before)
    d.close()


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("t, h", ((1.7976931348623157e308, 1e300), (1e300, 1e-300), (1e9, 1e-9)))
def test_drive_refuses_a_step_whose_end_is_not_a_later_finite_time(version, tmp_path, t, h):
    """t + h overflowing, or rounding back to t, is refused with Error, and the
    instance steps on normally afterwards."""
    d = drive(version)
    d.initialize()
    before = _state(d)
    with pytest.raises(FMICallException):
        d.do_step(t, h)
    assert _state(d) == before
    d.do_step(0, 0.01)
    assert d.get("status") == 0 and d.get("crank.angle") != before[0]
    d.close()

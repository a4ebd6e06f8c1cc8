"""Mechanism FMUs (kinematics = "internal"): every output from the driver's motion and the
loads alone, against the harness's NumPy kinematics and Newton-Euler reference; the
effective inertia against the FMU's own torque; the driving effort against Lagrange's
equation built from the FMU's own positions (no reference kinematics)."""

import math
import tomllib

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import mechanism_fmus as mf
from dyadfmu.cosim import multidriver_fmus as mdf
from dyadfmu.fmi import slave as fmi_slave

CASES = [
    (name, branch, motion)
    for name in mf.MECHANISM_FMUS
    for branch in ((1, -1) if name in mf.BRANCHES else (1,))
    for motion in ("constant", "varying")
]


@pytest.mark.parametrize(("name", "branch", "motion"), CASES)
def test_every_output_against_the_reference(name, branch, motion):
    """Two driver cycles: each kinematic output within 1e-12 of its peak, every other
    output within 1e-12 of the largest peak of its unit; status 0 throughout."""
    result = mf.run(name, 2, branch, motion, revolutions=2.0, steps=180)
    assert result.statuses == {0}
    kinematic = {k: v for k, v in result.errors.items() if mf.is_kinematic(k)}
    others = {k: v for k, v in result.unit_errors.items() if not mf.is_kinematic(k)}
    assert name == "monitor" or kinematic  # every mechanism FMU but the monitor shows them
    assert max(kinematic.values(), default=0.0) < 1e-12, mf.summary(result)
    assert max(others.values()) < 1e-12, mf.summary(result)


@pytest.mark.parametrize("name", ["engine", "lift"])
def test_fmi3_agrees(name):
    result = mf.run(name, 3, 1, "varying", revolutions=1.0, steps=120)
    assert result.statuses == {0}
    assert max(result.unit_errors.values()) < 1e-12, mf.summary(result)


def _slave(name, tmp_path):
    s = fmi_slave.Slave(paths.built_fmu(name, 2, None, how="scripts/run-tests"), instance_name=name)
    s.initialize()
    return s


def _evaluate(s, values, names, t):
    s.set(tuple(values), list(values.values()))
    s.do_step(t, 1e-3)
    return np.array(s.get(tuple(names)))


@pytest.mark.parametrize(
    ("name", "driver", "rates"),
    [
        ("engine", "crank", ("omega", "epsilon")),
        ("shaper", "crank", ("omega", "epsilon")),
        ("lift", "ram", ("velocity", "acceleration")),
    ],
)
def test_effective_inertia_is_the_effort_per_unit_driver_acceleration(
    name, driver, rates, tmp_path
):
    """J from the FMU equals d(effort)/d(q''), measured on the FMU's own effort (it is
    affine in q''), and effort = J q'' + effort0."""
    s = _slave(name, tmp_path)
    effort = "force" if driver == "ram" else "torque"
    names = [f"{driver}.{effort}", f"{driver}.J", f"{driver}.{effort}0"]
    series = mf.setup(name, 2, steps=24, revolutions=1.0)[1]
    t = 0.0
    for k in range(0, 24, 5):
        values = {n: float(v[k]) for n, v in series.inputs.items()}
        low = _evaluate(s, values, names, t)
        values[f"{driver}.{rates[1]}"] += 1.0
        high = _evaluate(s, values, names, t + 1e-3)
        t += 2e-3
        assert high[0] - low[0] == pytest.approx(low[1], rel=1e-9, abs=1e-12 * abs(low[0]))
        q2 = values[f"{driver}.{rates[1]}"]
        assert high[0] == pytest.approx(high[1] * q2 + high[2], rel=1e-12, abs=1e-9)


def _spectral_derivative(values: np.ndarray, period: float) -> np.ndarray:
    """d/dq of samples of a smooth periodic function on a uniform grid over one period."""
    n = len(values)
    k = np.fft.fftfreq(n, d=period / n) * 2 * math.pi
    return np.real(np.fft.ifft(1j * k * np.fft.fft(values)))


def test_engine_torque_meets_lagrange_from_the_fmu_alone(tmp_path):
    """Lagrange's equation for the engine at arbitrary crank speeds and accelerations,
    with J, dJ/dq, the positions and the torque all from the FMU: torque = J q'' +
    J'/2 q'^2 + dV/dq - F . dS_piston/dq, dV/dq and dS/dq by spectral differentiation in
    the crank angle of the FMU's own positions. Within 1e-9 of the peak power."""
    with open(paths.SCENES_DIR / "engine.toml", "rb") as f:
        scene = tomllib.load(f)
    links = {g["name"]: g for g in scene["link"]}
    g_y = scene["gravity"]["y"]
    n = 256
    q = 2 * math.pi * np.arange(n) / n
    qd = 300.0 * (1.0 + 0.3 * np.sin(q))
    qdd = 4.0e4 * np.cos(2 * q)
    force = -2.0e4 * np.exp(8.0 * (np.cos(q - 0.3) - 1.0))  # a gas force along -x
    s = _slave("engine", tmp_path)
    names = [
        "crank.torque",
        "crank.J",
        "crank.dJdq",
        "engine.D_m.position.y",
        "engine.D_m.position.x",
        "engine.D_n.position.y",
        "rod.angle",
    ]
    rows = np.array(
        [
            _evaluate(
                s,
                {
                    "crank.angle": q[k],
                    "crank.omega": qd[k],
                    "crank.epsilon": qdd[k],
                    "piston.force.x": force[k],
                    "piston.force.y": 0.0,
                },
                names,
                k * 1e-3,
            )
            for k in range(n)
        ]
    )
    torque, J, dJ, piston_y, piston_x, pin_y, rod_angle = rows.T
    # centres of mass from the FMU's positions and the scene's numbers
    c = scene["crank"]
    crank_com_y = c["com"][0] * np.sin(q) + c["com"][1] * np.cos(q)
    piston_com_y = piston_y + links["piston"]["com"][1]  # the piston translates along x
    rc = links["rod"]["com"]
    rod_com_y = pin_y + rc[0] * np.sin(rod_angle) + rc[1] * np.cos(rod_angle)
    potential = -g_y * (
        c["mass"] * crank_com_y
        + links["piston"]["mass"] * piston_com_y
        + links["rod"]["mass"] * rod_com_y
    )
    dV = _spectral_derivative(potential, 2 * math.pi)
    dx = _spectral_derivative(piston_x, 2 * math.pi)
    # the FMU's J' against the spectral derivative of its J
    assert np.max(np.abs(dJ - _spectral_derivative(J, 2 * math.pi))) < 1e-9 * np.max(np.abs(J))
    lagrange = J * qdd + 0.5 * dJ * qd**2 + dV - force * dx
    power = np.max(np.abs(torque * qd))
    assert np.max(np.abs((torque - lagrange) * qd)) < 1e-9 * power


def test_the_scenes_report_has_a_row_per_scene_with_several_drivers(monkeypatch):
    """dyadfmu scenes' mechanism table (report/mechanisms.rows): a row per FMU of a scene
    with several drivers, its inputs with external kinematics and its own (every driver's
    motion and the loads), its worst errors at random working points within 1e-12. The
    single-driver rows and the callgrind counts are left out here (their own tests)."""
    from dyadfmu.report import mechanisms

    monkeypatch.setattr(mechanisms.mf, "MECHANISM_FMUS", {})
    monkeypatch.setattr(mechanisms, "instructions", lambda *a, **k: (math.nan, math.nan))
    table = mechanisms.rows(paths.build_dir(), quick=True, log=lambda text: None)
    assert table[0] == list(mechanisms.HEADER)
    assert [r[0] for r in table[1:]] == list(mdf.NAMES)
    for r in table[1:]:
        s = fmi_slave.Slave(paths.built_fmu(r[0], 2), instance_name=r[0])
        own = sum(v.causality == "input" for v in s.md.modelVariables)
        s.close()
        # as many where the drivers' links are all there is (carried_cylinders: each
        # cylinder's length and rates for its link's angle and rates)
        assert int(r[2]) >= int(r[3]) == own, r
        for cell in r[4:6]:
            assert float(cell.split()[0]) < 1e-12, r


@pytest.mark.parametrize("name", mdf.NAMES)
def test_several_drivers_co_simulated_along_their_motion(name):
    """The importers' and the Windows comparisons' run of a scene with several drivers
    (multidriver_fmus.setup: one period of every driver's motion at once, 120 steps):
    exactly the FMU's inputs, status 0 throughout, each effort, M(q) entry and h within
    1e-12 of the largest of its unit in the reference along the same motion."""
    from dyadfmu.cosim.compare import simulate_matched
    from dyadfmu.mechanisms import multidriver

    if mdf.fmu_path(name, 2) is None:
        pytest.skip(f"{name}'s FMU is not built yet")
    co = mdf.setup(name, 2, revolutions=1.0, steps=120)
    assert len(co.time) == 121
    fmu, sample, _ = simulate_matched(co, name, float(co.time[-1]), False)
    assert set(np.unique(fmu["status"]).tolist()) == {0}
    chain = multidriver.load(name)
    motion = chain.motion("varying", 1.0)
    want = chain.fmu_outputs(chain.kinematics(np.asarray(co.time), motion))
    names = chain.effort_names + chain.inertia_names() + [d.effort0 for d in chain.drivers]
    peaks: dict = {}
    for o in names:
        peaks[co.units[o]] = max(peaks.get(co.units[o], 0.0), np.max(np.abs(want[o])))
    for o in names:
        error = np.max(np.abs(fmu[o] - want[o][sample])) / peaks[co.units[o]]
        assert error < 1e-12, (name, o, error)

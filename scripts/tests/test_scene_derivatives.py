"""Directional derivatives of the tailored and mechanism FMUs (the generated `derivative`,
the scene's code differentiated on dual numbers): against fourth-order central differences
of the FMU's own outputs, against identities that hold exactly (J = d(effort)/d(q''),
dJ/dq, a link's angle moves at its velocity ratio; with several drivers M(q) = d(efforts)
/d(q'') and h = the efforts at q'' = 0, every angle moves with the drivers' rates), zero
where the model description declares no dependency, and NaN with Discard where the chain
cannot close."""

import math
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import mechanism_fmus as mf
from dyadfmu.cosim import multidriver_fmus as mdf
from dyadfmu.fmi import slave as fmi_slave
from dyadfmu.mechanisms import multidriver

#: the FMUs of scenes with several drivers (leg, three_drivers), at random points of
#: their working ranges
SEVERAL = list(mdf.NAMES)
SCENE_FMUS = [*mf.MECHANISM_FMUS, "press", *SEVERAL]
#: central differences of steps h and 2h: their truncation and round-off stay below this
#: share of the largest rate of a known
DIFFERENCE_LIMIT = 1e-7


def _slave(name, version=2):
    if name in SEVERAL and mdf.fmu_path(name, version) is None:
        # the reference knows it before the generator builds it (the importers' test
        # fails where the build and the scenes the tools cover part ways)
        pytest.skip(f"{name}'s FMU is not built yet")
    path = paths.built_fmu(name, version, None, how="scripts/run-tests")
    s = fmi_slave.Slave(path, instance_name=name)
    s.initialize()
    return s


def _names(s):
    variables = s.md.modelVariables
    inputs = [v.name for v in variables if v.causality == "input"]
    reals = [v.name for v in variables if v.causality == "output" and v.type in ("Real", "Float64")]
    return inputs, reals


def _state(name, k):
    """Inputs at sample k of the harness's driver motion (a state where the chain closes);
    with several drivers at the k-th of 24 random working points; the press, with its
    kinematics outside, at its start values with loads."""
    if name == "press":
        return {}
    if name in SEVERAL:
        return {n: float(v[k]) for n, v in mdf.working_inputs(name, 24, seed=35).items()}
    series = mf.setup(name, 2, motion="varying", steps=24, revolutions=1.0)[1]
    return {n: float(v[k]) for n, v in series.inputs.items()}


def _outputs(s, values, outputs):
    s.set(tuple(values), list(values.values()))
    return np.array(s.get(tuple(outputs)), dtype=float)


def _central(s, values, known, outputs, step=1e-4):
    base = values[known]
    h = step * max(1.0, abs(base))

    def at(x):
        return _outputs(s, {**values, known: x}, outputs)

    fd = (8 * (at(base + h) - at(base - h)) - (at(base + 2 * h) - at(base - 2 * h))) / (12 * h)
    _outputs(s, values, outputs)
    return fd


@pytest.mark.parametrize("name", SCENE_FMUS)
def test_against_central_differences(name):
    """Every Real output along every input, at three states of a driver cycle."""
    s = _slave(name)
    inputs, outputs = _names(s)
    worst = 0.0
    for k in (2, 9, 17):
        values = {n: float(s.get(n)) for n in inputs} | _state(name, k)
        values = {
            n: v + (3.0 if n.endswith((".x", ".y", "moment")) else 0.0) for n, v in values.items()
        }
        _outputs(s, values, outputs)
        for known in inputs:
            exact = np.array(s.directional_derivative(tuple(outputs), (known,), [1.0]))
            fd = _central(s, values, known, outputs)
            off = np.abs(exact - fd)
            if np.max(off) >= DIFFERENCE_LIMIT * np.max(np.abs(fd)):
                off = np.minimum(off, _kinked(s, values, known, outputs, exact))
            error = np.max(off) / max(np.max(np.abs(fd)), 1e-300)
            worst = max(worst, error)
            assert error < DIFFERENCE_LIMIT, (name, known, k, error)
    print(f"{name}: worst difference {worst:.2e} of the largest rate")
    s.close()


def _kinked(s, values, known, outputs, exact):
    """|exact - central difference| with steps 100 times smaller for the amplifications,
    inf for every other output: an amplification is a bound summed from norms |x| + |y|
    and |force| of the reactions, whose rate jumps where a component changes sign; a kink
    within the steps of 1e-4 spoils their difference (three_drivers at 24 random working
    points has one 1e-5 m of the jack's length away)."""
    bounds = np.array([o.endswith("amplification") for o in outputs])
    fine = _central(s, values, known, outputs, step=1e-6)
    return np.where(bounds, np.abs(exact - fine), np.inf)


def _driver(name):
    """The driver's name, effort and motion inputs: a crank's, a ram's or a cylinder's."""
    mechanism = mf.mechanism_of(name)
    if getattr(mechanism, "driver", "crank") == "crank":
        return "crank", "torque", "angle", "omega", "epsilon"
    q, rate, accel = (k.rpartition(".")[2] for k in mechanism.coordinate_names)
    return mechanism.driver_name, "force", q, rate, accel


# the monitor offers only its bearing loads: no effort, J or link motion to relate
@pytest.mark.parametrize("name", [n for n in mf.MECHANISM_FMUS if n != "monitor"])
def test_exact_identities(name):
    """J = d(effort)/d(q'') and dJ/dq = d(J)/dq, to round-off; every link angle moves
    with its velocity ratio, d(angle)/dq q' = omega, and omega is linear in q'."""
    driver, effort, q, rate, accel = _driver(name)
    s = _slave(name)
    inputs, outputs = _names(s)
    for k in (3, 11, 20):
        values = {n: float(s.get(n)) for n in inputs} | _state(name, k)
        out = dict(zip(outputs, _outputs(s, values, outputs), strict=True))

        def along(known, wanted):
            return np.array(s.directional_derivative(tuple(wanted), (f"{driver}.{known}",), [1.0]))

        (d_effort,) = along(accel, [f"{driver}.{effort}"])
        assert d_effort == pytest.approx(out[f"{driver}.J"], rel=1e-13)
        (d_j,) = along(q, [f"{driver}.J"])
        assert d_j == pytest.approx(
            out[f"{driver}.dJdq"], rel=1e-12, abs=1e-14 * out[f"{driver}.J"]
        )
        angles = [o for o in outputs if o.endswith(".angle")]
        omegas = [o[: -len("angle")] + "omega" for o in angles]
        if not angles:
            continue
        ratio = along(q, angles) * values[f"{driver}.{rate}"]
        scale = max(abs(values[f"{driver}.{rate}"]), *(abs(out[o]) for o in omegas))
        assert np.max(np.abs(ratio - [out[o] for o in omegas])) <= 1e-13 * scale
        d_omega = along(rate, omegas)
        linear = np.array([out[o] for o in omegas]) / values[f"{driver}.{rate}"]
        assert np.max(np.abs(d_omega - linear)) <= 1e-13 * np.max(np.abs(linear))
    s.close()


@pytest.mark.parametrize("name", SCENE_FMUS)
def test_zero_where_no_dependency_is_declared(name):
    """An output's rate along an input its ModelStructure entry does not list is exactly 0
    (a dependency the description leaves out would mislead an importer's solver)."""
    s = _slave(name)
    inputs, outputs = _names(s)
    values = {n: float(s.get(n)) for n in inputs} | _state(name, 7)
    _outputs(s, values, outputs)
    declared = {u.variable.name: {d.name for d in u.dependencies or []} for u in s.md.outputs}
    for known in inputs:
        rates = s.directional_derivative(tuple(outputs), (known,), [1.0])
        stray = [
            o for o, r in zip(outputs, rates, strict=True) if r != 0 and known not in declared[o]
        ]
        assert not stray, f"{name}: {stray} move with {known} but do not declare it"
    s.close()


def test_fmi3_gives_the_fmi2_rates():
    """The same generated derivative behind both FMI versions, to the bit; both model
    descriptions say so."""
    rates = []
    for version in (2, 3):
        s = _slave("shaper", version)
        flag = "providesDirectionalDerivative" + ("s" if version == 3 else "")
        description = Path(fmi_slave.unpacked(s.path)[1]) / "modelDescription.xml"
        assert f'{flag}="true"' in description.read_text(encoding="utf-8")
        inputs, outputs = _names(s)
        values = {n: float(s.get(n)) for n in inputs} | _state("shaper", 5)
        _outputs(s, values, outputs)
        rates.append(s.directional_derivative(tuple(outputs), tuple(inputs), [1.0] * len(inputs)))
        s.close()
    assert rates[0] == rates[1]


def test_no_rate_where_the_chain_cannot_close():
    """The lift's ram beyond reach: Discard, every rate NaN, the log names the dyad and
    the gap; back within reach, the rates return."""
    s = _slave("lift")
    inputs, outputs = _names(s)
    values = {n: float(s.get(n)) for n in inputs} | _state("lift", 4)
    _outputs(s, values, outputs)
    good = s.directional_derivative(tuple(outputs), ("ram.position",), [1.0])
    s.set(("ram.position",), [1.5])
    with pytest.raises(fmi_slave.SlaveError) as failure:
        s.directional_derivative(tuple(outputs), ("ram.position",), [1.0])
    assert failure.value.status == 2
    assert "cannot assemble" in failure.value.message and " m;" in failure.value.message
    _outputs(s, values, outputs)
    again = s.directional_derivative(tuple(outputs), ("ram.position",), [1.0])
    assert again == good and all(math.isfinite(r) for r in again)
    s.close()


@pytest.mark.parametrize("name", ["slider_crank", "dyad_rrt"])
def test_a_seed_that_is_not_finite_is_refused_and_changes_nothing(name):
    """Error naming the known; the outputs read afterwards are those before the call."""
    s = _slave(name)
    inputs, outputs = _names(s)
    before = s.get(tuple(outputs))
    for bad in (math.nan, math.inf):
        with pytest.raises(fmi_slave.SlaveError) as failure:
            s.directional_derivative(tuple(outputs), (inputs[0],), [bad])
        assert failure.value.status == 3
        assert f"the seed of known {inputs[0]} is not finite" in failure.value.message
        assert s.get(tuple(outputs)) == before
    s.close()


def _drivers(name):
    """Each driver of a scene with several drivers: (effort, effort at zero accelerations,
    coordinate, rate, acceleration), in the scene's order; and the names the FMU gives
    M(q)'s entries, row a, column b."""
    drivers = multidriver.load(name).drivers
    rows = [(d.effort, d.effort0, *d.coordinates) for d in drivers]
    entries = [[f"M.{a.name}.{b.name}" for b in drivers] for a in drivers]
    return rows, entries


def _inertia_errors(s, values, outputs, name):
    """At one state: (max |d(effort a)/d(q'' b) - M.a.b| / max |M|, the largest of
    |effort at q'' = 0 - h| and |effort - (M q'' + h)| / the largest effort or h)."""
    drivers, entries = _drivers(name)
    efforts = [d[0] for d in drivers]
    out = dict(zip(outputs, _outputs(s, values, outputs), strict=True))
    M = np.array([[out[e] for e in row] for row in entries])
    # column b: the efforts' rate along driver b's acceleration
    rates = np.array([s.directional_derivative(tuple(efforts), (d[4],), [1.0]) for d in drivers])
    m_error = np.max(np.abs(rates.T - M)) / np.max(np.abs(M))
    h = np.array([out[d[1]] for d in drivers])
    got = np.array([out[e] for e in efforts])
    accelerations = np.array([values[d[4]] for d in drivers])
    still = _outputs(s, values | {d[4]: 0.0 for d in drivers}, efforts)
    scale = max(np.max(np.abs(got)), np.max(np.abs(h)))
    h_error = max(np.max(np.abs(still - h)), np.max(np.abs(got - M @ accelerations - h)))
    return m_error, h_error / scale


@pytest.mark.parametrize("name", SEVERAL)
def test_the_inertia_matrix_is_the_efforts_rate_along_the_accelerations(name):
    """M.a.b = d(effort a)/d(q'' b) for every ordered pair, to 1e-13 of max |M|; the
    efforts with every acceleration zero are torque0 / force0 (h), and efforts = M q'' + h,
    to 1e-13 of the largest effort."""
    s = _slave(name)
    inputs, outputs = _names(s)
    worst_m = worst_h = 0.0
    for k in (3, 11, 20):
        values = {n: float(s.get(n)) for n in inputs} | _state(name, k)
        m_error, h_error = _inertia_errors(s, values, outputs, name)
        worst_m, worst_h = max(worst_m, m_error), max(worst_h, h_error)
    s.close()
    print(f"{name}: M against d(efforts)/d(q'') {worst_m:.1e} of max |M|, h {worst_h:.1e}")
    assert worst_m <= 1e-13
    assert worst_h <= 1e-13


@pytest.mark.parametrize("name", SEVERAL)
def test_every_angle_moves_with_the_drivers_rates(name):
    """omega = sum over drivers of d(angle)/dq_b q'_b (one directional derivative seeded
    with the rates along every coordinate), and omega is linear in the rates, to 1e-13 of
    the largest omega."""
    drivers, _ = _drivers(name)
    coordinates, rates = [d[2] for d in drivers], [d[3] for d in drivers]
    s = _slave(name)
    inputs, outputs = _names(s)
    angles = [o for o in outputs if o.endswith(".angle")]
    omegas = [o[: -len("angle")] + "omega" for o in angles]
    assert angles and all(o in outputs for o in omegas)
    for k in (3, 11, 20):
        values = {n: float(s.get(n)) for n in inputs} | _state(name, k)
        out = dict(zip(outputs, _outputs(s, values, outputs), strict=True))
        seed = [values[r] for r in rates]
        want = np.array([out[o] for o in omegas])
        scale = np.max(np.abs(want))
        along_q = np.array(s.directional_derivative(tuple(angles), tuple(coordinates), seed))
        assert np.max(np.abs(along_q - want)) <= 1e-13 * scale, (name, k)
        along_rates = np.array(s.directional_derivative(tuple(omegas), tuple(rates), seed))
        assert np.max(np.abs(along_rates - want)) <= 1e-13 * scale, (name, k)
    s.close()

"""Scenes with several drivers in the harness's NumPy reference
(scripts/dyadfmu/mechanisms/multidriver.py): the two-motor leg
(modelDescription/scenes/leg.toml, two cranks), tests/scenes/three_drivers.toml (a
crank, a cylinder and a ram), tests/scenes/carried_cylinders.toml (a cylinder pinned
at both ends to the boom another one raises), modelDescription/scenes/excavator.toml
(boom, stick and bucket cylinders, each carried by the link the one before turns) and
modelDescription/scenes/loader.toml (a wheel loader's Z-bar: the tilt cylinder's barrel
on the frame, its bellcrank on the lift arm).

- at random points of the working ranges (rates, accelerations and loads random too):
  every body balances to 1e-12, and a reaction or an effort moved by 1e-6 of the
  largest force is seen;
- M(q), solved for per unit acceleration, is symmetric and positive definite, equals M
  from the kinetic energy alone (T = q'^T M q' / 2, polarised), and the efforts change by
  M's columns when an acceleration changes (efforts = M q'' + h, h the efforts at zero
  accelerations);
- the energy balance along a smooth motion of all drivers: sum of effort x rate + the
  loads' power = d(T + V)/dt, the rate a five-point finite difference in time of the
  reference's own energies, to 1e-9 of the peak power;
- the kinematics' rates are the complex-step derivatives in time of its positions
  (every driver's body: angles, centres of mass and their velocities);
- the leg with its rear hip held still is a single-driver chain (chains.Chain, the
  rear knee a frame pivot): the front torque and the knees' reactions agree; likewise a
  carried cylinder with its carrier held still is a cylinder on the frame;
- a cylinder's O or A on the link it turns, or on no earlier driver's link, is refused;
- the scene's FMU, where built, against the reference at the same points
  (:mod:`dyadfmu.cosim.multidriver_fmus`).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import multidriver_fmus as mdf
from dyadfmu.mechanisms import chains
from dyadfmu.mechanisms import multidriver as md

NAMES = md.NAMES


@pytest.fixture(scope="module", params=NAMES)
def case(request):
    """(chain, kinematics at 60 random working points, its outputs)."""
    chain = md.load(request.param)
    kin = chain.working_points(60, seed=35)
    return chain, kin, chain.outputs(kin)


def _largest(values: dict, unit_of) -> dict:
    """The largest |value| per unit."""
    peaks: dict = {}
    for key, v in values.items():
        peaks[unit_of(key)] = max(peaks.get(unit_of(key), 0.0), float(np.max(np.abs(v))))
    return peaks


# ---------------------------------------------------------------------------
# the working ranges
# ---------------------------------------------------------------------------
def test_the_points_cover_the_working_ranges():
    """The leg's hips over -100..-20 and -160..-80 deg; the wheel all round, the jack
    over 1.85..2.02 m, the slide over 0.6..1.4 m; the lift over 1.1..1.4 m, the reach
    over 1.3..1.7 m; the excavator's and the loader's cylinders over the ranges of
    their headers; rates of both signs."""
    want = {
        "leg": {"front": (-100, -20), "rear": (-160, -80)},
        "three_drivers": {"wheel": (0, 360), "jack": (1.85, 2.02), "slide": (0.6, 1.4)},
        "carried_cylinders": {"lift": (1.1, 1.4), "reach": (1.3, 1.7)},
        "excavator": {"boom_cyl": (1.95, 3.35), "stick_cyl": (2.5, 3.8)}
        | {"bucket_cyl": (1.85, 2.85)},
        "loader": {"lift_cyl": (1.2, 2.45), "tilt_cyl": (1.2, 2.0)},
    }
    for name, ranges in want.items():
        chain = md.load(name)
        kin = chain.working_points(400, seed=1)
        for d in chain.drivers:
            q = kin[d.coordinates[0]] * (180 / math.pi if d.kind == "crank" else 1.0)
            low, high = ranges[d.name]
            span = high - low
            assert low <= q.min() < low + 0.05 * span and high - 0.05 * span < q.max() <= high
            rate = kin[d.coordinates[1]]
            assert rate.min() < 0 < rate.max(), d.name


# ---------------------------------------------------------------------------
# Newton-Euler
# ---------------------------------------------------------------------------
def test_every_body_balances(case):
    """Each body's forces and moments about its centre of mass sum to 1e-12 of the
    largest term, at every point."""
    chain, kin, out = case
    worst = chain.residuals(kin, out).max()
    print(f"{chain.name}: worst Newton-Euler residual {worst:.1e}")
    assert worst < 1e-12
    for effort in chain.effort_names:
        assert np.min(np.abs(out[effort])) < 0.5 * np.max(np.abs(out[effort]))  # not constant


def test_the_residuals_see_every_reaction_and_effort(case):
    """Each reaction component, each sliding pair's N and M and each effort, moved by
    1e-6 of the largest output, puts some body out of balance by more than 1e-7."""
    chain, kin, out = case
    names = chain.output_names()
    step = 1e-6 * max(np.max(np.abs(out[n])) for n in names)
    assert chain.residuals(kin, out).max() < 1e-12
    for name in names:
        moved = dict(out)
        moved[name] = out[name] + step
        assert chain.residuals(kin, moved).max() > 1e-7, name


# ---------------------------------------------------------------------------
# the inertia matrix
# ---------------------------------------------------------------------------
def test_the_inertia_matrix_is_symmetric_and_positive_definite(case):
    chain, kin, out = case
    n = len(chain.drivers)
    M = np.stack(
        [[out[f"M.{a}.{b}"] for b in chain.driver_names] for a in chain.driver_names], axis=-1
    ).transpose(1, 0, 2)
    assert M.shape == (len(kin["t"]), n, n)
    scale = np.abs(M).max(axis=(1, 2))
    asym = np.abs(M - M.transpose(0, 2, 1)).max(axis=(1, 2)) / scale
    eig = np.linalg.eigvalsh(0.5 * (M + M.transpose(0, 2, 1)))
    print(f"{chain.name}: M asymmetry {asym.max():.1e}, smallest eigenvalue {eig.min():.3g}")
    assert asym.max() < 1e-12
    assert np.all(eig > 1e-6 * scale[:, None])
    off = np.abs(M[:, 0, 1]) / np.sqrt(M[:, 0, 0] * M[:, 1, 1])
    assert off.max() > 1e-3  # the drivers are coupled: M is no diagonal


def test_the_inertia_matrix_is_that_of_the_kinetic_energy(case):
    """M from the kinetic energy alone (no Newton-Euler), polarised at unit rates."""
    chain, kin, out = case
    q = np.stack([kin[d.coordinates[0]] for d in chain.drivers], axis=-1)
    want = md.inertia_from_energy(chain, q)
    got = chain.inertia_matrix(kin)
    worst = (np.abs(got - want).max(axis=(1, 2)) / np.abs(want).max(axis=(1, 2))).max()
    print(f"{chain.name}: M (Newton-Euler) against M (kinetic energy): {worst:.1e}")
    assert worst < 1e-12


def test_the_efforts_are_m_times_the_accelerations_plus_h(case):
    """Each driver's acceleration raised by delta moves the efforts by delta times M's
    column; efforts = M q'' + h with h the outputs torque0 / force0."""
    chain, kin, out = case
    q, dq, ddq = chain._motion_of(kin)
    loads = {k: kin[k] for k in chain.load_inputs()}
    M = chain.inertia_matrix(kin)
    efforts = np.stack([out[e] for e in chain.effort_names], axis=-1)
    h = np.stack([out[d.effort0] for d in chain.drivers], axis=-1)
    scale = np.abs(efforts).max(axis=0)
    worst = 0.0
    for b in range(len(chain.drivers)):
        delta = np.zeros_like(ddq)
        delta[:, b] = 0.5 * (np.abs(ddq[:, b]).max() + 1.0)
        moved = chain.reference(chain.state(q, dq, ddq + delta, loads))
        change = np.stack([moved[e] for e in chain.effort_names], axis=-1) - efforts
        err = np.abs(change - M[:, :, b] * delta[:, b : b + 1]).max(axis=0) / scale
        worst = max(worst, err.max())
    balance = np.abs(efforts - np.einsum("nab,nb->na", M, ddq) - h).max(axis=0) / scale
    print(
        f"{chain.name}: finite differences in q'' against M {worst:.1e}, "
        f"M q'' + h {balance.max():.1e}"
    )
    assert worst < 1e-12 and balance.max() < 1e-12
    assert np.abs(efforts - h).max() > 1e-3 * scale.max()  # the inertia terms count


# ---------------------------------------------------------------------------
# energy
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_energy_balance_over_a_motion_of_all_drivers(name):
    """sum effort x rate + the loads' power = d(T + V)/dt along chains.toml's motion of
    every driver at once, to 1e-9 of the peak power; the kinetic energy's rate and the
    loads' power are no small part of it, and every driver works."""
    chain = md.load(name)
    balance = md.energy_balance(chain)
    kin, out, peak, residual = balance["kin"], balance["out"], balance["peak"], balance["residual"]
    loads = balance["loads"]
    print(f"{name}: energy balance, worst residual {residual:.1e} of the peak power {peak:.4g} W")
    assert residual < 1e-9
    assert np.max(np.abs(loads)) > 0.05 * peak
    kinetic = np.gradient(chain.kinetic_energy(kin), balance["t"])
    assert np.max(np.abs(kinetic)) > 1e-3 * peak  # the leg is light: 0.4 %
    for d in chain.drivers:
        own = np.asarray(out[d.effort]) * kin[d.coordinates[1]]
        assert np.max(np.abs(own)) > 0.05 * peak, d.name


# ---------------------------------------------------------------------------
# the kinematics
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_the_rates_are_the_derivatives_of_the_positions(name):
    """A complex step in time of the positions along chains.toml's motion gives the
    velocities, of the velocities the accelerations, to 1e-12 of each one's peak: every
    body's angle and centre of mass (a carried cylinder's link, barrel and rod move with
    their carrier)."""
    chain = md.load(name)
    motion = chain.motion()
    t = (np.arange(48) + 0.3) * motion.duration / 48
    h = 1e-20 * motion.duration
    kin, step = chain.kinematics(t, motion), chain.kinematics(t + 1j * h, motion)
    pairs = []
    for b in chain.bodies:
        pairs += [(f"S_{b}", f"v_S_{b}"), (f"v_S_{b}", f"a_S_{b}")]
        if b not in [d.link for d in chain.drivers if d.kind == "ram"]:  # a ram never turns
            pairs += [(f"{b}.angle", f"{b}.omega"), (f"{b}.omega", f"{b}.epsilon")]
    for position, rate in pairs:
        got, want = np.imag(step[position]) / h, np.real(kin[rate])
        peak = np.max(np.abs(want))
        assert peak > 0, rate
        assert np.max(np.abs(got - want)) < 1e-12 * peak, (name, rate)


# ---------------------------------------------------------------------------
# the single-driver reference
# ---------------------------------------------------------------------------
def _leg_with_rear_held(angle: float) -> chains.Chain:
    """The leg as a single-driver chain: the front crank, the rear knee a frame pivot
    where the rear crank held at ``angle`` puts it."""
    leg = md.load("leg")
    scene = copy.deepcopy(leg.scene)
    rear = next(c for c in scene["crank"] if c["name"] == "rear")
    scene["crank"] = next(c for c in scene["crank"] if c["name"] == "front")
    knee = np.asarray(rear["at"]) + rear["length"] * np.array([math.cos(angle), math.sin(angle)])
    scene["dyad"][0]["p"] = {"link": "frame", "at": knee.tolist()}
    table = copy.deepcopy(leg.data)
    table["motion"] = {"omega": table["motion"]["omega"]}
    return chains.Chain("leg", scene, table)


def test_the_leg_with_one_hip_held_is_a_single_driver_chain():
    """Rear hip still (rate and acceleration 0): the front torque and the knees'
    reactions of the several-driver reference equal those of chains.Chain to 1e-12."""
    angle = -2.0
    single = _leg_with_rear_held(angle)
    leg = md.load("leg")
    rng = np.random.default_rng(7)
    q = rng.uniform(math.radians(-100), math.radians(-20), 40)
    dq, ddq = rng.uniform(-4, 4, 40), rng.uniform(-40, 40, 40)
    foot = {"foot.force.x": rng.uniform(-10, 10, 40), "foot.force.y": rng.uniform(0, 60, 40)}
    kin = leg.state({"front": q, "rear": angle + 0 * q}, {"front": dq}, {"front": ddq}, foot)
    want = single._solve(np.zeros(40), q, dq, ddq)
    want.update(foot)
    ref, got = single.reference(want), leg.reference(kin)
    compared = ["front.torque", "front.R_O.x", "front.R_O.y"]
    compared += [f"knees.R_{tag}.{c}" for tag in ("mk", "mn") for c in "xy"]
    scale = max(np.max(np.abs(ref[k])) for k in compared if k != "front.torque")
    for key in compared:
        peak = np.max(np.abs(ref[key])) if key == "front.torque" else scale
        assert np.max(np.abs(got[key] - ref[key])) < 1e-12 * peak, key
    # the rear knee's reaction on the shank is the frame pivot's
    for c in "xy":
        assert np.max(np.abs(got[f"knees.R_np.{c}"] - ref[f"knees.R_np.{c}"])) < 1e-12 * scale


def _reach_on_a_held_boom(carried: md.MultiChain, length: float) -> chains.Chain:
    """carried_cylinders' reach cylinder as a single-driver chain: its O and A fixed on
    the frame where the boom held at the lift's ``length`` puts them."""
    kin = carried.state({"lift": length, "reach": 1.5})
    scene = copy.deepcopy(carried.scene)
    reach = next(c for c in scene["cylinder"] if c["name"] == "reach")
    reach["at"] = np.real(kin["arm.O"][0]).tolist()
    reach["base"] = np.real(kin["reach.A"][0]).tolist()
    scene["cylinder"] = reach
    table = copy.deepcopy(carried.data)
    del table["drivers"]
    table["motion"] = {"s0": 1.35, "stroke": 0.3, "omega": 1.0, "variation": 0.0}
    return chains.Chain("carried_cylinders", scene, table)


def test_a_carried_cylinder_on_a_held_carrier_is_a_cylinder_on_the_frame():
    """Boom held (the lift's rate and acceleration 0): the reach cylinder's force, its
    reactions at A, B and O, N and M equal those of chains.Chain's frame cylinder to
    1e-12; and the boom receives minus R_O and minus R_A: the lift's force changes with
    the payload."""
    carried = md.load("carried_cylinders")
    length = 1.25
    single = _reach_on_a_held_boom(carried, length)
    rng = np.random.default_rng(11)
    s, ds, dds = rng.uniform(1.3, 1.7, 40), rng.uniform(-0.4, 0.4, 40), rng.uniform(-1, 1, 40)
    payload = {"payload.force.x": rng.uniform(-500, 500, 40)}
    payload["payload.force.y"] = rng.uniform(-3000, 0, 40)
    kin = carried.state({"lift": length + 0 * s, "reach": s}, {"reach": ds}, {"reach": dds})
    kin.update(payload)
    want = single._solve(np.zeros(40), s, ds, dds)
    want.update(payload)
    ref, got = single.reference(want), carried.reference(kin)
    forces = [f"{k}.{c}" for k in ("reach.R_A", "reach.R_B", "arm.R_O") for c in "xy"]
    forces += ["reach.force", "reach.N"]
    scale = max(np.max(np.abs(ref[k])) for k in forces)
    for key in forces:
        assert np.max(np.abs(got[key] - ref[key])) < 1e-12 * scale, key
    assert np.max(np.abs(got["reach.M"] - ref["reach.M"])) < 1e-12 * np.max(np.abs(ref["reach.M"]))
    heavier = dict(kin, **{"payload.force.y": kin["payload.force.y"] - 1000.0})
    assert np.all(carried.reference(heavier)["lift.force"] > got["lift.force"] + 100.0)


@pytest.mark.parametrize(
    ("key", "spec", "match"),
    [
        ("at", {"link": "arm", "at": [0.0, 0.0]}, "not on the link it turns"),
        ("base", {"link": "arm", "at": [0.5, 0.0]}, "not on the link it turns"),
        ("base", {"link": "mast", "at": [0.5, 0.0]}, "neither the frame nor an earlier"),
        ("at", {"link": "boom", "at": [3.0, 0.0], "guide": 0.0}, "not a key"),
    ],
)
def test_a_cylinder_on_its_own_or_no_earlier_link_is_refused(key, spec, match):
    carried = md.load("carried_cylinders")
    scene = copy.deepcopy(carried.scene)
    scene["cylinder"][1][key] = spec
    with pytest.raises(ValueError, match=match):
        md.MultiChain("carried_cylinders", scene, carried.data)


def test_a_cylinder_on_a_later_cylinders_link_is_refused():
    """The lift's base on the arm, which the reach cylinder (listed after it) turns."""
    carried = md.load("carried_cylinders")
    scene = copy.deepcopy(carried.scene)
    scene["cylinder"][0]["base"] = {"link": "arm", "at": [0.5, 0.0]}
    with pytest.raises(ValueError, match="neither the frame nor an earlier driver's link"):
        md.MultiChain("carried_cylinders", scene, carried.data)


def test_repeated_driver_names_are_refused():
    leg = md.load("leg")
    scene = copy.deepcopy(leg.scene)
    scene["crank"][1]["name"] = "front"
    with pytest.raises(ValueError, match="driver names must differ|repeated"):
        md.MultiChain("leg", scene, leg.data)


def test_one_driver_is_no_scene_of_several():
    leg = md.load("leg")
    scene = copy.deepcopy(leg.scene)
    scene["crank"] = scene["crank"][:1]
    with pytest.raises(ValueError, match="two or more"):
        md.MultiChain("leg", scene, leg.data)


# ---------------------------------------------------------------------------
# the FMUs
# ---------------------------------------------------------------------------
def _cylinder_outputs(cyl: str, link: str) -> list:
    """A cylinder's outputs of the spec."""
    names = [f"{cyl}.force", f"{cyl}.force0", f"{cyl}.N", f"{cyl}.M", f"{cyl}.conditioning"]
    names += [f"{k}.{c}" for k in (f"{cyl}.R_A", f"{cyl}.R_B", f"{link}.R_O") for c in "xy"]
    names += [f"{g}.{k}" for g in (link, cyl) for k in ("angle", "omega", "epsilon")]
    return names + [f"{cyl}.B.position.x", f"{cyl}.B.position.y"]


def _inertia_outputs(*drivers: str) -> list:
    return [f"M.{a}.{b}" for a in drivers for b in drivers]


SPEC_OUTPUTS = {
    "leg": ["front.torque", "front.R_O.x", "front.R_O.y", "front.torque0"]
    + ["rear.torque", "rear.R_O.x", "rear.R_O.y", "rear.torque0"]
    + [f"M.{a}.{b}" for a in ("front", "rear") for b in ("front", "rear")],
    "three_drivers": ["wheel.torque", "wheel.R_O.x", "wheel.R_O.y", "wheel.torque0"]
    + ["slide.force", "slide.N", "slide.M", "slide.force0"]
    + ["jack.force", "jack.R_A.x", "jack.R_A.y", "jack.R_B.x", "jack.R_B.y"]
    + ["arm.R_O.x", "arm.R_O.y", "jack.N", "jack.M", "jack.force0", "jack.conditioning"]
    + [f"{g}.{k}" for g in ("arm", "jack") for k in ("angle", "omega", "epsilon")]
    + ["jack.B.position.x", "jack.B.position.y"]
    + [f"M.{a}.{b}" for a in ("wheel", "slide", "jack") for b in ("wheel", "slide", "jack")],
    "carried_cylinders": _cylinder_outputs("lift", "boom")
    + _cylinder_outputs("reach", "arm")
    + _inertia_outputs("lift", "reach"),
    "excavator": _cylinder_outputs("boom_cyl", "boom")
    + _cylinder_outputs("stick_cyl", "stick")
    + _cylinder_outputs("bucket_cyl", "rocker")
    + _inertia_outputs("boom_cyl", "stick_cyl", "bucket_cyl"),
    "loader": _cylinder_outputs("lift_cyl", "lift_arm")
    + _cylinder_outputs("tilt_cyl", "bellcrank")
    + _inertia_outputs("lift_cyl", "tilt_cyl"),
}


@pytest.mark.parametrize("name", NAMES)
def test_the_outputs_are_named_as_the_fmus_name_them(name):
    """The drivers' outputs of the spec, the dyads' reactions, points, links' motion and
    conditionings; no J, no dJdq, no vector of a driver's sliding pair."""
    chain = md.load(name)
    out = chain.fmu_outputs(chain.working_points(3, seed=0))
    drivers = {n for d in chain.drivers for n in (d.name, d.link)}
    own = {k for k in out if k.split(".")[0] in drivers or k.startswith("M.")}
    assert own == set(SPEC_OUTPUTS[name])
    for e in chain.plan:
        for tag in ("mk", "mn", "np"):
            assert {f"{e['name']}.R_{tag}.x", f"{e['name']}.R_{tag}.y"} <= set(out)
        for p in ("D_m", "E", "D_n"):
            assert f"{e['name']}.{p}.position.x" in out
        assert f"{e['name']}.conditioning" in out
        for g in (e["m"], e["n"]):
            assert {f"{g}.angle", f"{g}.omega", f"{g}.epsilon"} <= set(out)
    assert all(np.shape(v) == (3,) for v in out.values())


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("version", (2, 3))
def test_the_fmu_agrees_with_the_reference(name, version):
    """Every output of the reference within 1e-12 of its unit's peak (kinematic ones of
    their own peak) at random working points."""
    path = paths.built_fmu(name, version, None, how="scripts/run-tests")
    result = mdf.compare(name, version, count=40, seed=3, path=path)
    print(mdf.summary(result))
    assert not result.missing, f"outputs the FMU lacks: {result.missing}"
    assert result.worst[1] < 1e-12, mdf.summary(result)


def _periodic_motion(chain: md.MultiChain, count: int) -> tuple[np.ndarray, dict, dict]:
    """Each driver swinging over most of its working range with its own whole number of
    cycles in one period 2 pi: the times, the FMU's motion inputs, each driver's rate."""
    t = np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
    inputs, rates = {}, {}
    for k, d in enumerate(chain.drivers):
        low, high = chain.ranges[d.name]
        mid, amp, cycles, phase = 0.5 * (low + high), 0.45 * (high - low), k + 1, 0.7 * k
        arg = cycles * t + phase
        position, rate, accel = d.coordinates
        inputs[position] = mid + amp * np.sin(arg)
        inputs[rate] = rates[d.name] = amp * cycles * np.cos(arg)
        inputs[accel] = -amp * cycles**2 * np.sin(arg)
    inputs.update({n: np.zeros(count) for n in chain.load_inputs()})
    return t, inputs, rates


@pytest.mark.parametrize("name", NAMES)
def test_the_drivers_power_meets_the_fmus_own_energies(name):
    """The energy balance from the FMU's outputs alone, no reference kinematics: with the
    loads off and every driver along a periodic motion over its working range, the
    drivers' power sum effort q' equals dT/dt + G(q) . q', where T = q'^T M(q) q' / 2 from
    the FMU's M and G, the weight's share of the efforts, is the FMU's efforts with every
    rate and acceleration zero; dT/dt by spectral differentiation over the period. Within
    1e-9 of the peak power."""
    chain = md.load(name)
    path = paths.built_fmu(name, 2, None, how="scripts/run-tests")
    t, inputs, rates = _periodic_motion(chain, 512)
    drivers = chain.driver_names
    entries = [f"M.{a}.{b}" for a in drivers for b in drivers]
    moving = mdf.evaluate(path, inputs, chain.effort_names + entries)
    at_rest = dict(inputs)
    for d in chain.drivers:
        at_rest[d.coordinates[1]] = at_rest[d.coordinates[2]] = np.zeros(len(t))
    weight = mdf.evaluate(path, at_rest, chain.effort_names)
    qd = np.array([rates[a] for a in drivers])
    mass = np.array([[moving[f"M.{a}.{b}"] for b in drivers] for a in drivers])
    kinetic = 0.5 * np.einsum("at,abt,bt->t", qd, mass, qd)
    spectrum = np.fft.fftfreq(len(t), d=t[1] - t[0]) * 2.0 * math.pi
    kinetic_rate = np.real(np.fft.ifft(1j * spectrum * np.fft.fft(kinetic)))
    power = sum(moving[e] * qd[k] for k, e in enumerate(chain.effort_names))
    gravity = sum(weight[e] * qd[k] for k, e in enumerate(chain.effort_names))
    residual = np.max(np.abs(power - kinetic_rate - gravity)) / np.max(np.abs(power))
    print(f"{name}: energy balance {residual:.1e} of the peak power {np.max(np.abs(power)):.4g}")
    assert residual < 1e-9

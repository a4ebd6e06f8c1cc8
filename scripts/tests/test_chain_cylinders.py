"""The hydraulic cylinder between two pins ([cylinder]) in the harness's NumPy reference of
the chains (scripts/dyadfmu/mechanisms/chains.py, chains.toml): the tipper
(modelDescription/scenes/tipper.toml, a dump body and its tailgate dyad) and the test
scenes cylinder_arm (the cylinder alone) and cylinder_boom (with an RRR dyad).

- the mechanism FMUs, FMI 2 and 3 (cylinder_arm on both branches of its triangle), over
  two strokes out and back at a varying speed with the payload swinging: every output
  within 1e-12 of its peak (kinematic) or of its unit's peak (the others), status 0 on the
  whole working stroke, where the inertia terms (J s'' and dJ/dq s'^2 / 2) move the axial
  force by far more than that;
- the geometry of chains.py's closure written out (|AB| = s, |OB| = |pin|, B turned with
  the link, B on the branch's side of O -> A, the conditioning as |sin| of the angle
  between OB and AB) and its rates against complex-step derivatives in time of its
  positions (the link's and the axis's angles, B, every centre of mass);
- the energy balance with the energies written out here from the scene's numbers (the
  barrel's centre of mass at A + com u, the rod's at B - com u, the link's and the dyads'
  links'): the cylinder's power force x ds/dt + the loads' power = d(T + V)/dt, the
  derivative a complex step in time, to 1e-9 of the peak power;
- the Newton-Euler residuals of every body, each output seen when moved;
- malformed [cylinder] tables and strokes beyond the triangle's reach refused, named.
"""

from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pytest
from dyadfmu.cosim import mechanism_fmus as mf
from dyadfmu.mechanisms import chains

NAMES = chains.CYLINDER_NAMES
KINDS = ("constant", "varying")


def scene(name):
    with open(chains.scene_path(name), "rb") as f:
        return tomllib.load(f)


def harness(name):
    return chains.default_data()[name]


def unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def rot90(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def rotate(theta, v):
    """The vectors v (..., 2) turned by the angles theta (...)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def square(v):
    """v . v without conjugation, so that a complex step passes through."""
    return v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1]


def times(motion, count):
    """Samples over the motion, off its turning points."""
    return (np.arange(count) + 0.41) * motion.duration / count


# ---------------------------------------------------------------------------
# the FMUs against chains.py
# ---------------------------------------------------------------------------
CASES = [
    (name, version, branch)
    for name in NAMES
    for version in (2, 3)
    for branch in ((1, -1) if name in mf.BRANCHES else (1,))
]


@pytest.mark.parametrize(("name", "version", "branch"), CASES)
def test_the_fmus_agree_with_chains_over_the_stroke(name, version, branch):
    """Two strokes out and back: each kinematic output within 1e-12 of its peak, every
    other within 1e-12 of its unit's peak, status 0 throughout; the lengths run over the
    whole working stroke of chains.toml, and the inertia terms of the axial force exceed
    1e-4 of its peak, so that an error in them would be seen."""
    _, series, _ = mf.setup(name, version, branch, "varying", revolutions=2.0, steps=180)
    cyl = scene(name)["cylinder"]["name"]
    stroke = harness(name)["motion"]
    s, ds, dds = (series.inputs[f"{cyl}.{k}"] for k in ("length", "velocity", "acceleration"))
    assert np.min(s) == pytest.approx(stroke["s0"], rel=1e-12)
    assert np.max(s) == pytest.approx(stroke["s0"] + stroke["stroke"], rel=1e-12)
    force = series.outputs[f"{cyl}.force"]
    peak = np.max(np.abs(force))
    assert np.max(np.abs(series.outputs[f"{cyl}.J"] * dds)) > 1e-4 * peak
    assert np.max(np.abs(0.5 * series.outputs[f"{cyl}.dJdq"] * ds * ds)) > 1e-6 * peak
    result = mf.run(name, version, branch, "varying", revolutions=2.0, steps=180)
    print(mf.summary(result))
    assert result.statuses == {0}
    assert result.worst_of(True)[1] < 1e-12, mf.summary(result)
    assert result.worst_of(False)[1] < 1e-12, mf.summary(result)
    for out in (f"{cyl}.force", f"{cyl}.R_A.x", f"{cyl}.N", f"{cyl}.M", f"{cyl}.J"):
        assert np.max(np.abs(result.reference[out])) > 0, out  # compared, not zero


def test_the_branches_of_the_triangle_differ():
    """cylinder_arm on its other branch: B mirrored in the line O -> A, so the arm's
    angle and the axial force differ from branch +1 (the comparison above sees the FMU's
    tunable branch, not the same motion twice)."""
    up, down = (mf.mechanism_of("cylinder_arm", b) for b in (1, -1))
    motion = up.motion("varying", 1.0)
    t = times(motion, 40)
    a, b = up.kinematics(t, motion), down.kinematics(t, motion)
    assert np.min(np.abs(a["arm.angle"] - b["arm.angle"])) > 0.1
    assert np.all(cross(a["A"] - a["O"], a["hoist.B"] - a["O"]) > 0)
    assert np.all(cross(b["A"] - b["O"], b["hoist.B"] - b["O"]) < 0)


# ---------------------------------------------------------------------------
# kinematics
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_the_triangle_closes(name):
    """B from chains.py: |AB| = s, |OB| = |pin|, B = O + R(theta) pin, on the branch's
    side of O -> A; u = (B - A) / s at the axis's angle; the conditioning |sin| of the
    angle between OB and AB."""
    chain = chains.load(name)
    cyl = scene(name)["cylinder"]
    c, link = cyl["name"], cyl["link"]
    motion = chain.motion("varying", 1.0)
    kin = chain.kinematics(times(motion, 64), motion)
    O, A, B = np.asarray(cyl["at"]), np.asarray(cyl["base"]), kin[f"{c}.B"]  # noqa: E741
    s = kin[f"{c}.length"]
    pin = np.broadcast_to(np.asarray(cyl["pin"], dtype=float), B.shape)
    assert np.max(np.abs(np.hypot(*(B - A).T) - s)) < 1e-14 * np.max(s)
    assert np.max(np.abs(np.hypot(*(B - O).T) - math.hypot(*cyl["pin"]))) < 1e-14
    assert np.max(np.abs(O + rotate(kin[f"{link}.angle"], pin) - B)) < 1e-14 * np.max(s)
    assert np.all(cyl["branch"] * cross(A - O, B - O) > 0)
    u = (B - A) / s[:, None]
    assert np.max(np.abs(unit(kin[f"{c}.angle"]) - u)) < 1e-14
    ob = (B - O) / math.hypot(*cyl["pin"])
    assert np.max(np.abs(kin[f"{c}.conditioning"] - np.abs(cross(ob, u)))) < 1e-14
    assert np.min(kin[f"{c}.conditioning"]) > 0.4  # clear of the toggles


def _bodies(name, kin):
    """(mass, inertia, centre of mass, angle) of every moving body, written out from the
    scene's numbers and chains.py's positions (complex where kin is)."""
    sc = scene(name)
    cyl = sc["cylinder"]
    c, link = cyl["name"], cyl["link"]
    u = unit(kin[f"{c}.angle"])
    theta = kin[f"{link}.angle"]
    com = np.broadcast_to(np.asarray(cyl["com"], dtype=float), u.shape)
    out = {link: (cyl["mass"], cyl["inertia"], np.asarray(cyl["at"]) + rotate(theta, com), theta)}
    barrel, rod = cyl["barrel"], cyl["rod"]
    S_barrel = np.asarray(cyl["base"]) + barrel["com"] * u
    out[f"{c}.barrel"] = (barrel["mass"], barrel["inertia"], S_barrel, kin[f"{c}.angle"])
    S_rod = kin[f"{c}.B"] - rod["com"] * u
    out[f"{c}.rod"] = (rod["mass"], rod["inertia"], S_rod, kin[f"{c}.angle"])
    links = {g["name"]: g for g in sc.get("link", [])}
    for d in sc.get("dyad", []):
        for side, pair in (("m", "D_m"), ("n", "D_n")):
            g = links[d[side]]
            local = np.broadcast_to(np.asarray(g["com"], dtype=float), u.shape)
            angle = kin[f"{g['name']}.angle"]
            out[g["name"]] = (
                g["mass"],
                g["inertia"],
                kin[f"{d['name']}.{pair}"] + rotate(angle, local),
                angle,
            )
    return out


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kind", KINDS)
def test_rates_are_the_derivatives_of_the_positions(name, kind):
    """A complex step in time of chains.py's positions (the link's and the axis's
    angles, B, every centre of mass as written out here) gives its velocities; of its
    velocities, its accelerations: to 1e-12 of each one's peak."""
    chain = chains.load(name)
    c, link = scene(name)["cylinder"]["name"], scene(name)["cylinder"]["link"]
    motion = chain.motion(kind, 1.0)
    t = times(motion, 64)
    h = 1e-20 * motion.duration
    kin, step = chain.kinematics(t, motion), chain.kinematics(t + 1j * h, motion)

    def rate(key):
        return np.imag(step[key]) / h

    pairs = [
        (rate(f"{link}.angle"), kin[f"{link}.omega"], "link omega"),
        (rate(f"{link}.omega"), kin[f"{link}.epsilon"], "link epsilon"),
        (rate(f"{c}.angle"), kin[f"{c}.omega"], "axis omega"),
        (rate(f"{c}.omega"), kin[f"{c}.epsilon"], "axis epsilon"),
        (rate(f"{c}.B"), kin["v_B"], "v_B"),
        (rate("v_B"), kin["a_B"], "a_B"),
        (rate(f"{c}.length"), kin[f"{c}.velocity"], "s'"),
    ]
    written = _bodies(name, step)
    for body, (_, _, S, _) in written.items():
        pairs.append((np.imag(S) / h, kin[f"v_S_{body}"], f"v_S {body}"))
        pairs.append((np.real(S), kin[f"S_{body}"], f"S {body}"))
        pairs.append((rate(f"v_S_{body}"), kin[f"a_S_{body}"], f"a_S {body}"))
    for got, want, what in pairs:
        peak = np.max(np.abs(want))
        assert peak > 0, what
        assert np.max(np.abs(got - want)) < 1e-12 * peak, what


# ---------------------------------------------------------------------------
# energy
# ---------------------------------------------------------------------------
def _energy(name, kin):
    """Kinetic plus potential energy (J) of every moving body, from the scene's numbers,
    chains.py's positions and its centres' velocities (complex where kin is)."""
    sc = scene(name)
    g = np.array([sc["gravity"]["x"], sc["gravity"]["y"]])
    total = 0.0
    for body, (mass, inertia, S, _) in _bodies(name, kin).items():
        angle_rate = kin[f"{body}.omega"]
        total = total + 0.5 * mass * square(kin[f"v_S_{body}"]) + 0.5 * inertia * angle_rate**2
        total = total - mass * (S @ g)
    return total


def _load_power(name, kin):
    """The [[load]]s' power (W): F . v_P, P = O + R(theta) at on the link (or on a dyad's
    link, from its pin D), F global as the scene's loads are."""
    sc = scene(name)
    cyl = sc["cylinder"]
    total = 0.0
    for row in sc.get("load", []):
        assert row["link"] == cyl["link"] and row.get("components", "global") == "global"
        theta, omega = kin[f"{cyl['link']}.angle"], kin[f"{cyl['link']}.omega"]
        arm = rotate(theta, np.broadcast_to(np.asarray(row["at"], dtype=float), theta.shape + (2,)))
        v_p = omega[:, None] * rot90(arm)
        f = np.stack([kin[f"{row['name']}.force.x"], kin[f"{row['name']}.force.y"]], axis=-1)
        total = total + np.sum(f * v_p, axis=-1)
    return total


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kind", KINDS)
def test_energy_balance(name, kind):
    """force x ds/dt + the loads' power = d(T + V)/dt, T and V written out here, the rate a
    complex step in time: to 1e-9 of the peak power; the kinetic energy's rate and the
    loads' power are no small part of it. chains.py's own energies agree with these."""
    chain = chains.load(name)
    c = scene(name)["cylinder"]["name"]
    motion = chain.motion(kind, 1.0)
    t = times(motion, 120)
    kin = chain.kinematics(t, motion)
    out = chain.reference(kin)
    h = 1e-20 * motion.duration
    step = chain.kinematics(t + 1j * h, motion)
    rate = np.imag(_energy(name, step)) / h
    power = out[f"{c}.force"] * kin[f"{c}.velocity"]
    assert np.array_equal(power, chain.driver_power(kin, out))
    loads = _load_power(name, kin)
    peak = np.max(np.abs(power))
    residual = np.max(np.abs(power + loads - rate))
    print(f"{name} {kind}: energy balance, worst residual {residual / peak:.1e} of the peak power")
    assert residual < 1e-9 * peak
    assert np.max(np.abs(loads)) > 0.1 * peak
    kinetic = np.imag(chain.kinetic_energy(step)) / h
    assert np.max(np.abs(kinetic)) > 1e-3 * peak
    mine = _energy(name, kin)
    theirs = chain.kinetic_energy(kin) + chain.potential_energy(kin)
    assert np.max(np.abs(mine - theirs)) < 1e-12 * np.max(np.abs(mine))
    assert np.max(np.abs(chain.load_power(kin) - loads)) < 1e-12 * peak


# ---------------------------------------------------------------------------
# Newton-Euler
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_residuals_see_every_output(name):
    """Every body balances to 1e-12; each output moved by 1e-4 of the largest force (or
    moment) is seen."""
    chain = chains.load(name)
    motion = chain.motion("varying", 1.0)
    kin = chain.kinematics(times(motion, 30), motion)
    out = chain.reference(kin)
    assert set(out) == set(chain.output_names())
    assert np.max(chain.residuals(kin, out)) < 1e-12

    def is_moment(key):
        return key.endswith(".M") or ".M_" in key

    forces = max(np.max(np.abs(v)) for k, v in out.items() if not is_moment(k))
    moments = max(np.max(np.abs(v)) for k, v in out.items() if is_moment(k))
    for key in out:
        bad = dict(out)
        bad[key] = out[key] + 1e-4 * (moments if is_moment(key) else forces)
        assert np.min(chain.residuals(kin, bad)) > 1e-7, key


# ---------------------------------------------------------------------------
# refusals
# ---------------------------------------------------------------------------
def _set(**changes):
    def edit(sc, table):
        sc["cylinder"].update(changes)

    return edit


def _part(part, **changes):
    def edit(sc, table):
        sc["cylinder"][part] = {**sc["cylinder"][part], **changes}

    return edit


def _motion(**changes):
    def edit(sc, table):
        table["motion"].update(changes)

    return edit


def _two_drivers(sc, table):
    sc["crank"] = {"length": 0.1, "com": [0.0, 0.0], "mass": 1.0, "inertia": 0.1}


BAD = {
    "two drivers": (_two_drivers, "expected one table [crank], [ram] or [cylinder]"),
    "no link": (_set(link=None), "cylinder.link: expected the name of the link"),
    "pin at O": (_set(pin=[0.0, 0.0]), "cylinder.pin: B must be off the pivot O"),
    "base at O": (_set(base=[0.0, 1.0]), "cylinder.base: A must be off the pivot O"),
    "branch": (_set(branch=0), "cylinder.branch: expected +1 or -1"),
    "bad pin": (_set(pin=[1.2, "x"]), "cylinder.pin: expected two numbers"),
    "no mass": (_set(mass=None), "cylinder_arm.cylinder: missing key 'mass'"),
    "barrel not a table": (_set(barrel=3.0), "cylinder.barrel: expected a table"),
    "barrel key": (_part("barrel", length=1.0), "cylinder.barrel.length: not a key"),
    "rod mass": (_part("rod", mass=-1.0), "cylinder.rod.mass: must be >= 0"),
    "too short": (_motion(s0=0.2), "cylinder hoist: the triangle O, A, B does not close"),
    "too long": (_motion(stroke=1.7), "it closes for 0.2166 < s < 2.217 m"),
    "no length": (_motion(s0=0.0), "cylinder_arm.motion.s0: must be > 0"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_malformed_cylinders_are_refused(case):
    """Each malformed [cylinder] table or stroke refused, the key or the reach named."""
    edit, words = BAD[case]
    sc, table = scene("cylinder_arm"), copy.deepcopy(harness("cylinder_arm"))
    edit(sc, table)
    sc["cylinder"] = {k: v for k, v in sc["cylinder"].items() if v is not None}
    with pytest.raises(ValueError) as refused:
        chains.Chain("cylinder_arm", sc, table)
    assert words in str(refused.value)

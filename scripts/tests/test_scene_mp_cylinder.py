"""The mpmath reference of a mechanism driven by a hydraulic cylinder (scene_mp with a
[cylinder]), proved by other means than its own formulas, on
modelDescription/scenes/tipper.toml (a dump body tipped by a cylinder, a tailgate on an
RRR dyad hanging on the body, a payload force on the body):

(a) energy: along a quick motion of the cylinder, its power F s' plus the power of
    gravity and of the payload equals d/dt of the kinetic energy of every body (built
    from the reference's angles, rates and pair points alone), the derivative a 13-point
    central difference at 50 digits, to 1e-20 (2e-29 found); the same on a weightless
    copy, where the force only moves the masses; every angle's and pin B's difference
    quotient is its rate, every rate's its acceleration; the frame's reactions (R_A, R_O,
    the opener's pin) balance the whole mechanism, and R_O, R_B and the tailgate's hinge
    the link, with the accelerations from difference quotients of the velocities;
(b) statics: with inertia off, the axial force balances gravity and the payload,
    F = dV/ds of their potential V (the generalized force on the cylinder is -dV/ds);
(c) J and force0: the kinetic energy is J s'^2 / 2; the force is affine in s'' with
    slope J and force0 at s'' = 0; force0 grows with s'^2 by dJdq / 2; dJdq is the
    difference quotient of J; at rest the force is the static one of (b);
(d) a massless barrel and rod: R_A = R_B = F u, N = M = 0;
(e) statuses: cannot assemble on either side of the triangle's reach, the cylinder named;
    singular exactly at the toggle of a scene whose reach is a binary number, ok on both
    branches just past it with B on each branch's side;
and the reader: a dyad on "body" alone sits at pin B; what the [cylinder] spec does not
allow is refused, naming the field; the stroke and conditioning tipper.toml states.

The motion is given by the velocity as a function of the length, s' = v(s), so that
s'' = v dv/ds: at lengths on a grid of step 2^-12 m, v and s'' are binary numbers the
FMU's float inputs carry exactly, and d/dt = v d/ds.
"""

from __future__ import annotations

import math
import tomllib
from fractions import Fraction
from functools import cache

import mpmath
import pytest
from dyadfmu import paths
from dyadfmu.reference import scene_mp
from mpmath import mpf

TIPPER = paths.SCENES_DIR / "tipper.toml"
DPS = 50
STEP = 2.0**-12  # m, the grid of lengths
HALF = 6  # the central differences' half width (13 points, error of order STEP^12)
START, END = 1.25, 4.75  # m, the stroke of tipper.toml
#: lengths (m) on the grid where the balances are checked, over the stroke
INSTANTS = tuple(START + STEP * k for k in (160, 2400, 5200, 8000, 10800, 13200))
PAYLOAD = (1500.0, -98100.0)  # N: a push and the weight of 10 t


def tipper_data() -> dict:
    with open(TIPPER, "rb") as f:
        return tomllib.load(f)


def variant(name: str) -> dict:
    """tipper.toml, or a copy of it: "static" (inertia off), "weightless" (gravity off,
    and no payload), "massless" (no barrel and rod), "toggle" (O, A and pin B at binary
    points, |OA| = 5 m, |OB| = 3.75 m: toggles at s = 1.25 m and 8.75 m; the tailgate's
    rod raised with the hinge)."""
    data = tipper_data()
    if name == "static":
        data["effects"]["inertia"] = False
    elif name == "weightless":
        data["effects"]["gravity"] = False
    elif name == "massless":
        del data["cylinder"]["barrel"], data["cylinder"]["rod"]
    elif name == "toggle":
        data["cylinder"].update(at=[0.0, 2.0], base=[4.0, -1.0], pin=[2.25, -3.0])
        data["dyad"][0]["p"]["at"] = [0.0, 1.3]
    return data


@cache
def scene(name: str) -> scene_mp.MechanismScene:
    return scene_mp.read_scene(variant(name))


def speed(s: float) -> tuple[float, float]:
    """(s', s'') of the motion s' = v(s) = 1 + (s - 1.25)/2 - (s - 1.25)^2/8 m/s (1 to 1.5
    m/s, a quick stroke: inertia's share of the force up to a third), exact in binary on
    the grid."""
    x = Fraction(s) - Fraction(START)
    v = 1 + x / 2 - x * x / 8
    a = v * (Fraction(1, 2) - x / 4)
    assert Fraction(float(v)) == v and Fraction(float(a)) == a
    return float(v), float(a)


@cache
def run(name: str, s: float, rate: float | None = None, accel: float | None = None) -> dict:
    """The reference's outputs at length s (m) on the motion v(s), or at the given rates;
    the payload at PAYLOAD."""
    force = payload(name)
    values = {"hoist.length": s, "payload.force.x": force[0], "payload.force.y": force[1]}
    if scene(name).inertia:
        v, a = speed(s)
        values["hoist.velocity"] = v if rate is None else rate
        values["hoist.acceleration"] = a if accel is None else accel
    r = scene_mp.evaluate(scene(name), values, dps=DPS)
    assert r.status == scene_mp.OK, (name, s, r.reason)
    return r.outputs


def payload(name: str) -> tuple[float, float]:
    """The payload's force (N): PAYLOAD, none in the weightless copy."""
    return (0.0, 0.0) if name == "weightless" else PAYLOAD


def weights() -> list[mpf]:
    """The weights w_k of f'(x) ~ sum w_k (f(x + k h) - f(x - k h)) / h, k = 1..HALF."""
    m = HALF
    f = mpmath.factorial
    return [(-1) ** (k + 1) * f(m) ** 2 / (k * f(m - k) * f(m + k)) for k in range(1, m + 1)]


def derivative(fn, s: float) -> mpf:
    """d fn / ds at s by the central difference on the grid."""
    return sum(
        w * (fn(s + k * STEP) - fn(s - k * STEP)) for k, w in enumerate(weights(), start=1)
    ) / mpf(STEP)


# ---------------------------------------------------------------------------
# the bodies, from the outputs and the scene's numbers alone
# ---------------------------------------------------------------------------
def _vec(p: dict, name: str) -> tuple:
    return (mpf(p[f"{name}.x"]), mpf(p[f"{name}.y"]))


def _rot(angle: mpf, v: tuple) -> tuple:
    c, s = mpmath.cos(angle), mpmath.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _add(a: tuple, b: tuple, k: mpf = 1) -> tuple:
    return (a[0] + k * b[0], a[1] + k * b[1])


def _perp(v: tuple) -> tuple:
    return (-v[1], v[0])


def _dot(a: tuple, b: tuple) -> mpf:
    return a[0] * b[0] + a[1] * b[1]


def _cross(a: tuple, b: tuple) -> mpf:
    return a[0] * b[1] - a[1] * b[0]


def _spin(w: mpf, point: tuple, centre: tuple) -> tuple:
    """The velocity of ``point`` of a body turning at w about ``centre`` (at rest)."""
    return _perp((w * (point[0] - centre[0]), w * (point[1] - centre[1])))


#: each body's mass and inertia parameters
MASSES = {
    "body": ("body.mass", "body.inertia"),
    "barrel": ("hoist.barrel.mass", "hoist.barrel.inertia"),
    "rod": ("hoist.rod.mass", "hoist.rod.inertia"),
    "tailgate": ("tailgate.mass", "tailgate.inertia"),
    "opener": ("opener.mass", "opener.inertia"),
}


def bodies(name: str, o: dict) -> dict:
    """body -> (centre of mass S, its velocity, angular velocity): the link turns about
    O, the barrel about A, the rod is pinned to the link at B and turns with the barrel,
    the tailgate hangs on the link at D_m, the opener turns about its frame pin D_n."""
    p = scene(name).parameters
    zero = mpf(0)
    o_pin, a_pin = _vec(p, "body.at"), _vec(p, "hoist.base")
    w, wc = o.get("body.omega", zero), o.get("hoist.omega", zero)
    u = (mpmath.cos(o["hoist.angle"]), mpmath.sin(o["hoist.angle"]))
    b_pin = (o["hoist.B.position.x"], o["hoist.B.position.y"])
    d_m = (o["gate.D_m.position.x"], o["gate.D_m.position.y"])
    d_n = (o["gate.D_n.position.x"], o["gate.D_n.position.y"])
    s_body = _add(o_pin, _rot(o["body.angle"], _vec(p, "body.com")))
    s_barrel = _add(a_pin, u, mpf(p["hoist.barrel.com"]))
    s_rod = _add(b_pin, u, -mpf(p["hoist.rod.com"]))
    s_gate = _add(d_m, _rot(o["tailgate.angle"], _vec(p, "tailgate.com")))
    s_opener = _add(d_n, _rot(o["opener.angle"], _vec(p, "opener.com")))
    w_gate, w_opener = o.get("tailgate.omega", zero), o.get("opener.omega", zero)
    v_b, v_dm = _spin(w, b_pin, o_pin), _spin(w, d_m, o_pin)
    return {
        "body": (s_body, _spin(w, s_body, o_pin), w),
        "barrel": (s_barrel, _spin(wc, s_barrel, a_pin), wc),
        "rod": (s_rod, _add(v_b, _spin(wc, s_rod, b_pin)), wc),
        "tailgate": (s_gate, _add(v_dm, _spin(w_gate, s_gate, d_m)), w_gate),
        "opener": (s_opener, _spin(w_opener, s_opener, d_n), w_opener),
    }


def payload_point(name: str, o: dict) -> tuple:
    """(the payload's point P, its velocity)."""
    p = scene(name).parameters
    o_pin = _vec(p, "body.at")
    point = _add(o_pin, _rot(o["body.angle"], _vec(p, "payload.at")))
    return point, _spin(o.get("body.omega", mpf(0)), point, o_pin)


def kinetic(name: str, o: dict) -> mpf:
    """The kinetic energy of every moving body (J)."""
    p = scene(name).parameters
    return sum(
        p[MASSES[b][0]] * _dot(v, v) / 2 + p[MASSES[b][1]] * w * w / 2
        for b, (_, v, w) in bodies(name, o).items()
    )


def potential(name: str, o: dict) -> mpf:
    """The potential energy of gravity and of the payload, a constant force (J)."""
    p = scene(name).parameters
    g = _vec(p, "gravity") if scene(name).gravity else (0, 0)
    weight = sum(-p[MASSES[b][0]] * _dot(g, s) for b, (s, _, _) in bodies(name, o).items())
    return weight - _dot(payload(name), payload_point(name, o)[0])


def external_power(name: str, o: dict) -> mpf:
    """The power of gravity and of the payload (W)."""
    p = scene(name).parameters
    g = _vec(p, "gravity") if scene(name).gravity else (0, 0)
    weight = sum(p[MASSES[b][0]] * _dot(g, v) for b, (_, v, _) in bodies(name, o).items())
    return weight + _dot(payload(name), payload_point(name, o)[1])


def relative(got: mpf, want: mpf, scale: mpf) -> mpf:
    return abs(got - want) / scale


# ---------------------------------------------------------------------------
# (a) energy and rates
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["tipper", "weightless"])
@pytest.mark.parametrize("s", INSTANTS)
def test_power_of_the_cylinder_gravity_and_payload_is_the_rate_of_kinetic_energy(name, s):
    """On tipper.toml and, where the cylinder's power goes to the kinetic energy alone,
    on its weightless copy."""
    with mpmath.workdps(DPS + 10):
        o = run(name, s)
        v, _ = speed(s)
        cylinder = o["hoist.force"] * v
        loads = external_power(name, o)
        rate = derivative(lambda x: kinetic(name, run(name, x)), s) * v
        scale = max(abs(cylinder), abs(loads), abs(rate))
        assert relative(cylinder + loads, rate, scale) < 1e-20, (s, cylinder, loads, rate)
        assert scale > 10  # W: something moves


RATES = [(f"{g}.angle", f"{g}.omega") for g in ("body", "hoist", "tailgate", "opener")]
RATES += [(f"{g}.omega", f"{g}.epsilon") for g in ("body", "hoist", "tailgate", "opener")]


@pytest.mark.parametrize("s", INSTANTS[::2])
def test_every_rate_is_the_derivative_along_the_motion(s):
    """d/dt = v d/ds on the motion: angles to rates to accelerations, and pin B moves at
    the link's omega about O."""
    with mpmath.workdps(DPS + 10):
        o = run("tipper", s)
        v, _ = speed(s)
        for value, rate in RATES:
            got = derivative(lambda x, k=value: run("tipper", x)[k], s) * v
            assert relative(got, o[rate], max(abs(o[rate]), mpf(1e-3))) < 1e-20, (value, s)
        o_pin = _vec(scene("tipper").parameters, "body.at")
        v_b = _spin(o["body.omega"], (o["hoist.B.position.x"], o["hoist.B.position.y"]), o_pin)
        for c, axis in enumerate("xy"):
            got = derivative(lambda x, a=axis: run("tipper", x)[f"hoist.B.position.{a}"], s)
            assert relative(got * v, v_b[c], abs(o["body.omega"])) < 1e-20, axis


def _pair(o: dict, name: str) -> tuple:
    return (o[f"{name}.x"], o[f"{name}.y"])


def balance(forces: list, moving: list, centre: tuple) -> tuple[tuple, mpf]:
    """(sum of ``forces`` - sum of m a_S, their moment about ``centre`` - that of m a_S
    and I epsilon): forces as (point, force); moving as (mass, inertia, S, a_S, epsilon)."""
    total, moment = (mpf(0), mpf(0)), mpf(0)
    for point, force in forces:
        total = _add(total, force)
        moment += _cross(_add(point, centre, -1), force)
    for mass, inertia, point, acc, eps in moving:
        total = _add(total, acc, -mass)
        moment -= _cross(_add(point, centre, -1), (mass * acc[0], mass * acc[1])) + inertia * eps
    return total, moment


@pytest.mark.parametrize("s", INSTANTS[1::2])
def test_frame_reactions_balance_the_whole_mechanism_and_the_link(s):
    """Newton-Euler of the whole mechanism (the frame's forces at A, O and the opener's
    pin, gravity and the payload) and of the link alone (R_O, R_B, the tailgate's hinge),
    the accelerations the difference quotients of the velocities."""
    name = "tipper"
    with mpmath.workdps(DPS + 10):
        o, p = run(name, s), scene(name).parameters
        v, _ = speed(s)
        moving = {}
        for b, (point, _, _) in bodies(name, o).items():
            acc = [
                derivative(lambda x, b=b, c=c: bodies(name, run(name, x))[b][1][c], s) * v
                for c in (0, 1)
            ]
            eps = derivative(lambda x, b=b: bodies(name, run(name, x))[b][2], s) * v
            moving[b] = (p[MASSES[b][0]], p[MASSES[b][1]], point, tuple(acc), eps)
        g = _vec(p, "gravity")
        weights = [(m[2], (m[0] * g[0], m[0] * g[1])) for m in moving.values()]
        load = (payload_point(name, o)[0], payload(name))
        o_pin, a_pin = _vec(p, "body.at"), _vec(p, "hoist.base")
        d_m, d_n = _pair(o, "gate.D_m.position"), _pair(o, "gate.D_n.position")
        b_pin = _pair(o, "hoist.B.position")
        frame = [(a_pin, _pair(o, "hoist.R_A")), (o_pin, _pair(o, "body.R_O"))]
        frame.append((d_n, _pair(o, "gate.R_np")))
        scale = abs(o["hoist.force"])
        total, moment = balance(frame + weights + [load], list(moving.values()), o_pin)
        assert mpmath.hypot(*total) < 1e-20 * scale and abs(moment) < 1e-20 * scale, (total, moment)
        r_mk = _pair(o, "gate.R_mk")
        on_link = [(o_pin, _pair(o, "body.R_O")), (b_pin, _pair(o, "hoist.R_B")), weights[0], load]
        on_link.append((d_m, (-r_mk[0], -r_mk[1])))
        total, moment = balance(on_link, [moving["body"]], o_pin)
        assert mpmath.hypot(*total) < 1e-20 * scale and abs(moment) < 1e-20 * scale, (total, moment)


# ---------------------------------------------------------------------------
# (b) statics
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("s", INSTANTS)
def test_static_force_balances_gravity_and_the_payload(s):
    with mpmath.workdps(DPS + 10):
        force = run("static", s)["hoist.force"]
        slope = derivative(lambda x: potential("static", run("static", x)), s)
        assert relative(force, slope, abs(force)) < 1e-20, (s, force, slope)
        assert force > 2e4  # N: the cylinder pushes


# ---------------------------------------------------------------------------
# (c) J, force0, dJdq
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("s", INSTANTS)
def test_effective_inertia_and_force0(s):
    with mpmath.workdps(DPS + 10):
        o = run("tipper", s)
        v, a = speed(s)
        j, dj, f0 = o["hoist.J"], o["hoist.dJdq"], o["hoist.force0"]
        assert relative(kinetic("tipper", o), j * mpf(v) ** 2 / 2, j * v * v) < 1e-40
        other = run("tipper", s, v, -3.0)  # the same speed, another acceleration
        assert relative(other["hoist.force"] - o["hoist.force"], j * (-3 - mpf(a)), j) < 1e-40
        assert other["hoist.J"] == j and other["hoist.dJdq"] == dj and other["hoist.force0"] == f0
        assert relative(f0, o["hoist.force"] - j * mpf(a), abs(f0)) < 1e-40
        # F = J s'' + (dJ/ds) s'^2 / 2 + the static force
        still = run("tipper", s, 0.0, 0.0)
        want = still["hoist.force"] + dj * mpf(v) ** 2 / 2
        assert relative(f0, want, abs(f0)) < 1e-40
        assert relative(still["hoist.force"], run("static", s)["hoist.force"], abs(f0)) < 1e-40
        assert relative(derivative(lambda x: run("tipper", x)["hoist.J"], s), dj, j) < 1e-20


# ---------------------------------------------------------------------------
# (d) the barrel and the rod
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("s", INSTANTS[1::2])
def test_massless_barrel_and_rod_carry_the_force_along_the_axis(s):
    with mpmath.workdps(DPS + 10):
        o = run("massless", s)
        u = (mpmath.cos(o["hoist.angle"]), mpmath.sin(o["hoist.angle"]))
        force = o["hoist.force"]
        for pin in ("R_A", "R_B"):
            r = (o[f"hoist.{pin}.x"], o[f"hoist.{pin}.y"])
            assert mpmath.hypot(*_add(r, u, -force)) < 1e-40 * abs(force), pin
        assert abs(o["hoist.N"]) < 1e-40 * abs(force) and abs(o["hoist.M"]) < 1e-40 * abs(force)
        # with their masses, the barrel's pin takes their weight and inertia across the axis
        heavy = run("tipper", s)
        r_a = (heavy["hoist.R_A.x"], heavy["hoist.R_A.y"])
        assert abs(_cross(r_a, u)) > 100  # N


# ---------------------------------------------------------------------------
# (e) statuses
# ---------------------------------------------------------------------------
def reach(name: str) -> tuple[mpf, mpf]:
    """The shortest and longest length (m) at which the triangle O, A, B closes."""
    p = scene(name).parameters
    d = _add(_vec(p, "hoist.base"), _vec(p, "body.at"), -1)
    oa, ob = mpmath.hypot(*d), mpmath.hypot(*_vec(p, "hoist.pin"))
    return abs(oa - ob), oa + ob


def floats_around(x: mpf) -> tuple[float, float]:
    """The floats just below and just above x."""
    f = float(x)
    below = f if f < x else math.nextafter(f, -math.inf)
    above = f if f > x else math.nextafter(f, math.inf)
    return below, above


def status(name: str, s: float, branch: float | None = None) -> scene_mp.Result:
    values = {"hoist.length": s}
    if branch is not None:
        values["hoist.branch"] = branch
    return scene_mp.evaluate(scene(name), values, dps=30)


def test_cannot_assemble_outside_the_reach_of_the_triangle():
    with mpmath.workdps(60):
        shortest, longest = reach("tipper")
    assert abs(shortest - 1.1106688749) < 1e-9 and abs(longest - 9.7576336604) < 1e-9
    for s in (*floats_around(shortest)[:1], floats_around(longest)[1], 0.0, -1.0):
        r = status("tipper", s)
        assert (r.status, r.dyad, r.outputs) == (scene_mp.CANNOT_ASSEMBLE, "hoist", {}), s
        assert "outside the triangle's reach" in r.reason
    near = status("tipper", floats_around(shortest)[1])
    assert near.status == scene_mp.OK and 0 < near.outputs["hoist.conditioning"] < 1e-7
    # at full reach the body is upside down and the tailgate's rod too short: the
    # triangle closes, the gate does not
    far = scene_mp.assembly_status(scene("tipper"), {"hoist.length": floats_around(longest)[0]})
    assert (far.status, far.dyad) == (scene_mp.CANNOT_ASSEMBLE, "gate")


def test_singular_at_the_toggle_and_ok_on_both_branches_past_it():
    assert reach("toggle") == (1.25, 8.75)
    for s in (1.25, 8.75):
        for branch in (1.0, -1.0):
            r = status("toggle", s, branch)
            assert (r.status, r.dyad, r.outputs) == (scene_mp.SINGULAR, "hoist", {}), s
    assert status("toggle", 1.25 - 2.0**-30).status == scene_mp.CANNOT_ASSEMBLE
    p = scene("toggle").parameters
    o_pin, a_pin = _vec(p, "body.at"), _vec(p, "hoist.base")
    for branch in (1.0, -1.0):
        r = status("toggle", 1.25 + 2.0**-30, branch)
        assert r.status == scene_mp.OK, r.reason
        o = r.outputs
        assert 0 < o["hoist.conditioning"] < 1e-4
        b_pin = (o["hoist.B.position.x"], o["hoist.B.position.y"])
        side = _cross(_add(a_pin, o_pin, -1), _add(b_pin, o_pin, -1))
        assert side * branch > 0 and abs(o["hoist.force"]) > 1e7  # N: near the toggle


def test_tipper_over_its_stroke():
    """The stroke the scene's comment gives: the body from 0 to 50 deg, the triangle's and
    the gate's conditioning above 0.5 and 0.8, the tailgate opening by about 47 deg."""
    first, last = run("static", START), run("static", END)
    assert abs(first["body.angle"]) < 1e-15
    assert 50.0 < math.degrees(last["body.angle"]) < 50.2
    for k in range(0, 14337, 512):
        o = run("static", START + k * STEP)
        assert o["hoist.conditioning"] > 0.51 and o["gate.conditioning"] > 0.83
    opening = (first["tailgate.angle"] - first["body.angle"]) - (
        last["tailgate.angle"] - last["body.angle"]
    )
    assert 46 < math.degrees(opening) < 48


# ---------------------------------------------------------------------------
# the reader
# ---------------------------------------------------------------------------
def test_a_dyad_on_the_link_alone_sits_at_pin_b():
    data = tipper_data()
    b_pin = run("static", 2.0)
    data["dyad"][0]["k"] = "body"
    data["dyad"][0]["p"]["at"] = [float(b_pin[f"hoist.B.position.{a}"]) for a in "xy"]
    data["dyad"][0]["p"]["at"][0] += 0.6  # m: the gate's triangle 0.5, 0.7, 0.6 m
    data["link"][1]["length"] = 0.7
    o = scene_mp.evaluate(data, {"hoist.length": 2.0}, dps=30).outputs
    assert o["gate.D_m.position.x"] == o["hoist.B.position.x"]
    assert o["gate.D_m.position.y"] == o["hoist.B.position.y"]


def _edit(path: str, value: object) -> dict:
    """tipper.toml with the field at ``path`` ("cylinder.branch") set to value, or
    removed (value None)."""
    data = tipper_data()
    *heads, key = path.split(".")
    table = data
    for head in heads:
        table = table[int(head)] if head.isdigit() else table[head]
    if value is None:
        del table[key]
    else:
        table[key] = value
    return data


CRANK = {"length": 0.1, "inertia": 1.0, "com": [0.0, 0.0], "mass": 1.0}
REFUSED = [
    ("crank", {"length": 0.1}, r"\[crank\]: missing 'inertia'"),
    ("crank", {"name": "body", **CRANK}, r"\[cylinder\]: two drivers or links named 'body'"),
    ("crank", {"name": "hoist", **CRANK}, r"\[cylinder\]: two drivers or links named 'hoist'"),
    ("cylinder.stroke", 3.5, r"\[cylinder\]: unknown key 'stroke'"),
    ("cylinder.branch", 0, r"\[cylinder\].branch: must be 1 or -1, not 0"),
    ("cylinder.branch", True, r"\[cylinder\].branch: must be 1 or -1"),
    ("cylinder.branch", None, r"\[cylinder\].branch: must be 1 or -1, not None"),
    ("cylinder.pin", [0.0, 0.0], r"\[cylinder\].pin: must not be \[0, 0\]"),
    ("cylinder.pin", None, r"\[cylinder\]: 'pin' must be \[x, y\]"),
    ("cylinder.base", [0.0, 1.7], r"\[cylinder\].base: A must differ from the link's pivot"),
    ("cylinder.base", [5.3, math.inf], r"\[cylinder\].base must be finite"),
    ("cylinder.link", "tailgate", r"link 'tailgate': a \[\[link\]\] named like the driver"),
    ("cylinder.link", "Body", r"\[cylinder\].link: must be a lower-case name"),
    ("cylinder.name", "body", r"the cylinder and the link it turns are both named 'body'"),
    ("cylinder.name", None, r"\[cylinder\].name: must be a lower-case name, not None"),
    ("cylinder.mass", None, r"\[cylinder\]: missing 'mass'"),
    ("cylinder.barrel", {"mass": 1.0, "length": 2.0}, r"\[cylinder\].barrel: must be \{ mass"),
    ("cylinder.rod", {"mass": 1.0, "com": 0.5}, r"\[cylinder\].rod: missing 'inertia'"),
    ("dyad.0.k", "hoist", r"dyad 'gate'.k: a dyad hangs on the link the cylinder turns, 'body'"),
    ("dyad.0.k", "body2", r"dyad 'gate'.k: 'body2' is not the frame"),
    ("load.0.link", "hoist", r"load 'payload': needs a name and the link it acts on"),
]


@pytest.mark.parametrize(("path", "value", "message"), REFUSED)
def test_what_the_cylinder_spec_does_not_allow_is_refused(path, value, message):
    with pytest.raises(scene_mp.SceneError, match=message):
        scene_mp.read_scene(_edit(path, value))


def test_parameters_by_name_override_the_scene():
    """Parameters given with the inputs replace the scene's; a pin at O is refused."""
    base = run("tipper", INSTANTS[2])
    values = {"hoist.length": INSTANTS[2], "body.mass": 6000.0, "hoist.rod.com": 0.9}
    values.update({"payload.force.x": PAYLOAD[0], "payload.force.y": PAYLOAD[1]})
    v, a = speed(INSTANTS[2])
    values.update({"hoist.velocity": v, "hoist.acceleration": a})
    other = scene_mp.evaluate(scene("tipper"), values, dps=DPS).outputs
    assert other["body.angle"] == base["body.angle"]
    assert other["hoist.J"] > base["hoist.J"] and other["hoist.force"] > base["hoist.force"]
    assert other["hoist.M"] != base["hoist.M"]
    with pytest.raises(scene_mp.SceneError, match="hoist.pin: O, A and B must be distinct"):
        scene_mp.evaluate(scene("tipper"), {"hoist.pin.x": 0.0, "hoist.pin.y": 0.0})
    assert scene("tipper").motion_inputs == ("hoist.length", "hoist.velocity", "hoist.acceleration")
    assert set(scene("static").inputs) == {"hoist.length", "payload.force.x", "payload.force.y"}

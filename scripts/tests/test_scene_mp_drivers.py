"""The mpmath reference of scenes with several drivers (dyadfmu.reference.scene_mp):
modelDescription/scenes/leg.toml (two cranks, an RRR dyad, a foot load),
tests/scenes/three_drivers.toml (a crank, a ram and a cylinder, two RRR dyads, a
follower force and moment), and with cylinders pinned to moving links (spec part 2):
tests/scenes/carried_cylinders.toml (cylinder lift raises a boom; cylinder reach, pinned
at both ends to the boom, turns an arm with a payload), modelDescription/scenes/
excavator.toml (three cylinders, each carried by the previous one's link, and an RRR
four-bar) and loader.toml (a tilt cylinder with A on the frame and O on the lift arm,
and an RRR Z-bar); at points of their working ranges with nonzero rates, accelerations
and loads, at 50 digits:

- every body in equilibrium with its weight, its d'Alembert force and couple and the
  reactions the reference outputs (each driver's body, a cylinder's barrel and rod,
  every dyad link), a carrier bearing minus R_A at A and minus R_O at O of each cylinder
  it carries; the accelerations rebuilt here by rigid-body kinematics from the drivers'
  motion and the output angles, rates and pair points, carrier after carrier, to 1e-25
  of the largest term;
- each carried cylinder's triangle closed in position, velocity and acceleration: pin B
  moved with the link (its pivot O with O's carrier) and with the rod (A with A's
  carrier, s', s'' along the axis) alike, to 1e-25;
- M (from the kinetic energy) symmetric, positive definite, and equal to the efforts'
  response to unit accelerations with velocities, gravity and loads off (a Newton-Euler
  route, symmetric only when the balances are right), to 1e-25;
- every effort = M q'' + h, h the torque0 / force0 outputs, to 1e-25;
- the outputs named as the spec says: M.<a>.<b> for every ordered pair, no J nor dJdq;
- the refusals: a cylinder pinned to the link it turns, a carrier that is not the frame
  nor an earlier driver's link (a later cylinder's link, a cylinder's own name, an
  unknown name, a dyad's link), each with a message naming the field.
"""

from __future__ import annotations

import copy
import math
import re
import tomllib

import mpmath
import pytest
from dyadfmu.reference import scene_mp
from mpmath import mpf
from test_scene_mp import scene_file

DPS = 50
TOL = mpf(10) ** -25
DEG = math.pi / 180
#: (front.angle, rear.angle) over the leg's working range (rad)
LEG_POINTS = [(-60 * DEG, -120 * DEG), (-95 * DEG, -85 * DEG), (-25 * DEG, -155 * DEG)]
LEG_POINTS.append((-40 * DEG, -100 * DEG))
#: (wheel.angle rad, slide.position m, jack.length m) over three_drivers' working range
THREE_POINTS = [(0.5, 1.0, 1.95), (2.5, 0.65, 1.86), (4.0, 1.35, 2.01), (-1.2, 0.8, 1.9)]
#: driver coordinates (lift.length, reach.length in m) over carried_cylinders' range
CARRIED_POINTS = [(1.1, 1.3), (1.25, 1.5), (1.4, 1.7), (1.15, 1.65), (1.38, 1.35)]
#: boom_cyl, stick_cyl, bucket_cyl (m) over the excavator's working range, its corners too
EXCAVATOR_POINTS = [(2.65, 3.15, 2.35), (1.98, 3.75, 1.9), (3.3, 2.55, 2.8), (2.2, 2.6, 2.0)]
#: lift_cyl, tilt_cyl (m) over the loader's working range
LOADER_POINTS = [(1.825, 1.6), (1.25, 1.95), (2.4, 1.25), (2.0, 1.9)]
#: the scenes with a cylinder pinned to a moving link
CARRIED = [("carried_cylinders", p) for p in CARRIED_POINTS]
CARRIED += [("excavator", p) for p in EXCAVATOR_POINTS] + [("loader", p) for p in LOADER_POINTS]
#: every scene: the frame-pinned ones check the rebuilding of cranks and rams too
CASES = [("leg", p) for p in LEG_POINTS] + [("three_drivers", p) for p in THREE_POINTS]
CASES += CARRIED
#: each driver's rate and acceleration, by kind, the k-th driver's scaled by (-1)^k
RATES = {"crank": (2.0, -3.0), "ram": (-0.3, 0.5), "cylinder": (0.08, -0.35)}
#: every load's inputs (N, N m), arbitrary and nonzero
LOADS = {"force.x": 150.0, "force.y": -900.0, "moment": 40.0}


@pytest.fixture(autouse=True)
def _precision():
    """The checks' own arithmetic at 60 digits, beyond the outputs' 50."""
    with mpmath.workdps(DPS + 10):
        yield


def read(name: str) -> scene_mp.MechanismScene:
    return scene_mp.read_scene(scene_file(name))


def values_at(scene, point) -> dict:
    """The inputs: the coordinates, each driver's RATES, every load at LOADS."""
    values = {}
    for k, drv in enumerate(scene.drivers):
        names = drv.motion(True)
        rate, accel = RATES[drv.kind]
        sign = (-1) ** k
        values |= {names[0]: point[k], names[1]: sign * rate}
        values[names[2]] = sign * accel
    for name in scene.inputs:
        if name not in values:
            values[name] = LOADS[name.split(".", 1)[1]]
    return values


def evaluate(scene, values) -> dict:
    r = scene_mp.evaluate(scene, values, dps=DPS)
    assert r.status == scene_mp.OK, (scene.label, values, r.reason)
    return r.outputs


# ---------------------------------------------------------------------------
# plane vectors as (x, y) pairs of mpf
# ---------------------------------------------------------------------------
def add(*vs):
    return (sum(v[0] for v in vs), sum(v[1] for v in vs))


def scale(s, v):
    return (s * v[0], s * v[1])


def minus(v):
    return (-v[0], -v[1])


def perp(v):
    return (-v[1], v[0])


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


# ---------------------------------------------------------------------------
# the bodies' motion rebuilt from the outputs, carrier after carrier
# ---------------------------------------------------------------------------
class Moving:
    """A body: its origin's position, velocity and acceleration, angle, omega, epsilon."""

    def __init__(self, origin, angle, omega, epsilon):
        self.origin = origin  # (position, velocity, acceleration)
        self.i = (mpmath.cos(angle), mpmath.sin(angle))
        self.omega, self.epsilon = mpf(omega), mpf(epsilon)

    def at(self, local) -> tuple:
        """(position, velocity, acceleration) of the body's point ``local``."""
        r = add(scale(local[0], self.i), scale(local[1], perp(self.i)))
        p, v, a = self.origin
        w, e = self.omega, self.epsilon
        return add(p, r), add(v, scale(w, perp(r))), add(a, scale(e, perp(r)), scale(-w * w, r))


ZERO = (mpf(0), mpf(0))
FRAME = Moving((ZERO, ZERO, ZERO), 0, 0, 0)


def local(scene, name: str) -> tuple:
    p = scene.parameters
    return (mpf(p[f"{name}.x"]), mpf(p[f"{name}.y"]))


def vec(out, name: str) -> tuple:
    return (mpf(out[f"{name}.x"]), mpf(out[f"{name}.y"]))


class Rebuilt:
    """Every moving body of a scene (cranks, rams, cylinders' links, RRR dyads' links)
    and each cylinder's axis, from the inputs and the outputs."""

    def __init__(self, scene, values, out) -> None:
        self.scene, self.values, self.out = scene, values, out
        self.bodies: dict[str, Moving] = {}
        self.axes: dict[str, tuple] = {}
        for drv in scene.drivers:
            self.bodies[drv.link] = getattr(self, drv.kind)(drv)
        for d in scene.dyads:
            assert d.type == "RRR", "only RRR dyads are rebuilt here"
            for g, pair, att in ((d.m, "D_m", d.k), (d.n, "D_n", d.p)):
                _, v, a = self.mount(att)
                origin = (vec(out, f"{d.prefix}{pair}.position"), v, a)
                self.bodies[g] = self.link(g, origin)

    def link(self, g: str, origin: tuple) -> Moving:
        out = self.out
        return Moving(origin, out[f"{g}.angle"], out[f"{g}.omega"], out[f"{g}.epsilon"])

    def crank(self, drv) -> Moving:
        motion = (self.values[n] for n in drv.motion(True))
        return Moving((local(self.scene, f"{drv.name}.at"), ZERO, ZERO), *motion)

    def ram(self, drv) -> Moving:
        x, v, a = (mpf(self.values[n]) for n in drv.motion(True))
        guide = mpf(self.scene.parameters[f"{drv.name}.guide"])
        i = (mpmath.cos(guide), mpmath.sin(guide))
        at = local(self.scene, f"{drv.name}.at")
        return Moving((add(at, scale(x, i)), scale(v, i), scale(a, i)), guide, 0, 0)

    def carried(self, carrier, name: str) -> tuple:
        """A point of the frame (global) or of its carrier's frame, and its motion."""
        return (FRAME if carrier is None else self.bodies[carrier]).at(local(self.scene, name))

    def cylinder(self, drv) -> Moving:
        c, g, out = drv.name, drv.link, self.out
        self.axes[c] = (
            self.carried(drv.base_on, f"{c}.base"),
            (mpmath.cos(out[f"{c}.angle"]), mpmath.sin(out[f"{c}.angle"])),
            mpf(out[f"{c}.omega"]),
            mpf(out[f"{c}.epsilon"]),
        )
        return self.link(g, self.carried(drv.pivot_on, f"{g}.at"))

    def along(self, c: str, x, x1, x2) -> tuple:
        """(position, velocity, acceleration) of the point x from A along the axis, x
        growing at x1, x2 (the rod's points at s', s'', the barrel's fixed)."""
        (a_p, a_v, a_a), u, w, e = self.axes[c]
        n = perp(u)
        return (
            add(a_p, scale(x, u)),
            add(a_v, scale(x1, u), scale(x * w, n)),
            add(a_a, scale(x2 - x * w * w, u), scale(2 * x1 * w + x * e, n)),
        )

    def mount(self, att) -> tuple:
        """Where a dyad meets its outer link: (position, velocity, acceleration)."""
        if att.body is None:
            return self.carried(None, att.at)
        drv = self.scene.driver_on(att.body)
        if att.at is not None:
            point = local(self.scene, att.at)
        elif drv.kind == "crank":
            point = (mpf(self.scene.parameters[f"{drv.name}.length"]), 0)
        elif drv.kind == "cylinder":
            point = local(self.scene, f"{drv.name}.pin")
        else:
            point = ZERO
        return self.bodies[att.body].at(point)


# ---------------------------------------------------------------------------
# every body's balance
# ---------------------------------------------------------------------------
class Balance:
    """The forces at points and couples on one body; the residual of its equilibrium."""

    def __init__(self) -> None:
        self.forces, self.couples = [], []

    def force(self, point, f) -> None:
        self.forces.append((point, (mpf(f[0]), mpf(f[1]))))

    def couple(self, m) -> None:
        self.couples.append(mpf(m))

    def mass(self, scene, name: str, body_point: tuple, epsilon, gravity) -> None:
        """Weight and d'Alembert force at the centre of mass, d'Alembert couple."""
        p = scene.parameters
        m = mpf(p[f"{name}.mass"])
        (s, a_s) = body_point
        self.force(s, scale(m, add(gravity, scale(-1, a_s))))
        self.couple(-mpf(p.get(f"{name}.inertia", 0.0)) * epsilon)

    def residual(self) -> mpf:
        """max(|sum F|, |sum M about the first point|) / the largest term."""
        centre = self.forces[0][0]
        moments = [cross(add(p, scale(-1, centre)), f) for p, f in self.forces] + self.couples
        terms = [abs(c) for _, f in self.forces for c in f] + [abs(m) for m in moments]
        sums = [abs(sum(f[k] for _, f in self.forces)) for k in (0, 1)] + [abs(sum(moments))]
        return max(sums) / max(terms)


class Balances:
    """The forces and couples on every body, from the outputs."""

    def __init__(self, scene, values, out) -> None:
        self.scene, self.values, self.out = scene, values, out
        self.rb = Rebuilt(scene, values, out)
        p = scene.parameters
        self.gravity = (mpf(p.get("gravity.x", 0)), mpf(p.get("gravity.y", 0)))
        self.of: dict[str, Balance] = {}

    def on(self, body) -> Balance | None:
        """The balance of ``body`` (None: the frame, which is not checked)."""
        return None if body is None else self.of.setdefault(body, Balance())

    def weigh(self, body: str, name: str, point: tuple, epsilon) -> None:
        """Weight and d'Alembert force at the centre of mass ``point``, the d'Alembert couple."""
        self.on(body).mass(self.scene, name, (point[0], point[2]), epsilon, self.gravity)

    def all(self) -> dict[str, Balance]:
        for drv in self.scene.drivers:
            getattr(self, drv.kind)(drv)
        for d in self.scene.dyads:
            self.dyad(d)
        for name, link, components, has_force, has_moment in self.scene.point_loads:
            self.load(name, link, components, has_force, has_moment)
        return self.of

    def crank(self, drv) -> None:
        c, body, out = drv.name, self.rb.bodies[drv.link], self.out
        self.on(c).force(body.origin[0], vec(out, f"{c}.R_O"))
        self.on(c).couple(out[f"{c}.torque"])
        self.weigh(c, c, body.at(local(self.scene, f"{c}.com")), body.epsilon)

    def ram(self, drv) -> None:
        c, body, out = drv.name, self.rb.bodies[drv.link], self.out
        push = add(scale(out[f"{c}.force"], body.i), scale(out[f"{c}.N"], perp(body.i)))
        self.on(c).force(body.origin[0], push)
        self.on(c).couple(out[f"{c}.M"])
        self.weigh(c, c, body.at(local(self.scene, f"{c}.com")), 0)

    def cylinder(self, drv) -> None:
        c, g, out, rb = drv.name, drv.link, self.out, self.rb
        p = self.scene.parameters
        (a_pin, _, _), u, _, e = rb.axes[c]
        b_pin, o_pin = vec(out, f"{c}.B.position"), rb.bodies[g].origin[0]
        on_rod = add(scale(out[f"{c}.force"], u), scale(out[f"{c}.N"], perp(u)))
        barrel, rod = self.on(f"{c}.barrel"), self.on(f"{c}.rod")
        barrel.force(a_pin, vec(out, f"{c}.R_A"))
        barrel.force(b_pin, minus(on_rod))
        barrel.couple(-out[f"{c}.M"])
        self.weigh(f"{c}.barrel", f"{c}.barrel", rb.along(c, mpf(p[f"{c}.barrel.com"]), 0, 0), e)
        rod.force(b_pin, on_rod)
        rod.couple(out[f"{c}.M"])
        rod.force(b_pin, minus(vec(out, f"{c}.R_B")))
        s, v, a = (mpf(self.values[n]) for n in drv.motion(True))
        self.weigh(f"{c}.rod", f"{c}.rod", rb.along(c, s - mpf(p[f"{c}.rod.com"]), v, a), e)
        link = self.on(g)
        link.force(o_pin, vec(out, f"{g}.R_O"))
        link.force(b_pin, vec(out, f"{c}.R_B"))
        body = rb.bodies[g]
        self.weigh(g, g, body.at(local(self.scene, f"{g}.com")), body.epsilon)
        # the carriers: the barrel's pin and the link's pivot act back on them
        if self.on(drv.base_on):
            self.on(drv.base_on).force(a_pin, minus(vec(out, f"{c}.R_A")))
        if self.on(drv.pivot_on):
            self.on(drv.pivot_on).force(o_pin, minus(vec(out, f"{g}.R_O")))

    def dyad(self, d) -> None:
        out, pre = self.out, d.prefix
        e = vec(out, f"{pre}E.position")
        d_m, d_n = vec(out, f"{pre}D_m.position"), vec(out, f"{pre}D_n.position")
        self.on(d.m).force(d_m, vec(out, f"{pre}R_mk"))
        self.on(d.m).force(e, vec(out, f"{pre}R_mn"))
        self.on(d.n).force(d_n, vec(out, f"{pre}R_np"))
        self.on(d.n).force(e, minus(vec(out, f"{pre}R_mn")))
        for g in (d.m, d.n):
            body = self.rb.bodies[g]
            self.weigh(g, g, body.at(local(self.scene, f"{g}.com")), body.epsilon)
        if self.on(d.k.body):
            self.on(d.k.body).force(d_m, minus(vec(out, f"{pre}R_mk")))
        if self.on(d.p.body):
            self.on(d.p.body).force(d_n, minus(vec(out, f"{pre}R_np")))

    def load(self, name, link, components, has_force, has_moment) -> None:
        body = self.rb.bodies[link]
        if has_force:
            f = (mpf(self.values[f"{name}.force.x"]), mpf(self.values[f"{name}.force.y"]))
            if components == "link":
                f = add(scale(f[0], body.i), scale(f[1], perp(body.i)))
            self.on(link).force(body.at(local(self.scene, f"{name}.at"))[0], f)
        if has_moment:
            self.on(link).couple(self.values[f"{name}.moment"])


# ---------------------------------------------------------------------------
# the tests
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(("name", "point"), CASES)
def test_every_body_is_in_equilibrium(name, point):
    """Each body's forces and moments, d'Alembert's included, sum to zero to 1e-25 of
    their largest term; every carrier checked with the cylinders it carries."""
    scene = read(name)
    values = values_at(scene, point)
    balances = Balances(scene, values, evaluate(scene, values)).all()
    bodies = {d.link for d in scene.drivers} | {g for d in scene.dyads for g in (d.m, d.n)}
    assert bodies <= set(balances)
    worst = max((b.residual(), body) for body, b in balances.items())
    assert worst[0] < TOL, (name, point, worst)


def relative(a: tuple, b: tuple) -> mpf:
    return max(abs(a[k] - b[k]) for k in (0, 1)) / max(abs(c) for c in a + b)


@pytest.mark.parametrize(("name", "point"), CARRIED)
def test_every_cylinder_closes_in_position_velocity_and_acceleration(name, point):
    """Pin B moved with the link (O with its carrier) and with the rod (A with its
    carrier, sliding at s', s'') alike, and at the output B, to 1e-25."""
    scene = read(name)
    values = values_at(scene, point)
    out = evaluate(scene, values)
    rb = Rebuilt(scene, values, out)
    carried = 0
    for drv in (d for d in scene.drivers if d.kind == "cylinder"):
        by_link = rb.bodies[drv.link].at(local(scene, f"{drv.name}.pin"))
        s, v, a = (mpf(values[n]) for n in drv.motion(True))
        by_rod = rb.along(drv.name, s, v, a)
        for k in range(3):
            assert relative(by_link[k], by_rod[k]) < TOL, (name, point, drv.name, k)
        assert relative(by_link[0], vec(out, f"{drv.name}.B.position")) < TOL
        assert max(abs(c) for c in by_link[1] + by_link[2]) > 1e-3  # it does move
        carried += drv.pivot_on is not None or drv.base_on is not None
    assert carried  # the scene has a carried cylinder


def matrix_of(scene, out) -> mpmath.matrix:
    names = [d.name for d in scene.drivers]
    return mpmath.matrix([[out[f"M.{a}.{b}"] for b in names] for a in names])


def response_matrix(scene, values: dict) -> mpmath.matrix:
    """Column b: the efforts at zero velocities, gravity and loads with driver b's
    acceleration 1 and the others' 0."""
    kept = {d.motion(True)[0] for d in scene.drivers}  # the coordinates
    still = {k: (v if k in kept else 0.0) for k, v in values.items()}  # rates, loads: 0
    still |= {k: 0.0 for k in scene.parameters if k.startswith("gravity.")}
    columns = []
    for d in scene.drivers:
        out = evaluate(scene, {**still, d.motion(True)[2]: 1.0})
        columns.append([out[f"{e.name}.{e.effort}"] for e in scene.drivers])
    n = len(columns)
    return mpmath.matrix([[columns[b][a] for b in range(n)] for a in range(n)])


def largest(m: mpmath.matrix) -> mpf:
    return max(abs(m[i, j]) for i in range(m.rows) for j in range(m.cols))


@pytest.mark.parametrize(("name", "point"), CASES)
def test_inertia_matrix_is_symmetric_positive_definite_and_the_efforts_response(name, point):
    """M symmetric, positive definite, and equal to the efforts' response to unit
    accelerations (itself symmetric) to 1e-25 of its largest entry."""
    scene = read(name)
    values = values_at(scene, point)
    m = matrix_of(scene, evaluate(scene, values))
    k = response_matrix(scene, values)
    size = largest(m)
    assert largest(m - m.T) / size < TOL
    assert largest(k - k.T) / size < TOL, (name, point, largest(k - k.T) / size)
    assert largest(k - m) / size < TOL, (name, point, largest(k - m) / size)
    lower = mpmath.cholesky(m)  # ValueError unless positive definite
    assert min(lower[i, i] for i in range(m.rows)) > 0
    eigen = mpmath.eigsy(m)[0]
    assert min(eigen) > size * mpf(10) ** -6, (name, point, eigen)
    assert min(abs(m[i, j]) for i in range(m.rows) for j in range(m.cols)) > 0  # coupled


@pytest.mark.parametrize(("name", "point"), CASES)
def test_efforts_are_inertia_times_accelerations_plus_h(name, point):
    """Every effort = sum_b M_ab q''_b + effort0_a to 1e-25 of the largest term."""
    scene = read(name)
    values = values_at(scene, point)
    out = evaluate(scene, values)
    qdd = [mpf(values[d.motion(True)[2]]) for d in scene.drivers]
    for a in scene.drivers:
        terms = [out[f"M.{a.name}.{b.name}"] * x for b, x in zip(scene.drivers, qdd, strict=True)]
        h, effort = out[f"{a.name}.{a.effort}0"], out[f"{a.name}.{a.effort}"]
        size = max([abs(h), abs(effort)] + [abs(t) for t in terms])
        assert abs(effort - sum(terms) - h) / size < TOL, (name, point, a.name)
        assert abs(h - effort) > size * mpf(10) ** -6  # the accelerations do count


@pytest.mark.parametrize(
    ("name", "point"), [("leg", LEG_POINTS[0]), ("three_drivers", THREE_POINTS[0])]
)
def test_outputs_are_named_as_the_spec_says(name, point):
    scene = read(name)
    out = evaluate(scene, values_at(scene, point))
    names = [d.name for d in scene.drivers]
    assert {k for k in out if k.startswith("M.")} == {f"M.{a}.{b}" for a in names for b in names}
    assert not [k for k in out if k.endswith((".J", ".dJdq"))]
    for d in scene.drivers:
        assert {f"{d.name}.{d.effort}", f"{d.name}.{d.effort}0"} <= set(out)
        assert set(d.motion(True)) <= set(scene.inputs)
    kinds = {"leg": ["crank", "crank"], "three_drivers": ["crank", "ram", "cylinder"]}
    assert [d.kind for d in scene.drivers] == kinds[name]


def carried_data() -> dict:
    with open(scene_file("carried_cylinders"), "rb") as f:
        return tomllib.load(f)


def refusal(change) -> str:
    """The message of the SceneError read_scene raises on carried_cylinders changed by
    ``change`` (a function of its parsed table)."""
    data = copy.deepcopy(carried_data())
    change(data)
    with pytest.raises(scene_mp.SceneError) as caught:
        scene_mp.read_scene(data)
    return str(caught.value)


def _reach(key, value):
    def change(data):
        data["cylinder"][1][key] = value

    return change


def _lift_on_arm(data):
    data["cylinder"][0]["base"] = {"link": "arm", "at": [0.5, 0.0]}


def _on_dyad_link(data):
    """A third cylinder whose A is on a dyad's link."""
    data["link"] = [{"name": "tie", "length": 1.0, "com": [0.5, 0.0], "mass": 1.0}]
    data["link"].append({"name": "post", "length": 1.0, "com": [0.5, 0.0], "mass": 1.0})
    data["link"][0]["inertia"] = data["link"][1]["inertia"] = 0.1
    data["dyad"] = [{"name": "pair", "type": "RRR", "m": "tie", "n": "post", "branch": 1}]
    data["dyad"][0] |= {"k": {"link": "arm", "at": [1.0, 0.0]}, "p": {"link": "frame"}}
    data["dyad"][0]["p"]["at"] = [4.0, 0.0]
    third = dict(data["cylinder"][1], name="tip", link="claw")
    third["base"] = {"link": "tie", "at": [0.5, 0.0]}
    data["cylinder"].append(third)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (_reach("at", {"link": "arm", "at": [0.0, 0.0]}), r"#2\.at: on 'arm', the link the"),
        (_reach("base", {"link": "arm", "at": [1.5, 0.3]}), r"#2\.base: on 'arm', the link"),
        (_lift_on_arm, r"#1\.base: 'arm' is not the frame nor the link of a driver listed bef"),
        (_reach("base", {"link": "lift", "at": [1.5, 0.3]}), r"#2\.base: 'lift' is not the fr"),
        (_reach("at", {"link": "jib", "at": [3.0, 0.0]}), r"#2\.at: 'jib' is not the frame"),
        (_on_dyad_link, r"#3\.base: 'tie' is not the frame nor the link of a driver listed"),
        (_reach("at", {"link": "boom"}), r"#2\.at: must be \[x, y\] \(m, the frame\) or \{"),
        (_reach("base", {"link": "boom", "at": [3.0, 0.0]}), r"#2\.base: A must differ"),
    ],
)
def test_refused_carriers(change, message):
    """A cylinder pinned to the link it turns, or to a body that is neither the frame nor
    an earlier driver's link, refused with a message naming the field."""
    said = refusal(change)
    assert said.startswith("scene: [[cylinder]] "), said
    assert re.search(message, said), said


def test_a_frame_point_given_as_a_link_is_the_frame():
    """``{ link = "frame", at = [x, y] }`` is the frame's point [x, y]: the same outputs."""
    data = carried_data()
    scene = scene_mp.read_scene(data)
    values = values_at(scene, CARRIED_POINTS[1])
    changed = copy.deepcopy(data)
    changed["cylinder"][0]["base"] = {"link": "frame", "at": data["cylinder"][0]["base"]}
    assert scene_mp.read_scene(changed).drivers == scene.drivers
    a = scene_mp.evaluate(data, values, dps=30).outputs
    assert a == scene_mp.evaluate(changed, values, dps=30).outputs


def test_o_and_a_with_equal_coordinates_on_different_bodies_are_accepted():
    """A on the frame at [3, 0] and O at [3, 0] of the boom are distinct points: read
    and evaluated (the check of A against O holds on one body only)."""
    data = copy.deepcopy(carried_data())
    data["cylinder"][1]["base"] = [3.0, 0.0]
    scene = scene_mp.read_scene(data)
    assert (scene.drivers[1].pivot_on, scene.drivers[1].base_on) == ("boom", None)
    r = scene_mp.assembly_status(scene, values_at(scene, CARRIED_POINTS[1]), dps=30)
    assert r.status in (scene_mp.OK, scene_mp.CANNOT_ASSEMBLE), r

"""The mpmath reference of a scene with several drivers (dyadfmu.reference.scene_mp), on
modelDescription/scenes/leg.toml (two cranks, an RRR dyad, a foot load) and
tests/scenes/three_drivers.toml (a crank, a ram and a cylinder, two RRR dyads, a
follower force and moment), at points of their working ranges with nonzero rates,
accelerations and loads, at 50 digits:

- every body in equilibrium with its weight, its d'Alembert force and couple and the
  reactions the reference outputs: each driver's body, the cylinder's barrel and rod,
  every dyad link; the accelerations rebuilt here from the output angles, rates and pair
  points by rigid-body kinematics from the drivers' motion, to 1e-25 of the largest term;
- M (from the kinetic energy) symmetric and positive definite, and equal to the efforts'
  response to unit accelerations with velocities, gravity and loads off (a Newton-Euler
  route, symmetric only when the balances are right) to 1e-25;
- every effort = M q'' + h, h the torque0 / force0 outputs, to 1e-25;
- the outputs named as the spec says: M.<a>.<b> for every ordered pair, no J nor dJdq.
"""

from __future__ import annotations

import math

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
#: the rates, accelerations and loads, arbitrary and nonzero
LEG_MOTION = {"front.omega": 3.0, "front.epsilon": 10.0, "rear.omega": -2.0}
LEG_MOTION |= {"rear.epsilon": 5.0, "foot.force.x": 5.0, "foot.force.y": 30.0}
THREE_MOTION = {"wheel.omega": 2.0, "wheel.epsilon": -3.0, "slide.velocity": -0.3}
THREE_MOTION |= {"slide.acceleration": 0.5, "jack.velocity": 0.08, "jack.acceleration": -0.2}
THREE_MOTION |= {"tool.force.x": 10.0, "tool.force.y": -20.0, "tool.moment": 3.0}
CASES = [("leg", p) for p in LEG_POINTS] + [("three_drivers", p) for p in THREE_POINTS]
#: what turns every velocity, weight and load off
STILL = {
    "leg": {"gravity.y": 0.0, "foot.force.y": 0.0, "foot.force.x": 0.0},
    "three_drivers": {"gravity.y": 0.0, "tool.force.x": 0.0, "tool.force.y": 0.0},
}
STILL["three_drivers"]["tool.moment"] = 0.0


@pytest.fixture(autouse=True)
def _precision():
    """The checks' own arithmetic at 60 digits, beyond the outputs' 50."""
    with mpmath.workdps(DPS + 10):
        yield


def read(name: str) -> scene_mp.MechanismScene:
    return scene_mp.read_scene(scene_file(name))


def values_at(name: str, point: tuple) -> dict:
    """The inputs: the drivers' coordinates at ``point``, rates, accelerations and loads."""
    scene = read(name)
    coords = [d.motion(True)[0] for d in scene.drivers]
    motion = LEG_MOTION if name == "leg" else THREE_MOTION
    return {**dict(zip(coords, point, strict=True)), **motion}


def evaluate(name: str, values: dict) -> dict:
    r = scene_mp.evaluate(read(name), values, dps=DPS)
    assert r.status == scene_mp.OK, (name, values, r.reason)
    return r.outputs


# ---------------------------------------------------------------------------
# rigid-body kinematics from the outputs
# ---------------------------------------------------------------------------
def vec(out: dict, name: str) -> tuple:
    return (mpf(out[f"{name}.x"]), mpf(out[f"{name}.y"]))


def add(*vs):
    return (sum(v[0] for v in vs), sum(v[1] for v in vs))


def scale(s, v):
    return (s * v[0], s * v[1])


def perp(v):
    return (-v[1], v[0])


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


class Body:
    """A body's origin (position, acceleration) and its angle, omega, epsilon."""

    def __init__(self, origin, accel, angle, omega, epsilon):
        self.origin, self.accel = origin, accel
        self.i = (mpmath.cos(angle), mpmath.sin(angle))
        self.omega, self.epsilon = mpf(omega), mpf(epsilon)

    def arm(self, local):
        return add(scale(local[0], self.i), scale(local[1], perp(self.i)))

    def at(self, local):
        """(position, acceleration) of the body's point ``local``."""
        r = self.arm(local)
        acc = add(self.accel, scale(self.epsilon, perp(r)), scale(-(self.omega**2), r))
        return add(self.origin, r), acc


def link(out: dict, g: str, origin: tuple, accel: tuple) -> Body:
    """A dyad link from its output angle and rates, its origin D and D's acceleration."""
    return Body(origin, accel, out[f"{g}.angle"], out[f"{g}.omega"], out[f"{g}.epsilon"])


def crank(scene, values, c: str) -> Body:
    p = scene.parameters
    at = (mpf(p[f"{c}.at.x"]), mpf(p[f"{c}.at.y"]))
    motion = (values[f"{c}.{k}"] for k in ("angle", "omega", "epsilon"))
    return Body(at, (mpf(0), mpf(0)), *motion)


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


def minus(v):
    return (-v[0], -v[1])


def leg_balances(scene, values, out) -> dict:
    g = (mpf(0), mpf(-9.81))
    cranks = {c: crank(scene, values, c) for c in ("front", "rear")}
    pins = {c: b.at((mpf(scene.parameters[f"{c}.length"]), mpf(0))) for c, b in cranks.items()}
    shank_m = link(out, "front_shank", vec(out, "knees.D_m.position"), pins["front"][1])
    shank_n = link(out, "rear_shank", vec(out, "knees.D_n.position"), pins["rear"][1])
    e = vec(out, "knees.E.position")
    bal = {}
    for c, body in cranks.items():
        b = bal[c] = Balance()
        b.force(body.origin, vec(out, f"{c}.R_O"))
        pair = "R_mk" if c == "front" else "R_np"
        b.force(pins[c][0], minus(vec(out, f"knees.{pair}")))
        b.couple(out[f"{c}.torque"])
        b.mass(scene, c, body.at(_com(scene, c)), body.epsilon, g)
    b = bal["front_shank"] = Balance()
    b.force(shank_m.origin, vec(out, "knees.R_mk"))
    b.force(e, vec(out, "knees.R_mn"))
    b.force(
        shank_m.at(_local(scene, "foot.at"))[0], (values["foot.force.x"], values["foot.force.y"])
    )
    b.mass(scene, "front_shank", shank_m.at(_com(scene, "front_shank")), shank_m.epsilon, g)
    b = bal["rear_shank"] = Balance()
    b.force(shank_n.origin, vec(out, "knees.R_np"))
    b.force(e, minus(vec(out, "knees.R_mn")))
    b.mass(scene, "rear_shank", shank_n.at(_com(scene, "rear_shank")), shank_n.epsilon, g)
    return bal


def _local(scene, name: str) -> tuple:
    p = scene.parameters
    return (mpf(p[f"{name}.x"]), mpf(p[f"{name}.y"]))


def _com(scene, name: str) -> tuple:
    return _local(scene, f"{name}.com")


def three_bodies(scene, values, out) -> dict:
    """Every moving body of three_drivers, its acceleration chained from the drivers."""
    p = scene.parameters
    zero = (mpf(0), mpf(0))
    wheel = crank(scene, values, "wheel")
    x, xdd = mpf(values["slide.position"]), mpf(values["slide.acceleration"])
    slide = Body(add(_local(scene, "slide.at"), (x, mpf(0))), (xdd, mpf(0)), 0, 0, 0)
    arm = link(out, "arm", _local(scene, "arm.at"), zero)
    coupler = link(
        out, "coupler", vec(out, "tie.D_m.position"), wheel.at((mpf(p["wheel.length"]), 0))[1]
    )
    rocker = link(out, "rocker", vec(out, "tie.D_n.position"), arm.at(_local(scene, "tie.D_n"))[1])
    hanger = link(
        out, "hanger", vec(out, "hang.D_m.position"), coupler.at(_local(scene, "hang.D_m"))[1]
    )
    strut = link(out, "strut", vec(out, "hang.D_n.position"), slide.accel)
    return dict(
        wheel=wheel,
        slide=slide,
        arm=arm,
        coupler=coupler,
        rocker=rocker,
        hanger=hanger,
        strut=strut,
    )


def cylinder_parts(scene, values, out) -> dict:
    """The barrel and the rod as (centre of mass, its acceleration), the axis u, its
    epsilon: the rod's point at x = s - c from A slides at s', s''."""
    p = scene.parameters
    s, v, a = (mpf(values[f"jack.{k}"]) for k in ("length", "velocity", "acceleration"))
    w, e = mpf(out["jack.omega"]), mpf(out["jack.epsilon"])
    u = (mpmath.cos(out["jack.angle"]), mpmath.sin(out["jack.angle"]))
    base = _local(scene, "jack.base")

    def point(x, x1, x2):
        acc = add(scale(x2 - x * w * w, u), scale(2 * x1 * w + x * e, perp(u)))
        return add(base, scale(x, u)), acc

    barrel = point(mpf(p["jack.barrel.com"]), 0, 0)
    rod = point(s - mpf(p["jack.rod.com"]), v, a)
    return {"barrel": barrel, "rod": rod, "u": u, "epsilon": e}


def three_balances(scene, values, out) -> dict:
    g = (mpf(0), mpf(-9.81))
    b_ = three_bodies(scene, values, out)
    cyl = cylinder_parts(scene, values, out)
    bal = {name: Balance() for name in ("wheel", "slide", "arm", "barrel", "rod")}
    bal.update({name: Balance() for name in ("coupler", "rocker", "hanger", "strut")})
    # the crank
    wheel = b_["wheel"]
    bal["wheel"].force(wheel.origin, vec(out, "wheel.R_O"))
    bal["wheel"].force(vec(out, "tie.D_m.position"), minus(vec(out, "tie.R_mk")))
    bal["wheel"].couple(out["wheel.torque"])
    bal["wheel"].mass(scene, "wheel", wheel.at(_com(scene, "wheel")), wheel.epsilon, g)
    # the ram: the actuator's force along i, the guide's N along j and M about R
    slide = bal["slide"]
    slide.force(b_["slide"].origin, (out["slide.force"], out["slide.N"]))
    slide.couple(out["slide.M"])
    slide.force(vec(out, "hang.D_n.position"), minus(vec(out, "hang.R_np")))
    slide.mass(scene, "slide", b_["slide"].at(_com(scene, "slide")), 0, g)
    # the cylinder: barrel, rod, arm
    u, b_pin = cyl["u"], vec(out, "jack.B.position")
    along = add(scale(out["jack.force"], u), scale(out["jack.N"], perp(u)))  # on the rod
    bal["barrel"].force(_local(scene, "jack.base"), vec(out, "jack.R_A"))
    bal["barrel"].force(b_pin, minus(along))
    bal["barrel"].couple(-out["jack.M"])
    bal["barrel"].mass(scene, "jack.barrel", cyl["barrel"], cyl["epsilon"], g)
    bal["rod"].force(b_pin, along)
    bal["rod"].couple(out["jack.M"])
    bal["rod"].force(b_pin, minus(vec(out, "jack.R_B")))
    bal["rod"].mass(scene, "jack.rod", cyl["rod"], cyl["epsilon"], g)
    arm = b_["arm"]
    bal["arm"].force(arm.origin, vec(out, "arm.R_O"))
    bal["arm"].force(b_pin, vec(out, "jack.R_B"))
    bal["arm"].force(vec(out, "tie.D_n.position"), minus(vec(out, "tie.R_np")))
    bal["arm"].mass(scene, "arm", arm.at(_com(scene, "arm")), arm.epsilon, g)
    # the dyads' links
    for dyad, m, n in (("tie", "coupler", "rocker"), ("hang", "hanger", "strut")):
        e = vec(out, f"{dyad}.E.position")
        bal[m].force(vec(out, f"{dyad}.D_m.position"), vec(out, f"{dyad}.R_mk"))
        bal[m].force(e, vec(out, f"{dyad}.R_mn"))
        bal[n].force(vec(out, f"{dyad}.D_n.position"), vec(out, f"{dyad}.R_np"))
        bal[n].force(e, minus(vec(out, f"{dyad}.R_mn")))
        for g_ in (m, n):
            body = b_[g_]
            bal[g_].mass(scene, g_, body.at(_com(scene, g_)), body.epsilon, g)
    bal["coupler"].force(vec(out, "hang.D_m.position"), minus(vec(out, "hang.R_mk")))
    hanger = b_["hanger"]
    tool = hanger.arm((mpf(values["tool.force.x"]), mpf(values["tool.force.y"])))  # follower
    bal["hanger"].force(hanger.at(_local(scene, "tool.at"))[0], tool)
    bal["hanger"].couple(values["tool.moment"])
    return bal


# ---------------------------------------------------------------------------
# the tests
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(("name", "point"), CASES)
def test_every_body_is_in_equilibrium(name, point):
    """Each body's forces and moments, d'Alembert's included, sum to zero to 1e-25 of
    their largest term."""
    scene, values = read(name), values_at(name, point)
    out = evaluate(name, values)
    balances = (leg_balances if name == "leg" else three_balances)(scene, values, out)
    worst = max((b.residual(), body) for body, b in balances.items())
    assert worst[0] < TOL, (name, point, worst)


def matrix_of(scene, out) -> mpmath.matrix:
    names = [d.name for d in scene.drivers]
    return mpmath.matrix([[out[f"M.{a}.{b}"] for b in names] for a in names])


def response_matrix(name: str, values: dict) -> mpmath.matrix:
    """Column b: the efforts at zero velocities, gravity and loads with driver b's
    acceleration 1 and the others' 0."""
    scene = read(name)
    still = dict(values, **STILL[name])
    rates = [n for d in scene.drivers for n in d.motion(True)[1:]]
    still.update(dict.fromkeys(rates, 0.0))
    columns = []
    for d in scene.drivers:
        out = evaluate(name, {**still, d.motion(True)[2]: 1.0})
        columns.append([out[f"{e.name}.{e.effort}"] for e in scene.drivers])
    n = len(columns)
    return mpmath.matrix([[columns[b][a] for b in range(n)] for a in range(n)])


def largest(m: mpmath.matrix) -> mpf:
    return max(abs(m[i, j]) for i in range(m.rows) for j in range(m.cols))


@pytest.mark.parametrize(("name", "point"), CASES)
def test_inertia_matrix_is_symmetric_positive_definite_and_the_efforts_response(name, point):
    """M symmetric, positive definite (Cholesky), and equal to the efforts' response to
    unit accelerations (itself symmetric) to 1e-25 of its largest entry."""
    scene, values = read(name), values_at(name, point)
    m = matrix_of(scene, evaluate(name, values))
    k = response_matrix(name, values)
    size = largest(m)
    assert largest(m - m.T) / size < TOL
    assert largest(k - k.T) / size < TOL, (name, point, largest(k - k.T) / size)
    assert largest(k - m) / size < TOL, (name, point, largest(k - m) / size)
    lower = mpmath.cholesky(m)  # ValueError unless positive definite
    assert min(lower[i, i] for i in range(m.rows)) > 0
    eigen = mpmath.eigsy(m)[0]
    assert min(eigen) > size * mpf(10) ** -6, (name, point, eigen)


@pytest.mark.parametrize(("name", "point"), CASES)
def test_efforts_are_inertia_times_accelerations_plus_h(name, point):
    """Every effort = sum_b M_ab q''_b + effort0_a to 1e-25 of the largest term."""
    scene, values = read(name), values_at(name, point)
    out = evaluate(name, values)
    qdd = [mpf(values[d.motion(True)[2]]) for d in scene.drivers]
    for a in scene.drivers:
        terms = [out[f"M.{a.name}.{b.name}"] * x for b, x in zip(scene.drivers, qdd, strict=True)]
        h, effort = out[f"{a.name}.{a.effort}0"], out[f"{a.name}.{a.effort}"]
        size = max([abs(h), abs(effort)] + [abs(t) for t in terms])
        assert abs(effort - sum(terms) - h) / size < TOL, (name, point, a.name)
        assert abs(h - effort) > size * mpf(10) ** -6  # the accelerations do count


@pytest.mark.parametrize("name", ["leg", "three_drivers"])
def test_outputs_are_named_as_the_spec_says(name):
    scene = read(name)
    out = evaluate(name, values_at(name, (LEG_POINTS if name == "leg" else THREE_POINTS)[0]))
    names = [d.name for d in scene.drivers]
    assert {k for k in out if k.startswith("M.")} == {f"M.{a}.{b}" for a in names for b in names}
    assert not [k for k in out if k.endswith((".J", ".dJdq"))]
    for d in scene.drivers:
        assert {f"{d.name}.{d.effort}", f"{d.name}.{d.effort}0"} <= set(out)
        assert set(d.motion(True)) <= set(scene.inputs)
    kinds = {"leg": ["crank", "crank"], "three_drivers": ["crank", "ram", "cylinder"]}
    assert [d.kind for d in scene.drivers] == kinds[name]

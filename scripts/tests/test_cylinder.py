"""The cylinder between two pins (src/dyad_cylinder.c) against an independent NumPy
solve: the triangle by the law of cosines, the rates by linear solves of the loop's
velocity and acceleration, and the nine unknowns (R_A, R_B, R_O, the axial force, the
barrel-rod normal force and moment) from the 9 x 9 Newton-Euler system of the three
bodies with moments about their centres of mass. Through ctypes on the double core."""

import ctypes
import math

import mpmath
import numpy as np
import pytest
from dyadfmu.core import library_path

pytestmark = pytest.mark.skipif(
    not library_path().is_file(), reason=f"C core not built at {library_path()}"
)

EPS = np.finfo(float).eps
OK, SINGULAR, CANNOT_ASSEMBLE = 0, 1, 4


class Vec2(ctypes.Structure):
    _fields_ = [("x", ctypes.c_double), ("y", ctypes.c_double)]


class PointMotion(ctypes.Structure):
    _fields_ = [("position", Vec2), ("velocity", Vec2), ("acceleration", Vec2)]


class Part(ctypes.Structure):
    _fields_ = [("mass", ctypes.c_double), ("com", ctypes.c_double), ("inertia", ctypes.c_double)]


class Link(ctypes.Structure):
    _fields_ = [
        ("mass", ctypes.c_double),
        ("com", Vec2),
        ("inertia", ctypes.c_double),
        ("force", Vec2),
        ("moment", ctypes.c_double),
    ]


class Input(ctypes.Structure):
    _fields_ = [
        ("a", PointMotion),
        ("o", PointMotion),
        ("pin_b", Vec2),
        ("length", ctypes.c_double),
        ("rate", ctypes.c_double),
        ("accel", ctypes.c_double),
        ("branch", ctypes.c_int),
        ("barrel", Part),
        ("rod", Part),
        ("link", Link),
        ("gravity", Vec2),
        ("singular_threshold", ctypes.c_double),
        ("mount_amplification", ctypes.c_double),
    ]


class Result(ctypes.Structure):
    _fields_ = [
        ("status", ctypes.c_int),
        ("field", ctypes.c_int),
        ("failure", ctypes.c_int),
        ("gap", ctypes.c_double),
        ("link_dir", Vec2),
        ("link_angle", ctypes.c_double),
        ("link_omega", ctypes.c_double),
        ("link_epsilon", ctypes.c_double),
        ("axis", Vec2),
        ("cylinder_angle", ctypes.c_double),
        ("cylinder_omega", ctypes.c_double),
        ("cylinder_epsilon", ctypes.c_double),
        ("b", PointMotion),
        ("barrel_com", PointMotion),
        ("rod_com", PointMotion),
        ("link_com", PointMotion),
        ("axial_force", ctypes.c_double),
        ("r_a", Vec2),
        ("r_b", Vec2),
        ("r_o", Vec2),
        ("n_rod", ctypes.c_double),
        ("m_rod", ctypes.c_double),
        ("conditioning", ctypes.c_double),
        ("closure", ctypes.c_double),
        ("kin_amplification", ctypes.c_double),
        ("amplification", ctypes.c_double),
    ]


@pytest.fixture(scope="module")
def lib():
    found = ctypes.CDLL(str(library_path()))
    found.dyad_cylinder_input_default.restype = Input
    found.dyad_cylinder.argtypes = [ctypes.POINTER(Input), ctypes.POINTER(Result)]
    found.dyad_cylinder.restype = ctypes.c_int
    found.dyad_cylinder_field_name.argtypes = [ctypes.c_int]
    found.dyad_cylinder_field_name.restype = ctypes.c_char_p
    return found


class Backend:
    """The arithmetic of a reference: NumPy in double, or mpmath at 40 digits on NumPy
    arrays of mpf (the same formulas, the solves by LU)."""

    def __init__(self, num, solve, scalar):
        self.num, self.solve, self.scalar = num, solve, scalar

    def vec(self, x, y):
        return np.array(
            [self.scalar(x), self.scalar(y)], dtype=object if self.num is mpmath else float
        )


def _mp_solve(k, f):
    return np.array(list(mpmath.lu_solve(mpmath.matrix(k.tolist()), mpmath.matrix(list(f)))))


DOUBLE = Backend(math, np.linalg.solve, float)
MP = Backend(mpmath, _mp_solve, mpmath.mpf)


def v2(a, bk=DOUBLE):
    return bk.vec(a.x, a.y)


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def perp(a):
    return np.array([-a[1], a[0]])


def rot(angle, bk=DOUBLE):
    return bk.vec(bk.num.cos(angle), bk.num.sin(angle))


def random_case(rng, lib):
    """A random cylinder, A and O moving, as the C input and as plain numbers."""
    c = lib.dyad_cylinder_input_default()
    rb, s = rng.uniform(0.3, 1.5), rng.uniform(0.5, 2.0)
    lo, hi = abs(rb - s), rb + s
    dist = lo + (hi - lo) * rng.uniform(0.15, 0.85)
    o = rng.uniform(-1, 1, 2)
    a = o + dist * rot(rng.uniform(-math.pi, math.pi))
    for name, value in (("o", o), ("a", a)):
        point = getattr(c, name)
        point.position = Vec2(*value)
        point.velocity = Vec2(*rng.uniform(-2, 2, 2))
        point.acceleration = Vec2(*rng.uniform(-5, 5, 2))
    c.pin_b = Vec2(*(rb * rot(rng.uniform(-math.pi, math.pi))))
    c.length, c.rate, c.accel = s, rng.uniform(-1, 1), rng.uniform(-3, 3)
    c.branch = int(rng.choice([-1, 1]))
    c.barrel = Part(rng.uniform(0, 20), rng.uniform(-0.1, 0.6), rng.uniform(0, 2))
    c.rod = Part(rng.uniform(0, 10), rng.uniform(-0.1, 0.6), rng.uniform(0, 1))
    c.link = Link(
        rng.uniform(0, 50),
        Vec2(*rng.uniform(-1, 1, 2)),
        rng.uniform(0, 5),
        Vec2(*rng.uniform(-500, 500, 2)),
        rng.uniform(-200, 200),
    )
    c.gravity = Vec2(*rng.uniform(-10, 10, 2))
    return c


def reference_motion(c, bk=DOUBLE):
    """The motion by the law of cosines and two linear solves."""
    num, p = bk.num, bk.scalar
    o, a = v2(c.o.position, bk), v2(c.a.position, bk)
    rb, s = num.sqrt(p(c.pin_b.x) ** 2 + p(c.pin_b.y) ** 2), p(c.length)
    d = a - o
    dist = num.sqrt(d[0] ** 2 + d[1] ** 2)
    alpha = num.acos((rb**2 + dist**2 - s**2) / (2 * rb * dist))
    e = rot(num.atan2(d[1], d[0]) + c.branch * alpha, bk)  # O towards B
    b = o + rb * e
    u = (b - a) / s
    cols = np.column_stack([rb * perp(e), -s * perp(u)])
    w_l, w_c = bk.solve(cols, v2(c.a.velocity, bk) + p(c.rate) * u - v2(c.o.velocity, bk))
    rhs = (
        v2(c.a.acceleration, bk)
        + p(c.accel) * u
        + 2 * p(c.rate) * w_c * perp(u)
        - s * w_c**2 * u
        - v2(c.o.acceleration, bk)
        + rb * w_l**2 * e
    )
    e_l, e_c = bk.solve(cols, rhs)
    i_l = rot(num.atan2(e[1], e[0]) - num.atan2(p(c.pin_b.y), p(c.pin_b.x)), bk)
    return {"o": o, "a": a, "b": b, "e": e, "u": u, "i_l": i_l, "w": (w_l, w_c, e_l, e_c)}


def point_accel(base_acc, q, w, eps):
    """Acceleration of base + q on a body turning at w, eps."""
    return base_acc + eps * perp(q) - w**2 * q


def body_terms(c, m, bk=DOUBLE):
    """Each body's centre of mass, its acceleration and the applied load (weight,
    active load) as (mass, com, a_com, J, epsilon, force, moment)."""
    w_l, w_c, e_l, e_c = m["w"]
    p = bk.scalar
    u, i_l, g = m["u"], m["i_l"], v2(c.gravity, bk)
    q_l = p(c.link.com.x) * i_l + p(c.link.com.y) * perp(i_l)
    a_a, a_o = v2(c.a.acceleration, bk), v2(c.o.acceleration, bk)
    a_b = point_accel(a_o, m["b"] - m["o"], w_l, e_l)
    q_c = p(c.barrel.com) * u
    bodies = {
        "barrel": (c.barrel, m["a"] + q_c, point_accel(a_a, q_c, w_c, e_c), e_c),
        "rod": (
            c.rod,
            m["b"] - p(c.rod.com) * u,
            point_accel(a_b, -p(c.rod.com) * u, w_c, e_c),
            e_c,
        ),
        "link": (c.link, m["o"] + q_l, point_accel(a_o, q_l, w_l, e_l), e_l),
    }
    out = {}
    for name, (part, com, acc, eps) in bodies.items():
        force = p(part.mass) * g + (v2(c.link.force, bk) if name == "link" else 0)
        moment = p(c.link.moment) if name == "link" else p(0)
        out[name] = (p(part.mass), com, acc, p(part.inertia), eps, force, moment)
    return out


def reference_reactions(c, m, bk=DOUBLE):
    """The nine unknowns x = [R_A, R_B, R_O, F_ax, N, M] from K x = f: per body its
    forces and its moment about its own centre of mass, m a = sum F, J eps = sum M."""
    u, j, a, b, o = m["u"], perp(m["u"]), m["a"], m["b"], m["o"]
    bodies = body_terms(c, m, bk)
    kind = object if bk is MP else float
    k, f = np.zeros((9, 9), dtype=kind) + bk.scalar(0), np.zeros(9, dtype=kind) + bk.scalar(0)
    # Each force acting on a body: (body, point, column, 2 x 1 direction or identity).
    rows = {"barrel": 0, "rod": 3, "link": 6}
    eye = np.eye(2)
    acts = [
        ("barrel", a, slice(0, 2), eye),  # R_A
        ("barrel", b, slice(6, 7), -u[:, None]),  # -F_ax u
        ("barrel", b, slice(7, 8), -j[:, None]),  # -N j
        ("rod", b, slice(6, 7), u[:, None]),
        ("rod", b, slice(7, 8), j[:, None]),
        ("rod", b, slice(2, 4), -eye),  # -R_B
        ("link", b, slice(2, 4), eye),  # R_B
        ("link", o, slice(4, 6), eye),  # R_O
    ]
    for body, at, cols, direction in acts:
        row, lever = rows[body], at - bodies[body][1]
        k[row : row + 2, cols] += direction
        k[row + 2, cols] += lever[0] * direction[1] - lever[1] * direction[0]
    k[0 + 2, 8] -= 1.0  # the rod's moment on the barrel
    k[3 + 2, 8] += 1.0
    for body, row in rows.items():
        mass, _, acc, inertia, eps, force, moment = bodies[body]
        f[row : row + 2] = mass * acc - force
        f[row + 2] = inertia * eps - moment
    return bk.solve(k, f)


def solve_c(lib, c):
    r = Result()
    status = lib.dyad_cylinder(ctypes.byref(c), ctypes.byref(r))
    return status, r


def scaled_errors(c, r, bk=DOUBLE):
    """The C outputs against the reference, in eps x amplification of their unit's
    largest output: motion (kin_amplification) and forces, moment (amplification)."""
    m = reference_motion(c, bk)
    x = np.array([float(v) for v in reference_reactions(c, m, bk)])
    m = {key: np.array([float(v) for v in value]) for key, value in m.items()}
    forces_c = np.array([*v2(r.r_a), *v2(r.r_b), *v2(r.r_o), r.axial_force, r.n_rod])
    forces_ref = x[:8]
    angles = np.array([*v2(r.link_dir), *v2(r.axis), *v2(r.b.position)])
    angles_ref = np.array([*m["i_l"], *m["u"], *m["b"]])
    rates = np.array([r.link_omega, r.cylinder_omega])
    rates_ref = np.array(m["w"][:2])
    accels = np.array([r.link_epsilon, r.cylinder_epsilon])
    accels_ref = np.array(m["w"][2:])

    def worst(got, want, amp):
        return np.max(np.abs(got - want)) / (EPS * amp * np.max(np.abs(want)))

    return {
        "position": worst(angles, angles_ref, r.kin_amplification),
        "rate": worst(rates, rates_ref, r.kin_amplification),
        "accel": worst(accels, accels_ref, r.kin_amplification),
        "force": worst(forces_c, forces_ref, r.amplification),
        "moment": abs(r.m_rod - x[8]) / (EPS * r.amplification * max(abs(x[8]), 1e-300)),
    }


def test_matches_numpy_newton_euler(lib):
    rng = np.random.default_rng(35)
    worst = dict.fromkeys(("position", "rate", "accel", "force", "moment"), 0.0)
    for _ in range(3000):
        c = random_case(rng, lib)
        status, r = solve_c(lib, c)
        assert status == OK, lib.dyad_cylinder_field_name(r.field)
        for key, value in scaled_errors(c, r).items():
            worst[key] = max(worst[key], value)
    print("worst error in eps x amplification:", {k: f"{v:.3g}" for k, v in worst.items()})
    assert max(worst.values()) < 16, worst


def test_random_cases_match_mpmath(lib):
    """The same random cylinders against the 40-digit reference: what is left is the C
    core's own round-off, without the double reference's."""
    rng = np.random.default_rng(35)
    worst = dict.fromkeys(("position", "rate", "accel", "force", "moment"), 0.0)
    with mpmath.workdps(40):
        for _ in range(300):
            c = random_case(rng, lib)
            status, r = solve_c(lib, c)
            assert status == OK
            for key, value in scaled_errors(c, r, MP).items():
                worst[key] = max(worst[key], value)
    print(
        "against mpmath, worst in eps x amplification:", {k: f"{v:.3g}" for k, v in worst.items()}
    )
    assert max(worst.values()) < 16, worst


def test_static_lever_by_hand(lib):
    """A weightless cylinder holding a horizontal lever: O at the origin, B at (1, 0),
    A at (1, -1), a load of 100 N down at the lever's end (2, 0). Moments about O:
    F_ax = 200 N, pushing B upwards (the cylinder extends against the load)."""
    c = lib.dyad_cylinder_input_default()
    c.a.position = Vec2(1, -1)
    c.pin_b = Vec2(1, 0)
    c.length = 1.0
    c.branch = 1
    c.link.com = Vec2(2, 0)
    c.link.force = Vec2(0, -100)
    status, r = solve_c(lib, c)
    assert status == OK
    assert r.axial_force == pytest.approx(200, rel=1e-14)
    assert (r.r_o.x, r.r_o.y) == pytest.approx((0, -100), abs=1e-12)
    assert (r.r_a.x, r.r_a.y) == pytest.approx((0, 200), abs=1e-12)
    assert r.link_angle == pytest.approx(0, abs=1e-15)
    assert r.cylinder_angle == pytest.approx(math.pi / 2, rel=1e-15)


def test_beyond_the_stroke_names_the_gap(lib):
    c = lib.dyad_cylinder_input_default()
    c.a.position = Vec2(1, 0)
    c.pin_b = Vec2(0.5, 0)
    c.length = 1.6
    status, r = solve_c(lib, c)
    assert status == CANNOT_ASSEMBLE
    assert r.gap == pytest.approx(0.1, rel=1e-12)
    assert math.isnan(r.axial_force)
    c.length = 1.5 - 1e-10
    status, r = solve_c(lib, c)
    assert status == SINGULAR and r.conditioning < 1e-4


def test_matches_mpmath_on_the_way_to_both_toggles(lib):
    """Closing on a toggle (O, A, B in line, either way) from 1e-2 to 1e-15 of the
    triangle's size: every output with status ok within 16 eps x amplification of the
    40-digit reference; once not, singular (never a wrong number)."""
    rng = np.random.default_rng(3535)
    worst = dict.fromkeys(("position", "rate", "accel", "force", "moment"), 0.0)
    statuses = set()
    with mpmath.workdps(40):
        for _ in range(40):
            c = random_case(rng, lib)
            rb = math.hypot(c.pin_b.x, c.pin_b.y)
            dist = math.dist((c.a.position.x, c.a.position.y), (c.o.position.x, c.o.position.y))
            upper = rng.uniform() < 0.5  # the longest stroke, or the shortest
            end, inward = (rb + dist, -1.0) if upper else (abs(dist - rb), 1.0)
            for k in range(2, 16):
                c.length = end + inward * 10.0**-k
                if c.length <= 0:
                    continue
                status, r = solve_c(lib, c)
                statuses.add(status)
                if status != OK:
                    assert status == SINGULAR, status
                    continue
                for key, value in scaled_errors(c, r, MP).items():
                    worst[key] = max(worst[key], value)
    print(
        "near the toggles, worst in eps x amplification:", {k: f"{v:.3g}" for k, v in worst.items()}
    )
    assert statuses == {OK, SINGULAR}
    assert max(worst.values()) < 16, worst

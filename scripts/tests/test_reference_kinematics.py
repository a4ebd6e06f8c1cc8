"""The mpmath kinematics reference of the dyads (dyadfmu.reference.dyad_kinematics) checked
against hand-computed mechanisms, position differences and its own invariances."""

import math
import random
from dataclasses import replace

import mpmath
import pytest
from dyadfmu.reference.dyad_kinematics import (
    CANNOT_ASSEMBLE,
    POINTS,
    SINGULAR,
    TYPES,
    DyadInputs,
    Mount,
    as_floats,
    configuration,
    derivative,
    solve,
)

mpf = mpmath.mpf
SLIDES_K = ("RRT", "TRT", "RTT")  # D_m slides on a guide of k


@pytest.fixture(autouse=True)
def high_precision():
    """The tests' own arithmetic at 60 digits (the reference sets its own precision)."""
    with mpmath.workdps(60):
        yield


def random_mount(rng, position, angle):
    return Mount(
        position=position,
        velocity=(rng.uniform(-1, 1), rng.uniform(-1, 1)),
        acceleration=(rng.uniform(-2, 2), rng.uniform(-2, 2)),
        direction=(math.cos(angle), math.sin(angle)),
        omega=rng.uniform(-1, 1),
        epsilon=rng.uniform(-2, 2),
    )


def assembled_case(dyad_type, seed, branch=1, with_figure=False):
    """Inputs built around a figure that closes: D_m, the link angles and lengths drawn
    (with the figure: E and the link angles and l_m it was built from)."""
    rng = random.Random(seed)
    d_m = (rng.uniform(-1, 1), rng.uniform(-1, 1))
    th_m = rng.uniform(-math.pi, math.pi)
    th_n = th_m + math.pi + rng.choice((-1, 1)) * rng.uniform(0.6, 2.2)  # away from folding
    l_m, l_n = rng.uniform(0.6, 1.6), rng.uniform(0.6, 1.6)
    e = (d_m[0] + l_m * math.cos(th_m), d_m[1] + l_m * math.sin(th_m))
    d_n = (e[0] - l_n * math.cos(th_n), e[1] - l_n * math.sin(th_n))
    th_k, th_p = rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi, math.pi)
    s_k, s_p = rng.uniform(-1, 1), rng.uniform(-1, 1)
    g_k = (d_m[0] - s_k * math.cos(th_k), d_m[1] - s_k * math.sin(th_k))
    g_p = (d_n[0] - s_p * math.cos(th_p), d_n[1] - s_p * math.sin(th_p))
    slides_k, slides_p = dyad_type in SLIDES_K, dyad_type == "TRT"
    k = random_mount(rng, g_k if slides_k else d_m, th_k)
    p = random_mount(rng, g_p if slides_p else d_n, th_p)
    turn_n = th_n - (th_p if slides_p else th_m)
    inputs = DyadInputs(
        dyad_type,
        k,
        p,
        length_m=l_m,
        length_n=l_n,
        turn_m=th_m - th_k,
        turn_n=turn_n,
        com_m=(rng.uniform(-0.5, 1), rng.uniform(-0.5, 0.5)),
        com_n=(rng.uniform(-0.5, 1), rng.uniform(-0.5, 0.5)),
        branch=branch,
    )
    return (
        (inputs, {"e": e, "angle_m": th_m, "angle_n": th_n, "l_m": l_m}) if with_figure else inputs
    )


def vec_close(a, b, tol):
    return all(abs(mpf(x) - mpf(y)) <= tol * (1 + abs(mpf(y))) for x, y in zip(a, b, strict=True))


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


@pytest.mark.parametrize("dyad_type", TYPES)
def test_closure_residuals_and_points(dyad_type):
    for branch in (1, -1):
        r = solve(assembled_case(dyad_type, 11, branch), dps=40)
        if r["status"] != "ok":  # RTR -1 may have no positive l_m; the other types must close
            assert dyad_type == "RTR" and branch == -1
            continue
        assert r["residual"] < 1e-30
        i_m, i_n = r["i_m"], r["i_n"]
        e_from_m = [r["m.d.position"][c] + r["l_m"] * i_m[c] for c in (0, 1)]
        e_from_n = [r["n.d.position"][c] + r["l_n"] * i_n[c] for c in (0, 1)]
        assert vec_close(e_from_m, r["e.position"], 1e-30)
        assert vec_close(e_from_n, r["e.position"], 1e-30)
        assert abs(i_m[0] ** 2 + i_m[1] ** 2 - 1) < 1e-35
        assert abs(r["angle_m"] - mpmath.atan2(i_m[1], i_m[0])) < 1e-35


def same_angle(a, b, tol):
    turn = (mpf(a) - mpf(b)) % (2 * mpmath.pi)
    return min(turn, 2 * mpmath.pi - turn) < tol


def unit(angle):
    return (mpmath.cos(angle), mpmath.sin(angle))


def check_mounts(r, inputs):
    """The relations of the specification between the outputs and the mounts."""
    k, p, kind = inputs.k, inputs.p, inputs.type
    angle_k, angle_p = (mpmath.atan2(mpf(m.direction[1]), mpf(m.direction[0])) for m in (k, p))
    for g, com in (("m", inputs.com_m), ("n", inputs.com_n)):
        i = r[f"i_{g}"]
        d = r[f"{g}.d.position"]
        s = [d[c] + mpf(com[0]) * i[c] + mpf(com[1]) * (-i[1], i[0])[c] for c in (0, 1)]
        assert vec_close(r[f"{g}.s.position"], s, 1e-30)
    if kind in SLIDES_K:
        d_m = [mpf(k.position[c]) + r["s_k"] * unit(angle_k)[c] for c in (0, 1)]
        assert vec_close(r["m.d.position"], d_m, 1e-30)
        assert same_angle(r["angle_m"], angle_k + mpf(inputs.turn_m), 1e-30)
        assert abs(r["omega_m"] - mpf(k.omega)) < 1e-30
        assert abs(r["epsilon_m"] - mpf(k.epsilon)) < 1e-30
    else:
        assert vec_close(r["m.d.position"], k.position, 1e-30)
        assert vec_close(r["m.d.velocity"], k.velocity, 1e-30)
        assert vec_close(r["m.d.acceleration"], k.acceleration, 1e-30)
    if kind == "TRT":
        d_n = [mpf(p.position[c]) + r["s_p"] * unit(angle_p)[c] for c in (0, 1)]
        assert vec_close(r["n.d.position"], d_n, 1e-30)
        assert same_angle(r["angle_n"], angle_p + mpf(inputs.turn_n), 1e-30)
        assert abs(r["omega_n"] - mpf(p.omega)) < 1e-30
    else:
        assert vec_close(r["n.d.position"], p.position, 1e-30)
        assert vec_close(r["n.d.acceleration"], p.acceleration, 1e-30)
    if kind in ("RTR", "RTT"):
        assert same_angle(r["angle_n"], r["angle_m"] + mpf(inputs.turn_n), 1e-30)
        assert abs(r["epsilon_n"] - r["epsilon_m"]) < 1e-30


@pytest.mark.parametrize("dyad_type", TYPES)
def test_specification_relations_and_the_built_figure(dyad_type):
    inputs, figure = assembled_case(dyad_type, 13, with_figure=True)
    found = 0
    for branch in (1, -1):
        r = solve(replace(inputs, branch=branch), dps=40)
        if r["status"] != "ok":
            continue
        check_mounts(r, inputs)
        found += vec_close(r["e.position"], figure["e"], 1e-14) and all(
            same_angle(r[a], figure[a], 1e-14) for a in ("angle_m", "angle_n")
        )
    assert found >= 1 if dyad_type in ("RRR", "RRT", "RTR") else found == 2


def test_branch_rules():
    for seed in (1, 2):
        plus, minus = (solve(assembled_case("RRR", seed, b), dps=30) for b in (1, -1))
        for r, sign in ((plus, 1), (minus, -1)):
            d = [r["n.d.position"][c] - r["m.d.position"][c] for c in (0, 1)]
            e = [r["e.position"][c] - r["m.d.position"][c] for c in (0, 1)]
            assert sign * cross(d, e) > 1e-3
        plus, minus = (solve(assembled_case("RRT", seed, b), dps=30) for b in (1, -1))
        assert plus["s_k"] > minus["s_k"] + 1e-3
        # a guide passing by the pin at a distance below l_n: both solutions real
        assert abs(plus["angle_n"] - minus["angle_n"]) > 1e-3
    # RTR with l_n > |D_m D_n| and cos(turn_n) > 0: both solutions have l_m > 0
    k, p = Mount((0, 0)), Mount((0.5, 0.2))
    rtr = [DyadInputs("RTR", k, p, length_n=1.0, turn_n=0.4, branch=b) for b in (1, -1)]
    plus, minus = (solve(x, dps=30) for x in rtr)
    assert plus["l_m"] > minus["l_m"] > 1e-3
    assert minus["residual"] < 1e-25
    tn = mpf(0.4)  # the float the inputs hold
    for r in (plus, minus):  # i_n = turn_n (x) i_m
        assert abs(r["angle_n"] - r["angle_m"] - tn) % (2 * mpmath.pi) < 1e-25


def finite_difference_rates_of(values, h):
    minus, mid, plus = values
    return (plus - minus) / (2 * h), (plus - 2 * mid + minus) / (h * h)


@pytest.mark.parametrize("dyad_type", TYPES)
def test_rates_match_position_differences(dyad_type):
    inputs = assembled_case(dyad_type, 5)
    r = solve(inputs, dps=40)
    h = mpf("1e-12")
    with mpmath.workdps(50):
        figures = [configuration(inputs, t, dps=50) for t in (-h, 0, h)]
    pairs = [("angle_m", "omega_m", "epsilon_m"), ("angle_n", "omega_n", "epsilon_n")]
    pairs += [("l_m", "l_m_dot", "l_m_ddot")]
    pairs += [(s, f"{s}_dot", f"{s}_ddot") for s in ("s_k", "s_p") if s in r]
    pairs += [(f"{pt}.position", f"{pt}.velocity", f"{pt}.acceleration") for pt in POINTS]
    for pos, vel, acc in pairs:
        values = [f[pos] for f in figures]
        comps = range(2) if isinstance(values[0], tuple) else [None]
        for c in comps:
            series = [v if c is None else v[c] for v in values]
            rate, accel = finite_difference_rates_of(series, h)
            want_v = r[vel] if c is None else r[vel][c]
            want_a = r[acc] if c is None else r[acc][c]
            assert abs(rate - want_v) < 1e-18 * (1 + abs(want_v)), (pos, c, rate, want_v)
            assert abs(accel - want_a) < 1e-18 * (1 + abs(want_a)), (pos, c, accel, want_a)


@pytest.mark.parametrize("dyad_type", TYPES)
def test_implicit_and_findroot_routes_agree(dyad_type):
    inputs = assembled_case(dyad_type, 7)
    a, b = solve(inputs, dps=30), solve(inputs, dps=30, method="findroot")
    for key, value in a.items():
        if isinstance(value, tuple):
            assert vec_close(value, b[key], 1e-25), key
        elif isinstance(value, mpmath.mpf) and key != "residual":
            assert abs(value - b[key]) < 1e-25 * (1 + abs(value)), key


def test_precision_converges():
    inputs = assembled_case("RRT", 3)
    low, high = solve(inputs, dps=30), solve(inputs, dps=60)
    for key, value in low.items():
        if isinstance(value, tuple):
            assert vec_close(value, high[key], 1e-27), key


def test_four_bar_by_the_law_of_cosines():
    """Crank a = 2 about O2 = (0, 0) at 40 deg, coupler b = 5, rocker c = 4, O4 = (6, 0)."""
    with mpmath.workdps(40):
        a, b, c, d = mpf(2), mpf(5), mpf(4), mpf(6)
        th2, w2 = mpmath.radians(40), mpf(3)
        pin = (a * mpmath.cos(th2), a * mpmath.sin(th2))
        crank = Mount(
            pin,
            velocity=(-a * w2 * mpmath.sin(th2), a * w2 * mpmath.cos(th2)),
            acceleration=(-a * w2**2 * mpmath.cos(th2), -a * w2**2 * mpmath.sin(th2)),
        )
        f = mpmath.hypot(d - pin[0], -pin[1])  # diagonal A O4
        beta = mpmath.atan2(-pin[1], d - pin[0])  # direction A -> O4
        th3 = beta + mpmath.acos((b**2 + f**2 - c**2) / (2 * b * f))  # B left of A -> O4
        th4 = beta + mpmath.pi - mpmath.acos((c**2 + f**2 - b**2) / (2 * c * f))
        w3 = a * w2 * mpmath.sin(th4 - th2) / (b * mpmath.sin(th3 - th4))
        w4 = a * w2 * mpmath.sin(th2 - th3) / (c * mpmath.sin(th4 - th3))
    r = solve(DyadInputs("RRR", crank, Mount((d, 0)), length_m=b, length_n=c), dps=40)
    assert abs(r["angle_m"] - th3) < 1e-30
    assert abs(r["angle_n"] - (th4 - 2 * mpmath.pi)) % (2 * mpmath.pi) < 1e-30
    assert abs(r["omega_m"] - w3) < 1e-30
    assert abs(r["omega_n"] - w4) < 1e-30


@pytest.mark.parametrize("offset", [0, "0.3"])
def test_slider_crank_against_the_classical_closed_form(offset):
    r_, rod, e = mpf("0.5"), mpf("1.7"), mpf(offset)
    phi0, omega, alpha = mpf("0.9"), mpf(12), mpf(-5)

    def piston(t):
        phi = phi0 + omega * t + alpha * t * t / 2
        return r_ * mpmath.cos(phi) + mpmath.sqrt(rod**2 - (r_ * mpmath.sin(phi) - e) ** 2)

    with mpmath.workdps(40):
        pin = (r_ * mpmath.cos(phi0), r_ * mpmath.sin(phi0))
        tangent, normal = (-pin[1], pin[0]), (-pin[0], -pin[1])
        crank_pin = Mount(
            pin,
            velocity=(omega * tangent[0], omega * tangent[1]),
            acceleration=tuple(alpha * tangent[c] + omega**2 * normal[c] for c in (0, 1)),
        )
        frame_guide = Mount((0, e), direction=(1, 0))
        want = [mpmath.diff(piston, 0, n) for n in (0, 1, 2)]
    inputs = DyadInputs("RRT", frame_guide, crank_pin, length_m=0, length_n=rod, branch=1)
    got = solve(inputs, dps=40)
    for have, expected in zip(("s_k", "s_k_dot", "s_k_ddot"), want, strict=True):
        assert abs(got[have] - expected) < 1e-28, have
    assert vec_close(got["m.d.velocity"], (want[1], 0), 1e-28)


@pytest.mark.parametrize("dyad_type", ["RRR", "RRT", "TRT"])
def test_rigid_rotation_invariance(dyad_type):
    inputs = assembled_case(dyad_type, 21)
    with mpmath.workdps(40):
        alpha = mpf("0.7")
        ca, sa = mpmath.cos(alpha), mpmath.sin(alpha)

        def rot(v):
            return (ca * v[0] - sa * v[1], sa * v[0] + ca * v[1])

        def turned(m):
            return Mount(
                rot(m.position),
                rot(m.velocity),
                rot(m.acceleration),
                rot(m.direction),
                m.omega,
                m.epsilon,
            )

    rotated = DyadInputs(
        dyad_type, turned(inputs.k), turned(inputs.p), inputs.length_m, inputs.length_n,
        inputs.turn_m, inputs.turn_n, inputs.com_m, inputs.com_n, inputs.branch,
    )  # fmt: skip
    a, b = solve(inputs, dps=35), solve(rotated, dps=35)
    for key, value in a.items():
        if key.endswith((".position", ".velocity", ".acceleration")) or key in ("i_m", "i_n"):
            assert vec_close(rot(value), b[key], 1e-28), key
        elif key.startswith(("omega", "epsilon", "l_", "s_")):
            assert abs(value - b[key]) < 1e-28 * (1 + abs(value)), key
    turn = (b["angle_m"] - a["angle_m"] - alpha) % (2 * mpmath.pi)
    assert min(turn, 2 * mpmath.pi - turn) < 1e-28


def test_cannot_assemble():
    k, p = Mount((0, 0)), Mount((3, 0))
    assert solve(DyadInputs("RRR", k, p, 1.0, 1.5))["status"] == CANNOT_ASSEMBLE  # too far
    near = Mount((0.2, 0))
    assert solve(DyadInputs("RRR", k, near, 1.0, 1.5))["status"] == CANNOT_ASSEMBLE  # too near
    assert solve(DyadInputs("RRR", k, Mount((2.4, 0)), 1.0, 1.5), dps=20)["status"] == "ok"
    # RTR: the distance of the pins below l_n |sin turn_n|
    assert (
        solve(DyadInputs("RTR", k, Mount((0.5, 0)), 0, 1.0, turn_n=1.2))["status"]
        == CANNOT_ASSEMBLE
    )
    # RTR: l_m of the smaller solution negative (l_n < |D_m D_n|)
    rtr = DyadInputs("RTR", k, p, 0, 1.0, turn_n=0.5, branch=-1)
    assert solve(rtr)["status"] == CANNOT_ASSEMBLE
    assert solve(DyadInputs("RTR", k, p, 0, 1.0, turn_n=0.5, branch=1), dps=20)["status"] == "ok"
    # RRT: the guide further from the pin than l_m + l_n can reach
    guide = Mount((0, 5), direction=(1, 0))
    assert solve(DyadInputs("RRT", guide, k, 0.5, 1.0, turn_m=1.0))["status"] == CANNOT_ASSEMBLE
    # TRT: parallel guides, E's two lines never meet
    guides = Mount((0, 0), direction=(1, 0)), Mount((0, 1), direction=(1, 0))
    trt = DyadInputs("TRT", *guides, 0.2, 0.2, turn_m=0.3, turn_n=-0.3)
    assert solve(trt)["status"] == CANNOT_ASSEMBLE


def test_dead_point_and_near_it():
    k = Mount((0, 0), velocity=(0.25, 0.5))
    stretched = DyadInputs("RRR", k, Mount((2.5, 0)), 1.0, 1.5)
    assert solve(stretched, dps=30)["status"] == SINGULAR
    gap = mpf(2) ** -60  # just short of stretched: two mirrored solutions, both regular
    near = [replace(stretched, p=Mount((mpf("2.5") - gap, 0)), branch=b) for b in (1, -1)]
    plus, minus = (solve(x, dps=40) for x in near)
    assert plus["status"] == minus["status"] == "ok"
    assert plus["angle_m"] > 0 > minus["angle_m"]
    assert abs(plus["angle_m"] + minus["angle_m"]) < 1e-30
    with mpmath.workdps(60):  # law of cosines: cos angle_m = (l_m^2 + d^2 - l_n^2) / (2 l_m d)
        d = mpf("2.5") - gap
        assert abs(plus["angle_m"] - mpmath.acos((1 + d * d - mpf("2.25")) / (2 * d))) < 1e-30


def test_derivative_matches_differences_of_solve():
    inputs = assembled_case("RRT", 9)
    # dyadic rates: the same numbers as floats (the seed) and as mpf (the moved inputs)
    seed = {"k.position": (0.375, -0.25), "turn_m": 0.5, "length_n": -0.625, "p.omega": 1.0}
    seed |= {"k.direction": 0.125, "p.acceleration": (1.0, 0.5), "com_n": (0.0625, 0.75)}
    got = derivative(inputs, seed, dps=30)
    delta = mpf("1e-15")

    def moved(sign):
        s = sign * delta
        k, p = inputs.k, inputs.p
        k2 = Mount(
            (k.position[0] + mpf("0.375") * s, k.position[1] - mpf("0.25") * s),
            k.velocity, k.acceleration,
            mpmath.atan2(k.direction[1], k.direction[0]) + mpf("0.125") * s, k.omega, k.epsilon,
        )  # fmt: skip
        p2 = Mount(
            p.position, p.velocity,
            (p.acceleration[0] + s, p.acceleration[1] + mpf("0.5") * s),
            p.direction, p.omega + s, p.epsilon,
        )  # fmt: skip
        return solve(
            DyadInputs(
                "RRT", k2, p2, inputs.length_m, inputs.length_n - mpf("0.625") * s,
                inputs.turn_m + mpf("0.5") * s, inputs.turn_n, inputs.com_m,
                (inputs.com_n[0] + mpf("0.0625") * s, inputs.com_n[1] + mpf("0.75") * s),
            ),
            dps=60,
        )  # fmt: skip

    plus, minus = moved(1), moved(-1)
    for key in ("s_k", "s_k_dot", "s_k_ddot", "omega_n", "epsilon_n", "n.s.acceleration"):
        want = plus[key], minus[key]
        if isinstance(want[0], tuple):
            fd = [(x - y) / (2 * delta) for x, y in zip(*want, strict=True)]
            assert vec_close(got[key], fd, 1e-20), key
        else:
            assert abs(got[key] - (want[0] - want[1]) / (2 * delta)) < 1e-20 * (1 + abs(got[key]))


def test_derivative_of_a_rigid_translation():
    inputs = assembled_case("RTT", 4)
    d = derivative(inputs, {"k.position": (1, 0), "p.position": (1, 0)}, dps=30)
    for point in POINTS:
        assert vec_close(d[f"{point}.position"], (1, 0), 1e-25)
        assert vec_close(d[f"{point}.velocity"], (0, 0), 1e-25)
    assert abs(d["omega_m"]) < 1e-25 and abs(d["l_m"]) < 1e-25


def test_invalid_inputs_and_floats():
    k, p = Mount((0, 0)), Mount((1, 0))
    with pytest.raises(ValueError):
        solve(DyadInputs("RRX", k, p, 1, 1))
    with pytest.raises(ValueError):
        solve(DyadInputs("RRR", k, p, 1, 1, branch=0))
    with pytest.raises(ValueError):
        derivative(DyadInputs("RRR", k, p, 1, 1), {"k.nothing": 1})
    f = as_floats(solve(DyadInputs("RRR", k, p, 1, 1), dps=20))
    assert math.isclose(f["angle_m"], math.pi / 3) and f["e.position"][0] == pytest.approx(0.5)

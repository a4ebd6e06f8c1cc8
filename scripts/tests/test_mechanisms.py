"""Tests of the five class II mechanisms (scripts/dyadfmu/mechanisms/builtin.py) and their
drawing (scripts/dyadfmu/report/drawing.py).

For every mechanism and both crank motions:
- positions close (E = D_m + l_m i_m = D_n + l_n i_n, A on the crank circle, points on
  their guides) and the pairs hold: at a revolute pair the material points of both
  bodies have equal velocity and acceleration; at a translational pair the angular
  velocities are equal and the relative velocity and the relative acceleration (less
  its Coriolis part) lie along the guide. This checks ``accel_d`` as the acceleration
  of the material point of the link at D_g against the frame and the crank.
- every closed-form velocity and acceleration against 4th-order central finite
  differences of the closed-form positions (and angle -> omega -> epsilon);
- the FMU inputs and parameters are exactly the variables of modelDescription/*.toml;
- the reference solve gives finite reactions with good conditioning, and the power
  balance of the whole mechanism (crank torque from those reactions) holds.
- the drawing runs on Agg and returns the force scale.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
from dyadfmu.mechanisms import builtin as mechanisms  # noqa: E402
from dyadfmu.reference import newton_euler as reference  # noqa: E402
from dyadfmu.report import drawing  # noqa: E402

NAMES = mechanisms.NAMES
KINDS = ("constant", "varying")
CASES = [(n, k) for n in NAMES for k in KINDS]
# pair kinds (D_m, E, D_n), written out independently of the module
KIND_OF = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}


def unit(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def rot90(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def dot(a, b):
    return np.sum(a * b, axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def col(x):
    return np.asarray(x, dtype=float)[..., None]


def norm(v):
    return np.hypot(v[..., 0], v[..., 1])


def setup(name, kind, count=72, revolutions=1.0):
    mech = mechanisms.load(name)
    motion = mech.motion(kind, revolutions)
    t = (np.arange(count) + 0.37) * motion.duration / count
    return mech, motion, t


def scales(mech, motion, t):
    """Characteristic length L, angular speed W of a mechanism's motion."""
    w = float(np.max(np.abs(motion.omega(np.linspace(0, motion.duration, 2001)))))
    return mech.crank["radius"], w


def assert_close(got, want, scale, rel, what):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    ref = max(float(np.max(np.abs(want))), scale)
    err = float(np.max(np.abs(got - want)))
    assert err <= rel * ref, f"{what}: max error {err:.3e} > {rel:g} x {ref:.3e}"


# ---------------------------------------------------------------------------
# loading and data
# ---------------------------------------------------------------------------
def test_names_and_unknown():
    assert NAMES == ("slider-crank", "four-bar", "quick-return", "scotch-yoke", "trt-slot")
    with pytest.raises(ValueError) as exc:
        mechanisms.load("pendulum")
    for n in NAMES:
        assert n in str(exc.value)


@pytest.mark.parametrize("name", NAMES)
def test_attributes(name):
    mech = mechanisms.load(name)
    assert mech.name == name
    assert (
        mech.dyad
        == {
            "slider-crank": "RRT",
            "four-bar": "RRR",
            "quick-return": "RTR",
            "scotch-yoke": "RTT",
            "trt-slot": "TRT",
        }[name]
    )
    assert mech.description
    assert mech.gravity == (0.0, -9.81)
    c = mech.crank
    assert c["radius"] > 0 and c["mass"] > 0 and c["inertia"] > 0 and len(c["com"]) == 2
    params = mech.fmu_parameters()
    for g in ("m", "n"):
        assert params[f"link_{g}.mass"] > 0 and params[f"link_{g}.inertia"] > 0
    # some centres of mass off the link axis
    assert any(params[f"link_{g}.com.y"] != 0 for g in ("m", "n"))


def test_data_overrides():
    mech = mechanisms.load("four-bar", {"crank": {"radius": 0.04}})
    assert mech.crank["radius"] == 0.04
    assert mech.crank["mass"] == mechanisms.load("four-bar").crank["mass"]
    whole = mechanisms.default_data()
    whole["slider-crank"]["link_n"]["length"] = 0.2
    assert mechanisms.load("slider-crank", whole).fmu_parameters()["link_n.length"] == 0.2


@pytest.mark.parametrize(
    "name, bad, match",
    [
        ("four-bar", {"crank": {"radius": 0.13}}, "Grashof"),
        ("slider-crank", {"link_n": {"length": 0.05}}, "rod"),
        ("quick-return", {"geometry": {"O2": [0.0, -0.09]}}, "O2"),
        ("scotch-yoke", {"geometry": {"h": 0.05}}, "h"),
        ("trt-slot", {"motion": {"amplitude": 1.5}}, "sin"),
        ("trt-slot", {"crank": {"radius": 0.12}}, "slot"),
        ("four-bar", {"link_m": {"mass": -1.0}}, "mass"),
        ("four-bar", {"dyad": "RRT"}, "dyad"),
    ],
)
def test_bad_data(name, bad, match):
    with pytest.raises(ValueError, match=match):
        mechanisms.load(name, bad)


# ---------------------------------------------------------------------------
# motion
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name, kind", CASES)
def test_motion(name, kind):
    mech = mechanisms.load(name)
    for revolutions in (1.0, 2.0, 1.37):
        m = mech.motion(kind, revolutions)
        assert m.duration > 0
        t = np.linspace(0.0, m.duration, 4001)
        phi = m.phi(t)
        if name == "trt-slot":
            period = m.duration / revolutions
            assert m.phi(period) == pytest.approx(m.phi(0.0), abs=1e-12)
            assert m.omega(period) == pytest.approx(m.omega(0.0), rel=1e-12)
            assert 0 < phi.min() and phi.max() < math.pi
        else:
            assert phi[-1] - phi[0] == pytest.approx(2 * math.pi * revolutions, rel=1e-12)
            assert np.all(m.omega(t) > 0)
        w = m.omega(t)
        if kind == "constant" and name != "trt-slot":
            assert np.ptp(w) == 0.0
        else:
            assert np.ptp(w) > 0.1 * np.max(np.abs(w))
    # phi -> omega -> epsilon
    m = mech.motion(kind, 1.0)
    t = np.linspace(0.01, 0.99, 57) * m.duration
    h = 1e-3 / float(np.max(np.abs(m.omega(np.linspace(0, m.duration, 1001)))))
    W = 1e-3 / h
    assert_close(fd1(m.phi, t, h), m.omega(t), W, 1e-8, "omega")
    assert_close(fd1(m.omega, t, h), m.epsilon(t), W * W, 1e-7, "epsilon")
    with pytest.raises(ValueError):
        mech.motion("jerky")


# ---------------------------------------------------------------------------
# positions, pairs and guides
# ---------------------------------------------------------------------------
def crank_point(kin, P):
    """Velocity and acceleration of the crank's material point at P."""
    w, e = col(kin["crank.omega"]), col(kin["crank.epsilon"])
    rel = P - kin["O"]
    return w * rot90(rel), e * rot90(rel) - w * w * rel


def link_point(kin, g, P):
    """Velocity and acceleration of link g's material point at P (rigid from D_g)."""
    w, e = col(kin[f"{g}.omega"]), col(kin[f"{g}.epsilon"])
    rel = P - kin[f"D_{g}"]
    return kin[f"v_D_{g}"] + w * rot90(rel), kin[f"{g}.accel_d"] + e * rot90(rel) - w * w * rel


def _check_pairs_on_their_guides(kin, kinds, tol, L):
    """D_m, D_n and E where the kinds of their pairs keep them: on a fixed guide or a
    fixed pivot, on the crank's guide or pin, in the slot of link m."""
    frame = kin["frame"]
    for p in frame["pivots"].values():  # fixed pivots do not move
        assert np.isfinite(p).all()
    if kinds[0] == "T":
        # D_m stays on the fixed guide k: a fixed line through D_m[0] along i_k
        ak = kin["guide_k.angle"]
        assert np.ptp(ak) == 0.0
        jk = rot90(unit(ak))
        assert np.max(np.abs(dot(kin["D_m"] - kin["D_m"][0], jk))) <= tol
        seg = np.asarray(frame["guides"]["k"])
        assert abs(cross(seg[1] - seg[0], unit(ak[0]))) <= tol  # drawn guide along i_k
        assert abs(dot(seg[0] - kin["D_m"][0], jk[0])) <= tol  # and through D_m
    else:
        assert np.ptp(kin["D_m"], axis=0).max() == 0.0  # D_m is a fixed pivot
        assert any(np.allclose(p, kin["D_m"][0]) for p in frame["pivots"].values())
    if kinds[2] == "T":
        # the guide p turns with the crank, and D_n keeps its offset from it
        ap = kin["guide_p.angle"]
        assert np.ptp(ap - kin["crank.angle"]) <= 1e-12
        jp = rot90(unit(ap))
        off = dot(kin["D_n"] - kin["O"], jp)
        assert np.ptp(off) <= tol
    else:
        # D_n is the crank pin
        assert_close(kin["D_n"], kin["A"], L, 1e-12, "D_n = A")
    if kinds[1] == "T":
        # E slides along link m; the block n keeps its orientation and offset in the slot
        assert np.max(np.abs(np.sin(kin["n.angle"] - kin["m.angle"]))) <= 1e-12
        jm = rot90(unit(kin["m.angle"]))
        assert np.ptp(dot(kin["D_n"] - kin["D_m"], jm)) <= tol


@pytest.mark.parametrize("name, kind", CASES)
def test_positions_and_guides(name, kind):
    mech, motion, t = setup(name, kind)
    kin = mech.kinematics(t, motion)
    L, W = scales(mech, motion, t)
    N = len(t)
    for key in (
        "O",
        "A",
        "D_m",
        "E",
        "D_n",
        "S_m",
        "S_n",
        "S_c",
        "v_S_m",
        "v_S_n",
        "v_S_c",
        "a_S_c",
        "m.accel_d",
        "n.accel_d",
        "m.force",
        "n.force",
    ):
        assert kin[key].shape == (N, 2), key
        assert np.all(np.isfinite(kin[key])), key
    for key in (
        "t",
        "crank.angle",
        "crank.omega",
        "crank.epsilon",
        "m.angle",
        "m.omega",
        "m.epsilon",
        "m.length",
        "n.angle",
        "n.omega",
        "n.epsilon",
        "n.length",
        "m.moment",
        "n.moment",
    ):
        assert kin[key].shape == (N,), key
        assert np.all(np.isfinite(kin[key])), key
    tol = 1e-12 * L
    assert np.max(np.abs(kin["O"])) == 0.0
    assert np.max(np.abs(norm(kin["A"]) - mech.crank["radius"])) <= tol
    assert_close(unit(kin["crank.angle"]) * mech.crank["radius"], kin["A"], L, 1e-12, "A")
    E = kin["E"]
    assert_close(kin["D_m"] + col(kin["m.length"]) * unit(kin["m.angle"]), E, L, 1e-12, "E from m")
    assert_close(kin["D_n"] + col(kin["n.length"]) * unit(kin["n.angle"]), E, L, 1e-12, "E from n")
    assert np.all(kin["m.length"] >= 0) and np.all(kin["n.length"] >= 0)
    params = mech.fmu_parameters()
    for g in ("m", "n"):
        i, j = unit(kin[f"{g}.angle"]), rot90(unit(kin[f"{g}.angle"]))
        S = kin[f"D_{g}"] + params[f"link_{g}.com.x"] * i + params[f"link_{g}.com.y"] * j
        assert_close(kin[f"S_{g}"], S, L, 1e-12, f"S_{g}")
        if f"link_{g}.length" in params:  # a constant length
            assert np.all(kin[f"{g}.length"] == params[f"link_{g}.length"])
    cx, cy = mech.crank["com"]
    ic = unit(kin["crank.angle"])
    assert_close(kin["S_c"], cx * ic + cy * rot90(ic), L, 1e-12, "S_c")

    _check_pairs_on_their_guides(kin, KIND_OF[mech.dyad], tol, L)
    # mechanism-specific geometry
    if name == "slider-crank":
        assert np.all(kin["D_m"][:, 1] == mech.e) and np.all(kin["D_m"][:, 0] > 0)
        assert np.all(kin["m.length"] == 0) and np.all(kin["m.angle"] == 0)
    elif name == "four-bar":
        assert np.max(np.abs(norm(E - kin["D_m"]) - params["link_m.length"])) <= tol
        assert np.max(np.abs(norm(E - kin["A"]) - params["link_n.length"])) <= tol
        # one assembly branch: E stays on the same side of the line A -> O4
        side = cross(kin["D_m"] - kin["A"], E - kin["A"])
        assert np.all(side > 0)
    elif name == "quick-return":
        assert_close(E, kin["A"], L, 1e-12, "E = A")
        assert np.all(kin["n.length"] == 0)
        assert_close(kin["m.length"], norm(kin["A"] - np.asarray(mech.O2)), L, 1e-12, "l_m")
    elif name == "scotch-yoke":
        assert_close(E, kin["A"], L, 1e-12, "E = A")
        assert np.all(kin["D_m"][:, 1] == -mech.h)
        assert np.allclose(kin["m.angle"], math.pi / 2) and np.allclose(kin["n.angle"], math.pi / 2)
        assert_close(kin["m.length"], kin["A"][:, 1] + mech.h, L, 1e-12, "l_m")
    elif name == "trt-slot":
        assert np.allclose(E[:, 1], mech.h, rtol=0, atol=tol)
        assert np.max(np.abs(cross(unit(kin["crank.angle"]), E))) <= tol  # E in the slot
        assert np.all(dot(E, unit(kin["crank.angle"])) > 0)  # in front of O
        assert np.all(norm(E) < mech.crank["radius"])  # within the arm


@pytest.mark.parametrize("name, kind", CASES)
def test_pairs(name, kind):
    """Velocity and acceleration conditions of the three pairs, from accel_d and omegas."""
    mech, motion, t = setup(name, kind)
    kin = mech.kinematics(t, motion)
    L, W = scales(mech, motion, t)
    V, Acc, rel = L * W, L * W * W, 1e-10
    k_dm, k_e, k_dn = KIND_OF[mech.dyad]
    zero = np.zeros_like(kin["A"])

    def check(kind_, v1, a1, w1, v2, a2, w2, e1, e2, guide_angle, what):
        if kind_ == "R":
            assert_close(v1, v2, V, rel, f"{what}: velocity")
            assert_close(a1, a2, Acc, rel, f"{what}: acceleration")
        else:
            j = rot90(unit(guide_angle))
            assert_close(w1, w2, W, rel, f"{what}: omega")
            assert_close(e1, e2, W * W, rel, f"{what}: epsilon")
            v_rel = v1 - v2
            assert_close(dot(v_rel, j), 0 * w1, V, rel, f"{what}: relative velocity off the guide")
            coriolis = 2.0 * col(w2) * rot90(v_rel)
            assert_close(
                dot(a1 - a2 - coriolis, j),
                0 * w1,
                Acc,
                rel,
                f"{what}: relative acceleration off the guide",
            )

    zeros = np.zeros(len(t))
    # D_m: link m against the frame k
    v1, a1 = link_point(kin, "m", kin["D_m"])
    check(
        k_dm,
        v1,
        a1,
        kin["m.omega"],
        zero,
        zero,
        zeros,
        kin["m.epsilon"],
        zeros,
        kin.get("guide_k.angle"),
        "D_m",
    )
    # D_n: link n against the crank p
    v1, a1 = link_point(kin, "n", kin["D_n"])
    v2, a2 = crank_point(kin, kin["D_n"])
    check(
        k_dn,
        v1,
        a1,
        kin["n.omega"],
        v2,
        a2,
        kin["crank.omega"],
        kin["n.epsilon"],
        kin["crank.epsilon"],
        kin.get("guide_p.angle"),
        "D_n",
    )
    # E: link n against link m (the guide of a T pair at E is i_m)
    v1, a1 = link_point(kin, "n", kin["E"])
    v2, a2 = link_point(kin, "m", kin["E"])
    check(
        k_e,
        v1,
        a1,
        kin["n.omega"],
        v2,
        a2,
        kin["m.omega"],
        kin["n.epsilon"],
        kin["m.epsilon"],
        kin["m.angle"],
        "E",
    )
    # the centres of mass move with their links
    for g in ("m", "n"):
        v, a = link_point(kin, g, kin[f"S_{g}"])
        assert_close(kin[f"v_S_{g}"], v, V, rel, f"v_S_{g}")
        assert_close(kin[f"a_S_{g}"], a, Acc, rel, f"a_S_{g}")
    v, a = crank_point(kin, kin["S_c"])
    assert_close(kin["v_S_c"], v, V, rel, "v_S_c")
    assert_close(kin["a_S_c"], a, Acc, rel, "a_S_c")
    # translational pairs on the fixed frame: the link does not turn
    if k_dm == "T":
        assert np.all(kin["m.omega"] == 0) and np.all(kin["m.epsilon"] == 0)
    if mech.dyad == "RTR":
        assert np.array_equal(kin["n.omega"], kin["m.omega"])
        assert np.array_equal(kin["n.epsilon"], kin["m.epsilon"])
    if mech.dyad == "RTT":
        assert np.all(kin["n.omega"] == 0) and np.all(kin["n.epsilon"] == 0)
    if mech.dyad == "TRT":
        assert np.array_equal(kin["n.omega"], kin["crank.omega"])
        assert np.array_equal(kin["guide_p.angle"], kin["crank.angle"])


# ---------------------------------------------------------------------------
# closed form against finite differences
# ---------------------------------------------------------------------------
def fd1(f, t, h):
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


def fd2(f, t, h):
    return (-f(t + 2 * h) + 16 * f(t + h) - 30 * f(t) + 16 * f(t - h) - f(t - 2 * h)) / (12 * h * h)


def test_stencils_detect_errors():
    """The finite-difference stencils are 4th order (and so can tell a wrong derivative)."""
    t = np.linspace(0.1, 1.0, 7)
    for h in (1e-2, 5e-3):
        assert np.max(np.abs(fd1(np.sin, t, h) - np.cos(t))) < 2 * h**4
        assert np.max(np.abs(fd2(np.sin, t, h) + np.sin(t))) < 2 * h**4
    assert np.max(np.abs(fd1(np.sin, t, 1e-3) - 1.000001 * np.cos(t))) > 1e-7


@pytest.mark.parametrize("name, kind", CASES)
def test_finite_differences(name, kind):
    mech, motion, t = setup(name, kind, count=48)
    L, W = scales(mech, motion, t)
    h = 1e-3 / W
    kins = {k: mech.kinematics(t + k * h, motion) for k in (-2, -1, 0, 1, 2)}
    kin = kins[0]
    rel = 1e-6

    def series(key, angle=False):
        base = kins[0][key]
        if angle:  # unwrap each shifted angle next to the centre sample
            return {k: base + np.angle(np.exp(1j * (v[key] - base))) for k, v in kins.items()}
        return {k: v[key] for k, v in kins.items()}

    def d1(key, angle=False):
        s = series(key, angle)
        return (-s[2] + 8 * s[1] - 8 * s[-1] + s[-2]) / (12 * h)

    def d2(key, angle=False):
        s = series(key, angle)
        return (-s[2] + 16 * s[1] - 30 * s[0] + 16 * s[-1] - s[-2]) / (12 * h * h)

    for g in ("crank", "m", "n"):
        assert_close(d1(f"{g}.angle", True), kin[f"{g}.omega"], W, rel, f"{g}: angle -> omega")
        assert_close(d1(f"{g}.omega"), kin[f"{g}.epsilon"], W * W, rel, f"{g}: omega -> epsilon")
        assert_close(
            d2(f"{g}.angle", True), kin[f"{g}.epsilon"], W * W, rel, f"{g}: angle -> epsilon"
        )
    for g in ("m", "n"):
        assert_close(d1(f"{g}.length"), kin[f"{g}.length_rate"], L * W, rel, f"l_{g} rate")
        assert_close(d2(f"{g}.length"), kin[f"{g}.length_accel"], L * W * W, rel, f"l_{g} accel")
        # D_g is a material point of link g in all five mechanisms
        assert_close(d1(f"D_{g}"), kin[f"v_D_{g}"], L * W, rel, f"v_D_{g}")
        assert_close(d2(f"D_{g}"), kin[f"{g}.accel_d"], L * W * W, rel, f"{g}.accel_d")
    for p in ("S_m", "S_n", "S_c"):
        assert_close(d1(p), kin[f"v_{p}"], L * W, rel, f"v_{p}")
        assert_close(d2(p), kin[f"a_{p}"], L * W * W, rel, f"a_{p} (from positions)")
        assert_close(d1(f"v_{p}"), kin[f"a_{p}"], L * W * W, rel, f"a_{p} (from velocities)")
    for p in ("A", "E"):
        assert_close(d1(p), kin[f"v_{p}"], L * W, rel, f"v_{p}")
        assert_close(d2(p), kin[f"a_{p}"], L * W * W, rel, f"a_{p}")
    for a in ("guide_k.angle", "guide_p.angle"):
        if a in kin:
            w = d1(a, True)
            want = kin["crank.omega"] if a == "guide_p.angle" else 0 * w
            assert_close(w, want, W, rel, f"{a} rate")


# ---------------------------------------------------------------------------
# loads
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name, kind", CASES)
def test_loads(name, kind):
    mech, motion, t = setup(name, kind, count=720)
    kin = mech.kinematics(t, motion)
    fm, mm = kin["m.force"], kin["m.moment"]
    assert np.all(kin["n.force"] == 0) and np.all(kin["n.moment"] == 0)
    if name == "slider-crank":
        assert np.all(fm[:, 1] == 0) and np.all(fm[:, 0] < 0) and np.all(mm == 0)
        f = -fm[:, 0]
        # once per revolution, a peak a little after top dead centre (piston farthest out)
        k = int(np.argmax(f))
        tdc = kin["crank.angle"][np.argmax(kin["D_m"][:, 0])]
        after = (kin["crank.angle"][k] - tdc + math.pi) % (2 * math.pi) - math.pi
        assert 0 < after < 0.5
        assert f[k] > 10 * np.median(f)
        assert f.max() == pytest.approx(mech.area * mech.p_peak, rel=1e-3)
    elif name in ("four-bar", "quick-return"):
        assert np.all(fm == 0)
        w = kin["m.omega"]
        assert np.all(mm * w <= 0) and np.max(np.abs(mm)) > 0  # resists the rocker/lever
        if name == "quick-return":
            work, back = w > 0, w < 0  # slow and quick strokes
            assert work.mean() > back.mean() if kind == "constant" else True
            assert np.max(np.abs(mm[back])) < 0.2 * np.max(np.abs(mm[work]))
            assert np.max(np.abs(mm[work])) > 0.9 * mech.M0
    else:
        v = kin["v_D_m"][:, 0]
        assert np.all(fm[:, 1] == 0) and np.all(mm == 0)
        assert np.all(fm[:, 0] * v <= 0) and np.max(np.abs(fm)) > 0


def test_quick_return_strokes():
    """The working stroke (omega_m > 0) takes the 219 deg arc: time ratio 219/141."""
    mech = mechanisms.load("quick-return")
    m = mech.motion("constant", 1)
    t = (np.arange(36000) + 0.5) * m.duration / 36000
    w = mech.kinematics(t, m)["m.omega"]
    d, r = math.hypot(*mech.O2), mech.crank["radius"]
    share = (math.pi + 2 * math.asin(r / d)) / (2 * math.pi)
    assert np.mean(w > 0) == pytest.approx(share, abs=1e-4)


# ---------------------------------------------------------------------------
# the FMU interface and the reference
# ---------------------------------------------------------------------------
def toml_names(dyad, causality):
    """The generic dyad FMU's variables, as the scene generator makes them."""
    from dyadgen import pipeline

    table = pipeline.build_table(
        pipeline.load_scene(ROOT / "modelDescription" / "scenes" / f"dyad_{dyad.lower()}.toml")
    )
    return [v.name for v in table.variables if v.causality == causality]


@pytest.mark.parametrize("name", NAMES)
def test_fmu_interface(name):
    mech, motion, t = setup(name, "varying", count=30)
    kin = mech.kinematics(t, motion)
    inputs = mech.fmu_inputs(kin)
    params = mech.fmu_parameters()
    assert list(inputs) == toml_names(mech.dyad, "input")
    # the FMU's own settings are left at their defaults
    assert set(params) == set(toml_names(mech.dyad, "parameter")) - {
        "singular_threshold",
        "on_singular",
    }
    for key, v in inputs.items():
        assert v.shape == t.shape and np.all(np.isfinite(v)), key
    for key, v in params.items():
        assert isinstance(v, float) and math.isfinite(v), key
    assert params["gravity.x"] == 0.0 and params["gravity.y"] == -9.81
    # the values are those of the kinematics
    assert np.array_equal(inputs["link_m.accel_d.y"], kin["m.accel_d"][:, 1])
    assert np.array_equal(inputs["link_n.force.x"], kin["n.force"][:, 0])
    assert np.array_equal(inputs["link_n.angle"], kin["n.angle"])
    if "link_m.length" in inputs:
        assert np.array_equal(inputs["link_m.length"], kin["m.length"])
        assert np.all(inputs["link_m.length"] > 0)
    for g in ("m", "n"):
        if f"link_{g}.length" in params:
            assert params[f"link_{g}.length"] >= 0


def crank_torque(mech, kin, out):
    """Driving torque on the crank (N m) from its moment balance about O."""
    c = mech.crank
    g = np.asarray(mech.gravity)
    f_c = c["mass"] * (g - kin["a_S_c"])
    m_np = np.nan_to_num(out["m_np"])
    return -(
        cross(kin["D_n"] - kin["O"], -out["r_np"])
        - m_np
        + cross(kin["S_c"] - kin["O"], f_c)
        - c["inertia"] * kin["crank.epsilon"]
    )


@pytest.mark.parametrize("name, kind", CASES)
def test_reference_solve(name, kind):
    mech = mechanisms.load(name)
    motion = mech.motion(kind, 1.0)
    t = np.linspace(0.0, motion.duration, 361)
    kin = mech.kinematics(t, motion)
    m, n, gk, gp, grav = mech.reference_inputs(kin)
    assert (gk is None) == (mech.dyad == "RRR" or mech.dyad == "RTR")
    assert (gp is None) == (mech.dyad != "TRT")
    out = reference.solve(mech.dyad, m, n, gk, gp, grav)
    for key in ("r_mk", "r_np", "r_mn", "m_mk", "m_np", "m_mn"):
        assert np.all(np.isfinite(out[key])), key
    assert np.max(np.abs(out["r_np"])) > 0
    # well away from singular positions: the dyad's conditioning (as the FMU reports it)
    # and the condition number of the reference's 6x6 system
    cond = kin["conditioning"]
    assert np.all(cond > 0.3), cond.min()
    assert np.all(out["cond"] < 1e4)
    # power balance of crank + dyad: dT/dt = crank torque x omega + load and weight power
    params = mech.fmu_parameters()
    g = np.asarray(mech.gravity)
    c = mech.crank
    dTdt = (
        c["mass"] * dot(kin["v_S_c"], kin["a_S_c"])
        + c["inertia"] * kin["crank.omega"] * kin["crank.epsilon"]
    )
    power = crank_torque(mech, kin, out) * kin["crank.omega"] + c["mass"] * dot(kin["v_S_c"], g)
    for link in ("m", "n"):
        mass, inertia = params[f"link_{link}.mass"], params[f"link_{link}.inertia"]
        dTdt = (
            dTdt
            + mass * dot(kin[f"v_S_{link}"], kin[f"a_S_{link}"])
            + inertia * kin[f"{link}.omega"] * kin[f"{link}.epsilon"]
        )
        power = (
            power
            + dot(kin[f"{link}.force"], kin[f"v_S_{link}"])
            + kin[f"{link}.moment"] * kin[f"{link}.omega"]
            + mass * dot(kin[f"v_S_{link}"], g)
        )
    assert_close(power, dTdt, 0.0, 1e-9, "power balance")


def test_conditioning_matches_reference_singularity():
    """The conditioning falls towards the singular position (slot parallel to the guide)
    and the reference's system grows ill-conditioned with it."""
    mech = mechanisms.load(
        "trt-slot", {"crank": {"radius": 2.0}, "motion": {"amplitude": 1.35, "harmonic2": 0.0}}
    )
    motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration / 4, 200)  # phi from pi/2 up to pi/2 + 1.35
    kin = mech.kinematics(t, motion)
    out = reference.solve(mech.dyad, *mech.reference_inputs(kin))
    cond = kin["conditioning"]
    assert np.all(np.diff(cond) < 0)
    assert cond[0] == pytest.approx(1.0, abs=1e-12)
    assert cond[-1] == pytest.approx(math.sin(math.pi / 2 - 1.35), rel=1e-9)
    assert np.all(np.diff(out["cond"]) > 0)
    with pytest.raises(ValueError, match="sin"):
        mechanisms.load("trt-slot", {"crank": {"radius": 2.0}, "motion": {"amplitude": 1.45}})


# ---------------------------------------------------------------------------
# drawing
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_drawing(name, tmp_path):
    mech = mechanisms.load(name)
    motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration, 73)
    kin = mech.kinematics(t, motion)
    out = reference.solve(mech.dyad, *mech.reference_inputs(kin))
    i = 10
    r_o = out["r_np"][i] - mech.crank["mass"] * (np.asarray(mech.gravity) - kin["a_S_c"][i])
    reactions = {"R_mk": out["r_mk"][i], "R_np": out["r_np"][i], "R_mn": out["r_mn"][i], "R_O": r_o}
    fig, ax = plt.subplots()
    scale = drawing.draw(ax, mech, kin, i, reactions)
    largest = max(np.hypot(*v) for v in reactions.values())
    size = drawing.mechanism_size(mech, kin)
    assert scale > 0
    assert largest / scale == pytest.approx(0.4 * size, rel=1e-12)
    assert ax.get_legend() is not None and "N/m" in ax.get_legend().get_title().get_text()
    texts = " ".join(tx.get_text() for tx in ax.texts)
    for label in ("O", "A", "D_m", "E", "D_n", "k", "p", "m", "n"):
        assert label in texts, label
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    for key in ("O", "A", "D_m", "E", "D_n"):
        x, y = kin[key][i]
        assert x0 <= x <= x1 and y0 <= y <= y1, key
    fig.savefig(tmp_path / f"{name}.png", dpi=50)
    plt.close(fig)

    fig, ax = plt.subplots()
    assert drawing.draw(ax, mech, kin, 5, reactions, scale=1234.5) == 1234.5
    assert drawing.draw(ax, mech, kin, -1) > 0
    with pytest.raises(ValueError):
        drawing.draw(ax, mech, kin, 5, {"R_xy": (1.0, 0.0)})
    plt.close(fig)

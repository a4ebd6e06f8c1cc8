"""Tests of the chain mechanisms (scripts/dyadfmu/mechanisms/chains.py) and their drawing
(scripts/dyadfmu/report/chain_drawing.py).

For every mechanism (shaper, sixbar, rocker_slider) and both crank motions (constant,
varying):
- loop closure: every pair point computed from both of its links agrees, and the pairs'
  constraints hold (points on guides, blocks turning with their slotted links, sliders
  translating on frame guides and turning with the link that carries their guide); the
  geometry is rebuilt here from the scene file and chains.toml;
- every velocity and acceleration (angles, lengths, positions along guides on moving
  links, centres of mass, ``accel_d`` of every link as the acceleration of its material
  point at D_g) against 4th-order central finite differences of positions;
- the reference reactions satisfy every body's Newton-Euler equations (residuals), and
  the residual check detects any perturbed output; for the rocker-slider the balances of
  the rocker, slider and rod are also written out here term by term;
- energy balance of the whole mechanism: driving power + load power = d/dt (kinetic +
  potential energy), the derivative by 4th-order finite differences;
- every dyad stays well conditioned; loads follow their models;
- the drawing runs and draws one arrow per reaction vector.
"""

from __future__ import annotations

import copy
import math
import tomllib
from functools import cache
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrow  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
from dyadfmu.mechanisms import chains  # noqa: E402
from dyadfmu.report import chain_drawing  # noqa: E402

NAMES = ("shaper", "sixbar", "rocker_slider")
KINDS = ("constant", "varying")
CASES = [(n, k) for n in NAMES for k in KINDS]


def unit(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def rot90(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def dot(a, b):
    return np.sum(a * b, axis=-1)


def col(x):
    return np.asarray(x, dtype=float)[..., None]


def norm(v):
    return np.hypot(v[..., 0], v[..., 1])


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def d1(f, h):
    """4th-order central first derivative from the values at -2h, -h, 0, h, 2h."""
    return (f[0] - 8.0 * f[1] + 8.0 * f[3] - f[4]) / (12.0 * h)


def d2(f, h):
    """4th-order central second derivative from the values at -2h, -h, 0, h, 2h."""
    return (-f[0] + 16.0 * f[1] - 30.0 * f[2] + 16.0 * f[3] - f[4]) / (12.0 * h * h)


@cache
def chain(name):
    return chains.load(name)


@cache
def scene(name):
    with open(ROOT / "modelDescription" / "scenes" / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


@cache
def harness(name):
    with open(ROOT / "scripts" / "dyadfmu" / "mechanisms" / "chains.toml", "rb") as f:
        return tomllib.load(f)[name]


def times(motion, count=97):
    """Samples over two turns, off the special angles."""
    return (np.arange(count) + 0.37) * motion.duration / count


@cache
def stencil(name, kind, step):
    """kinematics at t + j h, j = -2..2, and h = step / w0."""
    ch = chain(name)
    motion = ch.motion(kind, 2.0)
    h = step / harness(name)["motion"]["omega"]
    t = times(motion)
    return [ch.kinematics(t + j * h, motion) for j in range(-2, 3)], h


def assert_close(got, want, rel, what, floor=0.0):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    ref = max(float(np.max(np.abs(want))), floor)
    err = float(np.max(np.abs(got - want)))
    assert err <= rel * ref, f"{what}: max error {err:.3e} > {rel:g} x {ref:.3e}"


# ---------------------------------------------------------------------------
# data
# ---------------------------------------------------------------------------
def test_names_and_paths():
    assert chains.NAMES == (*NAMES, "four_bar_payload")
    assert chains.RAM_NAMES == ("lift", "lift_loads")
    assert chains.CYLINDER_NAMES == ("tipper", "cylinder_arm", "cylinder_boom")
    for name in chains.NAMES + chains.RAM_NAMES + ("tipper",):
        assert chains.scene_path(name) == ROOT / "modelDescription" / "scenes" / f"{name}.toml"
        assert chains.scene_path(name).is_file()
    for name in ("cylinder_arm", "cylinder_boom"):  # the build's test scenes
        assert chains.scene_path(name) == ROOT / "tests" / "scenes" / f"{name}.toml"
        assert chains.scene_path(name).is_file()
    with pytest.raises(ValueError, match="shaper"):
        chains.load("pendulum")


@pytest.mark.parametrize("name", NAMES)
def test_attributes(name):
    ch = chain(name)
    sc = scene(name)
    assert ch.name == name and ch.scene == sc
    assert ch.crank == sc["crank"]
    assert ch.gravity == (sc["gravity"]["x"], sc["gravity"]["y"])
    assert [d["name"] for d in ch.dyads] == [d["name"] for d in sc["dyad"]]
    assert set(ch.links) == {lt["name"] for lt in sc["link"]}
    for lt in sc["link"]:
        link = ch.links[lt["name"]]
        for key in ("mass", "inertia"):
            assert link[key] == lt[key]
        assert tuple(link["com"]) == tuple(lt["com"])
    # derived constant lengths; the lever's length varies
    if name == "shaper":
        assert "length" not in ch.links["lever"]
        assert ch.links["rod"]["length"] == 0.16 and ch.links["block"]["length"] == 0.0
    elif name == "rocker_slider":
        assert ch.links["slider"]["length"] == 0.0
        assert all(ch.links[g]["length"] > 0 for g in ch.links if g != "slider")
        k = ch.plan[1]["k"]
        assert (k["kind"], k["body"], k["at"], k["angle"]) == (
            "link_guide",
            "rocker",
            (0.0, 0.0),
            0.0,
        )
        assert [pr["second"] for pr in ch.pairs if pr["key"] == "second.R_mk"] == ["rocker"]
    else:
        assert all(ch.links[g]["length"] > 0 for g in ch.links)


def with_scene(name, edit):
    """The chain `name` with its scene file edited by `edit(scene)`."""
    sc = copy.deepcopy(scene(name))
    edit(sc)
    return chains.Chain(name, sc, copy.deepcopy(harness(name)))


def _set(dyad, side, value):
    def edit(sc):
        for d in sc["dyad"]:
            if d["name"] == dyad:
                d[side] = value

    return edit


def test_overrides_and_bad_data():
    moved = with_scene("sixbar", _set("second", "p", {"link": "frame", "at": [0.12, -0.28]}))
    assert moved.plan[1]["p"]["position"] == (0.12, -0.28)
    assert chains.load(
        "shaper", {"shaper": {"motion": {"omega": 3.0}}}
    ).motion().duration == pytest.approx(2 * 2 * math.pi / 3.0)
    with pytest.raises(ValueError, match="intersect"):
        with_scene("sixbar", _set("second", "p", {"link": "frame", "at": [0.12, -0.6]}))
    with pytest.raises(ValueError, match="reach"):
        with_scene("shaper", _set("ram", "k", {"link": "frame", "guide": 0.0, "at": [0.0, 0.4]}))
    with pytest.raises(ValueError, match="branch"):
        with_scene("sixbar", _set("first", "branch", 0))
    with pytest.raises(ValueError, match="variation"):
        chains.load("shaper", {"motion": {"variation": 1.2}})
    with pytest.raises(ValueError, match="motion kind"):
        chain("shaper").motion("jerky")
    with pytest.raises(ValueError, match="reach"):
        with_scene("rocker_slider", _set("second", "p", {"link": "frame", "at": [0.4, -0.3]}))
    with pytest.raises(ValueError, match="branch"):
        with_scene("rocker_slider", _set("second", "branch", 2))


def test_the_harness_frame_agrees_with_the_scenes():
    """chains.toml still holds the frame pivots, guide heights and branches the scene files
    now state (the tests' independent geometry reads them): they must agree."""
    for name in ("shaper", "sixbar", "rocker_slider"):
        table = harness(name)
        for d in scene(name)["dyad"]:
            assert table["branches"].get(d["name"], 1) == d.get("branch", 1), (name, d["name"])
            for side, pair in (("k", "D_m"), ("p", "D_n")):
                spec = d[side]
                if not (isinstance(spec, dict) and spec.get("link") == "frame"):
                    continue
                frame = table["frame"][d["name"]][pair]
                if "guide" in spec:
                    assert spec["at"][1] == frame["height"] and spec["at"][0] == 0.0
                else:
                    assert tuple(spec["at"]) == tuple(frame["position"]), (name, d["name"])


def test_bad_guides_on_links():
    """A guide on a moving link: only at D_m of an RRT; its slider takes no angle; the
    resisting force only on such a slider."""
    sc, table = scene("rocker_slider"), harness("rocker_slider")

    def build(edit_scene=None, edit_table=None):
        s, t = copy.deepcopy(sc), copy.deepcopy(table)
        if edit_scene:
            edit_scene(s)
        if edit_table:
            edit_table(t)
        return chains.Chain("rocker_slider", s, t)

    build()  # as it is: fine
    with pytest.raises(ValueError, match="turns with link 'rocker'"):
        build(lambda s: s["link"][2].update(angle=0.0))
    with pytest.raises(ValueError, match="revolute pair at D_n"):
        build(lambda s: s["dyad"][1].update(p={"link": "rocker", "guide": 0.0, "at": [0.0, 0.0]}))
    with pytest.raises(ValueError, match="RRR dyad has revolute pairs"):
        build(lambda s: s["dyad"][1].update(type="RRR"))
    with pytest.raises(ValueError, match="at"):
        build(lambda s: s["dyad"][1].update(k={"link": "rocker", "guide": 0.0}))
    with pytest.raises(ValueError, match="not the crank nor a link of an earlier dyad"):
        build(lambda s: s["dyad"][1].update(k={"link": "rod", "guide": 0.0, "at": [0.0, 0.0]}))

    def rod_loaded(t):
        t["load"] = {"rod": dict(t["load"]["slider"])}

    def scene_rod(s):
        s["loads"]["force"] = ["rod"]

    with pytest.raises(ValueError, match="needs a slider"):
        build(scene_rod, rod_loaded)


def test_output_names():
    assert set(chain("shaper").output_names()) == {
        "crank.R_O.x",
        "crank.R_O.y",
        "crank.torque",
        "slot.R_mk.x",
        "slot.R_mk.y",
        "slot.R_mn.x",
        "slot.R_mn.y",
        "slot.N_mn",
        "slot.M_mn",
        "slot.R_np.x",
        "slot.R_np.y",
        "ram.R_mk.x",
        "ram.R_mk.y",
        "ram.N_mk",
        "ram.M_mk",
        "ram.R_mn.x",
        "ram.R_mn.y",
        "ram.R_np.x",
        "ram.R_np.y",
    }
    assert set(chain("sixbar").output_names()) == {"crank.R_O.x", "crank.R_O.y", "crank.torque"} | {
        f"{d}.R_{t}.{c}" for d in ("first", "second") for t in ("mk", "mn", "np") for c in "xy"
    }
    assert set(chain("rocker_slider").output_names()) == {
        "crank.R_O.x",
        "crank.R_O.y",
        "crank.torque",
        "second.N_mk",
        "second.M_mk",
    } | {f"{d}.R_{t}.{c}" for d in ("first", "second") for t in ("mk", "mn", "np") for c in "xy"}


# ---------------------------------------------------------------------------
# kinematics
# ---------------------------------------------------------------------------
def link_origins(name, kin):
    """D_g of every link from the dyad points (D_m of m, D_n of n)."""
    out = {}
    for d in scene(name)["dyad"]:
        out[d["m"]] = kin[f"{d['name']}.D_m"]
        out[d["n"]] = kin[f"{d['name']}.D_n"]
    return out


def external_point(name, dyad, pair, spec, kin, origins):
    """The pair point D_m / D_n as a point of the external link (None for a guide)."""
    frame = harness(name)["frame"]
    if spec == "frame":
        return np.broadcast_to(np.asarray(frame[dyad][pair]["position"], float), kin["A"].shape)
    if isinstance(spec, dict) and spec.get("link") == "frame" and "guide" not in spec:
        return np.broadcast_to(np.asarray(spec["at"], float), kin["A"].shape)  # the scene's pivot
    if spec == "crank":
        return scene(name)["crank"]["length"] * unit(kin["crank.angle"])
    if spec["link"] == "frame" or "guide" in spec:
        return None
    g = spec["link"]
    i_g = unit(kin[f"{g}.angle"])
    x, y = spec["at"]
    return origins[g] + x * i_g + y * rot90(i_g)


def _check_outer_pairs(name, d, kin, origins, tol):
    """D_m and D_n of dyad d from the external links: a pin, or a point on a guide."""
    dn = d["name"]
    for pair, spec in (("D_m", d["k"]), ("D_n", d["p"])):
        P = external_point(name, dn, pair, spec, kin, origins)
        if P is None and spec["link"] != "frame":
            # on the guide of a moving link k: through Q (``at`` in k's frame), along
            # i_k = i_(link k) rotated by the guide angle; D_m = Q + slide_k i_k
            k = spec["link"]
            i_g = unit(kin[f"{k}.angle"])
            x, y = spec["at"]
            Q = origins[k] + x * i_g + y * rot90(i_g)
            i_k = unit(kin[f"{k}.angle"] + spec["guide"])
            assert np.all(kin[f"{dn}.guide_k.angle"] == kin[f"{k}.angle"] + spec["guide"])
            off = dot(kin[f"{dn}.{pair}"] - Q, rot90(i_k))
            assert np.max(np.abs(off)) < tol, f"{dn}.{pair} on its guide"
            want = Q + col(kin[f"{dn}.slide_k"]) * i_k
            assert np.max(norm(want - kin[f"{dn}.{pair}"])) < tol, f"{dn}.slide_k"
        elif P is None:  # on a frame guide through (0, height)
            i_k = unit(spec["guide"])
            foot = np.array([0.0, harness(name)["frame"][dn][pair]["height"]])
            off = dot(kin[f"{dn}.{pair}"] - foot, rot90(i_k))
            assert np.max(np.abs(off)) < tol, f"{dn}.{pair} on its guide"
        else:
            assert np.max(norm(P - kin[f"{dn}.{pair}"])) < tol, f"{dn}.{pair} from {spec}"


def _check_pair_constraints(sc, d, kin, tol):
    """What the inner pairs of dyad d impose on its links' angles and rates."""
    dn, m, n = d["name"], d["m"], d["n"]
    i_m, lm = unit(kin[f"{m}.angle"]), kin[f"{m}.length"]
    if d["type"] == "RTR":  # block turns with the lever; E = A on the slot
        assert np.max(np.abs(np.sin(kin[f"{n}.angle"] - kin[f"{m}.angle"]))) < 1e-14
        assert np.max(np.abs(dot(kin[f"{dn}.D_n"] - kin[f"{dn}.D_m"], rot90(i_m)))) < tol
        assert np.min(lm) > 0
    if d["type"] == "RRT" and d["k"]["link"] == "frame":  # the slider translates
        for key in ("omega", "epsilon"):
            assert np.all(kin[f"{m}.{key}"] == 0.0)
        link = next(lt for lt in sc["link"] if lt["name"] == m)
        assert np.all(kin[f"{m}.angle"] == link.get("angle", d["k"]["guide"]))
    elif d["type"] == "RRT":  # the slider turns with the link carrying its guide
        k = d["k"]["link"]
        assert np.all(kin[f"{m}.angle"] == kin[f"{k}.angle"] + d["k"]["guide"])
        for key in ("omega", "epsilon"):
            assert np.all(kin[f"{m}.{key}"] == kin[f"{k}.{key}"])


@pytest.mark.parametrize("name, kind", CASES)
def test_loop_closure(name, kind):
    ch = chain(name)
    motion = ch.motion(kind, 2.0)
    kin = ch.kinematics(np.linspace(0.0, motion.duration, 1441), motion)
    origins = link_origins(name, kin)
    sc, lengths = scene(name), {lt["name"]: lt.get("length") for lt in scene(name)["link"]}
    tol = 1e-12
    r = sc["crank"]["length"]
    assert_close(kin["A"], r * unit(kin["crank.angle"]), tol / r, "crank pin A")
    assert_close(norm(kin["A"]), np.full(len(kin["t"]), r), tol / r, "|O A|")
    for d in sc["dyad"]:
        dn, m, n = d["name"], d["m"], d["n"]
        i_m, i_n = unit(kin[f"{m}.angle"]), unit(kin[f"{n}.angle"])
        lm, ln = kin[f"{m}.length"], kin[f"{n}.length"]
        for g in (m, n):
            if lengths[g] is not None:
                assert np.all(kin[f"{g}.length"] == lengths[g]), g
        # E from both links
        E_m = kin[f"{dn}.D_m"] + col(lm) * i_m
        E_n = kin[f"{dn}.D_n"] + col(ln) * i_n
        assert np.max(norm(E_m - kin[f"{dn}.E"])) < tol, f"{dn}.E from {m}"
        assert np.max(norm(E_n - kin[f"{dn}.E"])) < tol, f"{dn}.E from {n}"
        _check_outer_pairs(name, d, kin, origins, tol)
        _check_pair_constraints(sc, d, kin, tol)
        # centres of mass
        for g, D, i_g in ((m, kin[f"{dn}.D_m"], i_m), (n, kin[f"{dn}.D_n"], i_n)):
            x, y = next(lt for lt in sc["link"] if lt["name"] == g)["com"]
            assert np.max(norm(D + x * i_g + y * rot90(i_g) - kin[f"S_{g}"])) < tol, f"S_{g}"
    x, y = sc["crank"]["com"]
    i_c = unit(kin["crank.angle"])
    assert np.max(norm(x * i_c + y * rot90(i_c) - kin["S_crank"])) < tol


def test_branches():
    kin = chain("shaper").kinematics(np.linspace(0, 2, 200), chain("shaper").motion())
    assert np.all(kin["ram.E"][:, 0] > kin["ram.D_n"][:, 0])  # C right of B
    rod = np.degrees(np.abs(np.arctan2(*(kin["ram.E"] - kin["ram.D_n"]).T[::-1])))
    assert rod.max() < 16.0
    lever = np.degrees(kin["lever.angle"])
    assert lever.min() == pytest.approx(90 - math.degrees(math.asin(1 / 3)), abs=0.05)
    kin = chain("sixbar").kinematics(np.linspace(0, 2, 200), chain("sixbar").motion())
    assert np.all(kin["first.E"][:, 1] > 0)  # B above O C
    assert np.all(kin["second.E"][:, 0] > 0.12)  # F right of G
    kin = chain("rocker_slider").kinematics(np.linspace(0, 2, 200), chain("rocker_slider").motion())
    assert np.all(kin["first.E"][:, 1] > 0)  # B above O C
    assert np.all(kin["second.slide_k"] < 0)  # slider below C
    G = np.asarray(harness("rocker_slider")["frame"]["second"]["D_n"]["position"])
    i_k = unit(kin["second.guide_k.angle"])
    assert np.all(dot(kin["second.E"] - G, i_k) > 0)  # ahead of G's foot
    assert np.ptp(kin["second.slide_k"]) > 0.02


@pytest.mark.parametrize("name, kind", CASES)
def test_derivatives(name, kind):
    kins, h = stencil(name, kind, 3e-3)
    mid = kins[2]
    rel = 1e-6
    angles = ["crank"] + list(chain(name).links)
    for g in angles:
        a = np.unwrap(np.array([k[f"{g}.angle"] for k in kins]), axis=0)
        assert_close(d1(a, h), mid[f"{g}.omega"], rel, f"{g}.omega", floor=1e-3)
        w = np.array([k[f"{g}.omega"] for k in kins])
        assert_close(d1(w, h), mid[f"{g}.epsilon"], rel, f"{g}.epsilon", floor=1e-3)
        if g == "crank":
            continue
        L = np.array([k[f"{g}.length"] for k in kins])
        assert_close(d1(L, h), mid[f"{g}.length_rate"], rel, f"{g}.length_rate", floor=1e-3)
        Ld = np.array([k[f"{g}.length_rate"] for k in kins])
        assert_close(d1(Ld, h), mid[f"{g}.length_accel"], rel, f"{g}.length_accel", floor=1e-3)
    for b in angles:
        S = np.array([k[f"S_{b}"] for k in kins])
        assert_close(d1(S, h), mid[f"v_S_{b}"], rel, f"v_S_{b}", floor=1e-3)
        v = np.array([k[f"v_S_{b}"] for k in kins])
        assert_close(d1(v, h), mid[f"a_S_{b}"], rel, f"a_S_{b}", floor=1e-3)
    for d in scene(name)["dyad"]:
        if d["type"] == "RRT" and d["k"]["link"] != "frame":
            dn = d["name"]
            s = np.array([k[f"{dn}.slide_k"] for k in kins])
            assert_close(d1(s, h), mid[f"{dn}.slide_k_rate"], rel, f"{dn}.slide_k_rate", floor=1e-3)
            assert_close(
                d2(s, h), mid[f"{dn}.slide_k_accel"], rel, f"{dn}.slide_k_accel", floor=1e-2
            )
            sd = np.array([k[f"{dn}.slide_k_rate"] for k in kins])
            assert_close(
                d1(sd, h), mid[f"{dn}.slide_k_accel"], rel, f"{dn}.slide_k_accel", floor=1e-2
            )
            g = np.unwrap(np.array([k[f"{dn}.guide_k.angle"] for k in kins]), axis=0)
            assert_close(d1(g, h), mid[f"{d['k']['link']}.omega"], rel, f"{dn}.guide_k.angle'")
    assert np.ptp(mid["lever.length"] if name == "shaper" else mid["rocker.angle"]) > 0.1


@pytest.mark.parametrize("name, kind", CASES)
def test_accel_d(name, kind):
    """accel_d of every link: the second derivative of its material point at D_g. Every
    link frame is fixed in its link, so that point is D_g itself, taken here from the
    link's pair point (which the loop closure test ties to the external links)."""
    kins, h = stencil(name, kind, 3e-3)
    mid = kins[2]
    for d in scene(name)["dyad"]:
        for g, pair in ((d["m"], "D_m"), (d["n"], "D_n")):
            P = np.array([k[f"{d['name']}.{pair}"] for k in kins])
            assert_close(d2(P, h), mid[f"{g}.accel_d"], 1e-6, f"{g}.accel_d", floor=1e-2)
            assert_close(d1(P, h), mid[f"{g}.vel_d"], 1e-6, f"{g}.vel_d", floor=1e-2)
            assert np.all(mid[f"{g}.accel_d.x"] == mid[f"{g}.accel_d"][:, 0])
            assert np.all(mid[f"{g}.accel_d.y"] == mid[f"{g}.accel_d"][:, 1])
    if name == "shaper":
        assert np.all(mid["lever.accel_d"] == 0.0)
        assert np.max(norm(mid["slider.accel_d"])) > 1.0
    if name == "rocker_slider":
        # the slider's point at D_m: the rocker's point there (C fixed) plus the relative
        # acceleration along the guide plus Coriolis 2 w x v_rel
        w, e = mid["rocker.omega"], mid["rocker.epsilon"]
        r = mid["second.D_m"] - np.asarray(harness(name)["frame"]["first"]["D_n"]["position"])
        i_k = unit(mid["second.guide_k.angle"])
        transport = col(e) * rot90(r) - col(w * w) * r
        relative = col(mid["second.slide_k_accel"]) * i_k
        coriolis = col(2.0 * w * mid["second.slide_k_rate"]) * rot90(i_k)
        assert_close(
            transport + relative + coriolis, mid["slider.accel_d"], 1e-12, "slider.accel_d"
        )
        # no term is negligible
        for term in (transport, relative, coriolis):
            assert np.max(norm(term)) > 0.1 * np.max(norm(mid["slider.accel_d"]))
        assert np.all(mid["rocker.accel_d"] == 0.0)


@pytest.mark.parametrize("name", NAMES)
def test_conditioning(name):
    ch = chain(name)
    for kind in KINDS:
        motion = ch.motion(kind, 2.0)
        kin = ch.kinematics(np.linspace(0.0, motion.duration, 2881), motion)
        assert np.ptp(np.unwrap(kin["crank.angle"])) == pytest.approx(4 * math.pi)
        for d in scene(name)["dyad"]:
            c = kin[f"{d['name']}.conditioning"]
            assert np.min(c) > (0.3 if d["type"] == "RRT" else 0.2), (d["name"], np.min(c))
            i_m, i_n = unit(kin[f"{d['m']}.angle"]), unit(kin[f"{d['n']}.angle"])
            if d["type"] == "RRR":
                want = np.abs(dot(i_m, rot90(i_n)))
            elif d["type"] == "RRT" and d["k"]["link"] != "frame":
                want = np.abs(dot(i_n, unit(kin[f"{d['k']['link']}.angle"] + d["k"]["guide"])))
            elif d["type"] == "RRT":
                want = np.abs(dot(i_n, unit(d["k"]["guide"])))
            else:
                want = np.ones_like(c)  # block on the pin: i_beta = i_m, l_n = 0
            assert_close(c, want, 1e-14, f"{d['name']}.conditioning")


@pytest.mark.parametrize("name, kind", CASES)
def test_loads(name, kind):
    ch = chain(name)
    motion = ch.motion(kind, 2.0)
    kin = ch.kinematics(times(motion, 721), motion)
    load = harness(name)["load"]
    loaded = {g for g in load}
    for g in ch.links:
        if g not in loaded or load[g]["model"] not in ("cutting", "resisting-force"):
            assert np.all(kin[f"{g}.force"] == 0.0)
        if g not in loaded or load[g]["model"] != "resisting-torque":
            assert np.all(kin[f"{g}.moment"] == 0.0)
    if name == "shaper":
        ld = load["slider"]
        v = kin["v_S_slider"][:, 0]
        sign = ld["s"]
        want = -sign * ld["F0"] * (1 + np.tanh(sign * v / ld["v_ref"])) / 2
        assert_close(kin["slider.force.x"], want, 1e-14, "cutting force")
        assert np.all(kin["slider.force.y"] == 0.0)
        assert np.max(np.abs(kin["slider.force.x"])) > 0.99 * ld["F0"]
        assert np.min(np.abs(kin["slider.force.x"])) < 1.0
    elif name == "rocker_slider":
        ld = load["slider"]
        i_k = unit(kin["rocker.angle"])  # guide = 0: along the rocker
        # the velocity of D_m relative to the rocker: v_D - w k x (D_m - C)
        C = np.asarray(harness(name)["frame"]["first"]["D_n"]["position"])
        v_rel = dot(
            kin["slider.vel_d"] - col(kin["rocker.omega"]) * rot90(kin["second.D_m"] - C), i_k
        )
        assert_close(v_rel, kin["second.slide_k_rate"], 1e-12, "v_rel")
        want = col(-ld["F0"] * np.tanh(v_rel / ld["v_ref"])) * i_k
        assert_close(kin["slider.force"], want, 1e-12, "resisting force")
        assert np.all(dot(kin["slider.force"], i_k) * v_rel <= 0.0)
        assert np.max(norm(kin["slider.force"])) > 0.9 * ld["F0"]
    else:
        ld = load["output"]
        w = kin["output.omega"]
        want = -ld["T0"] * np.tanh(w / ld["w_ref"]) - ld["c"] * w
        assert_close(kin["output.moment"], want, 1e-14, "resisting torque")
        assert np.all(kin["output.moment"] * w <= 0.0)


# ---------------------------------------------------------------------------
# dynamics
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name, kind", CASES)
def test_reference_residuals(name, kind):
    ch = chain(name)
    motion = ch.motion(kind, 2.0)
    kin = ch.kinematics(times(motion, 181), motion)
    out = ch.reference(kin)
    assert set(out) == set(ch.output_names())
    assert all(np.all(np.isfinite(v)) and v.shape == kin["t"].shape for v in out.values())
    res = ch.residuals(kin, out)
    assert res.shape == kin["t"].shape
    assert np.max(res) < 1e-12, np.max(res)
    # the largest reaction scaled by 1 + 1e-6 is seen
    reactions = [k for k in out if ".R_" in k]
    key = max(reactions, key=lambda k: np.max(np.abs(out[k])))
    bad = dict(out)
    bad[key] = out[key] * (1.0 + 1e-6)
    i = int(np.argmax(np.abs(out[key])))
    assert ch.residuals(kin, bad)[i] > 1e-8, key


@pytest.mark.parametrize("name", NAMES)
def test_residuals_see_every_output(name):
    """Each output, moved by 1e-4 of the largest force (or moment) term, is detected."""
    ch = chain(name)
    motion = ch.motion("varying", 1.0)
    kin = ch.kinematics(times(motion, 24), motion)
    out = ch.reference(kin)
    forces = max(np.max(np.abs(out[k])) for k in out if ".R_" in k or ".N_" in k)
    moments = max(np.max(np.abs(out[k])) for k in out if k.endswith("torque") or ".M_" in k)
    for key in out:
        bad = dict(out)
        delta = 1e-4 * (moments if key.endswith("torque") or ".M_" in key else forces)
        bad[key] = out[key] + delta
        assert np.min(ch.residuals(kin, bad)) > 1e-7, key


def test_reactions_physics():
    """Some plain checks of the reference: the slot's force is normal to the slot, the
    crank torque on the loaded stroke of the shaper is about F0 reduced through the
    lever, and the whole mechanism's external forces balance its momentum change."""
    ch = chain("shaper")
    motion = ch.motion("constant", 1.0)
    kin = ch.kinematics(times(motion, 360), motion)
    out = ch.reference(kin)
    R = np.stack([out["slot.R_mn.x"], out["slot.R_mn.y"]], axis=-1)
    assert np.max(np.abs(dot(R, unit(kin["lever.angle"])))) < 1e-9 * np.max(norm(R))
    assert_close(out["slot.N_mn"], dot(R, rot90(unit(kin["lever.angle"]))), 1e-14, "N_mn")
    # the ram's guide force is vertical
    assert np.max(np.abs(out["ram.R_mk.x"])) < 1e-9 * np.max(np.abs(out["ram.R_mk.y"]))
    for c in (ch, chain("sixbar"), chain("rocker_slider")):
        k = c.kinematics(times(c.motion(), 90), c.motion())
        o = c.reference(k)
        total = np.stack([o["crank.R_O.x"], o["crank.R_O.y"]], axis=-1)
        for pr in c.pairs[1:]:
            if pr["second"] is None:  # a pair with the frame
                total = total + np.stack([o[pr["key"] + ".x"], o[pr["key"] + ".y"]], axis=-1)
        g = np.array(c.gravity)
        for b in c.bodies:
            m = c.scene["crank"]["mass"] if b == "crank" else c.links[b]["mass"]
            total = total + m * g - m * k[f"a_S_{b}"]
            if b != "crank":
                total = total + k[f"{b}.force"]
        assert np.max(norm(total)) < 1e-10 * np.max(np.abs(o["crank.R_O.x"])), c.name


def vec(out, key):
    return np.stack([out[f"{key}.x"], out[f"{key}.y"]], axis=-1)


@pytest.mark.parametrize("kind", KINDS)
def test_rocker_slider_balances(kind):
    """The rocker-slider's sliding pair on the moving rocker, written out by hand: R_mk
    is normal to the guide (N_mk j_k) at D_m on the slider, with the couple M_mk; the
    rocker takes -R_mk at D_m and -M_mk. Each of slider, rod and rocker balances, with
    moments about a fixed point of the plane (the origin), so that the d'Alembert terms
    are written here from a_S and epsilon."""
    ch = chain("rocker_slider")
    motion = ch.motion(kind, 1.0)
    kin = ch.kinematics(times(motion, 90), motion)
    out = ch.reference(kin)
    g = np.array(ch.gravity)
    i_k = unit(kin["rocker.angle"])
    R_mk = vec(out, "second.R_mk")
    assert_close(R_mk, col(out["second.N_mk"]) * rot90(i_k), 1e-13, "R_mk = N_mk j_k")
    assert np.max(np.abs(out["second.N_mk"])) > 1.0 and np.max(np.abs(out["second.M_mk"])) > 1e-3

    def inertial(b):
        link = ch.links[b]
        f = link["mass"] * g - link["mass"] * kin[f"a_S_{b}"] + kin[f"{b}.force"]
        return f, cross(kin[f"S_{b}"], f) - link["inertia"] * kin[f"{b}.epsilon"] + kin[
            f"{b}.moment"
        ]

    def check(b, terms, couples):
        F, M = inertial(b)
        scale_f = max(np.max(norm(f)) for _, f in terms)
        scale_m = max(np.max(np.abs(cross(p, f))) for p, f in terms)
        for p, f in terms:
            F, M = F + f, M + cross(p, f)
        for mu in couples:
            M = M + mu
        assert np.max(norm(F)) < 1e-12 * scale_f, b
        assert np.max(np.abs(M)) < 1e-12 * scale_m, b

    D, E = kin["second.D_m"], kin["second.E"]
    G, C, B = kin["second.D_n"], kin["first.D_n"], kin["first.E"]
    check("slider", [(D, R_mk), (E, vec(out, "second.R_mn"))], [out["second.M_mk"]])
    check("rod", [(E, -vec(out, "second.R_mn")), (G, vec(out, "second.R_np"))], [])
    check(
        "rocker",
        [(C, vec(out, "first.R_np")), (B, -vec(out, "first.R_mn")), (D, -R_mk)],
        [-out["second.M_mk"]],
    )


@pytest.mark.parametrize("name, kind", CASES)
def test_energy_balance(name, kind):
    kins, h = stencil(name, kind, 1e-3)
    ch = chain(name)
    mid = kins[2]
    out = ch.reference(mid)
    drive = out["crank.torque"] * mid["crank.omega"]
    energy = np.array([ch.kinetic_energy(k) + ch.potential_energy(k) for k in kins])
    balance = drive + ch.load_power(mid) - d1(energy, h)
    peak = np.max(np.abs(drive))
    assert np.max(np.abs(balance)) < 1e-6 * peak, np.max(np.abs(balance)) / peak
    # the terms are not trivial
    assert np.max(np.abs(ch.load_power(mid))) > 0.1 * peak
    assert np.ptp(ch.kinetic_energy(mid)) > 0 and np.ptp(ch.potential_energy(mid)) > 0


def test_energy_functions():
    """Kinetic and potential energy of a simple state written out by hand."""
    ch = chain("sixbar")
    kin = ch.kinematics(np.array([0.0]), ch.motion())
    sc = scene("sixbar")
    want_T = 0.5 * sc["crank"]["inertia"] * 10.0**2 + 0.5 * sc["crank"]["mass"] * (0.01 * 10.0) ** 2
    want_V = 0.0
    for lt in sc["link"]:
        g = lt["name"]
        want_T += (
            0.5 * lt["mass"] * dot(kin[f"v_S_{g}"], kin[f"v_S_{g}"])[0]
            + 0.5 * lt["inertia"] * kin[f"{g}.omega"][0] ** 2
        )
        want_V += lt["mass"] * 9.81 * kin[f"S_{g}"][0, 1]
    want_V += sc["crank"]["mass"] * 9.81 * kin["S_crank"][0, 1]
    assert ch.kinetic_energy(kin)[0] == pytest.approx(want_T, rel=1e-14)
    assert ch.potential_energy(kin)[0] == pytest.approx(want_V, rel=1e-14, abs=1e-15)
    assert ch.load_power(kin)[0] == pytest.approx(kin["output.moment"][0] * kin["output.omega"][0])
    ch = chain("rocker_slider")
    kin = ch.kinematics(np.array([0.1]), ch.motion())
    want = dot(kin["slider.force"], kin["v_S_slider"])[0]
    assert ch.load_power(kin)[0] == pytest.approx(want, rel=1e-14)
    assert want < 0.0


# ---------------------------------------------------------------------------
# drawing
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_drawing(name, tmp_path):
    ch = chain(name)
    motion = ch.motion("constant", 1.0)
    kin = ch.kinematics(np.linspace(0.0, motion.duration, 73), motion)
    out = ch.reference(kin)
    vectors = len(ch.dyads) * 3 + 1
    fig, ax = plt.subplots()
    drawn = chain_drawing.draw(ax, ch, kin, 10, out)
    arrows = [p for p in ax.patches if isinstance(p, FancyArrow)]
    assert len(arrows) == vectors == len(drawn["arrows"])
    assert drawn["scale"] > 0
    assert len(ax.get_legend().get_texts()) == vectors
    if name == "rocker_slider":
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any(t.startswith("second.R_mk on slider at D:") for t in texts), texts
    plt.close(fig)
    fig, ax = plt.subplots()
    drawn = chain_drawing.draw(ax, ch, kin, 10)
    assert not [p for p in ax.patches if isinstance(p, FancyArrow)] and not drawn["arrows"]
    plt.close(fig)
    path = chain_drawing.figure(ch, kin, out, [0, 18, 36, 54], tmp_path / f"{name}.png")
    assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError):
        chain_drawing.figure(ch, kin, out, [0], tmp_path / "one.png")


def test_guide_on_link_with_offset_pin():
    """The rocker-slider with the slider's pin E off its guide point (l_slider = 0.03 m)
    and the guide through a point off the rocker's axis at an angle: E from both links,
    velocities and accelerations against finite differences, and the reference."""
    sc = copy.deepcopy(scene("rocker_slider"))
    sc["link"][2]["length"] = 0.03
    sc["dyad"][1]["k"] = {"link": "rocker", "guide": -0.1, "at": [0.01, -0.02]}
    ch = chains.Chain("rocker_slider", sc, harness("rocker_slider"))
    motion = ch.motion("varying", 1.0)
    h = 3e-3 / harness("rocker_slider")["motion"]["omega"]
    t = times(motion, 40)
    kins = [ch.kinematics(t + j * h, motion) for j in range(-2, 3)]
    mid = kins[2]
    i_m, i_n = unit(mid["slider.angle"]), unit(mid["rod.angle"])
    assert np.max(norm(mid["second.D_m"] + 0.03 * i_m - mid["second.E"])) < 1e-12
    assert np.max(norm(mid["second.D_n"] + 0.2 * i_n - mid["second.E"])) < 1e-12
    assert np.all(mid["slider.angle"] == mid["rocker.angle"] - 0.1)
    i_r = unit(mid["rocker.angle"])
    Q = mid["first.D_n"] + 0.01 * i_r - 0.02 * rot90(i_r)
    assert np.max(norm(Q + col(mid["second.slide_k"]) * i_m - mid["second.D_m"])) < 1e-12
    s = np.array([k["second.slide_k"] for k in kins])
    assert_close(d1(s, h), mid["second.slide_k_rate"], 1e-6, "slide_k_rate", floor=1e-3)
    assert_close(d2(s, h), mid["second.slide_k_accel"], 1e-6, "slide_k_accel", floor=1e-2)
    for g, pair in (("slider", "D_m"), ("rod", "D_n")):
        P = np.array([k[f"second.{pair}"] for k in kins])
        assert_close(d2(P, h), mid[f"{g}.accel_d"], 1e-6, f"{g}.accel_d", floor=1e-2)
    a = np.unwrap(np.array([k["rod.angle"] for k in kins]), axis=0)
    assert_close(d2(a, h), mid["rod.epsilon"], 1e-6, "rod.epsilon", floor=1e-3)
    out = ch.reference(mid)
    assert np.max(ch.residuals(mid, out)) < 1e-12

"""The ram-driven lift (modelDescription/scenes/lift.toml, chains.toml [lift]) and what chains.py
reads from a scene (frame pivots, guide points, branches, the crank's pivot).

- the ram's stroke: its ends, and its velocity and acceleration against complex-step
  derivatives of its position, for both motions;
- the loop closes: both links of each dyad give the same E, the platform's pin stays on
  its vertical guide, the rod starts at the arm's tip; the geometry is rebuilt here from
  the scene file;
- both dyads assemble over the stroke with conditioning >= 0.2, and the platform rises by
  more than half a metre;
- every velocity and acceleration against complex-step derivatives in time;
- the reference: Newton-Euler residuals; the energy balance F v = d(T + V)/dt - P_payload
  (dE/dt by complex step) to 1e-9 of the peak power; the ram's force, N and M from the
  ram's own equilibrium written out here;
- chains.py takes frame pivots, guide points and branches from the scene when it gives
  them (a shifted frame and crank pivot translate the whole sixbar; a branch in the scene
  overrides chains.toml's), and the lift's table repeats none of them.
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.mechanisms import chains

ROOT = Path(__file__).resolve().parents[2]
KINDS = ("constant", "varying")
H = 1e-30


def scene_file(name="lift"):
    with open(ROOT / "modelDescription" / "scenes" / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def unit(angle):
    angle = np.asarray(angle)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def rot90(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def run(kind, count=121, complex_step=False):
    chain = chains.load("lift")
    motion = chain.motion(kind, 1.0)
    t = (np.arange(count) + 0.5) * motion.duration / count
    kin = chain.kinematics(t, motion)
    cs = chain.kinematics(t + 1j * H, motion) if complex_step else None
    return chain, motion, t, kin, cs


def test_lift_table_omits_what_the_scene_gives():
    table = chains.default_data()["lift"]
    assert "frame" not in table and "branches" not in table
    sc = scene_file()
    assert sc["scene"]["kinematics"] == "internal"
    assert all("branch" in d for d in sc["dyad"])
    chain = chains.load("lift")
    assert chain.driver == "ram" and chain.crank_name == "ram"
    lever, hoist = chain.plan
    assert tuple(lever["k"]["position"]) == tuple(sc["dyad"][0]["k"]["at"])
    assert tuple(hoist["k"]["point"]) == tuple(sc["dyad"][1]["k"]["at"])
    assert (lever["branch"], hoist["branch"]) == (sc["dyad"][0]["branch"], sc["dyad"][1]["branch"])


@pytest.mark.parametrize("kind", KINDS)
def test_stroke(kind):
    chain = chains.load("lift")
    motion = chain.motion(kind, 2.0)
    md = chains.default_data()["lift"]["motion"]
    x0, stroke = md["x0"], md["stroke"]
    assert motion.duration == pytest.approx(2 * 2 * math.pi / md["omega"], rel=1e-15)
    t = np.linspace(0.0, motion.duration, 4001)
    _, x, v, a = motion.sampled(t)
    assert x.min() >= x0 - 1e-15 and x.max() <= x0 + stroke + 1e-15
    assert x[0] == pytest.approx(x0, abs=1e-15) and x.max() == pytest.approx(x0 + stroke, abs=1e-9)
    assert abs(v[0]) < 1e-15 and abs(v[-1]) < 1e-12  # at rest at the ends
    _, xc, vc, _ = motion.sampled(t + 1j * H)
    assert np.max(np.abs(xc.imag / H - v)) < 1e-13 * np.max(np.abs(v))
    assert np.max(np.abs(vc.imag / H - a)) < 1e-13 * np.max(np.abs(a))


@pytest.mark.parametrize("kind", KINDS)
def test_closure_from_the_scene(kind):
    chain, motion, t, kin, _ = run(kind)
    sc = scene_file()
    ram, (lever, hoist) = sc["ram"], sc["dyad"]
    links = {link["name"]: link for link in sc["link"]}
    x = motion.position(t)
    R = np.array(ram["at"]) + x[:, None] * unit(ram["guide"])
    assert np.max(np.abs(kin["R"] - R)) < 1e-15
    o1 = np.array(lever["k"]["at"])
    arm, strut = links[lever["m"]], links[lever["n"]]
    E1 = kin["lever.E"]
    assert np.max(np.abs(o1 + arm["length"] * unit(kin["arm.angle"]) - E1)) < 1e-14
    assert np.max(np.abs(R + strut["length"] * unit(kin["strut.angle"]) - E1)) < 1e-14
    assert np.all(cross(R - o1, E1 - o1) * lever["branch"] > 0)  # left of O1 -> R
    tip = o1 + hoist["p"]["at"][0] * unit(kin["arm.angle"])
    tip += hoist["p"]["at"][1] * rot90(unit(kin["arm.angle"]))
    assert np.max(np.abs(kin["hoist.D_n"] - tip)) < 1e-14
    guide, at = hoist["k"]["guide"], np.array(hoist["k"]["at"])
    P = kin["hoist.E"]
    assert np.max(np.abs(cross(unit(guide), P - at))) < 1e-14
    rod = links[hoist["n"]]["length"]
    assert np.max(np.abs(tip + rod * unit(kin["rod.angle"]) - P)) < 1e-14
    assert np.all(np.sum((P - tip) * unit(guide), axis=-1) * hoist["branch"] > 0)
    platform = links[hoist["m"]]
    turn = kin["platform.angle"] - guide - platform.get("turn", 0.0)
    assert np.max(np.abs(turn)) < 1e-15


def test_conditioning_and_rise_over_the_stroke():
    chain = chains.load("lift")
    md = chains.default_data()["lift"]["motion"]
    x = np.linspace(md["x0"], md["x0"] + md["stroke"], 2001)
    kin = chain.positions(x)
    for dyad in ("lever", "hoist"):
        assert kin[f"{dyad}.conditioning"].min() >= 0.2, dyad
    # the conditioning written out: RRR |i_arm x i_strut|, RRT |i_rod . i_guide|
    rrr = np.abs(cross(unit(kin["arm.angle"]), unit(kin["strut.angle"])))
    rrt = np.abs(np.sum(unit(kin["rod.angle"]) * unit(math.pi / 2), axis=-1))
    assert np.max(np.abs(rrr - kin["lever.conditioning"])) < 1e-14
    assert np.max(np.abs(rrt - kin["hoist.conditioning"])) < 1e-14
    y = kin["hoist.E"][:, 1]
    assert np.all(np.diff(y) > 0), "the platform rises all along the stroke out"
    assert y[-1] - y[0] > 0.5


@pytest.mark.parametrize("kind", KINDS)
def test_complex_step_derivatives(kind):
    chain, _, _, kin, cs = run(kind, complex_step=True)
    triples = [("R", "v_R", "a_R"), ("ram.position", "ram.velocity", "ram.acceleration")]
    for b in chain.bodies:
        triples += [(f"S_{b}", f"v_S_{b}", f"a_S_{b}"), (f"{b}.angle", f"{b}.omega", None)]
        triples += [(f"{b}.omega", f"{b}.epsilon", None)]
    for g in chain.links:
        triples.append((f"{g}.vel_d", f"{g}.accel_d", None))
    for x, v, a in triples:
        for p, d in ((x, v), (v, a)):
            if d is None:
                continue
            want = np.asarray(kin[d])
            err = np.max(np.abs(np.imag(cs[p]) / H - want))
            assert err <= 1e-12 * max(np.max(np.abs(want)), 1e-300), (p, d, err)
    for e in chain.plan:
        for point in ("D_m", "E", "D_n"):
            assert np.all(np.isfinite(np.imag(cs[f"{e['name']}.{point}"])))


@pytest.mark.parametrize("kind", KINDS)
def test_reference_residuals_and_energy(kind):
    chain, motion, t, kin, cs = run(kind, complex_step=True)
    out = chain.reference(kin)
    assert chain.residuals(kin, out).max() < 1e-12
    g = np.array([0.0, -9.81])
    T = sum(
        0.5 * chain.mass_properties(b)[0] * np.sum(cs[f"v_S_{b}"] ** 2, axis=-1)
        + 0.5 * chain.mass_properties(b)[1] * cs[f"{b}.omega"] ** 2
        for b in chain.bodies
    )
    V = sum(-chain.mass_properties(b)[0] * (cs[f"S_{b}"] @ g) for b in chain.bodies)
    rate = np.imag(T + V) / H
    payload = np.array(chains.default_data()["lift"]["load"]["platform"]["force"])
    p_payload = kin["v_S_platform"] @ payload
    power = out["ram.force"] * kin["ram.velocity"]
    residual = power - (rate - p_payload)
    assert np.max(np.abs(residual)) < 1e-9 * np.max(np.abs(power))
    assert np.max(np.abs(kin["platform.force"] - payload)) == 0.0


@pytest.mark.parametrize("kind", KINDS)
def test_ram_equilibrium(kind):
    """The ram: actuator force F i_g and the guide's N j_g at R, the guide's couple M, the
    strut's pull -R_np at R, its weight and its inertia force at S."""
    chain, _, _, kin, _ = run(kind)
    out = chain.reference(kin)
    ram = scene_file()["ram"]
    i_g, m = unit(ram["guide"]), ram["mass"]
    j_g = rot90(i_g)
    R = kin["R"]
    S = R + ram["com"][0] * i_g + ram["com"][1] * j_g
    assert np.max(np.abs(kin["S_ram"] - S)) < 1e-15
    a_S = kin["ram.acceleration"][:, None] * i_g
    own = m * (np.array([0.0, -9.81]) - a_S)
    strut = -np.stack([out["lever.R_np.x"], out["lever.R_np.y"]], axis=-1)
    rest = own + strut
    force = -rest @ i_g
    normal = -rest @ j_g
    moment = -cross(S - R, own)
    scale = np.max(np.abs(force))
    assert np.max(np.abs(out["ram.force"] - force)) < 1e-12 * scale
    assert np.max(np.abs(out["ram.N"] - normal)) < 1e-12 * scale
    assert np.max(np.abs(out["ram.M"] - moment)) < 1e-12 * np.max(np.abs(moment))


def sixbar(shift=(0.0, 0.0), scene_edit=None, table_edit=None):
    sc = scene_file("sixbar")
    table = copy.deepcopy(chains.default_data()["sixbar"])
    if scene_edit:
        scene_edit(sc, table, np.asarray(shift))
    if table_edit:
        table_edit(table)
    return chains.Chain("sixbar", sc, table)


def frame_in_scene(sc, table, shift):
    """Every frame pivot and the crank's pivot stated by the scene, moved by shift; the
    harness table loses its frame."""
    frame = table.pop("frame")
    for d in sc["dyad"]:
        for key, pair in (("k", "D_m"), ("p", "D_n")):
            spec = d[key]
            if spec == "frame" or (isinstance(spec, dict) and spec.get("link") == "frame"):
                at = np.asarray(frame[d["name"]][pair]["position"]) + shift
                d[key] = {"link": "frame", "at": [float(c) for c in at]}
    sc["crank"]["at"] = [float(c) for c in shift]


def frame_nowhere(sc, table, shift):
    """Neither the scene nor the harness table says where the frame pivots are."""
    table.pop("frame")
    for d in sc["dyad"]:
        for key in ("k", "p"):
            if isinstance(d[key], dict) and d[key].get("link") == "frame":
                d[key] = "frame"


def test_scene_frame_pivots_and_crank_pivot():
    base, moved = sixbar(), sixbar((0.3, -0.2), frame_in_scene)
    same = sixbar((0.0, 0.0), frame_in_scene)
    motion = base.motion("varying", 1.0)
    t = np.linspace(0.0, motion.duration, 50)
    k0, k1, k2 = (c.kinematics(t, motion) for c in (base, moved, same))
    for e in base.plan:
        for point in ("D_m", "E", "D_n"):
            key = f"{e['name']}.{point}"
            assert np.max(np.abs(k2[key] - k0[key])) == 0.0
            assert np.max(np.abs(k1[key] - k0[key] - [0.3, -0.2])) < 1e-14
    assert np.max(np.abs(k1["A"] - k0["A"] - [0.3, -0.2])) < 1e-15
    r0, r1 = base.reference(k0), moved.reference(k1)
    for name in base.output_names():  # a translated mechanism: the same reactions
        scale = max(np.max(np.abs(r0[name])), 1.0)
        assert np.max(np.abs(r1[name] - r0[name])) < 1e-10 * scale, name
    # without the frame in chains.toml or in the scene: an error naming what is missing
    with pytest.raises(ValueError, match="fixed pivot"):
        sixbar(scene_edit=frame_nowhere)


def test_scene_branch_overrides_the_table():
    def flip(sc, table, shift):
        sc["dyad"][1]["branch"] = -table["branches"]["second"]

    base, flipped = sixbar(), sixbar(scene_edit=flip)
    assert flipped.plan[1]["branch"] == -base.plan[1]["branch"]
    phi = np.linspace(0.0, 2 * math.pi, 13)
    k0, k1 = base.positions(phi), flipped.positions(phi)
    D, G = k0["second.D_m"], k0["second.D_n"]
    side0, side1 = cross(G - D, k0["second.E"] - D), cross(G - D, k1["second.E"] - D)
    assert np.all(side0 * side1 < 0)


def test_scene_guide_point_and_turn():
    """The rocker_slider's fixed pivot and the shaper's frame guide through a point of the
    scene; a slider's turn from its guide."""
    sc = scene_file("shaper")
    table = copy.deepcopy(chains.default_data()["shaper"])
    h = table["frame"]["ram"].pop("D_m")["height"]
    sc["dyad"][1]["k"]["at"] = [0.7, h]  # another point of the same line
    slider = next(link for link in sc["link"] if link["name"] == "slider")
    del slider["angle"]
    slider["turn"] = 0.0
    shaper, base = chains.Chain("shaper", sc, table), chains.load("shaper")
    phi = np.linspace(0.0, 2 * math.pi, 17)
    k0, k1 = base.positions(phi), shaper.positions(phi)
    assert np.max(np.abs(k1["ram.E"] - k0["ram.E"])) < 1e-15
    sc["dyad"][1]["k"]["at"] = [0.7, h + 0.01]  # a parallel line 10 mm higher
    higher = chains.Chain("shaper", sc, table).positions(phi)
    assert np.max(np.abs(higher["ram.E"][:, 1] - h - 0.01)) < 1e-15
    slider["angle"] = 0.0
    with pytest.raises(ValueError, match="not both"):
        chains.Chain("shaper", sc, table)

"""The input series and reference outputs of the mechanism FMUs
(dyadfmu.mechanisms.driven.driver_motion_inputs), for the five built-in mechanisms, the
crank chains, the ram-driven chains (the lift) and the cylinder-driven ones (the tipper
and the cylinder test scenes), with loads where they act among them.

- the inputs are exactly the driver's motion and the loads the scene lists ([loads] and
  [[load]]), with the motion's values;
- the outputs are named as the FMU names them (written out here per dyad type) and
  equal the kinematics where they are kinematics;
- J = sum m |v_S|^2 / q'^2 + I omega^2 / q'^2 from the kinematics at the samples
  themselves, dJdq against a complex step of J in q, and torque0 (force0) against
  Lagrange's equation: effort0 - dJdq q'^2 / 2 = -(power of the loads and weights) / q'.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.mechanisms import builtin, chains, crank, driven

ROOT = Path(__file__).resolve().parents[2]
H = 1e-30
#: the sliding pairs of each type, written out: D_m (mk), E (mn), D_n (np)
SLIDING = {"RRR": (), "RRT": ("mk",), "RTR": ("mn",), "TRT": ("mk", "np"), "RTT": ("mk", "mn")}
CASES = [("builtin", n) for n in builtin.NAMES] + [
    ("chain", n) for n in chains.NAMES + chains.RAM_NAMES + chains.CYLINDER_NAMES
]
#: The cylinder scenes that are test scenes, not examples.
TEST_SCENES = ("cylinder_arm", "cylinder_boom")


def scene_of(kind, name):
    stem = driven.SCENE_OF[name] if kind == "builtin" else name
    folder = (
        ROOT / "tests" / "scenes" if name in TEST_SCENES else ROOT / "modelDescription" / "scenes"
    )
    with open(folder / f"{stem}.toml", "rb") as f:
        return tomllib.load(f)


def setup(kind, name, motion_kind="varying", count=73):
    mech = builtin.load(name) if kind == "builtin" else chains.load(name)
    motion = mech.motion(motion_kind, 1.0)
    t = (np.arange(count) + 0.45) * motion.duration / count
    return mech, motion, t, driven.driver_motion_inputs(mech, t, motion)


def driver_names(sc):
    if "ram" in sc:
        name = sc["ram"].get("name", "ram")
        return name, ("position", "velocity", "acceleration"), "force"
    if "cylinder" in sc:
        return sc["cylinder"]["name"], ("length", "velocity", "acceleration"), "force"
    name = sc["crank"].get("name", "crank")
    return name, ("angle", "omega", "epsilon"), "torque"


#: The outer pairs that slide, by dyad type (k at D_m, p at D_n).
SLIDES = {"RRR": "", "RRT": "k", "RTR": "", "TRT": "kp", "RTT": "k"}


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_inputs(kind, name):
    mech, motion, t, series = setup(kind, name)
    sc = scene_of(kind, name)
    driver, motion_names, _ = driver_names(sc)
    want = {f"{driver}.{k}" for k in motion_names}
    for link in sc.get("loads", {}).get("force", []):
        want |= {f"{link}.force.x", f"{link}.force.y"}
    for link in sc.get("loads", {}).get("moment", []):
        want.add(f"{link}.moment")
    for placed in sc.get("load", []):  # [[load]]: a force unless force = false, a moment
        if placed.get("force", True):
            want |= {f"{placed['name']}.force.x", f"{placed['name']}.force.y"}
        if placed.get("moment", False):
            want.add(f"{placed['name']}.moment")
    assert set(series.inputs) == want
    fns = (
        (motion.phi, motion.omega, motion.epsilon)
        if "crank" in sc
        else (motion.position, motion.velocity, motion.acceleration)
    )
    for what, fn in zip(motion_names, fns, strict=True):
        assert np.array_equal(series.inputs[f"{driver}.{what}"], fn(t))
    for key, value in series.inputs.items():
        assert value.shape == t.shape and value.dtype == float, key
    loaded = [k for k in series.inputs if not k.startswith(f"{driver}.")]
    assert loaded and any(np.max(np.abs(series.inputs[k])) > 0 for k in loaded)


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_output_names(kind, name):
    _, _, _, series = setup(kind, name)
    sc = scene_of(kind, name)
    driver, _, effort = driver_names(sc)
    want = set()
    for link in sc.get("link", []):
        want |= {f"{link['name']}.{k}" for k in ("angle", "omega", "epsilon")}
    for d in sc.get("dyad", []):
        for point in ("D_m", "E", "D_n"):
            want |= {f"{d['name']}.{point}.position.x", f"{d['name']}.{point}.position.y"}
        want.add(f"{d['name']}.conditioning")
        if d["type"] in ("RTR", "RTT"):
            want.add(f"{d['m']}.length")
        want |= {f"{d['name']}.slide_{side}" for side in SLIDES[d["type"]]}
        for pair in ("mk", "mn", "np"):
            want |= {f"{d['name']}.R_{pair}.x", f"{d['name']}.R_{pair}.y"}
        for pair in SLIDING[d["type"]]:
            want |= {f"{d['name']}.N_{pair}", f"{d['name']}.M_{pair}"}
    if "ram" in sc:
        want |= {f"{driver}.N", f"{driver}.M"}
    elif "cylinder" in sc:  # the link it turns, its axis, its pins, its barrel and rod
        link = sc["cylinder"]["link"]
        want |= {f"{g}.{k}" for g in (link, driver) for k in ("angle", "omega", "epsilon")}
        want |= {f"{driver}.B.position.x", f"{driver}.B.position.y", f"{driver}.conditioning"}
        want |= {
            f"{r}.{c}" for r in (f"{link}.R_O", f"{driver}.R_A", f"{driver}.R_B") for c in "xy"
        }
        want |= {f"{driver}.N", f"{driver}.M"}
    else:
        want |= {f"{driver}.R_O.x", f"{driver}.R_O.y"}
    want |= {f"{driver}.{effort}", f"{driver}.J", f"{driver}.dJdq", f"{driver}.{effort}0"}
    assert set(series.outputs) == want
    assert series.effort == f"{driver}.{effort}" and series.driver == driver
    for key, value in series.outputs.items():
        assert np.all(np.isfinite(value)), key


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_outputs_are_the_kinematics(kind, name):
    mech, motion, t, series = setup(kind, name)
    sc = scene_of(kind, name)
    kin = mech.kinematics(t, motion)
    if kind == "builtin":
        d = sc["dyad"][0]
        role = {d["m"]: "m", d["n"]: "n"}
        points = {f"{d['name']}.{p}.position": p for p in ("D_m", "E", "D_n")}
    else:
        role = {g: g for g in mech.links}
        points = {
            f"{e['name']}.{p}.position": f"{e['name']}.{p}" for e in mech.plan for p in ("D_m", "E")
        }
    if "cylinder" in sc:
        cyl, link = sc["cylinder"]["name"], sc["cylinder"]["link"]
        role.update({link: link, cyl: cyl})
        points[f"{cyl}.B.position"] = f"{cyl}.B"
        assert np.array_equal(series.outputs[f"{cyl}.conditioning"], kin[f"{cyl}.conditioning"])
    for link, key in role.items():
        for what in ("angle", "omega", "epsilon"):
            assert np.array_equal(series.outputs[f"{link}.{what}"], kin[f"{key}.{what}"])
    for name_, key in points.items():
        assert np.array_equal(series.outputs[f"{name_}.x"], kin[key][:, 0])
        assert np.array_equal(series.outputs[f"{name_}.y"], kin[key][:, 1])


def bodies(mech, kin):
    """(mass, inertia, v_S, omega) of every moving body, driver included, written out."""
    if isinstance(mech, chains.Chain):
        return [(*mech.mass_properties(b), kin[f"v_S_{b}"], kin[f"{b}.omega"]) for b in mech.bodies]
    c = mech.crank
    out = [(c["mass"], c["inertia"], kin["v_S_c"], kin["crank.omega"])]
    for g in ("m", "n"):
        link = mech.links[g]
        out.append((link["mass"], link["inertia"], kin[f"v_S_{g}"], kin[f"{g}.omega"]))
    return out


def coordinates(series):
    d = series.driver
    if f"{d}.position" in series.inputs:
        return (series.inputs[f"{d}.{k}"] for k in ("position", "velocity", "acceleration"))
    if f"{d}.length" in series.inputs:
        return (series.inputs[f"{d}.{k}"] for k in ("length", "velocity", "acceleration"))
    return (series.inputs[f"{d}.{k}"] for k in ("angle", "omega", "epsilon"))


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_effective_inertia(kind, name):
    mech, motion, t, series = setup(kind, name)
    q, dq, _ = coordinates(series)
    kin = mech.kinematics(t, motion)
    moving = np.abs(dq) > 0.05 * np.max(np.abs(dq))
    J = sum(m * np.sum(v * v, axis=-1) + i * w * w for m, i, v, w in bodies(mech, kin))
    J = J / (dq * dq)
    got = series.outputs[f"{series.driver}.J"]
    assert np.max(np.abs(got - J)[moving]) < 1e-12 * np.max(np.abs(J[moving]))
    Jc, _ = driven.effective_inertia(mech, q + 1j * H)
    dJ = np.imag(Jc) / H
    want = series.outputs[f"{series.driver}.dJdq"]
    assert np.max(np.abs(dJ - want)) < 1e-11 * np.max(np.abs(want))


def load_power(mech, kin):
    """The power of the active loads and of the weights (W)."""
    if isinstance(mech, builtin.Mechanism):
        return crank.load_power(mech, kin)  # weights included
    g = np.asarray(mech.gravity)
    weights = sum(mech.mass_properties(b)[0] * (kin[f"v_S_{b}"] @ g) for b in mech.bodies)
    return mech.load_power(kin) + weights


@pytest.mark.parametrize(("kind", "name"), CASES)
def test_effort_at_zero_acceleration(kind, name):
    mech, motion, t, series = setup(kind, name)
    _, dq, ddq = coordinates(series)
    kin = mech.kinematics(t, motion)
    out = series.outputs
    effort0 = out[f"{series.effort}0"]
    assert np.max(np.abs(out[series.effort] - out[f"{series.driver}.J"] * ddq - effort0)) < (
        1e-12 * np.max(np.abs(out[series.effort]))
    )
    moving = np.abs(dq) > 0.05 * np.max(np.abs(dq))
    lagrange = effort0 - 0.5 * out[f"{series.driver}.dJdq"] * dq * dq
    want = -load_power(mech, kin) / dq
    err = np.max(np.abs(lagrange - want)[moving])
    assert err < 1e-9 * np.max(np.abs(out[series.effort])), err


def test_other_branch_and_scene_path():
    mech = builtin.load("four-bar")
    motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration, 25)
    up = driven.driver_motion_inputs(mech, t, motion)
    down = driven.driver_motion_inputs(
        mech, t, motion, ROOT / "modelDescription" / "scenes" / "four_bar.toml", -1
    )
    assert not np.allclose(up.outputs["rocker.angle"], down.outputs["rocker.angle"])
    kin = mech.kinematics(t, motion, -1)
    assert np.array_equal(down.outputs["rocker.angle"], kin["m.angle"])
    J = sum(m * np.sum(v * v, axis=-1) + i * w * w for m, i, v, w in bodies(mech, kin))
    J = J / kin["crank.omega"] ** 2
    assert np.max(np.abs(down.outputs["crank.J"] - J)) < 1e-12 * np.max(J)
    assert np.max(np.abs(up.outputs["crank.J"] - J)) > 1e-6 * np.max(J)

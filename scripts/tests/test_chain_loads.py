"""Loads where they act ([[load]] tables) in the harness's NumPy reference of the chains
(scripts/dyadfmu/mechanisms/chains.py, chains.toml): the scenes four_bar_payload (a
payload at a coupler point, a drag along the coupler, a follower force and a moment on
the crank) and lift_loads (a follower force and a moment on the ram, a payload at the
platform's edge).

- the mechanism FMUs of both scenes, FMI 2 and 3, on both branches of the four-bar, over
  two driver cycles at a varying speed with every load swinging as chains.toml models it:
  every output within 1e-12 of its peak (kinematic) or of its unit's peak (the others),
  where the loads move the reactions by far more than that;
- a load at a point P of its link equals, output for output, the same load at the centre
  of mass C plus the moment (P - C) x F, the arm turned by the link's angle and a
  follower force turned into global components here, from the scene's numbers;
- the energy balance with the loads' power written out here (F . v_P + M omega, v_P from
  the centre of mass's velocity and the link's rate): the driver's power plus the loads'
  and the weights' equals d(kinetic energy)/dt, the derivative by complex step in time;
- malformed [[load]] tables and load models refused with the table named.
"""

from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import mechanism_fmus as mf
from dyadfmu.mechanisms import chains

SCENES = ("four_bar_payload", "lift_loads")
#: (scene, load, the point where the load is placed for the comparison: the scene's
#: own, or for a load the scene puts at the centre of mass a point off it; the ram's
#: guide angle, rad: the scene's, or turned so that the ram's frame is not the global
#: one and its follower force differs from a global one)
PLACED = [
    ("four_bar_payload", "payload", None, None),
    ("four_bar_payload", "drag", (0.12, -0.015), None),
    ("four_bar_payload", "tool", None, None),
    ("lift_loads", "push", None, None),
    ("lift_loads", "push", None, 0.3),
    ("lift_loads", "payload", None, None),
]


def scene(name):
    with open(paths.SCENES_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def harness(name):
    return chains.default_data()[name]


def rotate(theta, v):
    """The vectors v (..., 2) turned by the angles theta (...)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def is_moment(output):
    """The outputs of chains.py's reference in N m (the others are in N): a driving
    torque, a sliding pair's moment M_.., the ram guide's moment M."""
    return output.endswith(("torque", ".M")) or ".M_" in output


def unit_error(a, b):
    """The largest |a - b| of every output against the largest |b| of its unit."""
    peaks = {True: 0.0, False: 0.0}
    for key, value in b.items():
        peaks[is_moment(key)] = max(peaks[is_moment(key)], float(np.max(np.abs(value))))
    return max(float(np.max(np.abs(a[k] - b[k]))) / peaks[is_moment(k)] for k in b)


def the_loads(name):
    """The scene's [[load]] tables by name."""
    return {row["name"]: row for row in scene(name)["load"]}


def link_com(sc, link):
    driver = sc.get("crank") or sc.get("ram")
    if link == driver.get("name"):
        return np.asarray(driver["com"], dtype=float)
    return np.asarray(next(g for g in sc["link"] if g["name"] == link)["com"], dtype=float)


def global_force(row, kin):
    """A load's force (N, 2) in global components, from its inputs in kin."""
    f = np.stack([kin[f"{row['name']}.force.x"], kin[f"{row['name']}.force.y"]], axis=-1)
    if row.get("components", "global") == "link":
        f = rotate(kin[f"{row['link']}.angle"], f)
    return f


# ---------------------------------------------------------------------------
# the FMUs against chains.py
# ---------------------------------------------------------------------------
CASES = [
    (name, version, branch)
    for name in SCENES
    for version in (2, 3)
    for branch in ((1, -1) if name in mf.BRANCHES else (1,))
]


def _without_loads(name, branch, motion_kind, revolutions, t):
    """chains.py's reference over the same motion with every [[load]] input at 0."""
    chain = mf.mechanism_of(name, branch)
    kin = chain.kinematics(t, chain.motion(motion_kind, revolutions))
    for load in the_loads(name):
        for key in ("force.x", "force.y", "moment"):
            if f"{load}.{key}" in kin:
                kin[f"{load}.{key}"] = np.zeros_like(kin[f"{load}.{key}"])
    return chain.reference(kin)


@pytest.mark.parametrize(("name", "version", "branch"), CASES)
def test_the_fmus_agree_with_chains_over_the_motion(name, version, branch):
    """Every [[load]] input swings over the run; every output within 1e-12 of its peak
    (kinematic) or of its unit's (the others); without the loads chains.py's reactions
    move by more than 1e-3 of their unit's peak, so that the comparison sees the loads."""
    co, series, _ = mf.setup(name, version, branch, "varying", revolutions=2.0, steps=180)
    for load, row in the_loads(name).items():
        keys = (["force.x", "force.y"] if row.get("force", True) else []) + (
            ["moment"] if row.get("moment", False) else []
        )
        for key in keys:
            values = series.inputs[f"{load}.{key}"]
            assert np.ptp(values) > 0.1 * np.max(np.abs(values)), f"{load}.{key}"
    result = mf.run(name, version, branch, "varying", revolutions=2.0, steps=180)
    assert result.statuses == {0}
    print(mf.summary(result))
    assert result.worst_of(True)[1] < 1e-12, mf.summary(result)
    assert result.worst_of(False)[1] < 1e-12, mf.summary(result)
    bare = _without_loads(name, branch, "varying", 2.0, series.t)
    loaded = {k: series.outputs[k] for k in bare if k in series.outputs}
    assert unit_error({k: bare[k] for k in loaded}, loaded) > 1e-3


# ---------------------------------------------------------------------------
# a load at P = the load at C plus (P - C) x F
# ---------------------------------------------------------------------------
def _chain_with(name, edit, guide):
    sc = copy.deepcopy(scene(name))
    edit(sc)
    if guide is not None:
        sc["ram"]["guide"] = guide
    return chains.Chain(name, sc, harness(name))


@pytest.mark.parametrize(("name", "load", "point", "guide"), PLACED)
def test_a_load_at_a_point_is_the_load_at_the_centre_of_mass_plus_r_x_f(name, load, point, guide):
    """chains.py with the load at P against chains.py with it at the centre of mass C of
    its link and its moment input raised by (P - C) x F: every output alike to
    round-off (1e-13 of its unit's peak) over a cycle at a varying speed; without the
    added moment they differ."""
    row = the_loads(name)[load]
    com = link_com(scene(name), row["link"])
    at = np.asarray(point if point is not None else row["at"], dtype=float)
    assert np.hypot(*(at - com)) > 0.01  # a real moment arm

    def at_point(sc):
        next(r for r in sc["load"] if r["name"] == load)["at"] = list(at)

    def at_com(sc):
        moved = next(r for r in sc["load"] if r["name"] == load)
        moved["at"], moved["moment"] = list(com), True

    placed, centred = _chain_with(name, at_point, guide), _chain_with(name, at_com, guide)
    motion = placed.motion("varying", 1.0)
    t = (np.arange(90) + 0.3) * motion.duration / 90
    kin_p, kin_c = placed.kinematics(t, motion), centred.kinematics(t, motion)
    force = global_force(row, kin_p)
    arm = rotate(kin_p[f"{row['link']}.angle"], np.broadcast_to(at - com, force.shape))
    own = kin_p.get(f"{load}.moment", 0.0)
    kin_c[f"{load}.force.x"], kin_c[f"{load}.force.y"] = (
        kin_p[f"{load}.force.x"],
        kin_p[f"{load}.force.y"],
    )
    kin_c[f"{load}.moment"] = own + np.zeros(len(t))
    without = centred.reference(kin_c)
    kin_c[f"{load}.moment"] = own + cross(arm, force)
    want, got = placed.reference(kin_p), centred.reference(kin_c)
    error = unit_error(got, want)
    print(f"{name} {load}: worst difference {error:.1e} of its unit's peak")
    assert error < 1e-13
    assert unit_error(without, want) > 1e-4


# ---------------------------------------------------------------------------
# energy
# ---------------------------------------------------------------------------
def _load_power(name, chain, kin):
    """The loads' power, F . v_P + M omega of each [[load]] and F . v_S + M omega of each
    [loads] link, written out from the scene and the kinematics (W)."""
    sc = scene(name)
    total = 0.0
    for row in the_loads(name).values():
        link = row["link"]
        com = link_com(sc, link)
        theta, omega = kin[f"{link}.angle"], kin[f"{link}.omega"]
        at = np.asarray(row.get("at", com), dtype=float)
        r = rotate(theta, np.broadcast_to(at - com, theta.shape + (2,)))
        v_p = kin[f"v_S_{link}"] + omega[:, None] * np.stack([-r[:, 1], r[:, 0]], axis=-1)
        if row.get("force", True):
            total = total + np.sum(global_force(row, kin) * v_p, axis=-1)
        if row.get("moment", False):
            total = total + kin[f"{row['name']}.moment"] * omega
    for link in sc.get("loads", {}).get("force", []):
        total = total + np.sum(kin[f"{link}.force"] * kin[f"v_S_{link}"], axis=-1)
    for link in sc.get("loads", {}).get("moment", []):
        total = total + kin[f"{link}.moment"] * kin[f"{link}.omega"]
    return total


@pytest.mark.parametrize("name", SCENES)
def test_energy_balance_with_the_loads_where_they_act(name):
    """The driver's power + the loads' + the weights' = d(kinetic energy)/dt, the
    derivative a complex step in time, to 1e-9 of the peak power."""
    chain = chains.load(name)
    motion = chain.motion("varying", 1.0)
    t = (np.arange(120) + 0.45) * motion.duration / 120
    kin = chain.kinematics(t, motion)
    out = chain.reference(kin)
    h = 1e-20 * motion.duration
    kinetic = np.imag(chain.kinetic_energy(chain.kinematics(t + 1j * h, motion))) / h
    if chain.driver == "crank":
        drive = out[chain.drive_output] * kin[f"{chain.crank_name}.omega"]
    else:
        drive = out[chain.drive_output] * kin[f"{chain.crank_name}.velocity"]
    g = np.asarray(chain.gravity)
    weights = sum(chain.mass_properties(b)[0] * (kin[f"v_S_{b}"] @ g) for b in chain.bodies)
    loads = _load_power(name, chain, kin)
    peak = max(np.max(np.abs(drive)), np.max(np.abs(loads)))
    residual = np.max(np.abs(drive + loads + weights - kinetic))
    print(f"{name}: energy balance, worst residual {residual / peak:.1e} of the peak power")
    assert residual < 1e-9 * peak
    assert np.max(np.abs(loads)) > 0.1 * np.max(np.abs(drive))


# ---------------------------------------------------------------------------
# refusals
# ---------------------------------------------------------------------------
def _edit_load(load, **changes):
    def edit(sc, table):
        next(r for r in sc["load"] if r["name"] == load).update(changes)

    return edit


def _edit_model(load, **changes):
    def edit(sc, table):
        table["load"][load].update(changes)

    return edit


def _drop_model(load):
    def edit(sc, table):
        del table["load"][load]

    return edit


BAD = {
    "unknown link": (_edit_load("payload", link="boom"), "payload].link: unknown link 'boom'"),
    "components": (_edit_load("drag", components="local"), "drag].components: expected"),
    "name of a link": (_edit_load("drag", name="rocker"), "].name: expected an identifier"),
    "no input": (_edit_load("payload", force=False, moment=False), "one true"),
    "bad at": (_edit_load("tool", at=[0.1, math.nan]), "tool].at: expected finite"),
    "no model": (_drop_model("tool"), "[[load]] 'tool' but chains.toml has no model"),
    "model kind": (_edit_model("payload", model="payload"), "takes model 'swinging'"),
    "moment of a force": (_edit_model("drag", moment=1.0), "load.drag.moment: not a key"),
    "swing": (_edit_model("tool", force_swing=[1.0]), "tool.force_swing: expected two"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_malformed_loads_are_refused(case):
    """Each malformed [[load]] table or load model refused, the table named."""
    edit, words = BAD[case]
    sc, table = copy.deepcopy(scene("four_bar_payload")), copy.deepcopy(harness("four_bar_payload"))
    edit(sc, table)
    with pytest.raises(ValueError) as refused:
        chains.Chain("four_bar_payload", sc, table)
    assert words in str(refused.value)

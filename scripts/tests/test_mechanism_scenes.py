"""The mechanism FMU scenes of the five built-in mechanisms
(modelDescription/scenes/slider_crank.toml, four_bar, quick_return, scotch_yoke, trt_slot) against
mechanisms.toml, through the mechanism objects of dyadfmu.mechanisms.builtin.

Every number of each scene (crank pivot, length, mass, inertia, centre of mass; the frame
pivot or guide and its point; the links' lengths, masses, inertias, centres of mass; the
links' turns; the assembly branch; gravity) is compared with the mechanism's, and the
geometry the scene states (the branch's side, the guides' lines, the turns) is rebuilt
here from the scene alone and compared with the mechanism's kinematics. The loads the
scene lists are exactly the links the mechanism loads.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.mechanisms import builtin

ROOT = Path(__file__).resolve().parents[2]
SCENES = {
    "slider-crank": "slider_crank",
    "four-bar": "four_bar",
    "quick-return": "quick_return",
    "scotch-yoke": "scotch_yoke",
    "trt-slot": "trt_slot",
}
#: the frame point of each mechanism, from its geometry table (D_m's pivot or a point
#: of D_m's guide)
FRAME_POINT = {
    "slider-crank": lambda g: (0.0, g["offset"]),
    "four-bar": lambda g: tuple(g["O4"]),
    "quick-return": lambda g: tuple(g["O2"]),
    "scotch-yoke": lambda g: (0.0, -g["h"]),
    "trt-slot": lambda g: (0.0, g["h"]),
}


def scene(name):
    with open(ROOT / "modelDescription" / "scenes" / f"{SCENES[name]}.toml", "rb") as f:
        return tomllib.load(f)


def kinematics(mech, count=48):
    motion = mech.motion("constant", 1.0)
    return mech.kinematics((np.arange(count) + 0.4) * motion.duration / count, motion)


def unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def wrapped(a):
    return np.abs(np.mod(np.asarray(a) + math.pi, 2 * math.pi) - math.pi)


@pytest.mark.parametrize("name", builtin.NAMES)
def test_scene_header_and_crank(name):
    sc, mech = scene(name), builtin.load(name)
    head = sc["scene"]
    assert head["identifier"] == SCENES[name]
    assert head["kinematics"] == "internal" and head["outputs"] == ["all"]
    assert sc["effects"] == {"inertia": True, "gravity": True}
    assert (sc["gravity"]["x"], sc["gravity"]["y"]) == tuple(mech.gravity)
    crank = sc["crank"]
    assert tuple(crank["at"]) == (0.0, 0.0)
    assert crank["length"] == mech.crank["radius"]
    assert crank["mass"] == mech.crank["mass"]
    assert crank["inertia"] == mech.crank["inertia"]
    assert tuple(crank["com"]) == tuple(mech.crank["com"])
    assert len(sc["dyad"]) == 1 and sc["dyad"][0]["type"] == mech.dyad


@pytest.mark.parametrize("name", builtin.NAMES)
def test_links(name):
    sc, mech = scene(name), builtin.load(name)
    dyad = sc["dyad"][0]
    links = {link["name"]: link for link in sc["link"]}
    assert set(links) == {dyad["m"], dyad["n"]}
    kin = kinematics(mech)
    for g in ("m", "n"):
        link, want = links[dyad[g]], mech.links[g]
        assert link["mass"] == want["mass"]
        assert link["inertia"] == want["inertia"]
        assert tuple(link["com"]) == tuple(want["com"])
        varies = np.ptp(kin[f"{g}.length"]) > 0
        assert ("length" in link) == (not varies), (g, "a sliding length is no parameter")
        if "length" in link:
            assert np.all(kin[f"{g}.length"] == link["length"])


@pytest.mark.parametrize("name", builtin.NAMES)
def test_frame_and_guides(name):
    """The external links: the crank carries D_n (its pin, or its slot through O), the
    frame D_m (a pivot or a guide through a point), where the mechanism has them."""
    sc, mech = scene(name), builtin.load(name)
    dyad, kin = sc["dyad"][0], kinematics(mech)
    k, p = dyad["k"], dyad["p"]
    at = np.array(k["at"])
    assert tuple(at) == FRAME_POINT[name](mech.geometry)
    if "guide" in k:  # D_m slides on the frame guide through at
        i_k = unit(k["guide"])
        assert np.max(wrapped(kin["guide_k.angle"] - k["guide"])) < 1e-15
        assert np.max(np.abs(cross(i_k, kin["D_m"] - at))) < 1e-15
    else:
        assert np.max(np.abs(kin["D_m"] - at)) == 0.0
    if isinstance(p, dict):  # the slot on the crank, through O along the crank
        assert p["link"] == "crank" and tuple(p.get("at", (0.0, 0.0))) == (0.0, 0.0)
        assert np.max(wrapped(kin["guide_p.angle"] - kin["crank.angle"] - p["guide"])) < 1e-15
        assert np.max(np.abs(cross(unit(kin["crank.angle"]), kin["D_n"]))) < 1e-15
    else:
        assert p == "crank"
        assert np.max(np.abs(kin["D_n"] - kin["A"])) == 0.0


@pytest.mark.parametrize("name", builtin.NAMES)
def test_turns(name):
    """A link that keeps its direction: its angle is the turn from its guide (its outer
    pair slides) or from link m (link n of RTR, RTT)."""
    sc, mech = scene(name), builtin.load(name)
    dyad, kin = sc["dyad"][0], kinematics(mech)
    links = {link["name"]: link for link in sc["link"]}
    reference = {
        "m": kin.get("guide_k.angle") if "guide" in dyad["k"] else None,
        "n": kin.get("guide_p.angle") if isinstance(dyad["p"], dict) else None,
    }
    if mech.dyad in ("RTR", "RTT"):
        reference["n"] = kin["m.angle"]
    checked = 0
    for g in ("m", "n"):
        link = links[dyad[g]]
        if reference[g] is None:
            assert "turn" not in link, (g, "turns freely")
            continue
        assert np.max(wrapped(kin[f"{g}.angle"] - reference[g] - link["turn"])) < 1e-15
        checked += 1
    assert checked >= (0 if mech.dyad == "RRR" else 1)


@pytest.mark.parametrize("name", builtin.NAMES)
def test_branch(name):
    """The scene's branch, in the scene's convention, is the mechanism's assembly: RRR +1
    puts E on the left of the directed line D_m -> D_n; RRT +1 puts E ahead of the foot of
    D_n on the guide along i_k; RTR +1 has l_m > 0."""
    sc, mech = scene(name), builtin.load(name)
    dyad, kin = sc["dyad"][0], kinematics(mech)
    if mech.dyad in ("TRT", "RTT"):
        assert "branch" not in dyad
        return
    branch = dyad["branch"]
    if mech.dyad == "RRR":
        side = cross(kin["D_n"] - kin["D_m"], kin["E"] - kin["D_m"])
    elif mech.dyad == "RRT":
        side = np.sum((kin["E"] - kin["D_n"]) * unit(dyad["k"]["guide"]), axis=-1)
    else:
        side = kin["m.length"]
    assert np.all(branch * side > 0)


@pytest.mark.parametrize("name", builtin.NAMES)
def test_loads(name):
    sc, mech = scene(name), builtin.load(name)
    dyad, kin = sc["dyad"][0], kinematics(mech)
    loads = sc["loads"]
    for g in ("m", "n"):
        link = dyad[g]
        forced = np.max(np.abs(kin[f"{g}.force"])) > 0
        turned = np.max(np.abs(kin[f"{g}.moment"])) > 0
        assert (link in loads.get("force", [])) == forced, (link, "force")
        assert (link in loads.get("moment", [])) == turned, (link, "moment")
    assert set(loads.get("force", []) + loads.get("moment", [])) <= {dyad["m"], dyad["n"]}


def _internal_scenes() -> list[str]:
    """The scenes of modelDescription/scenes/ whose kinematics are solved inside their FMU."""
    return sorted(
        p.stem
        for p in (ROOT / "modelDescription" / "scenes").glob("*.toml")
        if tomllib.loads(p.read_text(encoding="utf-8"))["scene"].get("kinematics") == "internal"
    )


def _generator(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(ROOT / "modelDescription" / "scene.py"), *args],
        capture_output=True,
        text=True,
    )


@pytest.mark.parametrize("name", _internal_scenes())
def test_external_inputs_of_every_mechanism_scene(name):
    """What the kinematics inside save a user (the scenes report's 'inputs before'): the
    inputs the scene's FMU would take with every link's motion an input, for every
    mechanism scene, the ram-driven lift among them. More inputs than the scene's own,
    each named once."""
    scene = str(ROOT / "modelDescription" / "scenes" / f"{name}.toml")
    external = _generator(scene, "--external-inputs")
    assert external.returncode == 0, external.stderr[-600:]
    names = external.stdout.split()
    counts = re.search(r"(\d+) inputs?", _generator(scene, "--check").stdout)
    assert counts is not None
    assert len(names) == len(set(names)) > int(counts.group(1))
    assert all(re.fullmatch(r"[a-z][a-z0-9_]*(\.[a-z_]+)+", n) for n in names), names

"""The mpmath reference of a whole mechanism FMU (dyadfmu.reference.scene_mp).

- every Real output of every mechanism FMU of modelDescription/scenes/ (built, run through
  fmpy) against the reference at a few driver positions, both branches where a branch is
  tunable,
  within 1e-12 of the largest output of its unit; the scenes with several drivers (leg,
  three_drivers) and with cylinders pinned to moving links (carried_cylinders, excavator,
  loader) likewise, skipped while their FMUs (or scene files) are missing;
- the lift bisected with the reference's own status to within 1e-15 m of the ram
  position where its lever dyad stops closing: there, 50 and 80 digits agree to 30;
- the statuses: a dyad exactly at its dead point (singular), just inside it (ok, both
  branches, on their sides), just outside (cannot assemble, naming the dyad);
  TRT guides exactly parallel (singular);
- dyad_kinematics' start near an assembly limit gives the roots its float search gives
  where both apply;
- inputs and parameters by name, a wrong name refused.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from collections import defaultdict

import mpmath
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave
from dyadfmu.reference import dyad_kinematics as dk
from dyadfmu.reference import scene_mp

SCENES = dict.fromkeys(
    (
        "slider_crank",
        "four_bar",
        "quick_return",
        "scotch_yoke",
        "trt_slot",
        "engine",
        "monitor",
        "shaper",
        "sixbar",
        "rocker_slider",
        "four_bar_payload",
    ),
    (0.7, 1.9, 2.8),  # crank angles (rad), inside (0, pi) for trt_slot's slot
)
SCENES["lift"] = (0.13, 0.25, 0.38)  # ram positions (m) over its stroke
SCENES["lift_loads"] = SCENES["lift"]
SCENES["tipper"] = (1.4, 3.0, 4.6)  # cylinder lengths (m) over its stroke
SCENES["cylinder_arm"] = (0.4, 1.2, 2.0)
SCENES["cylinder_boom"] = (0.95, 1.2, 1.45)
#: scenes with several drivers: each driver's coordinate, in the scene's driver order
#: (cranks, rams, cylinders), over their working ranges
SCENES["leg"] = ((-1.05, -2.09), (-1.66, -1.48), (-0.44, -2.71))  # front, rear (rad)
SCENES["three_drivers"] = ((0.5, 1.0, 1.95), (2.5, 0.65, 1.86), (4.0, 1.35, 2.01))  # wheel,
# slide (m), jack (m)
#: cylinders pinned to moving links: lift, reach (m)
SCENES["carried_cylinders"] = ((1.1, 1.3), (1.25, 1.5), (1.4, 1.7), (1.38, 1.35))
#: boom_cyl, stick_cyl, bucket_cyl (m); lift_cyl, tilt_cyl (m)
# with the boom raised too (boom_cyl 3.3 m), where the bound of the round-off carried from
# cylinder to cylinder is largest (the scene's singular_threshold allows for it)
SCENES["excavator"] = (
    (2.65, 3.15, 2.35),
    (1.98, 3.75, 1.9),
    (1.98, 2.55, 2.8),
    (2.2, 2.6, 2.0),
    (3.3, 2.55, 2.8),
    (3.3, 3.75, 1.9),
)
SCENES["loader"] = ((1.825, 1.6), (1.25, 1.95), (2.4, 1.25), (2.0, 1.9))
#: the scenes with a tunable branch
BRANCHES = {
    "slider_crank": "engine.branch",
    "four_bar": "linkage.branch",
    "four_bar_payload": "linkage.branch",
}
#: the driver's rates and the loads: arbitrary, nonzero
RATES = {"omega": 9.5, "epsilon": -23.0, "velocity": 0.35, "acceleration": -1.7}
LOADS = {"force.x": -850.0, "force.y": 420.0, "moment": -3.5}
#: outputs the reference does not give: the FMU's bound on its own round-off
NOT_REFERENCED = ("amplification",)
LIFT_LIMIT = 0.712348  # m, about where the lift's arm and strut stretch out


def scene_file(name):
    """A shipped scene's file, or a test scene's (tests/scenes/)."""
    shipped = paths.SCENES_DIR / f"{name}.toml"
    return shipped if shipped.is_file() else paths.ROOT / "tests" / "scenes" / f"{name}.toml"


def inputs_at(scene, q):
    """The FMU's inputs: the driver at q (several drivers: each at its entry of the tuple
    q) with RATES, every load at LOADS."""
    if isinstance(q, tuple):
        coordinates = dict(zip((d.motion(True)[0] for d in scene.drivers), q, strict=True))
    else:
        coordinates = {scene.motion_inputs[0]: q}
    drivers = {d.name for d in scene.drivers}
    values = {}
    for name in scene.inputs:
        head, _, tail = name.partition(".")
        if name in coordinates:
            values[name] = coordinates[name]
        elif head in drivers:
            values[name] = RATES[tail]
        else:
            values[name] = LOADS[tail]
    return values


def run_fmu(name, cases):
    """(status, {output: value}, {output: unit}) of the FMI 2 FMU at each (parameters,
    inputs) of ``cases``, one instance per parameter set."""
    path = paths.built_fmu(name, 2, None, how="scripts/run-tests")
    out = []
    for params, rows in cases:
        s = Slave(path, instance_name=name)
        try:
            s.initialize(params)
            variables = [v for v in s.md.modelVariables if v.causality == "output"]
            reals = [v for v in variables if v.type == "Real"]
            units = {v.name: v.unit for v in reals}
            for t, values in enumerate(rows):
                s.set(tuple(values), list(values.values()))
                s.do_step(t * 1e-3, 1e-3)
                got = dict(zip(units, s.get(tuple(units)), strict=True))
                out.append((s.get_status(), got, units))
        finally:
            s.close()
    return out


def unit_errors(got, ref, units):
    """The error of each output relative to the largest reference output of its unit
    (angles modulo 2 pi)."""
    largest = defaultdict(float)
    for name, unit in units.items():
        largest[unit] = max(largest[unit], abs(float(ref[name])))
    errors = {}
    for name, unit in units.items():
        diff = got[name] - float(ref[name])
        if unit == "rad":
            diff = math.remainder(diff, 2 * math.pi)
        errors[name] = abs(diff) / (largest[unit] or 1.0)
    return errors


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_output_of_every_mechanism_fmu(name):
    """The FMU's every Real output (but its amplification) within 1e-12 of the largest
    reference output of its unit, status 0, at each position and branch."""
    scene = scene_mp.read_scene(scene_file(name))
    branch = BRANCHES.get(name)
    params = [{branch: b} for b in (1.0, -1.0)] if branch else [{}]
    cases = [(p, [inputs_at(scene, q) for q in SCENES[name]]) for p in params]
    runs = iter(run_fmu(name, cases))
    worst = (0.0, "")
    for p, rows in cases:
        for values in rows:
            status, got, units = next(runs)
            assert status == 0, (name, p, values)
            ref = scene_mp.evaluate(scene, {**values, **p}, dps=30)
            assert ref.status == scene_mp.OK, (name, p, values, ref.reason)
            units = {k: u for k, u in units.items() if k.rpartition(".")[2] not in NOT_REFERENCED}
            assert set(units) <= set(ref.outputs), set(units) - set(ref.outputs)
            for key, err in unit_errors(got, ref.outputs, units).items():
                worst = max(worst, (err, f"{key} at {values[scene.motion_inputs[0]]} {p}"))
    assert worst[0] < 1e-12, worst


def lift_values(x):
    scene = scene_mp.read_scene(scene_file("lift"))
    return scene, {**inputs_at(scene, x), "platform.force.x": 35.0, "platform.force.y": -900.0}


def bisect_lift():
    """(ok, failing) ram positions, less than 1e-15 m apart, where the lever stops closing
    by the reference's own status."""
    scene, values = lift_values(0.0)
    lo, hi = 0.70, 0.72
    for x, want in ((lo, scene_mp.OK), (hi, scene_mp.CANNOT_ASSEMBLE)):
        assert scene_mp.assembly_status(scene, {**values, "ram.position": x}).status == want
    while hi - lo > 1e-15:
        mid = 0.5 * (lo + hi)
        r = scene_mp.assembly_status(scene, {**values, "ram.position": mid})
        if r.status == scene_mp.OK:
            lo = mid
        else:
            assert (r.status, r.dyad) == (scene_mp.CANNOT_ASSEMBLE, "lever"), r
            hi = mid
    return lo, hi


def test_lift_at_its_assembly_limit_50_and_80_digits_agree():
    """Within 1e-15 m of the ram position where the arm and the strut stretch out (the
    lever's two closures merge), every output at 50 and 80 digits agrees to 30 digits of
    the largest output of its unit; the lever sits on its branch (+1: B left of O1 -> R)."""
    lo, hi = bisect_lift()
    assert hi - lo <= 1e-15 and abs(lo - LIFT_LIMIT) < 1e-6
    scene, values = lift_values(lo)
    r50, r80 = (scene_mp.evaluate(scene, values, dps=d) for d in (50, 80))
    assert r50.status == r80.status == scene_mp.OK
    assert set(r50.outputs) == set(r80.outputs)
    out = r80.outputs
    assert out["lever.conditioning"] < 1e-6  # near the limit indeed
    assert abs(out["arm.omega"]) > 1e3
    with mpmath.workdps(90):
        d_m, e, d_n = (
            (out[f"lever.{p}.position.x"], out[f"lever.{p}.position.y"])
            for p in ("D_m", "E", "D_n")
        )
        side = (d_n[0] - d_m[0]) * (e[1] - d_m[1]) - (d_n[1] - d_m[1]) * (e[0] - d_m[0])
        assert side > 0
        largest = defaultdict(lambda: mpmath.mpf(0))
        for k, v in out.items():
            largest[_unit_of(k)] = max(largest[_unit_of(k)], abs(v))
        worst = max(
            (abs(r50.outputs[k] - v) / (largest[_unit_of(k)] or 1), k) for k, v in out.items()
        )
    assert worst[0] < mpmath.mpf(10) ** -30, worst


def _unit_of(name: str) -> str:
    """A coarse unit of an output by its name: enough to group comparable outputs."""
    tail = name.rpartition(".")[2]
    if name.endswith((".x", ".y")):
        tail = name.rpartition(".")[0].rpartition(".")[2]
    groups = {"angle": "rad", "omega": "rad/s", "epsilon": "rad/s2", "position": "m"}
    if tail.startswith(("R_", "N_")) or tail in ("force", "N", "force0"):
        return "N"
    if tail.startswith("M_") or tail == "M":
        return "N.m"
    if tail.startswith("slide_") or tail == "length":
        return "m"
    return groups.get(tail, tail)


# ---------------------------------------------------------------------------
# statuses at and near a dead point
# ---------------------------------------------------------------------------
def stretched_scene():
    """A crank whose pin, at crank angle 0, lies exactly at full reach of an RRR dyad
    pivoted on the frame behind the crank's pivot: 0.25 + 0.375 = 0.625 m, every number
    a binary fraction."""
    return {
        "scene": {"identifier": "stretch", "description": "x", "outputs": ["all"]},
        "effects": {"inertia": True, "gravity": False},
        "crank": {"length": 0.25, "com": [0.1, 0.0], "mass": 1.0, "inertia": 0.01},
        "dyad": [
            {
                "name": "pair",
                "type": "RRR",
                "m": "a",
                "n": "b",
                "k": {"link": "frame", "at": [-0.375, 0.0]},
                "p": "crank",
                "branch": 1,
            }
        ],
        "link": [
            {"name": "a", "length": 0.25, "com": [0.1, 0.0], "mass": 1.0, "inertia": 0.01},
            {"name": "b", "length": 0.375, "com": [0.1, 0.0], "mass": 1.0, "inertia": 0.01},
        ],
    }


def test_exact_dead_point_is_singular_and_its_neighbourhood_ok():
    sc = stretched_scene()
    at = {"crank.angle": 0.0, "crank.omega": 1.0, "crank.epsilon": 0.0}
    r = scene_mp.evaluate(sc, at)
    assert (r.status, r.dyad, r.outputs) == (scene_mp.SINGULAR, "pair", {})
    near = {**at, "crank.angle": 1e-9}  # the pin moves inwards: two closures 1e-9 apart
    sides = []
    for branch in (1.0, -1.0):
        r = scene_mp.evaluate(sc, {**near, "pair.branch": branch}, dps=40)
        assert r.status == scene_mp.OK
        o = r.outputs
        sides.append(o["pair.E.position.y"] - o["pair.D_m.position.y"])
        assert 0 < o["pair.conditioning"] < 1e-8
    assert sides[0] > 0 > sides[1]
    far = copy.deepcopy(sc)
    far["dyad"][0]["k"]["at"] = [-0.3750000000000001, 0.0]
    r = scene_mp.assembly_status(far, at)
    assert (r.status, r.dyad) == (scene_mp.CANNOT_ASSEMBLE, "pair")


def test_trt_slot_parallel_to_its_guide_is_singular():
    scene = scene_mp.read_scene(scene_file("trt_slot"))
    r = scene_mp.evaluate(scene, inputs_at(scene, 0.0))
    assert (r.status, r.dyad) == (scene_mp.SINGULAR, "cross")
    r = scene_mp.evaluate(scene, inputs_at(scene, 1e-9), dps=30)  # the slider far away
    assert r.status == scene_mp.OK and r.outputs["cross.slide_k"] > 1e7


# ---------------------------------------------------------------------------
# dyad_kinematics near a limit, inputs
# ---------------------------------------------------------------------------
def _near_cases():
    """One dyad of each type about 1e-7 (relative) from its assembly limit, or with guides
    (slot and guide) 9e-4 rad from parallel: near enough for the start from the figure,
    far enough for the float search."""
    ik, jk = (math.cos(0.3), math.sin(0.3)), (-math.sin(0.3), math.cos(0.3))
    rrt_pin = tuple(0.2 * ik[c] + (0.4 - 1e-7) * jk[c] for c in (0, 1))
    rtr_pin = (0.0, 0.3 * math.sin(1.2) + 1e-7)
    reach = 0.65 - 1e-7
    moving = dk.Mount((0.1, -0.2), (0.3, 0.1), (1.0, -2.0), 0.3, 0.5, -1.0)
    return {
        "RRR": dk.DyadInputs(
            "RRR",
            moving,
            dk.Mount((0.1 + reach * math.cos(0.4), -0.2 + reach * math.sin(0.4)), (0.0, 0.5)),
            0.25,
            0.4,
            com_m=(0.1, 0.02),
            com_n=(0.2, -0.01),
        ),
        "RRT": dk.DyadInputs(
            "RRT",
            dk.Mount((0.0, 0.0), (0.1, 0.0), (0.0, 0.3), 0.3, 0.5, -1.0),
            dk.Mount(rrt_pin, (0.0, 0.2)),
            0.0,
            0.4,
            com_n=(0.2, 0.0),
        ),
        "RTR": dk.DyadInputs(
            "RTR",
            dk.Mount((0.0, 0.0), (0.1, 0.2)),
            dk.Mount(rtr_pin, (0.0, -0.1), (0.4, 0.0)),
            0.0,
            0.3,
            turn_n=1.2,
            com_m=(0.3, 0.0),
        ),
        "TRT": dk.DyadInputs(
            "TRT",
            dk.Mount((0.0, 0.1), direction=0.0),
            dk.Mount((0.0, 0.0), (0.0, 0.0), (0.0, 0.0), 9e-4, 1.5, 0.5),
            60.0,
            60.0,
        ),
        "RTT": dk.DyadInputs(
            "RTT",
            dk.Mount((0.0, 0.0), direction=0.0),
            dk.Mount((30.0, 0.05), (0.2, -0.1), (1.0, 0.5)),
            0.0,
            0.0,
            turn_m=9e-4,
            com_m=(1.0, 0.0),
        ),
    }


NEAR_CASES = _near_cases()


@pytest.mark.parametrize(
    ("kind", "branch"),
    [(k, b) for k in sorted(NEAR_CASES) for b in ((1, -1) if k in ("RRR", "RRT", "RTR") else (1,))],
)
def test_near_limit_start_finds_the_float_search_roots(kind, branch, monkeypatch):
    """Near an assembly limit (RRR, RRT, RTR) or parallel guides (TRT, RTT), where both
    routes apply, the start from the figure and the float search give every output alike
    to 30 digits."""
    inputs = dataclasses.replace(NEAR_CASES[kind], branch=branch)
    with mpmath.workdps(50):
        m = dk._model(inputs)
        assert dk._near_limit_starts(m, 0) not in (None, [])
    near = dk.solve(inputs, dps=40)
    monkeypatch.setattr(dk, "_NEAR_LIMIT", 0.0)
    monkeypatch.setattr(dk, "_LINEAR_NEAR", 0.0)
    with mpmath.workdps(50):
        assert dk._near_limit_starts(dk._model(inputs), 0) is None
    searched = dk.solve(inputs, dps=40)
    assert near["status"] == searched["status"] == "ok"
    for key, value in near.items():
        if isinstance(value, mpmath.mpf) and key != "residual":
            assert abs(value - searched[key]) <= 1e-30 * max(1, abs(value)), key


def test_inputs_and_parameters_by_name():
    scene = scene_mp.read_scene(scene_file("lift"))
    assert scene.motion_inputs == ("ram.position", "ram.velocity", "ram.acceleration")
    assert set(scene.inputs) == {*scene.motion_inputs, "platform.force.x", "platform.force.y"}
    assert scene.inputs["ram.position"] == 0.1  # [start]
    values = inputs_at(scene, 0.25)
    base = scene_mp.evaluate(scene, values, dps=20).outputs
    heavier = scene_mp.evaluate(scene, {**values, "gravity.y": -19.62}, dps=20).outputs
    assert base["ram.J"] == heavier["ram.J"] and base["ram.force"] != heavier["ram.force"]
    with pytest.raises(scene_mp.SceneError, match="'ram.speed' is no input or parameter"):
        scene_mp.evaluate(scene, {"ram.speed": 1.0})
    with pytest.raises(scene_mp.SceneError, match="ram.position must be finite"):
        scene_mp.evaluate(scene, {"ram.position": math.nan})
    with open(scene_file("sixbar"), "rb") as f:
        data = tomllib.load(f)
    data["dyad"][1]["k"] = {"link": "output", "at": [0.0, 0.0]}
    with pytest.raises(scene_mp.SceneError, match=r"dyad 'second'.k: 'output' is not"):
        scene_mp.read_scene(data)

"""Status 0 means right to the digits the FMU claims: every mechanism FMU against mpmath
truth (dyadfmu.reference.scene_mp, 50 digits), over its motion and on the way to its
assembly limits.

- Over the motion (the crank around its circle, the ram over its stroke; with several
  drivers, points of their working ranges): every output with status 0 within
  10 eps x amplification (the FMU's own output) of the peak of its unit over the motion.
- Bisected to each assembly limit (the lift's ram where its arm and strut stretch out;
  tests/scenes/toggles.toml's crank where its RRT rod and its RTR slot stop reaching;
  cylinder_arm's cylinder where its triangle stretches out and folds) and to the TRT
  slot's dead centre (slot and guide parallel); with several drivers, one driver moved
  and the others held at the middle of their working ranges (rates and accelerations
  nonzero), to the stroke limits of the cylinders carried by a driven link (their
  triangles stretched out and folded: carried_cylinders' reach, the excavator's stick
  cylinder at both ends and its bucket cylinder short, the loader's tilt cylinder at
  both ends) and to the excavator's bucket four-bar folded (its bucket cylinder long):
  going in, the status goes 0, then 1 (singular), and only past the last position that
  closes 4 (cannot assemble), never back; every output with status 0 within
  10 eps x amplification of the peak of its unit; at the last status 0 every output
  keeps half its digits (error below sqrt(eps) of the peak of its unit).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import multidriver_fmus as mdf
from dyadfmu.fmi.slave import Slave
from dyadfmu.mechanisms import multidriver
from dyadfmu.reference import scene_mp

EPS = float(np.finfo(float).eps)
TESTS_SCENES = paths.ROOT / "tests" / "scenes"
#: every mechanism FMU, and the driver positions its motion is sampled at
MOTION = {
    name: np.linspace(-math.pi, math.pi, 13)[:-1] + 0.05
    for name in (
        "slider_crank",
        "four_bar",
        "quick_return",
        "scotch_yoke",
        "engine",
        "monitor",
        "shaper",
        "sixbar",
        "rocker_slider",
        "four_bar_payload",
    )
}
MOTION["trt_slot"] = np.linspace(0.1, 3.0, 8)  # the slot's cross slide only in (0, pi)
MOTION["lift"] = np.linspace(0.1, 0.7, 8)  # m, the ram's stroke up to its limit
MOTION["lift_loads"] = MOTION["lift"]
MOTION["toggles"] = np.linspace(-0.9, 0.85, 8)  # rad, between its two limits
MOTION["tipper"] = np.linspace(1.25, 4.75, 8)  # m, the cylinder's stroke
MOTION["cylinder_arm"] = np.linspace(0.25, 2.18, 8)  # m, close to both toggles
MOTION["cylinder_boom"] = np.linspace(0.95, 1.45, 6)  # m, where its platform hangs


def _working_points(name: str, count: int = 6, seed: int = 35) -> list[tuple]:
    """``count`` random points of the working ranges of a scene with several drivers
    (chains.toml's, :attr:`.multidriver.MultiChain.ranges`): each a tuple of the drivers'
    coordinates in the scene's driver order (cranks, rams, cylinders)."""
    chain = multidriver.load(name)
    low, high = np.array([chain.ranges[d] for d in chain.driver_names]).T
    points = np.random.default_rng(seed).uniform(low, high, (count, len(low)))
    return [tuple(float(x) for x in q) for q in points]


#: scenes with several drivers: at points of their working ranges
MOTION.update({name: _working_points(name) for name in multidriver.NAMES})
#: the driver's rates and the loads: arbitrary, nonzero
RATES = {"omega": 9.5, "epsilon": -23.0, "velocity": 0.35, "acceleration": -1.7}
LOADS = {"force.x": -850.0, "force.y": 420.0, "moment": -3.5}
#: (scene, a driver position that closes, one beyond the limit[, the driver moved, the
#: others held at the middle of their working ranges]); the brackets found by scanning
#: the FMU's status
LIMITS = {
    "lift": ("lift", 0.70, 0.72),
    "toggles rtr": ("toggles", 0.80, 0.90),
    "toggles rrt": ("toggles", -0.90, -0.95),
    # the cylinder's triangle stretched out and folded (O, A and B in line)
    "cylinder long": ("cylinder_arm", 2.2, 2.25),
    "cylinder short": ("cylinder_arm", 0.25, 0.2),
    # cylinders carried by a driven link: their triangles stretched out and folded
    "carried reach long": ("carried_cylinders", 1.95, 2.0, "reach"),
    "carried reach short": ("carried_cylinders", 1.1, 1.05, "reach"),
    "excavator stick long": ("excavator", 3.9, 4.0, "stick_cyl"),
    "excavator stick short": ("excavator", 2.5, 2.4, "stick_cyl"),
    "excavator bucket short": ("excavator", 1.85, 1.8, "bucket_cyl"),
    "loader tilt long": ("loader", 2.31, 2.32, "tilt_cyl"),
    "loader tilt short": ("loader", 0.82, 0.81, "tilt_cyl"),
    # the bucket's four-bar folded (the connector over the bucket's link), before the
    # bucket cylinder's triangle stretches out
    "excavator linkage": ("excavator", 2.89, 2.895, "bucket_cyl"),
}


def scene_file(name: str):
    """The scene file of a mechanism FMU."""
    shipped = paths.SCENES_DIR / f"{name}.toml"
    return shipped if shipped.is_file() else TESTS_SCENES / f"{name}.toml"


class Mechanism:
    """A mechanism FMU (FMI 2) and its mpmath reference, evaluated at driver positions."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.scene = scene_mp.read_scene(scene_file(name))
        path = paths.built_fmu(name, 2, None, how="scripts/run-tests")
        self.fmu = Slave(path, instance_name=name)
        self.fmu.initialize({"on_singular": 2})  # a step without an answer goes on
        reals = [v for v in self.fmu.md.modelVariables if v.causality == "output"]
        self.units = {v.name: v.unit or "-" for v in reals if v.type == "Real"}
        self.compared = [n for n in self.units if not n.endswith("amplification")]
        self.t = 0.0

    def inputs(self, q: float | tuple) -> dict:
        """The FMU's inputs with the driver at q (several drivers: each at its entry of
        the tuple q)."""
        drivers = self.scene.drivers
        qs = q if isinstance(q, tuple) else (q,)
        coordinates = dict(zip((d.motion(True)[0] for d in drivers), qs, strict=True))
        values = {}
        for name in self.scene.inputs:
            head, _, tail = name.partition(".")
            if name in coordinates:
                values[name] = coordinates[name]
            elif head in {d.name for d in drivers}:
                values[name] = RATES[tail]
            else:
                values[name] = LOADS[tail]
        return values

    def step(self, q: float | tuple) -> tuple[int, dict, dict]:
        """(status, outputs, inputs) of one step with the driver at q."""
        values = self.inputs(q)
        self.fmu.set(tuple(values), list(values.values()))
        self.fmu.do_step(self.t, 1e-3)
        self.t += 1e-3
        got = dict(zip(self.units, self.fmu.get(tuple(self.units)), strict=True))
        return self.fmu.get_status(), got, values

    def truth(self, values: dict) -> dict:
        """Every output at 50 digits, as floats (the status checked ok)."""
        r = scene_mp.evaluate(self.scene, values, dps=50)
        assert r.status == scene_mp.OK, (values, r.reason)
        return {k: float(v) for k, v in r.outputs.items()}

    def close(self) -> None:
        """Free the FMU."""
        self.fmu.close()


def _error(name: str, unit: str, got: dict, truth: dict) -> float:
    diff = got[name] - truth[name]
    return abs(math.remainder(diff, 2 * math.pi) if unit == "rad" else diff)


def peaks(m: Mechanism, samples: list) -> dict:
    """The largest |truth| of each unit over the samples (status 0 ones)."""
    largest: dict = defaultdict(float)
    for _, _, truth in samples:
        for name in m.compared:
            largest[m.units[name]] = max(largest[m.units[name]], abs(truth[name]))
    return largest


def worst_against_bound(m: Mechanism, samples: list) -> tuple[float, str]:
    """The largest error / (eps x amplification x peak of its unit) over the samples,
    with the output and driver position where it is; and of each dyad's reactions
    against the dyad's own amplification and its largest reaction of the unit there."""
    largest = peaks(m, samples)
    worst = (0.0, "")
    for q, got, truth in samples:
        for name in m.compared:
            scale = EPS * got["amplification"] * (largest[m.units[name]] or 1.0)
            ratio = _error(name, m.units[name], got, truth) / scale
            worst = max(worst, (ratio, f"{name} at {q!r}"))
        for dyad, names in dyad_reactions(m).items():
            own: dict = defaultdict(float)
            for name in names:
                own[m.units[name]] = max(own[m.units[name]], abs(truth[name]))
            for name in names:
                scale = EPS * got[f"{dyad}.amplification"] * (own[m.units[name]] or 1.0)
                ratio = _error(name, m.units[name], got, truth) / scale
                worst = max(worst, (ratio, f"{name} against {dyad}.amplification at {q!r}"))
    return worst


def dyad_reactions(m: Mechanism) -> dict:
    """The reaction outputs (R_, N_, M_) of each dyad that has an amplification output."""
    out: dict = defaultdict(list)
    for name in m.compared:
        dyad, _, rest = name.partition(".")
        if f"{dyad}.amplification" in m.units and rest[:2] in ("R_", "N_", "M_"):
            out[dyad].append(name)
    return out


@pytest.mark.parametrize("name", sorted(MOTION))
def test_over_the_motion_every_output_is_within_its_amplification(name):
    """Every output with status 0 within 10 eps x amplification of the peak of its unit
    over the motion; the amplification at least 1 and finite."""
    if name in multidriver.NAMES and mdf.fmu_path(name, 2) is None:
        pytest.skip(f"{name}'s FMU is not built yet")
    m = Mechanism(name)
    try:
        samples = []
        for q in MOTION[name]:
            q = tuple(q) if isinstance(q, tuple) else float(q)
            status, got, values = m.step(q)
            assert status == 0, (name, q, m.fmu.messages[-1:])
            assert 1 <= got["amplification"] < 1 / EPS, (name, q)
            samples.append((q, got, m.truth(values)))
    finally:
        m.close()
    worst = worst_against_bound(m, samples)
    assert worst[0] <= 10, (name, worst)


def along(m: Mechanism, driver: str | None = None) -> Callable[[float], float | tuple]:
    """x -> the drivers' positions with one driver at x: a scene's only driver, or
    ``driver`` of several with the others held at the middle of their working ranges
    (chains.toml's)."""
    if driver is None:
        return float
    ranges = multidriver.load(m.name).ranges
    held = {d: 0.5 * (low + high) for d, (low, high) in ranges.items()}
    order = [d.name for d in m.scene.drivers]
    assert driver in order, (m.name, driver, order)
    return lambda x: tuple(float(x) if d == driver else held[d] for d in order)


def find_limit(
    m: Mechanism, inside: float, beyond: float, place: Callable[[float], float | tuple] = float
) -> float:
    """The last position x of a driver (a double) at which the FMU's chain closes with
    the drivers at place(x): status 0 or 1 there, 4 at the next double beyond."""
    assert m.step(place(inside))[0] != 4 and m.step(place(beyond))[0] == 4
    while True:
        mid = 0.5 * (inside + beyond)
        if mid in (inside, beyond):
            return inside
        if m.step(place(mid))[0] == 4:
            beyond = mid
        else:
            inside = mid


def approach(m: Mechanism, limit: str) -> tuple[list, list, int]:
    """(statuses, samples, status beyond) going in towards the limit in gaps of 10^-k
    (k = 1 .. 15 in quarter steps), then at the last position that closes; samples:
    (driver positions, outputs, truth) of the status-0 steps; the status beyond: at the
    next double."""
    _, inside, beyond, *driver = LIMITS[limit]
    place = along(m, *driver)
    edge = find_limit(m, inside, beyond, place)
    toward = math.copysign(1.0, beyond - inside)
    statuses, samples = [], []
    for k in np.arange(1.0, 15.25, 0.25):
        q = place(edge - toward * 10.0**-k)
        status, got, values = m.step(q)
        statuses.append(status)
        if status == 0:
            samples.append((q, got, m.truth(values)))
    statuses.append(m.step(place(edge))[0])
    after = m.step(place(math.nextafter(edge, toward * math.inf)))[0]
    return statuses, samples, after


@pytest.mark.parametrize("limit", sorted(LIMITS))
def test_singular_before_the_limit_and_right_until_then(limit):
    """Going in towards the limit (:func:`approach`; with several drivers, one of them,
    the others held): the status never goes back from 1 to 0, is 1 at the last position
    that closes, and only 4 beyond it; every status-0 output within 10 eps x
    amplification of its unit's peak, and within sqrt(eps) of it at the last."""
    name = LIMITS[limit][0]
    if name in multidriver.NAMES and mdf.fmu_path(name, 2) is None:
        pytest.skip(f"{name}'s FMU is not built yet")
    m = Mechanism(name)
    try:
        statuses, samples, after = approach(m, limit)
    finally:
        m.close()
    assert statuses[-1] == 1 and after == 4, (limit, statuses[-1], after)
    first_singular = statuses.index(1)
    assert set(statuses[first_singular:]) == {1}, (limit, statuses)
    assert first_singular >= 4 and len(samples) == first_singular, (limit, statuses)
    worst = worst_against_bound(m, samples)
    assert worst[0] <= 10, (limit, worst)
    q, got, truth = samples[-1]
    largest = peaks(m, samples[-1:])
    for name_ in m.compared:
        error = _error(name_, m.units[name_], got, truth)
        assert error <= math.sqrt(EPS) * (largest[m.units[name_]] or 1.0), (limit, q, name_)


@pytest.mark.parametrize("side", (1.0, -1.0))
def test_singular_at_a_dead_centre_and_right_until_then(side):
    """The TRT slot's crank turned to its guide (crank angle 0, slot and guide parallel:
    the slides run to infinity) from either side in steps of 10^-k: the status goes from 0
    to 1, never back, and is 1 at the dead centre; every status-0 output within
    10 eps x amplification of its unit's peak, and within sqrt(eps) of it at the last."""
    m = Mechanism("trt_slot")
    try:
        statuses, samples = [], []
        for k in np.arange(1.0, 16.25, 0.25):
            q = side * 10.0**-k
            status, got, values = m.step(q)
            statuses.append(status)
            if status == 0:
                samples.append((q, got, m.truth(values)))
        statuses.append(m.step(0.0)[0])
    finally:
        m.close()
    first_singular = statuses.index(1)
    assert set(statuses[first_singular:]) == {1}, statuses
    assert first_singular >= 4 and len(samples) == first_singular, statuses
    worst = worst_against_bound(m, samples)
    assert worst[0] <= 10, worst
    q, got, truth = samples[-1]
    largest = peaks(m, samples[-1:])
    for name_ in m.compared:
        error = _error(name_, m.units[name_], got, truth)
        assert error <= math.sqrt(EPS) * (largest[m.units[name_]] or 1.0), (q, name_)

"""Mechanism FMUs (scenes with ``kinematics = "internal"``) co-simulated from the
driver's motion and the loads alone, and compared output by output with the harness's
NumPy kinematics and Newton-Euler reference (:mod:`dyadfmu.mechanisms.driven`).

Each output's error is measured against its own peak over the run: max |FMU - reference|
/ max |reference|. An angle's error is the wrapped difference (the FMU gives angles in
(-pi, pi]).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.simulate import CoSimSetup, setup_for
from ..mechanisms import builtin, chains, driven
from .compare import communication_grid, simulate_matched

#: Every mechanism FMU: its harness mechanism and where that comes from.
MECHANISM_FMUS = {
    "slider_crank": ("builtin", "slider-crank"),
    "four_bar": ("builtin", "four-bar"),
    "quick_return": ("builtin", "quick-return"),
    "scotch_yoke": ("builtin", "scotch-yoke"),
    "trt_slot": ("builtin", "trt-slot"),
    "engine": ("builtin", "slider-crank"),
    "monitor": ("builtin", "four-bar"),
    "shaper": ("chain", "shaper"),
    "sixbar": ("chain", "sixbar"),
    "rocker_slider": ("chain", "rocker_slider"),
    "lift": ("chain", "lift"),
    "four_bar_payload": ("chain", "four_bar_payload"),
    "lift_loads": ("chain", "lift_loads"),
    "tipper": ("chain", "tipper"),
    # test scenes (tests/scenes/), built with the tests
    "cylinder_arm": ("chain", "cylinder_arm"),
    "cylinder_boom": ("chain", "cylinder_boom"),
}

#: The mechanisms that close in two ways: their FMU's tunable branch parameter, and the
#: sign that turns the harness's branch into the scene's (the four-bar of mechanisms.toml
#: counts E's side along A -> O4, the scene along D_m -> D_n = O4 -> A; the loaded
#: four-bar, a chain, takes the scene's branch, and its branch 1 is the four-bar's).
BRANCHES = {
    "slider_crank": ("engine.branch", 1),
    "four_bar": ("linkage.branch", -1),
    "four_bar_payload": ("linkage.branch", -1),
    "cylinder_arm": ("hoist.branch", 1),
}


@dataclass
class MechanismRun:
    """A mechanism FMU co-simulated and compared with the reference."""

    name: str
    fmi_version: int
    branch: int
    motion: str
    errors: dict  # output -> max |FMU - reference| / peak |reference|
    unit_errors: dict  # output -> max |FMU - reference| / the largest peak of its unit
    fmu: dict
    reference: dict
    inputs: list
    steps: int
    seconds: float
    statuses: set = field(default_factory=set)

    @property
    def worst(self) -> tuple[str, float]:
        """The output with the largest error, and that error."""
        name = max(self.errors, key=self.errors.get)
        return name, self.errors[name]

    def worst_of(self, kinematic: bool) -> tuple[str, float]:
        """The worst kinematic output (link motion, pair points, slides) against its own
        peak, or the worst of the others (reactions, the driver's balance and inertia)
        against the largest peak of its unit, as the accuracy contract states it."""
        errors = self.errors if kinematic else self.unit_errors
        chosen = {k: v for k, v in errors.items() if is_kinematic(k) == kinematic}
        name = max(chosen, key=chosen.get)
        return name, chosen[name]


def is_kinematic(output: str) -> bool:
    """Whether an output is kinematic: a link's motion or length, a pair's position, a slide."""
    head, _, last = output.rpartition(".")
    return (
        last in ("angle", "omega", "epsilon", "length")
        or head.endswith(".position")
        or head == "position"
        or last.startswith("slide_")
    )


def mechanism_of(
    name: str, branch: int = 1, data: dict | None = None
) -> builtin.Mechanism | chains.Chain:
    """The harness mechanism behind a mechanism FMU, with the scene's effects (a scene
    without gravity, the monitor's horizontal four-bar, gets a weightless mechanism); a
    chain of BRANCHES on the harness's assembly ``branch`` (a built-in mechanism takes
    its branch with its kinematics). ``data`` overrides the harness's table of the
    mechanism key by key (:func:`.chains.load`, :func:`.builtin.load`)."""
    kind, harness = MECHANISM_FMUS[name]
    if kind == "chain" and name in BRANCHES:
        parameter, sign = BRANCHES[name]
        return chains.load(harness, data, branches={parameter.split(".")[0]: sign * branch})
    if kind == "chain":
        return chains.load(harness, data)
    with open(paths.SCENES_DIR / f"{name}.toml", "rb") as f:
        effects = tomllib.load(f).get("effects", {})
    data = dict(data or {})
    if not effects.get("gravity", False):
        data["gravity"] = [0.0, 0.0]
    return builtin.load(harness, data or None)


def scene_file(name: str) -> Path:
    """The scene file of the mechanism FMU ``name``: a chain's (an example scene or a
    test scene, :func:`.chains.scene_path`), else ``modelDescription/scenes/<name>.toml``."""
    kind, harness = MECHANISM_FMUS[name]
    return chains.scene_path(harness) if kind == "chain" else paths.SCENES_DIR / f"{name}.toml"


def relative_error(output: str, got: np.ndarray, want: np.ndarray) -> float:
    """max |got - want| / max |want| (wrapped for an angle; absolute where want is 0)."""
    diff = got - want
    if output.endswith(".angle"):
        diff = np.angle(np.exp(1j * diff))
    peak = float(np.max(np.abs(want)))
    return float(np.max(np.abs(diff)) / (peak if peak > 0 else 1.0))


def setup(
    name: str,
    fmi_version: int = 2,
    branch: int = 1,
    motion: str = "constant",
    revolutions: float = 2.0,
    steps: int = 360,
    build: Path | None = None,
) -> tuple[CoSimSetup, driven.DrivenSeries, float]:
    """The co-simulation of the mechanism FMU `name` from the driver's motion and the
    loads alone, on the harness's assembly `branch`: (setup, the harness's series, the
    duration)."""
    if branch != 1 and name not in BRANCHES:
        raise ValueError(f"{name} closes in one way only: branch must be 1, not {branch}")
    mechanism = mechanism_of(name, branch)
    drive = mechanism.motion(motion, revolutions)
    t = communication_grid(drive.duration, revolutions, steps)
    kw = {"branch": branch} if name in BRANCHES else {}
    series = driven.driver_motion_inputs(mechanism, t, drive, scene=scene_file(name), **kw)
    start = {}
    if name in BRANCHES:
        parameter, sign = BRANCHES[name]
        start[parameter] = float(sign * branch)
    path = paths.built_fmu(name, fmi_version, build, how="scripts/run-tests")
    variables = read_model_description(str(path)).modelVariables
    given, wanted = set(series.inputs), {v.name for v in variables if v.causality == "input"}
    if given != wanted:  # an input left at its start value would go untested
        raise ValueError(
            f"{path.name}: the harness gives {sorted(given - wanted)}, which are no inputs "
            f"of the FMU, and no series for its inputs {sorted(wanted - given)}"
        )
    return setup_for(path, t, series.inputs, start), series, drive.duration


def run(
    name: str,
    fmi_version: int = 2,
    branch: int = 1,
    motion: str = "constant",
    revolutions: float = 2.0,
    steps: int = 360,
    build: Path | None = None,
) -> MechanismRun:
    """Co-simulate the mechanism FMU `name` over `revolutions` driver cycles at `steps`
    communication steps per cycle (see setup) and compare every output but the
    amplifications with the reference."""
    co, series, duration = setup(name, fmi_version, branch, motion, revolutions, steps, build)
    fmu, sample, seconds = simulate_matched(co, f"{name} FMI {fmi_version}", duration, False)
    compared = [o for o in co.outputs if o != "status" and not o.endswith("amplification")]
    want = {o: np.asarray(series.outputs[o])[sample] for o in compared}
    errors = {o: relative_error(o, fmu[o], want[o]) for o in compared}
    peaks: dict[str, float] = {}
    for o in compared:
        unit = co.units.get(o, "")
        peaks[unit] = max(peaks.get(unit, 0.0), float(np.max(np.abs(want[o]))))
    unit_errors = {
        o: errors[o] * float(np.max(np.abs(want[o]))) / (peaks[co.units.get(o, "")] or 1.0)
        for o in compared
    }
    return MechanismRun(
        name,
        fmi_version,
        branch,
        motion,
        errors,
        unit_errors,
        fmu,
        {k: np.asarray(v)[sample] for k, v in series.outputs.items()},
        list(series.inputs),
        len(co.time) - 1,
        seconds,
        set(np.unique(fmu["status"]).tolist()),
    )


def summary(result: MechanismRun) -> str:
    """One line: inputs, outputs, the worst error and where."""
    kin, kin_error = result.worst_of(True) if any(map(is_kinematic, result.errors)) else ("-", 0)
    other, other_error = result.worst_of(False)
    return (
        f"{result.name} FMI {result.fmi_version}, branch {result.branch:+d}, {result.motion}: "
        f"{len(result.inputs)} inputs, {len(result.errors)} outputs compared over "
        f"{result.steps} steps; worst kinematic {kin_error:.1e} of its peak ({kin}), "
        f"worst other {other_error:.1e} of its unit's peak ({other})"
        + ("" if result.statuses == {0} else f"; statuses {sorted(result.statuses)}")
    )


__all__ = [
    "BRANCHES",
    "is_kinematic",
    "MECHANISM_FMUS",
    "MechanismRun",
    "mechanism_of",
    "relative_error",
    "run",
    "scene_file",
    "setup",
    "summary",
]

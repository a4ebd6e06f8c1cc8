"""The example studies of the README (modelDescription/scenes/studies/), run as a user runs
them: the mechanism FMU built from the scene with the study's parameters tunable, two local Dask
workers. Their answers are checked by means the sweep does not use: the engine's
main-bearing force against superposition (a counterweight only adds its own weight and
centrifugal force), the shaper's against the physics of a flywheel."""

from __future__ import annotations

import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.fmi.slave import Slave
from dyadfmu.sweep import results, study

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ROOT / "modelDescription" / "scenes" / "studies"

pytestmark = pytest.mark.skipif(
    shutil.which("cmake") is None, reason="building a study's scene needs CMake"
)


def test_the_engine_counterweight_study_agrees_with_superposition(tmp_path):
    out = tmp_path / "out"
    result = study.run_study(STUDIES / "engine_counterweight.toml", out, workers=2, plots=False)
    table, s = result.table, result.study
    assert set(table.status) == {"ok"}
    # The force of the frame on the crank at O with no counterweight, from the FMU; a
    # counterweight m at a adds -m (g + omega^2 R(phi) a) and changes nothing else.
    fmu = next((out / "engine_counterweight").glob("engine_sweep_*.toml"))
    built = ROOT / "build-scene" / "fmus" / f"{fmu.stem}_fmi2.fmu"
    crank = Slave(built)
    crank.initialize()
    omega, n = s.run.speed, s.run.points
    phi = 2 * math.pi * np.arange(n) / n
    r0 = np.array(
        [
            crank.set(("crank.angle", "crank.omega", "crank.epsilon"), (p, omega, 0.0))
            or crank.get(("crank.R_O.x", "crank.R_O.y"))
            for p in phi
        ]
    )
    crank.close()
    ax, ay = s.parameters[0].at
    at = np.column_stack([np.cos(phi) * ax - np.sin(phi) * ay, np.sin(phi) * ax + np.cos(phi) * ay])
    gravity = np.array([0.0, -9.81])
    for k, (m,) in enumerate(table.values):
        force = r0 - m * (gravity + omega**2 * at)
        peak = np.max(np.hypot(force[:, 0], force[:, 1]))
        assert table.column("bearing_peak")[k] == pytest.approx(peak, rel=1e-10)
    best = result.best[0]
    assert 0 < table.values[best, 0] < 3.0  # inside the range: a balance, not a bound
    assert table.column("bearing_peak")[best] < 0.6 * table.column("bearing_peak")[0]


def test_the_shaper_motor_study_finds_a_design_within_the_fluctuation_limit(tmp_path):
    result = study.run_study(STUDIES / "shaper_motor.toml", tmp_path, workers=2)
    table, s = result.table, result.study
    assert set(table.status) == {"ok"}
    fluctuation = table.column("speed_fluctuation")
    best = result.best[0]
    assert fluctuation[best] <= 0.05
    assert results.feasible(table, s).sum() >= 1
    # More flywheel, less fluctuation, for every motor of the grid.
    for stall in np.unique(table.values[:, 0]):
        rows = np.flatnonzero(table.values[:, 0] == stall)
        by_inertia = rows[np.argsort(table.values[rows, 1])]
        assert np.all(np.diff(fluctuation[by_inertia]) < 0), stall
    # The motor's work per revolution is the mechanism's: the cutting (500 N over the
    # working stroke) and no more than a few percent of losses to the motor's speed drop.
    energy = table.column("motor_energy_per_revolution")
    assert np.all(np.abs(energy / np.median(energy) - 1) < 0.2)
    assert (tmp_path / "shaper_motor" / "designs.png").stat().st_size > 10_000


def _tip(fmu: Path, design: dict, run, payload: float) -> dict:
    """The tipper's FMU with a design's pins, stepped through the run's tip: the body's
    angle on the cycloid theta(t), the cylinder's length |B - A| with B = O + R(theta) p,
    its rate u . v_B and acceleration u . a_B + (|v_B|^2 - s'^2) / s from the motion of B
    about O. Returns each output's series."""
    scene = tomllib.loads((ROOT / "modelDescription" / "scenes" / "tipper.toml").read_text())
    o = np.array(scene["cylinder"]["at"])
    a = np.array([design["hoist.base.x"], design["hoist.base.y"]])
    p = np.array([design["hoist.pin.x"], design["hoist.pin.y"]])
    tau = np.linspace(0.0, 1.0, run.points)
    span, t_end = run.high - run.low, run.duration
    theta = run.low + span * (tau - np.sin(2 * math.pi * tau) / (2 * math.pi))
    omega = span / t_end * (1 - np.cos(2 * math.pi * tau))
    epsilon = 2 * math.pi * span / t_end**2 * np.sin(2 * math.pi * tau)
    tipper = Slave(fmu)
    tipper.initialize(design)
    names = ("hoist.force", "body.angle", "body.omega", "body.epsilon", "hoist.length", "status")
    series = {n: [] for n in names}
    h = t_end / (run.points - 1)
    for k in range(run.points):
        c, s = math.cos(theta[k]), math.sin(theta[k])
        r = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])
        d = o + r - a
        length = math.hypot(*d)
        u, across = d / length, np.array([-r[1], r[0]])
        v_b = omega[k] * across
        a_b = epsilon[k] * across - omega[k] ** 2 * r
        rate = u @ v_b
        acceleration = u @ a_b + (v_b @ v_b - rate**2) / length
        tipper.set(
            ("hoist.length", "hoist.velocity", "hoist.acceleration", "payload.force.y"),
            (length, rate, acceleration, payload),
        )
        tipper.do_step(k * h, h)
        for n in names:
            series[n].append(tipper.get(n))
    tipper.close()
    return {n: np.array(v) for n, v in series.items()} | {"theta": theta, "omega": omega,
                                                         "epsilon": epsilon}  # fmt: skip


def _collinear_within(design: dict, run) -> bool:
    """Whether O, A and B fall in line within the run: the sign of (A - O) x (B - O) at
    its two ends differs or is zero (once at most: the run turns the body by less than
    pi)."""
    o = np.array([0.0, 1.7])
    a = np.array([design["hoist.base.x"], design["hoist.base.y"]]) - o
    p = (design["hoist.pin.x"], design["hoist.pin.y"])

    def side(angle: float) -> float:
        c, s = math.cos(angle), math.sin(angle)
        return a[0] * (s * p[0] + c * p[1]) - a[1] * (c * p[0] - s * p[1])

    return side(run.low) * side(run.high) <= 0


def test_the_tipper_cylinder_study_agrees_with_the_fmu_stepped_through_the_tip(tmp_path):
    """The best pins' peak cylinder force against the FMU of the study set to them and
    stepped through the same tip, the cylinder's motion computed here from the pins; every
    design whose triangle passes its toggle within the tip is singular, with the angle,
    and only those; the best design beats the tipper's own pins."""
    from dataclasses import replace

    from dyadfmu.sweep.studyfile import Figure

    path = STUDIES / "tipper_cylinder.toml"
    out = tmp_path / "out"
    result = study.run_study(path, out, workers=2, plots=False)
    table, s = result.table, result.study
    assert set(table.status) <= {"ok", "singular", "inaccurate"}, set(table.status)
    copy = next((out / "tipper_cylinder").glob("tipper_sweep_*.toml"))
    fmu = ROOT / "build-scene" / "fmus" / f"{copy.stem}_fmi2.fmu"
    best = result.best[0]
    design = dict(zip(table.parameters, map(float, table.values[best]), strict=True))
    payload = s.loads[0].value[0]
    tip = _tip(fmu, design, s.run, payload)
    assert set(tip["status"]) == {0}
    assert np.max(np.abs(tip["body.angle"] - tip["theta"])) < 1e-9
    assert tip["body.omega"] == pytest.approx(tip["omega"], rel=1e-9, abs=1e-12)
    assert tip["body.epsilon"] == pytest.approx(tip["epsilon"], rel=1e-7, abs=1e-12)
    peak = np.max(np.abs(tip["hoist.force"]))
    assert table.column("force_peak")[best] == pytest.approx(peak, rel=1e-12)
    assert table.column("length_closed")[best] == pytest.approx(tip["hoist.length"].min())
    # the whole series, where the motion's rates count (the peak is at rest, body down)
    _, run, _, _ = study.prepare(path, out / "tipper_cylinder")
    rms = replace(run, figures=(Figure("force_rms", ("hoist.force",), "rms"),))
    (figure,) = rms(tuple(table.values[best])).figures
    assert figure == pytest.approx(np.sqrt(np.mean(tip["hoist.force"] ** 2)), rel=1e-12)
    # the designs that pass the toggle
    for k in range(len(table)):
        design = dict(zip(table.parameters, table.values[k], strict=True))
        toggles = "passes its toggle" in table.message[k]
        assert toggles == _collinear_within(design, s.run), (k, table.message[k])
        assert toggles <= (table.status[k] == "singular")
        assert toggles <= (not math.isfinite(table.figures[k][0]))
    assert any("passes its toggle" in m for m in table.message)
    original = np.flatnonzero(
        np.all(np.isclose(table.values, [5.3, 0.5, 4.3, -0.45], rtol=0, atol=1e-12), axis=1)
    )
    assert len(original) == 1 and table.status[original[0]] == "ok"
    assert table.column("force_peak")[best] < 0.9 * table.column("force_peak")[original[0]]


def test_the_excavator_pins_study_moves_all_three_cylinders_and_beats_the_original(tmp_path):
    """Every design of the excavator's pass runs (the boom's pins never bring its triangle
    to a toggle over it); the original pins are one of them, feasible, and the best design
    lowers the peak boom cylinder force by more than 15 % within the cylinder's lengths.
    The stick's and the bucket's cylinders, whose pins the study does not move, pull the
    same over every design: their motion is each design's same pass."""
    result = study.run_study(STUDIES / "excavator_pins.toml", tmp_path, workers=2, plots=False)
    table, s = result.table, result.study
    assert set(table.status) == {"ok"}, set(table.message)
    original = np.flatnonzero(
        np.all(np.isclose(table.values, [1.2, 0.7, 2.35, 0.75], rtol=0, atol=1e-12), axis=1)
    )
    assert len(original) == 1
    feasible = results.feasible(table, s)
    assert feasible[original[0]]
    best = result.best[0]
    force = table.column("boom_force_peak")
    assert force[best] < 0.85 * force[original[0]]
    assert table.column("boom_length_closed")[best] >= 2.0
    assert table.column("boom_length_extended")[best] <= 3.2
    stick = table.column("stick_force_peak")
    assert np.max(np.abs(stick / stick[original[0]] - 1)) < 1e-12

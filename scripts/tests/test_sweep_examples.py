"""The two example studies of the README (modelDescription/scenes/studies/), run as a user runs
them: the mechanism FMU built from the scene with the study's parameters tunable, two local Dask
workers. Their answers are checked by means the sweep does not use: the engine's
main-bearing force against superposition (a counterweight only adds its own weight and
centrifugal force), the shaper's against the physics of a flywheel."""

from __future__ import annotations

import math
import shutil
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

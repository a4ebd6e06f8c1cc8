"""dyadfmu.run_table and `dyadfmu rows`: every row holds the inputs and the outputs of one
instant, and each scene FMU's DefaultExperiment is the scene's own run.

- An algebraic FMU's row t is the geometry at the row's own crank angle (to 1e-15 m),
  where fmpy's simulate_fmu records the outputs of the inputs one row earlier.
- A plant's rows under constant inputs are fmpy's, bit for bit.
- A bad column, a time that does not increase, a refused input: RowsError naming it.
- The DefaultExperiment: [experiment] keys, else derived from the kind of scene.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import Rows, paths, run_table
from dyadfmu.fmi.rows import RowsError, default_grid
from fmpy import read_model_description, simulate_fmu
from fmpy.util import read_csv

ROOT = Path(__file__).resolve().parents[2]
SCENES_DIR = ROOT / "modelDescription" / "scenes"
VERSIONS = (2, 3)


def _slider_crank_x(angle: np.ndarray) -> np.ndarray:
    """The piston pin's x from the geometry: crank 0.05 m, rod 0.18 m, offset 0.01 m."""
    return 0.05 * np.cos(angle) + np.sqrt(0.18**2 - (0.01 - 0.05 * np.sin(angle)) ** 2)


def _crank_table(n: int = 21, omega: float = 31.4) -> dict:
    t = np.linspace(0.0, 0.2, n)
    return {"time": t, "crank.angle": 0.3 + omega * t, "crank.omega": np.full(n, omega)}


@pytest.mark.parametrize("version", VERSIONS)
def test_a_row_holds_the_outputs_of_its_own_inputs(version):
    fmu = paths.built_fmu("slider_crank", version)
    table = _crank_table()
    rows = run_table(fmu, table, ["engine.E.position.x", "status"])
    assert isinstance(rows, Rows) and len(rows) == 21
    assert np.array_equal(rows["crank.angle"], table["crank.angle"])  # the row's own input
    assert np.abs(rows["engine.E.position.x"] - _slider_crank_x(rows["crank.angle"])).max() < 1e-15
    assert np.all(rows["status"] == 0)
    # fmpy's rows over the same table: each one the outputs of the row before
    lagged = simulate_fmu(
        str(fmu),
        stop_time=0.2,
        output_interval=0.01,
        input=rows.table[list(rows.names[:6])],
        output=["engine.E.position.x"],
    )
    x = rows["engine.E.position.x"]
    assert np.array_equal(lagged["engine.E.position.x"][1:], x[:-1])
    assert not np.array_equal(lagged["engine.E.position.x"], x)


def test_every_input_is_recorded_with_its_unit_those_not_given_at_their_start():
    rows = run_table(paths.built_fmu("slider_crank", 2), _crank_table(5), ["crank.torque"])
    assert rows.names == (
        "time",
        "crank.angle",
        "crank.omega",
        "crank.epsilon",
        "piston.force.x",
        "piston.force.y",
        "crank.torque",
    )
    assert rows.units["time"] == "s" and rows.units["crank.torque"] == "N.m"
    assert rows.units["piston.force.x"] == "N" and rows.units["crank.angle"] == "rad"
    assert np.all(rows["crank.epsilon"] == 0.0) and np.all(rows["piston.force.x"] == 0.0)


@pytest.mark.parametrize("version", VERSIONS)
def test_a_plants_rows_under_constant_inputs_are_fmpys(version):
    fmu = paths.built_fmu("slider_crank_forward", version)
    t = np.linspace(0.0, 0.05, 26)
    inputs = {"time": t, "crank.torque": np.full(t.size, 2.0)}
    names = ["crank.angle", "crank.omega", "engine.R_np.x", "status"]
    rows = run_table(fmu, inputs, names, start_values={"crank.omega_start": 5.0})
    signals = rows.table[["time", "crank.torque", "piston.force.x", "piston.force.y"]]
    fmpy_rows = simulate_fmu(
        str(fmu),
        stop_time=0.05,
        output_interval=0.002,
        input=signals,
        output=names,
        start_values={"crank.omega_start": 5.0},
    )
    for name in names:
        assert np.array_equal(fmpy_rows[name], rows[name]), name
    assert rows["crank.angle"][-1] > 0.2  # it moved


def test_a_plants_row_holds_the_reactions_of_its_own_input():
    """A step in the torque at one row: that row's reaction is the new torque's, the state
    the old one's (the plant's state is continuous, its reactions are not)."""
    fmu = paths.built_fmu("slider_crank_forward", 2)
    t = np.linspace(0.0, 0.02, 11)
    torque = np.where(t < 0.01 - 1e-12, 1.0, 30.0)
    names = ["engine.R_np.x", "crank.angle"]
    base = run_table(fmu, {"time": t, "crank.torque": np.full(t.size, 1.0)}, names)
    rows = run_table(fmu, {"time": t, "crank.torque": torque}, names)
    k = int(np.argmax(torque > 1.0))
    assert rows["crank.angle"][k] == base["crank.angle"][k]  # the same state at t_k
    assert np.array_equal(rows["engine.R_np.x"][:k], base["engine.R_np.x"][:k])
    assert rows["engine.R_np.x"][k] != base["engine.R_np.x"][k]  # the torque of t_k


def _refusal(fmu, table, **kwargs) -> str:
    with pytest.raises(RowsError) as caught:
        run_table(fmu, table, **kwargs)
    return str(caught.value)


def test_a_bad_table_is_refused_by_name():
    fmu = paths.built_fmu("slider_crank", 2)
    t = np.linspace(0.0, 0.1, 3)
    message = _refusal(fmu, {"time": t, "crank.angel": t})
    assert "'crank.angel' is not an input or a tunable parameter" in message
    assert "crank.angle" in message
    assert "no 'time' column" in _refusal(fmu, {"crank.angle": t})
    message = _refusal(fmu, {"time": [0.0, 0.1, 0.1], "crank.angle": t})
    assert "must increase: row 2" in message
    assert "row 1 is nan" in _refusal(fmu, {"time": [0.0, math.nan]})
    assert "has 2 values, 'time' has 3" in _refusal(fmu, {"time": t, "crank.angle": t[:2]})
    assert "'nothing' is not a variable" in _refusal(fmu, {"time": t}, outputs=["nothing"])
    assert "not an FMU that loads here" in _refusal(ROOT / "README.md", {"time": t})
    assert "column 'crank.angle' is not numbers" in _refusal(
        fmu, {"time": t, "crank.angle": ["a", "b", "c"]}
    )
    message = _refusal(fmu, {"time": t}, start_values={"gravity.z": 1.0})
    assert "start value of 'gravity.z': not a variable" in message
    message = _refusal(fmu, {"time": t}, start_values={"gravity.y": math.nan})
    assert "refused to initialise" in message and "gravity.y" in message


def test_a_refused_input_names_the_time_and_keeps_the_rows_before():
    fmu = paths.built_fmu("slider_crank", 2)
    t = np.linspace(0.0, 0.1, 5)
    angle = np.array([0.0, 0.1, 0.2, math.inf, 0.4])
    with pytest.raises(RowsError) as caught:
        run_table(fmu, {"time": t, "crank.angle": angle})
    message = str(caught.value)
    assert "at t = 0.075 s (row 3)" in message and "crank.angle" in message
    assert len(caught.value.rows) == 3 and np.array_equal(
        caught.value.rows["crank.angle"], angle[:3]
    )


# ---------------------------------------------------------------------------
# the DefaultExperiment of each scene
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "identifier,stop,step",
    [
        ("slider_crank", 1.0, 1.0 / 360.0),  # a crank's mechanism: a row a degree at 60 rpm
        ("slider_crank_forward", 1.0, 1.0e-3),  # a plant
        ("lift", 1.0, 1.0e-2),  # a ram
        ("dyad_rrt", 1.0, 1.0e-2),  # a generic dyad: every input held
    ],
)
@pytest.mark.parametrize("version", VERSIONS)
def test_each_scene_fmu_runs_its_own_default_experiment(identifier, stop, step, version):
    fmu = paths.built_fmu(identifier, version)
    run = read_model_description(str(fmu)).defaultExperiment
    assert (float(run.stopTime), float(run.stepSize)) == (stop, step)
    grid = default_grid(fmu)
    assert len(grid) == round(stop / step) + 1 and grid[-1] == pytest.approx(stop, rel=1e-12)


def test_a_default_run_of_the_crank_mechanism_has_a_row_a_degree():
    rows = run_table(paths.built_fmu("slider_crank", 2))
    assert len(rows) == 361 and np.all(rows["status"] == 0)


def test_the_scene_files_experiment_is_the_fmus(tmp_path):
    text = (SCENES_DIR / "slider_crank.toml").read_text()
    scene = tmp_path / "slider_crank.toml"
    text = text.replace('identifier = "slider_crank"', 'identifier = "my_slider_crank"')
    scene.write_text(text + "\n[experiment]\nstop = 0.05\nstep = 1.0e-4\n")
    done = subprocess.run(
        [sys.executable, str(ROOT / "modelDescription" / "scene.py"), scene, "--out", tmp_path],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    for version in VERSIONS:
        md = read_model_description(str(tmp_path / f"fmi{version}" / "modelDescription.xml"))
        run = md.defaultExperiment
        assert (float(run.stopTime), float(run.stepSize)) == (0.05, 1.0e-4)


# ---------------------------------------------------------------------------
# dyadfmu rows
# ---------------------------------------------------------------------------
def _rows_command(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "dyadfmu", "rows", *map(str, args)], capture_output=True, text=True
    )


def test_the_rows_command_writes_what_run_table_returns(tmp_path):
    fmu = paths.built_fmu("slider_crank", 3)
    table = _crank_table(6)
    given = tmp_path / "in.csv"
    columns = list(table)
    values = np.column_stack([table[c] for c in columns])
    np.savetxt(given, values, fmt="%.17g", delimiter=",", header=",".join(columns), comments="")
    done = _rows_command(fmu, "--input", given, "--output", "crank.torque", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    assert "6 rows from t = 0 s to 0.2 s" in done.stdout and "crank.torque (N.m)" in done.stdout
    assert "rows with status other than 0 (ok)" not in done.stdout  # status not chosen
    written = read_csv(str(tmp_path / "slider_crank_fmi3.csv"))
    expected = run_table(fmu, table, ["crank.torque"])
    assert written.dtype.names == expected.names
    for name in expected.names:
        assert np.array_equal(written[name], expected[name]), name


def test_the_rows_command_names_what_it_refuses(tmp_path):
    fmu = paths.built_fmu("slider_crank", 2)
    given = tmp_path / "in.csv"
    given.write_text("time,crank.angel\n0,0\n")
    done = _rows_command(fmu, "--input", given, "--out", tmp_path)
    assert done.returncode == 1
    assert done.stderr.startswith("dyadfmu rows: error: column 'crank.angel'")
    assert len(done.stderr.splitlines()) == 1
    done = _rows_command(fmu, "--start", "gravity.y", "--out", tmp_path)
    assert done.returncode == 2 and "expected NAME=VALUE" in done.stderr
    done = _rows_command(tmp_path / "none.fmu")
    assert done.returncode == 2 and "none.fmu" in done.stderr

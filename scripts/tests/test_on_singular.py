"""on_singular through `fmpy simulate`, as a user runs it: a path through a position the
model has no answer for ends the run by default (FMI 3 with an error, FMI 2 at the last
successful time); with `--start-values on_singular 2` the run goes on, the samples
without an answer have NaN outputs and their status, and every other sample is what the
default run gives."""

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.fmi.slave import Slave, SlaveError
from fmpy import read_model_description

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("DYADFMU_BUILD", ROOT / "build"))
VERSIONS = (2, 3)
STEP = 0.01


def fmu(name: str, version: int) -> Path:
    path = BUILD / "fmus" / f"{name}_fmi{version}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (scripts/run-tests does)")
    return path


def write_inputs(path: Path, name: str, values: np.ndarray) -> None:
    t = np.arange(len(values)) * STEP
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["time", name])
        writer.writerows((repr(float(a)), repr(float(b))) for a, b in zip(t, values, strict=True))


def fmpy_simulate(fmu_path: Path, inputs: Path, outputs: list[str], out: Path, *start: str):
    """`fmpy simulate` over 1 s in steps of STEP; the finished process and its rows."""
    command = [sys.executable, "-m", "fmpy", "simulate", str(fmu_path), "--stop-time", "1"]
    command += ["--output-interval", str(STEP), "--input-file", str(inputs)]
    command += ["--output-variables", *outputs, "--output-file", str(out)]
    if start:
        command += ["--start-values", *start]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    rows = []
    if out.is_file():
        with open(out, newline="") as f:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return done, rows


def check_run_goes_on(default, default_rows, rows, outputs, failing_status, version):
    """The continued run: every sample, NaN and the status where there is no answer,
    and the default run's values everywhere else."""
    assert len(rows) == 101 and rows[-1]["time"] == pytest.approx(1.0)
    failed = [r for r in rows if r["status"] != 0]
    assert failed, "no sample without an answer: the path misses the singular position"
    assert all(r["status"] == failing_status for r in failed)
    assert all(math.isnan(r[name]) for r in failed for name in outputs if name != "status")
    answered = [r for r in rows if r["status"] == 0]
    assert all(math.isfinite(r[name]) for r in answered for name in outputs)
    assert rows[-1]["status"] == 0, "the run does not recover after the singular position"
    if version == 3:
        assert default.returncode != 0 and "status 2 (discard)" in default.stderr
        assert not default_rows
    else:
        assert default.returncode == 0 and len(default_rows) < len(rows)
        assert default_rows[-1]["status"] == failing_status
        for mine, theirs in zip(rows[: len(default_rows) - 1], default_rows[:-1], strict=True):
            assert mine == theirs  # bit for bit before the failure


@pytest.mark.parametrize("version", VERSIONS)
def test_a_dyad_goes_on_through_its_singular_position(version, tmp_path):
    """The RRT's rod swept through the normal of its guide (conditioning 6e-17 at 0.5 s)."""
    path = fmu("dyad_rrt", version)
    angle = math.pi / 2 + (np.arange(101) * STEP - 0.5)
    inputs = tmp_path / "inputs.csv"
    write_inputs(inputs, "link_n.angle", angle)
    outputs = ["R_mk.x", "R_np.y", "N_mk", "M_mk", "status"]
    default, default_rows = fmpy_simulate(path, inputs, outputs, tmp_path / "default.csv")
    done, rows = fmpy_simulate(path, inputs, outputs, tmp_path / "on.csv", "on_singular", "2")
    assert done.returncode == 0, done.stderr
    assert "[WARNING]" in done.stdout + done.stderr and "singular" in done.stdout + done.stderr
    check_run_goes_on(default, default_rows, rows, outputs, 1, version)


@pytest.mark.parametrize("version", VERSIONS)
def test_a_mechanism_goes_on_where_it_cannot_assemble(version, tmp_path):
    """The lift's ram pushed out of the arm's reach (1.5 m) and back: the mechanism FMU
    cannot assemble there (status 4) and assembles again once the ram is back."""
    path = fmu("lift", version)
    t = np.arange(101) * STEP
    position = 0.1 + 1.4 * np.sin(np.pi * t) ** 2
    inputs = tmp_path / "inputs.csv"
    write_inputs(inputs, "ram.position", position)
    outputs = ["arm.angle", "lever.R_mk.x", "hoist.R_mk.y", "status"]
    default, default_rows = fmpy_simulate(path, inputs, outputs, tmp_path / "default.csv")
    done, rows = fmpy_simulate(path, inputs, outputs, tmp_path / "on.csv", "on_singular", "2")
    assert done.returncode == 0, done.stderr
    check_run_goes_on(default, default_rows, rows, outputs, 4, version)


@pytest.mark.parametrize("version", VERSIONS)
def test_an_item_that_is_not_one_is_refused(version, tmp_path):
    """on_singular 3 stops the run before it starts, naming the items."""
    path = fmu("dyad_rrt", version)
    inputs = tmp_path / "inputs.csv"
    write_inputs(inputs, "link_n.angle", np.full(101, 0.4))
    done, rows = fmpy_simulate(path, inputs, ["status"], tmp_path / "o.csv", "on_singular", "3")
    assert done.returncode != 0 and not rows
    assert "on_singular = 3 is not an item of its enumeration: 1 (discard) or 2 (continue)" in (
        done.stdout + done.stderr
    )


def _is_plant(md: object) -> bool:
    """A plant (dynamics = "forward"): its integrator's tolerance is a parameter."""
    return any(v.name == "solver.rtol" for v in md.modelVariables)


def test_every_fmu_but_the_drive_declares_on_singular():
    """A discard-only FMU would be a surprise: every built FMU but those with states (the
    drive, the motor, the plants) has the parameter, an Enumeration of declared type
    OnSingular defaulting to discard."""
    fmus = sorted((BUILD / "fmus").glob("*_fmi[23].fmu"))
    assert len(fmus) >= 40
    for path in fmus:
        md = read_model_description(str(path))
        found = [v for v in md.modelVariables if v.name == "on_singular"]
        if path.name.startswith(("drive_", "motor_")) or _is_plant(md):
            assert not found  # a model with states stops where its step fails
            continue
        assert len(found) == 1, path.name
        v = found[0]
        assert (v.type, v.causality, v.variability, int(v.start)) == (
            "Enumeration",
            "parameter",
            "fixed",
            1,
        ), path.name
        items = {i.name: int(i.value) for i in v.declaredType.items}
        assert items == {"discard": 1, "continue": 2}, path.name


@pytest.mark.parametrize("version", VERSIONS)
def test_the_python_slave_sets_and_reads_on_singular(version):
    """dyadfmu's own wrapper takes on_singular among the parameters, by its item's value;
    the singular step then goes on, where by default it raises."""
    rod = "link_n.angle"
    default = Slave(fmu("dyad_rrt", version), instance_name="default")
    default.initialize({"link_m.mass": 2.0})
    default.set(rod, math.pi / 2)
    with pytest.raises(SlaveError):
        default.do_step(0.0, STEP)
    goes_on = Slave(fmu("dyad_rrt", version), instance_name="continue")
    goes_on.initialize({"link_m.mass": 2.0, "on_singular": 2})
    assert goes_on.get("on_singular") == 2 and goes_on.get("link_m.mass") == 2.0
    goes_on.set(rod, math.pi / 2)
    goes_on.do_step(0.0, STEP)
    assert goes_on.get_status() == 1 and math.isnan(goes_on.get("R_np.x"))
    goes_on.set(rod, 0.4)
    goes_on.do_step(STEP, STEP)
    assert goes_on.get_status() == 0 and math.isfinite(goes_on.get("R_np.x"))
    default.close()
    goes_on.close()

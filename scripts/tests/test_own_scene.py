"""`dyadfmu scene FILE.toml`: a user's own scene built where needed, drawn and reported over
one turn of its crank, with the instants where it does not assemble marked, not fatal."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
from dyadfmu.fmi.slave import Slave
from tool_checks import required_tool

ROOT = Path(__file__).resolve().parents[2]
SLIDER_CRANK = ROOT / "modelDescription" / "scenes" / "slider_crank.toml"


def _scene(tmp_path: Path, identifier: str, rod: float = 0.18, offset: float = 0.01) -> Path:
    text = SLIDER_CRANK.read_text().replace(
        'identifier = "slider_crank"', f'identifier = "{identifier}"'
    )
    text = text.replace("length = 0.18", f"length = {rod}")
    text = text.replace("at = [0.0, 0.01] }", f"at = [0.0, {offset}] }}")
    path = tmp_path / f"{identifier}.toml"
    path.write_text(text)
    return path


def _scene_command(*args: object) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "dyadfmu", "scene", *map(str, args)], capture_output=True, text=True
    )


def _csv(path: Path) -> dict:
    names = [n.strip('"') for n in path.read_text().splitlines()[0].split(",")]
    values = np.loadtxt(path, delimiter=",", skiprows=1)
    return {n: values[:, k] for k, n in enumerate(names)}


def test_a_users_scene_is_built_drawn_and_reported(tmp_path):
    required_tool("cmake")
    scene = _scene(tmp_path, "users_drawn")
    done = _scene_command(scene, "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr[-3000:]
    out = tmp_path / "out"
    for name in ("users_drawn.png", "users_drawn_forces.png", "users_drawn_reactions.png"):
        assert (out / name).stat().st_size > 10_000, name
    report = (out / "users_drawn_report.md").read_text()
    assert "| `crank.torque` |" in report and "No answer" not in report
    # each row of the reactions is the FMU's at that row's angle, turning at 60 rpm
    rows = _csv(out / "users_drawn_reactions.csv")
    assert len(rows["share"]) == 361
    fmu = next((ROOT / "build-scene" / "fmus").glob("users_drawn_fmi2.fmu"), None)
    fmu = fmu or next(out.glob("**/users_drawn_fmi2.fmu"))
    slave = Slave(fmu)
    slave.initialize()
    for k in (0, 97, 300):
        angle = 2 * math.pi * rows["share"][k]
        slave.set(("crank.angle", "crank.omega", "crank.epsilon"), (angle, 2 * math.pi, 0.0))
        rx, ry = slave.get(("crank.R_O.x", "crank.R_O.y"))
        assert abs(rows["crank.R_O"][k] - math.hypot(rx, ry)) <= 1e-9 * math.hypot(rx, ry)
    slave.close()
    # built once: a second run finds the FMU
    again = _scene_command(scene, "--out", tmp_path / "out")
    assert again.returncode == 0 and "building" not in again.stdout + again.stderr


def test_an_fmu_older_than_its_scene_or_the_sources_is_stale(tmp_path):
    import os

    from dyadfmu.report.own_scene import BUILT_FROM, stale

    project, scene, fmu = tmp_path / "project", tmp_path / "a.toml", tmp_path / "a_fmi2.fmu"
    for folder in BUILT_FROM:
        (project / folder).mkdir(parents=True)
        (project / folder / "x.c").write_text("")
        os.utime(project / folder / "x.c", (100, 100))
    scene.write_text("")
    os.utime(scene, (100, 100))
    assert stale(fmu, scene, project)  # missing
    fmu.write_text("")
    os.utime(fmu, (200, 200))
    assert not stale(fmu, scene, project)
    os.utime(project / "src" / "x.c", (300, 300))
    assert stale(fmu, scene, project)  # a core source changed
    os.utime(project / "src" / "x.c", (100, 100))
    os.utime(scene, (300, 300))
    assert stale(fmu, scene, project)  # the scene changed


def test_a_scene_that_does_not_assemble_everywhere_is_marked_not_fatal(tmp_path):
    """A rod of 0.05 m on a crank of 0.05 m off the axis by 0.01 m: no assembly where
    0.01 - 0.05 sin(phi) > 0.05, about 233 to 307 degrees."""
    required_tool("cmake")
    done = _scene_command(_scene(tmp_path, "users_short_rod", rod=0.05), "--out", tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    report = (tmp_path / "users_short_rod_report.md").read_text()
    gaps = [line for line in report.splitlines() if line.startswith("- ") and "%:" in line]
    assert "No answer at" in report and gaps
    first = float(gaps[0][2:].split(" %")[0])
    assert 60.0 < first < 68.0  # 233 degrees is 64.7 % of the turn
    rows = _csv(tmp_path / "users_short_rod_reactions.csv")
    missing = np.isnan(rows["crank.R_O"])
    share = rows["share"][missing]
    assert 0.6 < share.min() and share.max() < 0.88 and 0 < missing.sum() < 100
    assert (tmp_path / "users_short_rod.png").is_file()  # the poses that assemble


def test_a_scene_that_never_assembles_says_why_in_one_line(tmp_path):
    """A rod of 0.05 m on a crank of 0.05 m: it never reaches an axis 0.2 m off the pivot."""
    required_tool("cmake")
    scene = _scene(tmp_path, "users_no_rod", rod=0.05, offset=0.2)
    done = _scene_command(scene, "--out", tmp_path)
    assert done.returncode == 2, done.stderr[-3000:]
    (line,) = [ln for ln in done.stderr.splitlines() if ln.startswith("dyadfmu scene: error:")]
    assert "no instant of the turn of crank.angle has an answer" in line
    assert not (tmp_path / "users_no_rod.png").exists()


def test_a_scene_without_a_crank_says_how_to_draw_it(tmp_path):
    done = _scene_command(ROOT / "modelDescription" / "scenes" / "lift.toml", "--out", tmp_path)
    assert done.returncode == 2 and "no crank to turn" in done.stderr
    assert "drivers_drawing" in done.stderr
    done = _scene_command(tmp_path / "absent.toml", "--out", tmp_path)
    assert done.returncode == 2 and "no such scene file" in done.stderr

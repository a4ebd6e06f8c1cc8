"""The Python package as a user installs it: `pip wheel ./scripts` (scikit-build-core runs the
project's CMake and bundles the shared core, dyadfmu/_lib/libdyadfmu.so, the built-in
FMUs, dyadfmu/fmus/*.fmu, and the sources a scene's FMU is built from, dyadfmu/_project),
the wheel installed into a fresh venv with the dependencies at the versions of
scripts/constraints.txt, then, from a directory outside the checkout and with no DYADFMU_*
variable set, one dyad solved through Core() (against its closed form), one bundled FMU
read and simulated with fmpy, and a design study of a scene (its FMU built from the
bundled sources) while traps at every path derived from the install location record any
use of them.

One wheel build (without the FMUs' Windows binaries) and one venv per session (module
fixtures): about two and a half minutes on two cores, 90 s of it the CMake build and 55 s
the venv. Without CMake or a C compiler the tests skip, except under CI (CI=true), where they
fail (scripts/env.sh installs them).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from dyadfmu import paths
from tool_checks import required_tool

pytestmark = pytest.mark.slow  # about 2.5 minutes: one CMake build of the whole project

SCRIPTS = paths.ROOT / "scripts"
CONSTRAINTS = SCRIPTS / "constraints.txt"
#: The FMUs every package holds: the generic dyads, the drive and the motor, FMI 2 and 3.
EXPECTED_FMUS = [
    f"{name}_fmi{version}.fmu"
    for name in ("drive", "motor", "dyad_rrr", "dyad_rrt", "dyad_rtr", "dyad_rtt", "dyad_trt")
    for version in (2, 3)
]
#: One RRT dyad (the inputs of Core().solve) and its reactions in closed form, which this
#: checkout's core gives too: r_mk = (0, 24.175), r_np = (0.15, 9.81), ...
LINK_M = dict(
    dir=[0.6, 0.8],
    length=0.5,
    omega=2.0,
    epsilon=-1.0,
    accel_d=[0.3, -0.2],
    com=[0.1, 0.2],
    mass=1.5,
    inertia=0.05,
    force=[2.0, -1.0],
    moment=0.3,
)
LINK_N = dict(
    dir=[1.0, 0.0],
    length=0.7,
    omega=0.0,
    epsilon=0.0,
    accel_d=[0.4, 0.0],
    com=[0.35, 0.0],
    mass=2.0,
    inertia=0.08,
    force=[0.0, 0.0],
    moment=0.0,
)
CLOSED_FORM = dict(
    r_mk=[0.0, 24.175],
    r_np=[0.15, 9.81],
    r_mn=[-0.65, -9.81],
    n_mk=24.175,
    m_mk=1.0265,
    n_np=0.0,
    m_np=0.0,
)

#: Run in the installed venv: one RRT solve through Core() and one FMU, printed as JSON.
PROBE = """
import json, sys
import dyadfmu, dyadfmu.core, dyadfmu.paths
from dyadfmu.core import Core
from fmpy import read_model_description, simulate_fmu
m, n = json.loads(sys.argv[1])
core = Core()
fmu = dyadfmu.paths.built_fmu("dyad_rrt", 3)
md = read_model_description(str(fmu))
result = simulate_fmu(str(fmu), stop_time=0.01, output_interval=0.005)
print(json.dumps({
    "package": dyadfmu.__file__,
    "library": str(dyadfmu.core.library_path()),
    "fmu": str(fmu),
    "bundled": [p.name for p in dyadfmu.paths.bundled_fmus()],
    "solve": core.solve("RRT", m, n, guide_p=(1.0, 0.0), gravity=(0.0, -9.81)),
    "model": md.modelName,
    "fmi": md.fmiVersion,
    "rows": len(result),
}))
"""


def _run(*command: str | Path, cwd: Path | None = None, env: dict | None = None) -> str:
    done = subprocess.run(
        [str(c) for c in command], capture_output=True, text=True, cwd=cwd, env=env, check=False
    )
    assert done.returncode == 0, (
        f"{' '.join(str(c) for c in command)} exited with {done.returncode}:\n"
        f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    )
    return done.stdout


def _clean_env() -> dict[str, str]:
    """This environment without the checkout's pointers (DYADFMU_LIB, DYADFMU_BUILD,
    PYTHONPATH), so that the installed package finds only what it bundles."""
    return {
        key: value
        for key, value in os.environ.items()
        if not key.startswith("DYADFMU_") and key not in ("PYTHONPATH", "VIRTUAL_ENV")
    }


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel of scripts/, built once (scikit-build-core in a temporary build dir)."""
    required_tool("cmake")
    required_tool("cc")
    out = tmp_path_factory.mktemp("wheel")
    # without the FMUs' Windows and ARM binaries, to be quicker (test_windows.py and
    # test_aarch64.py have them)
    windows = "--config-settings=cmake.define.DYADFMU_WINDOWS=OFF"
    arm = "--config-settings=cmake.define.DYADFMU_AARCH64=OFF"
    command = ("-m", "pip", "wheel", SCRIPTS, "-w", out, "--no-deps", "-q", windows, arm)
    _run(sys.executable, *command, env=_clean_env())
    (found,) = out.glob("dyadfmu-*.whl")
    return found


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory) -> Path:
    """A fresh venv with the wheel and its dependencies at the constraints' versions."""
    where = tmp_path_factory.mktemp("venv") / "venv"
    _run(sys.executable, "-m", "venv", where)
    python = where / "bin" / "python"
    _run(python, "-m", "pip", "install", "-q", "-c", CONSTRAINTS, wheel, env=_clean_env())
    return python


def test_wheel_holds_core_and_fmus(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    assert "dyadfmu/_lib/libdyadfmu.so" in names
    fmus = {Path(name).name for name in names if name.startswith("dyadfmu/fmus/")}
    assert set(EXPECTED_FMUS) <= fmus, sorted(fmus)
    assert all(name.endswith(".fmu") for name in fmus)
    assert "dyadfmu/mechanisms/builtin.py" in names
    assert "dyadfmu/animation/page.html" in names  # the animation's page template
    assert any(n.startswith("dyadfmu/mechanisms/") and n.endswith(".toml") for n in names)
    # the C install of `cmake --install` (headers, static libraries, CMake package) stays out;
    # the sources of a scene's FMU are there, under dyadfmu/_project only
    project = [n for n in names if n.startswith("dyadfmu/_project/")]
    assert not [n for n in names if n.endswith((".a", ".cmake", ".pc"))]
    assert not [n for n in names if n.endswith(".h") and n not in project]
    for needed in (
        "CMakeLists.txt",
        "fmu/CMakeLists.txt",
        "fmu/fmu_instance.c",
        "src/dyad_rrt.c",
        "src/include/dyadfmu/dyad.h",
        "modelDescription/scene.py",
        "modelDescription/dyadgen/pipeline.py",
        "modelDescription/interface/dyad_interface.toml",
        "modelDescription/scenes/engine.toml",
    ):
        assert f"dyadfmu/_project/{needed}" in project, needed
    assert any("/dyadgen/emit/templates/" in n for n in project)
    assert not [n for n in names if "__pycache__" in n]
    (info,) = [n for n in names if n.endswith(".dist-info/METADATA")]
    metadata = zipfile.ZipFile(wheel).read(info).decode()
    assert "Requires-Python: >=3.11" in metadata
    requirements = [
        line.removeprefix("Requires-Dist: ").split(";")[0]
        for line in metadata.splitlines()
        if line.startswith("Requires-Dist: ")
    ]
    assert requirements and not [r for r in requirements if "==" in r], requirements


def test_installed_package_solves_and_simulates(venv, tmp_path):
    out = _run(venv, "-c", PROBE, json.dumps([LINK_M, LINK_N]), cwd=tmp_path, env=_clean_env())
    got = json.loads(out.splitlines()[-1])
    site = Path(got["package"]).parent
    assert paths.ROOT not in Path(got["package"]).parents, got["package"]
    assert Path(got["library"]) == site / "_lib" / "libdyadfmu.so"
    assert Path(got["fmu"]) == site / "fmus" / "dyad_rrt_fmi3.fmu"
    assert set(EXPECTED_FMUS) <= set(got["bundled"])
    assert got["model"] == "dyad_rrt" and got["fmi"] == "3.0" and got["rows"] >= 2
    assert got["solve"]["status"] == "ok"
    for key, value in CLOSED_FORM.items():
        assert got["solve"][key] == pytest.approx(value, rel=1e-12, abs=1e-12), key


#: A design study of tests/scenes/balance.toml (copied beside it): the counterweight that
#: balances the crank, known in closed form (scripts/tests/test_sweep.py).
SCENE_STUDY = """
[study]
scene = "balance.toml"

[run]
kind = "kinetostatic"
speed = 100.0
points = 36

[sampling]
method = "grid"
count = 13

[[parameter]]
name = "counterweight"
counterweight = "crank"
at = [-0.036, -0.009]
low = 0.0
high = 2.0

[[figure]]
name = "bearing_peak"
of = ["crank.R_O.x", "crank.R_O.y"]
stat = "peak"

[objective]
minimize = "bearing_peak"
best = 1
"""

#: A shared library whose loading writes MARKER: planted where the old checkout tests
#: looked (build/libdyadfmu.so beside the install location).
TRAP_LIBRARY = """
#include <stdio.h>
__attribute__((constructor)) static void trap(void)
{
    FILE* f = fopen(MARKER, "a");
    if (f) { fputs("build/libdyadfmu.so\\n", f); fclose(f); }
}
"""


def _plant_traps(python: Path, marker: Path, work: Path) -> tuple[Path, Path]:
    """Files at every path derived from the installed package's location that the package
    must never run: the scene generator, scripts/build-scene, the checkout's markers (so
    that a package taking itself for a checkout would go on to run them) and the core in
    build/. Each one that runs appends its name to `marker`. Returns (that location, the
    installed package's folder)."""
    derived = Path(_run(python, "-c", "import dyadfmu.paths as p; print(p.ROOT)", cwd=work).strip())
    site = Path(_run(python, "-c", "import dyadfmu; print(dyadfmu.__file__)", cwd=work).strip())
    # <venv>/lib/python3.X, outside the package: a folder of this test's own venv
    assert derived == site.parents[2] and python.parents[1] in derived.parents, derived
    script = f"open({str(marker)!r}, 'a').write(__file__ + '\\n')\nraise SystemExit(3)\n"
    for name in ("modelDescription/scene.py", "modelDescription/generate.py"):
        (derived / name).parent.mkdir(parents=True, exist_ok=True)
        (derived / name).write_text(script)
    shell = derived / "scripts" / "build-scene"
    shell.parent.mkdir(parents=True, exist_ok=True)
    shell.write_text(f'#!/bin/sh\necho "$0" >> "{marker}"\nexit 3\n')
    shell.chmod(0o755)
    (derived / "scripts" / "pyproject.toml").write_text("")
    (derived / "CMakeLists.txt").write_text(f'file(APPEND "{marker}" "CMakeLists.txt\\n")\n')
    (derived / "build").mkdir(exist_ok=True)
    source = work / "trap.c"
    source.write_text(f'#define MARKER "{marker}"\n' + TRAP_LIBRARY)
    _run("cc", "-shared", "-fPIC", "-o", derived / "build" / "libdyadfmu.so", source)
    return derived, site.parent


def test_installed_package_runs_a_scene_study_from_its_own_sources_only(venv, tmp_path):
    marker = tmp_path / "ran-outside-the-package.txt"
    work = tmp_path / "work"
    work.mkdir()
    derived, package = _plant_traps(venv, marker, work)
    try:
        (work / "balance.toml").write_text(
            (paths.ROOT / "tests" / "scenes" / "balance.toml").read_text()
        )
        (work / "study.toml").write_text(SCENE_STUDY)
        # with the checkout's markers planted beside it, the package still knows it is
        # installed, and none of its places lies there
        places = _run(
            venv, "-c", "import dyadfmu.paths as p, dyadfmu.core as c; print(p.in_checkout()); "
            "print(*[p.build_dir().resolve(), p.GENERATOR, p.SCENES_DIR, p.project_dir(), "
            "*c.library_candidates()], sep='\\n')", cwd=work, env=_clean_env(),
        ).split()  # fmt: skip
        assert places[0] == "False"
        beside = [p for p in places[1:] if derived in Path(p).parents]
        assert places[1:] and not [p for p in beside if package not in Path(p).parents], places
        dyadfmu = venv.parent / "dyadfmu"
        out = _run(dyadfmu, "sweep", "study.toml", "--workers", "0", "--out", "out", cwd=work,
                   env=_clean_env())  # fmt: skip
        assert not marker.exists(), marker.read_text()
        rows = (work / "out" / "study" / "results.csv").read_text().splitlines()
        assert rows[0] == "design,counterweight,bearing_peak,digits,status,message"
        assert all(row.endswith(",ok,") for row in rows[1:]) and len(rows) == 14
        # the best counterweight balances the crank: 2 kg at (12, 3) mm against m at (-36, -9) mm
        best = rows[5].split(",")
        assert float(best[1]) == pytest.approx(2.0 / 3.0, rel=1e-12)
        assert float(best[2]) < 1e-9 and "| 4 | 0.666667 |" in out
        built = list((work / "out" / "study" / "build-scene" / "fmus").glob("balance_sweep_*.fmu"))
        assert len(built) == 1  # in the study's own folder, from the bundled sources
        # a user's scene built by the installed command, where asked, from the same sources
        built = _run(dyadfmu, "build-scene", "balance.toml", "--out", "mine", "--windows", "off",
                     cwd=work, env=_clean_env())  # fmt: skip
        assert not marker.exists(), marker.read_text()
        for version in (2, 3):
            fmu = work / "mine" / "fmus" / f"balance_fmi{version}.fmu"
            assert f"{fmu}: " in built and fmu.is_file()
        # and, with every output, animated by the installed command from its own template
        every = (
            (work / "balance.toml")
            .read_text()
            .replace('outputs = ["crank.R_O", "crank.torque"]', 'outputs = ["all"]')
        )
        (work / "shown.toml").write_text(every.replace('"balance"', '"shown"', 1))
        shown = _run(dyadfmu, "animate", "shown.toml", "--no-gif", "--instants", "9",
                     "--out", "anim", cwd=work, env=_clean_env())  # fmt: skip
        assert not marker.exists(), marker.read_text()
        page = work / "anim" / "shown_animation.html"
        assert "shown_animation.html" in shown and "__DYADFMU_DATA__" not in page.read_text()
        # drawn and reported, and turned by the drive FMU, its FMU built once
        drawn = _run(dyadfmu, "scene", "shown.toml", "--out", "anim", cwd=work, env=_clean_env())
        assert "shown_report.md" in drawn
        turned = _run(dyadfmu, "cosim", "--scene", "shown.toml", "--duration", "0.1", "--out",
                      "anim", cwd=work, env=_clean_env())  # fmt: skip
        assert "mean speed" in turned and (work / "anim" / "shown_cosim.csv").is_file()
        assert len(list((work / "anim" / "build-scene" / "fmus").glob("shown_fmi*.fmu"))) == 2
        assert not marker.exists(), marker.read_text()
    finally:
        for name in ("modelDescription", "scripts", "build", "CMakeLists.txt"):
            target = derived / name
            if target.is_dir():
                shutil.rmtree(target)
            elif target.exists():
                target.unlink()


def test_installed_package_without_cmake_refuses_a_scene_study_in_one_line(venv, tmp_path):
    (tmp_path / "balance.toml").write_text(
        (paths.ROOT / "tests" / "scenes" / "balance.toml").read_text()
    )
    (tmp_path / "study.toml").write_text(SCENE_STUDY)
    empty = tmp_path / "bin"
    empty.mkdir()
    env = dict(_clean_env(), PATH=str(empty))  # no cmake, no cc
    done = subprocess.run(
        [str(venv.parent / "dyadfmu"), "sweep", "study.toml", "--workers", "0"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
    )
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(
        "dyadfmu sweep: building the study's mechanism FMU from its scene needs CMake (cmake), "
        "a C compiler (cc), not found here: install them (Debian: apt-get install cmake gcc"
    ), done.stderr

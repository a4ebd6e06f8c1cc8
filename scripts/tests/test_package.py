"""The Python package as a user installs it: `pip wheel ./scripts` (scikit-build-core runs the
project's CMake and bundles the shared core, dyadfmu/_lib/libdyadfmu.so, and the built-in
FMUs, dyadfmu/fmus/*.fmu), the wheel installed into a fresh venv with the dependencies at
the versions of scripts/constraints.txt, then, from a directory outside the checkout and
with no DYADFMU_* variable set, one dyad solved through Core() (against its closed form) and
one bundled FMU read and simulated with fmpy.

One wheel build (without the FMUs' Windows binaries) and one venv per session (module
fixtures): about two and a half minutes on two cores, 90 s of it the CMake build and 55 s
the venv. Without CMake or a C compiler the tests skip, except under CI (CI=true), where they
fail (scripts/env.sh installs them).
"""

from __future__ import annotations

import json
import os
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
#: The FMUs every package holds: the generic dyads and the drive, FMI 2 and 3.
EXPECTED_FMUS = [
    f"{name}_fmi{version}.fmu"
    for name in ("drive", "dyad_rrr", "dyad_rrt", "dyad_rtr", "dyad_rtt", "dyad_trt")
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
    # without the FMUs' Windows binaries, to be quicker (tests/test_windows.py has them)
    windows = "--config-settings=cmake.define.DYADFMU_WINDOWS=OFF"
    command = ("-m", "pip", "wheel", SCRIPTS, "-w", out, "--no-deps", "-q", windows)
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
    assert any(n.startswith("dyadfmu/mechanisms/") and n.endswith(".toml") for n in names)
    # the C install of `cmake --install` (headers, static libraries, CMake package) stays out
    assert not [n for n in names if n.endswith((".h", ".a", ".cmake", ".pc"))]
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

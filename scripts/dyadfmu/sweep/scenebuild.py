"""The mechanism FMU of a scene study, built by the project's own CMake build from the
project's sources: the checkout's, or in an installed package those it bundles
(dyadfmu/_project: the core, the FMU layer, the scene generator). Nothing is run from a
path outside the package or the checkout.

The build needs CMake, a C compiler and fmpy's FMI headers (fmpy/c-code); where one is
missing the study is refused with one line saying what to install, or to give the study
an .fmu built elsewhere."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from .. import paths

__all__ = ["BuildError", "generator", "build_folder", "tools_problem", "scene_fmu"]


class BuildError(RuntimeError):
    """A scene's FMU could not be built: the message says why (one line where a tool is
    missing)."""


def generator() -> Path:
    """The scene generator of the project's sources (modelDescription/scene.py)."""
    return paths.project_dir() / "modelDescription" / "scene.py"


def build_folder(out: Path) -> Path:
    """Where a study's scene FMUs are built: the checkout's build-scene/ (shared by every
    study, each FMU named by its scene's content), or, for an installed package, the
    study's output folder `out` (never a folder beside the install location)."""
    return paths.ROOT / "build-scene" if paths.in_checkout() else Path(out) / "build-scene"


def _fmi_headers() -> Path | None:
    try:
        import fmpy
    except ImportError:
        return None
    headers = Path(fmpy.__file__).parent / "c-code"
    return headers if (headers / "fmi3Functions.h").is_file() else None


def tools_problem() -> str | None:
    """What building a scene's FMU lacks here, as one line saying what to do; None where
    CMake, a C compiler, fmpy's FMI headers and the project's sources are all there."""
    missing = []
    if shutil.which("cmake") is None:
        missing.append("CMake (cmake)")
    compiler = (os.environ.get("CC", "").split() or ["cc"])[0]  # as CMake reads $CC
    if shutil.which(compiler) is None:
        missing.append(f"a C compiler ({compiler})")
    if _fmi_headers() is None:
        missing.append("fmpy's FMI headers (fmpy/c-code)")
    if not (paths.project_dir() / "CMakeLists.txt").is_file():
        missing.append(f"the project's sources ({paths.project_dir()}: reinstall dyadfmu)")
    if not missing:
        return None
    return (
        f"building the study's mechanism FMU from its scene needs {', '.join(missing)}, not "
        f"found here: install {'them' if len(missing) > 1 else 'it'} (Debian: apt-get install "
        "cmake gcc; pip install fmpy), or build the FMU elsewhere and name it in the study "
        '(fmu = "....fmu" instead of scene)'
    )


def _run(command: list[str], what: str) -> None:
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        tail = (done.stderr.strip() or done.stdout.strip())[-2000:]
        raise BuildError(f"{what} failed (exit status {done.returncode}):\n{tail}")


def scene_fmu(scene: Path, identifier: str, fmi: int, out: Path) -> Path:
    """<build folder>/fmus/<identifier>_fmi<fmi>.fmu of the scene file `scene`, built where
    it is not there yet (its identifier names the scene's content); BuildError otherwise."""
    build = build_folder(out)
    fmu = build / "fmus" / f"{identifier}_fmi{fmi}.fmu"
    if fmu.is_file():
        return fmu
    problem = tools_problem()
    if problem:
        raise BuildError(problem)
    if ";" in f"{build}{Path(scene).resolve()}":  # CMake's list separator
        raise BuildError(f"{build}: a folder whose path holds ';' cannot be built in by CMake")
    configure = [
        "cmake", "-S", str(paths.project_dir()), "-B", str(build),
        "-DCMAKE_BUILD_TYPE=Release", f"-DPython3_EXECUTABLE={sys.executable}",
        "-DDYADFMU_BUILD_TESTS=OFF", "-DDYADFMU_BUILD_BENCH=OFF", "-DDYADFMU_INSTALL=OFF",
        "-DDYADFMU_PYTHON_PACKAGE=OFF", "-DDYADFMU_WINDOWS=OFF",
        f"-DDYADFMU_SCENES={Path(scene).resolve()}",
    ]  # fmt: skip
    _run(configure, f"configuring the build of {identifier} ({build})")
    jobs = str(os.cpu_count() or 2)
    target = f"{identifier}_fmi{fmi}_package"
    _run(["cmake", "--build", str(build), "--target", target, "-j", jobs], f"building {target}")
    if not fmu.is_file():
        raise BuildError(f"building {target} made no {fmu}")
    return fmu

"""The mechanism FMU of a scene study, built by the project's own CMake build from the
project's sources: the checkout's, or in an installed package those it bundles
(dyadfmu/_project: the core, the FMU layer, the scene generator). Nothing is run from a
path outside the package or the checkout.

The build needs CMake, a C compiler and fmpy's FMI headers (fmpy/c-code); where one is
missing the study is refused with one line saying what to install, or to give the study
an .fmu built elsewhere."""

from __future__ import annotations

from pathlib import Path

from .. import paths
from ..build_scene import Refused, build_logged, configure, tools_problem

__all__ = [
    "BUILT_FROM",
    "BuildError",
    "build_folder",
    "generator",
    "scene_fmu",
    "stale",
    "tools_problem",
]


#: The project's folders an FMU is built from (beside its scene file).
BUILT_FROM = ("src", "fmu", "modelDescription/dyadgen")


def stale(fmu: Path, scene: Path, project: Path) -> bool:
    """Whether the FMU is missing or older than its scene file or any file of the
    project's sources it is built from (BUILT_FROM under `project`)."""
    if not fmu.is_file():
        return True
    built = fmu.stat().st_mtime
    if scene.stat().st_mtime > built:
        return True
    for folder in BUILT_FROM:
        for path in (project / folder).rglob("*"):
            if path.is_file() and "__pycache__" not in path.parts and path.stat().st_mtime > built:
                return True
    return False


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


def scene_fmu(scene: Path, identifier: str, fmi: int, out: Path) -> Path:
    """<build folder>/fmus/<identifier>_fmi<fmi>.fmu of the scene file `scene` (its
    identifier names the scene's content), built where it is stale (:func:`stale`: missing,
    or older than the scene or the project's sources); BuildError otherwise."""
    build = build_folder(out)
    fmu = build / "fmus" / f"{identifier}_fmi{fmi}.fmu"
    if not stale(fmu, Path(scene), paths.project_dir()):
        return fmu
    problem = tools_problem()
    if problem:
        raise BuildError(problem)
    target = f"{identifier}_fmi{fmi}_package"
    try:
        configure(build, [Path(scene).resolve()], windows=False, quiet=True)
        build_logged(build, [target], quiet=True)
    except Refused as refused:
        raise BuildError(str(refused)) from None
    if not fmu.is_file():
        raise BuildError(f"building {target} made no {fmu}")
    return fmu

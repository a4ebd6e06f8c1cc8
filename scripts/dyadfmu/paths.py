"""Where the project's files are: the checkout, its scenes, the build and the FMUs in it, or,
in an installed package (``pip install ./scripts``), the core and FMUs bundled with it."""

from __future__ import annotations

import os
from pathlib import Path

#: The checkout (the directory holding scripts/, scenes/, modelDescription/).
ROOT = Path(__file__).resolve().parents[2]
#: The scene files, scenes/*.toml.
SCENES_DIR = ROOT / "scenes"
#: The scene generator, modelDescription/scene.py.
GENERATOR = ROOT / "modelDescription" / "scene.py"

#: What the package's build (scikit-build-core, CMakeLists.txt DYADFMU_PYTHON_PACKAGE)
#: bundles: the shared core, dyadfmu/_lib/libdyadfmu.so, and the FMUs, dyadfmu/fmus/*.fmu.
PACKAGE_DIR = Path(__file__).resolve().parent
BUNDLED_LIB = PACKAGE_DIR / "_lib" / "libdyadfmu.so"
BUNDLED_FMUS = PACKAGE_DIR / "fmus"

#: The platform folder of the FMU binaries, by FMI version.
PLATFORM = {2: "linux64", 3: "x86_64-linux"}


def in_checkout() -> bool:
    """Whether this package runs from a checkout (scripts/dyadfmu), not an installed copy."""
    return (ROOT / "scripts" / "pyproject.toml").is_file() and (ROOT / "CMakeLists.txt").is_file()


def build_dir() -> Path:
    """The CMake build directory: $DYADFMU_BUILD, else build/ of the checkout."""
    return Path(os.environ.get("DYADFMU_BUILD", ROOT / "build"))


def built_fmu(
    identifier: str,
    version: int,
    build: Path | None = None,
    what: str = "the FMUs",
    how: str = "scripts/run-main",
) -> Path:
    """<build>/fmus/<identifier>_fmi<version>.fmu: of `build` or $DYADFMU_BUILD when given
    (that one only), else of the checkout's build/, else the one the installed package
    bundles (dyadfmu/fmus/). FileNotFoundError naming the places looked in when none has it.
    """
    name = f"{identifier}_fmi{version}.fmu"
    if build is not None or "DYADFMU_BUILD" in os.environ:
        places = [(build or build_dir()) / "fmus"]
    else:
        places = [BUNDLED_FMUS]
        if in_checkout():
            places.insert(0, build_dir() / "fmus")
    for place in places:
        if (place / name).is_file():
            return place / name
    looked = f"{places[0] / name} does not exist" + "".join(f", nor {p / name}" for p in places[1:])
    if in_checkout() or build is not None or "DYADFMU_BUILD" in os.environ:
        hint = f"build {what} first ({how} does, or cmake --build build)"
    else:
        hint = "the installed dyadfmu bundles no such FMU (dyadfmu.paths.bundled_fmus())"
    raise FileNotFoundError(f"{looked}: {hint}")


def bundled_fmus() -> list[Path]:
    """The FMUs the installed package bundles (dyadfmu/fmus/*.fmu; none in a checkout)."""
    return sorted(BUNDLED_FMUS.glob("*.fmu"))


def stage_binary(build: Path, identifier: str, version: int) -> Path:
    """The shared library of a built FMU, in the build's unpacked stage/ folder."""
    return (
        build
        / "fmus"
        / "stage"
        / f"{identifier}_fmi{version}"
        / "binaries"
        / PLATFORM[version]
        / f"{identifier}.so"
    )

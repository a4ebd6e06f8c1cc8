"""Where the project's files are: the checkout, its scenes, the build and the FMUs in it."""

from __future__ import annotations

import os
from pathlib import Path

#: The checkout (the directory holding scripts/, scenes/, modelDescription/).
ROOT = Path(__file__).resolve().parents[2]
#: The scene files, scenes/*.toml.
SCENES_DIR = ROOT / "scenes"
#: The scene generator, modelDescription/scene.py.
GENERATOR = ROOT / "modelDescription" / "scene.py"

#: The platform folder of the FMU binaries, by FMI version.
PLATFORM = {2: "linux64", 3: "x86_64-linux"}


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
    """build/fmus/<identifier>_fmi<version>.fmu (FileNotFoundError while it is not built)."""
    path = (build or build_dir()) / "fmus" / f"{identifier}_fmi{version}.fmu"
    if not path.is_file():
        raise FileNotFoundError(
            f"{path} does not exist: build {what} first ({how} does, or cmake --build build)"
        )
    return path


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

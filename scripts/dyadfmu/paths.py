"""Where the project's files are: the checkout, its scenes, the build and the FMUs in it, or,
in an installed package (``pip install ./scripts``), the core, the FMUs and the project's
sources bundled with it. An installed package never looks outside itself: the folders
around its install location (``<prefix>/lib/python3.X/...``) belong to whoever can write
there, so nothing is run or loaded from a path derived from it."""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

#: The checkout (the directory holding scripts/, modelDescription/) where this
#: package runs from one (in_checkout()); in an installed package, a folder outside it that
#: nothing reads.
ROOT = Path(__file__).resolve().parents[2]

#: What the package's build (scikit-build-core, CMakeLists.txt DYADFMU_PYTHON_PACKAGE)
#: bundles: the shared core, dyadfmu/_lib/libdyadfmu.so, the FMUs, dyadfmu/fmus/*.fmu, and
#: the sources a scene's FMU is built from, dyadfmu/_project (the CMake project's core,
#: FMU layer, scene generator and example scenes).
PACKAGE_DIR = Path(__file__).resolve().parent
BUNDLED_LIB = PACKAGE_DIR / "_lib" / "libdyadfmu.so"
BUNDLED_FMUS = PACKAGE_DIR / "fmus"
BUNDLED_PROJECT = PACKAGE_DIR / "_project"

#: The platform folder of the FMU binaries, by FMI version.
PLATFORM = {2: "linux64", 3: "x86_64-linux"}


def in_checkout() -> bool:
    """Whether this package runs from a checkout (scripts/dyadfmu), not an installed copy:
    decided by the package's own folder first (an installed copy sits in site-packages and
    bundles its core), so that files planted around an install location cannot make it
    one."""
    if PACKAGE_DIR.parent.name != "scripts" or BUNDLED_LIB.exists():
        return False
    return (ROOT / "scripts" / "pyproject.toml").is_file() and (ROOT / "CMakeLists.txt").is_file()


def project_dir() -> Path:
    """The project's sources (CMakeLists.txt, src/, fmu/, modelDescription/): the
    checkout's, else those the installed package bundles."""
    return ROOT if in_checkout() else BUNDLED_PROJECT


#: The scene files, modelDescription/scenes/*.toml.
SCENES_DIR = project_dir() / "modelDescription" / "scenes"
#: The build's test scenes, tests/scenes/*.toml (a checkout's; an installed package has none).
TEST_SCENES_DIR = project_dir() / "tests" / "scenes"
#: The scene generator, modelDescription/scene.py.
GENERATOR = project_dir() / "modelDescription" / "scene.py"


def build_dir() -> Path:
    """The CMake build directory: $DYADFMU_BUILD, else build/ of the checkout, else (an
    installed package, which has no build of its own) ./build, where the user ran it."""
    default = ROOT / "build" if in_checkout() else Path("build")
    return Path(os.environ.get("DYADFMU_BUILD", default))


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


# ---- path arguments: checked before any work, each problem one line -------------------------

#: The kinds of path argument: a folder written into (made where missing), an existing file
#: read, an existing folder read.
OUT, FILE, FOLDER = "folder to write", "file to read", "folder to read"


class PathProblem(ValueError):
    """A path that cannot be used: the message names the argument, the path and why."""


def _reason(error: OSError) -> str:
    return error.strerror or type(error).__name__


def _nearest(path: Path) -> Path:
    """`path` itself, else its nearest ancestor, that is there (a broken link counts)."""
    here = path
    while not os.path.lexists(here) and here.parent != here:
        here = here.parent
    return here


def _not_there(path: Path) -> str:
    """Why `path`, which is not there, cannot be reached: the ancestor in the way, if any."""
    there = _nearest(path.parent)
    if os.path.lexists(there) and not there.is_dir():
        return f"does not exist ({there} is not a folder)"
    return "does not exist"


def _writable(folder: Path) -> str | None:
    """None where an entry can be made in `folder` (tried: a folder made and removed, which
    also holds for root, whom permission bits do not stop, and for /proc), else why not."""
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".dyadfmu-probe-", dir=folder))
    except OSError as error:
        return _reason(error)
    return None


def folder_to_write_problem(path: Path) -> str | None:
    """Why `path` cannot be the folder a command writes into (made where missing), or None.
    Nothing is left behind."""
    try:
        there = _nearest(path)
        if os.path.islink(there) and not there.exists():
            return f"{there} is a broken symbolic link"
        if not there.is_dir():
            if there == path:
                return "is a file, not a folder"
            return f"cannot be created: {there} is a file, not a folder"
        why = _writable(there)
    except OSError as error:  # a name too long, a loop of links
        return f"cannot be used ({_reason(error)})"
    if why is None:
        return None
    return f"is not writable ({why})" if there == path else f"cannot be created in {there} ({why})"


def file_to_read_problem(path: Path) -> str | None:
    """Why `path` cannot be read as a file, or None."""
    try:
        if not path.exists():
            return _not_there(path)
        if path.is_dir():
            return "is a folder, not a file"
        if not path.is_file():
            return "is not a regular file"
        with open(path, "rb"):
            pass
    except OSError as error:
        return f"cannot be read ({_reason(error)})"
    return None


def folder_to_read_problem(path: Path) -> str | None:
    """Why `path` is not a folder that can be read, or None."""
    try:
        if not path.exists():
            return _not_there(path)
        if not path.is_dir():
            return "is a file, not a folder"
        with os.scandir(path):
            pass
    except OSError as error:
        return f"cannot be read ({_reason(error)})"
    return None


_CHECKS = {OUT: folder_to_write_problem, FILE: file_to_read_problem, FOLDER: folder_to_read_problem}


def path_problem(name: str, path: Path | str | None, kind: str) -> str | None:
    """'NAME PATH: problem' where the path argument `name` cannot be used as a `kind` (OUT,
    FILE or FOLDER), else None (also for an argument not given)."""
    if path is None:
        return None
    why = _CHECKS[kind](Path(path))
    return f"{name} {path}: {why}" if why else None


def check_path(name: str, path: Path | str | None, kind: str) -> None:
    """PathProblem (one line: the argument, the path, why) where path_problem finds one."""
    problem = path_problem(name, path, kind)
    if problem:
        raise PathProblem(problem)


def parse_checked(
    parser: argparse.ArgumentParser, argv: list[str] | None, arguments: tuple
) -> argparse.Namespace:
    """parser.parse_args(argv), then its path arguments checked: `arguments` holds
    (name as shown, attribute, kind) triples. A bad one ends the program with status 2 and
    one line, 'PROG: error: NAME PATH: problem'."""
    args = parser.parse_args(argv)
    refuse_bad_paths(parser, args, arguments)
    return args


def refuse_bad_paths(
    parser: argparse.ArgumentParser, args: argparse.Namespace, arguments: tuple
) -> None:
    """Exit with status 2 and one line at the first of `arguments` (see parse_checked) whose
    path cannot be used."""
    for name, attribute, kind in arguments:
        problem = path_problem(name, getattr(args, attribute), kind)
        if problem:
            parser.exit(2, f"{parser.prog}: error: {problem}\n")


def _main(argv: list[str]) -> int:
    """`python3 -P paths.py KIND NAME PATH` (KIND out, file or folder): prints the path's
    problem as path_problem words it and exits 1, or exits 0; for the shell scripts that
    check a path before the venv exists (scripts/run-fuzz)."""
    kinds = {"out": OUT, "file": FILE, "folder": FOLDER}
    if len(argv) != 3 or argv[0] not in kinds:
        print("usage: paths.py out|file|folder NAME PATH")
        return 2
    problem = path_problem(argv[1], argv[2], kinds[argv[0]])
    if problem:
        print(problem)
        return 1
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(_main(sys.argv[1:]))

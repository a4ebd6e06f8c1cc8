"""``dyadfmu build-scene``: the FMUs (FMI 2 and 3) of scene files, or their bundles for
firmware, built from the project's sources: the checkout's, or in an installed package
those it bundles (:func:`dyadfmu.paths.project_dir`). Each scene is checked first (a
malformed one is named with its file and line and nothing is built); the build prints a
line per FMU it packages and keeps its whole output in ``DIR/build.log``; each FMU is
validated with fmpy. Windows binaries come with the MinGW-w64 cross compiler, and the
command says when it is not there."""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from . import paths

#: The arguments naming a path, checked before any work (cli.py).
PATHS = (("--out", "out", paths.OUT), ("--bundle", "bundle", paths.OUT))
#: The cross compiler of the Windows binaries (CMake's DYADFMU_MINGW_CC default).
MINGW = "x86_64-w64-mingw32-gcc"
_PACKAGED = re.compile(r"^\[ *(\d+)%\] Packaging (\S+\.fmu)$")


class Refused(Exception):
    """What stops the command: the message and the exit status (1 a scene, 2 a usage)."""

    def __init__(self, message: str, status: int) -> None:
        super().__init__(message)
        self.status = status


def parser() -> argparse.ArgumentParser:
    """The options of `dyadfmu build-scene`."""
    command = argparse.ArgumentParser(
        prog="dyadfmu build-scene",
        description="Check scene files (a malformed one is named with its file, line and "
        "problem, and nothing is built), then build each one's FMUs, FMI 2 and 3, into "
        "DIR/fmus/<identifier>_fmi{2,3}.fmu, validate them with fmpy and give their variable "
        "counts. Needs CMake, a C compiler and fmpy. The scene format: the scenes' README "
        "(modelDescription/scenes/README.md).",
    )
    command.add_argument("scenes", nargs="+", type=Path, metavar="SCENE.toml")
    command.add_argument(
        "--out",
        type=Path,
        default=Path("build-scene"),
        metavar="DIR",
        help="the build folder (default build-scene in the current folder): the FMUs in "
        "DIR/fmus/, the build's output in DIR/build.log",
    )
    command.add_argument(
        "--windows",
        choices=("auto", "on", "off"),
        default="auto",
        help=f"Windows binaries in the FMUs too: auto (where {MINGW} is found, the default), "
        "on (refused without it), off",
    )
    command.add_argument(
        "--bundle",
        type=Path,
        metavar="DIR",
        help="build no FMU: write DIR/<identifier>/ for each scene, the C a firmware compiles "
        "to call <identifier>_evaluate (the scene's code, exactly the core's files it needs, "
        "an example, a CMakeLists.txt and a README.md with the example's size)",
    )
    command.add_argument(
        "--with-derivatives",
        action="store_true",
        help="with --bundle: also <identifier>_derivative and the core's tangents",
    )
    return command


def _fmi_headers() -> Path | None:
    try:
        import fmpy
    except ImportError:
        return None
    headers = Path(fmpy.__file__).parent / "c-code"
    return headers if (headers / "fmi3Functions.h").is_file() else None


def tools_problem(study: bool = True) -> str | None:
    """What building a scene's FMU lacks here, as one line saying what to do (for a study:
    or to give it an FMU built elsewhere); None where CMake, a C compiler, fmpy's FMI
    headers and the project's sources are all there."""
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
    what = "the study's mechanism FMU from its scene" if study else "a scene's FMUs"
    text = (
        f"building {what} needs {', '.join(missing)}, not found here: install "
        f"{'them' if len(missing) > 1 else 'it'} (Debian: apt-get install cmake gcc; pip "
        "install fmpy)"
    )
    if study:
        text += ", or build the FMU elsewhere and name it in the study"
        text += ' (fmu = "....fmu" instead of scene)'
    return text


def _generator(*arguments: object) -> subprocess.CompletedProcess:
    """The project's scene generator (modelDescription/scene.py of its sources)."""
    command = [sys.executable, str(paths.GENERATOR), *map(str, arguments)]
    return subprocess.run(command, capture_output=True, text=True)


def checked_identifiers(scenes: list[Path]) -> list[str]:
    """Each scene's identifier, all checked in one run of the generator; Refused with the
    generator's messages (status 1) or where two scenes share an identifier (status 2)."""
    done = _generator("--cmake-info", *scenes)
    if done.returncode != 0:
        raise Refused(done.stderr.rstrip(), 1)
    ids = [line.split(";")[0] for line in done.stdout.splitlines()]
    first: dict[str, Path] = {}
    for scene, identifier in zip(scenes, ids, strict=True):
        if identifier in first and first[identifier] != scene:
            raise Refused(
                f"{scene}: identifier '{identifier}' is also that of {first[identifier]}; "
                "give each scene its own",
                2,
            )
        first[identifier] = scene
    return ids


def _windows(choice: str) -> bool:
    """Whether to build Windows binaries, said in one line."""
    found = shutil.which(MINGW)
    if choice == "on" and not found:
        raise Refused(
            f"--windows on needs the MinGW-w64 cross compiler {MINGW}, not found "
            "(Debian: apt-get install gcc-mingw-w64-x86-64)",
            2,
        )
    wanted = choice == "on" or (choice == "auto" and found is not None)
    if wanted:
        print(f"== Windows binaries too ({found})", file=sys.stderr)
    elif choice == "auto":
        print(
            f"== Linux binaries only: {MINGW} not found (Debian: apt-get install "
            "gcc-mingw-w64-x86-64)",
            file=sys.stderr,
        )
    return wanted


def configure(out: Path, extra: list[Path], windows: bool, quiet: bool = False) -> None:
    """CMake's configuration of the project's sources in `out` with the scene files `extra`
    (beside the built-in ones), Windows binaries or not, no tests, benchmark or install."""
    if ";" in "".join(str(p) for p in [out, *extra]):  # CMake's list separator
        raise Refused(f"{out}: a path that holds ';' cannot be built in by CMake", 2)
    command = [
        "cmake", "-S", str(paths.project_dir()), "-B", str(out),
        "-DCMAKE_BUILD_TYPE=Release", f"-DPython3_EXECUTABLE={sys.executable}",
        "-DDYADFMU_BUILD_TESTS=OFF", "-DDYADFMU_BUILD_BENCH=OFF", "-DDYADFMU_INSTALL=OFF",
        "-DDYADFMU_PYTHON_PACKAGE=OFF", f"-DDYADFMU_WINDOWS={'ON' if windows else 'OFF'}",
        f"-DDYADFMU_SCENES={';'.join(str(p) for p in extra)}",
    ]  # fmt: skip
    if not quiet:
        print(f"== configuring {out}", file=sys.stderr)
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise Refused(f"configuring {out} failed:\n{done.stderr.strip()[-3000:]}", 1)


def build_logged(out: Path, targets: list[str], quiet: bool = False) -> None:
    """cmake --build of the targets: a line per FMU packaged (none if quiet), the whole
    output in out/build.log, its end in the message where the build fails."""
    log = out / "build.log"
    command = ["cmake", "--build", str(out), "-j", str(os.cpu_count() or 2)]
    for target in targets:
        command += ["--target", target]
    with open(log, "w", encoding="utf-8") as kept:
        process = subprocess.Popen(
            command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace"
        )
        for line in process.stdout:
            kept.write(line)
            found = _PACKAGED.match(line.rstrip())
            if found and not quiet:
                print(f"== [{found[1]}%] packaged {found[2]}", file=sys.stderr, flush=True)
        status = process.wait()
    if status != 0:
        tail = "".join(log.read_text(errors="replace").splitlines(True)[-40:])
        raise Refused(f"{tail}the build failed: its whole output is in {log}", 1)


def _validated(fmu: Path) -> str:
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(fmu))
    if problems:
        raise Refused(f"{fmu}: fmpy finds problems: {problems}", 1)
    md = read_model_description(str(fmu))
    count = {
        c: sum(v.causality == c for v in md.modelVariables)
        for c in ("input", "parameter", "output")
    }
    counted = ", ".join(f"{count[c]} {c}{'' if count[c] == 1 else 's'}" for c in count)
    return f"{fmu}: {counted}; valid"


def build(scenes: list[Path], out: Path, windows: str = "auto") -> list[Path]:
    """The scenes' FMUs in out/fmus/, built and validated (the lines printed); Refused."""
    problem = tools_problem(study=False)
    if problem:
        raise Refused(problem, 2)
    ids = checked_identifiers(scenes)
    # a built-in scene is in every build already: given again it is built, not added
    builtin = {p.resolve() for p in paths.SCENES_DIR.glob("*.toml")}
    extra = list(dict.fromkeys(s for s in scenes if s not in builtin))
    wanted = _windows(windows)
    out.mkdir(parents=True, exist_ok=True)
    configure(out, extra, wanted)
    print(f"== building {' '.join(ids)}", file=sys.stderr)
    build_logged(out, [f"{i}_fmi{v}_package" for i in ids for v in (2, 3)])
    fmus = [out / "fmus" / f"{i}_fmi{v}.fmu" for i in ids for v in (2, 3)]
    for fmu in fmus:
        print(_validated(fmu))
    return fmus


def _bundles(scenes: list[Path], folder: Path, derivatives: bool) -> None:
    checked_identifiers(scenes)
    for scene in scenes:
        extra = ["--with-derivatives"] if derivatives else []
        done = _generator(scene, "--bundle", folder, *extra, "--measure")
        sys.stdout.write(done.stdout)
        if done.returncode != 0:
            raise Refused(done.stderr.rstrip(), done.returncode)


def main(argv: list[str] | None = None) -> int:
    """Run the command: 0, or 1 (a scene or the build) or 2 (usage) with its reason."""
    args = paths.parse_checked(parser(), argv, PATHS)
    scenes = [s.resolve() for s in args.scenes]
    try:
        for given, scene in zip(args.scenes, scenes, strict=True):
            if not scene.is_file():
                raise Refused(f"no such file: {given}", 2)
        if args.with_derivatives and args.bundle is None:
            raise Refused("--with-derivatives is an option of --bundle, which is not given", 2)
        if args.bundle is not None:
            _bundles(scenes, args.bundle, args.with_derivatives)
        else:
            build(scenes, args.out.resolve(), args.windows)
    except Refused as refused:
        text = str(refused)  # the generator's own lines say what they are about
        print(
            text if text.startswith("error:") else f"dyadfmu build-scene: {text}", file=sys.stderr
        )
        return refused.status
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""scene.py: check a scene, generate the files of its FMU, or write its bundle for
firmware."""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from dyadgen.bundle import BundleError, block_members, write_bundle
from dyadgen.emit.batch_c import scheduled_lanes
from dyadgen.model import Scene
from dyadgen.pipeline import build_table, load_scene, outputs_of, write_files
from dyadgen.scenefile.problems import SceneError
from dyadgen.scenefile.read import inputs_with_external_kinematics
from dyadgen.table import Table


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        description="Generate a tailored FMU's model descriptions, C model and documentation "
        "from a scene (see modelDescription/scenes/README.md)."
    )
    parser.add_argument(
        "scene", type=Path, nargs="+", help="the scene file (TOML); with --cmake-info, any number"
    )
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--out", type=Path, help="directory to write the generated files to")
    what.add_argument(
        "--check",
        action="store_true",
        help="validate the scene and print its variable counts; write nothing",
    )
    what.add_argument(
        "--external-inputs",
        action="store_true",
        help="print the inputs the scene's FMU would take with kinematics = 'external', "
        "one per line",
    )
    what.add_argument(
        "--cmake-info",
        action="store_true",
        help="print 'identifier;realisation;lanes;type;...' for CMake (lanes: 'scheduled' "
        "where the build schedules its C for register pressure, a generic dyad's or a "
        "batch's of at most two dyads and cylinders, else 'plain'; its dyad types, lower "
        "case), a line per scene file, in their order (one Python run for every scene of a "
        "build)",
    )
    what.add_argument(
        "--blocks",
        action="store_true",
        help="print, as JSON, the members of the input and output blocks of its bundle's "
        "C (each with its variable's name, unit and start; an angle input is kept as its "
        "unit vector): what a program that fills and reads them needs",
    )
    what.add_argument(
        "--bundle",
        type=Path,
        metavar="DIR",
        help="write DIR/<identifier>/: the C files and headers a firmware needs to call "
        "<identifier>_evaluate (the scene's code and the core's), a CMakeLists.txt, an "
        "example and a README.md; an earlier bundle there is replaced",
    )
    parser.add_argument(
        "--with-derivatives",
        action="store_true",
        help="with --bundle: also <identifier>_derivative (the exact directional "
        "derivative) and the core's tangents, which an evaluate-only bundle leaves out",
    )
    parser.add_argument(
        "--measure",
        action="store_true",
        help="with --bundle: build the example with cc at -O2, in double and in float, "
        "and give its size (size(1)'s text, bytes) in the README",
    )
    return parser


def _scene_problem(scene: Path) -> str | None:
    """Why the scene file cannot be read, or None."""
    if scene.is_dir():
        return "is a folder, not a file"
    if not scene.exists():
        return "does not exist"
    return None


def _out_problem(out: Path) -> str | None:
    """Why `out` cannot be the folder the files go to (made where missing), or None: a
    folder is made and removed in it, or in its nearest existing ancestor, which also
    holds for root (whom permissions do not stop) and for /proc."""
    there = out
    while not os.path.lexists(there) and there.parent != there:
        there = there.parent
    try:
        if not there.is_dir():
            if there == out:
                return "is a file, not a folder"
            return f"cannot be created: {there} is not a folder"
        os.rmdir(tempfile.mkdtemp(prefix=".scene-probe-", dir=there))
    except OSError as error:
        where = "is not writable" if there == out else f"cannot be created in {there}"
        return f"{where} ({error.strerror or error})"
    return None


def _path_problem(args: argparse.Namespace) -> str | None:
    """'NAME PATH: problem' for a scene file or the --out folder, or None."""
    if len(args.scene) > 1 and not args.cmake_info:
        return "one scene file at a time (several only with --cmake-info)"
    for scene in args.scene:
        problem = _scene_problem(scene)
        if problem:
            return f"{scene}: {problem}"
    for option, folder in (("--out", args.out), ("--bundle", args.bundle)):
        problem = _out_problem(folder) if folder is not None else None
        if problem:
            return f"{option} {folder}: {problem}"
    if args.bundle is None and (args.with_derivatives or args.measure):
        given = "--with-derivatives" if args.with_derivatives else "--measure"
        return f"{given} is an option of --bundle, which is not given"
    return None


def main(argv: list[str] | None = None) -> int:
    """scene.py SCENE --out DIR | --check | --external-inputs | --cmake-info | --blocks |
    --bundle DIR [--with-derivatives] [--measure]."""
    parser = _parser()
    args = parser.parse_args(argv)
    problem = _path_problem(args)
    if problem:  # one line, before the scene is read
        parser.exit(2, f"{parser.prog}: error: {problem}\n")
    if args.cmake_info:
        return _cmake_info(args.scene)
    (args.scene,) = args.scene
    loaded = _loaded(args.scene)
    if loaded is None:
        return 1
    scene, table = loaded
    kind = table.kind
    if args.external_inputs:
        print("\n".join(inputs_with_external_kinematics(scene)))
        return 0
    if args.blocks:
        print(json.dumps(block_members(table), indent=1))
        return 0
    if args.bundle is not None:
        return _bundle(args, scene, table, parser.prog)
    if args.check:
        n = table.counts()
        counts = ", ".join(_counted(n[c], c) for c in ("input", "parameter", "output"))
        print(f"{scene.identifier} ({kind.label}): {counts}")
        return 0
    try:
        write_files(args.out, outputs_of(table))
    except OSError as error:  # the folder went bad after the check (a full disk, say)
        print(f"{parser.prog}: error: {error.filename}: {error.strerror or error}", file=sys.stderr)
        return 2
    return 0


def _loaded(path: Path) -> tuple[Scene, Table] | None:
    """The scene and its table, or None after printing every problem."""
    try:
        scene = load_scene(path)
        return scene, build_table(scene)
    except SceneError as exc:
        for problem in exc.args[0]:
            print(f"error: {problem}", file=sys.stderr)
        print(f"{path}: rejected, nothing written", file=sys.stderr)
        return None


def _cmake_info(paths: list[Path]) -> int:
    """--cmake-info: a line per scene, or 1 at the first malformed one."""
    for path in paths:
        loaded = _loaded(path)
        if loaded is None:
            return 1
        scene, table = loaded
        types = sorted({d.type.lower() for d in scene.dyads})
        if any(d.is_cylinder() for d in scene.drivers):
            types.append("cylinder")  # its closed forms link as a type's do
        generic = table.kind.realisation == "generic"  # its variable table holds lanes
        lanes = "scheduled" if generic or scheduled_lanes(scene) else "plain"
        print(";".join([scene.identifier, table.kind.realisation, lanes] + types))
    return 0


def _counted(count: int, noun: str) -> str:
    """'1 parameter', '4 parameters'."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def _bundle(args: argparse.Namespace, scene: Scene, table: Table, prog: str) -> int:
    """Write the scene's bundle (--bundle); 1 for a scene that has no code of its own to
    bundle, 2 where the folder or the measurement fails."""
    if table.kind.realisation == "generic":
        dyad = scene.dyads[0].type
        print(
            f"error: {args.scene}: the scene {table.identifier} is one whole {dyad} dyad "
            f"(realisation generic): its FMU runs the core's dyad_solve_{dyad.lower()} and "
            "there is no generated code to bundle; call that function of the installed core",
            file=sys.stderr,
        )
        return 1
    try:
        folder = write_bundle(table, args.bundle, args.with_derivatives, args.measure)
    except BundleError as error:
        print(f"{prog}: error: {error.args[0]}", file=sys.stderr)
        return 2
    except OSError as error:
        print(f"{prog}: error: {error.filename}: {error.strerror or error}", file=sys.stderr)
        return 2
    print(folder)
    return 0

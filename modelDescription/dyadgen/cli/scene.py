"""scene.py: check a scene, or generate the files of its FMU."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dyadgen.pipeline import build_table, load_scene, outputs_of, write_files
from dyadgen.scenefile.problems import SceneError
from dyadgen.scenefile.read import inputs_with_external_kinematics


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        description="Generate a tailored FMU's model descriptions, C model and documentation "
        "from a scene (see scenes/README.md)."
    )
    parser.add_argument("scene", type=Path, help="the scene file (TOML)")
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
        help="print 'identifier;type;...' (its dyad types, lower case) for CMake",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """scene.py SCENE --out DIR | --check | --external-inputs | --cmake-info."""
    args = _parser().parse_args(argv)
    try:
        scene = load_scene(args.scene)
        table = build_table(scene)
    except SceneError as exc:
        for problem in exc.args[0]:
            print(f"error: {problem}", file=sys.stderr)
        print(f"{args.scene}: rejected, nothing written", file=sys.stderr)
        return 1
    kind = table.kind
    if args.cmake_info:
        types = sorted({d.type.lower() for d in scene.dyads})
        print(";".join([scene.identifier, kind.realisation] + types))
        return 0
    if args.external_inputs:
        print("\n".join(inputs_with_external_kinematics(scene)))
        return 0
    if args.check:
        n = table.counts()
        counts = ", ".join(_counted(n[c], c) for c in ("input", "parameter", "output"))
        print(f"{scene.identifier} ({kind.label}): {counts}")
        return 0
    write_files(args.out, outputs_of(table))
    return 0


def _counted(count: int, noun: str) -> str:
    """'1 parameter', '4 parameters'."""
    return f"{count} {noun}{'' if count == 1 else 's'}"

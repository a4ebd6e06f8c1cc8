"""``dyadfmu animate``: a mechanism in motion, written as a self-contained HTML page with
a time slider, an animated GIF and the CSV of what is drawn (see :mod:`dyadfmu.animation`).

What moves it (SOURCE):

- a shipped mechanism FMU's name (``shaper``, ``slider_crank``, ...): the harness's motion
  of its driver (``--motion``, ``--revolutions``);
- a scene file ``FILE.toml``: its FMU (built where missing or stale, as ``dyadfmu scene``
  does) moved by a motion law: ``--range INPUT MIN MAX`` for each driver moved (default:
  the first crank one turn) in ``--duration`` s at constant rates;
- a recorded run ``FILE.csv`` of the FMU of ``--scene`` (a file or a shipped name) in
  any simulator: a time column, the pair positions and the drivers' coordinates."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .. import argtypes, paths
from ..report import drivers_drawing as dd
from ..report import own_scene
from . import movie, page, sources
from .frames import DrawingError, Frames, Run, frames

#: The arguments naming a path, checked before any work (cli.py).
PATHS = (("--out", "out", paths.OUT),)
#: The most instants of a run (the page holds every one).
MOST_INSTANTS = 5_000


def _motion_options(p: argparse.ArgumentParser) -> None:
    """The options of the motion: a scene file's law, a shipped mechanism's harness run."""
    p.add_argument(
        "--range",
        nargs=3,
        action="append",
        default=[],
        metavar=("INPUT", "MIN", "MAX"),
        help="a scene file's motion: a driver's coordinate (rad or m) from MIN to MAX; "
        "repeatable (default: the first crank one turn)",
    )
    p.add_argument(
        "--duration",
        type=argtypes.real(0.0, 1e6, above=True),
        default=1.0,
        help="a scene file's motion takes this long, s (default 1: 60 rpm for a turn)",
    )
    p.add_argument(
        "--instants",
        type=argtypes.whole(2, MOST_INSTANTS),
        default=121,
        help="instants of a scene file's or a shipped mechanism's run (default 121)",
    )
    p.add_argument(
        "--motion",
        choices=("constant", "varying"),
        default="constant",
        help="a shipped mechanism's crank speed (default constant)",
    )
    p.add_argument(
        "--revolutions",
        type=argtypes.real(0.0, 100.0, above=True),
        default=1.0,
        help="a shipped mechanism's run, in driver cycles (default 1)",
    )


def parser() -> argparse.ArgumentParser:
    """The options of `dyadfmu animate`."""
    p = argparse.ArgumentParser(
        prog="dyadfmu animate",
        description="Animate a mechanism from its mechanism FMU's outputs: the links, pairs "
        "and force vectors frame by frame with the curves of chosen outputs beside them. "
        "Writes DIR/<id>_animation.html (self-contained, a time slider; opens in any "
        "browser), DIR/<id>_animation.gif and DIR/<id>_animation.csv (the values drawn).",
    )
    p.add_argument(
        "source",
        metavar="SOURCE",
        help="a shipped mechanism FMU's name (the harness's motion), a scene file .toml (a "
        "motion law), or a recorded run .csv of --scene's FMU",
    )
    p.add_argument(
        "--scene",
        metavar="SCENE",
        help="the scene of a recorded run: a .toml file or a shipped name",
    )
    p.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default 2)")
    _motion_options(p)
    p.add_argument(
        "--curve",
        action="append",
        metavar="NAME",
        help="an output, or a pair reaction (its magnitude), drawn beside the mechanism; "
        "repeatable (default: the drivers' efforts and every pair reaction)",
    )
    p.add_argument("--no-gif", action="store_true", help="write the page and the CSV only")
    p.add_argument(
        "--out",
        type=Path,
        default=Path("out/animation"),
        help="folder of the files (default out/animation)",
    )
    return p


def _shipped(name: str) -> bool:
    from ..cosim.mechanism_fmus import MECHANISM_FMUS

    return name in MECHANISM_FMUS


def _scene_and_fmu(scene: str, fmi: int, out: Path, say: Callable) -> tuple:
    """A scene given by file (its FMU built where stale) or by a shipped name."""
    if _shipped(scene):
        from ..cosim.mechanism_fmus import scene_file

        return scene_file(scene), paths.built_fmu(scene, fmi, None, how="scripts/run-tests")
    path = Path(scene)
    if path.suffix != ".toml" or not path.is_file():
        raise DrawingError(f"--scene {scene}: neither a scene file (.toml) nor a shipped mechanism")
    identifier = dd.read_scene(path).identifier
    return path.resolve(), own_scene.scene_fmu(path.resolve(), identifier, fmi, out, say)


def _run(args: argparse.Namespace, say: Callable) -> tuple[Path, Path, Callable]:
    """The scene, the FMU and the function giving the run from the opened mechanism."""
    source = args.source
    if _shipped(source):
        scene, fmu, columns = sources.harness(
            source, args.fmi, args.motion, args.revolutions, args.instants
        )
        where = f"the harness's {args.motion} motion of {source}"
        return scene, fmu, lambda m: sources.recorded(m, columns, where)
    if source.endswith(".csv"):
        if not args.scene:
            raise DrawingError(f"{source}: a recorded run needs --scene, the scene it is a run of")
        columns = sources.read_csv(Path(source))
        scene, fmu = _scene_and_fmu(args.scene, args.fmi, args.out, say)
        return scene, fmu, lambda m: sources.recorded(m, columns, Path(source).name)
    if source.endswith(".toml"):
        if not args.range and Path(source).is_file():
            sources.one_turn(dd.read_scene(source))  # refused before any build
        scene, fmu = _scene_and_fmu(source, args.fmi, args.out, say)

        def law(m: dd.Mechanism) -> Run:
            ranges = dd.ranges_given(m, args.range) or sources.one_turn(m.scene, m)
            return sources.motion_law(m, ranges, args.duration, args.instants)

        return scene, fmu, law
    raise DrawingError(
        f"{source}: not a shipped mechanism (see 'dyadfmu animate --help'), a scene file "
        ".toml or a recorded run .csv"
    )


def write_csv(found: Frames, path: Path) -> Path:
    """The values drawn: time, the drivers' coordinates, the pair positions and the
    curves at each instant (NaN where there is no answer), every name the FMU's."""
    run = found.run
    names = [*found.coordinates, *found.positions]
    columns = [run.times] + [
        np.array([np.nan if r is None else r[n] for r in run.rows]) for n in names
    ]
    columns += [c.values for c in found.curves]
    header = ",".join(f'"{n}"' for n in ["time", *names, *(c.name for c in found.curves)])
    np.savetxt(path, np.column_stack(columns), "%.17g", ",", header=header, comments="")
    return path


def animate(args: argparse.Namespace, say: Callable[[str], None]) -> list[Path]:
    """Build where needed, run, draw; the files written."""
    scene, fmu, run_of = _run(args, say)
    mechanism = dd.Mechanism(dd.read_scene(scene), fmu, {})
    try:
        run = run_of(mechanism)
        found = frames(mechanism, run, args.curve)
        args.out.mkdir(parents=True, exist_ok=True)
        stem = args.out / f"{found.identifier}_animation"
        written = [page.write(found, stem.with_suffix(".html"))]
        written.append(write_csv(found, stem.with_suffix(".csv")))
        if not args.no_gif:
            written.append(movie.write(mechanism, found, stem.with_suffix(".gif"), say))
    finally:
        mechanism.close()
    missing = sum(1 for r in run.reasons if r)
    if missing:
        say(
            f"no answer at {missing} of {len(run.reasons)} instants (marked); the first: "
            f"{next(r for r in run.reasons if r)}"
        )
    return written


def main(argv: list[str] | None = None) -> int:
    """Run the command; 0, or 1 with one line saying what is refused."""
    args = paths.parse_checked(parser(), argv, PATHS)

    def say(text: str) -> None:
        print(text, file=sys.stderr, flush=True)

    try:
        written = animate(args, say)
    except DrawingError as e:
        print(f"dyadfmu animate: error: {e}", file=sys.stderr)
        return 1
    for path in written:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Command line of the dyadfmu harness: co-simulate a mechanism's dyad FMU with
fmpy, compare every output with the NumPy reference, write tables and plots."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from . import paths
from .argtypes import real, whole
from .cosim import SCENE_NAMES

if TYPE_CHECKING:  # imported where a command runs: a sweep needs none of them
    from .cosim import harness, scenes

DEFAULT_MECHANISM = "slider-crank"


#: Bounds of a co-simulation's length: revolutions, steps per revolution, steps in all.
MAX_REVOLUTIONS = 1000.0
MAX_STEPS_PER_REVOLUTION = 100_000
MIN_STEPS, MAX_STEPS = 4, 1_000_000


def _cosimulation_options(command: argparse.ArgumentParser, out: Path, revolutions_help: str):
    """The options of a command that co-simulates FMUs over the crank's motion."""
    command.add_argument(
        "--fmi",
        choices=("2", "3", "both"),
        default="both",
        help="FMI version of the FMU to run (default both)",
    )
    command.add_argument(
        "--revolutions",
        type=real(0.0, MAX_REVOLUTIONS, above=True),
        default=2.0,
        help=revolutions_help,
    )
    command.add_argument(
        "--steps",
        type=whole(MIN_STEPS, MAX_STEPS_PER_REVOLUTION),
        default=360,
        help=f"communication steps per revolution (default 360; {MIN_STEPS} to "
        f"{MAX_STEPS_PER_REVOLUTION}, {MIN_STEPS} to {MAX_STEPS} in all)",
    )
    command.add_argument(
        "--motion",
        choices=("constant", "varying"),
        default="constant",
        help="crank speed: constant, or varying along the cycle (default constant)",
    )
    command.add_argument(
        "--out", type=Path, default=out, help=f"directory for tables and plots (default ./{out})"
    )
    command.add_argument(
        "--build",
        type=Path,
        default=None,
        help="CMake build directory holding fmus/ (default: build/ of the checkout)",
    )
    command.add_argument("--no-plots", action="store_true", help="write tables only")


def _run_command(sub: argparse._SubParsersAction) -> None:
    run = sub.add_parser(
        "run",
        help="co-simulate mechanisms and compare them with the reference",
        description="Co-simulate each mechanism's dyad FMU over the crank's "
        "motion, print the error of every output against the "
        "reference, write tables (Markdown, CSV) and plots (PNG).",
    )
    run.add_argument(
        "mechanisms",
        nargs="*",
        metavar="MECHANISM",
        default=[DEFAULT_MECHANISM],
        help=f"mechanism names (default {DEFAULT_MECHANISM}; 'all' for every "
        f"mechanism; see 'dyadfmu list')",
    )
    _cosimulation_options(
        run, Path("out"), "crank revolutions (oscillations for trt-slot) to simulate (default 2)"
    )
    run.add_argument(
        "--angle",
        type=real(-36000.0, 36000.0),
        default=60.0,
        help="crank angle in degrees at which the mechanism is drawn (default 60)",
    )
    run.set_defaults(run=_run)


def _study_command(sub: argparse._SubParsersAction) -> None:
    study = sub.add_parser(
        "study",
        help="accuracy and speed of every method; writes the report",
        description="Time the C core (double, float), GSL LU and SVD 6x6 solves, NumPy's "
        "batched solve and the FMUs (from C and fmpy) on the same inputs; measure "
        "their errors against mpmath ground truth on random, near-singular, "
        "extreme and cancelling configurations; write report.md, CSVs and plots.",
    )
    study.add_argument(
        "--quick",
        action="store_true",
        help="small input sets (for CI: about 35 s of CPU time; the full study about 1.5 minutes)",
    )
    study.add_argument(
        "--out",
        type=Path,
        default=Path("out/study"),
        help="directory for the report (default ./out/study)",
    )
    _build_argument(study)
    study.set_defaults(run=_study)


def _build_argument(command: argparse.ArgumentParser) -> None:
    command.add_argument(
        "--build",
        type=Path,
        default=None,
        help="CMake build directory with the benchmark and FMUs (default build/)",
    )


def _speed_command(sub: argparse._SubParsersAction) -> None:
    speed = sub.add_parser(
        "speed",
        help="each way of calling the core against its floor (the study's speed section)",
        description="Count under callgrind the closed forms' flops against the solve's, the "
        "instructions per solve, per FMU step from C (FMI 2 and 3) against the model's "
        "evaluation, per row of dyad_solve_batch, and time dyadfmu.solve per row; for "
        "every dyad type and built-in scene. Prints the tables (Markdown); needs valgrind "
        "and a build with the benchmark (scripts/run-study makes one).",
    )
    speed.add_argument("--quick", action="store_true", help="fewer steps and rows (CI)")
    _build_argument(speed)
    speed.set_defaults(run=_speed)


def _sweep_command(sub: argparse._SubParsersAction) -> None:
    sweep = sub.add_parser(
        "sweep",
        help="a design study over many runs on Dask (a study file: "
        "modelDescription/scenes/studies/README.md)",
        description="Read a study file, draw its designs (grid, random or Latin hypercube), "
        "run each on the mechanism FMU (and the drive FMU for a driven study) on a local Dask "
        "cluster or an existing one, and write the table (results.csv), the best designs "
        "(report.md) and a plot (designs.png) to OUT/<study>/. A run turns a crank through a "
        "revolution, moves a ram or a cylinder over its stroke or its link's angle, or, with "
        "[[run.driver]] tables, moves every driver of a mechanism with several at once, each "
        "over its own range. A failed run is a row with its status.",
    )
    sweep.add_argument("study", type=Path, metavar="STUDY.toml", help="the study file")
    sweep.add_argument(
        "--workers",
        type=whole(0, 256),
        default=None,
        help="local Dask worker processes (0 runs in this process, without Dask; default: "
        "none for a crank, ram or cylinder run of at most 200,000 samples, designs x points, "
        "which takes less than a cluster takes to start, else 2)",
    )
    sweep.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
        help="the address of an existing Dask scheduler (tcp://host:8786) to run on instead "
        "of a local cluster; its workers must see the FMU files at the same paths",
    )
    sweep.add_argument(
        "--out", type=Path, default=Path("out/sweep"), help="output folder (default out/sweep)"
    )
    sweep.add_argument("--no-plots", action="store_true", help="write the table and report only")
    _build_argument(sweep)
    sweep.set_defaults(run=_sweep)


def _scene_command(sub: argparse._SubParsersAction) -> None:
    scene = sub.add_parser(
        "scene",
        help="co-simulate tailored scene FMUs (modelDescription/scenes/*.toml) against their "
        "reference",
        description="Co-simulate each scene's tailored FMU over the crank's motion, print the "
        "error of every output against the independent reference, and write "
        "tables (Markdown, CSV) and, for the multi-dyad chains, a drawing with "
        "every reaction. Scenes: " + ", ".join(scenes_names()) + ".",
    )
    scene.add_argument(
        "scenes",
        nargs="*",
        metavar="SCENE",
        default=["shaper"],
        help="scene names (default shaper; 'all' for every example scene), or scene files "
        "(FILE.toml: built where needed, drawn and reported over one turn of the first "
        "crank)",
    )
    _cosimulation_options(scene, Path("out/scenes"), "crank revolutions to simulate (default 2)")
    scene.set_defaults(run=_scene)


def _own_commands(sub: argparse._SubParsersAction) -> None:
    """The commands that parse their own options (listed here for --help)."""
    sub.add_parser(
        "scenes",
        add_help=False,
        help="every example scene against its reference, and the tailored FMUs against the "
        "generic per-type FMUs: variables, binary size, callgrind instructions per doStep "
        "(see 'dyadfmu scenes --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "cosim",
        add_help=False,
        help="the dyad FMU in a closed loop with the drive FMU: explicit and stabilised "
        "coupling against a monolithic reference (see 'dyadfmu cosim --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "plants",
        add_help=False,
        help="what the forward FMUs' integration costs: steps, evaluations and callgrind "
        "instructions per ms of motion, a slow and a stiff motor (see 'dyadfmu plants --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "build-scene",
        add_help=False,
        help="check scene files and build their FMUs (FMI 2 and 3) into a folder of your "
        "choice, or their bundles for firmware (see 'dyadfmu build-scene --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "rows",
        add_help=False,
        help="run an FMU over a CSV table of inputs, each row with the inputs and outputs of "
        "one instant (see 'dyadfmu rows --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "animate",
        add_help=False,
        help="a mechanism in motion with its forces and curves: an HTML page with a time "
        "slider and a GIF, from a shipped mechanism, a scene file or a recorded run (see "
        "'dyadfmu animate --help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "embedded",
        add_help=False,
        help="scenes as Cortex-M4F firmware under QEMU, in float: instructions and cycles per "
        "tick, flash, RAM, stack, outputs against this machine's (see 'dyadfmu embedded "
        "--help')",
    ).set_defaults(run=None)
    sub.add_parser(
        "scene-bench",
        add_help=False,
        help="time the scene generator (--check and --out) on chains of 25 to 200 dyads "
        "(see 'dyadfmu scene-bench --help')",
    ).set_defaults(run=None)


def parser() -> argparse.ArgumentParser:
    """The parser of the dyadfmu command and its subcommands."""
    top = argparse.ArgumentParser(
        prog="dyadfmu",
        description="Joint reactions of planar linkages: build a scene's FMUs (build-scene), "
        "evaluate them over tables (rows), draw and sweep designs (animate, sweep), and check "
        "them: co-simulations against an independent Newton-Euler solve in NumPy (run, "
        "scene, scenes, study, cosim, plants), speed and firmware figures (speed, embedded). "
        "Each subcommand's --help says what it writes where.",
    )
    sub = top.add_subparsers(dest="command", required=True)
    listing = sub.add_parser(
        "list",
        help="list the mechanisms and their dyads",
        description="List the built-in mechanisms: name, dyad type and description.",
    )
    listing.set_defaults(run=_list)
    _run_command(sub)
    _study_command(sub)
    _speed_command(sub)
    _sweep_command(sub)
    _scene_command(sub)
    _own_commands(sub)
    return top


def _log(text: str) -> None:
    print(text, file=sys.stderr)


def _study(args: argparse.Namespace) -> int:
    from .report import study as study_report
    from .study import accuracy

    try:
        results = accuracy.run(args.out, quick=args.quick, build=args.build, log=_log)
    except FileNotFoundError as error:
        print(f"dyadfmu: {error}", file=sys.stderr)
        return 2
    report = study_report.write(args.out, results)
    _log(f"report written to {report} ({results.elapsed:.0f} s)")
    print(report.read_text())
    print(f"report: {report}")
    return 0


def _speed(args: argparse.Namespace) -> int:
    import tempfile

    from . import paths
    from .report import speed as speed_report
    from .study import speed

    try:
        with tempfile.TemporaryDirectory() as work:
            figures = speed.measure(args.build or paths.build_dir(), Path(work), args.quick, _log)
    except (FileNotFoundError, RuntimeError) as error:
        print(f"dyadfmu: {error}", file=sys.stderr)
        return 2
    print("\n".join(speed_report.markdown(*figures)))
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from .sweep import study
    from .sweep.sources import SourceError
    from .sweep.studyfile import StudyError

    try:
        result = study.run_study(
            args.study, args.out, args.workers, args.scheduler, args.build, not args.no_plots
        )
    except (StudyError, SourceError, FileNotFoundError, ValueError) as error:
        print(f"dyadfmu sweep: {error}", file=sys.stderr)
        return 2
    except OSError as error:  # --out not a folder, a scheduler not reachable
        print(f"dyadfmu sweep: {error}", file=sys.stderr)
        return 2
    print(result.files[1].read_text(encoding="utf-8"))
    for path in result.files:
        print(f"wrote {path}")
    return 0


def _list(args: argparse.Namespace) -> int:
    from .mechanisms import builtin

    for name in builtin.NAMES:
        mech = builtin.load(name)
        print(f"{name:14s} {mech.dyad}  {mech.description}")
    return 0


def _chosen(asked: list[str], names: tuple, what: str) -> list[str] | None:
    """The names asked for ('all': every one), or None after reporting unknown ones."""
    chosen = list(names) if asked == ["all"] else asked
    unknown = [n for n in chosen if n not in names]
    if unknown:
        print(
            f"dyadfmu: unknown {what} {', '.join(unknown)}; the {what}s are: {', '.join(names)}",
            file=sys.stderr,
        )
        return None
    return chosen


def _versions(args: argparse.Namespace) -> tuple[int, ...]:
    return (2, 3) if args.fmi == "both" else (int(args.fmi),)


def _print_written(worst: float, written: list[Path]) -> None:
    print(f"worst relative error of any output: {worst:.2e}")
    print("written:")
    for path in written:
        print(f"  {path}")


def _mechanism_outputs(args: argparse.Namespace, result: harness.MechanismResult) -> list[Path]:
    """Print one mechanism run's table; write its tables and plots."""
    from .cosim import harness
    from .report import tables

    rows = tables.error_rows(result.errors)
    print(harness.summary(result))
    print(tables.format_text(rows))
    print()
    args.out.mkdir(parents=True, exist_ok=True)
    stem = args.out / f"{result.mechanism.name}_fmi{result.fmi_version}"
    written = tables.write_error_tables(stem, harness.summary(result), rows)
    if not args.no_plots:
        from .report import plots  # matplotlib only when plotting

        written.append(plots.plot_reactions(result, Path(f"{stem}_reactions.png")))
        written.append(plots.plot_mechanism(result, args.angle, Path(f"{stem}_mechanism.png")))
    return written


def _run_each(args: argparse.Namespace, names: list[str], run: Callable, outputs: Callable) -> int:
    """Run each of `names` in each FMI version with `run`, write its outputs with
    `outputs`, then print the worst error and the files written."""
    written, worst = [], 0.0
    for name in names:
        for version in _versions(args):
            try:
                result = run(
                    name,
                    version,
                    args.revolutions,
                    args.steps,
                    args.motion,
                    args.build,
                    progress=True,
                )
            except FileNotFoundError as error:
                print(f"dyadfmu: {error}", file=sys.stderr)
                return 2
            worst = max(worst, result.worst_relative)
            written += outputs(args, result)
    _print_written(worst, written)
    return 0


def _run(args: argparse.Namespace) -> int:
    from .cosim import harness, scenes
    from .mechanisms import builtin

    names = _chosen(args.mechanisms, builtin.NAMES, "mechanism")
    if names is None:
        return 2
    status = _run_each(args, names, harness.run_mechanism, _mechanism_outputs)
    if status == 0 and "slider-crank" in names:
        # the same engine as a mechanism FMU: the crank's motion and the gas force in, the
        # kinematics solved inside
        print(
            "\nThe slider-crank as a mechanism FMU (modelDescription/scenes/engine.toml), "
            "driven by the crank:"
        )
        args.out.mkdir(parents=True, exist_ok=True)
        status = _run_each(args, ["engine"], scenes.run, _scene_outputs)
    return status


def scenes_names() -> tuple[str, ...]:
    """The example scenes, for the help text."""
    return SCENE_NAMES


def _scene_outputs(args: argparse.Namespace, result: scenes.SceneRun) -> list[Path]:
    """Print one scene run's table; write its tables and, for a chain, its drawing."""
    from .cosim import scenes
    from .report import tables

    rows = tables.error_rows(result.errors)
    print(scenes.summary(result))
    print(tables.format_text(rows))
    print()
    stem = args.out / f"{result.name}_fmi{result.fmi_version}"
    written = tables.write_error_tables(stem, scenes.summary(result), rows)
    if not args.no_plots and result.source.chain is not None:
        from .report import chain_drawing

        written.append(
            chain_drawing.figure(
                result.source.chain,
                result.kin,
                scenes.reactions_of(result),
                scenes.drawing_indices(result),
                f"{stem}_reactions.png",
            )
        )
    return written


def _is_file(name: str) -> bool:
    """A scene named by its file (SCENE.toml), not by a built-in scene's name."""
    return name.endswith(".toml")


def _scene(args: argparse.Namespace) -> int:
    from .cosim import scenes

    files = [Path(n) for n in args.scenes if _is_file(n)]
    names = _chosen([n for n in args.scenes if not _is_file(n)], SCENE_NAMES, "scene")
    if names is None:
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    status = _run_each(args, names, scenes.run, _scene_outputs) if names else 0
    for file in files:
        status = max(status, _own_scene(args, file))
    return status


def _own_scene(args: argparse.Namespace, file: Path) -> int:
    """A scene file: built where needed, drawn and reported (report/own_scene.py)."""
    from .report import cylinder_drawing, own_scene

    version = 3 if args.fmi == "3" else 2
    try:
        written = own_scene.run(file, args.out, version, lambda text: print(text, flush=True))
    except cylinder_drawing.DrawingError as error:
        print(f"dyadfmu scene: error: {error}", file=sys.stderr)
        return 2
    for path in written:
        print(f"wrote {path}")
    return 0


def _problem(args: argparse.Namespace) -> str | None:
    """What is wrong with the arguments of a run or scene command beyond each option's own
    type, or None: the names, the length of the run, the output folder."""
    from .mechanisms import builtin

    if args.command == "run":
        names, what, known = args.mechanisms, "mechanism", builtin.NAMES
    else:
        names, what, known = args.scenes, "scene", SCENE_NAMES
        missing = [n for n in names if _is_file(n) and not Path(n).is_file()]
        if missing:
            return f"no such scene file: {', '.join(missing)}"
        names = [n for n in names if not _is_file(n)]
    unknown = [n for n in names if n not in known] if names != ["all"] else []
    if unknown:
        return f"unknown {what} {', '.join(unknown)}; the {what}s are: {', '.join(known)}"
    total = int(round(args.steps * args.revolutions))
    if not MIN_STEPS <= total <= MAX_STEPS:
        return (
            f"--revolutions {args.revolutions:g} at --steps {args.steps} makes {total} "
            f"communication steps; a run needs {MIN_STEPS} to {MAX_STEPS}"
        )
    return None


#: The path arguments of each command parsed here: (name as shown, attribute, kind), checked
#: after the parse, before any work (those of the other commands: their modules' PATHS).
_BUILD = ("--build", "build", paths.FOLDER)
PATHS = {
    "run": (("--out", "out", paths.OUT), _BUILD),
    "scene": (("--out", "out", paths.OUT), _BUILD),
    "study": (("--out", "out", paths.OUT), _BUILD),
    "speed": (_BUILD,),
    "sweep": (("STUDY.toml", "study", paths.FILE), ("--out", "out", paths.OUT), _BUILD),
}


#: The commands that parse their own options: command -> module, each with main(argv)
#: and parser().
OWN_PARSERS = {
    "scenes": ".report.scenes",
    "cosim": ".report.cosim",
    "plants": ".report.plants",
    "scene-bench": ".study.long_chain",
    "rows": ".fmi.rows_command",
    "build-scene": ".build_scene",
    "animate": ".animation.command",
    "embedded": ".embedded.command",
}


def _own_command(command: str) -> ModuleType | None:
    """The module of a command that parses its own options, or None."""
    name = OWN_PARSERS.get(command)
    return importlib.import_module(name, __package__) if name else None


def main(argv: list[str] | None = None) -> int:
    """Run the dyadfmu command with `argv` (default: the process's arguments); with
    --parse-only first, only check the arguments (exit 2 and a message if one is bad): the
    scripts/run-* wrappers do so before they build."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parse_only = argv[:1] == ["--parse-only"]
    argv = argv[1:] if parse_only else argv
    own = _own_command(argv[0]) if argv else None
    if own is not None:
        if parse_only:
            paths.parse_checked(own.parser(), argv[1:], own.PATHS)
            return 0
        return _guarded(argv[0], own.main, argv[1:])
    top = parser()
    args = top.parse_args(argv)
    problem = _problem(args) if args.command in ("run", "scene") else None
    if problem:
        top.exit(2, f"dyadfmu {args.command}: error: {problem}\n")
    paths.refuse_bad_paths(_subparser(top, args.command), args, PATHS.get(args.command, ()))
    return 0 if parse_only else _guarded(args.command, args.run, args)


def _subparser(top: argparse.ArgumentParser, command: str) -> argparse.ArgumentParser:
    """The parser of a subcommand (its prog names the command in messages)."""
    sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[command]


def _guarded(command: str, run: Callable, *args: object) -> int:
    """run(*args), with a file or folder that fails after the checks (removed meanwhile, a
    full disk, a name the file system refuses) reported as one line, status 2."""
    try:
        return run(*args)
    except paths.PathProblem as error:
        print(f"dyadfmu {command}: error: {error}", file=sys.stderr)
    except OSError as error:
        where = f"{error.filename}: " if error.filename else ""
        print(f"dyadfmu {command}: error: {where}{error.strerror or error}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())

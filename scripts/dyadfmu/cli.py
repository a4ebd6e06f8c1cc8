"""Command line of the dyadfmu harness: co-simulate a mechanism's dyad FMU with
fmpy, compare every output with the NumPy reference, write tables and plots."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import harness, mechanisms

DEFAULT_SCENE = "slider-crank"


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 4:
        raise argparse.ArgumentTypeError(f"must be at least 4, got {value}")
    return value


def _positive_float(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {value}")
    return value


def _cosimulation_options(command, out: Path, revolutions_help: str):
    """The options of a command that co-simulates FMUs over the crank's motion."""
    command.add_argument("--fmi", choices=("2", "3", "both"), default="both",
                         help="FMI version of the FMU to run (default both)")
    command.add_argument("--revolutions", type=_positive_float, default=2.0,
                         help=revolutions_help)
    command.add_argument("--steps", type=_positive_int, default=360,
                         help="communication steps per revolution (default 360)")
    command.add_argument("--motion", choices=("constant", "varying"), default="constant",
                         help="crank speed: constant, or varying along the cycle "
                              "(default constant)")
    command.add_argument("--out", type=Path, default=out,
                         help=f"directory for tables and plots (default ./{out})")
    command.add_argument("--build", type=Path, default=None,
                         help="CMake build directory holding fmus/ (default: build/ of the "
                              "checkout)")
    command.add_argument("--no-plots", action="store_true", help="write tables only")


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(
        prog="dyadfmu",
        description="Co-simulate the dyad FMUs of planar mechanisms with fmpy and check every "
                    "joint reaction against an independent Newton-Euler solve in NumPy.")
    sub = top.add_subparsers(dest="command", required=True)

    listing = sub.add_parser("list", help="list the scenes (mechanisms) and their dyads")
    listing.set_defaults(run=_list)

    run = sub.add_parser("run", help="co-simulate scenes and compare them with the reference",
                         description="Co-simulate each scene's dyad FMU over the crank's motion, "
                                     "print the error of every output against the reference, "
                                     "write tables (Markdown, CSV) and plots (PNG).")
    run.add_argument("scenes", nargs="*", metavar="SCENE", default=[DEFAULT_SCENE],
                     help=f"scene names (default {DEFAULT_SCENE}; 'all' for every scene; "
                          f"see 'dyadfmu list')")
    _cosimulation_options(run, Path("out"),
                          "crank revolutions (oscillations for trt-slot) to simulate (default 2)")
    run.add_argument("--angle", type=float, default=60.0,
                     help="crank angle in degrees at which the mechanism is drawn (default 60)")
    run.set_defaults(run=_run)

    study = sub.add_parser(
        "study", help="accuracy and speed of every method; writes the report",
        description="Time the C core (double, float), GSL LU and SVD 6x6 solves, NumPy's "
                    "batched solve and the FMUs (from C and fmpy) on the same inputs; measure "
                    "their errors against mpmath ground truth on random, near-singular, "
                    "extreme and cancelling configurations; write report.md, CSVs and plots.")
    study.add_argument("--quick", action="store_true",
                       help="small input sets (for CI: under a minute)")
    study.add_argument("--out", type=Path, default=Path("out/study"),
                       help="directory for the report (default ./out/study)")
    study.add_argument("--build", type=Path, default=None,
                       help="CMake build directory with the benchmark and FMUs (default build/)")
    study.set_defaults(run=_study)

    scene = sub.add_parser(
        "scene", help="co-simulate tailored scene FMUs (scenes/*.toml) against their reference",
        description="Co-simulate each scene's tailored FMU over the crank's motion, print the "
                    "error of every output against the independent reference, and write "
                    "tables (Markdown, CSV) and, for the multi-dyad chains, a drawing with "
                    "every reaction. Scenes: " + ", ".join(scenes_names()) + ".")
    scene.add_argument("scenes", nargs="*", metavar="SCENE", default=["shaper"],
                       help="scene names (default shaper; 'all' for every example scene)")
    _cosimulation_options(scene, Path("out/scenes"), "crank revolutions to simulate (default 2)")
    scene.set_defaults(run=_scene)

    sub.add_parser(
        "scenes", add_help=False,
        help="every example scene against its reference, and the tailored FMUs against the "
             "generic per-type FMUs: variables, binary size, callgrind instructions per doStep "
             "(see 'dyadfmu scenes --help')").set_defaults(run=None)

    cosim = sub.add_parser(
        "cosim", add_help=False,
        help="the dyad FMU in a closed loop with the drive FMU: explicit and stabilised "
             "coupling against a monolithic reference (see 'dyadfmu cosim --help')")
    cosim.set_defaults(run=None)

    sub.add_parser(
        "scene-bench", add_help=False,
        help="time the scene generator (--check and --out) on chains of 25 to 200 dyads "
             "(see 'dyadfmu scene-bench --help')").set_defaults(run=None)
    return top


def _study(args) -> int:
    from . import study

    try:
        report = study.run(args.out, quick=args.quick, build=args.build,
                           log=lambda text: print(text, file=sys.stderr))
    except FileNotFoundError as error:
        print(f"dyadfmu: {error}", file=sys.stderr)
        return 2
    print(report.read_text())
    print(f"report: {report}")
    return 0


def _list(args) -> int:
    for name in mechanisms.NAMES:
        mech = mechanisms.load(name)
        print(f"{name:14s} {mech.dyad}  {mech.description}")
    return 0


def _run(args) -> int:
    scenes = list(mechanisms.NAMES) if args.scenes == ["all"] else args.scenes
    unknown = [s for s in scenes if s not in mechanisms.NAMES]
    if unknown:
        print(f"dyadfmu: unknown scene {', '.join(unknown)}; the scenes are: "
              f"{', '.join(mechanisms.NAMES)}", file=sys.stderr)
        return 2
    versions = (2, 3) if args.fmi == "both" else (int(args.fmi),)
    written = []
    worst = 0.0
    for scene in scenes:
        for version in versions:
            try:
                result = harness.run_scene(scene, version, args.revolutions, args.steps,
                                           args.motion, args.build, progress=True)
            except FileNotFoundError as error:
                print(f"dyadfmu: {error}", file=sys.stderr)
                return 2
            print(harness.summary(result))
            print(harness.format_text(harness.error_table(result)))
            print()
            worst = max(worst, result.worst_relative)
            written += harness.write_tables(result, args.out)
            if not args.no_plots:
                from . import plots  # matplotlib only when plotting

                stem = f"{scene}_fmi{version}"
                written.append(plots.plot_reactions(result, args.out / f"{stem}_reactions.png"))
                written.append(plots.plot_mechanism(result, args.angle,
                                                    args.out / f"{stem}_mechanism.png"))
    print(f"worst relative error of any output: {worst:.2e}")
    print("written:")
    for path in written:
        print(f"  {path}")
    return 0


def scenes_names():
    from . import scenes

    return scenes.NAMES


def _scene(args) -> int:
    import csv

    from . import scenes

    names = list(scenes.NAMES) if args.scenes == ["all"] else args.scenes
    unknown = [n for n in names if n not in scenes.NAMES]
    if unknown:
        print(f"dyadfmu: unknown scene {', '.join(unknown)}; the example scenes are: "
              f"{', '.join(scenes.NAMES)}", file=sys.stderr)
        return 2
    versions = (2, 3) if args.fmi == "both" else (int(args.fmi),)
    args.out.mkdir(parents=True, exist_ok=True)
    written, worst = [], 0.0
    for name in names:
        for version in versions:
            try:
                result = scenes.run(name, version, args.revolutions, args.steps, args.motion,
                                    args.build, progress=True)
            except FileNotFoundError as error:
                print(f"dyadfmu: {error}", file=sys.stderr)
                return 2
            rows = scenes.error_rows(result)
            print(scenes.summary(result))
            print(harness.format_text(rows))
            print()
            worst = max(worst, result.worst_relative)
            stem = args.out / f"{name}_fmi{version}"
            Path(f"{stem}_errors.md").write_text(
                f"# {scenes.summary(result)}\n\n{harness.format_markdown(rows)}\n")
            with open(f"{stem}_errors.csv", "w", newline="") as handle:
                csv.writer(handle).writerows(rows)
            written += [Path(f"{stem}_errors.md"), Path(f"{stem}_errors.csv")]
            if not args.no_plots and result.source.chain is not None:
                from . import chain_drawing

                written.append(chain_drawing.figure(
                    result.source.chain, result.kin, scenes.reactions_of(result),
                    scenes.drawing_indices(result), f"{stem}_reactions.png"))
    print(f"worst relative error of any output: {worst:.2e}")
    print("written:")
    for path in written:
        print(f"  {path}")
    return 0


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["scenes"]:
        from . import scene_report  # its own options: --quick, --out, ...

        return scene_report.main(argv[1:])
    if argv[:1] == ["cosim"]:
        from . import cosim_report  # its own options: --quick, --out, ...

        return cosim_report.main(argv[1:])
    if argv[:1] == ["scene-bench"]:
        from . import long_chain  # its own options: --sizes, --generator, --write

        return long_chain.main(argv[1:])
    args = parser().parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())

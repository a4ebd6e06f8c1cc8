"""What tailoring buys: for each example scene, its tailored FMU against the generic
per-type FMUs it would otherwise take (one per dyad), in variables, binary size and work
per doStep; and every tailored FMU co-simulated against its reference.

Work per doStep is counted by ``valgrind --tool=callgrind`` around the stepping loop of
``tests/bench/dyad_bench --method fmu`` (set the inputs, doStep, get the real outputs),
and timed in one run of the same program (median of several passes). The generic FMUs are
stepped through their own start values with smooth variations (as in the accuracy and
speed study); the tailored ones through the scene's own kinematics. The generic route also
leaves the master to carry the reactions from dyad to dyad and to balance the crank: that
work is not counted, so the comparison favours the generic FMUs.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .. import paths
from ..cosim import scenes
from ..study.footprint import measure
from . import markdown, mechanisms
from .tables import format_markdown, format_text


def footprint_rows(results: list) -> list:
    """The footprint table: each tailored FMU against the generic FMUs it replaces."""
    rows = [
        [
            "scene",
            "generic FMUs",
            "variables (in/par/out)",
            "generic variables",
            "binary (bytes)",
            "generic binaries",
            ".text (bytes)",
            "generic .text",
            "instr./doStep",
            "generic instr.",
            "ratio",
            "ns/doStep",
            "generic ns",
            "ratio",
        ]
    ]
    for name, mine, full in results:
        unique = {}
        for dyad, f in zip(scenes.FULL_OF[name], full, strict=False):
            unique[dyad] = f
        f_vars = sum(f.variables for f in full)
        f_in = sum(f.inputs for f in full)
        f_par = sum(f.parameters for f in full)
        f_out = sum(f.outputs for f in full)
        f_bytes = sum(f.binary_bytes for f in unique.values())
        f_text = sum(f.text_bytes for f in unique.values())
        f_instr = sum(f.instructions for f in full)
        f_sec = sum(f.seconds for f in full)
        rows.append(
            [
                name,
                " + ".join(f"dyad_{d.lower()}" for d in scenes.FULL_OF[name]),
                f"{mine.variables} ({mine.inputs}/{mine.parameters}/{mine.outputs})",
                f"{f_vars} ({f_in}/{f_par}/{f_out})",
                f"{mine.binary_bytes}",
                f"{f_bytes}",
                f"{mine.text_bytes}",
                f"{f_text}",
                f"{mine.instructions:.0f}",
                f"{f_instr:.0f}",
                f"{mine.instructions / f_instr:.2f}" if f_instr else "-",
                f"{1e9 * mine.seconds:.0f}",
                f"{1e9 * f_sec:.0f}",
                f"{mine.seconds / f_sec:.2f}" if f_sec else "-",
            ]
        )
    return rows


def accuracy_rows(runs: list) -> list:
    """The accuracy table: every scene run against its reference."""
    rows = [
        [
            "scene",
            "FMI",
            "outputs",
            "steps",
            "worst error / own peak",
            "worst error / peak of its unit",
            "driving torque (N m)",
            "energy balance",
            "run time (s)",
        ]
    ]
    for r in runs:
        torque = r.fmu.get(f"{r.source.crank_name}.torque")
        scale = {}
        for e in r.errors:
            scale[e.unit] = max(scale.get(e.unit, 0.0), e.peak)
        per_unit = max(e.max_abs / scale[e.unit] for e in r.errors if scale[e.unit] > 0)
        rows.append(
            [
                r.name,
                str(r.fmi_version),
                str(len(r.errors)),
                str(r.steps),
                f"{r.worst_relative:.2e}",
                f"{per_unit:.2e}",
                f"{torque[r.valid].min():.4g} .. {torque[r.valid].max():.4g}"
                if torque is not None
                else "-",
                f"{r.energy_residual:.1e}" if not math.isnan(r.energy_residual) else "-",
                f"{r.seconds_fmu:.3f}",
            ]
        )
    return rows


def parser() -> argparse.ArgumentParser:
    """The options of 'dyadfmu scenes'."""
    found = argparse.ArgumentParser(
        prog="dyadfmu scenes",
        description="Co-simulate every example scene's tailored FMU against its reference, "
        "draw the chains with their reactions, and measure each tailored FMU "
        "against the generic per-type FMUs it replaces (variables, binary size, "
        "callgrind instructions and time per doStep), and every mechanism FMU from the "
        "driver's motion alone (inputs before and after, worst errors, instructions with "
        "and without the kinematics); writes report.md.",
    )
    found.add_argument(
        "--out",
        type=Path,
        default=Path("out/scenes"),
        help="directory for the report, tables and drawings (default ./out/scenes)",
    )
    found.add_argument(
        "--build",
        type=Path,
        default=None,
        help="CMake build directory with fmus/ and tests/bench (default build/)",
    )
    found.add_argument("--quick", action="store_true", help="fewer steps and rows (for CI)")
    return found


def _log(text: str) -> None:
    print(text, file=sys.stderr)


def _runs(build: Path, quick: bool) -> list:
    """Every example scene's tailored FMU, FMI 2 and 3, against its reference."""
    runs = []
    for name in scenes.NAMES:
        for version in (2, 3):
            result = scenes.run(
                name,
                version,
                revolutions=1.0 if quick else 2.0,
                steps=180 if quick else 360,
                build=build,
            )
            runs.append(result)
            _log(scenes.summary(result))
    return runs


def _drawings(runs: list, out: Path) -> list[Path]:
    """The chains drawn with every reaction (FMI 2 runs)."""
    from . import chain_drawing

    return [
        chain_drawing.figure(
            r.source.chain,
            r.kin,
            scenes.reactions_of(r),
            scenes.drawing_indices(r),
            out / f"{r.name}_reactions.png",
        )
        for r in runs
        if r.source.chain is not None and r.fmi_version == 2
    ]


def report_text(
    acc: list, foot: list, quick: bool, moving: list, drawings: tuple[Path, ...] = ()
) -> str:
    """The report: the accuracy table, the footprint table, what they leave out, the
    mechanism FMUs' table and the drawings' file names."""
    lines = [
        "# Scenes: tailored FMUs against the generic per-type FMUs",
        "",
        markdown.provenance(f"scripts/run-scenes{' --quick' if quick else ''}"),
        "",
        "Every example scene's tailored FMU, co-simulated with fmpy over "
        f"{'one crank turn (180' if quick else 'two crank turns (360'} steps per "
        "turn) and compared output by output with its independent reference. Errors are "
        "relative to each output's own peak, and to the peak of all outputs in the same "
        "unit (a reaction that is tiny beside the mechanism's other forces, like the "
        "shaper's slot moment M_mn of 8e-3 N m among moments of 275 N m, keeps the "
        "round-off of those); the chains' driving torque is also checked against the "
        "energy balance of the whole mechanism, relative to the peak driving power:",
        "",
        format_markdown(acc),
        "",
        "What tailoring buys (FMI 2 binaries; the generic route needs one dyad_<type> FMU "
        "per dyad, binaries counted once per type; instructions by callgrind per doStep "
        "including setting the inputs and getting the real outputs; times are medians "
        "of one run, ratios in the same run):",
        "",
        format_markdown(foot),
        "",
        "The generic route also leaves the master to carry each dyad's reactions to the "
        "links it is attached to and to balance the crank; that work is not counted "
        "above.",
        "",
        "## Mechanism FMUs",
        "",
        mechanisms.REPORT_TEXT,
        "",
        format_markdown(moving),
        "",
    ]
    if drawings:
        names = ", ".join(markdown.code(p.name) for p in drawings)
        lines += [f"Drawings with every reaction: {names}", ""]
    return "\n".join(lines)


#: The path arguments, checked before any work (dyadfmu.paths.parse_checked).
PATHS = (("--out", "out", paths.OUT), ("--build", "build", paths.FOLDER))


def main(argv: list[str] | None = None) -> int:
    """Run 'dyadfmu scenes' with `argv`: every scene, drawings, footprints, report.md."""
    args = paths.parse_checked(parser(), argv, PATHS)
    build = args.build or paths.build_dir()
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    try:
        runs = _runs(build, args.quick)
        drawings = _drawings(runs, out)
        results = measure(
            build,
            2,
            rows_count=200 if args.quick else 500,
            repeat=5 if args.quick else 21,
            log=_log,
        )
    except FileNotFoundError as error:
        print(f"dyadfmu: {error}", file=sys.stderr)
        return 2
    acc = accuracy_rows(runs)
    foot = footprint_rows(results)
    moving = mechanisms.rows(build, args.quick, log=_log)
    report = out / "report.md"
    report.write_text(report_text(acc, foot, args.quick, moving, tuple(drawings)), encoding="utf-8")
    print(format_text(acc))
    print()
    print(format_text(foot))
    print()
    print(format_text(moving))
    print(f"\nreport: {report}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

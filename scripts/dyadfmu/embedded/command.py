"""``dyadfmu embedded``: built-in scenes as Cortex-M4F firmware under QEMU, in float,
against this machine's float build: instructions and estimated cycles per tick, flash,
RAM and stack, and how the outputs compare. Writes OUT/report.md and prints it."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from .. import paths
from ..argtypes import whole
from ..report import markdown
from . import firmware, stack, study
from .ticks import EmbeddedError

#: The arguments naming a path, checked before any work (cli.py).
PATHS = (("--out", "out", paths.OUT), ("--build", "build", paths.FOLDER))
DEFAULT_SCENES = ("shaper", "lift", "excavator")
#: The shaper controller's budget: at most this share of a 1 ms tick at 168 MHz.
SHAPER_SHARE_TARGET = 0.20


def parser() -> argparse.ArgumentParser:
    """The options of `dyadfmu embedded`."""
    command = argparse.ArgumentParser(
        prog="dyadfmu embedded",
        description="Build each scene's bundle (scripts/build-scene --bundle) as firmware for "
        "a 168 MHz Cortex-M4F in float (arm-none-eabi-gcc, newlib-nano, no heap), run it "
        "under QEMU (mps2-an386) over the harness's inputs, one evaluation per tick, and "
        "compare every output with the same program built for this machine in float. "
        "Reports per scene the instructions per tick (QEMU's trace), the cycles estimated "
        "from the Cortex-M4's instruction timings, the share of a 1 ms tick, flash and RAM "
        "(from the link map) and the deepest stack (painted), with and without the "
        "directional derivative. Needs gcc-arm-none-eabi, libnewlib-arm-none-eabi and "
        "qemu-system-arm, and the build's FMUs (for the harness's inputs).",
    )
    command.add_argument(
        "scenes",
        nargs="*",
        metavar="SCENE",
        default=list(DEFAULT_SCENES),
        help=f"built-in scenes by name (over the harness's motion; default "
        f"{' '.join(DEFAULT_SCENES)}) or scene files FILE.toml (yours; the first crank one "
        "turn, or --range)",
    )
    command.add_argument(
        "--range",
        nargs=3,
        action="append",
        default=[],
        metavar=("INPUT", "MIN", "MAX"),
        help="move the input INPUT (a driver's coordinate, rad or m) from MIN to MAX over the "
        "ticks instead, the other inputs at their start values; repeatable",
    )
    command.add_argument(
        "--ticks", type=whole(4, 2000), default=120, help="ticks per run (default 120)"
    )
    command.add_argument(
        "--traced",
        type=whole(1, 100),
        default=12,
        help="ticks traced for the instruction count, spread over the run (default 12)",
    )
    command.add_argument(
        "--out",
        type=Path,
        default=Path("out/embedded"),
        help="folder of report.md and the builds (default out/embedded)",
    )
    command.add_argument(
        "--build", type=Path, default=None, help="the build with the FMUs (default build/)"
    )
    return command


def _scene_problem(names: list[str]) -> str | None:
    for name in names:
        if name.endswith(".toml"):
            problem = paths.path_problem("SCENE", name, paths.FILE)
            if problem:
                return problem
    known = sorted(p.stem for p in paths.SCENES_DIR.glob("*.toml"))
    unknown = [n for n in names if n not in known and not n.endswith(".toml")]
    if unknown:
        return (
            f"unknown scene {', '.join(unknown)} (a scene file ends in .toml); the built-in "
            f"scenes are: {', '.join(known)}"
        )
    return None


def _ranges(given: list[list[str]]) -> dict[str, tuple[float, float]]:
    """--range INPUT MIN MAX ..., each MIN and MAX a number."""
    ranges = {}
    for name, low, high in given:
        try:
            ranges[name] = (float(low), float(high))
        except ValueError:
            raise EmbeddedError(f"--range {name} {low} {high}: MIN and MAX are numbers") from None
    return ranges


def main(argv: list[str] | None = None) -> int:
    """Run the command: 0, 1 where a scene fails its run, 2 on bad arguments or tools."""
    args = paths.parse_checked(parser(), argv, PATHS)
    problem = _scene_problem(args.scenes) or _tools_problem()
    if problem:
        print(f"dyadfmu embedded: error: {problem}", file=sys.stderr)
        return 2
    results = []
    for name in args.scenes:
        print(f"{name}: building and running on the Cortex-M4F model ...", file=sys.stderr)
        work = args.out / Path(name).stem
        try:
            ranges = _ranges(args.range)
            results.append(
                study.run_scene(name, work, args.ticks, args.traced, args.build, _log, ranges)
            )
        except EmbeddedError as error:
            print(f"dyadfmu embedded: {name}: {error}", file=sys.stderr)
            return 1
    report = args.out / "report.md"
    plot_budget(results, args.out / BUDGET_PLOT)
    report.write_text(report_text(results), encoding="utf-8")
    print(report.read_text(encoding="utf-8"))
    print(f"report: {report}")
    return 0


#: The picture of the report: each scene's share of a tick.
BUDGET_PLOT = "tick_budget.png"


def plot_budget(results: list[study.SceneResult], path: Path) -> Path:
    """Each scene's estimated cycles per tick as a share of 1 ms at 168 MHz, the shaper's
    target marked: `path` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 0.6 + 0.5 * len(results)))
    shares = [100 * r.cycles_share() for r in results]
    ax.barh([r.scene for r in results], shares, color="tab:blue")
    for k, share in enumerate(shares):
        ax.annotate(f"{share:.1f} %", (share, k), xytext=(4, 0), textcoords="offset points",
                    va="center")  # fmt: skip
    ax.axvline(100 * SHAPER_SHARE_TARGET, color="tab:red", linestyle="--",
               label="the shaper's target")  # fmt: skip
    ax.set_xlim(0, 100)
    ax.set_xlabel("estimated cycles of one evaluation, % of a 1 ms tick at 168 MHz")
    ax.invert_yaxis()
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _log(text: str) -> None:
    print(f"  {text}", file=sys.stderr)


def _tools_problem() -> str | None:
    missing = firmware.missing_tools()
    if missing:
        return (
            f"missing {', '.join(missing)}: scripts/run-tests installs them as root "
            "(scripts/env.sh: dyadfmu_ensure_system embedded)"
        )
    return None


def _tool_text(tool: str) -> str:
    """The first line of the tool's --version, escaped for Markdown."""
    done = subprocess.run([tool, "--version"], capture_output=True, text=True, check=False)
    return markdown.text((done.stdout.splitlines() or ["?"])[0])


#: The tables' headers.
COST_HEADER = (
    "scene",
    "instructions per tick",
    "cycles per tick (estimate)",
    "share of 1 ms at 168 MHz",
    "flash: scene and core (B)",
    "flash: libc, libm, libgcc (B)",
    "RAM (B)",
    "stack: call graph, painted (B)",
    "with the derivative: flash, stack by the call graph (B)",
)
COMPARE_HEADER = (
    "scene",
    "outputs",
    "bit-identical",
    "largest difference",
    "with -ffp-contract=fast: bit-identical",
    "largest difference",
)


def _cost_row(r: study.SceneResult) -> list[str]:
    ins = [c.instructions for c in r.costs]
    cyc = [c.cycles for c in r.costs]
    d = r.derivative_sizes
    return [
        r.scene,
        f"{min(ins):,} to {max(ins):,}",
        f"{min(cyc):,} to {max(cyc):,}",
        f"{100 * r.cycles_share():.1f} %",
        f"{r.sizes.flash['scene']:,}",
        f"{r.sizes.flash['libraries']:,}",
        f"{r.sizes.ram['scene'] + r.sizes.ram['libraries']:,}",
        f"{_bytes(r.stack_bound)}, {r.stack:,}",
        f"{d.flash['scene']:,}, {_bytes(r.derivative_stack_bound)}" if d else "-",
    ]


def _bytes(bound: stack.StackBound | None) -> str:
    return "unbounded" if bound is None or bound.bytes is None else f"{bound.bytes:,}"


def _outside(results: list[study.SceneResult]) -> str:
    """The outside functions the bounds leave out, over every scene."""
    names = sorted({n for r in results for n in r.stack_bound.outside if not n.startswith("__")})
    return ", ".join(f"`{n}`" for n in names) or "none"


def _difference(c: study.Comparison) -> str:
    where = f" ({c.worst_output})" if c.worst_output else ""
    return f"{c.worst:.2g} eps{where}" + ("" if c.same_status else ", statuses DIFFER")


def _compare_row(r: study.SceneResult) -> list[str]:
    a, f = r.against_host, r.contracted
    return [
        r.scene,
        str(a.outputs),
        str(a.identical),
        _difference(a),
        str(f.identical),
        _difference(f),
    ]


def _target_line(results: list[study.SceneResult]) -> list[str]:
    shaper = next((r for r in results if r.scene == "shaper"), None)
    if shaper is None:
        return []
    share = shaper.cycles_share()
    met = "met" if share <= SHAPER_SHARE_TARGET else "**not met**"
    return [
        f"Target: the shaper controller's evaluation in at most "
        f"{100 * SHAPER_SHARE_TARGET:.0f} % of a 1 ms tick at 168 MHz: "
        f"{100 * share:.1f} % by the estimate, {met}.",
        "",
    ]


def report_text(results: list[study.SceneResult]) -> str:
    """The report: the costs and sizes, then the comparison with the host."""
    ticks = results[0].ticks if results else 0
    return "\n".join(
        [
            "# Scenes on a Cortex-M4F",
            "",
            markdown.provenance("dyadfmu embedded"),
            "",
            f"Each scene's bundle in float, {_tool_text(firmware.M4F_CC)}, `-O2`, under "
            f"{_tool_text(firmware.QEMU_ARM)} (`mps2-an386`), {ticks} ticks over the "
            "harness's inputs (one cycle of the drivers).",
            "",
            "## Cost and size",
            "",
            "Instructions: QEMU's trace of the traced ticks' `<id>_evaluate` calls. Cycles: "
            "each instruction at the Cortex-M4's documented count (taken branches at the "
            "worst refill, zero-wait memory: dyadfmu/embedded/trace.py). Flash: code, "
            "read-only data and initial data of the scene's and the core's objects, and of "
            "what they pull in of the C library and libm (no printf: `DYAD_SCENE_TERSE`). RAM: "
            "their `.data` and `.bss`. Stack: the deepest chain of frames from "
            "`<id>_evaluate` in GCC's call graph (`-fcallgraph-info=su`; the C library's "
            f"frames left out: {_outside(results)}), and the deepest over every tick, "
            "painted (the tick program's own frames in).",
            "",
            *markdown.table(COST_HEADER, [_cost_row(r) for r in results], "-rrrrrrrr"),
            "",
            *_target_line(results),
            markdown.image("each scene's share of a 1 ms tick at 168 MHz", BUDGET_PLOT),
            "",
            "## Against the host's float build",
            "",
            "The same tick program built with `cc` for this machine in float, both without "
            "contraction into fused multiply-adds: an output differs only where the two C "
            "libraries do (`atan2f` behind the angles); the difference is in FLT_EPSILON "
            "(2^-23) of the output's peak. GCC's default for the M4F contracts `a*b+c` "
            "into `vfma.f32`, one rounding fewer, which moves most outputs.",
            "",
            *markdown.table(COMPARE_HEADER, [_compare_row(r) for r in results], "-rrrrr"),
            "",
        ]
    )

"""One scene on the Cortex-M4F: its bundle built as firmware in float, run under QEMU
over the harness's inputs (one cycle of the scene's drivers) against the same tick
program built for this machine in float, its instructions and estimated cycles per
tick, its flash, RAM and stack; with GCC's default contraction into fused
multiply-adds too, and with the directional derivative (``<id>_derivative`` called in
place of ``<id>_evaluate``) for its size."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import paths
from . import firmware, sizes, stack, ticks, trace

__all__ = ["Comparison", "SceneResult", "compare", "run_scene", "TICK_SECONDS", "CLOCK_HZ"]

#: The controller's tick and the part's clock.
TICK_SECONDS = 1e-3
CLOCK_HZ = 168e6


@dataclass(frozen=True)
class Comparison:
    """The M4F's outputs against the host's over every tick: outputs equal bit for bit at
    every tick, and the largest difference relative to the output's peak on the host
    (in float epsilons, FLT_EPSILON = 2^-23)."""

    outputs: int
    identical: int
    worst: float  # in FLT_EPSILON of the output's peak
    worst_output: str
    same_status: bool


def compare(names: list[str], host: firmware.TickRun, m4f: firmware.TickRun) -> Comparison:
    """How the M4F run compares with the host run."""
    identical, worst, worst_output = 0, 0.0, ""
    for j, name in enumerate(names):
        a, b = host.values[:, j], m4f.values[:, j]
        if np.array_equal(a.view(np.uint64), b.view(np.uint64)):
            identical += 1
            continue
        finite = np.isfinite(a) & np.isfinite(b)
        if not np.array_equal(np.isfinite(a), np.isfinite(b)):
            return Comparison(len(names), identical, float("inf"), name, False)
        peak = float(np.max(np.abs(a[finite]))) if finite.any() else 0.0
        diff = float(np.max(np.abs(a[finite] - b[finite]))) / (peak or 1.0)
        if diff / np.finfo(np.float32).eps > worst:
            worst, worst_output = diff / float(np.finfo(np.float32).eps), name
    same = np.array_equal(host.status, m4f.status)
    return Comparison(len(names), identical, worst, worst_output, bool(same))


@dataclass(frozen=True)
class SceneResult:
    """What `run_scene` measured of one scene."""

    scene: str
    ticks: int
    outputs: list[str]
    against_host: Comparison
    contracted: Comparison  # the M4F built with -ffp-contract=fast against the host
    costs: list[trace.TickCost]  # per traced tick
    sizes: sizes.Sizes
    stack: int  # bytes, the deepest over every tick (painted)
    stack_bound: stack.StackBound  # of <id>_evaluate, from the call graph
    derivative_sizes: sizes.Sizes | None
    derivative_stack: int
    derivative_stack_bound: stack.StackBound | None

    def cycles_share(self) -> float:
        """The worst traced tick's estimated cycles as a share of one tick at CLOCK_HZ."""
        return max(c.cycles for c in self.costs) / (CLOCK_HZ * TICK_SECONDS)


def scene_file(scene: str | Path) -> tuple[Path, bool]:
    """(the scene file, whether it is a built-in scene) of a built-in scene's name or a
    scene file's path."""
    if str(scene).endswith(".toml"):
        return Path(scene), False
    return paths.SCENES_DIR / f"{scene}.toml", True


def _inputs(
    scene: str | Path, blocks: ticks.Blocks, count: int, build: Path | None, ranges: dict
) -> dict[str, np.ndarray]:
    """The ticks' inputs: a built-in scene's over the harness's motion (its built FMU's
    setup), or over `ranges` (ticks.swept_inputs) where given or for a scene file."""
    path, builtin = scene_file(scene)
    if ranges or not builtin:
        return ticks.swept_inputs(blocks, ranges, count)
    from ..cosim import importers

    setup = importers.setup_of(path.stem, 3, build, steps=count)
    return {n: np.asarray(v, dtype=float)[:count] for n, v in setup.inputs.items()}


def _program(
    scene: Path, work: Path, inputs: dict, count: int, derivative: bool
) -> tuple[ticks.Blocks, Path, Path]:
    bundle = ticks.write_bundle(scene, work / "bundle", derivatives=derivative)
    blocks = ticks.read_blocks(scene)
    tick_c = work / f"{bundle.name}_ticks.c"
    text = ticks.source(blocks, inputs, count, derivative=derivative)
    tick_c.write_text(text, encoding="utf-8")
    return blocks, bundle, tick_c


def _m4f_run(bundle: Path, tick_c: Path, work: Path, contract: bool = False):
    built = firmware.build_m4f(bundle, tick_c, work, contract=contract)
    return built, firmware.run(built)


def _bound(built: firmware.Build, function: str) -> stack.StackBound:
    return stack.deepest(sorted(built.program.parent.glob("*.ci")), function)


def run_scene(
    source: str | Path,
    work: Path,
    count: int = 120,
    traced: int = 12,
    build: Path | None = None,
    log: Callable[[str], None] = lambda _: None,
    ranges: dict | None = None,
) -> SceneResult:
    """Measure a scene (a built-in scene's name, or a scene file) over `count` ticks,
    `traced` of them (evenly spread) traced for the instruction count; its inputs as
    :func:`_inputs` gives them."""
    scene, _ = scene_file(source)
    name = scene.stem
    inputs = _inputs(source, ticks.read_blocks(scene), count, build, ranges or {})
    blocks, bundle, tick_c = _program(scene, work / "evaluate", inputs, count, False)
    n = len(blocks.outputs)
    log(f"{name}: the host's float build and the M4F's, {count} ticks")
    host = firmware.parse(firmware.run(firmware.build_host(bundle, tick_c, work / "host")), n)
    built, text = _m4f_run(bundle, tick_c, work / "m4f")
    m4f = firmware.parse(text, n)
    _, contracted_text = _m4f_run(bundle, tick_c, work / "m4f-fma", contract=True)
    names = [m.name for m in blocks.outputs]
    log(f"{name}: {traced} ticks traced under QEMU")
    costs = _traced(scene, work / "traced", inputs, count, traced)
    log(f"{name}: with the directional derivative")
    d_blocks, d_bundle, d_tick = _program(scene, work / "derivative", inputs, count, True)
    d_built, d_text = _m4f_run(d_bundle, d_tick, work / "derivative" / "m4f")
    return SceneResult(
        blocks.identifier,
        count,
        names,
        compare(names, host, m4f),
        compare(names, host, firmware.parse(contracted_text, n)),
        costs,
        sizes.read_map(built.map_file, built.scene_objects),
        m4f.stack,
        _bound(built, f"{blocks.identifier}_evaluate"),
        sizes.read_map(d_built.map_file, d_built.scene_objects),
        firmware.parse(d_text, len(d_blocks.outputs)).stack,
        _bound(d_built, f"{blocks.identifier}_derivative"),
    )


def _traced(scene: Path, work: Path, inputs: dict, count: int, traced: int) -> list:
    """The costs of `traced` ticks spread over the `count`: a program of those alone."""
    picks = np.unique(np.linspace(0, count - 1, traced).round().astype(int))
    chosen = {k: v[picks] if np.ndim(v) else v for k, v in inputs.items()}
    _, bundle, tick_c = _program(scene, work, chosen, len(picks), False)
    built = firmware.build_m4f(bundle, tick_c, work / "m4f")
    log_file = work / "trace.log"
    firmware.run(built, trace=log_file)
    try:
        return trace.tick_costs(built.program, log_file)
    finally:
        log_file.unlink(missing_ok=True)

"""``dyadfmu scene FILE.toml``: a user's own scene, built where its FMU is missing or older
than the file or the project's sources, then drawn and reported over one revolution of its
first crank (the other drivers at their start values, the loads at the FMU's start values):

- ``<id>.png``: the mechanism to scale from the FMU's outputs at four poses a quarter turn
  apart, with every pair reaction and load at the first pose (:mod:`.drivers_drawing`);
- ``<id>_forces.png``: every driver's effort over the turn, at rest and turning at 60 rpm;
- ``<id>_reactions.png`` and ``<id>_reactions.csv``: the magnitude of every pair reaction
  over the turn at 60 rpm;
- ``<id>_report.md``: each reaction's and effort's peak and where, the files.

An instant where the mechanism does not assemble (or the FMU gives no answer) is a gap in
the curves, marked on the figures and listed in the report with the FMU's reason: the
command does not stop there."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .. import build_scene, paths  # noqa: E402
from ..sweep import scenebuild  # noqa: E402
from ..sweep.scenebuild import BUILT_FROM, stale  # noqa: E402, F401
from . import cylinder_drawing as cd  # noqa: E402
from . import drivers_drawing as dd  # noqa: E402
from . import markdown as md  # noqa: E402

#: Samples over the turn (a degree apart), the poses drawn, the turn's duration (60 rpm).
SAMPLES, POSES, TURN = 361, (0.0, 0.25, 0.5, 0.75), 1.0


def scene_fmu(scene: Path, identifier: str, fmi: int, out: Path, say: Callable) -> Path:
    """The scene's FMU of FMI version `fmi`, built (into the build folder of scene studies,
    :func:`dyadfmu.sweep.scenebuild.build_folder`) where it is stale; DrawingError where the
    build refuses the scene."""
    folder = scenebuild.build_folder(out)
    fmu = folder / "fmus" / f"{identifier}_fmi{fmi}.fmu"
    if stale(fmu, scene, paths.project_dir()):
        say(f"building {identifier} in {folder}")
        try:
            build_scene.build([scene], folder, windows="off")
        except build_scene.Refused as refused:
            raise cd.DrawingError(str(refused)) from None
    return fmu


def _sampled(mechanism: dd.Mechanism, ranges: dict, loads: dict, moving: bool) -> tuple:
    """Every Real output at each of the SAMPLES along the turn ({name: array}, NaN where
    the FMU has no answer) and the failing instants [(share, reason)]."""
    shares = np.linspace(0.0, 1.0, SAMPLES)
    speeds = dd.rates(ranges, TURN) if moving else None
    found, reasons = dd.evaluate(mechanism, ranges, shares, loads, speeds)
    rows = [r or {} for r in found]
    failed = [(float(s), why) for s, why in zip(shares, reasons, strict=True) if why]
    names = next((list(r) for r in rows if r), [])
    table = {n: np.array([r.get(n, math.nan) for r in rows]) for n in names}
    return {"share": shares, **table}, failed


def _reactions(table: dict) -> dict:
    """|R| of every pair reaction output (a name ending in .x with its .y), N."""
    found = {}
    for name in table:
        stem = name[:-2]
        if name.endswith(".x") and ".R_" in name and f"{stem}.y" in table:
            found[stem] = np.hypot(table[name], table[f"{stem}.y"])
    return found


def _mark_failures(ax: plt.Axes, failed: list) -> None:
    for k, (share, _) in enumerate(failed):
        label = "no answer (see the report)" if k == 0 else None
        ax.axvline(100.0 * share, color="red", alpha=0.3, lw=2, label=label)


def _reaction_figure(identifier: str, angle: str, table: dict, failed: list, path: Path) -> Path:
    fig, ax = plt.subplots(figsize=(9.0, 5.0))
    for name, values in _reactions(table).items():
        ax.plot(100.0 * table["share"], values, label=name)
    _mark_failures(ax, failed)
    ax.set_xlabel(f"share of the turn of {angle} (%)")
    ax.set_ylabel("|R| (N)")
    ax.set_title(f"{identifier}: pair reactions over one turn at 60 rpm", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def _write_csv(table: dict, path: Path) -> Path:
    names = ["share", *_reactions(table)]
    values = np.column_stack([table["share"], *_reactions(table).values()])
    header = ",".join(f'"{n}"' for n in names)
    np.savetxt(path, values, fmt="%.10g", delimiter=",", header=header, comments="")
    return path


def _peaks(table: dict, mechanism: dd.Mechanism) -> list:
    """The table of each reaction's and effort's peak magnitude and where."""
    efforts = {d.effort: "N m" if d.kind == "crank" else "N" for d in mechanism.scene.drivers}
    magnitudes = {**_reactions(table), **{n: np.abs(table[n]) for n in efforts if n in table}}
    rows = []
    for name, values in magnitudes.items():
        if not np.all(np.isnan(values)):
            k = int(np.nanargmax(values))
            share = f"{100 * table['share'][k]:.1f} %"
            rows.append([md.code(name), f"{values[k]:.6g}", efforts.get(name, "N"), share])
    return md.table(["output", "peak", "unit", "at share of the turn"], rows, "lrll")


def _report(mechanism: dd.Mechanism, fmu: Path, table: dict, failed: list, written: list) -> str:
    lines = [f"# {md.text(mechanism.scene.identifier)}", ""]
    lines += [f"From {md.code(fmu)}, one turn of the first crank at 60 rpm.", ""]
    lines += _peaks(table, mechanism) + [""]
    if failed:
        lines += [f"No answer at {len(failed)} of {SAMPLES} instants (gaps in the curves):", ""]
        lines += [f"- {100 * share:.1f} %: {md.text(reason)}" for share, reason in failed[:20]]
        lines += [""]
    lines += ["Files:", ""] + [f"- {md.code(p.name)}" for p in written]
    return "\n".join(lines) + "\n"


def run(scene_file: Path, out: Path, fmi: int, say: Callable[[str], None]) -> list[Path]:
    """Build where needed, draw and report the scene (see the module's text); the files."""
    scene_file = Path(scene_file).resolve()
    scene = dd.read_scene(scene_file)
    cranks = [d for d in scene.drivers if d.kind == "crank"]
    if not cranks:
        raise cd.DrawingError(
            f"{scene_file.name}: no crank to turn; draw it along a stroke with 'python -m "
            "dyadfmu.report.drivers_drawing FILE --range INPUT MIN MAX'"
        )
    fmu = scene_fmu(scene_file, scene.identifier, fmi, out, say)
    out.mkdir(parents=True, exist_ok=True)
    mechanism = dd.Mechanism(scene, fmu, {})
    try:
        return _drawn(mechanism, cranks[0].input(0), out, fmu, say)
    finally:
        mechanism.close()


def _drawn(mechanism: dd.Mechanism, angle: str, out: Path, fmu: Path, say: Callable) -> list:
    identifier = mechanism.scene.identifier
    start = float(mechanism.coordinates()[angle])
    ranges = {angle: (start, start + 2.0 * math.pi)}
    loads = cd.loads_given(mechanism, None)
    say(f"{identifier}: {SAMPLES} instants over one turn of {angle}")
    moving, failed = _sampled(mechanism, ranges, loads, moving=mechanism.rated)
    if len(failed) == SAMPLES:
        raise cd.DrawingError(f"no instant of the turn of {angle} has an answer: {failed[0][1]}")
    resting, _ = _sampled(mechanism, ranges, loads, moving=False)
    good = [s for s in POSES if not any(abs(s - f) < 1e-12 for f, _ in failed)]
    written = []
    if good:
        path = out / f"{identifier}.png"
        written.append(dd.figure(mechanism, ranges, good, loads, path, 0)["path"])
    curves = {(True, False): {k: resting[k] for k in ["share", *_efforts(mechanism)]}}
    if mechanism.rated:
        curves[(True, True)] = {k: moving[k] for k in ["share", *_efforts(mechanism)]}
    forces = out / f"{identifier}_forces.png"
    written.append(dd.effort_figure(mechanism, curves, loads, ranges, forces, TURN, good)["path"])
    written.append(
        _reaction_figure(identifier, angle, moving, failed, out / f"{identifier}_reactions.png")
    )
    written.append(_write_csv(moving, out / f"{identifier}_reactions.csv"))
    report = out / f"{identifier}_report.md"
    report.write_text(_report(mechanism, fmu, moving, failed, written))
    return [*written, report]


def _efforts(mechanism: dd.Mechanism) -> list[str]:
    return [d.effort for d in mechanism.scene.drivers]

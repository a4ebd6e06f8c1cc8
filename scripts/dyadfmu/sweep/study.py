"""A study from its file to its table, plot and report (``dyadfmu sweep``)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..report import sweep as report
from . import execute, sources
from .checks import check_names, units_of
from .designs import designs
from .results import Table, best_designs, table_of, write_csv
from .runs import DrivenRun, KinetostaticRun, StrokeRun, run_of
from .studyfile import Study, StudyError, line_of, read_study

__all__ = ["SweepResult", "run_study", "prepare"]


@dataclass
class SweepResult:
    """A finished study: its table, where it was written, how long it took."""

    study: Study
    table: Table
    best: list
    files: list
    seconds: float


def prepare(
    path: Path, out: Path, build: Path | None = None
) -> tuple[Study, KinetostaticRun | StrokeRun | DrivenRun, np.ndarray, dict]:
    """(study, run, designs, units): the study read, its FMUs found or built and its
    names checked against them, its designs drawn, the units of its columns. A scene
    study's names are checked against the model description generated from its scene
    first: a misspelt name is refused before the mechanism FMU is built."""
    study = read_study(path)
    drive = sources.drive_fmu(study, build)
    drive_md = sources.model_description(drive) if drive is not None else None
    planned = sources.planned_model_description(study, out)
    if planned is not None:
        check_names(study, planned[0], drive_md, planned[1])
    mechanism = sources.mechanism_fmu(study, out)
    md = sources.model_description(mechanism, trial=study.fmu is not None)
    check_names(study, md, drive_md, mechanism.name)
    try:
        run = run_of(study, str(mechanism), str(drive) if drive else None, md)
    except ValueError as e:  # no driver (check_names refuses that first)
        source = "scene" if study.scene is not None else "fmu"
        line = line_of(study.text, "study", key=source)
        raise StudyError(f"{study.path}:{line}: {mechanism.name}: {e}") from None
    values = designs(
        study.sampling, [p.low for p in study.parameters], [p.high for p in study.parameters]
    )
    return study, run, values, units_of(study, md, drive_md)


#: Samples of a study whose runs evaluate in calls of the binary (a kinetostatic or a
#: stroke run) that it runs in this process when no worker count is given: about a
#: second at most for the built-in scenes (the tipper's 10,000 instructions a sample),
#: about what a local cluster takes to start.
IN_PROCESS_SAMPLES = 200_000
#: Local worker processes when no count is given and the study is larger.
DEFAULT_WORKERS = 2


def workers_for(run: object, designs: int, workers: int | None) -> int:
    """The worker processes to run ``designs`` designs of ``run`` on: ``workers`` where
    given; else none (this process) for a study evaluated in calls of the binary with at
    most IN_PROCESS_SAMPLES samples, DEFAULT_WORKERS for any other."""
    if workers is not None:
        return workers
    batched = isinstance(run, KinetostaticRun) and run.use_rows
    small = batched and designs * run.points <= IN_PROCESS_SAMPLES
    return 0 if small else DEFAULT_WORKERS


def run_study(
    path: Path,
    out: Path,
    workers: int | None = None,
    scheduler: str | None = None,
    build: Path | None = None,
    plots: bool = True,
) -> SweepResult:
    """Run a study: ``workers`` = 0 runs it in this process, else on a local Dask cluster
    of that many processes, or on the cluster at ``scheduler``; None chooses
    (:func:`workers_for`)."""
    if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}", Path(path).stem):
        raise StudyError(
            f"{path}: a study file's name (its output folder) must be letters, "
            "digits, '_', '-' and '.'"
        )
    study_out = out / Path(path).stem
    study_out.mkdir(parents=True, exist_ok=True)
    study, run, values, units = prepare(Path(path), study_out, build)
    progress = execute.Progress(len(values))
    workers = workers_for(run, len(values), workers) if scheduler is None else workers
    if workers == 0 and scheduler is None:
        outcomes, where = execute.run_serial(run, values, progress), "this process"
    else:
        outcomes = execute.run_dask(run, values, workers, scheduler, progress)
        where = (
            f"the cluster at {scheduler}"
            if scheduler
            else f"{workers} local worker" + "s" * (workers > 1)
        )
    seconds = progress.seconds()
    progress.close()
    table = table_of(study, values, outcomes)
    files = [study_out / "results.csv", study_out / "report.md"]
    write_csv(table, files[0])
    files[1].write_text(report.report_text(table, study, seconds, where, units), encoding="utf-8")
    if plots:
        files.append(report.plot_study(table, study, study_out / "designs.png", units))
    return SweepResult(study, table, best_designs(table, study), files, seconds)

"""What the harness and the scenes share when they check a recorded co-simulation against
a reference: the communication grid, the progress bar, matching recorded rows to input
samples, the timed co-simulation, and the error of each output relative to its peak."""

from __future__ import annotations

import math
import sys
import time as clock
from dataclasses import dataclass

import numpy as np

from ..fmi.simulate import CoSimSetup, simulate

#: Below this conditioning a sample counts as near-singular and is left out of
#: the error figures (its amplification exceeds 1e6, 1 / conditioning).
NEAR_SINGULAR = 1e-6


@dataclass
class OutputError:
    """The error of one output over the valid samples, relative to its reference's peak."""

    name: str
    unit: str
    peak: float  # largest |reference| over the valid samples
    max_abs: float  # largest |FMU - reference|
    relative: float  # max_abs / peak


def output_error(name: str, unit: str, want: np.ndarray, got: np.ndarray) -> OutputError:
    """The error of one output over the valid samples, relative to the reference's peak."""
    peak = float(np.max(np.abs(want))) if want.size else 0.0
    max_abs = float(np.max(np.abs(got - want))) if want.size else math.nan
    return OutputError(name, unit, peak, max_abs, max_abs / peak if peak > 0 else max_abs)


def rows_of(kin: dict, sample: np.ndarray, t: np.ndarray) -> dict:
    """The kinematics at the recorded rows: every array over the grid picked at `sample`."""
    return {
        k: (v[sample] if isinstance(v, np.ndarray) and v.shape[:1] == t.shape else v)
        for k, v in kin.items()
    }


def communication_grid(duration: float, revolutions: float, steps: int) -> np.ndarray:
    """`steps` communication points per revolution over `revolutions`, from 0 to `duration`."""
    return np.linspace(0.0, duration, int(round(steps * revolutions)) + 1)


class Progress:
    """A one-line progress bar on stderr for runs long enough to need one."""

    def __init__(self, label: str, duration: float, enabled: bool):
        self.label, self.duration = label, duration
        self.enabled = enabled and sys.stderr.isatty()
        self.shown = -1

    def __call__(self, time: float, recorder: object) -> bool:
        """fmpy's step callback: redraws the bar; always goes on."""
        if self.enabled:
            percent = int(100 * time / self.duration) if self.duration > 0 else 100
            if percent != self.shown:
                self.shown = percent
                bar = "#" * (percent // 4)
                sys.stderr.write(f"\r{self.label} [{bar:<25}] {percent:3d} %")
                sys.stderr.flush()
        return True

    def close(self) -> None:
        """Ends the bar's line."""
        if self.enabled and self.shown >= 0:
            sys.stderr.write("\n")


def match_samples(recorded: dict, inputs: dict, names: list[str], t: np.ndarray) -> np.ndarray:
    """The kinematic sample whose input values each recorded row carries.

    fmpy records, after each step, the inputs it applied before the step, so
    rows are matched to samples by value; where values repeat (the first and
    last sample of whole revolutions) the sample nearest in time wins. Every
    row must match exactly.
    """
    table = np.stack([inputs[n] for n in names], axis=1)
    rows = np.stack([recorded[n] for n in names], axis=1)
    scale = np.maximum(np.abs(table).max(axis=0), 1e-300)
    index = np.empty(len(rows), dtype=int)
    for k, row in enumerate(rows):
        distance = np.max(np.abs(table - row) / scale, axis=1)
        candidates = np.flatnonzero(distance <= 1e-12)
        if candidates.size == 0:
            raise RuntimeError(
                f"recorded row {k} matches no input sample "
                f"(closest differs by {distance.min():.2e})"
            )
        index[k] = candidates[np.argmin(np.abs(t[candidates] - recorded["time"][k]))]
    return index


def simulate_matched(
    setup: CoSimSetup, label: str, duration: float, progress: bool
) -> tuple[dict, np.ndarray, float]:
    """Co-simulate `setup` under a progress bar: (recorded variables, the kinematic sample
    of each recorded row, wall seconds of the co-simulation)."""
    bar = Progress(label, duration, progress)
    started = clock.perf_counter()
    fmu = simulate(setup, step_finished=bar)
    seconds = clock.perf_counter() - started
    bar.close()
    sample = match_samples(fmu, setup.inputs, list(setup.inputs), setup.time)
    return fmu, sample, seconds

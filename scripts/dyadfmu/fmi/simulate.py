"""A whole co-simulation of one FMU with fmpy's ``simulate_fmu``: the input signals on the
communication grid in, every input and output recorded after each step out. The same
:class:`CoSimSetup` feeds the second importer (:mod:`dyadfmu.cosim.importers`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu


@dataclass
class CoSimSetup:
    """What one co-simulation feeds an FMU, the same for every importer: the input
    signals on the communication grid, the parameters' start values, what it records."""

    path: Path
    time: np.ndarray  # communication points (s), evenly spaced from 0
    inputs: dict  # input name -> values at `time`
    start_values: dict  # parameter name -> value
    outputs: list  # output names, in model-description order
    units: dict  # variable name -> unit ("" where none)

    @property
    def step(self) -> float:
        """The communication step (s)."""
        return float(self.time[1] - self.time[0])

    @property
    def stop(self) -> float:
        """The last communication point (s)."""
        return float(self.time[-1])

    def signals(self) -> np.ndarray:
        """Time and every input as a structured array, the form fmpy's simulate_fmu takes."""
        rows = np.zeros(len(self.time), dtype=[("time", float)] + [(n, float) for n in self.inputs])
        rows["time"] = self.time
        for n, values in self.inputs.items():
            rows[n] = values
        return rows


def setup_for(
    path: Path, time: np.ndarray, inputs: dict, start_values: dict | None = None
) -> CoSimSetup:
    """The setup of an FMU file: its outputs and units from the model description."""
    md = read_model_description(str(path))
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    units = {v.name: v.unit or "" for v in md.modelVariables}
    return CoSimSetup(path, time, inputs, dict(start_values or {}), outputs, units)


def simulate(setup: CoSimSetup, step_finished: Callable | None = None) -> dict:
    """Co-simulate with fmpy over the setup's grid; every input and output recorded after
    each step (name -> array, with "time")."""
    recorded = simulate_fmu(
        str(setup.path),
        start_time=0.0,
        stop_time=setup.stop,
        step_size=setup.step,
        output_interval=setup.step,
        input=setup.signals(),
        output=list(setup.inputs) + setup.outputs,
        start_values=dict(setup.start_values),
        step_finished=step_finished,
    )
    return {n: np.asarray(recorded[n]) for n in recorded.dtype.names}

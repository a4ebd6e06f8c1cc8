"""Co-simulation of a mechanism's dyad FMU with fmpy, checked output by output
against the independent Newton-Euler reference.

A scene is one of the mechanisms of :mod:`dyadfmu.mechanisms`: its kinematics
and loads become the FMU's input signals, fmpy's ``simulate_fmu`` steps the FMU
over the run, and the reference solves the same recorded inputs with
``numpy.linalg.solve``.
"""

from __future__ import annotations

import csv
import math
import os
import sys
import time as clock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu

from . import crank, mechanisms, reference

ROOT = Path(__file__).resolve().parents[2]

#: FMU output name -> (reference key, component or None).
OUTPUTS = {"R_mk.x": ("r_mk", 0), "R_mk.y": ("r_mk", 1), "R_np.x": ("r_np", 0),
           "R_np.y": ("r_np", 1), "R_mn.x": ("r_mn", 0), "R_mn.y": ("r_mn", 1),
           "N_mk": ("n_mk", None), "N_np": ("n_np", None), "N_mn": ("n_mn", None),
           "M_mk": ("m_mk", None), "M_np": ("m_np", None), "M_mn": ("m_mn", None)}

#: Below this conditioning a sample counts as near-singular and is left out of
#: the error figures (its amplification exceeds 1e6).
NEAR_SINGULAR = 1e-6


def build_dir() -> Path:
    return Path(os.environ.get("DYADFMU_BUILD", ROOT / "build"))


def fmu_path(dyad: str, version: int, build: Path | None = None) -> Path:
    path = (build or build_dir()) / "fmus" / f"dyad_{dyad.lower()}_fmi{version}.fmu"
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist: build the FMUs first "
                                "(scripts/run-main does, or cmake --build build)")
    return path


def links_from_values(values, dyad: str):
    """The reference's inputs from FMU variable values (inputs and parameters).

    `values` maps FMU variable names to arrays (or scalars); returns
    (m, n, guide_k, guide_p, gravity) for :func:`reference.solve`.
    """
    def get(name):
        return np.asarray(values[name], dtype=float) if name in values else 0.0

    def vec(x, y):
        x, y = np.broadcast_arrays(get(x), get(y))
        return np.stack([x, y], axis=-1)

    def direction(name):
        angle = get(name)
        return np.stack([np.cos(angle), np.sin(angle)], axis=-1)

    def link(g):
        return dict(dir=direction(f"link_{g}.angle"), length=get(f"link_{g}.length"),
                    omega=get(f"link_{g}.omega"), epsilon=get(f"link_{g}.epsilon"),
                    accel_d=vec(f"link_{g}.accel_d.x", f"link_{g}.accel_d.y"),
                    com=vec(f"link_{g}.com.x", f"link_{g}.com.y"),
                    mass=get(f"link_{g}.mass"), inertia=get(f"link_{g}.inertia"),
                    force=vec(f"link_{g}.force.x", f"link_{g}.force.y"),
                    moment=get(f"link_{g}.moment"))

    pairs = reference.PAIRS[dyad]
    guide_k = direction("guide_k.angle") if pairs[0] == "T" else None
    guide_p = direction("guide_p.angle") if pairs[2] == "T" else None
    return link("m"), link("n"), guide_k, guide_p, vec("gravity.x", "gravity.y")


def reference_outputs(ref: dict, names) -> dict:
    """The reference's solution under the FMU's output names."""
    out = {}
    for name in names:
        if name in OUTPUTS:
            key, component = OUTPUTS[name]
            out[name] = ref[key][:, component] if component is not None else ref[key]
    return out


@dataclass
class OutputError:
    name: str
    unit: str
    peak: float        # largest |reference| over the valid samples
    max_abs: float     # largest |FMU - reference|
    relative: float    # max_abs / peak


@dataclass
class SceneResult:
    mechanism: mechanisms.Mechanism
    fmi_version: int
    kin: dict                       # kinematics on the sample grid
    sample: np.ndarray              # kinematic sample index of each recorded row
    fmu: dict                       # recorded FMU variables, name -> array
    ref: dict                       # reference under FMU output names
    valid: np.ndarray               # rows away from singular positions
    errors: list[OutputError]
    crank: dict                     # driving torque and pivot reaction, from the FMU
    seconds_fmu: float
    seconds_reference: float
    steps: int
    extra: dict = field(default_factory=dict)

    @property
    def worst_relative(self) -> float:
        return max(e.relative for e in self.errors)


class _Progress:
    """A one-line progress bar on stderr for runs long enough to need one."""

    def __init__(self, label: str, duration: float, enabled: bool):
        self.label, self.duration = label, duration
        self.enabled = enabled and sys.stderr.isatty()
        self.shown = -1

    def __call__(self, time, recorder):
        if self.enabled:
            percent = int(100 * time / self.duration) if self.duration > 0 else 100
            if percent != self.shown:
                self.shown = percent
                bar = "#" * (percent // 4)
                sys.stderr.write(f"\r{self.label} [{bar:<25}] {percent:3d} %")
                sys.stderr.flush()
        return True

    def close(self):
        if self.enabled and self.shown >= 0:
            sys.stderr.write("\n")


def _match_samples(recorded: dict, inputs: dict, names, t: np.ndarray) -> np.ndarray:
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
            raise RuntimeError(f"recorded row {k} matches no input sample "
                               f"(closest differs by {distance.min():.2e})")
        index[k] = candidates[np.argmin(np.abs(t[candidates] - recorded["time"][k]))]
    return index


@dataclass
class CoSimSetup:
    """What one co-simulation feeds an FMU, the same for every importer: the input
    signals on the communication grid, the parameters' start values, what it records."""
    path: Path
    time: np.ndarray                # communication points (s), evenly spaced from 0
    inputs: dict                    # input name -> values at `time`
    start_values: dict              # parameter name -> value
    outputs: list                   # output names, in model-description order
    units: dict                     # variable name -> unit ("" where none)

    @property
    def step(self) -> float:
        return float(self.time[1] - self.time[0])

    @property
    def stop(self) -> float:
        return float(self.time[-1])

    def signals(self) -> np.ndarray:
        """Time and every input as a structured array, the form fmpy's simulate_fmu takes."""
        rows = np.zeros(len(self.time), dtype=[("time", float)] + [(n, float) for n in self.inputs])
        rows["time"] = self.time
        for n, values in self.inputs.items():
            rows[n] = values
        return rows


def communication_grid(duration: float, revolutions: float, steps: int) -> np.ndarray:
    """`steps` communication points per revolution over `revolutions`, from 0 to `duration`."""
    return np.linspace(0.0, duration, int(round(steps * revolutions)) + 1)


def setup_for(path: Path, time: np.ndarray, inputs: dict, start_values: dict | None = None
              ) -> CoSimSetup:
    md = read_model_description(str(path))
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    units = {v.name: v.unit or "" for v in md.modelVariables}
    return CoSimSetup(path, time, inputs, dict(start_values or {}), outputs, units)


def simulate(setup: CoSimSetup, step_finished=None) -> dict:
    """Co-simulate with fmpy over the setup's grid; every input and output recorded after
    each step (name -> array, with "time")."""
    recorded = simulate_fmu(str(setup.path), start_time=0.0, stop_time=setup.stop,
                            step_size=setup.step, output_interval=setup.step,
                            input=setup.signals(), output=list(setup.inputs) + setup.outputs,
                            start_values=dict(setup.start_values), step_finished=step_finished)
    return {n: np.asarray(recorded[n]) for n in recorded.dtype.names}


def scene_setup(name: str, fmi_version: int = 2, revolutions: float = 2.0, steps: int = 360,
                motion: str = "constant", build: Path | None = None):
    """The co-simulation of one mechanism's dyad FMU: (setup, mechanism, crank motion,
    kinematics on the grid)."""
    mech = mechanisms.load(name)
    crank_motion = mech.motion(motion, revolutions)
    t = communication_grid(crank_motion.duration, revolutions, steps)
    kin = mech.kinematics(t, crank_motion)
    setup = setup_for(fmu_path(mech.dyad, fmi_version, build), t, mech.fmu_inputs(kin),
                      mech.fmu_parameters())
    return setup, mech, crank_motion, kin


def run_scene(name: str, fmi_version: int = 2, revolutions: float = 2.0,
              steps: int = 360, motion: str = "constant", build: Path | None = None,
              progress: bool = False) -> SceneResult:
    """Co-simulate one mechanism's dyad FMU and compare it with the reference.

    steps: communication steps per crank revolution (or oscillation).
    """
    setup, mech, crank_motion, kin = scene_setup(name, fmi_version, revolutions, steps, motion,
                                                 build)
    t, inputs, params = setup.time, setup.inputs, setup.start_values
    outputs, units, names = setup.outputs, setup.units, list(setup.inputs)

    bar = _Progress(f"{name} FMI {fmi_version}", crank_motion.duration, progress)
    started = clock.perf_counter()
    fmu = simulate(setup, step_finished=bar)
    seconds_fmu = clock.perf_counter() - started
    bar.close()
    sample = _match_samples(fmu, inputs, names, t)

    started = clock.perf_counter()
    values = dict(params)
    values.update({n: fmu[n] for n in names})
    ref_raw = reference.solve(mech.dyad, *links_from_values(values, mech.dyad))
    seconds_reference = clock.perf_counter() - started
    ref = reference_outputs(ref_raw, outputs)

    valid = (fmu["status"] == 0) & (fmu["conditioning"] >= NEAR_SINGULAR)
    errors = []
    for out in outputs:
        if out not in ref:
            continue
        want, got = ref[out][valid], fmu[out][valid]
        peak = float(np.max(np.abs(want))) if want.size else 0.0
        max_abs = float(np.max(np.abs(got - want))) if want.size else math.nan
        errors.append(OutputError(out, units.get(out, ""), peak, max_abs,
                                  max_abs / peak if peak > 0 else max_abs))

    r_np = np.stack([fmu["R_np.x"], fmu["R_np.y"]], axis=-1)
    m_np = fmu.get("M_np")
    rows_kin = {k: (v[sample] if isinstance(v, np.ndarray) and v.shape[:1] == t.shape else v)
                for k, v in kin.items()}
    balance = crank.balance(mech, rows_kin, r_np, m_np)
    return SceneResult(mech, fmi_version, kin, sample, fmu, ref, valid, errors, balance,
                       seconds_fmu, seconds_reference, len(t) - 1,
                       extra={"rows_kin": rows_kin, "units": units})


# ---- reports ------------------------------------------------------------------------

def error_table(result: SceneResult) -> list[list[str]]:
    rows = [["output", "unit", "peak |reference|", "max |FMU - reference|", "relative to peak"]]
    for e in result.errors:
        rows.append([e.name, e.unit, f"{e.peak:.6g}", f"{e.max_abs:.3e}", f"{e.relative:.3e}"])
    return rows


def format_text(rows: list[list[str]]) -> str:
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    lines = ["  ".join(cell.rjust(w) if c else cell.ljust(w) for c, (cell, w) in
                       enumerate(zip(row, widths))) for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def format_markdown(rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
    lines += ["| " + " | ".join(r) + " |" for r in rows[1:]]
    return "\n".join(lines)


def summary(result: SceneResult) -> str:
    mech = result.mechanism
    torque = result.crank["torque"][result.valid]
    return (f"{mech.name} ({mech.dyad}), FMI {result.fmi_version}: {result.steps} steps, "
            f"co-simulation {result.seconds_fmu:.3f} s, reference {result.seconds_reference:.4f} s; "
            f"worst relative error {result.worst_relative:.2e}; "
            f"driving torque {torque.min():.4g} .. {torque.max():.4g} N m; "
            f"{int((~result.valid).sum())} near-singular samples left out")


def write_tables(result: SceneResult, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    rows = error_table(result)
    stem = f"{result.mechanism.name}_fmi{result.fmi_version}"
    md = out / f"{stem}_errors.md"
    md.write_text(f"# {summary(result)}\n\n{format_markdown(rows)}\n")
    path_csv = out / f"{stem}_errors.csv"
    with open(path_csv, "w", newline="") as handle:
        csv.writer(handle).writerows(rows)
    return [md, path_csv]

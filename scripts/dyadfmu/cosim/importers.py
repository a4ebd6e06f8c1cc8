"""A second FMI importer, independent of fmpy, over the harness's co-simulations.

``fmi-sim`` (the Rust crate of that name, its own FMI 2 and FMI 3 import layer) runs an
FMU over the same co-simulation setup as :func:`dyadfmu.fmi.simulate.simulate` (the grid, the
input signals, the parameters' start values); its outputs are compared with fmpy's row
by row. ``fmutool -check`` (PyPI ``fmu-manipulation-toolbox``) checks the model
description against the FMI XSD schema and the standard's semantic rules.

Both importers record after each step the outputs of the inputs applied before it, so
row k of each holds the FMU's answer to the inputs at t[k-1] (row 0: at t[0]).
"""

from __future__ import annotations

import csv
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from lxml import etree

from .. import paths
from ..fmi.simulate import CoSimSetup, setup_for, simulate
from ..report import markdown
from . import harness, mechanism_fmus, multidriver_fmus, scenes

DYADS = ("rrr", "rrt", "rtr", "trt", "rtt")
#: The generic dyad FMUs run over the harness mechanism of their type.
MECHANISM_OF = {
    "rrr": "four-bar",
    "rrt": "slider-crank",
    "rtr": "quick-return",
    "trt": "trt-slot",
    "rtt": "scotch-yoke",
}
#: The tailored test FMUs (tests/scenes/tailored_<type>.toml) have the generic dyad's inputs.
TAILORED = tuple(f"tailored_{d}" for d in DYADS)
VERSIONS = (2, 3)
#: The fmi-sim this comparison is made with (scripts/env.sh installs it).
FMI_SIM_VERSION = "0.7.0"


class ImporterError(RuntimeError):
    """An external importer failed; the message carries its command and output."""


# ---------------------------------------------------------------------------
# Finding the tools
# ---------------------------------------------------------------------------
def fmi_sim_executable() -> str | None:
    """fmi-sim: $DYADFMU_FMI_SIM, else on PATH, else where cargo install puts it."""
    explicit = os.environ.get("DYADFMU_FMI_SIM")
    candidates = (
        [explicit]
        if explicit
        else [shutil.which("fmi-sim"), str(Path.home() / ".cargo" / "bin" / "fmi-sim")]
    )
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    return None


def fmutool_executable() -> str | None:
    """fmutool from the venv the harness runs in, else on PATH."""
    beside = Path(sys.executable).parent / "fmutool"
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    return shutil.which("fmutool")


def fmi_sim_version(executable: str) -> str:
    """The version fmi-sim reports (it prints `fmi-sim X.Y.Z` and exits 1 on --version)."""
    done = subprocess.run(
        [executable, "--version"], capture_output=True, text=True, env=_quiet_env()
    )
    found = re.search(r"fmi-sim (\d+\.\d+\.\d+)", done.stdout + done.stderr)
    if not found:
        raise ImporterError(f"{executable} --version printed no version:\n{done.stderr}")
    return found.group(1)


def _quiet_env() -> dict:
    env = dict(os.environ)
    env["RUST_BACKTRACE"] = "0"
    return env


# ---------------------------------------------------------------------------
# The co-simulation setups: the harness's, one per FMU
# ---------------------------------------------------------------------------
def fmu_names() -> list[str]:
    """Every FMU the build makes, without the _fmi<v> suffix."""
    mechanisms = [n for n in mechanism_fmus.MECHANISM_FMUS if n not in scenes.NAMES]
    mechanisms += list(multidriver_fmus.NAMES)
    return (
        [f"dyad_{d}" for d in DYADS]
        + list(scenes.NAMES)
        + mechanisms
        + list(TAILORED)
        + ["drive", "motor"]
        + list(PLANTS)
    )


#: The plants (dynamics = "forward") of modelDescription/scenes/, each with its inputs
#: over time t: (name -> array), their motion integrated inside the FMU.
PLANTS = {
    "slider_crank_forward": lambda t, wave: {
        "crank.torque": 2.0 + 1.5 * wave,
        "piston.force.x": -40.0 + 20.0 * wave,
        "piston.force.y": 0.0 * t,
    },
    "slider_crank_motor": lambda t, wave: {
        "crank.motor.voltage": 290.0 * (1.0 + 0.2 * wave),
        "piston.force.x": -400.0 + 200.0 * wave,
        "piston.force.y": 0.0 * t,
    },
}


def plant_setup(name: str, version: int, build: Path | None = None) -> CoSimSetup:
    """A plant driven by inputs that swing over 0.5 s, at steps of 2^-8 s (a binary
    fraction, as for the drive: both importers pass the same step to doStep)."""
    path = (build or paths.build_dir()) / "fmus" / f"{name}_fmi{version}.fmu"
    t = np.linspace(0.0, 0.5, 129)
    return setup_for(path, t, PLANTS[name](t, np.sin(2 * math.pi * t / 0.125)))


def drive_setup(version: int, build: Path | None = None) -> CoSimSetup:
    """The drive under a load that varies like a mechanism's: the load torque (N m) and
    the inertia the mechanism adds (kg m2) swing about the values of the drive tests, at
    the parameters' start values. The step is a binary fraction (2^-8 s), so that
    t[n+1] - t[n], the step fmpy passes to doStep, is the step exactly, as fmi-sim's FMI 2
    co-simulation passes it: the drive integrates over the step it is given."""
    path = (build or paths.build_dir()) / "fmus" / f"drive_fmi{version}.fmu"
    t = np.linspace(0.0, 0.5, 129)
    phase = 2 * math.pi * t / 0.125
    inputs = {
        "load.torque": -3.0 + 2.0 * np.sin(phase) - 0.5 * np.cos(2 * phase),
        "load.inertia": 1e-3 * (1.0 + 0.4 * np.cos(phase)),
    }
    return setup_for(path, t, inputs)


def motor_setup(version: int, build: Path | None = None) -> CoSimSetup:
    """The motor under a supply and a shaft speed that swing like a run-up's (290 V, up
    to 145 rad/s at the shaft, its gear ratio 1), at the parameters' start values and
    steps of 2^-8 s (as the drive's), inputs held over each."""
    path = (build or paths.build_dir()) / "fmus" / f"motor_fmi{version}.fmu"
    t = np.linspace(0.0, 0.5, 129)
    phase = 2 * math.pi * t / 0.125
    inputs = {
        "motor.voltage": 290.0 * (1.0 + 0.2 * np.sin(phase)),
        "shaft.omega": 145.0 * (1.0 - np.cos(phase / 4)) / 2 + 5.0 * np.sin(3 * phase),
    }
    return setup_for(path, t, inputs)


def setup_of(name: str, version: int, build: Path | None = None, steps: int = 120) -> CoSimSetup:
    """The harness's co-simulation of the FMU `name` (one crank revolution at `steps`
    communication steps): a generic dyad over the mechanism of its type, a tailored scene
    over its scene's kinematics, a tailored test FMU over the generic dyad's mechanism
    with its own baked parameters, a scene with several drivers over one period of its
    drivers' motion, the drive under a varying load, the motor under a varying supply and
    shaft speed."""
    if name == "drive":
        return drive_setup(version, build)
    if name == "motor":
        return motor_setup(version, build)
    if name in PLANTS:
        return plant_setup(name, version, build)
    if name.startswith("dyad_"):
        return harness.mechanism_setup(
            MECHANISM_OF[name.removeprefix("dyad_")], version, 1.0, steps, build=build
        )[0]
    if name in TAILORED:
        generic = harness.mechanism_setup(
            MECHANISM_OF[name.removeprefix("tailored_")], version, 1.0, steps, build=build
        )[0]
        path = (build or paths.build_dir()) / "fmus" / f"{name}_fmi{version}.fmu"
        return setup_for(path, generic.time, generic.inputs)
    if name in multidriver_fmus.NAMES:
        return multidriver_fmus.setup(name, version, 1.0, steps, build)
    if name not in scenes.NAMES:  # a mechanism FMU of a built-in mechanism or a chain
        return mechanism_fmus.setup(name, version, revolutions=1.0, steps=steps, build=build)[0]
    return scenes.setup(name, version, 1.0, steps, build=build)[0]


# ---------------------------------------------------------------------------
# fmi-sim
# ---------------------------------------------------------------------------
def readable_copy(fmu: Path, dest: Path) -> Path:
    """A copy of the FMU that fmi-sim 0.7.0 reads. Its FMI 3 parser (fmi-schema 0.8)
    refuses the `unit` and `displayUnit` attributes on <Float64>, which the FMI 3 schema
    allows and our model descriptions carry; the copy goes without those attributes (a
    unit changes nothing an importer computes), and without the unit definitions where
    they have the ampere (a motor's). An FMI 2 FMU is copied unchanged."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as out:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = _without_float64_units(data)
            out.writestr(item, data)
    return dest


def _without_float64_units(xml: bytes) -> bytes:
    root = etree.fromstring(xml)
    if not root.get("fmiVersion", "").startswith("3."):
        return xml
    for variable in root.iter("Float64"):
        variable.attrib.pop("unit", None)
        variable.attrib.pop("displayUnit", None)
    # nor does it know the ampere among the base units (a motor's units): a model with a
    # motor goes without its unit definitions
    for definitions in list(root.iter("UnitDefinitions")):
        if any(base.get("A") for base in definitions.iter("BaseUnit")):
            definitions.getparent().remove(definitions)
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8")


def write_inputs(setup: CoSimSetup, path: Path, perturb: str | None = None) -> None:
    """The setup's input signals as fmi-sim's input CSV: a `time` column, then one column
    per input, each double written with 17 significant digits so that it reads back
    exactly. `perturb` (a test of the comparison) scales one input column by 1 + 1e-9."""
    names = list(setup.inputs)
    columns = [np.asarray(setup.time, dtype=float)]
    for n in names:
        values = np.asarray(setup.inputs[n], dtype=float)
        columns.append(values * (1 + 1e-9) if n == perturb else values)
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["time"] + names)
        for row in zip(*columns, strict=False):
            writer.writerow([format(float(x), ".16e") for x in row])


def fmi_sim_stop(setup: CoSimSetup) -> float:
    """The stop time for fmi-sim: it steps while t = n * step < stop, exactly, where fmpy
    stops within round-off of its stop time; the grid's last point (linspace's endpoint)
    can lie an ulp above n * step, which would cost fmi-sim one more step."""
    return (len(setup.time) - 1) * setup.step


def as_applied_by_fmi_sim(setup: CoSimSetup) -> CoSimSetup:
    """The setup with the input values fmi-sim 0.7.0 applies, bit for bit.

    FMI 3: it applies at each communication point t_k the right-hand value,
    v_k + 0 * (v_k+1 - v_k) = v_k, the harness's value itself.
    FMI 2: it interpolates from the left, t_k lying at the end of [t_k-1, t_k] with the
    fraction exactly 1: v_k-1 + 1 * (v_k - v_k-1), which rounds to within an ulp of the
    larger of |v_k-1|, |v_k| but not always to v_k. fmpy applies v_k (weights 0 and 1).
    """
    k = np.arange(len(setup.time))
    if not np.array_equal(setup.time[:-1], k[:-1] * setup.step):
        raise ValueError(
            f"{setup.path.name}: the grid is not n * step, so fmi-sim's "
            "communication points fall between its samples"
        )
    if _fmi_version(setup.path) == 3:
        return setup
    applied = {}
    for name, values in setup.inputs.items():
        v = np.asarray(values, dtype=float)
        u = v.copy()
        u[1:] = v[:-1] + 1.0 * (v[1:] - v[:-1])
        applied[name] = u
    return replace(setup, inputs=applied)


def _fmi_version(fmu: Path) -> int:
    with zipfile.ZipFile(fmu) as archive:
        root = etree.fromstring(archive.read("modelDescription.xml"))
    return int(root.get("fmiVersion").split(".")[0])


def fmi_sim(
    executable: str,
    model: Path,
    output: Path,
    stop: float,
    step: float,
    inputs: Path | None = None,
    start_values: dict | None = None,
) -> subprocess.CompletedProcess:
    """One fmi-sim co-simulation from 0 to `stop` with communication step `step` (it takes
    the step from --output-interval; --step it ignores), outputs written to `output`."""
    command = [executable, "--model", str(model), "-o", str(output)]
    if inputs is not None:
        command += ["-i", str(inputs)]
    command += [
        "co-simulation",
        "-s",
        "0",
        "-f",
        repr(float(stop)),
        "--output-interval",
        repr(float(step)),
    ]
    for name, value in (start_values or {}).items():
        command += ["--init-values", f"{name}={float(value)!r}"]
    done = subprocess.run(command, capture_output=True, text=True, env=_quiet_env())
    done.args = command
    return done


def run_fmi_sim(
    setup: CoSimSetup, workdir: Path, executable: str, perturb: str | None = None
) -> dict:
    """Run fmi-sim's co-simulation over the setup; returns output name -> array, with
    "time" (fmi-sim 0.7.0 records outputs only: it accepts --print-all and ignores it)."""
    workdir.mkdir(parents=True, exist_ok=True)
    stem = setup.path.stem
    model = readable_copy(setup.path, workdir / f"{stem}.fmu")
    inputs, outputs = workdir / f"{stem}_in.csv", workdir / f"{stem}_out.csv"
    write_inputs(setup, inputs, perturb)
    done = fmi_sim(
        executable, model, outputs, fmi_sim_stop(setup), setup.step, inputs, setup.start_values
    )
    if done.returncode != 0 or not outputs.is_file():
        raise ImporterError(
            f"fmi-sim failed ({done.returncode}) on {setup.path.name}: "
            f"{' '.join(done.args)}\n{done.stderr.strip()}"
        )
    return read_csv(outputs)


def read_csv(path: Path) -> dict:
    """The columns of a CSV file of fmi-sim by header name, as float arrays."""
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    header, body = rows[0], rows[1:]
    return {name: np.array([float(r[k]) for r in body]) for k, name in enumerate(header)}


# ---------------------------------------------------------------------------
# The comparison
# ---------------------------------------------------------------------------
@dataclass
class Difference:
    """fmi-sim against fmpy over one FMU's co-simulation, over every output and row."""

    fmu: str
    rows: int
    outputs: int
    max_abs: float  # largest |fmi-sim - fmpy|
    max_relative: float  # largest |fmi-sim - fmpy| / peak |fmpy| of that output
    max_ulps: float  # largest distance in units in the last place
    worst: str  # the output with the largest relative difference
    #: largest |fmi-sim - fmpy| / (eps a^2) over the amplification outputs a: an
    #: amplification divides by the outputs it measures, so it is itself known only to
    #: about eps x a relative, and a one-ulp change of an input moves it by that much.
    amplification_in_own_roundoff: float = 0.0

    def line(self) -> str:
        """The difference as one line of text."""
        return (
            f"{self.fmu}: {self.rows} rows x {self.outputs} outputs, max abs "
            f"{self.max_abs:.2e}, max relative to peak {self.max_relative:.2e}, "
            f"{self.max_ulps:.0f} ulps ({self.worst})"
        )


def ulps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance between doubles in units in the last place: 0 where equal (+0 and -0
    too, NaN and NaN too), inf for NaN against a number."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)

    def ordered(x: np.ndarray):  # the doubles' bit patterns as integers in the doubles' order
        bits = x.view(np.int64).astype(object)
        return [(-(1 << 63) - v) if v < 0 else v for v in bits]

    distance = np.array([float(abs(p - q)) for p, q in zip(ordered(a), ordered(b), strict=False)])
    distance[np.isnan(a) & np.isnan(b)] = 0.0
    distance[np.isnan(a) ^ np.isnan(b)] = math.inf
    return distance


def compare(setup: CoSimSetup, fmpy_run: dict, fmi_sim_run: dict) -> Difference:
    """Row by row over the same communication points, every output of the setup."""
    name = setup.path.stem
    if len(fmpy_run["time"]) != len(fmi_sim_run["time"]):
        raise AssertionError(
            f"{name}: fmpy recorded {len(fmpy_run['time'])} rows, fmi-sim "
            f"{len(fmi_sim_run['time'])}"
        )
    if not np.array_equal(fmpy_run["time"], fmi_sim_run["time"]):
        raise AssertionError(f"{name}: the communication points differ")
    missing = [n for n in setup.outputs if n not in fmi_sim_run]
    if missing:
        raise AssertionError(f"{name}: fmi-sim printed no {missing}")
    max_abs = max_rel = max_ulp = max_amp = 0.0
    worst = setup.outputs[0]
    for out in setup.outputs:
        want = np.asarray(fmpy_run[out], dtype=float)
        got = np.asarray(fmi_sim_run[out], dtype=float)
        distance = ulps(got, want)
        diff = np.where(distance == 0, 0.0, np.abs(got - want))
        diff[np.isinf(distance)] = math.inf
        max_ulp = max(max_ulp, float(np.max(distance)))
        if is_amplification(out):
            with np.errstate(invalid="ignore", divide="ignore"):
                own = np.where(diff == 0, 0.0, diff / (EPS * want * want))
            max_amp = max(max_amp, float(np.max(own)))
            continue
        peak = float(np.max(np.abs(want[np.isfinite(want)]), initial=0.0))
        biggest = float(np.max(diff))
        rel = biggest / peak if peak > 0 else (0.0 if biggest == 0 else math.inf)
        if rel > max_rel:
            max_rel, worst = rel, out
        max_abs = max(max_abs, biggest)
    return Difference(
        name, len(fmpy_run["time"]), len(setup.outputs), max_abs, max_rel, max_ulp, worst, max_amp
    )


EPS = float(np.finfo(np.float64).eps)


def is_amplification(output: str) -> bool:
    """The amplification outputs: `amplification` of a dyad FMU, `<DYAD>.amplification`
    of a scene."""
    return output == "amplification" or output.endswith(".amplification")


def fmutool_check(fmu: Path, executable: str) -> subprocess.CompletedProcess:
    """fmutool -check on one FMU: exit 0 when the model description validates against the
    FMI XSD schema of its version and breaks none of the standard's semantic rules."""
    return subprocess.run(
        [executable, "-input", str(fmu), "-check"], capture_output=True, text=True
    )


# ---------------------------------------------------------------------------
# The table of the README: python -m dyadfmu.cosim.importers
# ---------------------------------------------------------------------------
#: The table's header.
TABLE_HEADER = (
    "FMU",
    "FMI",
    "rows x outputs",
    "max abs",
    "max relative to peak",
    "amplification / (eps a^2)",
    "same inputs",
)


def table_lines(runs: list[tuple[str, int, Difference, Difference]]) -> list[str]:
    """The Markdown table of (FMU name, FMI version, the difference over the harness's
    signals, the difference with the same input values applied)."""
    rows = [
        [
            name,
            str(version),
            f"{raw.rows} x {raw.outputs}",
            f"{raw.max_abs:.1e}",
            f"{raw.max_relative:.1e}",
            f"{raw.amplification_in_own_roundoff:.2g}",
            "bit-identical" if exact.max_ulps == 0 else f"{exact.max_ulps:.0f} ulps",
        ]
        for name, version, raw, exact in runs
    ]
    return markdown.table(TABLE_HEADER, rows)


def table(workdir: Path, executable: str) -> list[str]:
    """fmi-sim against fmpy for every FMU the build makes, as the lines of a Markdown
    table: over the harness's signals, and with the same input values applied."""
    runs = []
    for name in fmu_names():
        for version in VERSIONS:
            setup = setup_of(name, version)
            other = run_fmi_sim(setup, workdir, executable)
            raw = compare(setup, simulate(setup), other)
            same = as_applied_by_fmi_sim(setup)
            runs.append((name, version, raw, compare(same, simulate(same), other)))
    return table_lines(runs)


def main(argv: list[str] | None = None) -> int:
    """Print the table of every FMU through fmi-sim against fmpy and fmutool -check."""
    import argparse
    import tempfile

    parser = argparse.ArgumentParser(
        prog="python -m dyadfmu.cosim.importers",
        description="fmi-sim against fmpy over the harness's co-simulation of every FMU of "
        "the build (DYADFMU_BUILD, default build/): a Markdown table",
    )
    parser.parse_args(argv)
    executable = fmi_sim_executable()
    if executable is None:
        parser.error("fmi-sim is not installed (scripts/run-tests installs it)")
    print(f"fmi-sim {fmi_sim_version(executable)} ({executable})")
    with tempfile.TemporaryDirectory() as workdir:
        print("\n".join(table(Path(workdir), executable)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

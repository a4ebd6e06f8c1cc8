"""The FMU of a scene with several drivers (one of :data:`.multidriver.NAMES`) evaluated at random
points of its working ranges and compared output by output with the NumPy reference of
:mod:`dyadfmu.mechanisms.multidriver`.

At each point the FMU gets every driver's coordinate, rate and acceleration and the
[[load]] inputs, takes one step and is read. An output's error is max |FMU - reference|
over the points; a kinematic one (:func:`.mechanism_fmus.is_kinematic`, angles wrapped)
is measured against its own peak, any other against the largest peak of the outputs of
its unit (N, N.m, kg, kg.m, kg.m2, ...), the accuracy contract of the mechanism FMUs.

:func:`setup` gives the co-simulation of such an FMU along chains.toml's motion of every
driver at once (the importers' and the Windows binaries' comparisons run it).

Example::

    result = compare("leg", 2)
    print(summary(result)); assert not result.missing
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.simulate import CoSimSetup, setup_for
from ..fmi.slave import Slave
from ..mechanisms import multidriver
from .compare import communication_grid
from .mechanism_fmus import is_kinematic

__all__ = [
    "NAMES",
    "Comparison",
    "compare",
    "evaluate",
    "fmu_path",
    "setup",
    "summary",
    "working_inputs",
]

#: The scenes with several drivers whose FMUs the build makes and the reference knows.
NAMES = multidriver.NAMES


@dataclass
class Comparison:
    """``errors``: output -> its error (see the module's docstring); ``missing``: the
    reference's outputs the FMU lacks; ``unchecked``: the FMU's Real outputs the
    reference has no value for; ``fmu``, ``reference``: the values compared."""

    name: str
    version: int
    points: int
    errors: dict
    missing: list
    unchecked: list
    fmu: dict
    reference: dict

    @property
    def worst(self) -> tuple[str, float]:
        """The output with the largest error, and that error (none: ("-", 0))."""
        if not self.errors:
            return "-", 0.0
        name = max(self.errors, key=self.errors.get)
        return name, self.errors[name]


def fmu_path(name: str, version: int, build: Path | None = None) -> Path | None:
    """The built FMU of scene ``name`` (:func:`dyadfmu.paths.built_fmu`: ``build``,
    $DYADFMU_BUILD or the checkout's build/), or None where it is not built."""
    try:
        return paths.built_fmu(name, version, build, how="scripts/run-tests")
    except FileNotFoundError:
        return None


def _inputs_of(chain: multidriver.MultiChain, kin: dict) -> dict:
    """The FMU's inputs at kin: every driver's coordinate, rate and acceleration, and the
    [[load]] inputs."""
    inputs = {n: np.real(kin[n]) for d in chain.drivers for n in d.coordinates}
    inputs.update({n: np.real(kin[n]) for n in chain.load_inputs()})
    return inputs


def _checked(path: Path, inputs: dict, wanted: set) -> None:
    """ValueError unless the reference gives exactly the FMU's inputs (one left at its
    start value would go untested)."""
    if set(inputs) != wanted:
        raise ValueError(
            f"{path.name}: the reference gives {sorted(set(inputs) - wanted)}, no inputs of "
            f"the FMU, and nothing for its inputs {sorted(wanted - set(inputs))}"
        )


def working_inputs(name: str, count: int, seed: int = 0) -> dict:
    """The FMU's inputs (name -> (count,)) at ``count`` random points of the working
    ranges of scene ``name`` (:meth:`.multidriver.MultiChain.working_points`)."""
    chain = multidriver.load(name)
    return _inputs_of(chain, chain.working_points(count, seed))


def setup(
    name: str,
    version: int = 2,
    revolutions: float = 1.0,
    steps: int = 120,
    build: Path | None = None,
) -> CoSimSetup:
    """The co-simulation of the FMU of scene ``name`` along chains.toml's motion of every
    driver at once (:meth:`.multidriver.MultiChain.motion`): ``revolutions`` periods of
    the loads' swing at ``steps`` communication steps each; each driver's coordinate,
    rate and acceleration and the [[load]] inputs at the grid's times."""
    chain = multidriver.load(name)
    motion = chain.motion("varying", revolutions)
    t = communication_grid(motion.duration, revolutions, steps)
    inputs = _inputs_of(chain, chain.kinematics(t, motion))
    path = paths.built_fmu(name, version, build, how="scripts/run-tests")
    variables = read_model_description(str(path)).modelVariables
    _checked(path, inputs, {v.name for v in variables if v.causality == "input"})
    return setup_for(path, t, inputs)


def evaluate(path: Path, inputs: dict, outputs: list) -> dict:
    """The FMU's ``outputs`` at each point of ``inputs`` (name -> (N,)), one step each."""
    slave = Slave(path, instance_name=path.stem)
    try:
        slave.initialize()
        names = tuple(inputs)
        count = len(next(iter(inputs.values())))
        got = {o: np.empty(count) for o in outputs}
        for k in range(count):
            slave.set(names, [float(inputs[n][k]) for n in names])
            slave.do_step(1e-3 * k, 1e-3)
            for o, v in zip(outputs, slave.get(tuple(outputs)), strict=True):
                got[o][k] = v
        return got
    finally:
        slave.close()


def _error(output: str, got: np.ndarray, want: np.ndarray) -> float:
    diff = got - want
    if output.endswith(".angle"):
        diff = np.angle(np.exp(1j * diff))
    return float(np.max(np.abs(diff)))


def compare(
    name: str,
    version: int = 2,
    count: int = 40,
    seed: int = 0,
    path: Path | None = None,
    build: Path | None = None,
) -> Comparison:
    """The FMU of scene ``name`` (``path``, else the built one) at ``count`` random
    working points against the reference (see the module's docstring)."""
    path = path or paths.built_fmu(name, version, build, how="scripts/run-tests")
    chain = multidriver.load(name)
    kin = chain.working_points(count, seed)
    want = chain.fmu_outputs(kin)
    inputs = _inputs_of(chain, kin)
    variables = Slave(path, instance_name="listing")
    md = variables.md
    variables.close()
    reals = {
        v.name: v.unit or ""
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    }
    _checked(path, inputs, {v.name for v in md.modelVariables if v.causality == "input"})
    compared = [o for o in want if o in reals]
    got = evaluate(path, inputs, compared)
    peaks: dict = {}
    for o in compared:
        if not is_kinematic(o):
            peaks[reals[o]] = max(peaks.get(reals[o], 0.0), float(np.max(np.abs(want[o]))))
    errors = {}
    for o in compared:
        own = float(np.max(np.abs(want[o])))
        peak = own if is_kinematic(o) else peaks[reals[o]]
        errors[o] = _error(o, got[o], want[o]) / (peak or 1.0)
    return Comparison(
        name,
        version,
        count,
        errors,
        sorted(set(want) - set(reals)),
        sorted(set(reals) - set(want)),
        got,
        {o: want[o] for o in compared},
    )


def summary(result: Comparison) -> str:
    """One line: what was compared and the worst error."""
    worst, error = result.worst
    return (
        f"{result.name} FMI {result.version}: {len(result.errors)} outputs at "
        f"{result.points} working points, worst {error:.1e} ({worst})"
        + (f"; missing in the FMU: {', '.join(result.missing)}" if result.missing else "")
        + (f"; not compared: {', '.join(result.unchecked)}" if result.unchecked else "")
    )

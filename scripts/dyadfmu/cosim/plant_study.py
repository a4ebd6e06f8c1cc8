"""The machine with its motor inside the plant, against the same machine as one ODE.

Each machine of :data:`MACHINES` (the slider-crank, the four-bar, the shaper, the leg: a
plant with its DC motor inside, supply voltage in) runs up from rest under a constant voltage, at
communication steps from 0.1 s down to 10 us and (the slider-crank) at relative
tolerances from 1e-6 down to 1e-11. Its crank angle and speed at every communication
point are compared with the machine as one ODE, from the harness's own kinematics
(:mod:`dyadfmu.mechanisms.driven`: the effective inertia J(phi), its derivative and the
weights' generalised force Q_g(phi)) and the motor's circuit:

    phi' = omega,
    (J(phi) + r^2 J_r) omega' = r (k i - c r omega) + Q_g(phi) - J'(phi) omega^2 / 2,
    L i' = V - R i - k r omega,

integrated by SciPy (Radau where the circuit is stiff). J, J' and Q_g enter as their
Fourier series from 128 of the harness's values, each within 2e-15 of the harness
(``_Periodic.fit_error``), so that an evaluation costs tens of microseconds, not
milliseconds. The leg, with two drivers, is the same ODE in both hips' angles
(:mod:`dyadfmu.cosim.chain_reference`: M(q) and h's terms as Chebyshev series); its rear
hip takes no effort, and no drive FMU turns it (no :func:`drive_run`). The drive FMU's
machine (:func:`drive_run`) is the same one with L = 0.
The motor's numbers are the plant's own parameters (read from its model description), so
the two cannot drift apart.

The joint reactions (every ``*.R_*`` output of the plant or the mechanism FMU) are compared
with the harness's Newton-Euler solve along the reference's motion: its angle, speed and
the acceleration its ODE gives, with the harness's load models switched off as the FMUs'
load inputs stay at zero (a load the harness still applies refuses the reference).

API: :data:`MACHINES`, :data:`STEPS`, :data:`RTOLS`, :data:`CIRCUITS`, :func:`reference`
(-> :class:`Reference`), :func:`run`, :func:`split_run`, :func:`drive_run`, :func:`errors`.
"""

from __future__ import annotations

import functools
import math
import time as clock
from dataclasses import dataclass, field, replace

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.slave import Slave
from ..mechanisms import builtin, chains, driven, multidriver
from ..mechanisms.motion import CrankMotion
from ..reference import machine
from . import chain_reference, mechanism_drive, mechanism_fmus

__all__ = [
    "CIRCUITS",
    "MACHINES",
    "RTOLS",
    "STEPS",
    "Circuit",
    "PlantMachine",
    "PlantRun",
    "Reference",
    "drive_line",
    "drive_run",
    "errors",
    "inputs_at_zero",
    "reaction_names",
    "reactions",
    "reference",
    "run",
    "split_run",
    "unloaded",
    "unloaded_chain",
]


@dataclass(frozen=True)
class PlantMachine:
    """A machine of the study: the plant with its motor inside (a), the plant whose crank
    takes a separate motor FMU's rotor (b), the inverse mechanism FMU (c) whose harness
    mechanism is the reference's, the supply voltage [V] and the run's duration [s]; where
    given, ``linear_plant``: the plant with the same motor without inductance (the drive
    FMU's linear characteristic, (a) one to one with (c)).

    A machine with several drivers names its harness ``chain``
    (:mod:`dyadfmu.mechanisms.multidriver`) instead of a ``mechanism``: no drive FMU turns
    more than one crank, so it has no (c). ``driver`` carries the motor, the ``others``
    take no effort; ``start`` holds each driver's angle at rest [rad] (the motor's first),
    ``domain`` the drivers' ranges [rad] over which the reference's series of M and h hold,
    and ``armature`` the slow circuit's L / R [s] where it is not the scene's."""

    name: str
    plant: str
    rotor_plant: str
    mechanism: str
    voltage: float
    t_end: float
    linear_plant: str = ""
    driver: str = "crank"
    others: tuple[str, ...] = ()
    start: tuple[float, ...] = (mechanism_drive.START_ANGLE,)
    chain: str = ""
    domain: tuple[tuple[float, float], ...] = ()
    armature: float | None = None

    @property
    def drivers(self) -> tuple[str, ...]:
        """The motor's driver, then the others."""
        return (self.driver, *self.others)


#: The machines, each run up from rest at its ``start`` (the motors: the plants' [motor]).
MACHINES = {
    m.name: m
    for m in (
        PlantMachine(
            "slider-crank",
            "slider_crank_motor",
            "slider_crank_rotor",
            "slider_crank",
            290.0,
            2.0,
            "slider_crank_linear_motor",
        ),
        PlantMachine(
            "four-bar", "four_bar_motor", "four_bar_forward", "four_bar_payload", 36.0, 0.5
        ),
        PlantMachine("shaper", "shaper_motor", "shaper_forward", "shaper", 7.5, 1.0),
        PlantMachine(
            "leg",
            "leg_motor",
            "leg_forward",
            "",
            1.0,
            0.5,
            driver="front",
            others=("rear",),
            start=(-math.pi / 3, -2 * math.pi / 3),
            chain="leg",
            domain=((-1.2, -0.5), (-2.2, -0.7)),
            armature=1.4e-3,
        ),
    )
}
SLIDER_CRANK = MACHINES["slider-crank"]
#: Communication steps [s] and relative tolerances of the study.
STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5)
RTOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)
#: The armature circuits compared: L / R of the scene's motor, and a stiff one.
#: (The drive FMU's motor is the same one without inductance: LINEAR.)
CIRCUITS = {"L/R 1.4 ms": None, "L/R 1 us": 1e-6}
LINEAR = "L = 0"
#: Angles at which the harness's J, J' and Q_g are sampled for their Fourier series.
SAMPLES = 128
_MOTOR_KEYS = ("resistance", "inductance", "torque_constant", "rotor_inertia", "friction", "ratio")


@dataclass(frozen=True)
class Circuit:
    """The motor's numbers (SI units), as the plant's parameters ``crank.motor.*``."""

    resistance: float
    inductance: float
    torque_constant: float
    rotor_inertia: float
    friction: float
    ratio: float

    def parameters(self, driver: str = "crank") -> dict[str, float]:
        """The plant's parameters for this motor at ``driver``."""
        return {f"{driver}.motor.{k}": getattr(self, k) for k in _MOTOR_KEYS}


def circuit(label: str, version: int = 2, m: PlantMachine = SLIDER_CRANK) -> Circuit:
    """The motor of ``m``'s plant with the time constant of :data:`CIRCUITS` ``label``
    (the slow one: ``m.armature`` where given, else the scene's)."""
    md = read_model_description(str(paths.built_fmu(m.plant, version, how="scripts/run-tests")))
    starts = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
    motor = Circuit(*(starts[f"{m.driver}.motor.{k}"] for k in _MOTOR_KEYS))
    time_constant = 0.0 if label == LINEAR else CIRCUITS[label]
    if time_constant is None:
        time_constant = m.armature
    if time_constant is None:
        return motor
    return replace(motor, inductance=time_constant * motor.resistance)


@dataclass
class PlantRun:
    """The plant's crank angle [rad] and speed [rad/s] at its communication points (one
    column per driver where the machine has several, the motor's first), the CPU time of
    the run [s], and its joint reactions there (output name -> [N] or [N.m])."""

    label: str
    step: float
    rtol: float
    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    cpu_time: float
    reactions: dict[str, np.ndarray] = field(default_factory=dict)


def reaction_names(variables: list) -> tuple[str, ...]:
    """The joint reactions among an FMU's model ``variables``: every ``*.R_*`` output."""
    return tuple(v.name for v in variables if v.causality == "output" and ".R_" in v.name)


def _recorded(names: tuple[str, ...], rows: np.ndarray, start: int) -> dict[str, np.ndarray]:
    """The columns of ``rows`` from ``start`` on, by the names of ``names``."""
    return {name: rows[:, start + k].copy() for k, name in enumerate(names)}


def inputs_at_zero(slave: Slave, keep: str) -> None:
    """Every continuous input of ``slave`` but ``keep`` set to zero: the drivers without
    a motor take no effort and the loads are off, as in the reference."""
    for v in slave.md.modelVariables:
        if v.causality == "input" and v.type in ("Real", "Float64") and v.name != keep:
            slave.set(v.name, 0.0)


def _starts(m: PlantMachine) -> dict[str, float]:
    """The plant's parameters that start ``m``'s drivers at rest at ``m.start``."""
    return {f"{d}.angle_start": q for d, q in zip(m.drivers, m.start, strict=True)}


def _motion_names(m: PlantMachine) -> tuple[str, ...]:
    """The drivers' angles, then their speeds."""
    return (*(f"{d}.angle" for d in m.drivers), *(f"{d}.omega" for d in m.drivers))


def _plant_run(
    label: str,
    step: float,
    rtol: float,
    m: PlantMachine,
    rows: np.ndarray,
    cpu: float,
    names: tuple,
) -> PlantRun:
    """The run of ``rows`` (the drivers' angles and speeds, then the reactions ``names``):
    one column per driver where ``m`` has several."""
    n = len(m.drivers)
    phi, omega = rows[:, :n], rows[:, n : 2 * n]
    if n == 1:
        phi, omega = phi[:, 0], omega[:, 0]
    t = step * np.arange(len(rows))
    return PlantRun(label, step, rtol, t, phi, omega, cpu, _recorded(names, rows, 2 * n))


def run(
    label: str,
    step: float,
    rtol: float | None = None,
    version: int = 2,
    m: PlantMachine = SLIDER_CRANK,
) -> PlantRun:
    """``m``'s plant with motor ``label`` over its run at communication step ``step`` (and
    ``solver.rtol`` = ``solver.atol`` = ``rtol`` where given); motor :data:`LINEAR`: its
    plant without inductance (``m.linear_plant``)."""
    n = mechanism_drive.whole_steps(m.t_end, step)
    parameters = circuit(label, version, m).parameters(m.driver)
    name = m.plant
    if label == LINEAR:
        if not m.linear_plant:
            raise ValueError(f"{m.name} has no plant with a motor without inductance")
        name = m.linear_plant
        del parameters[f"{m.driver}.motor.inductance"]  # no parameter there: no current state
    parameters.update(_starts(m))
    if rtol is not None:
        parameters.update({"solver.rtol": rtol, "solver.atol": rtol})
    plant = Slave(paths.built_fmu(name, version, how="scripts/run-tests"), "plant")
    reactions = reaction_names(plant.md.modelVariables)
    names = (*_motion_names(m), *reactions)
    rows = np.empty((n + 1, len(names)))
    started = clock.process_time()
    try:
        voltage = f"{m.driver}.motor.voltage"
        inputs_at_zero(plant, voltage)
        plant.set(voltage, m.voltage)
        plant.initialize(parameters)
        rows[0] = plant.get(names)
        for k in range(n):
            plant.do_step(k * step, step)
            rows[k + 1] = plant.get(names)
    finally:
        plant.close()
    cpu = clock.process_time() - started
    return _plant_run(label, step, rtol or math.nan, m, rows, cpu, reactions)


class _Periodic:
    """A function of the crank angle with period 2 pi, as its Fourier series from the
    harness's values at :data:`SAMPLES` angles (analytic in the angle for a crank that
    turns round: their coefficients fall below 1e-18 long before the last);
    ``fit_error`` is its largest distance to the harness at 1000 other angles, relative to
    its largest value."""

    def __init__(self, of: object) -> None:
        q = 2 * math.pi * np.arange(SAMPLES) / SAMPLES
        c = np.fft.rfft(of(q)) / SAMPLES
        c[1:] *= 2
        keep = np.nonzero(np.abs(c) > 1e-19 * np.max(np.abs(c)))[0]
        self.k, self.c = keep, c[keep]
        probe = np.random.default_rng(7).uniform(0, 2 * math.pi, 1000)
        truth = of(probe)
        self.fit_error = float(np.max(np.abs(self(probe) - truth)) / np.max(np.abs(truth)))

    def __call__(self, phi: np.ndarray | float) -> np.ndarray:
        return (np.exp(1j * np.multiply.outer(phi, self.k)) @ self.c).real


@functools.cache
def _machine_terms(mechanism: str) -> tuple[_Periodic, _Periodic, _Periodic]:
    """J(phi), J'(phi) and Q_g(phi) of the mechanism FMU ``mechanism``'s harness mechanism."""
    mech = mechanism_fmus.mechanism_of(mechanism)
    return (
        _Periodic(lambda q: driven.effective_inertia(mech, q)[0]),
        _Periodic(lambda q: driven.effective_inertia(mech, q)[1]),
        _Periodic(lambda q: driven.generalized_gravity(mech, q)),
    )


def fit_error(m: PlantMachine = SLIDER_CRANK) -> float:
    """The largest distance of ``m``'s series of J, J' and Q_g (several drivers: of M and
    h's terms) to the harness, relative to each one's largest value."""
    if m.chain:
        return chain_reference.series(unloaded_chain(m.chain), m.domain).fit_error
    return max(term.fit_error for term in _machine_terms(m.mechanism))


def _rhs(motor: Circuit, terms: tuple, voltage: float):
    inertia, slope, weight = terms
    r, k = motor.ratio, motor.torque_constant

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        if motor.inductance > 0:
            current = y[2]
        else:
            current = (voltage - k * r * y[1]) / motor.resistance
        torque = r * (k * current - motor.friction * r * y[1])
        load = torque + weight(y[0]) - 0.5 * slope(y[0]) * y[1] ** 2
        accel = load / (inertia(y[0]) + r * r * motor.rotor_inertia)
        if motor.inductance == 0:
            return np.array([y[1], accel])
        di = (voltage - motor.resistance * current - k * r * y[1]) / motor.inductance
        return np.array([y[1], accel, di])

    return rhs


@dataclass(frozen=True)
class Reference:
    """The machine as one ODE on a time grid ``t`` [s]: crank angle [rad], speed [rad/s],
    acceleration [rad/s2] (one column per driver where it has several, the motor's first)
    and the harness's joint reactions along that motion (output name -> [N] or [N.m], as
    the FMUs name them)."""

    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    reactions: dict[str, np.ndarray]


def reference(
    label: str,
    t: np.ndarray,
    method: str = "Radau",
    rtol: float = 1e-12,
    m: PlantMachine = SLIDER_CRANK,
) -> Reference:
    """``m`` with motor ``label`` as one ODE on the grid t, and its joint reactions."""
    from scipy.integrate import solve_ivp

    motor = circuit(label, m=m)
    if m.chain:
        return _chain_reference(motor, t, method, rtol, m)
    start, scale = [m.start[0], 0.0, 0.0], [1.0, 1.0, m.voltage / motor.resistance]
    n = 3 if motor.inductance > 0 else 2
    rhs = _rhs(motor, _machine_terms(m.mechanism), m.voltage)
    sol = solve_ivp(
        rhs,
        (0.0, float(t[-1])),
        start[:n],
        method=method,
        rtol=rtol,
        atol=rtol * np.array(scale[:n]),
        t_eval=t,
    )
    if not sol.success:
        raise RuntimeError(f"the reference ({method}) failed: {sol.message}")
    phi, omega = sol.y[0], sol.y[1]
    epsilon = np.concatenate([rhs(0.0, y)[1] for y in np.array_split(sol.y, _chunks(t), axis=1)])
    return Reference(t, phi, omega, epsilon, reactions(m, t, phi, omega, epsilon))


def _chain_reference(
    motor: Circuit, t: np.ndarray, method: str, rtol: float, m: PlantMachine
) -> Reference:
    """``m`` (several drivers) as one ODE (:mod:`dyadfmu.cosim.chain_reference`)."""
    fit = chain_reference.series(unloaded_chain(m.chain), m.domain)
    a = fit.chain.driver_names.index(m.driver)
    start = [m.start[m.drivers.index(d)] for d in fit.chain.driver_names]
    run = chain_reference.motion(fit, motor, m.voltage, a, tuple(start), t, method, rtol)
    order = [fit.chain.driver_names.index(d) for d in m.drivers]
    moved = (x[:, order] for x in (run.q, run.dq, run.ddq))
    return Reference(t, *moved, chain_reference.reactions(fit.chain, run))


#: Points of the grid per harness evaluation (the Fourier series and the kinematics hold
#: arrays of a few dozen times as many numbers).
_CHUNK = 20000


def _chunks(t: np.ndarray) -> int:
    return max(1, -(-len(t) // _CHUNK))


#: The keys of a harness load model's table that scale its load (the chains' models and
#: the built-in slider-crank's gas force): all zero, the model loads nothing.
_LOAD_SCALES = ("F0", "T0", "c", "force", "force_swing", "moment", "moment_swing")
_LOAD_SCALES += ("p_peak", "p_base")


def _zeroed(table: dict) -> dict:
    """``table`` with every key of :data:`_LOAD_SCALES` zero, in nested tables too."""
    out = {}
    for key, value in table.items():
        if isinstance(value, dict):
            out[key] = _zeroed(value)
        elif key in _LOAD_SCALES:
            out[key] = [0.0] * len(value) if isinstance(value, list) else 0.0
    return out


@functools.cache
def unloaded(mechanism: str) -> builtin.Mechanism | chains.Chain:
    """The harness mechanism of the mechanism FMU ``mechanism`` with its load models
    switched off (their scales zero)."""
    kind, harness = mechanism_fmus.MECHANISM_FMUS[mechanism]
    tables = (chains if kind == "chain" else builtin).default_data()[harness]
    return mechanism_fmus.mechanism_of(mechanism, data={"load": _zeroed(tables.get("load", {}))})


@functools.cache
def unloaded_chain(name: str) -> multidriver.MultiChain:
    """The harness chain ``name`` (several drivers) with its load models switched off."""
    return multidriver.load(name, {"load": _zeroed(chains.default_data()[name].get("load", {}))})


def reactions(
    m: PlantMachine,
    t: np.ndarray,
    phi: np.ndarray,
    omega: np.ndarray,
    epsilon: np.ndarray,
    mechanism: builtin.Mechanism | chains.Chain | None = None,
) -> dict[str, np.ndarray]:
    """The harness's joint reactions of ``m``'s mechanism (:func:`unloaded`, or
    ``mechanism``) along the crank motion phi, omega, epsilon at the times t. Refuses a
    mechanism whose loads (the scene's load inputs) are not zero where the FMUs' are."""
    mechanism = mechanism or unloaded(m.mechanism)
    scene = mechanism_fmus.scene_file(m.mechanism)
    kw = {"branch": 1} if isinstance(mechanism, builtin.Mechanism) else {}
    parts: dict[str, list[np.ndarray]] = {}
    for ix in np.array_split(np.arange(len(t)), _chunks(t)):
        motion = _given(t, phi, omega, epsilon, ix)
        series = driven.driver_motion_inputs(mechanism, t[ix], motion, scene, **kw)
        for name, values in series.inputs.items():
            if not name.startswith(f"{series.driver}.") and np.any(values != 0):
                raise ValueError(
                    f"{m.mechanism}: the harness applies the load {name} (up to "
                    f"{np.max(np.abs(values)):.3g}), which the FMUs of {m.name} do not have"
                )
        for name, values in series.outputs.items():
            if ".R_" in name:
                parts.setdefault(name, []).append(values)
    return {name: np.concatenate(p) for name, p in parts.items()}


def _given(
    t: np.ndarray, phi: np.ndarray, omega: np.ndarray, epsilon: np.ndarray, ix: np.ndarray
) -> CrankMotion:
    """The crank motion (phi, omega, epsilon)[ix] at the times t[ix], for the harness."""
    return CrankMotion(
        "reference",
        lambda _t: phi[ix],
        lambda _t: omega[ix],
        lambda _t: epsilon[ix],
        float(np.ptp(t[ix])),
        float(np.ptp(phi[ix])) / (2 * math.pi),
    )


def drive_line(motor: Circuit, voltage: float) -> machine.Motor:
    """The drive FMU's motor for ``motor`` at ``voltage`` [V] with L = 0: the torque at
    the crank r (k i - c r omega), i = (V - k r omega) / R, as a line: stall torque
    k r V / R, no-load speed where the line reaches zero, the rotor at the crank."""
    gain = motor.torque_constant * motor.ratio
    stall = gain * voltage / motor.resistance
    slope = gain**2 / motor.resistance + motor.friction * motor.ratio**2
    return machine.Motor(stall, stall / slope, motor.ratio**2 * motor.rotor_inertia)


def drive_run(step: float, version: int = 2, m: PlantMachine = SLIDER_CRANK) -> PlantRun:
    """``m`` as the drive FMU (the motor's linear characteristic, L = 0: stall torque
    k r V / R, falling with the speed at k^2 r^2 / R + c r^2, the friction c's share
    included) and its inverse mechanism FMU, stabilised
    (:mod:`dyadfmu.cosim.mechanism_drive`)."""
    linear = drive_line(circuit(LINEAR, m=m), m.voltage)
    drive = mechanism_drive.Machine(m.mechanism, linear, 0.0, m.t_end)
    path = paths.built_fmu(m.mechanism, version, how="scripts/run-tests")
    names = reaction_names(read_model_description(str(path)).modelVariables)
    started = clock.process_time()
    r = mechanism_drive.run(m.mechanism, step, version, drive, names)
    cpu = clock.process_time() - started
    return PlantRun(LINEAR, step, math.nan, r.t, r.phi, r.omega, cpu, r.extra)


#: The separate motor FMU of (b).
MOTOR_FMU = "motor"


def _split_fmus(label: str, version: int, m: PlantMachine) -> tuple[Slave, Slave]:
    """The motor FMU and ``m``'s rotor plant (its motor driver's inertia a parameter, to
    which the motor's rotor is added), initialised for ``label``."""
    motor = circuit(label, version, m)
    plant = Slave(paths.built_fmu(m.rotor_plant, version, how="scripts/run-tests"), "plant")
    inertia = f"{m.driver}.inertia"
    own = next(v for v in plant.md.modelVariables if v.name == inertia)
    rotor = motor.ratio**2 * motor.rotor_inertia
    inputs_at_zero(plant, f"{m.driver}.torque")
    plant.initialize({**_starts(m), inertia: float(own.start) + rotor})
    fmu = Slave(paths.built_fmu(MOTOR_FMU, version, how="scripts/run-tests"), "motor")
    names = ("resistance", "inductance", "torque_constant", "friction", "ratio")
    fmu.set("motor.voltage", m.voltage)
    fmu.initialize({f"motor.{k}": getattr(motor, k) for k in names})
    return fmu, plant


def _exchange(motor: Slave, plant: Slave, rates: bool, driver: str, recorded: tuple) -> tuple:
    """One communication point: the plant's speed of ``driver`` (and its rate) to the
    motor, the motor's torque (and its rate) to the plant; then the plant's ``recorded``
    outputs under the torque it now has (as a master records them)."""
    speed = f"{driver}.omega"
    omega = plant.get(speed)
    motor.set("shaft.omega", omega)
    if rates:
        motor.set_rates("shaft.omega", plant.output_rates((speed,))[0])
    torque = f"{driver}.torque"
    plant.set(torque, motor.get("shaft.torque"))
    if rates:
        plant.set_rates(torque, motor.output_rates(("shaft.torque",))[0])
    return plant.get(recorded)


def split_run(label: str, step: float, rates: bool, m: PlantMachine = SLIDER_CRANK) -> PlantRun:
    """The motor ``label`` of ``m`` as its own FMU (voltage and speed in, torque out) and
    the plant (torque in, speed out), exchanged at each communication point: held over the
    step, or with their first derivatives (``rates``: FMI 2's input and output
    derivatives)."""
    n = mechanism_drive.whole_steps(m.t_end, step)
    motor, plant = _split_fmus(label, 2, m)
    reactions = reaction_names(plant.md.modelVariables)
    names = (*_motion_names(m), *reactions)
    rows = np.empty((n + 1, len(names)))
    started = clock.process_time()
    try:
        for k in range(n + 1):
            rows[k] = _exchange(motor, plant, rates, m.driver, names)
            if k < n:
                motor.do_step(k * step, step)
                plant.do_step(k * step, step)
    finally:
        motor.close()
        plant.close()
    cpu = clock.process_time() - started
    return _plant_run(label, step, math.nan, m, rows, cpu, reactions)


def _largest(error: np.ndarray) -> float:
    """max |error|, infinite where any of it is not finite."""
    return float(np.max(np.abs(error))) if np.all(np.isfinite(error)) else math.inf


def _columns(x: np.ndarray, count: int) -> np.ndarray:
    """x as (count, drivers)."""
    return np.reshape(x, (count, -1))


def errors(result: PlantRun, ref: Reference) -> dict:
    """The largest angle error over the run as a fraction of the angle travelled, the
    largest speed error as a fraction of the peak speed (the worst driver's, where the
    machine has several), and the largest error of a joint reaction as a fraction of the
    largest reaction's peak (a run and a reference with different reactions are refused;
    NaN where the run has none, inf where one is not finite)."""
    step = max(1, int(round((len(ref.t) - 1) / (len(result.t) - 1))))
    count = len(result.t)
    phi, omega = (_columns(x[::step], len(ref.t[::step])) for x in (ref.phi, ref.omega))
    if len(phi) != count or abs(ref.t[::step][-1] - result.t[-1]) > 1e-9 * ref.t[-1]:
        raise ValueError(f"the reference's grid does not hold the run's {count} points")
    if set(result.reactions) != set(ref.reactions):
        apart = sorted(set(result.reactions) ^ set(ref.reactions))
        raise ValueError(f"the run and the reference differ in the reactions {', '.join(apart)}")
    angle = np.max(np.abs(_columns(result.phi, count) - phi), axis=0)
    speed = np.max(np.abs(_columns(result.omega, count) - omega), axis=0)
    travel = np.abs(phi[-1] - phi[0])
    peak = max((np.max(np.abs(ref.reactions[k])) for k in result.reactions), default=1.0)
    # a reaction that is not finite (NaN included) counts as infinitely wrong
    worst = max(
        (_largest(v - ref.reactions[k][::step]) for k, v in result.reactions.items()),
        default=math.nan,
    )
    return {
        "angle_rad": float(np.max(angle)),
        "angle": float(np.max(angle / travel)),
        "speed": float(np.max(speed / np.max(np.abs(omega), axis=0))),
        "reactions": float(worst / peak),
    }

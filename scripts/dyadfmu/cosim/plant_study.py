"""The machine with its motor inside the plant, against the same machine as one ODE.

Each machine of :data:`MACHINES` (the slider-crank, the four-bar, the shaper: a plant with
its DC motor inside, supply voltage in) runs up from rest under a constant voltage, at
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
milliseconds. The drive FMU's machine (:func:`drive_run`) is the same one with L = 0.
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
from ..mechanisms import builtin, chains, driven
from ..mechanisms.motion import CrankMotion
from ..reference import machine
from . import mechanism_drive, mechanism_fmus

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
    "reaction_names",
    "reactions",
    "reference",
    "run",
    "split_run",
    "unloaded",
]


@dataclass(frozen=True)
class PlantMachine:
    """A machine of the study: the plant with its motor inside (a), the plant whose crank
    takes a separate motor FMU's rotor (b), the inverse mechanism FMU (c) whose harness
    mechanism is the reference's, the supply voltage [V] and the run's duration [s]; where
    given, ``linear_plant``: the plant with the same motor without inductance (the drive
    FMU's linear characteristic, (a) one to one with (c))."""

    name: str
    plant: str
    rotor_plant: str
    mechanism: str
    voltage: float
    t_end: float
    linear_plant: str = ""


#: The machines, each run up from rest at START_ANGLE (the motors: the plants' [motor]).
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
    )
}
SLIDER_CRANK = MACHINES["slider-crank"]
START_ANGLE = 0.5  # rad
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

    def parameters(self) -> dict[str, float]:
        """The plant's parameters for this motor."""
        return {f"crank.motor.{k}": getattr(self, k) for k in _MOTOR_KEYS}


def circuit(label: str, version: int = 2, m: PlantMachine = SLIDER_CRANK) -> Circuit:
    """The motor of ``m``'s plant with the time constant of :data:`CIRCUITS` ``label``."""
    md = read_model_description(str(paths.built_fmu(m.plant, version, how="scripts/run-tests")))
    starts = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
    motor = Circuit(*(starts[f"crank.motor.{k}"] for k in _MOTOR_KEYS))
    time_constant = 0.0 if label == LINEAR else CIRCUITS[label]
    if time_constant is None:
        return motor
    return replace(motor, inductance=time_constant * motor.resistance)


@dataclass
class PlantRun:
    """The plant's crank angle [rad] and speed [rad/s] at its communication points, the
    CPU time of the run [s], and its joint reactions there (output name -> [N] or [N.m])."""

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
    parameters = circuit(label, version, m).parameters()
    name = m.plant
    if label == LINEAR:
        if not m.linear_plant:
            raise ValueError(f"{m.name} has no plant with a motor without inductance")
        name = m.linear_plant
        del parameters["crank.motor.inductance"]  # no parameter there: no current state
    parameters["crank.angle_start"] = START_ANGLE
    if rtol is not None:
        parameters.update({"solver.rtol": rtol, "solver.atol": rtol})
    plant = Slave(paths.built_fmu(name, version, how="scripts/run-tests"), "plant")
    names = ("crank.angle", "crank.omega", *reaction_names(plant.md.modelVariables))
    rows = np.empty((n + 1, len(names)))
    started = clock.process_time()
    try:
        plant.set("crank.motor.voltage", m.voltage)
        plant.initialize(parameters)
        rows[0] = plant.get(names)
        for k in range(n):
            plant.do_step(k * step, step)
            rows[k + 1] = plant.get(names)
    finally:
        plant.close()
    cpu = clock.process_time() - started
    t = step * np.arange(n + 1)
    reactions = _recorded(names[2:], rows, 2)
    return PlantRun(label, step, rtol or math.nan, t, rows[:, 0], rows[:, 1], cpu, reactions)


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
    """The largest distance of ``m``'s series of J, J' and Q_g to the harness (relative)."""
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
    acceleration [rad/s2] and the harness's joint reactions along that motion (output
    name -> [N] or [N.m], as the FMUs name them)."""

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
    start, scale = [START_ANGLE, 0.0, 0.0], [1.0, 1.0, m.voltage / motor.resistance]
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
    """The motor FMU and ``m``'s rotor plant (its crank's inertia a parameter, to which the
    motor's rotor is added), initialised for ``label``."""
    motor = circuit(label, version, m)
    plant = Slave(paths.built_fmu(m.rotor_plant, version, how="scripts/run-tests"), "plant")
    crank = next(v for v in plant.md.modelVariables if v.name == "crank.inertia")
    rotor = motor.ratio**2 * motor.rotor_inertia
    plant.initialize(
        {"crank.angle_start": START_ANGLE, "crank.inertia": float(crank.start) + rotor}
    )
    fmu = Slave(paths.built_fmu(MOTOR_FMU, version, how="scripts/run-tests"), "motor")
    names = ("resistance", "inductance", "torque_constant", "friction", "ratio")
    fmu.set("motor.voltage", m.voltage)
    fmu.initialize({f"motor.{k}": getattr(motor, k) for k in names})
    return fmu, plant


def _exchange(motor: Slave, plant: Slave, rates: bool, reactions: tuple) -> tuple:
    """One communication point: the plant's speed (and its rate) to the motor, the
    motor's torque (and its rate) to the plant; the crank's angle and speed, then the
    plant's ``reactions`` under the torque it now has (as a master records them)."""
    phi, omega = plant.get(("crank.angle", "crank.omega"))
    motor.set("shaft.omega", omega)
    if rates:
        motor.set_rates("shaft.omega", plant.output_rates(("crank.omega",))[0])
    plant.set("crank.torque", motor.get("shaft.torque"))
    if rates:
        plant.set_rates("crank.torque", motor.output_rates(("shaft.torque",))[0])
    return (phi, omega, *(plant.get(reactions) if reactions else ()))


def split_run(label: str, step: float, rates: bool, m: PlantMachine = SLIDER_CRANK) -> PlantRun:
    """The motor ``label`` of ``m`` as its own FMU (voltage and speed in, torque out) and
    the plant (torque in, speed out), exchanged at each communication point: held over the
    step, or with their first derivatives (``rates``: FMI 2's input and output
    derivatives)."""
    n = mechanism_drive.whole_steps(m.t_end, step)
    motor, plant = _split_fmus(label, 2, m)
    names = ("crank.angle", "crank.omega", *reaction_names(plant.md.modelVariables))
    rows = np.empty((n + 1, len(names)))
    started = clock.process_time()
    try:
        for k in range(n + 1):
            rows[k] = _exchange(motor, plant, rates, names[2:])
            if k < n:
                motor.do_step(k * step, step)
                plant.do_step(k * step, step)
    finally:
        motor.close()
        plant.close()
    cpu = clock.process_time() - started
    t = step * np.arange(n + 1)
    reactions = _recorded(names[2:], rows, 2)
    return PlantRun(label, step, math.nan, t, rows[:, 0], rows[:, 1], cpu, reactions)


def _largest(error: np.ndarray) -> float:
    """max |error|, infinite where any of it is not finite."""
    return float(np.max(np.abs(error))) if np.all(np.isfinite(error)) else math.inf


def errors(result: PlantRun, ref: Reference) -> dict:
    """The largest angle error over the run as a fraction of the angle travelled, the
    largest speed error as a fraction of the peak speed, and the largest error of a joint
    reaction as a fraction of the largest reaction's peak (a run and a reference with
    different reactions are refused; NaN where the run has none, inf where one is not
    finite)."""
    step = max(1, int(round((len(ref.t) - 1) / (len(result.t) - 1))))
    phi, omega = ref.phi[::step], ref.omega[::step]
    if len(phi) != len(result.t) or abs(ref.t[::step][-1] - result.t[-1]) > 1e-9 * ref.t[-1]:
        raise ValueError(f"the reference's grid does not hold the run's {len(result.t)} points")
    travel = abs(phi[-1] - phi[0])
    if set(result.reactions) != set(ref.reactions):
        apart = sorted(set(result.reactions) ^ set(ref.reactions))
        raise ValueError(f"the run and the reference differ in the reactions {', '.join(apart)}")
    peak = max((np.max(np.abs(ref.reactions[k])) for k in result.reactions), default=1.0)
    # a reaction that is not finite (NaN included) counts as infinitely wrong
    worst = max(
        (_largest(v - ref.reactions[k][::step]) for k, v in result.reactions.items()),
        default=math.nan,
    )
    return {
        "angle_rad": float(np.max(np.abs(result.phi - phi))),
        "angle": float(np.max(np.abs(result.phi - phi)) / travel),
        "speed": float(np.max(np.abs(result.omega - omega)) / np.max(np.abs(omega))),
        "reactions": float(worst / peak),
    }

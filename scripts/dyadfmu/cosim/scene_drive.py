"""A user's scene file turned by the drive FMU: its mechanism FMU built where stale, checked
to have the one crank a drive turns and the outputs the stabilised coupling reads, and its
machine derived from the FMU itself, for ``dyadfmu cosim --scene`` and
``python -m dyadfmu.cosim.ssp --scene``.

The machine (:func:`machine_for`): the motor of :data:`dyadfmu.reference.machine.MOTORS`
named (its stall torque and no-load speed each replaceable), with the rotor inertia the
mean of the FMU's ``crank.J`` over one revolution of ``crank.angle``, as
:func:`dyadfmu.cosim.mechanism_drive.machine_of` takes the harness's mean J for the shipped
mechanisms. Over a revolution at any constant speed the mean of ``crank.torque0`` is its
mean at rest (the inertial part, J'(phi) omega^2 / 2, is the derivative of a periodic
function times a constant), the torque the loads and the weights demand on average; the
default start speed is where the motor's line gives that torque, the speed the machine
settles about.

API: :func:`add_machine_options`, :func:`checked_scene`, :func:`revolution_means`,
:func:`machine_for`, :func:`default_step`, :func:`communication_step`,
:func:`options_problem`, :func:`prepare` (-> :class:`SceneMachine`).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import argtypes
from ..fmi.slave import Slave
from ..reference import machine
from . import mechanism_drive

__all__ = [
    "SceneRefused",
    "SceneMachine",
    "DEFAULT_MOTOR",
    "DEFAULT_DURATION",
    "add_machine_options",
    "checked_scene",
    "revolution_means",
    "machine_for",
    "default_step",
    "communication_step",
    "options_problem",
    "prepare",
]

#: The motor of :data:`dyadfmu.reference.machine.MOTORS` a scene is given unless told.
DEFAULT_MOTOR = "four-bar"
#: The simulated time [s] unless told.
DEFAULT_DURATION = 1.0
#: Angles a degree apart over the revolution the means are taken on.
SAMPLES = 360
#: The default communication step takes at least this many steps per revolution at the
#: motor's no-load speed, and at most 1 ms (the shipped mechanisms' coarser step).
STEPS_PER_REVOLUTION, LONGEST_STEP = 100, 1e-3
#: The most communication steps a run may take.
MOST_STEPS = 10_000_000
#: The outputs the stabilised coupling reads besides crank.torque.
NEEDED = ("crank.J", "crank.torque0")


class SceneRefused(ValueError):
    """A scene the drive cannot turn: the message, one line, names the file and why."""


@dataclass(frozen=True)
class SceneMachine:
    """A scene ready to run: its identifier, its mechanism FMU, the machine, the
    communication step [s] and the mean torque demand over a revolution [N m]."""

    identifier: str
    fmu: Path
    machine: mechanism_drive.Machine
    step: float
    mean_demand: float


def add_machine_options(parser: argparse.ArgumentParser) -> None:
    """The options that set a scene's machine: --motor, --stall-torque, --no-load-speed,
    --start-speed, --duration, --step (each checked for its range, with its unit)."""
    group = parser.add_argument_group("the machine turning a scene's crank (with --scene)")
    group.add_argument(
        "--motor",
        choices=tuple(machine.MOTORS),
        help=f"the motor, a straight torque-speed line (default {DEFAULT_MOTOR}: "
        + ", ".join(
            f"{k} {m.stall_torque:g} N m at stall, {m.no_load_speed:g} rad/s at no load"
            for k, m in machine.MOTORS.items()
        )
        + "); its rotor inertia is always the mean of the scene's crank.J over a revolution",
    )
    group.add_argument(
        "--stall-torque",
        type=argtypes.real(0.0, 1e7, above=True),
        metavar="N.m",
        help="the motor's torque at rest, N m (default the motor's)",
    )
    group.add_argument(
        "--no-load-speed",
        type=argtypes.real(0.0, 1e5, above=True),
        metavar="RAD/S",
        help="the speed where the motor's torque vanishes, rad/s (default the motor's)",
    )
    group.add_argument(
        "--start-speed",
        type=argtypes.real(0.0, 1e5),
        metavar="RAD/S",
        help="the crank's speed at t = 0, rad/s (default: where the motor's torque equals the "
        "mechanism's mean torque demand over a revolution, the speed it settles about)",
    )
    group.add_argument(
        "--duration",
        type=argtypes.real(0.0, 1e4, above=True),
        metavar="S",
        help=f"the simulated time, s (default {DEFAULT_DURATION:g} s)",
    )
    group.add_argument(
        "--step",
        type=argtypes.real(0.0, 1.0, above=True),
        metavar="S",
        help="the communication step, s (default: the longest of 1, 2, 5 x 10^k s up to "
        f"{LONGEST_STEP:g} s that takes {STEPS_PER_REVOLUTION} steps per revolution at the "
        "no-load speed); the duration must be a whole number of steps",
    )


#: The options of add_machine_options, as attributes of the parsed arguments.
MACHINE_OPTIONS = ("motor", "stall_torque", "no_load_speed", "start_speed", "duration", "step")


def checked_scene(scene_file: Path) -> str:
    """The identifier of a scene with exactly one driver, a crank; SceneRefused (one line
    naming the file and why) for a malformed scene, one with no crank or several drivers."""
    from ..report import cylinder_drawing, drivers_drawing

    try:
        scene = drivers_drawing.read_scene(scene_file)
    except cylinder_drawing.DrawingError as error:
        raise SceneRefused(str(error).splitlines()[0]) from None
    named = ", ".join(f"{d.kind} '{d.name}'" for d in scene.drivers)
    if len(scene.drivers) > 1:
        raise SceneRefused(
            f"{scene_file}: {len(scene.drivers)} drivers ({named}): one drive turns one crank"
        )
    if scene.drivers[0].kind != "crank":
        raise SceneRefused(
            f"{scene_file}: no crank, its driver is {named}: one drive turns one crank"
        )
    return scene.identifier


def revolution_means(fmu: Path) -> tuple[float, float]:
    """The means of the mechanism FMU's crank.J [kg m2] and crank.torque0 [N m] over one
    revolution of crank.angle, at rest (SAMPLES angles a degree apart); SceneRefused where
    the FMU has no such outputs."""
    y = Slave(fmu, "revolution")
    try:
        outputs = {v.name for v in y.md.modelVariables if v.causality == "output"}
        missing = [n for n in NEEDED if n not in outputs]
        if missing:
            raise SceneRefused(
                f"{fmu}: no output {' or '.join(missing)}: the drive needs the mechanism's "
                "effective inertia and its torque at zero acceleration, which a scene has with "
                '[effects] inertia = true and dynamics = "inverse"'
            )
        y.initialize()
        angles = np.linspace(0.0, 2.0 * math.pi, SAMPLES, endpoint=False)
        rows = []
        for angle in angles:
            y.set(("crank.angle", "crank.omega", "crank.epsilon"), (angle, 0.0, 0.0))
            rows.append(y.get(NEEDED))
    finally:
        y.close()
    rows = np.array(rows, dtype=float)
    unanswered = np.flatnonzero(~np.all(np.isfinite(rows), axis=1))
    if len(unanswered):
        raise SceneRefused(
            f"{fmu}: no answer at {len(unanswered)} of {SAMPLES} crank angles (the first "
            f"{angles[unanswered[0]]:.4g} rad): the mechanism does not go through a whole turn, "
            "so a drive cannot turn it (see where with 'dyadfmu scene FILE')"
        )
    inertia, demand = np.mean(rows, axis=0)
    return float(inertia), float(demand)


def machine_for(
    name: str, inertia: float, demand: float, args: argparse.Namespace
) -> mechanism_drive.Machine:
    """The machine of the options in ``args`` (see :func:`add_machine_options`) with the
    rotor inertia ``inertia`` [kg m2], the mean J; ``demand`` [N m] is the mean torque the
    mechanism demands, whose speed on the motor's line is the default start speed."""
    given = machine.MOTORS[args.motor or DEFAULT_MOTOR]
    motor = machine.Motor(
        args.stall_torque or given.stall_torque,
        args.no_load_speed or given.no_load_speed,
        inertia,
    )
    omega0 = args.start_speed
    if omega0 is None:
        omega0 = motor.no_load_speed * (1.0 - demand / motor.stall_torque)
        if omega0 <= 0.0:
            raise SceneRefused(
                f"the motor's stall torque, {motor.stall_torque:g} N m, does not exceed the "
                f"mechanism's mean demand over a revolution, {demand:.4g} N m: give a "
                "stronger --motor or --stall-torque (or a --start-speed)"
            )
    return mechanism_drive.Machine(name, motor, omega0, args.duration or DEFAULT_DURATION)


def default_step(no_load_speed: float) -> float:
    """The longest step of 1, 2 or 5 x 10^k s, at most LONGEST_STEP, that takes
    STEPS_PER_REVOLUTION steps per revolution at ``no_load_speed`` [rad/s]."""
    longest = min(LONGEST_STEP, 2.0 * math.pi / no_load_speed / STEPS_PER_REVOLUTION)
    decade = 10.0 ** math.floor(math.log10(longest))
    mantissa = max(m for m in (1.0, 2.0, 5.0) if m * decade <= longest * (1 + 1e-12))
    return float(f"{mantissa * decade:.1e}")


def communication_step(args: argparse.Namespace) -> float:
    """The communication step [s] of the options in ``args`` (--step, or the default for the
    motor's no-load speed); SceneRefused, naming --duration and --step, where it does not
    divide the duration or makes more than MOST_STEPS steps."""
    no_load_speed = args.no_load_speed or machine.MOTORS[args.motor or DEFAULT_MOTOR].no_load_speed
    step, duration = args.step or default_step(no_load_speed), args.duration or DEFAULT_DURATION
    try:
        steps = mechanism_drive.whole_steps(duration, step)
    except ValueError:
        raise SceneRefused(
            f"--duration {duration:g} s is not a whole number of --step {step:g} s"
        ) from None
    if steps > MOST_STEPS:
        raise SceneRefused(
            f"--duration {duration:g} s in --step {step:g} s makes {steps:,} steps; "
            f"at most {MOST_STEPS:,}"
        )
    return step


def options_problem(args: argparse.Namespace) -> str | None:
    """What is wrong with the options of :func:`add_machine_options` beyond each one's own
    type (one given without --scene, a --step that does not divide the --duration), or
    None."""
    if args.scene is None:
        given = [name for name in MACHINE_OPTIONS if getattr(args, name) is not None]
        return f"--{given[0].replace('_', '-')} needs --scene" if given else None
    try:
        communication_step(args)
    except SceneRefused as refused:
        return str(refused)
    return None


def prepare(
    scene_file: Path,
    args: argparse.Namespace,
    fmi_version: int,
    out: Path,
    say: Callable[[str], None],
) -> SceneMachine:
    """The scene checked, its FMU built where stale, its machine and communication step from
    the options in ``args``; SceneRefused where the scene, its FMU or the options cannot
    make one (see also :func:`communication_step`)."""
    from ..report import cylinder_drawing, own_scene

    scene_file = Path(scene_file).resolve()
    identifier = checked_scene(scene_file)
    try:
        fmu = own_scene.scene_fmu(scene_file, identifier, fmi_version, out, say)
    except cylinder_drawing.DrawingError as error:
        raise SceneRefused(str(error)) from None
    inertia, demand = revolution_means(fmu)
    m = machine_for(identifier, inertia, demand, args)
    step = communication_step(args)
    return SceneMachine(identifier, fmu, m, step, demand)

"""Forward dynamics of a mechanism scene ([scene] dynamics = "forward"): the drivers'
efforts in, their motion integrated inside the FMU, the scene's outputs at the state
reached.

The scene's own code (emit/scene_c.py) stays what it is: the inverse dynamics, the
drivers' motion in and their efforts out. With every driver's acceleration zero it
gives h(q, q', loads) (torque0, or each driver's effort0) and M(q) (J, or the inertia
matrix), so the equation of motion efforts = M(q) q'' + h reads

    q'' = M(q)^-1 (efforts - h(q, q', loads)),

one evaluation and an N x N solve. The behaviour generated here integrates y = (q, q')
with the core's Rosenbrock integrator (dyadfmu/ode.h) over each communication step and
evaluates the scene once more at the end with the acceleration found, so that every
reaction is the exact one of the motion integrated. The states live in the input block
(doubles the FMU state keeps): each driver's position and rate, and the step-size
controller's memory, so that a restored state continues bit for bit."""

from __future__ import annotations

from dataclasses import dataclass

from dyadgen.model import MOTOR_NUMBERS, Crank, Input, Motor, Output, Scene, member
from dyadgen.needs import effort_of, inertia_entry_member
from dyadgen.textsafe import c_string

#: The [scene] dynamics values.
DYNAMICS = ("inverse", "forward")
#: The most internal steps one communication step may take.
MAX_STEPS = 20000
#: The tolerances' defaults: the drivers' motion within about 1e-8 of its travel and
#: peak rate over seconds of motion.
RTOL_DEFAULT = 1e-8
ATOL_DEFAULT = 1e-8
#: The largest h R / L of a motor's circuit the explicit method takes on by default:
#: half DOP853's stability limit on the negative real axis (about 6).
EXPLICIT_LIMIT_DEFAULT = 3.0
#: The largest a user may set: below that limit, with a margin.
EXPLICIT_LIMIT_MAX = 5.0
#: The share of the tolerances each internal step's error is held to, by either method.
STEP_SHARE = 1.0 / 64.0
#: The share of a step's tolerances the slow system's own error may take (the three terms
#: of a stiff circuit's manifold leave out eps^3 k r |q''''| / R of its current).
SLOW_SHARE = 0.5


@dataclass
class ForwardDriver:
    """A driver of a forward scene: its motion's inputs of the inverse scene (now set
    inside from the states) and the C members of its effort, start values and states."""

    driver: Crank
    index: int
    position: Input
    rate: Input
    acceleration: Input
    motor: Motor | None = None
    #: the place of its motor's current in the state y, if its motor has an inductance
    current: int = -1

    @property
    def name(self) -> str:
        """The name of the driver's motion and effort (a cylinder's, not its link's)."""
        return self.driver.driver_name()

    def effort(self) -> tuple[str, str]:
        """(FMU name, unit) of the effort the driver is driven by."""
        effort, unit = effort_of(self.driver)
        return f"{self.name}.{effort}", unit

    def c(self, what: str) -> str:
        """The C member of one of the plant's own values of this driver."""
        return f"plant_{member(self.name)}_{what}"

    @property
    def circuit(self) -> bool:
        """Whether it has a motor whose armature current is a state (inductance > 0)."""
        return self.motor is not None and self.motor.circuit

    @property
    def steady(self) -> bool:
        """Whether it has a motor without inductance: its current follows the speed."""
        return self.motor is not None and not self.motor.circuit


def forward_drivers(scene: Scene) -> list[ForwardDriver]:
    """The drivers of a forward scene with their motion's inputs, in the scene's order."""
    found = []
    motors = {m.driver: m for m in scene.motors}
    geared = [d.name for d in scene.drivers if d.name in motors and motors[d.name].circuit]
    for k, driver in enumerate(scene.drivers):
        motion = [i for i in scene.inputs if i.owner == driver.name and i.unit not in ("N", "N.m")]
        f = ForwardDriver(driver, k, *motion[:3])
        if driver.name in motors:
            f.motor = motors[driver.name]
        if f.circuit:
            f.current = 2 * len(scene.drivers) + geared.index(driver.name)
        found.append(f)
    return found


def state_size(scene: Scene) -> int:
    """The dimension of y: each driver's position and rate, each motor's current (where
    it has an inductance)."""
    return 2 * len(scene.drivers) + sum(m.circuit for m in scene.motors)


def required_outputs(scene: Scene) -> list[str]:
    """The outputs the equation of motion reads: M(q) and h."""
    if len(scene.drivers) == 1:
        c = scene.drivers[0].driver_name()
        return [f"{c}.J", f"{c}.{effort_of(scene.drivers[0])[0]}0"]
    names = [f"M.{a.driver_name()}.{b.driver_name()}" for a in scene.drivers for b in scene.drivers]
    return names + [f"{d.driver_name()}.{effort_of(d)[0]}0" for d in scene.drivers]


def motion_inputs(scene: Scene) -> set[str]:
    """The inverse scene's inputs that are states (or their derivative) here."""
    return {i.name for f in forward_drivers(scene) for i in (f.position, f.rate, f.acceleration)}


def efforts(scene: Scene) -> set[str]:
    """The FMU names of the efforts that are inputs here (a driver's without a motor),
    outputs of the inverse scene."""
    return {f.effort()[0] for f in forward_drivers(scene) if f.motor is None}


def interpolated_inputs(scene: Scene) -> list[Input]:
    """The inputs the plant follows over a step as straight lines from their first
    derivatives (canInterpolateInputs): every Real input of the plant, none of which is an
    angle or bounded, so that a line carries it only to values its setter would take."""
    found = public_inputs(scene)
    wrong = [i.name for i in found if i.angle or i.domain]
    if wrong:
        raise ValueError(f"a plant's inputs are unbounded and no angles: {', '.join(wrong)}")
    return found


def slope_member(i: Input) -> str:
    """The C member of the first derivative of an interpolated input."""
    return f"plant_slope_{i.member}"


def input_members(scene: Scene) -> dict[str, str]:
    """The plant's own members of the input block: efforts, start values, tolerances,
    states, the inputs' first derivatives."""
    members: dict[str, str] = {slope_member(i): "real" for i in interpolated_inputs(scene)}
    for f in forward_drivers(scene):
        for what in ("effort", "position_start", "rate_start", "position", "rate"):
            members[f.c(what)] = "real"
        if f.motor is not None:
            for key in (*MOTOR_NUMBERS, "voltage"):
                members[f.c(f"motor_{key}")] = "real"
            members[f.c("current")] = "real"
    for name in ("rtol", "atol", "step_start", "h_next", "steps", "evaluations"):
        members[f"plant_{name}"] = "real"
    if any(f.motor is not None for f in forward_drivers(scene)):
        members["plant_explicit_limit"] = "real"
    return members


def output_members(scene: Scene) -> dict[str, str]:
    """The plant's own outputs: each driver's position, rate and acceleration."""
    members = {
        f.c(what): "real"
        for f in forward_drivers(scene)
        for what in ("position", "rate", "acceleration")
    }
    members.update((f.c("current"), "real") for f in forward_drivers(scene) if f.motor)
    return members | {"plant_h_next": "real", "plant_steps": "real", "plant_evaluations": "real"}


def public_inputs(scene: Scene) -> list[Input]:
    """The forward FMU's inputs: the efforts, then the scene's loads."""
    moved = motion_inputs(scene)
    found = []
    for f in forward_drivers(scene):
        if f.motor is not None:
            text = f"Supply voltage of the motor of {f.name}"
            found.append(Input(f"{f.name}.motor.voltage", "V", text, f.c("motor_voltage")))
            continue
        name, unit = f.effort()
        text = f"Driving {'force' if unit == 'N' else 'torque'} of {f.name}, the plant's input"
        found.append(Input(name, unit, text, f.c("effort")))
    return found + [i for i in scene.inputs if i.name not in moved]


#: The largest start position (rad or m): beyond 2^32 a double resolves a position no
#: finer than 1e-6, and a crank started there would not be seen to move.
POSITION_START_LIMIT = 2.0**32


def start_parameters(scene: Scene) -> list[tuple[Input, float]]:
    """The start values of the states as parameters, with their defaults (the inverse
    scene's start values of the driver's motion)."""
    found = []
    for f in forward_drivers(scene):
        for motion, what in ((f.position, "position"), (f.rate, "rate")):
            text = f"{motion.description} at the start"
            domain = {}
            if what == "position":
                domain = {"min": -POSITION_START_LIMIT, "max": POSITION_START_LIMIT}
            parameter = Input(
                f"{motion.name}_start", motion.unit, text, f.c(f"{what}_start"), domain=domain
            )
            found.append((parameter, motion.start))
        if f.motor is not None:
            found += _motor_parameters(f)
    return found


def _motor_parameters(f: ForwardDriver) -> list[tuple[Input, float]]:
    """A motor's numbers as parameters, with their bounds (a motor without inductance has
    neither it nor a start current: its current is no state)."""
    found = []
    for key, (unit, text, _, least, strict) in MOTOR_NUMBERS.items():
        if key in ("inductance", "current") and not f.circuit:
            continue
        if key == "inductance":
            strict = True  # a circuit's stays one: the state and its rate need L > 0
        name = f"{f.name}.motor.{key}" + ("_start" if key == "current" else "")
        domain = {} if least is None else {"min": least, "min_exclusive": strict}
        parameter = Input(name, unit or None, text, f.c(f"motor_{key}"), domain=domain)
        found.append((parameter, f.motor.numbers[key]))
    return found


#: The tightest relative tolerance: a few units of round-off.
RTOL_MIN = 1e-14


def tolerance_parameters() -> list[tuple[str, float, str]]:
    """(name, default, description) of the integrator's tolerances."""
    return [
        (
            "solver.rtol",
            RTOL_DEFAULT,
            "Relative tolerance of the integrator (each internal step's error is held to "
            f"1/{round(1 / STEP_SHARE)} of it)",
        ),
        (
            "solver.atol",
            ATOL_DEFAULT,
            "Absolute tolerance of the integrator (in the drivers' units: rad, m, rad/s, "
            f"m/s; each internal step's error is held to 1/{round(1 / STEP_SHARE)} of it)",
        ),
    ]


def step_start_parameter() -> tuple[str, float, str]:
    """(name, default, description) of the integrator's first internal step."""
    return (
        "solver.step_start",
        0.0,
        "The integrator's first internal step (0: it chooses one from the motion's "
        "derivatives); solver.step continues it",
    )


def explicit_limit_parameters(scene: Scene) -> list[tuple[str, float, str]]:
    """(name, default, description) of the switch between the integrator's methods, for
    a scene with a motor (without one, nothing of the plant's own is stiff: the explicit
    method always)."""
    if not any(f.motor is not None for f in forward_drivers(scene)):
        return []
    return [
        (
            "solver.explicit_limit",
            EXPLICIT_LIMIT_DEFAULT,
            "The explicit method (DOP853) integrates a communication step while its internal "
            "step times the fastest motor's decay rate (its circuit's R / L; without "
            "inductance, its damping over its rotor's inertia) stays at most this; above it, "
            "the Rosenbrock method (RODASP). 0: RODASP wherever a motor has a decay rate (a "
            "circuit, or a rotor with inertia)",
        )
    ]


def motion_outputs(scene: Scene) -> list[Output]:
    """Each driver's position, rate and acceleration at the end of the step."""
    inputs = [i.name for i in public_inputs(scene)]
    found = []
    for f in forward_drivers(scene):
        for motion, what in ((f.position, "position"), (f.rate, "rate")):
            found.append(Output(motion.name, motion.unit, motion.description, f.c(what)))
        a = f.acceleration
        found.append(Output(a.name, a.unit, a.description, f.c("acceleration"), depends=inputs))
        if f.motor is not None:
            text = f"Armature current of the motor of {f.name}"
            # a circuit's is a state; without inductance it follows the supply at once
            supply = [] if f.circuit else [_effort_input(scene, f).name]
            current = Output(f"{f.name}.motor.current", "A", text, f.c("current"), depends=supply)
            found.append(current)
    return found + [
        Output(
            "solver.step",
            "s",
            "The internal step the integrator takes first in the next communication step "
            "(what it kept of its step control; 0: it chooses one)",
            "plant_h_next",
        ),
        Output(
            "solver.steps",
            None,
            "Internal steps the integrator took since the start (accepted and rejected)",
            "plant_steps",
        ),
        Output(
            "solver.evaluations",
            None,
            "Evaluations of the equation of motion since the "
            "start, those of the integrator's difference Jacobians included",
            "plant_evaluations",
        ),
    ]


def public_outputs(scene: Scene) -> list[Output]:
    """The forward FMU's outputs: each driver's motion, then the scene's own (the
    efforts, now inputs, left out), their dependencies on the motion replaced by the
    inputs that set the acceleration."""
    inputs = [i.name for i in public_inputs(scene)]
    moved, given = motion_inputs(scene), efforts(scene)
    accelerations = {f.acceleration.name for f in forward_drivers(scene)}
    found = motion_outputs(scene)
    for o in scene.outputs:
        if o.name in given:
            continue
        depends = [d for d in o.depends if d not in moved]
        if any(d in accelerations for d in o.depends):
            depends = inputs
        found.append(Output(o.name, o.unit, o.description, o.member, o.integer, depends, o.source))
    return found


def _state_names(scene: Scene) -> list[tuple[str, str, str]]:
    """(name, unit, C member) of every model state, as an FMU state keeps it."""
    states = []
    for f in forward_drivers(scene):
        states.append((f.position.name, f.position.unit or "", f.c("position")))
        states.append((f.rate.name, f.rate.unit or "", f.c("rate")))
    states += [(f"{f.name}.motor.current", "A", f.c("current")) for f in _geared(scene)]
    states += [
        ("solver.step", "s", "plant_h_next"),
        ("solver.steps", "", "plant_steps"),
        ("solver.evaluations", "", "plant_evaluations"),
    ]
    return states


def _geared(scene: Scene) -> list[ForwardDriver]:
    """The drivers whose motor has an inductance (a current state), in the order of their
    currents in y."""
    return sorted((f for f in forward_drivers(scene) if f.circuit), key=lambda f: f.current)


def _motion_into(ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """put_motion(): the drivers' motion into the inverse scene's inputs."""
    lines = [
        "/* The drivers' motion as the inverse scene takes it. */",
        f"static void put_motion({ident}_input* at, const double* q, const double* v,",
        "                       const double* a)",
        "{",
    ]
    for f in drivers:
        k = f.index
        if f.position.angle:
            # the FMU layer's own cos and sin (dyadfmu/angle.h): the same bits on every
            # platform, as an angle input's unit vector has
            lines += [
                "    {",
                "        double c, s;",
                f"        dyad_cos_sin(q[{k}], &c, &s);",
                f"        at->{f.position.member} = dyad_vec2_make((dyad_real)c, (dyad_real)s);",
                "    }",
            ]
        else:
            lines.append(f"    at->{f.position.member} = q[{k}];")
        lines.append(f"    at->{f.rate.member} = v[{k}];")
        lines.append(f"    at->{f.acceleration.member} = a[{k}];")
    return lines + ["}", ""]


def _equation_of_motion(scene: Scene, ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """mass_and_bias(): M(q) and efforts - h from an evaluation at zero acceleration."""
    n = len(drivers)
    lines = [
        "/* M(q) (row-major) and the efforts less h(q, q', loads), from the scene's outputs",
        " * at zero acceleration of every driver. */",
        f"static void mass_and_bias(const {ident}_input* in, const {ident}_output* out, "
        "const double* y,",
        "                          double* m, double* r)",
        "{",
    ]
    if n == 1:
        lines.append(f"    m[0] = out->{member(drivers[0].name)}_reduced_j;")
    else:
        for a in drivers:
            for b in drivers:
                entry = inertia_entry_member(scene, a.driver, b.driver)
                lines.append(f"    m[{a.index * n + b.index}] = out->{entry};")
    if not scene.motors:
        lines.append("    (void)y;")
    for f in drivers:
        h = f"out->{member(f.name)}_{effort_of(f.driver)[0]}0"
        if f.motor is None:
            lines.append(f"    r[{f.index}] = in->{f.c('effort')} - {h};")
            continue
        ratio, k = f"in->{f.c('motor_ratio')}", f.index
        lines += [
            "    /* the motor's torque at the crank, its rotor's inertia on M's diagonal */",
            f"    m[{k * n + k}] += {ratio} * {ratio} * in->{f.c('motor_rotor_inertia')};",
            f"    r[{k}] = {ratio} * (in->{f.c('motor_torque_constant')} * {_current(f, 'y', n)} -",
            f"            in->{f.c('motor_friction')} * {ratio} * y[{n + k}]) - {h};",
        ]
    return lines + ["}", ""]


def _current(f: ForwardDriver, y: str, n: int, voltage: str = "") -> str:
    """The C expression of f's armature current at the state ``y``: the state's, or
    without inductance (V - k ratio q') / R, V the member ``voltage`` (the supply's)."""
    if f.circuit:
        return f"{y}[{f.current}]"
    c = f.c
    supply = voltage or f"in->{c('motor_voltage')}"
    return (
        f"({supply} - in->{c('motor_torque_constant')} * in->{c('motor_ratio')} * "
        f"{y}[{n + f.index}]) / in->{c('motor_resistance')}"
    )


def _inertia_and_bias_members(scene: Scene, drivers: list[ForwardDriver]) -> tuple[list, list]:
    """The output members of M(q) (row-major) and of h, as the scene names them."""
    n = len(drivers)
    if n == 1:
        masses = [f"{member(drivers[0].name)}_reduced_j"]
    else:
        masses = [inertia_entry_member(scene, a.driver, b.driver) for a in drivers for b in drivers]
    biases = [f"{member(f.name)}_{effort_of(f.driver)[0]}0" for f in drivers]
    return masses, biases


def _jacobian_parts(scene: Scene, ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """put_seed(), the rates of M and h along it, and the motors' partial derivatives:
    what the exact Jacobian (templates/forward_behaviour.c.in) is assembled from."""
    n = len(drivers)
    lines = [
        "/* The seed of the inverse scene's directional derivative along y's value j (a",
        " * driver's position, j < PLANT_DRIVERS, or its rate). */",
        f"static void put_seed(const {ident}_input* at, {ident}_input* seed, int j)",
        "{",
        "    memset(seed, 0, sizeof *seed);",
    ]
    if not any(f.position.angle for f in drivers):
        lines.append("    (void)at;")
    lines.append("    switch (j) {")
    for f in drivers:
        k = f.index
        if f.position.angle:
            m = f.position.member
            lines.append(f"    case {k}: seed->{m} = dyad_perp(at->{m}); break;")
        else:
            lines.append(f"    case {k}: seed->{f.position.member} = 1.0; break;")
        lines.append(f"    case {n + k}: seed->{f.rate.member} = 1.0; break;")
    lines += ["    default: break;", "    }", "}", ""]
    masses, biases = _inertia_and_bias_members(scene, drivers)
    lines += [
        "/* M's and h's rates along a seed. */",
        f"static void mass_and_bias_rate(const {ident}_output* rate, double* dm, double* dh)",
        "{",
    ]
    lines += [f"    dm[{k}] = rate->{m};" for k, m in enumerate(masses)]
    lines += [f"    dh[{k}] = rate->{b};" for k, b in enumerate(biases)]
    lines += ["}", "", *_motor_partials(ident, drivers, n)]
    return lines


def _motor_partials(ident: str, drivers: list[ForwardDriver], n: int) -> list[str]:
    """motor_partials(): d r / d y of the motors' torques (r = efforts - h, row-major N x
    PLANT_SIZE; a motor without inductance's through its current's speed term) and d i' / d y
    of the current states (row-major circuits x PLANT_SIZE), the rest zero: both are linear
    in y."""
    lines = [
        "/* The motors' part of d(efforts - h)/dy and the currents' d i'/dy. */",
        f"static void motor_partials(const {ident}_input* in, double* dr, double* di)",
        "{",
        "    memset(dr, 0, sizeof(double) * PLANT_DRIVERS * PLANT_SIZE);",
    ]
    geared = [f for f in drivers if f.circuit]
    if geared:
        rows = "(PLANT_SIZE - 2 * PLANT_DRIVERS)"
        lines.append(f"    memset(di, 0, sizeof(double) * {rows} * PLANT_SIZE);")
    else:
        lines.append("    (void)di;")
    if not any(f.motor for f in drivers):
        lines.append("    (void)in;")
    size = 2 * n + len(geared)
    for f in (f for f in drivers if f.steady):
        c, k = f.c, f.index
        ratio, kt = f"in->{c('motor_ratio')}", f"in->{c('motor_torque_constant')}"
        lines.append(
            f"    dr[{k * size + n + k}] = -{ratio} * {ratio} * (in->{c('motor_friction')} + "
            f"{kt} * {kt} / in->{c('motor_resistance')});"
        )
    for f in geared:
        c, k, row = f.c, f.index, f.current - 2 * n
        ratio = f"in->{c('motor_ratio')}"
        lines += [
            f"    dr[{k * size + n + k}] = -{ratio} * {ratio} * in->{c('motor_friction')};",
            f"    dr[{k * size + f.current}] = {ratio} * in->{c('motor_torque_constant')};",
            f"    di[{row * size + n + k}] = -in->{c('motor_torque_constant')} * {ratio} / "
            f"in->{c('motor_inductance')};",
            f"    di[{row * size + f.current}] = -in->{c('motor_resistance')} / "
            f"in->{c('motor_inductance')};",
        ]
    return lines + ["}", ""]


def _steady_lost(scene: Scene, ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """steady_lost(): whether a motor without inductance's torque is lost in round-off, and
    the speed error that moves it by the torques its crank balances."""
    lines = [
        "/* 1 where the current of a motor without inductance, (V - k r q') / R, carries more",
        " * round-off in its torque than solver.rtol of the torques its crank balances (the",
        " * torque, h and the inertia torque M_aa q'^2): a resistance so small that the motor",
        " * is a speed source to double precision, whose current no double can resolve.",
        " * speed_scale[a] (rad/s): the change of driver a's rate that moves its motor's",
        " * torque, r^2 k^2 / R times it, by |torque| + |h|, the torques its acceleration",
        " * balances (+inf without such a motor); the rate's error is held to rtol of it, so",
        " * that the current, the acceleration and the reactions, which carry the rate's",
        " * error times r^2 k^2 / R, are held to rtol of those torques too. */",
        f"static int steady_lost(const {ident}_input* in, const {ident}_output* out, "
        "const double* y,",
        "                       const double* m, double* speed_scale, fmu_evaluation* evaluation)",
        "{",
        "    int a;",
        "    for (a = 0; a < PLANT_DRIVERS; ++a) {",
        "        speed_scale[a] = INFINITY;",
        "    }",
    ]
    steady = [f for f in drivers if f.steady]
    if not steady:
        unused = "    (void)in, (void)out, (void)y, (void)m, (void)evaluation;"
        return lines + [unused, "    return 0;", "}", ""]
    n = len(drivers)
    for f in steady:
        k, c = f.index, f.c
        h = f"out->{member(f.name)}_{effort_of(f.driver)[0]}0"
        resistance, rate = f"in->{c('motor_resistance')}", f"y[{n + k}]"
        lines += [
            "    {",
            f"        const double ratio = in->{c('motor_ratio')};",
            f"        const double kt = in->{c('motor_torque_constant')};",
            f"        const double supply = in->{c('motor_voltage')}, back = kt * ratio * {rate};",
            f"        const double torque = ratio * (kt * {_current(f, 'y', n)} -",
            f"                                       in->{c('motor_friction')} * ratio * {rate});",
            "        const double noise =",
            "            4 * DBL_EPSILON * fabs(ratio * kt) * (fabs(supply) + fabs(back)) /",
            f"            {resistance};",
            "        const double scale =",
            f"            fabs(torque) + fabs({h}) + m[{k * n + k}] * {rate} * {rate};",
            f"        speed_scale[{k}] = (fabs(torque) + fabs({h})) /",
            f"                         fabs(ratio * ratio * kt * kt / {resistance});",
            "        if (noise > in->plant_rtol * scale) {",
            "            evaluation->status = FMU_DISCARD;",
            "            snprintf(evaluation->reason, sizeof evaluation->reason,",
            '                     "%s: the current of a motor without inductance lost in "',
            '                     "round-off (torque known to %.2g of %.2g N.m, beyond "',
            '                     "solver.rtol): %.2g ohm is too small; give it an inductance or "',
            '                     "more resistance; outputs are NaN",',
            f"                     {c_string(f.name)}, noise, scale, {resistance});",
            "            return 1;",
            "        }",
            "    }",
        ]
    return lines + ["    return 0;", "}", ""]


def _currents(ident: str, drivers: list[ForwardDriver], n: int) -> list[str]:
    """currents_rate(): the armature circuits, L i' = V - R i - k ratio q'."""
    lines = [
        "/* The motors' armature currents' rates. */",
        f"static void currents_rate(const {ident}_input* in, const dyad_real* y, dyad_real* dydt)",
        "{",
    ]
    geared = [f for f in drivers if f.circuit]
    if not geared:
        lines += ["    (void)in;", "    (void)y;", "    (void)dydt;"]
    for f in geared:
        c = f.c
        lines += [
            f"    dydt[{f.current}] = (dyad_real)((in->{c('motor_voltage')} - "
            f"in->{c('motor_resistance')} * (double)y[{f.current}] -",
            f"        in->{c('motor_torque_constant')} * in->{c('motor_ratio')} * "
            f"(double)y[{n + f.index}]) / in->{c('motor_inductance')});",
        ]
    return lines + ["}", ""]


def _state_io(drivers: list[ForwardDriver], ident: str) -> list[str]:
    """get_state() and put_state(): y = (q, q') from and into the input block."""
    get = [
        f"static void get_state(const {ident}_input* in, double* y)",
        "{",
    ]
    put = [f"static void put_state({ident}_input* in, const dyad_real* y)", "{"]
    n = len(drivers)
    for f in drivers:
        get.append(f"    y[{f.index}] = in->{f.c('position')};")
        get.append(f"    y[{n + f.index}] = in->{f.c('rate')};")
        put.append(f"    in->{f.c('position')} = (double)y[{f.index}];")
        put.append(f"    in->{f.c('rate')} = (double)y[{n + f.index}];")
        if f.circuit:
            get.append(f"    y[{f.current}] = in->{f.c('current')};")
            put.append(f"    in->{f.c('current')} = (double)y[{f.current}];")
    return [*get, "}", "", *put, "}", ""]


def _start(drivers: list[ForwardDriver], ident: str) -> list[str]:
    lines = [
        "/* The states from their start parameters; the controller has taken no step. */",
        "static void start(const fmu_model* model, void* input)",
        "{",
        f"    {ident}_input* in = ({ident}_input*)input;",
        "    (void)model;",
    ]
    for f in drivers:
        lines.append(f"    in->{f.c('position')} = in->{f.c('position_start')};")
        lines.append(f"    in->{f.c('rate')} = in->{f.c('rate_start')};")
        if f.circuit:
            lines.append(f"    in->{f.c('current')} = in->{f.c('motor_current')};")
    lines += [
        "    in->plant_h_next = in->plant_step_start;",
        "    in->plant_steps = 0.0;",
        "    in->plant_evaluations = 0.0;",
        "}",
        "",
    ]
    return lines


def _outputs(scene: Scene, drivers: list[ForwardDriver], ident: str) -> list[str]:
    """put_outputs(): the drivers' motion and currents at the state y with the
    accelerations a, or (``rates``: y the state's rates, a the jerks) their rates, a
    current without inductance's from the supply's derivative; 1 where such a current
    (or its rate) overflows double, which it then leaves NaN."""
    lines = [
        "/* The drivers' own outputs, or with `rates` their rates (y then y', a a'); 1 where",
        " * the current of a motor without inductance overflows (it is then NaN). */",
        f"static int put_outputs(const {ident}_input* in, {ident}_output* out, const double* y,",
        "                       const double* a, int rates)",
        "{",
    ]
    steady = [f for f in drivers if f.steady]
    if steady:
        lines.append("    int overflows = 0;")
    else:
        lines += ["    (void)in;", "    (void)rates;"]
    n = len(drivers)
    for f in drivers:
        lines.append(f"    out->{f.c('position')} = y[{f.index}];")
        lines.append(f"    out->{f.c('rate')} = y[{n + f.index}];")
        lines.append(f"    out->{f.c('acceleration')} = a[{f.index}];")
        if f.circuit:
            lines.append(f"    out->{f.c('current')} = y[{f.current}];")
        elif f.steady:
            slope, value = slope_member(_effort_input(scene, f)), f.c("motor_voltage")
            supply = f"(rates ? in->{slope} : in->{value})"
            lines += [
                "    {  /* NaN, not an infinity, where the current overflows */",
                f"        const double current = {_current(f, 'y', n, supply)};",
                f"        out->{f.c('current')} = isfinite(current) ? current : (double)NAN;",
                "        overflows |= !isfinite(current);",
                "    }",
            ]
    return lines + ["    return overflows;" if steady else "    return 0;", "}", ""]


def _no_outputs(scene: Scene, ident: str) -> list[str]:
    """plant_set_nan: every Real output NaN (no acceleration, so no scene at it)."""
    members = [o.member for o in scene.outputs if not o.integer] + list(output_members(scene))
    lines = [f"static void plant_set_nan({ident}_output* out)", "{"]
    lines += [f"    out->{m} = (double)NAN;" for m in dict.fromkeys(members)]
    return lines + ["}", ""]


def _state_table(scene: Scene, ident: str) -> list[str]:
    lines = [
        "/* What an FMU state keeps of the plant beyond its parameters and inputs. */",
        "static const fmu_model_state plant_states[] = {",
    ]
    for name, unit, c in _state_names(scene):
        lines.append(f"    {{{c_string(name)}, {c_string(unit)}, offsetof({ident}_input, {c})}},")
    return lines + ["};", ""]


def _input_lines(scene: Scene, ident: str) -> list[str]:
    """The interpolated inputs' table, their values t seconds on and the first input a
    line carries past the finite within h seconds."""
    inputs = interpolated_inputs(scene)
    lines = [
        "/* The inputs followed as straight lines over a step: each one's value and first",
        " * derivative. */",
        "static const fmu_input_rate plant_input_rates[] = {",
    ]
    lines += [
        f"    {{offsetof({ident}_input, {i.member}), offsetof({ident}_input, {slope_member(i)})}},"
        for i in inputs
    ]
    lines += ["};", "static const char* const plant_input_names[] = {"]
    lines += [f"    {c_string(i.name)}," for i in inputs]
    lines += [
        "};",
        "enum { PLANT_INPUTS = sizeof plant_input_rates / sizeof plant_input_rates[0] };",
        "",
        "/* The double at `offset` of an input block. */",
        f"static double* input_at({ident}_input* in, size_t offset)",
        "{",
        "    return (double*)(void*)((char*)in + offset);",
        "}",
        "",
        "/* The double at `offset` of a constant input block. */",
        f"static double input_value(const {ident}_input* in, size_t offset)",
        "{",
        "    return *(const double*)(const void*)((const char*)in + offset);",
        "}",
        "",
        "/* The inputs t seconds into a step: each value on along its derivative (one",
        " * without, as it is: -0 stays -0). */",
        f"static void inputs_at(const {ident}_input* in, double t, {ident}_input* now)",
        "{",
        "    size_t k;",
        "    *now = *in;",
        "    for (k = 0; k < PLANT_INPUTS; ++k) {",
        "        const double rate = input_value(in, plant_input_rates[k].rate_offset);",
        "        if (rate != 0) {",
        "            *input_at(now, plant_input_rates[k].value_offset) += t * rate;",
        "        }",
        "    }",
        "}",
        "",
    ]
    return lines + _input_checks(scene, ident)


def _input_checks(scene: Scene, ident: str) -> list[str]:
    """ramps(): whether any input moves; ramp_refused(): which one a step leaves infinite."""
    return [
        "/* Whether any input has a first derivative: the plant's motion then depends on t. */",
        f"static int ramps(const {ident}_input* in)",
        "{",
        "    size_t k;",
        "    for (k = 0; k < PLANT_INPUTS; ++k) {",
        "        if (input_value(in, plant_input_rates[k].rate_offset) != 0) {",
        "            return 1;",
        "        }",
        "    }",
        "    return 0;",
        "}",
        "",
        "/* The first input that its derivative carries past the finite within h seconds, or",
        " * -1. */",
        f"static int ramp_refused(const {ident}_input* in, double h)",
        "{",
        f"    {ident}_input end;",
        "    size_t k;",
        "    inputs_at(in, h, &end);",
        "    for (k = 0; k < PLANT_INPUTS; ++k) {",
        "        if (!isfinite(*input_at(&end, plant_input_rates[k].value_offset))) {",
        "            return (int)k;",
        "        }",
        "    }",
        "    return -1;",
        "}",
        "",
    ]


def _ramp_partials(scene: Scene, ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """put_input_seed() and ramp_partials(): what the inputs' derivatives add to df/dt."""
    lines = [
        "/* The inputs' derivatives as a seed of the inverse scene (its loads'; the efforts'",
        " * are no inputs of the scene and change nothing there). */",
        f"static void put_input_seed(const {ident}_input* in, {ident}_input* seed)",
        "{",
        "    size_t k;",
        "    memset(seed, 0, sizeof *seed);",
        "    for (k = 0; k < PLANT_INPUTS; ++k) {",
        "        const fmu_input_rate* r = &plant_input_rates[k];",
        "        *input_at(seed, r->value_offset) = input_value(in, r->rate_offset);",
        "    }",
        "}",
        "",
        "/* d(efforts)/dt of the drivers an effort drives, and d i'/dt of the motors' currents,",
        " * from the inputs' derivatives. */",
        f"static void ramp_partials(const {ident}_input* in, double* dr, double* di)",
        "{",
    ]
    n = len(drivers)
    if not any(f.circuit for f in drivers):
        lines.append("    (void)di;")
    for f in drivers:
        if f.motor is None:
            lines.append(f"    dr[{f.index}] = in->{slope_member(_effort_input(scene, f))};")
            continue
        if f.steady:
            c = f.c
            lines.append(
                f"    dr[{f.index}] = in->{c('motor_ratio')} * in->{c('motor_torque_constant')} "
                f"* in->{slope_member(_effort_input(scene, f))} / in->{c('motor_resistance')};"
            )
            continue
        lines += [
            f"    dr[{f.index}] = 0;",
            f"    di[{f.current - 2 * n}] = in->{slope_member(_effort_input(scene, f))} / "
            f"in->{f.c('motor_inductance')};",
        ]
    return lines + ["}", ""]


def _motion_seed(ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """put_motion_seed(): the drivers' motion's rates into a seed of the inverse scene."""
    lines = [
        "/* The rates of the drivers' motion into a seed of the inverse scene at `at`: v of",
        " * the positions, a of the rates, jerk of the accelerations. */",
        f"static void put_motion_seed(const {ident}_input* at, {ident}_input* seed, "
        "const double* v,",
        "                            const double* a, const double* jerk)",
        "{",
    ]
    if not any(f.position.angle for f in drivers):
        lines.append("    (void)at;")
    for f in drivers:
        k, m = f.index, f.position.member
        if f.position.angle:
            lines.append(f"    seed->{m} = dyad_scale((dyad_real)v[{k}], dyad_perp(at->{m}));")
        else:
            lines.append(f"    seed->{m} = v[{k}];")
        lines.append(f"    seed->{f.rate.member} = a[{k}];")
        lines.append(f"    seed->{f.acceleration.member} = jerk[{k}];")
    return lines + ["}", ""]


def _stiffness(ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """damping_rate(): how fast the damping of a motor without inductance slows its crank,
    (c + k^2 / R) / J_r (1/s), the fastest of the plant's; 0 where it has none."""
    lines = [
        "/* How fast the plant's stiffest motor without inductance slows its crank (1/s): the",
        " * damping it puts on it, r^2 (c + k^2 / R), over its rotor's share of the inertia,",
        " * r^2 J_r (a rotor without inertia gives no bound). A mechanism driven by efforts",
        " * alone is not stiff; the motors' circuits are circuit_values()'. */",
        f"static double damping_rate(const {ident}_input* in)",
        "{",
    ]
    limit = [
        "/* solver.explicit_limit: an internal step times a rate above it is the implicit",
        " * method's (a scene without motors has none). */",
        f"static double explicit_limit(const {ident}_input* in)",
        "{",
        *(
            ["    return in->plant_explicit_limit;"]
            if any(f.motor is not None for f in drivers)
            else ["    (void)in;", "    return INFINITY;"]
        ),
        "}",
        "",
    ]
    steady = [f for f in drivers if f.steady]
    if not steady:
        return limit + lines + ["    (void)in;", "    return 0;", "}", ""]
    lines.append("    double rate = 0;")
    for f in steady:
        k, rotor = f"in->{f.c('motor_torque_constant')}", f"in->{f.c('motor_rotor_inertia')}"
        lines += [
            f"    if ({rotor} > 0) {{",
            f"        rate = fmax(rate, (in->{f.c('motor_friction')} + {k} * {k} / "
            f"in->{f.c('motor_resistance')}) /",
            f"                              {rotor});",
            "    }",
        ]
    return limit + lines + ["    return rate;", "}", ""]


def _circuits(scene: Scene, ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """PLANT_CIRCUITS and circuit_values(): each motor with an inductance, the place of its
    current in y, its driver and its circuit's values at the inputs ``in``."""
    geared = [f for f in drivers if f.circuit]
    lines = [
        f"#define PLANT_CIRCUITS {len(geared)}",
        "",
        "/* The motors whose armature current is a state, with their circuits' values. */",
        f"static void circuit_values(const {ident}_input* in, plant_circuit* c)",
        "{",
    ]
    if not geared:
        return lines + ["    (void)in;", "    (void)c;", "}", ""]
    for j, f in enumerate(geared):
        lines += [
            f"    c[{j}].driver = {f.index};",
            f"    c[{j}].current = {f.current};",
            f"    c[{j}].resistance = in->{f.c('motor_resistance')};",
            f"    c[{j}].inductance = in->{f.c('motor_inductance')};",
            f"    c[{j}].torque_constant = in->{f.c('motor_torque_constant')};",
            f"    c[{j}].ratio = in->{f.c('motor_ratio')};",
            f"    c[{j}].voltage = in->{f.c('motor_voltage')};",
            f"    c[{j}].rotor_inertia = in->{f.c('motor_rotor_inertia')};",
            f"    c[{j}].friction = in->{f.c('motor_friction')};",
            f"    c[{j}].voltage_rate = in->{slope_member(_effort_input(scene, f))};",
            f"    c[{j}].eps = c[{j}].inductance / c[{j}].resistance;",
            f"    c[{j}].kr = c[{j}].torque_constant * c[{j}].ratio;",
        ]
    return lines + ["}", ""]


def _current_magnitudes(ident: str, drivers: list[ForwardDriver]) -> list[str]:
    """current_magnitudes(): each armature current's own scale for the relative
    tolerance, the current its supply drives at stall (|V| / R)."""
    lines = [
        "/* Each armature current's error is held relative to at least the current its supply",
        " * drives at stall (|V| / R), not to atol where it passes through zero (near no-load",
        " * speed a 1e-10 A tolerance would set the steps). */",
        f"static void current_magnitudes(const {ident}_input* in, dyad_ode_options* options)",
        "{",
    ]
    geared = [f for f in drivers if f.circuit]
    if not geared:
        return lines + ["    (void)in;", "    (void)options;", "}", ""]
    for f in geared:
        voltage, resistance = f.c("motor_voltage"), f.c("motor_resistance")
        lines.append(
            f"    options->magnitude[{f.current}] = "
            f"(dyad_real)(fabs(in->{voltage}) / in->{resistance});"
        )
    return lines + ["}", ""]


def _nearest_singular(scene: Scene, ident: str) -> list[str]:
    """not_positive_reason(): why M has no Cholesky factor, naming the dyad nearest its
    singular position (the largest amplification among the scene's dyads)."""
    dyads = [o for o in scene.outputs if o.name.endswith(".amplification") and not o.integer]
    lines = [
        "/* Why M(q) has no Cholesky factor, in evaluation->reason: near a toggle a ram's",
        " * effective mass grows without bound, so the dyad nearest its singular position",
        " * (the largest amplification of the scene's) is named. */",
        f"FMU_COLD static void not_positive_reason(const {ident}_output* out,",
        "                                        fmu_evaluation* evaluation)",
        "{",
    ]
    if not dyads:
        return lines + [
            "    (void)out;",
            "    snprintf(evaluation->reason, sizeof evaluation->reason,",
            '             "the drivers\' inertia matrix is not positive definite");',
            "}",
            "",
        ]
    names = ", ".join(c_string(o.name.removesuffix(".amplification")) for o in dyads)
    values = ", ".join(f"out->{o.member}" for o in dyads)
    return lines + [
        f"    static const char* const names[] = {{{names}}};",
        f"    const double amplification[] = {{{values}}};",
        "    size_t k, worst = 0;",
        "    for (k = 1; k < sizeof names / sizeof names[0]; ++k) {",
        "        if (!(amplification[k] <= amplification[worst])) {",
        "            worst = k;",
        "        }",
        "    }",
        "    snprintf(evaluation->reason, sizeof evaluation->reason,",
        '             "the drivers\' inertia matrix is not positive definite; nearest its "',
        '             "singular position: dyad %.64s (amplification %.3g)",',
        "             names[worst], amplification[worst]);",
        "}",
        "",
    ]


def _effort_input(scene: Scene, f: ForwardDriver) -> Input:
    """The input that drives f: its effort, or its motor's voltage."""
    member_of = f.c("motor_voltage") if f.motor is not None else f.c("effort")
    return next(i for i in public_inputs(scene) if i.member == member_of)


def state_table(scene: Scene) -> list[str]:
    """The table of the plant's states for the FMU layer (its FMU state's model states)."""
    return _state_table(scene, scene.identifier)


def behaviour_parts(scene: Scene) -> tuple[int, int, int, list[str]]:
    """The counts of drivers, of y's values and of the FMU state's model states, and the
    C generated for the scene's drivers (all but :func:`state_table`)."""
    ident = scene.identifier
    drivers = forward_drivers(scene)
    parts = (
        _motion_into(ident, drivers)
        + _equation_of_motion(scene, ident, drivers)
        + _steady_lost(scene, ident, drivers)
        + _currents(ident, drivers, len(drivers))
        + _jacobian_parts(scene, ident, drivers)
        + _state_io(drivers, ident)
        + _start(drivers, ident)
        + _outputs(scene, drivers, ident)
        + _no_outputs(scene, ident)
        + _input_lines(scene, ident)
        + _ramp_partials(scene, ident, drivers)
        + _motion_seed(ident, drivers)
        + _stiffness(ident, drivers)
        + _circuits(scene, ident, drivers)
        + _nearest_singular(scene, ident)
        + _current_magnitudes(ident, drivers)
    )
    return len(drivers), state_size(scene), len(_state_names(scene)), parts

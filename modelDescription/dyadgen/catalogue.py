"""The variables a generic dyad FMU, the crank drive and the motor have: where each one
lives, what it must look like and, for an output, the inputs it truly depends on. A table
of one of these kinds is checked against its catalogue (table.py)."""

from __future__ import annotations

import tomllib

from dyadgen.dyadtypes import MAY_BE_ZERO, PAIRS
from dyadgen.locations import INTERFACE_DIR
from dyadgen.settings import ON_SINGULAR, Setting


class Entry:
    """One variable a dyad type has: where it lives and what it must look like."""

    def __init__(
        self,
        lives: str,
        name: str,
        causality: str,
        unit: str | None,
        value_type: str = "Real",
        domain: dict | None = None,
        depends: tuple | None = None,
        description: str | None = None,
        start: float | None = None,
    ) -> None:
        self.lives = lives
        self.name = name
        self.causality = causality
        self.unit = unit
        self.value_type = value_type
        self.domain = domain or {}  # min, max, min_exclusive, max_exclusive
        # An output's true dependencies (input names) where the generator knows them.
        self.depends = depends
        self.description = description
        self.start = start  # where the catalogue fixes it (a setting's default item)


def setting_entry(setting: Setting) -> Entry:
    """The parameter of a setting of the FMU layer, an Enumeration."""
    return Entry(
        setting.lives,
        setting.name,
        "parameter",
        None,
        value_type="Enumeration",
        domain=setting.domain,
        description=setting.description,
        start=setting.start,
    )


def _length_domain(dyad_type: str, g: str) -> dict:
    may_be_zero = MAY_BE_ZERO[dyad_type]["mn".index(g)]
    return {"min": 0.0, "min_exclusive": not may_be_zero}


def _dyad_inputs(dyad_type: str) -> list[Entry]:
    d_m, e, d_n = PAIRS[dyad_type]
    entries = []
    for g in "mn":
        p = f"input.{g}"
        link = f"link_{g}"
        entries += [
            Entry(f"{p}.dir@angle", f"{link}.angle", "input", "rad"),
            Entry(f"{p}.omega", f"{link}.omega", "input", "rad/s"),
            Entry(f"{p}.epsilon", f"{link}.epsilon", "input", "rad/s2"),
            Entry(f"{p}.accel_d.x", f"{link}.accel_d.x", "input", "m/s2"),
            Entry(f"{p}.accel_d.y", f"{link}.accel_d.y", "input", "m/s2"),
            Entry(f"{p}.force.x", f"{link}.force.x", "input", "N"),
            Entry(f"{p}.force.y", f"{link}.force.y", "input", "N"),
            Entry(f"{p}.moment", f"{link}.moment", "input", "N.m"),
        ]
        if g == "m" and e == "T":  # link m slides: its length varies
            entries.append(
                Entry(
                    f"{p}.length",
                    f"{link}.length",
                    "input",
                    "m",
                    domain=_length_domain(dyad_type, g),
                )
            )
    if d_m == "T":
        entries.append(Entry("input.guide_k@angle", "guide_k.angle", "input", "rad"))
    if d_n == "T":
        entries.append(Entry("input.guide_p@angle", "guide_p.angle", "input", "rad"))
    return entries


def _dyad_parameters(dyad_type: str) -> list[Entry]:
    e = PAIRS[dyad_type][1]
    entries = []
    for g in "mn":
        p = f"input.{g}"
        link = f"link_{g}"
        if not (g == "m" and e == "T"):
            entries.append(
                Entry(
                    f"{p}.length",
                    f"{link}.length",
                    "parameter",
                    "m",
                    domain=_length_domain(dyad_type, g),
                )
            )
        entries += [
            Entry(f"{p}.com.x", f"{link}.com.x", "parameter", "m"),
            Entry(f"{p}.com.y", f"{link}.com.y", "parameter", "m"),
            Entry(f"{p}.mass", f"{link}.mass", "parameter", "kg", domain={"min": 0.0}),
            Entry(f"{p}.inertia", f"{link}.inertia", "parameter", "kg.m2", domain={"min": 0.0}),
        ]
    threshold_domain = {"min": 0.0, "max": 1.0, "min_exclusive": True, "max_exclusive": True}
    return entries + [
        Entry("input.gravity.x", "gravity.x", "parameter", "m/s2"),
        Entry("input.gravity.y", "gravity.y", "parameter", "m/s2"),
        Entry(
            "input.singular_threshold",
            "singular_threshold",
            "parameter",
            None,
            domain=threshold_domain,
        ),
        setting_entry(ON_SINGULAR),
    ]


def _dyad_outputs(dyad_type: str) -> list[Entry]:
    d_m, e, d_n = PAIRS[dyad_type]
    entries = []
    for pair in ("mk", "np", "mn"):
        for c in "xy":
            entries.append(Entry(f"result.r_{pair}.{c}", f"R_{pair}.{c}", "output", "N"))
    for pair, kind in (("mk", d_m), ("np", d_n), ("mn", e)):
        if kind == "T":
            entries.append(Entry(f"result.n_{pair}", f"N_{pair}", "output", "N"))
            entries.append(Entry(f"result.m_{pair}", f"M_{pair}", "output", "N.m"))
    return entries + [
        Entry("result.conditioning", "conditioning", "output", None),
        Entry("result.amplification", "amplification", "output", None),
        Entry("result.status", "status", "output", None, value_type="Integer"),
    ]


def dyad_catalogue(dyad_type: str) -> dict[str, Entry]:
    """Every variable of a dyad type, keyed by `lives`, in the canonical order."""
    entries = _dyad_inputs(dyad_type) + _dyad_parameters(dyad_type) + _dyad_outputs(dyad_type)
    interface = dyad_interface()
    texts = dict(interface["description"])
    texts.update(interface["description"].get(dyad_type, {}))
    independent = interface["independent"][dyad_type]
    inputs = [entry.name for entry in entries if entry.causality == "input"]
    for entry in entries:
        entry.description = entry.description or texts[entry.lives]
        if entry.causality == "output":
            entry.depends = tuple(name for name in inputs if name not in independent[entry.name])
    return {entry.lives: entry for entry in entries}


_INTERFACE: dict = {}


def dyad_interface() -> dict:
    """interface/dyad_interface.toml: the descriptions of the generic dyad FMUs'
    variables and the inputs each output does not depend on."""
    if not _INTERFACE:
        with open(INTERFACE_DIR / "dyad_interface.toml", "rb") as f:
            _INTERFACE.update(tomllib.load(f))
    return _INTERFACE


def dyad_absence_reason(dyad_type: str, lives: str) -> str:
    """Why a well-formed `lives` is not a variable of this type."""
    d_m, e, d_n = PAIRS[dyad_type]
    reasons = {
        "input.guide_k@angle": "its pair D_m is revolute, so it has no guide i_k",
        "input.guide_p@angle": "its pair D_n is revolute, so it has no guide i_p",
        "result.n_mk": "its pair D_m is revolute",
        "result.m_mk": "its pair D_m is revolute",
        "result.n_np": "its pair D_n is revolute",
        "result.m_np": "its pair D_n is revolute",
        "result.n_mn": "its pair E is revolute",
        "result.m_mn": "its pair E is revolute",
    }
    pairs = f"{dyad_type} (pairs D_m {d_m}, E {e}, D_n {d_n})"
    if lives in reasons:
        return f"the {pairs} dyad has no such variable: {reasons[lives]}"
    return f"the {pairs} dyad FMU has no variable for '{lives}'"


def drive_catalogue() -> dict[str, Entry]:
    """Every variable of the crank drive, keyed by `lives`, in the canonical order.

    The outputs' dependencies are exact: the angle and speed are states at the
    communication point, the motor torque a function of the speed alone, the
    acceleration (J + J_load) eps = T_m(omega) + tau_load - tau_demand + r_c x m_c g depends
    on the three load inputs, and so does the status (2 unless J + J_load > 0, 3 where the
    acceleration overflows)."""
    positive = {"min": 0.0, "min_exclusive": True}
    loads = ("load.torque", "load.inertia", "load.demand")
    entries = [
        Entry("input.load_torque", "load.torque", "input", "N.m"),
        Entry("input.load_inertia", "load.inertia", "input", "kg.m2"),
        Entry("input.load_demand", "load.demand", "input", "N.m"),
        Entry("input.stall_torque", "motor.stall_torque", "parameter", "N.m", domain=positive),
        Entry("input.no_load_speed", "motor.no_load_speed", "parameter", "rad/s", domain=positive),
        Entry("input.inertia", "inertia", "parameter", "kg.m2", domain=positive),
        Entry("input.crank_mass", "crank.mass", "parameter", "kg", domain={"min": 0.0}),
        Entry("input.crank_com_x", "crank.com.x", "parameter", "m"),
        Entry("input.crank_com_y", "crank.com.y", "parameter", "m"),
        Entry("input.gravity_x", "gravity.x", "parameter", "m/s2"),
        Entry("input.gravity_y", "gravity.y", "parameter", "m/s2"),
        Entry("input.start_angle", "start.angle", "parameter", "rad"),
        Entry("input.start_speed", "start.speed", "parameter", "rad/s"),
        Entry("result.angle", "crank.angle", "output", "rad", depends=()),
        Entry("result.speed", "crank.omega", "output", "rad/s", depends=()),
        Entry("result.acceleration", "crank.epsilon", "output", "rad/s2", depends=loads),
        Entry("result.motor_torque", "motor.torque", "output", "N.m", depends=()),
        Entry("result.status", "status", "output", None, value_type="Integer", depends=loads),
    ]
    return {entry.lives: entry for entry in entries}


def drive_absence_reason(lives: str) -> str:
    """Why a well-formed `lives` is not a variable of the drive."""
    if lives == ON_SINGULAR.lives:
        return (
            "the drive has no on_singular: it has no singular position, and a step it "
            "cannot integrate leaves its states where they were, so it cannot go on"
        )
    return f"the drive FMU has no variable for '{lives}'"


def motor_catalogue() -> dict[str, Entry]:
    """Every variable of the DC motor, keyed by `lives`, in the canonical order.

    The outputs' dependencies cover every inductance: the shaft torque r (k i - c r
    omega) depends on shaft.omega through the friction, and, without inductance (the
    current then u / R, u = V - k r omega), on both inputs through the current; the
    current depends on both inputs only then, which a parameter cannot rule out, and so
    does the status (3 where the current or the torque overflows)."""
    positive = {"min": 0.0, "min_exclusive": True}
    inputs = ("motor.voltage", "shaft.omega")
    entries = [
        Entry("input.voltage", "motor.voltage", "input", "V"),
        Entry("input.omega", "shaft.omega", "input", "rad/s"),
        Entry("input.resistance", "motor.resistance", "parameter", "Ohm", domain=positive),
        Entry("input.inductance", "motor.inductance", "parameter", "H", domain={"min": 0.0}),
        Entry(
            "input.torque_constant", "motor.torque_constant", "parameter", "N.m/A", domain=positive
        ),
        Entry("input.friction", "motor.friction", "parameter", "N.m.s/rad", domain={"min": 0.0}),
        Entry("input.ratio", "motor.ratio", "parameter", None, domain=positive),
        Entry("input.current_start", "motor.current_start", "parameter", "A"),
        Entry("result.torque", "shaft.torque", "output", "N.m", depends=inputs),
        Entry("result.current", "motor.current", "output", "A", depends=inputs),
        Entry("result.status", "status", "output", None, value_type="Integer", depends=inputs),
    ]
    return {entry.lives: entry for entry in entries}


def motor_absence_reason(lives: str) -> str:
    """Why a well-formed `lives` is not a variable of the motor."""
    if lives == ON_SINGULAR.lives:
        return (
            "the motor has no on_singular: it has no singular position, and a step that "
            "overflows leaves its current where it was, so it cannot go on"
        )
    return f"the motor FMU has no variable for '{lives}'"

#!/usr/bin/env python3
"""Generate everything an FMU of one model needs from its variable table.

The table ``modelDescription/<identifier>.toml`` is the single source of truth
for the interface of one FMU: names, value references, causalities, units,
start values, bounds, descriptions, where each value lives in the model's
structures and which inputs each output depends on. From it this script writes

    DIR/fmi2/modelDescription.xml      the FMI 2.0 model description
    DIR/fmi3/modelDescription.xml      the FMI 3.0 model description
    DIR/fmi3/buildDescription.xml      the FMI 3.0 build description
    DIR/<identifier>_model.c           the C variable table (see fmu/fmu_model.h)
    DIR/documentation/index.html       the FMU's documentation page

Usage:
    generate.py TABLE.toml --out DIR   generate the files of one table
    generate.py --update-golden        rewrite modelDescription/golden/*.xml
    generate.py --check-golden         exit 1 with a diff if a golden file differs

The table is validated first; every problem is reported with the file and the
variable it concerns, and nothing is written unless the table is valid.

Two kinds of model (``kind`` in ``[model]``):

    dyad    (the default) the kinetostatic solver of one Assur dyad, whose ``type``
            (RRR, RRT, RTR, TRT, RTT) fixes its variables; it lives in dyad_input
            and dyad_result (src/include/dyadfmu/types.h), behaviour fmu_dyad.c.
    drive   the crank drive, a DC motor with states (crank angle and speed)
            integrated inside doStep; no ``type``; it lives in fmu_drive_input and
            fmu_drive_output (fmu/fmu_drive.h), behaviour fmu_drive.c.

Value references start at 1: in FMI 3 the value reference 0 is the
independent variable `time`, which the FMI 3 description declares and the FMI 3
shim serves itself (the C table has no entry for it).

The instantiation token (FMI 3) / GUID (FMI 2) is "{" + a UUID formed from
the SHA-256 of a canonical JSON serialization of the whole table + "}": it
changes exactly when the table does. Output is deterministic (no dates).

Python 3.11 standard library only.
"""

from __future__ import annotations

import argparse
import difflib
import hashlib
import json
import math
import re
import sys
import tomllib
from pathlib import Path

import textsafe

HERE = Path(__file__).resolve().parent
GOLDEN_DIR = HERE / "golden"
#: The variable tables written by hand; the dyad FMUs' tables come from their scenes.
TABLES = ("drive.toml",)
#: The scenes of the generic per-type dyad FMUs, whose model descriptions are golden.
GOLDEN_SCENES = ("dyad_rrr.toml", "dyad_rrt.toml", "dyad_rtr.toml", "dyad_trt.toml",
                 "dyad_rtt.toml")
SCENES_DIR = HERE.parent / "scenes"
GENERATION_TOOL = "dyadfmu generate.py"

# ---------------------------------------------------------------------------
# What the generator knows about the dyads and the solver's structures
# ---------------------------------------------------------------------------

#: Pair kinds at (D_m, E, D_n) of each type.
PAIRS = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}

#: Whether the length of link m / n may be 0 (dyad_length_may_be_zero()).
MAY_BE_ZERO = {"RRR": (False, False), "RRT": (True, False), "RTR": (False, True),
               "TRT": (True, True), "RTT": (False, True)}

#: Per type: the conditioning figure, where it vanishes, and a typical use.
TYPE_NOTES = {
    "RRR": ("|i_m . j_n|", "links m and n are aligned (E on the line D_m D_n)",
            "the coupler and rocker of a four-bar linkage"),
    "RRT": ("|i_n . i_k|", "link n stands normal to the guide i_k",
            "the slider (m) and connecting rod (n) of a slider-crank"),
    "RTR": ("min(|i_beta . i_m|, |D_m D_n| / (l_m + l_n)), "
            "i_beta = (l_m i_m - l_n i_n) / |D_m D_n|",
            "the slot of link m stands normal to the line D_m D_n, or D_m and D_n coincide",
            "the slotted lever (m) and the block (n) of a quick-return mechanism"),
    "TRT": ("|j_k . i_p|", "the guides i_k and i_p are parallel",
            "two sliders on fixed guides pinned together at E"),
    "RTT": ("|j_k . i_m|", "the slot i_m of link m is parallel to the guide i_k",
            "the yoke (m) and the block (n) of a Scotch yoke"),
}

#: Units: name -> exponents of the SI base units (FMI BaseUnit attributes).
UNITS = {
    "rad": {"rad": 1},
    "rad/s": {"s": -1, "rad": 1},
    "rad/s2": {"s": -2, "rad": 1},
    "m": {"m": 1},
    "m/s2": {"m": 1, "s": -2},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "kg": {"kg": 1},
    "kg.m2": {"kg": 1, "m": 2},
}
BASE_UNIT_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

LOG_CATEGORIES = (
    ("logStatusError", "Errors: illegal call sequences, bad arguments, inputs the solver "
     "rejects (the offending variable is named)"),
    ("logStatusWarning", "Warnings, e.g. a singular configuration at exitInitializationMode"),
    ("logStatusDiscard", "Discarded steps: singular configuration or overflowing reactions "
     "(reaction outputs NaN)"),
    ("logCalls", "Calls into the FMU"),
)
#: The same categories (fmu_instance.c knows them by name) as the drive uses them.
DRIVE_LOG_CATEGORIES = (
    ("logStatusError", "Errors: illegal call sequences, bad arguments, inputs the model "
     "rejects (the offending variable is named, e.g. load.inertia when inertia + "
     "load.inertia is not positive)"),
    ("logStatusWarning", "Warnings"),
    ("logStatusDiscard", "Discarded steps: a step that would need more than 1e7 integrator "
     "substeps, or a crank state that is no longer finite (the state stays at the step's "
     "start)"),
    ("logCalls", "Calls into the FMU"),
)

#: The same categories as a scene uses them.
SCENE_LOG_CATEGORIES = (
    ("logStatusError", "Errors: illegal call sequences, bad arguments, values outside a "
     "variable's range (the variable is named)"),
    ("logStatusWarning", "Warnings, e.g. a singular dyad at exitInitializationMode"),
    ("logStatusDiscard", "Discarded steps: a singular dyad (named) or overflowing reactions "
     "(outputs NaN)"),
    ("logCalls", "Calls into the FMU"),
)

CAUSALITIES = ("input", "parameter", "output")
VALUE_TYPES = ("Real", "Integer")
VARIABLE_KEYS = {"name", "vr", "causality", "type", "unit", "start", "min", "max",
                 "min_exclusive", "max_exclusive", "description", "lives", "depends"}
MODEL_KEYS = {"kind", "type", "identifier", "description"}

# Member trees of dyad_input and dyad_result (types.h). Leaves: "real" (a
# dyad_real), "dir" (a unit dyad_vec2 set from an angle), "status", "enum".
_VEC2 = {"x": "real", "y": "real"}
_LINK = {"dir": "dir", "length": "real", "omega": "real", "epsilon": "real",
         "accel_d": _VEC2, "com": _VEC2, "mass": "real", "inertia": "real",
         "force": _VEC2, "moment": "real"}
INPUT_MEMBERS = {"m": _LINK, "n": _LINK, "guide_k": "dir", "guide_p": "dir",
                 "gravity": _VEC2, "singular_threshold": "real"}
RESULT_MEMBERS = {"status": "status", "field": "enum",
                  "r_mk": _VEC2, "r_np": _VEC2, "r_mn": _VEC2,
                  "n_mk": "real", "n_np": "real", "n_mn": "real",
                  "m_mk": "real", "m_np": "real", "m_mn": "real",
                  "denominator": "real", "conditioning": "real", "amplification": "real"}

#: dyad_field of each dyad_link member.
_LINK_FIELD = {"dir": "DIR", "length": "LENGTH", "omega": "OMEGA", "epsilon": "EPSILON",
               "accel_d": "ACCEL_D", "com": "COM", "mass": "MASS", "inertia": "INERTIA",
               "force": "FORCE", "moment": "MOMENT"}

# Members of fmu_drive_input and fmu_drive_output (fmu/fmu_drive.h), in declaration
# order. Leaves: "real" (a double), "state" (a double the model integrates itself,
# which no variable may set), "status" (the int status).
DRIVE_INPUT_MEMBERS = {
    "load_torque": "real", "load_inertia": "real", "stall_torque": "real",
    "no_load_speed": "real", "inertia": "real", "crank_mass": "real",
    "crank_com_x": "real", "crank_com_y": "real", "gravity_x": "real", "gravity_y": "real",
    "start_angle": "real", "start_speed": "real", "angle": "state", "speed": "state",
}
DRIVE_OUTPUT_MEMBERS = {
    "angle": "real", "speed": "real", "acceleration": "real", "motor_torque": "real",
    "status": "status",
}

#: The start parameter of each state of the drive.
_DRIVE_STATE_START = {"angle": "start.angle", "speed": "start.speed"}

#: struct.member.path[@angle]; a scene's flat members keep the case of its variables'
#: names (a pair point's parameter DYAD.D_m.x lives in input.DYAD_D_m_x). Matched whole.
LIVES_RE = re.compile(r"(input|result)\.([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)"
                      r"(@angle)?")


class Kind:
    """A kind of model: the C structs its variables live in and the behaviour
    that computes on them (fmu/fmu_model.h)."""

    def __init__(self, name, input_type, output_type, input_members, output_members,
                 header, behaviour):
        self.name = name
        self.input_type = input_type            # C type of the input block
        self.output_type = output_type          # C type of the output block
        self.input_members = input_members
        self.output_members = output_members
        self.header = header                    # the header declaring both and the behaviour
        self.behaviour = behaviour              # the fmu_behaviour object


DYAD = Kind("dyad", "dyad_input", "dyad_result", INPUT_MEMBERS, RESULT_MEMBERS,
            "fmu_dyad.h", "fmu_dyad_behaviour")
DRIVE = Kind("drive", "fmu_drive_input", "fmu_drive_output", DRIVE_INPUT_MEMBERS,
             DRIVE_OUTPUT_MEMBERS, "fmu_drive.h", "fmu_drive_behaviour")
KINDS = {"dyad": DYAD, "drive": DRIVE}


class TableError(Exception):
    """The table is invalid; args[0] is the list of problems."""


class Entry:
    """One variable a dyad type has: where it lives and what it must look like."""

    def __init__(self, lives, name, causality, unit, value_type="Real", domain=None,
                 depends=None, description=None):
        self.lives = lives
        self.name = name
        self.causality = causality
        self.unit = unit
        self.value_type = value_type
        self.domain = domain or {}  # min, max, min_exclusive, max_exclusive
        # An output's true dependencies (input names) where the generator knows them.
        self.depends = depends
        self.description = description


def catalogue(dyad_type: str) -> dict[str, Entry]:
    """Every variable of a dyad type, keyed by `lives`, in the canonical order."""
    d_m, e, d_n = PAIRS[dyad_type]
    sliding = {"m": e == "T", "n": False}
    entries: list[Entry] = []

    def length_domain(g):
        may_be_zero = MAY_BE_ZERO[dyad_type]["mn".index(g)]
        return {"min": 0.0, "min_exclusive": not may_be_zero}

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
        if sliding[g]:
            entries.append(Entry(f"{p}.length", f"{link}.length", "input", "m",
                                 domain=length_domain(g)))
    if d_m == "T":
        entries.append(Entry("input.guide_k@angle", "guide_k.angle", "input", "rad"))
    if d_n == "T":
        entries.append(Entry("input.guide_p@angle", "guide_p.angle", "input", "rad"))
    for g in "mn":
        p = f"input.{g}"
        link = f"link_{g}"
        if not sliding[g]:
            entries.append(Entry(f"{p}.length", f"{link}.length", "parameter", "m",
                                 domain=length_domain(g)))
        entries += [
            Entry(f"{p}.com.x", f"{link}.com.x", "parameter", "m"),
            Entry(f"{p}.com.y", f"{link}.com.y", "parameter", "m"),
            Entry(f"{p}.mass", f"{link}.mass", "parameter", "kg", domain={"min": 0.0}),
            Entry(f"{p}.inertia", f"{link}.inertia", "parameter", "kg.m2", domain={"min": 0.0}),
        ]
    entries += [
        Entry("input.gravity.x", "gravity.x", "parameter", "m/s2"),
        Entry("input.gravity.y", "gravity.y", "parameter", "m/s2"),
        Entry("input.singular_threshold", "singular_threshold", "parameter", None,
              domain={"min": 0.0, "max": 1.0, "min_exclusive": True, "max_exclusive": True}),
    ]
    for pair in ("mk", "np", "mn"):
        for c in "xy":
            entries.append(Entry(f"result.r_{pair}.{c}", f"R_{pair}.{c}", "output", "N"))
    for pair, kind in (("mk", d_m), ("np", d_n), ("mn", e)):
        if kind == "T":
            entries.append(Entry(f"result.n_{pair}", f"N_{pair}", "output", "N"))
            entries.append(Entry(f"result.m_{pair}", f"M_{pair}", "output", "N.m"))
    entries += [
        Entry("result.conditioning", "conditioning", "output", None),
        Entry("result.amplification", "amplification", "output", None),
        Entry("result.status", "status", "output", None, value_type="Integer"),
    ]
    interface = dyad_interface()
    texts = dict(interface["description"])
    texts.update(interface["description"].get(dyad_type, {}))
    independent = interface["independent"][dyad_type]
    inputs = [entry.name for entry in entries if entry.causality == "input"]
    for entry in entries:
        entry.description = texts[entry.lives]
        if entry.causality == "output":
            entry.depends = tuple(name for name in inputs
                                  if name not in independent[entry.name])
    return {entry.lives: entry for entry in entries}


_INTERFACE = {}


def dyad_interface() -> dict:
    """modelDescription/dyad_interface.toml: the descriptions of the generic dyad FMUs'
    variables and the inputs each output does not depend on."""
    if not _INTERFACE:
        with open(HERE / "dyad_interface.toml", "rb") as f:
            _INTERFACE.update(tomllib.load(f))
    return _INTERFACE


def _absence_reason(dyad_type: str, lives: str) -> str:
    """Why a well-formed `lives` is not a variable of this type."""
    d_m, e, d_n = PAIRS[dyad_type]
    reasons = {
        "input.guide_k@angle": "its pair D_m is revolute, so it has no guide i_k",
        "input.guide_p@angle": "its pair D_n is revolute, so it has no guide i_p",
        "result.n_mk": "its pair D_m is revolute", "result.m_mk": "its pair D_m is revolute",
        "result.n_np": "its pair D_n is revolute", "result.m_np": "its pair D_n is revolute",
        "result.n_mn": "its pair E is revolute", "result.m_mn": "its pair E is revolute",
    }
    pairs = f"{dyad_type} (pairs D_m {d_m}, E {e}, D_n {d_n})"
    if lives in reasons:
        return f"the {pairs} dyad has no such variable: {reasons[lives]}"
    return f"the {pairs} dyad FMU has no variable for '{lives}'"


def drive_catalogue() -> dict[str, Entry]:
    """Every variable of the crank drive, keyed by `lives`, in the canonical order.

    The outputs' dependencies are exact: the angle and speed are states at the
    communication point, the motor torque a function of the speed alone, the
    acceleration (J + J_load) eps = T_m(omega) + tau_load + r_c x m_c g depends on
    both load inputs, and so does the status (2 unless J + J_load > 0, 3 where the
    acceleration overflows)."""
    positive = {"min": 0.0, "min_exclusive": True}
    entries = [
        Entry("input.load_torque", "load.torque", "input", "N.m"),
        Entry("input.load_inertia", "load.inertia", "input", "kg.m2"),
        Entry("input.stall_torque", "motor.stall_torque", "parameter", "N.m", domain=positive),
        Entry("input.no_load_speed", "motor.no_load_speed", "parameter", "rad/s",
              domain=positive),
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
        Entry("result.acceleration", "crank.epsilon", "output", "rad/s2",
              depends=("load.torque", "load.inertia")),
        Entry("result.motor_torque", "motor.torque", "output", "N.m", depends=()),
        Entry("result.status", "status", "output", None, value_type="Integer",
              depends=("load.torque", "load.inertia")),
    ]
    return {entry.lives: entry for entry in entries}


def _drive_absence_reason(lives: str) -> str:
    """Why a well-formed `lives` is not a variable of the drive."""
    return f"the drive FMU has no variable for '{lives}'"


# ---------------------------------------------------------------------------
# `lives` grammar
# ---------------------------------------------------------------------------
class Lives:
    """A parsed `lives`: struct ("input" | "result"), member path, angle flag, and
    the kind of model whose structs it names."""

    def __init__(self, struct, path, angle, kind=DYAD):
        self.struct = struct
        self.path = path
        self.angle = angle
        self.kind = kind

    @property
    def target(self):
        if self.struct == "input":
            return "FMU_TARGET_INPUT_ANGLE" if self.angle else "FMU_TARGET_INPUT_REAL"
        return "FMU_TARGET_RESULT_STATUS" if self.path == "status" else "FMU_TARGET_RESULT_REAL"

    @property
    def offset(self):
        kind = self.kind
        if self.struct == "result":
            if kind is DYAD and self.path == "status":
                return "0"  # dyad_result.status is its first member
            return f"offsetof({kind.output_type}, {self.path})"
        return f"offsetof({kind.input_type}, {self.path})"

    @property
    def field(self):
        if self.struct == "result" or self.kind is not DYAD:
            return "DYAD_FIELD_NONE"
        parts = self.path.split(".")
        if parts[0] in ("m", "n"):
            return f"DYAD_FIELD_{parts[0].upper()}_{_LINK_FIELD[parts[1]]}"
        return f"DYAD_FIELD_{parts[0].upper()}"


def parse_lives(text, kind: Kind = DYAD) -> Lives:
    """Parse and resolve a `lives` string of a model of the given kind; raises
    ValueError with the reason."""
    if not isinstance(text, str):
        raise ValueError("must be a string")
    match = LIVES_RE.fullmatch(text)
    if not match:
        if kind is DYAD:
            raise ValueError("expected 'input.<member path>[@angle]' or 'result.<member path>'")
        raise ValueError(f"expected 'input.<member of {kind.input_type}>' or "
                         f"'result.<member of {kind.output_type}>'")
    struct, path, angle = match.group(1), match.group(2), bool(match.group(3))
    if kind is not DYAD:
        return _parse_flat_lives(kind, struct, path, angle)
    node = INPUT_MEMBERS if struct == "input" else RESULT_MEMBERS
    type_name = "dyad_input" if struct == "input" else "dyad_result"
    walked = []
    for part in path.split("."):
        if not isinstance(node, dict) or part not in node:
            raise ValueError(f"{type_name} has no member '{'.'.join(walked + [part])}'")
        node = node[part]
        walked.append(part)
    if isinstance(node, dict):
        raise ValueError(f"{type_name}.{path} is a structure, not a value; name a member "
                         f"({', '.join(sorted(node))})")
    if struct == "result" and angle:
        raise ValueError("'@angle' applies only to input directions")
    if node == "dir" and not angle:
        raise ValueError(f"{type_name}.{path} is a unit direction (dyad_vec2); "
                         f"write '{struct}.{path}@angle' to set it from an angle")
    if node != "dir" and angle:
        raise ValueError(f"'@angle' applies only to a direction (link dir, guide_k, guide_p), "
                         f"not to {type_name}.{path}")
    if node == "enum":
        raise ValueError(f"{type_name}.{path} is not a value an FMU variable can carry")
    return Lives(struct, path, angle)


def _parse_flat_lives(kind: Kind, struct: str, path: str, angle: bool) -> Lives:
    """`lives` of a model whose structs have only scalar members (the drive)."""
    members = kind.input_members if struct == "input" else kind.output_members
    type_name = kind.input_type if struct == "input" else kind.output_type
    if path not in members:
        raise ValueError(f"{type_name} has no member '{path}' (members: "
                         f"{', '.join(members)})")
    if angle and members[path] != "dir":
        raise ValueError(f"'@angle' applies only to a direction; "
                         f"{type_name}.{path} is a plain double")
    if members[path] == "dir" and not angle:
        raise ValueError(f"{type_name}.{path} is a unit direction; write "
                         f"'{struct}.{path}@angle' to set it from an angle")
    if members[path] == "state":
        raise ValueError(f"{type_name}.{path} is a state of the {kind.name}: it is set from "
                         f"'{_DRIVE_STATE_START[path]}' when initialization ends and advanced "
                         f"by doStep, so no variable may set it (read it through "
                         f"{kind.output_type}.{path})")
    return Lives(struct, path, angle, kind)


# ---------------------------------------------------------------------------
# Loading and validating a table
# ---------------------------------------------------------------------------
class Variable:
    """One validated row of the table, with its index in file order."""

    def __init__(self, raw: dict, index: int, kind: Kind = DYAD):
        self.raw = raw
        self.index = index
        self.name = raw["name"]
        self.vr = raw["vr"]
        self.causality = raw["causality"]
        self.type = raw["type"]
        self.unit = raw.get("unit")
        self.start = raw.get("start")
        self.min = raw.get("min")
        self.max = raw.get("max")
        self.min_exclusive = raw.get("min_exclusive", False)
        self.max_exclusive = raw.get("max_exclusive", False)
        self.description = raw["description"]
        self.lives = parse_lives(raw["lives"], kind)
        self.depends = list(raw.get("depends", []))


class Table:
    def __init__(self, path: Path, model: dict, variables: list[Variable]):
        self.path = path
        self.model = model
        self.variables = variables
        self.kind = KINDS[model.get("kind", "dyad")]
        self.type = model.get("type")  # the dyad type; None for other kinds
        self.identifier = model["identifier"]
        self.description = model["description"]
        self.by_name = {v.name: v for v in variables}
        self.token = instantiation_token(model, [v.raw for v in variables])

    def of(self, causality):
        return [v for v in self.variables if v.causality == causality]


def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _real(x):
    return float(x)


def load_table(path: Path) -> Table:
    """Read and validate a table; raises TableError listing every problem."""
    path = Path(path)
    fname = path.name
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as exc:
        raise TableError([f"{fname}: cannot read: {exc.strerror}"]) from None
    except tomllib.TOMLDecodeError as exc:
        raise TableError([f"{fname}: invalid TOML: {exc}"]) from None
    return table_from_data(data, path)


def table_from_data(data: dict, path: Path) -> Table:
    """Validate a table already read (a file's, or one a scene generates); `path` names
    it in messages and in the generated files."""
    path = Path(path)
    fname = path.name
    problems: list[str] = []

    def fail(message):
        problems.append(f"{fname}: {message}")

    for key in sorted(set(data) - {"model", "variable"}):
        fail(f"unknown top-level key '{key}' (expected [model] and [[variable]])")
    model = data.get("model")
    if not isinstance(model, dict):
        raise TableError([f"{fname}: missing [model] table"])
    for key in sorted(set(model) - MODEL_KEYS):
        fail(f"[model]: unknown key '{key}'")
    kind_name = model.get("kind", "dyad")
    if not isinstance(kind_name, str) or kind_name not in KINDS:
        raise TableError(problems + [f"{fname}: [model]: kind {kind_name!r} is not one of "
                                     f"{', '.join(KINDS)}"])
    kind = KINDS[kind_name]
    dyad_type = model.get("type")
    if kind is DYAD:
        if dyad_type not in PAIRS:
            raise TableError(problems + [f"{fname}: [model]: type {dyad_type!r} is not one of "
                                         f"{', '.join(PAIRS)}"])
        known = catalogue(dyad_type)
        owner = f"{dyad_type} dyad"

        def absence_reason(lives):
            return _absence_reason(dyad_type, lives)
    else:
        if "type" in model:
            fail(f"[model]: type {dyad_type!r} given, but only a dyad has a type "
                 f"(this table is of kind '{kind.name}')")
        known = drive_catalogue()
        owner = kind.name
        absence_reason = _drive_absence_reason
    identifier = model.get("identifier")
    if not isinstance(identifier, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", identifier):
        fail(f"[model]: identifier {identifier!r} must be a C identifier")
    problem = textsafe.description_problem(model.get("description"))
    if problem:
        fail(f"[model]: description {problem}")

    rows = data.get("variable")
    if not isinstance(rows, list) or not rows:
        raise TableError(problems + [f"{fname}: no [[variable]] entries"])

    variables: list[Variable] = []
    seen_names: dict[str, int] = {}
    seen_vrs: dict[int, str] = {}
    seen_lives: dict[str, str] = {}
    order = {"input": 0, "parameter": 1, "output": 2}
    last_rank = 0

    for k, raw in enumerate(rows):
        name = raw.get("name") if isinstance(raw, dict) else None
        label = (f"variable '{name}'" if isinstance(name, str) else f"variable #{k + 1}")
        if isinstance(raw, dict) and _is_number(raw.get("vr")):
            label += f" (vr {raw['vr']})"

        def bad(message, label=label):
            fail(f"{label}: {message}")

        if not isinstance(raw, dict):
            bad("must be a table")
            continue
        count_before = len(problems)
        for key in sorted(set(raw) - VARIABLE_KEYS):
            bad(f"unknown key '{key}'")
        for key in ("name", "vr", "causality", "type", "description", "lives"):
            if key not in raw:
                bad(f"missing key '{key}'")
        if problems[count_before:]:
            continue

        # name, vr
        if not isinstance(name, str) or not re.fullmatch(
                r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*", name):
            bad(f"name {name!r} is not a structured name (identifiers joined by '.')")
        elif name in seen_names:
            bad(f"duplicate name (also variable #{seen_names[name] + 1})")
        else:
            seen_names[name] = k
        vr = raw["vr"]
        if not isinstance(vr, int) or isinstance(vr, bool):
            bad(f"vr {vr!r} must be an integer")
        else:
            if vr in seen_vrs:
                bad(f"duplicate vr {vr} (also '{seen_vrs[vr]}')")
            else:
                seen_vrs[vr] = name
            if vr != k + 1:
                bad(f"vr {vr} is not consecutive: variable #{k + 1} in file order must have "
                    f"vr {k + 1} (vrs run 1, 2, 3, ...; vr 0 is FMI 3's time)")

        # causality, type, unit
        causality = raw["causality"]
        if causality not in CAUSALITIES:
            bad(f"unknown causality {causality!r} (expected one of {', '.join(CAUSALITIES)})")
            causality = None
        else:
            if order[causality] < last_rank:
                bad(f"{causality} after {CAUSALITIES[last_rank]}s: the table must list inputs, "
                    "then parameters, then outputs")
            last_rank = max(last_rank, order[causality])
        value_type = raw["type"]
        if value_type not in VALUE_TYPES:
            bad(f"unknown type {value_type!r} (expected one of {', '.join(VALUE_TYPES)})")
            value_type = None
        unit = raw.get("unit")
        if unit is not None and unit not in UNITS:
            bad(f"unknown unit {unit!r} (known: {', '.join(UNITS)}; omit it if dimensionless)")
            unit = "?"

        problem = textsafe.description_problem(raw["description"])
        if problem:
            bad(f"description {problem}")

        # lives, and the catalogue of the type
        entry = None
        try:
            lives = parse_lives(raw["lives"], kind)
        except ValueError as exc:
            bad(f"bad lives {raw['lives']!r}: {exc}")
            lives = None
        if lives is not None:
            key = raw["lives"]
            entry = known.get(key)
            if entry is None:
                bad(f"lives {key!r}: {absence_reason(key)}")
            elif key in seen_lives:
                bad(f"lives {key!r} is also the home of '{seen_lives[key]}'")
                entry = None
            else:
                seen_lives[key] = name
        if entry is not None:
            if causality is not None and causality != entry.causality:
                bad(f"causality '{causality}' but {entry.lives} is "
                    f"{'an' if entry.causality[0] in 'aeiou' else 'a'} {entry.causality} "
                    f"of the {owner}")
            if isinstance(name, str) and name != entry.name:
                bad(f"name does not match lives {entry.lives!r}: expected '{entry.name}'")
            if value_type is not None and value_type != entry.value_type:
                bad(f"type '{value_type}' but {entry.lives} is {entry.value_type}")
            if unit != "?" and unit != entry.unit:
                want = f"unit '{entry.unit}'" if entry.unit else "no unit (dimensionless)"
                have = f"unit '{unit}'" if unit else "no unit"
                bad(f"{have}, but {entry.lives} takes {want}")

        # start and bounds
        has_start = "start" in raw
        if causality in ("input", "parameter"):
            if not has_start:
                bad(f"start is missing (every {causality} needs one)")
            elif not _is_number(raw["start"]) or not math.isfinite(raw["start"]):
                bad(f"start {raw['start']!r} must be a finite number")
        elif causality == "output" and has_start:
            bad("start is present, but an output is calculated and must not have one")
        bounds_ok = True
        for key in ("min", "max"):
            if key in raw and (not _is_number(raw[key]) or not math.isfinite(raw[key])):
                bad(f"{key} {raw[key]!r} must be a finite number")
                bounds_ok = False
        for key in ("min_exclusive", "max_exclusive"):
            if key in raw:
                if not isinstance(raw[key], bool):
                    bad(f"{key} must be true or false")
                    bounds_ok = False
                elif raw[key] and key[:3] not in raw:
                    bad(f"{key} without {key[:3]}")
                    bounds_ok = False
        if causality == "output" and any(k in raw for k in ("min", "max")):
            bad("outputs carry no bounds")
            bounds_ok = False
        if bounds_ok and "min" in raw and "max" in raw and not raw["min"] < raw["max"]:
            bad(f"min {raw['min']!r} is not below max {raw['max']!r}")
            bounds_ok = False
        if bounds_ok and entry is not None and causality == entry.causality:
            domain = entry.domain
            declared = {key: raw[key] for key in ("min", "max") if key in raw}
            declared.update({key: True for key in ("min_exclusive", "max_exclusive")
                             if raw.get(key)})
            wanted = {key: value for key, value in domain.items() if value is not False}
            if {k: float(v) if k in ("min", "max") else v for k, v in declared.items()} != wanted:
                bad(f"bounds {_show_bounds(declared)} differ from the solver's domain of "
                    f"{entry.lives}: {_show_bounds(wanted)}")
        if bounds_ok and has_start and _is_number(raw["start"]) and math.isfinite(raw["start"]):
            s = raw["start"]
            if "min" in raw and (s <= raw["min"] if raw.get("min_exclusive") else s < raw["min"]):
                bad(f"start {s!r} is below min {raw['min']!r}"
                    f"{' (exclusive)' if raw.get('min_exclusive') else ''}")
            if "max" in raw and (s >= raw["max"] if raw.get("max_exclusive") else s > raw["max"]):
                bad(f"start {s!r} is above max {raw['max']!r}"
                    f"{' (exclusive)' if raw.get('max_exclusive') else ''}")

        # depends
        if causality == "output":
            if "depends" not in raw:
                bad("depends is missing (list the inputs this output depends on; [] if none)")
            elif not isinstance(raw["depends"], list) or not all(
                    isinstance(x, str) for x in raw["depends"]):
                bad("depends must be a list of input names")
        elif "depends" in raw and causality is not None:
            bad(f"depends is present, but only outputs have dependencies (this is "
                f"{'an' if causality[0] in 'aeiou' else 'a'} {causality})")

        if not problems[count_before:]:
            variables.append(Variable(raw, k, kind))

    # cross-variable checks
    if not problems:
        by_name = {v.name: v for v in variables}
        for v in variables:
            if v.causality != "output":
                continue
            label = f"variable '{v.name}' (vr {v.vr})"
            seen = set()
            for dep in v.depends:
                if dep in seen:
                    fail(f"{label}: depends lists '{dep}' twice")
                seen.add(dep)
                other = by_name.get(dep)
                if other is None:
                    fail(f"{label}: depends on unknown variable '{dep}'")
                elif other.causality != "input":
                    fail(f"{label}: depends on '{dep}', which is {'an' if other.causality[0] in 'aeiou' else 'a'} "
                         f"{other.causality}, not an input")
            entry = known[v.raw["lives"]]
            if entry.depends is not None and set(v.depends) != set(entry.depends):
                fail(f"{label}: depends {sorted(set(v.depends))} differ from the true "
                     f"dependencies of {entry.lives}: {sorted(entry.depends)} "
                     f"(missing {sorted(set(entry.depends) - set(v.depends))}, "
                     f"extra {sorted(set(v.depends) - set(entry.depends))})")
        for lives, entry in known.items():
            if lives not in seen_lives:
                fail(f"missing variable '{entry.name}' ({entry.causality}, lives {lives!r}): "
                     f"every {owner} FMU has it")
    if problems:
        raise TableError(problems)
    return Table(path, model, variables)


def _show_bounds(b):
    lo = "(" if b.get("min_exclusive") or "min" not in b else "["
    hi = ")" if b.get("max_exclusive") or "max" not in b else "]"
    return f"{lo}{b.get('min', '-inf')}, {b.get('max', 'inf')}{hi}"


# ---------------------------------------------------------------------------
# Instantiation token
# ---------------------------------------------------------------------------
_REAL_KEYS = ("start", "min", "max")


def canonical_table(model: dict, rows: list[dict]) -> str:
    """A canonical JSON text of the table: sorted keys, no spaces, numbers of
    Real-valued keys as floats (so `start = 0` and `start = 0.0` agree)."""
    norm = []
    for raw in rows:
        row = dict(raw)
        for key in _REAL_KEYS:
            if key in row and _is_number(row[key]):
                row[key] = float(row[key])
        norm.append(row)
    return json.dumps({"model": model, "variable": norm}, sort_keys=True,
                      separators=(",", ":"), ensure_ascii=True, allow_nan=False)


def instantiation_token(model: dict, rows: list[dict]) -> str:
    """"{" + UUID (version 8, RFC 9562 variant) from SHA-256 of the table + "}"."""
    digest = bytearray(hashlib.sha256(canonical_table(model, rows).encode("ascii")).digest()[:16])
    digest[6] = (digest[6] & 0x0F) | 0x80
    digest[8] = (digest[8] & 0x3F) | 0x80
    h = digest.hex()
    return "{" + f"{h[0:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:32]}" + "}"


# ---------------------------------------------------------------------------
# Writers
# ---------------------------------------------------------------------------
def _num(x) -> str:
    """A double as text that reads back to the same double."""
    return repr(float(x))


def _attr(value) -> str:
    return textsafe.xml_attribute(value)


def _element(indent: int, tag: str, attributes: list[tuple[str, object]], close=True,
             wrap=False) -> str:
    """One start tag; with wrap, one attribute a line (indented 2 deeper)."""
    pad = "  " * indent
    if wrap:
        inner = "\n".join(f'{pad}  {k}="{_attr(v)}"' for k, v in attributes)
        return f"{pad}<{tag}\n{inner}{'/>' if close else '>'}"
    text = "".join(f' {k}="{_attr(v)}"' for k, v in attributes)
    return f"{pad}<{tag}{text}{'/>' if close else '>'}"


#: The FMI shim's C files per FMI version (fmu/).
SHIM_FILES = {2: ["fmi2_functions.c"], 3: ["fmi3_functions.c", "fmi3_unsupported.c"]}


def source_files(table: Table, version: int) -> list[str]:
    """The C files an importer compiles to rebuild the FMI `version` binary."""
    shim = SHIM_FILES[version]
    if table.kind.name == "scene":
        types = sorted({d.type.lower() for d in table.scene.dyads})
        return (["dyad_common.c"] + [f"dyad_{t}.c" for t in types] +
                [f"{table.identifier}_scene.c", "fmu_instance.c", *shim,
                 f"{table.identifier}_model.c"])
    if table.kind is DRIVE:
        return ["fmu_drive.c", "fmu_instance.c", *shim, f"{table.identifier}_model.c"]
    return ["dyad_common.c", f"dyad_{table.type.lower()}.c", "dyad_tangent.c", "fmu_dyad.c",
            "fmu_instance.c", *shim, f"{table.identifier}_model.c"]


def _provides_directional_derivatives(table: Table) -> str:
    """The dyads differentiate their solve exactly; the drive has no derivative."""
    return "true" if table.kind is DYAD else "false"


def _used_units(table: Table) -> list[str]:
    used = {v.unit for v in table.variables if v.unit}
    return [u for u in UNITS if u in used]


def _unit_definitions(table: Table) -> list[str]:
    lines = ["  <UnitDefinitions>"]
    for unit in _used_units(table):
        exps = UNITS[unit]
        lines.append(f'    <Unit name="{_attr(unit)}">')
        lines.append(_element(3, "BaseUnit", [(b, exps[b]) for b in BASE_UNIT_ORDER if b in exps]))
        lines.append("    </Unit>")
    lines.append("  </UnitDefinitions>")
    return lines


def _common_tail(table: Table) -> list[str]:
    categories = (LOG_CATEGORIES if table.kind is DYAD else
                  SCENE_LOG_CATEGORIES if table.kind.name == "scene" else DRIVE_LOG_CATEGORIES)
    lines = ["  <LogCategories>"]
    lines += [_element(2, "Category", [("name", n), ("description", d)]) for n, d in categories]
    lines.append("  </LogCategories>")
    lines.append('  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.001"/>')
    return lines


def _variability(v: Variable) -> str:
    if v.causality == "parameter":
        return "fixed"
    return "discrete" if v.type == "Integer" else "continuous"


def _header(table: Table) -> list[str]:
    return ['<?xml version="1.0" encoding="UTF-8"?>',
            f"<!-- Generated by modelDescription/generate.py from "
            f"{textsafe.xml_comment(table.path.name)}; do not edit. -->"]


def fmi2_model_description(table: Table) -> str:
    lines = _header(table)
    lines.append(_element(0, "fmiModelDescription", [
        ("fmiVersion", "2.0"), ("modelName", table.identifier), ("guid", table.token),
        ("description", table.description), ("generationTool", GENERATION_TOOL),
        ("variableNamingConvention", "structured"), ("numberOfEventIndicators", "0")],
        close=False, wrap=True))
    lines.append(_element(1, "CoSimulation", [
        ("modelIdentifier", table.identifier),
        ("canHandleVariableCommunicationStepSize", "true"),
        ("canInterpolateInputs", "false"),
        ("canBeInstantiatedOnlyOncePerProcess", "false"),
        ("canGetAndSetFMUstate", "false"),
        ("canSerializeFMUstate", "false"),
        ("providesDirectionalDerivative", _provides_directional_derivatives(table))],
        close=False, wrap=True))
    lines.append("    <SourceFiles>")
    lines += [_element(3, "File", [("name", f)]) for f in source_files(table, 2)]
    lines.append("    </SourceFiles>")
    lines.append("  </CoSimulation>")
    lines += _unit_definitions(table)
    lines += _common_tail(table)
    lines.append("  <ModelVariables>")
    for v in table.variables:
        attrs = [("name", v.name), ("valueReference", v.vr), ("description", v.description),
                 ("causality", v.causality), ("variability", _variability(v))]
        if v.causality == "parameter":
            attrs.append(("initial", "exact"))
        elif v.causality == "output":
            attrs.append(("initial", "calculated"))
        lines.append(_element(2, "ScalarVariable", attrs, close=False))
        if v.type == "Integer":
            lines.append("      <Integer/>")
        else:
            typed = []
            if v.start is not None:
                typed.append(("start", _num(v.start)))
            if v.unit:
                typed.append(("unit", v.unit))
            if v.min is not None:
                typed.append(("min", _num(v.min)))
            if v.max is not None:
                typed.append(("max", _num(v.max)))
            lines.append(_element(3, "Real", typed))
        lines.append("    </ScalarVariable>")
    lines.append("  </ModelVariables>")
    index = {v.name: v.index + 1 for v in table.variables}  # 1-based, FMI 2
    lines.append("  <ModelStructure>")
    lines.append("    <Outputs>")
    for v in table.of("output"):
        deps = " ".join(str(i) for i in sorted(index[d] for d in v.depends))
        lines.append(_element(3, "Unknown", [("index", index[v.name]), ("dependencies", deps)]))
    lines.append("    </Outputs>")
    lines.append("    <InitialUnknowns>")
    for v in table.of("output"):
        lines.append(_element(3, "Unknown", [("index", index[v.name])]))
    lines.append("    </InitialUnknowns>")
    lines.append("  </ModelStructure>")
    lines.append("</fmiModelDescription>")
    return "\n".join(lines) + "\n"


def fmi3_model_description(table: Table) -> str:
    lines = _header(table)
    lines.append(_element(0, "fmiModelDescription", [
        ("fmiVersion", "3.0"), ("modelName", table.identifier),
        ("instantiationToken", table.token), ("description", table.description),
        ("generationTool", GENERATION_TOOL), ("variableNamingConvention", "structured")],
        close=False, wrap=True))
    lines.append(_element(1, "CoSimulation", [
        ("modelIdentifier", table.identifier),
        ("canHandleVariableCommunicationStepSize", "true"),
        ("canBeInstantiatedOnlyOncePerProcess", "false"),
        ("canGetAndSetFMUState", "false"),
        ("canSerializeFMUState", "false"),
        ("providesDirectionalDerivatives", _provides_directional_derivatives(table)),
        ("hasEventMode", "false"),
        ("canReturnEarlyAfterIntermediateUpdate", "false"),
        ("providesIntermediateUpdate", "false")], wrap=True))
    lines += _unit_definitions(table)
    lines += _common_tail(table)
    lines.append("  <ModelVariables>")
    lines.append(_element(2, "Float64", [
        ("name", "time"), ("valueReference", 0),
        ("description", "Simulation time (s), the independent variable"),
        ("causality", "independent"), ("variability", "continuous")]))
    for v in table.variables:
        attrs = [("name", v.name), ("valueReference", v.vr), ("description", v.description),
                 ("causality", v.causality), ("variability", _variability(v))]
        if v.causality == "parameter":
            attrs.append(("initial", "exact"))
        elif v.causality == "output":
            attrs.append(("initial", "calculated"))
        if v.unit:
            attrs.append(("unit", v.unit))
        if v.start is not None:
            attrs.append(("start", _num(v.start)))
        if v.min is not None:
            attrs.append(("min", _num(v.min)))
        if v.max is not None:
            attrs.append(("max", _num(v.max)))
        lines.append(_element(2, "Int32" if v.type == "Integer" else "Float64", attrs))
    lines.append("  </ModelVariables>")
    vr_of = {v.name: v.vr for v in table.variables}
    lines.append("  <ModelStructure>")
    for v in table.of("output"):
        deps = " ".join(str(r) for r in sorted(vr_of[d] for d in v.depends))
        lines.append(_element(2, "Output", [("valueReference", v.vr), ("dependencies", deps)]))
    for v in table.of("output"):
        lines.append(_element(2, "InitialUnknown", [("valueReference", v.vr)]))
    lines.append("  </ModelStructure>")
    lines.append("</fmiModelDescription>")
    return "\n".join(lines) + "\n"


def fmi3_build_description(table: Table) -> str:
    lines = _header(table)
    lines.append('<fmiBuildDescription fmiVersion="3.0">')
    lines.append(_element(1, "BuildConfiguration", [("modelIdentifier", table.identifier)],
                          close=False))
    lines.append('    <SourceFileSet language="C99">')
    lines += [_element(3, "SourceFile", [("name", f)])
              for f in source_files(table, 3)]
    lines.append("    </SourceFileSet>")
    lines.append("  </BuildConfiguration>")
    lines.append("</fmiBuildDescription>")
    return "\n".join(lines) + "\n"


def _c_string(text: str) -> str:
    return textsafe.c_string(text)


def _bounds_flags(v: Variable) -> str:
    flags = []
    if v.min is not None:
        flags.append("FMU_HAS_MIN")
    if v.max is not None:
        flags.append("FMU_HAS_MAX")
    if v.min_exclusive:
        flags.append("FMU_MIN_EXCLUSIVE")
    if v.max_exclusive:
        flags.append("FMU_MAX_EXCLUSIVE")
    return " | ".join(flags) if flags else "0"


def model_c(table: Table) -> str:
    causality = {"input": "FMU_INPUT", "parameter": "FMU_PARAMETER", "output": "FMU_OUTPUT"}
    value_type = {"Real": "FMU_REAL", "Integer": "FMU_INTEGER"}
    what = (f"the {table.type} dyad FMU" if table.kind is DYAD else
            f"the scene {table.identifier}" if table.kind.name == "scene" else
            "the crank drive FMU")
    source = textsafe.c_comment(f"scene {table.path.name}" if table.kind.name == "scene" else
                                f"modelDescription/{table.path.name}")
    lines = [
        f"/* {table.identifier}_model.c: the variable table of {what}.",
        f" * Generated by modelDescription/generate.py from {source};",
        " * do not edit: change the table and regenerate. The model descriptions are",
        " * generated from the same table, with the same instantiation token. */",
        "#include <stddef.h>",
        "",
        f'#include "{table.kind.header}"',
        "",
        "static const fmu_variable variables[] = {",
        "    /* vr, name, unit, causality, type, target, offset,",
        "       start, min, max, bounds */",
    ]
    for v in table.variables:
        lines.append(
            f"    {{{v.vr}u, {_c_string(v.name)}, {_c_string(v.unit or '')}, "
            f"{causality[v.causality]}, {value_type[v.type]}, {v.lives.target}, "
            f"{v.lives.offset},\n"
            f"     {_num(v.start if v.start is not None else 0.0)}, "
            f"{_num(v.min if v.min is not None else 0.0)}, "
            f"{_num(v.max if v.max is not None else 0.0)}, {_bounds_flags(v)}}},")
    lines.append("};")
    lines.append("")
    vr_limit = max(v.vr for v in table.variables) + 1
    index_of = [-1] * vr_limit
    for v in table.variables:
        index_of[v.vr] = v.index
    lines.append("/* Index into variables[] of each value reference; -1 where none (vr 0 is")
    lines.append(" * FMI 3's time, served by the FMI 3 shim). */")
    lines.append(f"static const short index_of_vr[{vr_limit}] = {{")
    for start in range(0, vr_limit, 12):
        lines.append("    " + ", ".join(str(i) for i in index_of[start:start + 12]) + ",")
    lines.append("};")
    lines.append("")
    if table.kind is DYAD:
        feeds = [(v.lives.field, v.index) for v in table.variables
                 if v.causality != "output" and v.lives.field != "DYAD_FIELD_NONE"]
        lines.append("/* The variable that feeds each input field of the core, for errors. */")
        lines.append("static const fmu_dyad_feed feeds[] = {")
        lines += [f"    {{{field}, {index}}}," for field, index in feeds]
        lines.append("};")
        lines.append("")
        t = table.type.lower()
        lines.append(f"static const fmu_dyad_data dyad = {{dyad_solve_{t}, &dyad_tangent_{t}, "
                     f"feeds, {len(feeds)}}};")
        lines.append("")
        data = "&dyad"
    else:
        data = "NULL"  # the drive's behaviour needs no model data
    lines.append(f"const fmu_model fmu_this_model = {{{_c_string(table.identifier)}, "
                 f"{_c_string(table.token)},")
    lines.append(f"                                  variables, {len(table.variables)}, "
                 f"index_of_vr, {vr_limit}, &{table.kind.behaviour}, {data}}};")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------
# Documentation
# ---------------------------------------------------------------------------
_CSS = """body { font-family: sans-serif; max-width: 72em; margin: 2em auto; padding: 0 1em;
       line-height: 1.45; color: #222; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #eee; }
code { background: #f4f4f4; padding: 0 0.2em; }
td.num { text-align: right; white-space: nowrap; }"""


def _h(text) -> str:
    return textsafe.html(text)


def _fmt_bounds(v: Variable) -> str:
    if v.min is None and v.max is None:
        return ""
    lo = ("(" if v.min_exclusive else "[") if v.min is not None else "("
    hi = (")" if v.max_exclusive else "]") if v.max is not None else ")"
    lo_v = _num(v.min) if v.min is not None else "-inf"
    hi_v = _num(v.max) if v.max is not None else "inf"
    return f"{lo}{lo_v}, {hi_v}{hi}"


def documentation(table: Table) -> str:
    if table.kind is DRIVE:
        return drive_documentation(table)
    t = table.type
    d_m, e, d_n = PAIRS[t]
    conditioning, singular, typical = TYPE_NOTES[t]
    guides = []
    if d_m == "T":
        guides.append("<code>i_k</code> (input <code>guide_k.angle</code>) at D_m")
    if e == "T":
        guides.append("<code>i_m</code> (link m itself) at E")
    if d_n == "T":
        guides.append("<code>i_p</code> (input <code>guide_p.angle</code>) at D_n")
    zero = [f"l_{g}" for g, ok in zip("mn", MAY_BE_ZERO[t]) if ok]
    sliders = [v.name for v in table.of("input") if v.name.endswith(".length")]
    o = []
    o.append("<!DOCTYPE html>")
    o.append('<html lang="en">')
    o.append("<head>")
    o.append('<meta charset="utf-8">')
    o.append(f"<title>{_h(table.identifier)}: joint reactions of an {t} dyad</title>")
    o.append(f"<style>\n{_CSS}\n</style>")
    o.append("</head>")
    o.append("<body>")
    o.append(f"<h1>{_h(table.identifier)}: joint reactions of an {t} dyad</h1>")
    o.append(f"<p>{_h(table.description)}</p>")
    o.append("<p>A co-simulation FMU (FMI 2.0 and FMI 3.0) around the closed-form "
             "kinetostatic solver of dyadfmu. At every communication point it takes the "
             "current position, velocity and acceleration of the two links of one Assur "
             "dyad, their active loads and their mass properties, adds to each link its "
             "weight and its d'Alembert inertia force and moment, and returns the reactions "
             "in the dyad's three kinematic pairs. It has no states: the outputs are a pure "
             "function of the inputs and parameters, and <code>doStep</code> only evaluates "
             f"them. Typical use: {_h(typical)}.</p>")

    o.append("<h2>The dyad</h2>")
    o.append("<p>The dyad has links <code>m</code> and <code>n</code> and three pairs: "
             "<code>D_m</code> joins link m to the external link k, <code>E</code> joins m "
             "to n, <code>D_n</code> joins n to the external link p. R is a revolute pair "
             "(a pin), T a translational pair (a slider on a guide).</p>")
    o.append("<table>")
    o.append("<tr><th>type</th><th>D_m</th><th>E</th><th>D_n</th><th>guides</th>"
             "<th>lengths that may be 0</th></tr>")
    o.append(f"<tr><td>{t}</td><td>{d_m}</td><td>{e}</td><td>{d_n}</td>"
             f"<td>{', '.join(guides) or 'none'}</td><td>{', '.join(zero) or 'none'}</td></tr>")
    o.append("</table>")
    if sliders:
        o.append(f"<p>Because the pair E slides along link m, the length l_m = |D_m E| "
                 f"changes with the motion and is an input (<code>{_h(sliders[0])}</code>); "
                 "every other length is a fixed parameter.</p>")

    o.append("<h2>Sign conventions</h2>")
    o.append("<ul>")
    for item in (
        "All vectors are given in one global frame: x and y span the plane of motion, z "
        "points out of it. Angles, angular velocities, angular accelerations and moments "
        "are z components, positive counter-clockwise.",
        "The angle of link g (<code>link_g.angle</code>) is the direction of the unit vector "
        "<code>i_g</code>, which points from D_g towards E, measured from the x axis. "
        "<code>j_g</code> is <code>i_g</code> turned by +90 degrees. Hence "
        "E = D_m + l_m i_m = D_n + l_n i_n.",
        "The centre of mass <code>S_g</code> is given in the link's own frame: "
        "S_g = D_g + com.x i_g + com.y j_g.",
        "A guide angle (<code>guide_k.angle</code>, <code>guide_p.angle</code>) is the "
        "direction <code>i_k</code> or <code>i_p</code> of the guide on the external link, "
        "from the x axis; its normal is j = i turned by +90 degrees.",
        "<code>link_g.accel_d</code> is the absolute acceleration of point D_g; "
        "<code>omega</code> and <code>epsilon</code> are the absolute angular velocity and "
        "acceleration of the link. The active load <code>force</code> acts at the centre "
        "of mass; <code>moment</code> is a pure couple. Gravity acts on each mass.",
        "<code>R_mk</code> is the force on link m from link k at D_m; <code>R_np</code> the "
        "force on link n from link p at D_n; <code>R_mn</code> the force on link m from link "
        "n at E (link n receives -R_mn). All in global components.",
        "For a translational pair, <code>N_..</code> is its normal force, the reaction's "
        "component along the guide's normal (R_mk . j_k, R_np . j_p, R_mn . j_m), and "
        "<code>M_..</code> the reactive moment it transmits: on m from k about D_m, on n from "
        "p about D_n, on m from n about E (n receives -M_mn). A revolute pair transmits no "
        "moment, so these outputs exist only for the sliding pairs of this type.",
    ):
        o.append(f"<li>{item}</li>")
    o.append("</ul>")

    o.append("<h2>Variables</h2>")
    o.append("<p>Value references as in the model descriptions (in FMI 3, value reference 0 "
             "is the independent variable <code>time</code>). Inputs may change at every "
             "communication point; parameters are fixed once initialization ends.</p>")
    o.append("<table>")
    o.append("<tr><th>vr</th><th>name</th><th>causality</th><th>type</th><th>unit</th>"
             "<th>start</th><th>range</th><th>description</th></tr>")
    for v in table.variables:
        start = _num(v.start) if v.start is not None else ""
        o.append(f"<tr><td class=\"num\">{v.vr}</td><td><code>{_h(v.name)}</code></td>"
                 f"<td>{v.causality}</td><td>{v.type}</td><td>{_h(v.unit or '-')}</td>"
                 f"<td class=\"num\">{start}</td><td class=\"num\">{_h(_fmt_bounds(v))}</td>"
                 f"<td>{_h(v.description)}</td></tr>")
    o.append("</table>")
    o.append("<p>A range in brackets is inclusive, in parentheses exclusive. Setting a "
             "value outside its range, or a value that is not finite, is rejected with an "
             "error that names the variable.</p>")

    o.append("<h2>Status codes</h2>")
    o.append("<table>")
    o.append("<tr><th><code>status</code></th><th>meaning</th><th>reaction outputs</th></tr>")
    for code, name, meaning, outputs in (
        (0, "ok", "solved", "finite"),
        (1, "singular", "the conditioning is below <code>singular_threshold</code>: the dyad "
         "is at or too near its singular position and cannot carry its load with finite "
         "reactions", "NaN"),
        (2, "invalid input", "an input or parameter is outside the solver's domain (not "
         "finite, a negative mass or inertia, a length that must be positive but is not, "
         "...)", "NaN"),
        (3, "out of range", "the inputs were valid and conditioned, but a load or reaction "
         "overflows double precision", "NaN"),
    ):
        o.append(f"<tr><td class=\"num\">{code}</td><td>{name}: {meaning}</td>"
                 f"<td>{outputs}</td></tr>")
    o.append("</table>")

    o.append("<h2>Singular positions and invalid inputs</h2>")
    o.append(f"<p>The closed-form solution of the {t} dyad divides by one number that "
             f"vanishes at its singular position, where {_h(singular)}. The output "
             f"<code>conditioning</code> is <code>{_h(conditioning)}</code>, in [0, 1]; "
             "<code>amplification</code> = data factor / conditioning bounds the round-off: "
             "eps x amplification times the largest reaction of a unit (N or N.m) bounds the "
             "error of every reaction of that unit, the data factor (1 to 1/eps) being how "
             "much the load terms cancel as they are summed. Only the conditioning decides "
             "the singular status. When the conditioning "
             "falls below the parameter <code>singular_threshold</code> (default "
             "sqrt(DBL_EPSILON) = 1.49e-8, where round-off still leaves half of the digits) "
             "the solve reports status 1.</p>")
    o.append("<ul>")
    o.append("<li>A singular or overflowing configuration during a step: <code>doStep</code> "
             "returns <code>Discard</code> and logs the reason (category "
             "<code>logStatusDiscard</code>) with the time and the conditioning; the reaction "
             "outputs are NaN and <code>status</code> tells which case it is. At "
             "<code>exitInitializationMode</code> the same is a <code>Warning</code>.</li>")
    o.append("<li>An input the solver rejects: <code>doStep</code> returns <code>Error</code> "
             "and logs the offending variable and its value (category "
             "<code>logStatusError</code>); outputs are NaN and <code>status</code> is 2.</li>")
    o.append("<li>A value outside the range of its variable, or not finite, is rejected "
             "already by the setter, which returns <code>Error</code> naming the variable.</li>")
    o.append("<li>No NaN leaves the FMU without a status other than 0 and a logged "
             "reason.</li>")
    o.append("</ul>")

    o.append("<h2>Directional derivatives</h2>")
    o.append("<p><code>fmi2GetDirectionalDerivative</code> and "
             "<code>fmi3GetDirectionalDerivative</code> give the exact derivative of every Real "
             "output with respect to the inputs (knowns must be inputs, unknowns Real "
             "outputs), at the current inputs: the equilibrium equations are differentiated "
             "implicitly and the dyad is solved once more, with no finite-difference step. "
             "Angles count in rad, so a derivative with respect to an angle is per rad. At a "
             "singular configuration the call returns <code>Discard</code> and NaN.</p>")

    return _closing(o, table)


def _closing(o: list[str], table: Table) -> str:
    """The identity section shared by every documentation page, and the end."""
    o.append("<h2>Identity</h2>")
    o.append(f"<p>Model identifier <code>{_h(table.identifier)}</code>, instantiation token "
             f"(FMI 2 GUID) <code>{_h(table.token)}</code>: a hash of the variable table "
             "<code>" + _h(table.path.name) + "</code>, from which this page, both model "
             "descriptions and the FMU's C variable table are generated.</p>")
    o.append("</body>")
    o.append("</html>")
    return "\n".join(o) + "\n"


def _variable_rows(table: Table) -> list[str]:
    o = ["<table>",
         "<tr><th>vr</th><th>name</th><th>causality</th><th>type</th><th>unit</th>"
         "<th>start</th><th>range</th><th>description</th></tr>"]
    for v in table.variables:
        start = _num(v.start) if v.start is not None else ""
        o.append(f"<tr><td class=\"num\">{v.vr}</td><td><code>{_h(v.name)}</code></td>"
                 f"<td>{v.causality}</td><td>{v.type}</td><td>{_h(v.unit or '-')}</td>"
                 f"<td class=\"num\">{start}</td><td class=\"num\">{_h(_fmt_bounds(v))}</td>"
                 f"<td>{_h(v.description)}</td></tr>")
    o.append("</table>")
    return o


def drive_documentation(table: Table) -> str:
    """The documentation page of the crank drive (fmu/fmu_drive.c)."""
    o = []
    o.append("<!DOCTYPE html>")
    o.append('<html lang="en">')
    o.append("<head>")
    o.append('<meta charset="utf-8">')
    o.append(f"<title>{_h(table.identifier)}: a DC motor driving a crank</title>")
    o.append(f"<style>\n{_CSS}\n</style>")
    o.append("</head>")
    o.append("<body>")
    o.append(f"<h1>{_h(table.identifier)}: a DC motor driving a crank</h1>")
    o.append(f"<p>{_h(table.description)}</p>")
    o.append("<p>A co-simulation FMU (FMI 2.0 and FMI 3.0) of the drive of a mechanism: a DC "
             "motor with a linear torque-speed characteristic turns, on a rigid shaft, a crank "
             "about the fixed pivot O. Unlike the dyad FMUs of dyadfmu it has states, the "
             "crank's angle and speed, which <code>doStep</code> integrates over each "
             "communication step. The mechanism the crank drives (typically built from dyad "
             "FMUs) acts on it through two inputs, <code>load.torque</code> and "
             "<code>load.inertia</code>.</p>")

    o.append("<h2>The model</h2>")
    o.append("<p>The crank turns about O at the angle phi = <code>crank.angle</code>, the speed "
             "omega = <code>crank.omega</code> and the acceleration eps = "
             "<code>crank.epsilon</code>, which obeys</p>")
    o.append("<pre>(inertia + load.inertia) eps = T_stall (1 - omega / omega_0) + load.torque "
             "+ r_c x m_c g</pre>")
    o.append("<ul>")
    for item in (
        "<code>inertia</code> is the inertia of the rotor and the crank about O, "
        "<code>load.inertia</code> the inertia the driven mechanism adds at the crank "
        "(see below); their sum must be positive.",
        "T_m = T_stall (1 - omega / omega_0) is the motor torque (output "
        "<code>motor.torque</code>), with T_stall = <code>motor.stall_torque</code> the torque "
        "at standstill and omega_0 = <code>motor.no_load_speed</code> the speed at which it "
        "vanishes. The characteristic is linear throughout: above omega_0 the motor brakes, "
        "turned backwards it delivers more than T_stall.",
        "<code>load.torque</code> is the torque of the driven mechanism on the crank about O "
        "at zero crank acceleration; the mechanism's whole torque on the crank is "
        "<code>load.torque - load.inertia * crank.epsilon</code>.",
        "r_c x m_c g is the moment of the crank's weight about O: m_c = "
        "<code>crank.mass</code>, g = (<code>gravity.x</code>, <code>gravity.y</code>), and "
        "r_c = (com.x cos phi - com.y sin phi, com.x sin phi + com.y cos phi) is the crank's "
        "centre of mass (<code>crank.com.x</code>, <code>crank.com.y</code> in the crank's "
        "own frame) turned by phi; r_c x m_c g = m_c (r_c,x g_y - r_c,y g_x).",
        "All angles, speeds, accelerations and torques are z components, positive "
        "counter-clockwise; the crank angle is the direction of the crank frame's x axis from "
        "the global x axis.",
    ):
        o.append(f"<li>{item}</li>")
    o.append("</ul>")

    o.append("<h2>States and the integrator</h2>")
    o.append("<p>The state (phi, omega) starts from the parameters <code>start.angle</code> "
             "and <code>start.speed</code> when initialization ends. "
             "<code>doStep(t, h)</code> holds the inputs over the communication step and "
             "integrates the state from t to t + h with the classical 4th-order Runge-Kutta "
             "method (RK4) in n equal substeps, n = ceil(h / dt_max), where dt_max is the "
             "smaller of a twentieth of the motor's mechanical time constant "
             "tau = (inertia + load.inertia) omega_0 / T_stall and the time the crank takes "
             "to turn 0.005 rad at the speed at the start of the step (no such limit at "
             "standstill), and dt_max = h if the step is shorter.</p>")
    o.append("<p>The state has two components and is smooth (gravity enters as a sine of "
             "phi), so an explicit method of high order is accurate and cheap once the substep "
             "resolves the one stiff scale, the motor's damping T_stall / omega_0: no Newton "
             "iteration is needed, and the result depends on nothing but the state, the "
             "inputs and the step, which keeps a co-simulation reproducible.</p>")
    o.append("<p>After a step <code>crank.angle</code> and <code>crank.omega</code> are the "
             "state at t + h, and <code>crank.epsilon</code> and <code>motor.torque</code> are "
             "evaluated at that state with the current inputs. The angle, the speed and the "
             "motor torque therefore do not depend on the inputs at a communication point (a "
             "new input acts only over the next step); the acceleration depends on "
             "<code>load.torque</code> and <code>load.inertia</code> at once, and "
             "<code>status</code> on <code>load.inertia</code>.</p>")

    o.append("<h2>Coupling with a mechanism</h2>")
    o.append("<p>A co-simulation master reads <code>crank.angle</code>, "
             "<code>crank.omega</code> and <code>crank.epsilon</code>, solves the mechanism's "
             "kinematics, feeds its dyad FMUs, and returns the torque T_mech the mechanism "
             "puts on the crank about O (for a crank that is link k of a dyad at its pair "
             "D_m = A, the mechanism acts on the crank with -R_mk at A, so "
             "T_mech = -(r_OA x R_mk)). At a given position and speed T_mech is affine in the "
             "crank acceleration, T_mech = tau_0 - J_eff eps: the dyads' reactions are linear "
             "in their accelerations, and these are affine in eps. J_eff is the mechanism's "
             "effective inertia at the crank. The master passes T_mech in one of two "
             "ways:</p>")
    o.append("<ul>")
    o.append("<li><b>Explicit:</b> <code>load.inertia</code> = 0 and <code>load.torque</code> "
             "= T_mech evaluated with the crank acceleration of the last communication point. "
             "Simple, but the mechanism's inertia then acts one step late, and the "
             "acceleration of successive steps is amplified by -J_eff / inertia: the coupling "
             "oscillates, and diverges unless the mechanism's effective inertia stays below "
             "that of the rotor and crank.</li>")
    o.append("<li><b>Stabilised:</b> <code>load.inertia</code> = J_eff and "
             "<code>load.torque</code> = tau_0 = T_mech + J_eff eps, the mechanism's torque at "
             "zero crank acceleration. J_eff comes from the dyad FMU's directional "
             "derivatives (<code>fmi2GetDirectionalDerivative</code> / "
             "<code>fmi3GetDirectionalDerivative</code>): seed its acceleration inputs "
             "(<code>link_m.epsilon</code>, <code>link_n.epsilon</code>, "
             "<code>link_m.accel_d</code>, <code>link_n.accel_d</code>) with their rates per "
             "unit crank acceleration (the mechanism's velocity ratios; for the crank pin, "
             "k x r_OA), take the derivative of the reaction at the crank's pin, and form "
             "J_eff = -dT_mech / d eps. The mechanism's inertia then enters the drive's "
             "equation of motion inside the step, as (inertia + load.inertia) eps, and no "
             "longer lags a step behind; only its change with the crank angle over a step "
             "does.</li>")
    o.append("</ul>")

    o.append("<h2>Variables</h2>")
    o.append("<p>Value references as in the model descriptions (in FMI 3, value reference 0 "
             "is the independent variable <code>time</code>). Inputs may change at every "
             "communication point; parameters are fixed once initialization ends.</p>")
    o += _variable_rows(table)
    o.append("<p>A range in brackets is inclusive, in parentheses exclusive. Setting a "
             "value outside its range, or a value that is not finite, is rejected with an "
             "error that names the variable.</p>")

    o.append("<h2>Status codes</h2>")
    o.append("<table>")
    o.append("<tr><th><code>status</code></th><th>meaning</th><th>outputs</th></tr>")
    o.append("<tr><td class=\"num\">0</td><td>ok</td><td>finite</td></tr>")
    o.append("<tr><td class=\"num\">2</td><td>invalid input: <code>inertia + "
             "load.inertia</code> is not positive; <code>exitInitializationMode</code> and "
             "<code>doStep</code> return <code>Error</code> and log <code>load.inertia</code> "
             "and its value (category <code>logStatusError</code>), and the state is not "
             "advanced</td><td><code>crank.epsilon</code> and <code>motor.torque</code> NaN; "
             "<code>crank.angle</code> and <code>crank.omega</code> keep the state</td></tr>")
    o.append("</table>")
    o.append("<p>The codes are those of the dyad FMUs; 1 (singular) and 3 (out of range) do "
             "not occur in the drive.</p>")
    o.append("<ul>")
    o.append("<li>A step the integrator cannot take, because it would need more than 1e7 "
             "substeps (a communication step far longer than the time constant or a crank "
             "turning very fast) or because the state is no longer finite: "
             "<code>doStep</code> returns <code>Discard</code> and logs the reason (category "
             "<code>logStatusDiscard</code>); the state stays at the start of the step.</li>")
    o.append("<li>A value outside the range of its variable, or not finite, is rejected "
             "already by the setter, which returns <code>Error</code> naming the variable: "
             "<code>motor.stall_torque</code>, <code>motor.no_load_speed</code> and "
             "<code>inertia</code> must be positive, <code>crank.mass</code> must not be "
             "negative.</li>")
    o.append("</ul>")

    o.append("<h2>Directional derivatives</h2>")
    o.append("<p>None: the model descriptions declare "
             "<code>providesDirectionalDerivative(s)=\"false\"</code>, and "
             "<code>fmi2GetDirectionalDerivative</code> and "
             "<code>fmi3GetDirectionalDerivative</code> return <code>Error</code>. The one "
             "output that depends on the inputs at a communication point, "
             "<code>crank.epsilon</code>, is explicit in them (see the equation above).</p>")

    return _closing(o, table)


# ---------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------
def outputs_of(table: Table) -> dict[str, str]:
    """Relative path -> text of every generated file."""
    return {
        "fmi2/modelDescription.xml": fmi2_model_description(table),
        "fmi3/modelDescription.xml": fmi3_model_description(table),
        "fmi3/buildDescription.xml": fmi3_build_description(table),
        f"{table.identifier}_model.c": model_c(table),
        "documentation/index.html": documentation(table),
    }


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def _shown(path: Path) -> str:
    """A path relative to the checkout where it lies inside it."""
    try:
        return str(path.relative_to(HERE.parent))
    except ValueError:
        return str(path)


def golden_files() -> dict[Path, str]:
    """Golden path -> expected text for every table in TABLES and scene in GOLDEN_SCENES."""
    # The scene generator builds on this module: let it find this very instance
    # (when run as a script, this module is __main__, not generate).
    sys.modules.setdefault("generate", sys.modules[__name__])
    sys.path.insert(0, str(HERE))
    import scene
    result = {}
    tables = [load_table(HERE / name) for name in TABLES]
    tables += [scene.build_table(scene.load_scene(SCENES_DIR / name)) for name in GOLDEN_SCENES]
    for table in tables:
        result[GOLDEN_DIR / f"{table.identifier}_fmi2.xml"] = fmi2_model_description(table)
        result[GOLDEN_DIR / f"{table.identifier}_fmi3.xml"] = fmi3_model_description(table)
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        description="Generate the model descriptions, C variable table and documentation "
                    "of a dyad or drive FMU from its variable table.")
    parser.add_argument("table", nargs="?", type=Path, help="the variable table (TOML)")
    parser.add_argument("--out", type=Path, help="directory to write the generated files to")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--update-golden", action="store_true",
                      help="rewrite modelDescription/golden/*.xml from the tables")
    mode.add_argument("--check-golden", action="store_true",
                      help="exit 1 with a unified diff if a golden file differs")
    args = parser.parse_args(argv)

    try:
        if args.update_golden or args.check_golden:
            if args.table or args.out:
                parser.error("--update-golden and --check-golden take no table or --out")
            files = golden_files()
            if args.update_golden:
                for path, text in files.items():
                    _write(path, text)
                    print(f"wrote {_shown(path)}")
                return 0
            differs = []
            for path, text in files.items():
                old = path.read_text(encoding="utf-8") if path.is_file() else ""
                if old != text:
                    differs.append(path)
                    rel = _shown(path)
                    sys.stdout.writelines(difflib.unified_diff(
                        old.splitlines(keepends=True), text.splitlines(keepends=True),
                        f"{rel} (golden)", f"{rel} (generated)"))
            if differs:
                print(f"{len(differs)} golden file(s) differ from the tables; review the diff "
                      "and run 'modelDescription/generate.py --update-golden'", file=sys.stderr)
                return 1
            return 0
        if args.table is None or args.out is None:
            parser.error("give a TABLE and --out DIR (or --update-golden / --check-golden)")
        table = load_table(args.table)
        for rel, text in outputs_of(table).items():
            _write(args.out / rel, text)
        return 0
    except TableError as exc:
        for problem in exc.args[0]:
            print(f"error: {problem}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())

"""The C structures a model's variables live in, and the `lives` grammar that names a
member of them: ``input.<member path>[@angle]`` or ``result.<member path>``, or a
setting of the FMU layer itself: ``fmu.<setting>`` (settings.py).

A generic dyad lives in dyad_input and dyad_result (src/include/dyadfmu/types.h), whose
members nest (link m's direction: input.m.dir); the drive in fmu_drive_input and
fmu_drive_output (fmu/models/fmu_drive.h), the motor in fmu_motor_input and fmu_motor_output
(fmu/models/fmu_motor.h), and a tailored scene in the flat blocks its header
declares, whose members keep the case of its variables' names (a pair point's parameter
DYAD.D_m.x lives in input.DYAD_D_m_x).
"""

from __future__ import annotations

import re

from dyadgen.settings import SETTINGS, Setting

# Member trees of dyad_input and dyad_result (types.h). Leaves: "real" (a
# dyad_real), "dir" (a unit dyad_vec2 set from an angle), "status", "enum".
_VEC2 = {"x": "real", "y": "real"}
_LINK = {
    "dir": "dir",
    "length": "real",
    "omega": "real",
    "epsilon": "real",
    "accel_d": _VEC2,
    "com": _VEC2,
    "mass": "real",
    "inertia": "real",
    "force": _VEC2,
    "moment": "real",
}
INPUT_MEMBERS = {
    "m": _LINK,
    "n": _LINK,
    "guide_k": "dir",
    "guide_p": "dir",
    "gravity": _VEC2,
    "singular_threshold": "real",
}
RESULT_MEMBERS = {
    "status": "status",
    "field": "enum",
    "r_mk": _VEC2,
    "r_np": _VEC2,
    "r_mn": _VEC2,
    "n_mk": "real",
    "n_np": "real",
    "n_mn": "real",
    "m_mk": "real",
    "m_np": "real",
    "m_mn": "real",
    "denominator": "real",
    "conditioning": "real",
    "amplification": "real",
}

#: dyad_field of each dyad_link member.
LINK_FIELD = {
    "dir": "DIR",
    "length": "LENGTH",
    "omega": "OMEGA",
    "epsilon": "EPSILON",
    "accel_d": "ACCEL_D",
    "com": "COM",
    "mass": "MASS",
    "inertia": "INERTIA",
    "force": "FORCE",
    "moment": "MOMENT",
}

# Members of fmu_drive_input and fmu_drive_output (fmu/models/fmu_drive.h), in declaration
# order. Leaves: "real" (a double), "state" (a double the model integrates itself,
# which no variable may set), "status" (the int status).
DRIVE_INPUT_MEMBERS = {
    "load_torque": "real",
    "load_inertia": "real",
    "load_demand": "real",
    "stall_torque": "real",
    "no_load_speed": "real",
    "inertia": "real",
    "crank_mass": "real",
    "crank_com_x": "real",
    "crank_com_y": "real",
    "gravity_x": "real",
    "gravity_y": "real",
    "start_angle": "real",
    "start_speed": "real",
    "angle": "state",
    "speed": "state",
}
DRIVE_OUTPUT_MEMBERS = {
    "angle": "real",
    "speed": "real",
    "acceleration": "real",
    "motor_torque": "real",
    "status": "status",
}

# Members of fmu_motor_input and fmu_motor_output (fmu/models/fmu_motor.h), in declaration
# order. "rate": the first derivative of an input, set by fmi2SetRealInputDerivatives
# and by no variable.
MOTOR_INPUT_MEMBERS = {
    "voltage": "real",
    "omega": "real",
    "voltage_rate": "rate",
    "omega_rate": "rate",
    "resistance": "real",
    "inductance": "real",
    "torque_constant": "real",
    "friction": "real",
    "ratio": "real",
    "current_start": "real",
    "current": "state",
}
MOTOR_OUTPUT_MEMBERS = {
    "torque": "real",
    "current": "real",
    "status": "status",
}

#: The start parameter of each state of the drive and of the motor.
STATE_START = {"angle": "start.angle", "speed": "start.speed", "current": "motor.current_start"}

#: struct.member.path[@angle]; a scene's flat members keep the case of its variables'
#: names (a pair point's parameter DYAD.D_m.x lives in input.DYAD_D_m_x). Matched whole.
LIVES_RE = re.compile(
    r"(input|result|fmu)\.([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)(@angle)?"
)


class Lives:
    """A parsed `lives`: struct ("input" | "result" | "fmu"), member path, angle flag, and
    the kind of model whose structs it names."""

    def __init__(self, struct: str, path: str, angle: bool, kind: Structs) -> None:
        self.struct = struct
        self.path = path
        self.angle = angle
        self.kind = kind

    @property
    def setting(self) -> Setting | None:
        """The FMU layer's setting it names, or None."""
        return SETTINGS[self.path] if self.struct == "fmu" else None

    @property
    def target(self) -> str:
        """The FMU_TARGET_... of the variable (fmu/fmu_model.h)."""
        if self.struct == "fmu":
            return "FMU_TARGET_SETTING"
        if self.struct == "input":
            return "FMU_TARGET_INPUT_ANGLE" if self.angle else "FMU_TARGET_INPUT_REAL"
        return "FMU_TARGET_RESULT_STATUS" if self.path == "status" else "FMU_TARGET_RESULT_REAL"

    @property
    def offset(self) -> str:
        """The C expression of the member's offset in its struct; a setting's fmu_setting."""
        if self.struct == "fmu":
            return SETTINGS[self.path].c_name
        return self.kind.lives_offset(self)

    @property
    def field(self) -> str:
        """The dyad_field the solver names when it rejects the value."""
        if self.struct == "fmu":
            return "DYAD_FIELD_NONE"
        return self.kind.lives_field(self)


class Structs:
    """A kind of model's C structures: the input and output blocks its variables live
    in, the header declaring both and the behaviour that computes on them
    (fmu/fmu_model.h). Members are flat: scalar members only."""

    def __init__(
        self,
        name: str,
        input_type: str,
        output_type: str,
        input_members: dict,
        output_members: dict,
        header: str,
        behaviour: str,
    ) -> None:
        self.name = name
        self.input_type = input_type  # C type of the input block
        self.output_type = output_type  # C type of the output block
        self.input_members = input_members
        self.output_members = output_members
        self.header = header  # the header declaring both and the behaviour
        self.behaviour = behaviour  # the fmu_behaviour object

    def parse_lives(self, text: object) -> Lives:
        """Parse and resolve a `lives` string of a model of this kind; raises ValueError
        with the reason."""
        if not isinstance(text, str):
            raise ValueError("must be a string")
        match = LIVES_RE.fullmatch(text)
        if not match:
            raise ValueError(self.lives_syntax())
        if match.group(1) == "fmu":
            return self.resolve_setting(match.group(2), bool(match.group(3)))
        return self.resolve_lives(match.group(1), match.group(2), bool(match.group(3)))

    def resolve_setting(self, path: str, angle: bool) -> Lives:
        """`fmu.<setting>`: a setting of the FMU layer, the same in every kind."""
        if path not in SETTINGS or angle:
            raise ValueError(
                f"the FMU layer has no setting '{path}{'@angle' if angle else ''}' "
                f"(settings: {', '.join(SETTINGS)})"
            )
        return Lives("fmu", path, False, self)

    def lives_syntax(self) -> str:
        """What a `lives` of this kind looks like, for a message."""
        return (
            f"expected 'input.<member of {self.input_type}>', "
            f"'result.<member of {self.output_type}>' or 'fmu.<setting>'"
        )

    def resolve_lives(self, struct: str, path: str, angle: bool) -> Lives:
        """`lives` of a model whose structs have only scalar members (the drive, a scene)."""
        members = self.input_members if struct == "input" else self.output_members
        type_name = self.input_type if struct == "input" else self.output_type
        if path not in members:
            raise ValueError(f"{type_name} has no member '{path}' (members: {', '.join(members)})")
        if angle and members[path] != "dir":
            raise ValueError(
                f"'@angle' applies only to a direction; {type_name}.{path} is a plain double"
            )
        if members[path] == "dir" and not angle:
            raise ValueError(
                f"{type_name}.{path} is a unit direction; write "
                f"'{struct}.{path}@angle' to set it from an angle"
            )
        if members[path] == "state":
            raise ValueError(
                f"{type_name}.{path} is a state of the {self.name}: it is set from "
                f"'{STATE_START[path]}' when initialization ends and advanced "
                f"by doStep, so no variable may set it (read it through "
                f"{self.output_type}.{path})"
            )
        if members[path] == "rate":
            raise ValueError(
                f"{type_name}.{path} is the first derivative of an input, set by "
                "fmi2SetRealInputDerivatives, so no variable may set it"
            )
        return Lives(struct, path, angle, self)

    def lives_offset(self, lives: Lives) -> str:
        """offsetof() of a member of the input or output block."""
        if lives.struct == "result":
            return f"offsetof({self.output_type}, {lives.path})"
        return f"offsetof({self.input_type}, {lives.path})"

    def lives_field(self, lives: Lives) -> str:
        """The dyad_field of a member: none outside the dyad's structs."""
        return "DYAD_FIELD_NONE"


def check_dyad_member(struct: str, path: str, angle: bool) -> None:
    """Walk a member path of dyad_input or dyad_result; raises ValueError with the reason
    where it names no value an FMU variable can carry."""
    node = INPUT_MEMBERS if struct == "input" else RESULT_MEMBERS
    type_name = "dyad_input" if struct == "input" else "dyad_result"
    walked = []
    for part in path.split("."):
        if not isinstance(node, dict) or part not in node:
            raise ValueError(f"{type_name} has no member '{'.'.join(walked + [part])}'")
        node = node[part]
        walked.append(part)
    if isinstance(node, dict):
        raise ValueError(
            f"{type_name}.{path} is a structure, not a value; name a member "
            f"({', '.join(sorted(node))})"
        )
    if struct == "result" and angle:
        raise ValueError("'@angle' applies only to input directions")
    if node == "dir" and not angle:
        raise ValueError(
            f"{type_name}.{path} is a unit direction (dyad_vec2); "
            f"write '{struct}.{path}@angle' to set it from an angle"
        )
    if node != "dir" and angle:
        raise ValueError(
            f"'@angle' applies only to a direction (link dir, guide_k, guide_p), "
            f"not to {type_name}.{path}"
        )
    if node == "enum":
        raise ValueError(f"{type_name}.{path} is not a value an FMU variable can carry")

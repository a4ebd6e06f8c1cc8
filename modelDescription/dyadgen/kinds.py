"""One object per kind of model, each with its own structures, table, source files, C
and documentation:

    dyad    (the default of a table) the kinetostatic solver of one Assur dyad, whose
            ``type`` (RRR, RRT, RTR, TRT, RTT) fixes its variables; it lives in
            dyad_input and dyad_result (src/include/dyadfmu/types.h), behaviour
            fmu_dyad.c. A scene that is one whole dyad is realised by it (generic).
    drive   the crank drive, a DC motor with states (crank angle and speed)
            integrated inside doStep; no ``type``; it lives in fmu_drive_input and
            fmu_drive_output (fmu/models/fmu_drive.h), behaviour fmu_drive.c.
    motor   a DC motor with a gear, voltage and shaft speed in, shaft torque out, its
            current a state solved in closed form inside doStep (inputs interpolated,
            outputs differentiated); it lives in fmu_motor_input and fmu_motor_output
            (fmu/models/fmu_motor.h), behaviour fmu_motor.c.
    scene   a tailored scene: flat input and output blocks and the code computing
            them, both generated from the scene (emit/scene_c.py).
"""

from __future__ import annotations

from dyadgen import forward
from dyadgen.catalogue import (
    Entry,
    drive_absence_reason,
    drive_catalogue,
    dyad_absence_reason,
    dyad_catalogue,
    motor_absence_reason,
    motor_catalogue,
    setting_entry,
)
from dyadgen.corefiles import dyad_core_sources, scene_core_sources
from dyadgen.dyadtypes import PAIRS
from dyadgen.emit import documentation, fmi2, fmi3
from dyadgen.emit.batch_c import batch_supported
from dyadgen.emit.c_table import model_c
from dyadgen.emit.forward_c import forward_behaviour
from dyadgen.emit.scene_c import (
    bare_lanes,
    bound_members,
    later_members,
    scene_c,
    scene_header,
    scene_tangent_c,
)
from dyadgen.model import Input, Param, Scene, member
from dyadgen.scenefile.problems import SceneError
from dyadgen.settings import ON_SINGULAR
from dyadgen.structs import (
    DRIVE_INPUT_MEMBERS,
    DRIVE_OUTPUT_MEMBERS,
    INPUT_MEMBERS,
    LINK_FIELD,
    MOTOR_INPUT_MEMBERS,
    MOTOR_OUTPUT_MEMBERS,
    RESULT_MEMBERS,
    Lives,
    Structs,
    check_dyad_member,
)
from dyadgen.table import Table, TableError, table_from_data

#: The FMI shim's C files per FMI version (fmu/).
SHIM_FILES = {2: ["fmi2_functions.c"], 3: ["fmi3_functions.c", "fmi3_unsupported.c"]}

LOG_CATEGORIES = (
    (
        "logStatusError",
        "Errors: illegal call sequences, bad arguments, inputs the solver "
        "rejects (the offending variable is named)",
    ),
    ("logStatusWarning", "Warnings, e.g. a singular configuration at exitInitializationMode"),
    (
        "logStatusDiscard",
        "Discarded steps: singular configuration or overflowing reactions (reaction outputs NaN)",
    ),
    ("logCalls", "Calls into the FMU"),
)
#: The same categories (fmu_instance.c knows them by name) as the drive uses them.
DRIVE_LOG_CATEGORIES = (
    (
        "logStatusError",
        "Errors: illegal call sequences, bad arguments, inputs the model "
        "rejects (the offending variable is named, e.g. load.inertia when inertia + "
        "load.inertia is not positive)",
    ),
    ("logStatusWarning", "Warnings"),
    (
        "logStatusDiscard",
        "Discarded steps: a step that would need more than 1e7 integrator "
        "substeps, or a crank state that is no longer finite (the state stays at the step's "
        "start)",
    ),
    ("logCalls", "Calls into the FMU"),
)
#: The same categories as the motor uses them.
MOTOR_LOG_CATEGORIES = (
    (
        "logStatusError",
        "Errors: illegal call sequences, bad arguments, values outside a variable's range "
        "or not finite, an input whose derivative carries it past the finite within a step "
        "(the variable is named)",
    ),
    ("logStatusWarning", "Warnings"),
    (
        "logStatusDiscard",
        "Discarded steps: a step that would end where the current or the shaft torque "
        "overflows double (the current stays at the step's start)",
    ),
    ("logCalls", "Calls into the FMU"),
)
#: The same categories as a scene uses them.
SCENE_LOG_CATEGORIES = (
    (
        "logStatusError",
        "Errors: illegal call sequences, bad arguments, values outside a "
        "variable's range (the variable is named)",
    ),
    ("logStatusWarning", "Warnings, e.g. a singular dyad at exitInitializationMode"),
    (
        "logStatusDiscard",
        "Discarded steps: a singular dyad (named) or overflowing reactions (outputs NaN)",
    ),
    ("logCalls", "Calls into the FMU"),
)


class Kind(Structs):
    """A kind of model: its structures (structs.Structs), and what an FMU of it is made
    of: its source files, its C variable table's model data, its documentation and its
    generated files; for a kind whose tables are written by hand, the catalogue they
    are checked against."""

    #: Whether its FMUs give directional derivatives (the model descriptions' flag).
    directional_derivatives = "false"
    #: Whether its FMUs follow their inputs' first derivatives over a step and give their
    #: outputs' (canInterpolateInputs, maxOutputDerivativeOrder 1).
    interpolates = False
    log_categories: tuple = ()
    #: How a scene of this kind is realised (scene.py --cmake-info) and named (--check).
    realisation = ""
    label = ""
    #: The headers its variable table (<identifier>_model.c) includes beyond its own.
    model_includes: tuple = ()
    #: The command that generates its files from its table (named in their comments).
    tool = "modelDescription/scene.py"

    def source_files(self, table: Table, version: int) -> list[str]:
        """The C files an importer compiles to rebuild the FMI `version` binary."""
        raise NotImplementedError

    def subject(self, table: Table) -> str:
        """What the FMU is, for the C variable table's comment."""
        raise NotImplementedError

    def table_source(self, table: Table) -> str:
        """Where the table comes from, for the C variable table's comment: a scene file
        (a generic dyad's is modelDescription/scenes/dyad_<type>.toml)."""
        return f"scene {table.path.name}"

    def model_data(self, table: Table) -> tuple[list[str], str]:
        """The C lines of the model data the behaviour needs, and its address."""
        return [], "NULL"

    def documentation(self, table: Table) -> str:
        """documentation/index.html."""
        raise NotImplementedError

    def own_sources(self, table: Table) -> dict[str, str]:
        """Generated C sources beyond the variable table: file name -> text."""
        return {}

    def files(self, table: Table) -> dict[str, str]:
        """Relative path -> text of every generated file."""
        files = {
            "fmi2/modelDescription.xml": fmi2.model_description(table),
            "fmi3/modelDescription.xml": fmi3.model_description(table),
            "fmi3/buildDescription.xml": fmi3.build_description(table),
            f"{table.identifier}_model.c": model_c(table),
        }
        files.update(self.own_sources(table))
        files["documentation/index.html"] = self.documentation(table)
        return files

    # ---- a table written by hand, checked against the kind's catalogue
    def catalogue_for(self, model: dict) -> dict[str, Entry]:
        """Every variable a table of this [model] must have; ValueError if there is none."""
        raise ValueError(f"kind '{self.name}' has no table of its own")

    def model_problems(self, model: dict) -> list[str]:
        """What is wrong with [model] for this kind."""
        return []

    def owner(self, model: dict) -> str:
        """The model, as messages name it."""
        return self.name

    def absence_reason(self, model: dict, lives: str) -> str:
        """Why a well-formed `lives` is not a variable of this model."""
        raise NotImplementedError

    def table_of_scene(self, scene: Scene) -> Table:
        """The variable table of a scene this kind realises."""
        raise NotImplementedError


class DyadKind(Kind):
    """The generic dyad FMU of one type, on the core's validating solver and its exact
    directional derivatives."""

    directional_derivatives = "true"
    log_categories = LOG_CATEGORIES
    realisation = "generic"
    label = "generic dyad"

    def lives_syntax(self) -> str:
        """What a `lives` of a dyad looks like."""
        return "expected 'input.<member path>[@angle]', 'result.<member path>' or 'fmu.<setting>'"

    def resolve_lives(self, struct: str, path: str, angle: bool) -> Lives:
        """A member path of dyad_input or dyad_result."""
        check_dyad_member(struct, path, angle)
        return Lives(struct, path, angle, self)

    def lives_offset(self, lives: Lives) -> str:
        """offsetof() of the member; dyad_result.status is its first member."""
        if lives.struct == "result" and lives.path == "status":
            return "0"
        return super().lives_offset(lives)

    def lives_field(self, lives: Lives) -> str:
        """The dyad_field of an input member."""
        if lives.struct == "result":
            return "DYAD_FIELD_NONE"
        parts = lives.path.split(".")
        if parts[0] in ("m", "n"):
            return f"DYAD_FIELD_{parts[0].upper()}_{LINK_FIELD[parts[1]]}"
        return f"DYAD_FIELD_{parts[0].upper()}"

    def source_files(self, table: Table, version: int) -> list[str]:
        """The dyad's solver, its derivatives and the dyad behaviour."""
        return [
            *dyad_core_sources(table.type.lower()),
            "fmu_dyad.c",
            "fmu_instance.c",
            "fmu_state.c",
            *SHIM_FILES[version],
            f"{table.identifier}_model.c",
        ]

    def subject(self, table: Table) -> str:
        """The dyad FMU of its type."""
        return f"the {table.type} dyad FMU"

    def model_data(self, table: Table) -> tuple[list[str], str]:
        """fmu_dyad_data: the type's solver and tangent, and the variable that feeds each
        of the core's input fields (the one an invalid input is blamed on)."""
        t = table.type.lower()
        feeds = [
            f"    {{{v.lives.field}, {v.index}}},"
            for v in table.variables
            if v.causality != "output" and v.lives.field != "DYAD_FIELD_NONE"
        ]
        return [
            "/* The variable that feeds each input field of the core, for errors. */",
            "static const fmu_dyad_feed feeds[] = {",
            *feeds,
            "};",
            "",
            f"static const fmu_dyad_data dyad = {{dyad_solve_{t}, dyad_solve_valid_{t}, "
            f"&dyad_tangent_{t}, feeds, {len(feeds)}}};",
            "",
            "/* The columns entry's samples solved together (fmu_dyad_lanes.h), this type's",
            " * only. */",
            f"#define DYAD_LANES_{t.upper()}",
            '#include "fmu_dyad_lanes.h"',
            f"FMU_DYAD_LANES({t})",
            "",
        ], "&dyad"

    def documentation(self, table: Table) -> str:
        """The page of the dyad type."""
        return documentation.dyad_page(table)

    def catalogue_for(self, model: dict) -> dict[str, Entry]:
        """The variables of the table's dyad type."""
        dyad_type = model.get("type")
        if dyad_type not in PAIRS:
            raise ValueError(f"type {dyad_type!r} is not one of {', '.join(PAIRS)}")
        return dyad_catalogue(dyad_type)

    def owner(self, model: dict) -> str:
        """'RRT dyad'."""
        return f"{model.get('type')} dyad"

    def absence_reason(self, model: dict, lives: str) -> str:
        """Why the type has no such variable."""
        return dyad_absence_reason(model["type"], lives)

    def table_of_scene(self, scene: Scene) -> Table:
        """The table of a generic scene (is_generic), checked as a table file is."""
        try:
            return table_from_data(generic_data(scene), scene.path, KINDS)
        except TableError as exc:
            raise SceneError(exc.args[0]) from None


class HandTableKind(Kind):
    """A model of its own behaviour (fmu/models/fmu_<kind>.c) whose variable table is
    written by hand (interface/<identifier>.toml) and checked against its catalogue."""

    tool = "modelDescription/generate.py"

    def source_files(self, table: Table, version: int) -> list[str]:
        """The model's behaviour."""
        return [
            f"fmu_{self.name}.c",
            "fmu_instance.c",
            "fmu_state.c",
            *SHIM_FILES[version],
            f"{table.identifier}_model.c",
        ]

    def table_source(self, table: Table) -> str:
        """The model's table, among the interface data."""
        return f"modelDescription/interface/{table.path.name}"

    def model_problems(self, model: dict) -> list[str]:
        """Only a dyad has a type."""
        if "type" in model:
            return [
                f"type {model['type']!r} given, but only a dyad has a type "
                f"(this table is of kind '{self.name}')"
            ]
        return []


class DriveKind(HandTableKind):
    """The crank drive (fmu/models/fmu_drive.c), from its table interface/drive.toml."""

    log_categories = DRIVE_LOG_CATEGORIES

    def subject(self, table: Table) -> str:
        """The crank drive."""
        return "the crank drive FMU"

    def documentation(self, table: Table) -> str:
        """The page of the drive."""
        return documentation.drive_page(table)

    def catalogue_for(self, model: dict) -> dict[str, Entry]:
        """The drive's variables."""
        return drive_catalogue()

    def absence_reason(self, model: dict, lives: str) -> str:
        """The drive has no such variable."""
        return drive_absence_reason(lives)


class MotorKind(HandTableKind):
    """The DC motor (fmu/models/fmu_motor.c), from its table interface/motor.toml: it
    follows its inputs' first derivatives and gives its outputs'."""

    interpolates = True
    log_categories = MOTOR_LOG_CATEGORIES

    def subject(self, table: Table) -> str:
        """The motor."""
        return "the DC motor FMU"

    def documentation(self, table: Table) -> str:
        """The page of the motor."""
        return documentation.motor_page(table)

    def catalogue_for(self, model: dict) -> dict[str, Entry]:
        """The motor's variables."""
        return motor_catalogue()

    def absence_reason(self, model: dict, lives: str) -> str:
        """The motor has no such variable."""
        return motor_absence_reason(lives)


class SceneKind(Kind):
    """A tailored scene: flat input and output blocks generated with the scene's C."""

    directional_derivatives = "true"
    realisation = "tailored"
    label = "tailored"
    log_categories = SCENE_LOG_CATEGORIES
    model_includes = ("<string.h>", '"fmu_model.h"')

    def __init__(self, scene: Scene) -> None:
        ident = scene.identifier
        inputs = {i.member: "dir" if i.angle else "real" for i in scene.inputs}
        inputs.update((prm.member, "real") for prm in scene.parameters() if prm.tunable)
        outputs = {o.member: "status" if o.integer else "real" for o in scene.outputs}
        if scene.forward():
            inputs.update(forward.input_members(scene))
            outputs.update(forward.output_members(scene))
        super().__init__(
            "scene",
            f"{ident}_input",
            f"{ident}_output",
            inputs,
            outputs,
            f"{ident}_scene.h",
            f"{ident}_behaviour",
        )
        self.scene = scene
        if scene.internal():
            # a mechanism FMU: the kinematics are solved inside, from the driver's motion
            self.realisation = "mechanism"
            self.label = "mechanism"
        if scene.forward():
            # a plant: the motion integrated inside, the efforts in
            self.realisation = "forward"
            self.label = "forward mechanism"
            self.directional_derivatives = "false"
            self.interpolates = True
            self.model_includes = (
                "<float.h>",
                "<math.h>",
                "<stdio.h>",
                "<string.h>",
                '"dyadfmu/angle.h"',
                '"dyadfmu/ode.h"',
                '"fmu_model.h"',
            )

    def source_files(self, table: Table, version: int) -> list[str]:
        """The closed forms of the scene's dyad types with their tangents, and its
        generated code."""
        plant = ["dyad_ode.c"] if table.scene.forward() else []
        return (
            scene_core_sources(table.scene, derivatives=True)
            + plant
            + [
                f"{table.identifier}_scene.c",
                f"{table.identifier}_scene_tangent.c",
                "fmu_instance.c",
                "fmu_state.c",
                *SHIM_FILES[version],
                f"{table.identifier}_model.c",
            ]
        )

    def subject(self, table: Table) -> str:
        """The scene."""
        return f"the scene {table.identifier}"

    def table_source(self, table: Table) -> str:
        """The scene file."""
        return f"scene {table.path.name}"

    def own_sources(self, table: Table) -> dict[str, str]:
        """The scene's C (its evaluation and, apart, its derivative) and header."""
        return {
            f"{table.identifier}_scene.c": scene_c(table.scene),
            f"{table.identifier}_scene_tangent.c": scene_tangent_c(table.scene),
            f"{table.identifier}_scene.h": scene_header(table),
        }

    def model_data(self, table: Table) -> tuple[list[str], str]:
        """The scene's behaviour: its functions (<identifier>_scene.h) on the FMU
        layer's untyped blocks."""
        if table.scene.forward():
            return forward_behaviour(table.scene), "NULL"
        return scene_behaviour(table), "NULL"

    def documentation(self, table: Table) -> str:
        """The page of the scene."""
        return documentation.scene_page(table)

    def table_of_scene(self, scene: Scene) -> Table:
        """The scene's table, valid by construction."""
        return SceneTable(scene, _scene_rows(scene), self)


DYAD = DyadKind(
    "dyad",
    "dyad_input",
    "dyad_result",
    INPUT_MEMBERS,
    RESULT_MEMBERS,
    "fmu_dyad.h",
    "fmu_dyad_lane_behaviour",
)
DRIVE = DriveKind(
    "drive",
    "fmu_drive_input",
    "fmu_drive_output",
    DRIVE_INPUT_MEMBERS,
    DRIVE_OUTPUT_MEMBERS,
    "fmu_drive.h",
    "fmu_drive_behaviour",
)
MOTOR = MotorKind(
    "motor",
    "fmu_motor_input",
    "fmu_motor_output",
    MOTOR_INPUT_MEMBERS,
    MOTOR_OUTPUT_MEMBERS,
    "fmu_motor.h",
    "fmu_motor_behaviour",
)
#: The kinds a table file may name in [model] kind.
KINDS = {"dyad": DYAD, "drive": DRIVE, "motor": MOTOR}


def scene_behaviour(table: Table) -> list[str]:
    """The C of a scene's fmu_behaviour, <identifier>_behaviour: its initialise, and its
    evaluate and derivative on the scene's functions; where some outputs can come later
    (emit/scene_c.py, later_members), the halves of evaluate as its fmu_later; where it
    has a batch evaluation (emit/batch_c.py), that as its fmu_lanes."""
    ident = table.identifier
    later = later_members(table.scene)
    lanes = batch_supported(table.scene)
    lines = [
        f"/* The scene's functions ({ident}_scene.c, {ident}_scene_tangent.c) as the FMU",
        " * layer calls them. */",
        "static void initialise(const fmu_model* model, void* input)",
        "{",
        "    (void)model;",
        f"    memset(input, 0, sizeof({ident}_input));",
        "}",
        "",
        "static void evaluate(const fmu_model* model, const void* input, void* output,",
        "                     fmu_evaluation* evaluation)",
        "{",
        "    (void)model;",
        f"    {ident}_evaluate((const {ident}_input*)input, ({ident}_output*)output, evaluation);",
        "}",
        "",
        "static void derivative(const fmu_model* model, const void* input, const void* seed,",
        "                       void* output, void* rate, fmu_evaluation* evaluation)",
        "{",
        "    (void)model;",
        f"    {ident}_derivative((const {ident}_input*)input, (const {ident}_input*)seed,",
        f"                       ({ident}_output*)output, ({ident}_output*)rate, evaluation);",
        "}",
        "",
        *(_later_behaviour(table, later) if later else []),
        *(_lanes_behaviour(table, table.scene, bool(later)) if lanes else []),
        f"static const fmu_behaviour {ident}_behaviour = {{sizeof({ident}_input),",
        f"                                                sizeof({ident}_output), initialise,",
        "                                                evaluate, NULL, NULL, derivative, NULL,",
        f"                                                NULL, {'&later' if later else 'NULL'},",
        f"                                                {'&many' if lanes else 'NULL'}}};",
        "",
    ]
    return lines


def _later_behaviour(table: Table, later: tuple[str, ...]) -> list[str]:
    """The outputs an FMU step can leave to their first read: their value references and
    the two halves of the evaluation."""
    ident = table.identifier
    vrs = [v.vr for v in table.variables if v.lives.struct == "result" and v.lives.path in later]
    lines = [
        "/* The effective inertia's outputs, computed by a kinematic pass of their own: an",
        " * importer that does not read them does not wait for them. */",
        f"static const unsigned int later_vrs[] = {{{', '.join(f'{vr}u' for vr in vrs)}}};",
        "",
    ]
    for half in ("first", "later"):
        lines += [
            f"static void evaluate_{half}(const fmu_model* model, const void* input, void* output,",
            f"                          {' ' * len(half)}fmu_evaluation* evaluation)",
            "{",
            "    (void)model;",
            f"    {ident}_evaluate_{half}((const {ident}_input*)input, ({ident}_output*)output,",
            f"    {' ' * len(ident)}               {' ' * len(half)}evaluation);",
            "}",
            "",
        ]
    halves = "evaluate_first, evaluate_later"
    return [*lines, f"static const fmu_later later = {{later_vrs, {len(vrs)}, {halves}}};", ""]


def _lanes_behaviour(table: Table, scene: Scene, first: bool) -> list[str]:
    """The scene's batch evaluation (<identifier>_lanes) as its fmu_lanes."""
    ident, upper = table.identifier, table.identifier.upper()
    bare = bare_lanes(scene)
    lines = [
        "/* Many samples at once, in columns: the loop over them vectorises. */",
    ]
    for half in ("", *(["_first"] if first else []), *(["_bare"] if bare else [])):
        name = f"lanes{half}"
        head = f"static void {name}("
        lines += [
            f"{head}dyad_lanes_isa cap, size_t count, double* lanes,",
            f"{' ' * len(head)}const unsigned char* wanted)",
            "{",
            f"    {ident}_lanes{half}_at_most(",
            f"        cap, count, (dyad_real(*)[{upper}_LANES])(void*)lanes, wanted);",
            "}",
            "",
        ]
    functions = f"lanes, {'lanes_first' if first else 'NULL'}, {'lanes_bare' if bare else 'NULL'}"
    flags = [
        f"    [offsetof({ident}_output, {m}) / sizeof(dyad_real)] = 1,"
        for m in bound_members(scene)
    ]
    lines += [
        "/* The outputs _bare leaves NaN: the reactions' bounds. */",
        f"static const unsigned char bounds[{upper}_LANE_OUTPUTS + 1] = {{",
        *(flags or ["    0,"]),
        "};",
        "",
    ]
    return [
        *lines,
        f"static const fmu_lanes many = {{{upper}_LANES, {upper}_LANE_INPUTS, "
        f"{upper}_LANE_OUTPUTS,",
        f"                               {upper}_LANE_COLUMNS,",
        f"                               {functions}, bounds}};",
        "",
    ]


class SceneTable(Table):
    """The table of a tailored scene, valid by construction."""

    def __init__(self, scene: Scene, rows: list[dict], kind: SceneKind) -> None:
        model = {"kind": "scene", "identifier": scene.identifier, "description": scene.description}
        super().__init__(scene.path, model, rows, kind)
        self.scene = scene
        self.experiment = scene.experiment


def _bounds(raw: dict, domain: dict) -> None:
    for key in ("min", "max"):
        if key in domain:
            raw[key] = domain[key]
    for key in ("min_exclusive", "max_exclusive"):
        if domain.get(key):
            raw[key] = True


def _row(rows: list, name: str, causality: str, unit: str | None, **values: object) -> dict:
    raw = {"name": name, "vr": len(rows) + 1, "causality": causality, **values}
    if unit:
        raw["unit"] = unit
    rows.append(raw)
    return raw


def _settable_row(
    rows: list, settable: Input | Param, causality: str, start: float, lives: str
) -> None:
    """The row of an input or a tunable parameter: a Real with the bounds of its domain."""
    raw = _row(
        rows,
        settable.name,
        causality,
        settable.unit,
        type="Real",
        start=start,
        description=settable.description,
        lives=lives,
    )
    _bounds(raw, settable.domain)


def _forward_rows(scene: Scene) -> list[dict]:
    """The rows of a forward scene's table: the efforts and loads, the tunable and start
    parameters and tolerances, the drivers' motion and the scene's outputs."""
    rows: list[dict] = []
    for i in forward.public_inputs(scene):
        _settable_row(rows, i, "input", i.start, f"input.{i.member}")
    for prm in scene.parameters():
        if prm.tunable:
            _settable_row(rows, prm, "parameter", prm.value, f"input.{prm.member}")
    for i, start in forward.start_parameters(scene):
        _settable_row(rows, i, "parameter", start, f"input.{i.member}")
    for name, start, text in forward.tolerance_parameters():
        raw = _row(rows, name, "parameter", None, type="Real", start=start, description=text)
        raw.update(lives=f"input.{member(name).replace('solver_', 'plant_')}", min=0.0)
        raw.update(min_exclusive=True, max=1.0, max_exclusive=True)
        if name == "solver.rtol":
            raw.update(min=forward.RTOL_MIN, min_exclusive=False)
    name, start, text = forward.step_start_parameter()
    raw = _row(rows, name, "parameter", "s", type="Real", start=start, description=text)
    raw.update(lives="input.plant_step_start", min=0.0, min_exclusive=False)
    for name, start, text in forward.explicit_limit_parameters(scene):
        raw = _row(rows, name, "parameter", None, type="Real", start=start, description=text)
        raw.update(lives="input.plant_explicit_limit", min=0.0, min_exclusive=False)
        raw.update(max=forward.EXPLICIT_LIMIT_MAX, max_exclusive=False)
    # no on_singular: a plant's step without an answer cannot go on (its states stop)
    _output_rows(rows, forward.public_outputs(scene))
    return rows


def _output_rows(rows: list[dict], outputs: list) -> None:
    for o in outputs:
        _row(
            rows,
            o.name,
            "output",
            o.unit,
            type="Integer" if o.integer else "Real",
            description=o.description,
            lives=f"result.{o.member}",
            depends=list(o.depends),
        )


def _scene_rows(scene: Scene) -> list[dict]:
    """The rows of a tailored scene's table: its inputs, tunable parameters, outputs."""
    if scene.forward():
        return _forward_rows(scene)
    rows: list[dict] = []
    for i in scene.inputs:
        _settable_row(rows, i, "input", i.start, f"input.{i.member}{'@angle' if i.angle else ''}")
    for prm in scene.parameters():
        if prm.tunable:
            _settable_row(rows, prm, "parameter", prm.value, f"input.{prm.member}")
    rows.append(entry_row(setting_entry(ON_SINGULAR), len(rows) + 1, ON_SINGULAR.start))
    _output_rows(rows, scene.outputs)
    return rows


def is_generic(scene: Scene) -> bool:
    """A scene that is one whole dyad: every variable of its type, every parameter tunable,
    both external links free. It is realised by the generic dyad FMU (the core's validating
    solver with its exact directional derivatives) rather than by generated code."""
    if len(scene.dyads) != 1 or scene.drivers:
        return False
    d = scene.dyads[0]
    links = [scene.links[d.m], scene.links[d.n]]
    offered = 2 * 3 + 2 * sum(k == "T" for k in PAIRS[d.type]) + 2 + 1
    return (
        d.name == ""
        and d.m == "link_m"
        and d.n == "link_n"
        and d.k.kind == "external"
        and d.p.kind == "external"
        and scene.inertia
        and scene.gravity
        and all(link.force and link.moment for link in links)
        and len(scene.outputs) == offered
        and all(prm.tunable for prm in scene.parameters())
    )


def entry_row(entry: Entry, vr: int, start: float | None) -> dict:
    """The table row (as a table file holds it) of a catalogue entry."""
    raw = {"name": entry.name, "vr": vr, "causality": entry.causality, "type": entry.value_type}
    if entry.unit:
        raw["unit"] = entry.unit
    if start is not None:
        raw["start"] = start
    raw.update((key, value) for key, value in entry.domain.items() if value is not False)
    raw["description"] = entry.description
    raw["lives"] = entry.lives
    if entry.causality == "output":
        raw["depends"] = list(entry.depends)
    return raw


def generic_data(scene: Scene) -> dict:
    """The variable table (as a table file holds it) of a generic scene."""
    d = scene.dyads[0]
    params = {prm.name: prm for prm in scene.parameters()}
    starts = {i.name: i.start for i in scene.inputs}
    rows = []
    for entry in dyad_catalogue(d.type).values():
        if entry.start is not None:
            start = entry.start
        elif entry.causality == "input":
            start = starts[entry.name]
        else:
            start = params[entry.name].value if entry.causality == "parameter" else None
        rows.append(entry_row(entry, len(rows) + 1, start))
    model = {"type": d.type, "identifier": scene.identifier, "description": scene.description}
    model.update(stop_time=scene.experiment.stop, step_size=scene.experiment.step)
    return {"model": model, "variable": rows}


def kind_of_scene(scene: Scene) -> Kind:
    """The kind that realises a scene: the generic dyad, or the scene's own."""
    return DYAD if is_generic(scene) else SceneKind(scene)


def build_table(scene: Scene) -> Table:
    """The scene's variable table: generic (of kind dyad) or tailored."""
    return kind_of_scene(scene).table_of_scene(scene)

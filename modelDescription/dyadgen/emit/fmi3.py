"""The FMI 3.0 model description and build description."""

from __future__ import annotations

from dyadgen.emit.xmltext import (
    element,
    enumeration_attributes,
    header,
    model_description_text,
    root_attributes,
    type_definitions,
    typed_attributes,
    variable_attributes,
)
from dyadgen.table import Table

#: The FMI 3 element of each table type.
_ELEMENT = {"Real": "Float64", "Integer": "Int32", "Enumeration": "Enumeration"}


def _cosimulation(table: Table) -> str:
    derivatives = [("maxOutputDerivativeOrder", "1")] if table.kind.interpolates else []
    return element(
        1,
        "CoSimulation",
        [
            ("modelIdentifier", table.identifier),
            ("canHandleVariableCommunicationStepSize", "true"),
            *derivatives,
            ("canBeInstantiatedOnlyOncePerProcess", "false"),
            ("canGetAndSetFMUState", "true"),
            ("canSerializeFMUState", "true"),
            ("providesDirectionalDerivatives", table.kind.directional_derivatives),
            ("hasEventMode", "false"),
            ("canReturnEarlyAfterIntermediateUpdate", "false"),
            ("providesIntermediateUpdate", "false"),
        ],
        wrap=True,
    )


def _variables(table: Table) -> list[str]:
    lines = ["  <ModelVariables>"]
    lines.append(
        element(
            2,
            "Float64",
            [
                ("name", "time"),
                ("valueReference", 0),
                ("description", "Simulation time (s), the independent variable"),
                ("causality", "independent"),
                ("variability", "continuous"),
            ],
        )
    )
    for v in table.variables:
        if v.type == "Enumeration":
            attrs = variable_attributes(v) + enumeration_attributes(v)
        else:
            attrs = variable_attributes(v) + typed_attributes(v, unit_first=True)
        lines.append(element(2, _ELEMENT[v.type], attrs))
    lines.append("  </ModelVariables>")
    return lines


def _structure(table: Table) -> list[str]:
    vr_of = {v.name: v.vr for v in table.variables}
    lines = ["  <ModelStructure>"]
    for v in table.of("output"):
        deps = " ".join(str(r) for r in sorted(vr_of[d] for d in v.depends))
        lines.append(element(2, "Output", [("valueReference", v.vr), ("dependencies", deps)]))
    for v in table.of("output"):
        lines.append(element(2, "InitialUnknown", [("valueReference", v.vr)]))
    lines.append("  </ModelStructure>")
    return lines


def model_description(table: Table) -> str:
    """fmi3/modelDescription.xml."""
    root = root_attributes(table, "3.0", "instantiationToken")
    model = _variables(table) + _structure(table)
    return model_description_text(
        table, root, [_cosimulation(table)], type_definitions(table, ("EnumerationType",)), model
    )


def build_description(table: Table) -> str:
    """fmi3/buildDescription.xml: the C files an importer compiles."""
    lines = header(table)
    lines.append('<fmiBuildDescription fmiVersion="3.0">')
    lines.append(
        element(1, "BuildConfiguration", [("modelIdentifier", table.identifier)], close=False)
    )
    lines.append('    <SourceFileSet language="C99">')
    lines += [element(3, "SourceFile", [("name", f)]) for f in table.kind.source_files(table, 3)]
    lines.append("    </SourceFileSet>")
    lines.append("  </BuildConfiguration>")
    lines.append("</fmiBuildDescription>")
    return "\n".join(lines) + "\n"

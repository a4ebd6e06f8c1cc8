"""The FMI 2.0 model description."""

from __future__ import annotations

from dyadgen.emit.xmltext import (
    element,
    enumeration_attributes,
    model_description_text,
    root_attributes,
    type_definitions,
    typed_attributes,
    variable_attributes,
)
from dyadgen.table import Table


def _cosimulation(table: Table) -> list[str]:
    interpolates = table.kind.interpolates
    derivatives = [("maxOutputDerivativeOrder", "1")] if interpolates else []
    lines = [
        element(
            1,
            "CoSimulation",
            [
                ("modelIdentifier", table.identifier),
                ("canHandleVariableCommunicationStepSize", "true"),
                ("canInterpolateInputs", "true" if interpolates else "false"),
                *derivatives,
                ("canBeInstantiatedOnlyOncePerProcess", "false"),
                ("canGetAndSetFMUstate", "true"),
                ("canSerializeFMUstate", "true"),
                ("providesDirectionalDerivative", table.kind.directional_derivatives),
            ],
            close=False,
            wrap=True,
        )
    ]
    lines.append("    <SourceFiles>")
    lines += [element(3, "File", [("name", f)]) for f in table.kind.source_files(table, 2)]
    lines.append("    </SourceFiles>")
    lines.append("  </CoSimulation>")
    return lines


def _variables(table: Table) -> list[str]:
    lines = ["  <ModelVariables>"]
    for v in table.variables:
        lines.append(element(2, "ScalarVariable", variable_attributes(v), close=False))
        if v.type == "Integer":
            lines.append("      <Integer/>")
        elif v.type == "Enumeration":
            lines.append(element(3, "Enumeration", enumeration_attributes(v)))
        else:
            lines.append(element(3, "Real", typed_attributes(v, unit_first=False)))
        lines.append("    </ScalarVariable>")
    lines.append("  </ModelVariables>")
    return lines


def _structure(table: Table) -> list[str]:
    index = {v.name: v.index + 1 for v in table.variables}  # 1-based, FMI 2
    lines = ["  <ModelStructure>", "    <Outputs>"]
    for v in table.of("output"):
        deps = " ".join(str(i) for i in sorted(index[d] for d in v.depends))
        lines.append(element(3, "Unknown", [("index", index[v.name]), ("dependencies", deps)]))
    lines.append("    </Outputs>")
    lines.append("    <InitialUnknowns>")
    for v in table.of("output"):
        lines.append(element(3, "Unknown", [("index", index[v.name])]))
    lines.append("    </InitialUnknowns>")
    lines.append("  </ModelStructure>")
    return lines


def model_description(table: Table) -> str:
    """fmi2/modelDescription.xml."""
    root = root_attributes(table, "2.0", "guid")
    root.append(("numberOfEventIndicators", "0"))
    model = _variables(table) + _structure(table)
    return model_description_text(
        table,
        root,
        _cosimulation(table),
        type_definitions(table, ("SimpleType", "Enumeration")),
        model,
    )

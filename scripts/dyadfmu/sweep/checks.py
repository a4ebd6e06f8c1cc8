"""The names of a study checked against its FMUs' model descriptions before anything
runs: a varied or fixed parameter must be a parameter of its FMU (tunable in the scene),
a load an input, a figure's series an output or input. A name that is not is refused as
``StudyError("FILE:LINE: ...")`` with what the FMU has instead."""

from __future__ import annotations

import math

from fmpy.model_description import ModelDescription

from .studyfile import Counterweight, Driven, Study, StudyError, line_of

__all__ = ["check_names", "base_values", "units_of"]


def _fail(study: Study, table: str, index: int | None, key: str, why: str) -> None:
    line = line_of(study.text, table, index, key)
    raise StudyError(f"{study.path}:{line}: {why}")


def _names(md: ModelDescription, causalities: tuple, reals: bool = False) -> list:
    return [
        v.name
        for v in md.modelVariables
        if v.causality in causalities and (not reals or v.type in ("Real", "Float64"))
    ]


def _short_list(names: list) -> str:
    shown = ", ".join(names[:12])
    return shown + (f", ... ({len(names)} in all)" if len(names) > 12 else "") if names else "none"


def _check_parameters(study: Study, md: ModelDescription, what: str) -> None:
    params = _names(md, ("parameter",), reals=True)
    for k, p in enumerate(study.parameters):
        weight = isinstance(p, Counterweight)
        wanted = p.needs() if weight else () if p.name.startswith("drive.") else (p.name,)
        for name in wanted:
            if name not in params:
                _fail(
                    study,
                    "parameter",
                    k,
                    "counterweight" if weight else "name",
                    f"{name} is not a Real parameter of {what} (make it tunable in the "
                    "scene); "
                    f"its parameters: {_short_list(params)}",
                )
    for name, _ in study.fixed:
        if name not in params:
            _fail(
                study,
                "fixed",
                None,
                name,
                f"{name} is not a Real parameter of {what}; its parameters: {_short_list(params)}",
            )


def _check_columns_and_aliases(study: Study, md: ModelDescription, what: str) -> None:
    """A counterweight's column may not take the name of an FMU parameter (the table
    would show its mass under that name); two names the study sets may not be one
    variable of the FMU (an alias: one would override the other)."""
    variables = {v.name: v.valueReference for v in md.modelVariables}
    owner: dict = {}
    for k, p in enumerate(study.parameters):
        weight = isinstance(p, Counterweight)
        if weight and p.name in variables:
            _fail(
                study,
                "parameter",
                k,
                "name",
                f"{p.name}: a counterweight's name cannot be a variable of {what}",
            )
        for name in p.needs() if weight else (p.name,):
            _claim(
                study,
                owner,
                variables,
                name,
                ("parameter", k, "counterweight" if weight else "name"),
            )
    for name, _ in study.fixed:
        _claim(study, owner, variables, name, ("fixed", None, name))


def _claim(study: Study, owner: dict, variables: dict, name: str, where: tuple) -> None:
    vr = variables.get(name)
    if vr is None:
        return
    if vr in owner and owner[vr] != name:
        _fail(
            study,
            where[0],
            where[1],
            where[2],
            f"{name} and {owner[vr]} are one variable of the FMU (value reference {vr}): "
            "set it once",
        )
    owner[vr] = name


def _check_loads(study: Study, md: ModelDescription, what: str) -> None:
    inputs = [n for n in _names(md, ("input",)) if not n.endswith((".angle", ".omega", ".epsilon"))]
    for load in study.loads:
        if load.name not in inputs:
            _fail(
                study,
                "loads",
                None,
                load.name,
                f"{load.name} is not a load input of {what}; its loads: {_short_list(inputs)}",
            )


def _check_figures(
    study: Study, md: ModelDescription, drive_md: ModelDescription | None, what: str
) -> None:
    known = set(_names(md, ("output", "input"), reals=True))
    if drive_md is not None:
        known |= {"drive." + n for n in _names(drive_md, ("output",), reals=True)}
    for k, f in enumerate(study.figures):
        for name in f.of:
            if name not in known:
                hint = "; the drive's outputs are drive.NAME" if drive_md is not None else ""
                _fail(
                    study,
                    "figure",
                    k,
                    "of",
                    f"{f.name}: {name} is not a Real output or input of {what}{hint}",
                )


def check_names(
    study: Study, md: ModelDescription, drive_md: ModelDescription | None, what: str
) -> None:
    """StudyError where a name of the study is not in its FMUs (``what`` names the
    mechanism FMU in the message)."""
    if isinstance(study.run, Driven) != (drive_md is not None):
        raise ValueError("a driven study needs the drive's model description, only it")
    _check_parameters(study, md, what)
    _check_columns_and_aliases(study, md, what)
    _check_loads(study, md, what)
    _check_figures(study, md, drive_md, what)


def base_values(study: Study, md: ModelDescription) -> dict:
    """The start values of the parameters the counterweights change (StudyError where
    the FMU gives one no finite start value)."""
    start = {v.name: v.start for v in md.modelVariables if v.causality == "parameter"}
    base = {}
    for k, p in enumerate(study.parameters):
        for name in p.needs() if isinstance(p, Counterweight) else ():
            try:
                value = float(start.get(name))
            except (TypeError, ValueError):
                value = math.nan
            if not math.isfinite(value):
                _fail(
                    study,
                    "parameter",
                    k,
                    "counterweight",
                    f"{p.name}: the FMU gives {name} no finite start value "
                    f"(start {start.get(name)!r})",
                )
            base[name] = value
    return base


def _unit(md: ModelDescription | None, name: str) -> str:
    if md is None:
        return "1"
    return next((v.unit for v in md.modelVariables if v.name == name and v.unit), "1")


def _figure_unit(of_unit: str, stat: str) -> str:
    if stat in ("fluctuation", "drop"):
        return "1"
    if stat == "work_per_revolution":
        return "J" if of_unit == "N.m" else f"{of_unit}.rad"
    return of_unit


def units_of(study: Study, md: ModelDescription, drive_md: ModelDescription | None) -> dict:
    """The unit of every parameter and figure of the study (FMI unit names; "1" for none)."""

    def unit(name: str) -> str:
        if name.startswith("drive."):
            return _unit(drive_md, name[6:])
        return _unit(md, name)

    units = {
        p.name: "kg" if isinstance(p, Counterweight) else unit(p.name) for p in study.parameters
    }
    units.update({f.name: _figure_unit(unit(f.of[0]), f.stat) for f in study.figures})
    return units

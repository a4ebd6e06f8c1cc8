"""The names of a study checked against its FMUs' model descriptions before anything
runs: a varied or fixed parameter must be a parameter of its FMU (tunable in the scene),
a load an input, a figure's series an output or input. A name that is not is refused as
``StudyError("FILE:LINE: ...")`` with what the FMU has instead."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fmpy.model_description import ModelDescription

from .studyfile import Counterweight, Driven, Kinetostatic, Stroke, Study, StudyError, line_of

__all__ = [
    "check_names",
    "base_values",
    "units_of",
    "Driver",
    "driver_of",
    "drivers_of",
    "DRIVERS",
]

#: Each kind of driver: its coordinate, rate and acceleration inputs, and its effort
#: output (the torque or force that drives it), as DRIVER.<suffix>.
DRIVERS = {
    "crank": ("angle", "omega", "epsilon", "torque"),
    "ram": ("position", "velocity", "acceleration", "force"),
    "cylinder": ("length", "velocity", "acceleration", "force"),
}
#: A driver's coordinate and its unit, as messages name them.
_COORDINATE = {"crank": "angle, rad", "ram": "position, m", "cylinder": "length, m"}


@dataclass(frozen=True)
class Driver:
    """The driver of a mechanism FMU: its ``kind`` (crank, ram or cylinder), ``name``, the
    ``motion`` inputs it takes (its coordinate, then its rate and acceleration where the
    FMU has inertia), its ``effort`` output and, for a cylinder whose geometry is among
    the FMU's parameters, the ``geometry`` parameters: its link's pivot O (x, y), its
    barrel's pin A (x, y), its rod's pin B in the link's frame (x, y), its branch; and
    its ``link`` (None otherwise)."""

    kind: str
    name: str
    motion: tuple
    effort: str
    link: str | None = None
    geometry: tuple = ()


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


def _cylinder_geometry(name: str, md: ModelDescription) -> tuple[str | None, tuple]:
    """(link, geometry parameters) of cylinder ``name`` where the FMU has them all as Real
    parameters: the link is the one with a pivot ``LINK.at`` and an angle output."""
    params = set(_names(md, ("parameter",), reals=True))
    outputs = set(_names(md, ("output",), reals=True))
    links = {n[: -len(".at.x")] for n in params if n.endswith(".at.x")}
    links = sorted(k for k in links if f"{k}.at.y" in params and f"{k}.angle" in outputs)
    if len(links) != 1:
        return None, ()
    link = links[0]
    geometry = (
        f"{link}.at.x", f"{link}.at.y", f"{name}.base.x", f"{name}.base.y",
        f"{name}.pin.x", f"{name}.pin.y", f"{name}.branch",
    )  # fmt: skip
    return (link, geometry) if set(geometry) <= params else (None, ())


def drivers_of(md: ModelDescription) -> list[Driver]:
    """The mechanism FMU's drivers, cranks, rams, cylinders: a crank (inputs
    CRANK.angle, .omega, .epsilon, output CRANK.torque), a ram (RAM.position, output
    RAM.force) or a cylinder (NAME.length, output NAME.force), their rates where the FMU
    takes them."""
    inputs = _names(md, ("input",))
    outputs = set(_names(md, ("output",)))
    found = []
    for kind, (q, rate, acceleration, effort) in DRIVERS.items():
        for n in inputs:
            name = n[: -len(q) - 1]
            if not (n.endswith("." + q) and f"{name}.{effort}" in outputs):
                continue
            rates = tuple(f"{name}.{r}" for r in (rate, acceleration) if f"{name}.{r}" in inputs)
            if kind == "crank" and len(rates) != 2:
                continue
            link, geometry = _cylinder_geometry(name, md) if kind == "cylinder" else (None, ())
            found.append(Driver(kind, name, (n, *rates), f"{name}.{effort}", link, geometry))
    return found


def driver_of(md: ModelDescription) -> Driver | None:
    """The mechanism FMU's first driver (:func:`drivers_of`); None where it has none."""
    return next(iter(drivers_of(md)), None)


def _check_driver(study: Study, md: ModelDescription, what: str) -> Driver:
    """The FMU's driver, refused at the run's line where the run is not one it can do."""
    drivers, run = drivers_of(md), study.run
    source = "scene" if study.scene is not None else "fmu"
    if len(drivers) > 1:
        # a run moves one driver: the others' motion inputs would stay at their start values
        names = ", ".join(f"the {d.kind} {d.name}" for d in drivers)
        _fail(
            study,
            "study",
            None,
            source,
            f"{what} has {len(drivers)} drivers ({names}): a study moves one driver; "
            "give a mechanism FMU with one",
        )
    d = drivers[0] if drivers else None
    if d is None:
        _fail(
            study,
            "study",
            None,
            source,
            f"{what}: the study needs a mechanism FMU driven by a crank (inputs CRANK.angle, "
            ".omega, .epsilon, output CRANK.torque), a ram (RAM.position, output RAM.force) "
            "or a cylinder (NAME.length, output NAME.force); this FMU has none",
        )
    driven_by = f"{what} is driven by the {d.kind} {d.name}"
    if d.kind != "crank" and not isinstance(run, Stroke):
        key = "speed" if isinstance(run, Kinetostatic) else "kind"
        angle = " or angle = [low, high] (rad, its link's)" if d.kind == "cylinder" else ""
        _fail(
            study,
            "run",
            None,
            key,
            f"{key} turns a crank ({'a revolution' if key == 'speed' else 'by the drive FMU'})"
            f"; {driven_by}: give kind = 'kinetostatic', stroke = [low, high] (m, its "
            f"{_COORDINATE[d.kind]}){angle} and duration (s)",
        )
    if isinstance(run, Stroke):
        _check_stroke(study, d, driven_by, what)
    return d


def _check_stroke(study: Study, d: Driver, driven_by: str, what: str) -> None:
    run: Stroke = study.run
    if d.kind == "crank":
        _fail(
            study,
            "run",
            None,
            run.over,
            f"{run.over} moves a ram or a cylinder over its stroke; {driven_by}: give "
            "speed (rad/s, one revolution)",
        )
    if run.over == "angle" and d.kind != "cylinder":
        _fail(
            study,
            "run",
            None,
            "angle",
            f"angle turns a cylinder's link; {driven_by}: give stroke = [low, high] (m, "
            "its position)",
        )
    if run.over == "angle" and not d.geometry:
        _fail(
            study,
            "run",
            None,
            "angle",
            f"angle needs the geometry of cylinder {d.name} among the parameters of "
            f"{what} (LINK.at, {d.name}.base, {d.name}.pin and {d.name}.branch "
            "tunable, and LINK.angle an output; a scene study makes them so): give stroke "
            "= [low, high] (m, its length) instead",
        )
    if d.kind == "cylinder" and run.over == "stroke" and not run.low > 0:
        _fail(
            study,
            "run",
            None,
            "stroke",
            f"a cylinder's length is positive: stroke from {run.low:g} m; {driven_by}",
        )


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
    d = driver_of(md)
    motion = d.motion if d is not None else ()
    inputs = [
        n
        for n in _names(md, ("input",))
        if not n.endswith((".angle", ".omega", ".epsilon")) and n not in motion
    ]
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
    _check_driver(study, md, what)
    _check_parameters(study, md, what)
    _check_columns_and_aliases(study, md, what)
    _check_loads(study, md, what)
    _check_figures(study, md, drive_md, what)


def _start(md: ModelDescription, name: str) -> tuple[float, object]:
    """(the start value of a parameter as a float, NaN where it has none; as given)."""
    start = next((v.start for v in md.modelVariables if v.name == name), None)
    try:
        return float(start), start
    except (TypeError, ValueError):
        return math.nan, start


def base_values(study: Study, md: ModelDescription) -> dict:
    """The start values of the parameters the counterweights change, and of a cylinder's
    geometry for a run over its link's angle (StudyError where the FMU gives one no
    finite start value)."""
    wanted = [
        (name, ("parameter", k, "counterweight"), p.name)
        for k, p in enumerate(study.parameters)
        if isinstance(p, Counterweight)
        for name in p.needs()
    ]
    d = driver_of(md) if isinstance(study.run, Stroke) and study.run.over == "angle" else None
    wanted += [(name, ("run", None, "angle"), "angle") for name in d.geometry] if d else []
    base = {}
    for name, where, who in wanted:
        value, given = _start(md, name)
        if not math.isfinite(value):
            _fail(
                study,
                *where,
                f"{who}: the FMU gives {name} no finite start value (start {given!r})",
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

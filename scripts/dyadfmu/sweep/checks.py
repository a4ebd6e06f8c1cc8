"""The names of a study checked against its FMUs' model descriptions before anything
runs: a varied or fixed parameter must be a parameter of its FMU (tunable in the scene),
a load an input, a figure's series an output or input. A name that is not is refused as
``StudyError("FILE:LINE: ...")`` with what the FMU has instead."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from fmpy.model_description import ModelDescription

from .studyfile import (
    Counterweight,
    Driven,
    DriverRange,
    Kinetostatic,
    MultiStroke,
    Stroke,
    Study,
    StudyError,
    line_of,
)

__all__ = [
    "check_names",
    "base_values",
    "units_of",
    "Driver",
    "driver_of",
    "drivers_of",
    "DRIVERS",
    "angle_runs",
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
    its ``link`` (None otherwise); and the ``carriers`` of O and A (None for the frame, else
    the driver's link they move with)."""

    kind: str
    name: str
    motion: tuple
    effort: str
    link: str | None = None
    geometry: tuple = ()
    carriers: tuple = (None, None)  # the links O and A are points of; None: the frame


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


#: The generator's descriptions of a cylinder's geometry parameters
#: (modelDescription/dyadgen/scenefile/sections.py): the link B is a pin of, and the
#: carriers of O and A, "the frame" or a driver's link.
_PIN_ON = re.compile(r"^The rod's pin B on ([A-Za-z_][A-Za-z0-9_]*), in \1's frame x$")
_CARRIED = re.compile(
    r"^The (?:pivot O of \S+|barrel's pin A) on (?:the frame, global|(\S+), in its frame) x$"
)


def _description(md: ModelDescription, name: str) -> str:
    return next((v.description or "" for v in md.modelVariables if v.name == name), "")


def _cylinder_link(name: str, md: ModelDescription, params: set, outputs: set) -> str | None:
    """The link cylinder ``name`` turns: the one its pin B's description names, else the
    only link with a pivot ``LINK.at`` among the parameters and an angle output."""
    named = _PIN_ON.match(_description(md, f"{name}.pin.x"))
    if named:
        return named.group(1)
    links = {n[: -len(".at.x")] for n in params if n.endswith(".at.x")}
    links = sorted(k for k in links if f"{k}.at.y" in params and f"{k}.angle" in outputs)
    return links[0] if len(links) == 1 else None


def _carriers(md: ModelDescription, link: str, name: str) -> tuple:
    """(O's carrier, A's carrier): None for the frame, else the driver's link they are
    points of, as the parameters' descriptions say (the frame where they say nothing:
    an FMU with one driver has no other link to carry them)."""
    found = []
    for which in (f"{link}.at.x", f"{name}.base.x"):
        said = _CARRIED.match(_description(md, which))
        found.append(said.group(1) if said else None)
    return tuple(found)


def _cylinder_geometry(name: str, md: ModelDescription) -> tuple[str | None, tuple, tuple]:
    """(link, geometry parameters, carriers) of cylinder ``name`` where the FMU has its
    geometry all as Real parameters and its link's angle as an output."""
    params = set(_names(md, ("parameter",), reals=True))
    outputs = set(_names(md, ("output",), reals=True))
    link = _cylinder_link(name, md, params, outputs)
    if link is None or f"{link}.angle" not in outputs:
        return None, (), (None, None)
    geometry = (
        f"{link}.at.x", f"{link}.at.y", f"{name}.base.x", f"{name}.base.y",
        f"{name}.pin.x", f"{name}.pin.y", f"{name}.branch",
    )  # fmt: skip
    if not set(geometry) <= params:
        return None, (), (None, None)
    return link, geometry, _carriers(md, link, name)


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
            link, geometry, carriers = (
                _cylinder_geometry(name, md) if kind == "cylinder" else (None, (), (None, None))
            )
            motion = (n, *rates)
            found.append(Driver(kind, name, motion, f"{name}.{effort}", link, geometry, carriers))
    return found


def driver_of(md: ModelDescription) -> Driver | None:
    """The mechanism FMU's first driver (:func:`drivers_of`); None where it has none."""
    return next(iter(drivers_of(md)), None)


def _check_driver(study: Study, md: ModelDescription, what: str) -> Driver:
    """The FMU's driver, refused at the run's line where the run is not one it can do."""
    drivers, run = drivers_of(md), study.run
    source = "scene" if study.scene is not None else "fmu"
    d = drivers[0] if drivers else None
    if d is not None and isinstance(run, MultiStroke):
        _check_multi(study, md, drivers, what)
        return d
    if len(drivers) > 1:
        # a run over one driver would leave the others' motion inputs at their start values
        key = "kind" if isinstance(run, Driven) else getattr(run, "over", "speed")
        _fail(
            study,
            "run",
            None,
            key,
            f"{what} has {len(drivers)} drivers ({_listed(drivers)}): a run over one driver "
            "would leave the others at their start values; give each driver its range in a "
            "[[run.driver]] table (name, and angle or stroke)",
        )
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


def _listed(drivers: list) -> str:
    return ", ".join(f"the {d.kind} {d.name}" for d in drivers)


def _check_multi(study: Study, md: ModelDescription, drivers: list, what: str) -> None:
    """A run moving several drivers: each [[run.driver]] names a driver of the FMU with a
    range it can take, and every driver of the FMU is named (one left out would stay at
    its start value, its rates at zero)."""
    by_name = {d.name: d for d in drivers}
    for k, entry in enumerate(study.run.drivers):
        d = by_name.get(entry.name)
        if d is None:
            _fail(
                study,
                "run.driver",
                k,
                "name",
                f"{entry.name} is no driver of {what}; its drivers: {_listed(drivers)}",
            )
        _check_range(study, md, k, entry, d, by_name)
    named = {e.name for e in study.run.drivers}
    left = [d for d in drivers if d.name not in named]
    if left:
        _fail(
            study,
            "run",
            None,
            None,
            f"the run moves no range of {_listed(left)} of {what}: give every driver a "
            "[[run.driver]] table (one left out would stay at its start value)",
        )


def _check_range(
    study: Study, md: ModelDescription, k: int, entry: DriverRange, d: Driver, by_name: dict
) -> None:
    """One [[run.driver]]'s range against its driver."""
    it = f"{d.name} is a {d.kind}"
    if entry.over == "angle" and d.kind == "ram":
        _fail(study, "run.driver", k, "angle",
              f"angle turns a crank or a cylinder's link; {it}: give stroke = [low, high] "
              "(m, its position)")  # fmt: skip
    if entry.over == "stroke" and d.kind == "crank":
        _fail(study, "run.driver", k, "stroke",
              f"stroke moves a ram or a cylinder; {it}: give angle = [low, high] (rad, its "
              "angle)")  # fmt: skip
    if d.kind == "cylinder" and entry.over == "stroke" and not min(entry.start, entry.end) > 0:
        _fail(study, "run.driver", k, "stroke",
              f"a cylinder's length is positive: stroke = [{entry.start:g}, {entry.end:g}] m; "
              f"{it}")  # fmt: skip
    if d.kind == "cylinder" and entry.over == "angle":
        _check_cylinder_angle(study, md, k, entry, d, by_name)


def _check_cylinder_angle(
    study: Study, md: ModelDescription, k: int, entry: DriverRange, d: Driver, by_name: dict
) -> None:
    """A cylinder's link turned over an angle: its geometry among the FMU's parameters,
    O and A on one body (the frame, or a rotating driver's link whose angle the FMU
    gives), less than pi between the toggles."""

    def fail(why: str) -> None:
        _fail(study, "run.driver", k, "angle", f"cylinder {d.name}: {why}")

    if not d.geometry:
        fail(
            "angle needs its geometry among the FMU's parameters (LINK.at, "
            f"{d.name}.base, {d.name}.pin and {d.name}.branch tunable, and LINK.angle an "
            "output; a scene study makes them so): give stroke = [low, high] (m, its "
            "length) instead"
        )
    o_on, a_on = d.carriers
    if o_on != a_on:
        fail(
            f"its pivot O is on {o_on or 'the frame'} and its barrel's pin A on "
            f"{a_on or 'the frame'}: its length depends on the angles of {d.link} and of "
            f"{o_on or a_on}, not on one angle; give stroke = [low, high] (m, its length)"
        )
    # the carrier turns with its angle: a crank's (an input) or a cylinder's link's (an
    # output); a ram's slides and has none
    rams = {d.name for d in by_name.values() if d.kind == "ram"}
    readable = set(_names(md, ("output", "input"), reals=True))
    if o_on is not None and (o_on in rams or f"{o_on}.angle" not in readable):
        fail(
            f"its pins O and A are on {o_on}, which has no angle in the FMU (a ram, or "
            f"{o_on}.angle not an output): give stroke = [low, high] (m, its length)"
        )
    if not abs(entry.end - entry.start) < math.pi:
        relative = f" relative to {o_on}" if o_on else ""
        fail(
            f"angle spans {abs(entry.end - entry.start):.6g} rad: a cylinder turns its link"
            f"{relative} by less than pi between its toggles (O, A and B in line)"
        )


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
    motion = {n for d in drivers_of(md) for n in d.motion}
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
    wanted += [(name, where, "angle") for where, d in angle_runs(study, md) for name in d.geometry]
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


def angle_runs(study: Study, md: ModelDescription) -> list:
    """[(where in the study file, Driver)] of the cylinders the run turns over their
    links' angles (their lengths then come from their geometry)."""
    run = study.run
    if isinstance(run, Stroke) and run.over == "angle":
        d = driver_of(md)
        return [(("run", None, "angle"), d)] if d is not None else []
    if not isinstance(run, MultiStroke):
        return []
    by_name = {d.name: d for d in drivers_of(md)}
    return [
        (("run.driver", k, "angle"), by_name[e.name])
        for k, e in enumerate(run.drivers)
        if e.over == "angle" and e.name in by_name and by_name[e.name].kind == "cylinder"
    ]


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

"""A study file (TOML) read into typed data: what FMUs, which parameters over which
ranges, how each design runs, the load case, the figures and the objective.

Everything in a study file is untrusted input. A problem is refused as
``StudyError("FILE:LINE: what is wrong")``, naming the key; nothing runs then. The
format is described in modelDescription/scenes/studies/README.md.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn

import numpy as np

__all__ = [
    "StudyError",
    "Parameter",
    "Counterweight",
    "LoadTable",
    "Figure",
    "Constraint",
    "Objective",
    "Sampling",
    "Kinetostatic",
    "Stroke",
    "DriverRange",
    "MultiStroke",
    "Driven",
    "Study",
    "read_study",
    "line_of",
    "STATS",
    "SAMPLING_METHODS",
]

#: What a figure makes of its series (see :mod:`dyadfmu.sweep.figures`).
STATS = ("peak", "rms", "mean", "min", "max", "fluctuation", "drop", "work_per_revolution")
SAMPLING_METHODS = ("grid", "random", "lhs")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")
#: The drive FMU's parameters a study may set or vary (as ``drive.<name>``).
DRIVE_PARAMETERS = ("motor.stall_torque", "motor.no_load_speed", "inertia")
#: The table's own columns, which no parameter or figure may be named.
RESERVED_COLUMNS = ("design", "digits", "status", "message")
#: The digits a design's outputs must keep by default ([study] min_digits): half of a
#: double's, the core's singular threshold sqrt(eps) on a load that does not cancel.
MIN_DIGITS = 8.0
#: The most digits a double gives: -log10(eps), eps = 2^-52.
DOUBLE_DIGITS = 52 * math.log10(2)
#: A driven run's figures are taken from at least this many communication points.
MIN_RECORDED = 10
#: The most work a study may ask for: driver positions (kinetostatic: designs x points)
#: or communication steps (driven: designs x steps), a few hours on one core here. A
#: study beyond them is split into several.
MAX_POSITIONS = 10_000_000_000
MAX_STEPS = 100_000_000
#: A stroke run's bounds: the driver's coordinate within +-MAX_STROKE m, a link's angle
#: within +-MAX_ANGLE rad (the load tables' bound).
MAX_STROKE = 1e4
MAX_ANGLE = 100.0
#: The most drivers a run moves at once ([[run.driver]] tables).
MAX_RUN_DRIVERS = 32
#: A counterweight's bounds: its mass (kg) and its distance from the link's frame (m).
MAX_COUNTERWEIGHT_MASS = 1e6
MAX_COUNTERWEIGHT_AT = 1e3
#: The largest load a load case may give (in the load input's unit: N or N m).
MAX_LOAD = 1e12
#: The largest study file read, and the deepest nesting of its arrays and tables (the
#: scene generator's limits for a scene file: modelDescription/dyadgen/tomltext.py).
MAX_STUDY_BYTES = 1_000_000
MAX_NESTING = 32
_STRINGS_AND_COMMENTS = re.compile(
    r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*|\Z'
)


class StudyError(ValueError):
    """A study file refused: the message starts with FILE:LINE."""


def finite(value: object) -> float | None:
    """``value`` as a finite float; None for anything else (a bool, a string, an
    integer too large for a float, inf, NaN)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class Parameter:
    """A varied FMU parameter: ``name`` of the mechanism FMU, or ``drive.<name>`` of the
    drive FMU, from ``low`` to ``high`` (its unit is the FMU's)."""

    name: str
    low: float
    high: float

    def assign(self, value: float, base: dict) -> dict:
        """The FMU parameter values this design value sets: {fmu variable name: value}."""
        return {self.name: value}

    def needs(self) -> tuple:
        """The FMU parameters whose start values :meth:`assign` reads."""
        return ()


@dataclass(frozen=True)
class Counterweight:
    """A point mass (kg, from ``low`` to ``high``) added to link ``link`` at ``at`` (m, in
    the link's frame): it changes the link's mass, centre of mass and inertia about it."""

    name: str
    low: float
    high: float
    link: str
    at: tuple

    def needs(self) -> tuple:
        """The link's mass, centre of mass and inertia, as the FMU starts with them."""
        return tuple(f"{self.link}.{p}" for p in ("mass", "com.x", "com.y", "inertia"))

    def assign(self, value: float, base: dict) -> dict:
        """The link's parameters with the mass ``value`` added at ``at``."""
        m0, cx, cy, i0 = (base[n] for n in self.needs())
        ax, ay = self.at
        mass = m0 + value
        names = self.needs()
        if not mass > 0:  # nothing there: the link as it was
            return dict(zip(names, (mass, cx, cy, i0), strict=True))
        gx, gy = (m0 * cx + value * ax) / mass, (m0 * cy + value * ay) / mass
        inertia = (
            i0 + m0 * ((cx - gx) ** 2 + (cy - gy) ** 2) + value * ((ax - gx) ** 2 + (ay - gy) ** 2)
        )
        return dict(zip(names, (mass, gx, gy, inertia), strict=True))


@dataclass(frozen=True)
class LoadTable:
    """An input of the mechanism FMU as a periodic function of the crank angle: linear
    between (angle [rad], value) points over one revolution from angle[0]."""

    name: str
    angle: tuple
    value: tuple

    def at(self, phi: float) -> float:
        """The load at crank angle ``phi`` (rad)."""
        a0 = self.angle[0]
        x = a0 + (phi - a0) % (2 * math.pi)
        angles = self.angle + (a0 + 2 * math.pi,)
        values = self.value + (self.value[0],)
        for k in range(len(angles) - 1):
            if x <= angles[k + 1]:
                span = angles[k + 1] - angles[k]
                w = (x - angles[k]) / span if span > 0 else 1.0
                return values[k] + w * (values[k + 1] - values[k])
        return values[-1]


@dataclass(frozen=True)
class Figure:
    """A number collected per run: ``stat`` of the series ``of`` (one output, or the
    magnitude of two: a vector's x and y)."""

    name: str
    of: tuple
    stat: str


@dataclass(frozen=True)
class Constraint:
    """A design is feasible where ``minimum`` <= ``figure`` <= ``maximum`` (a bound that
    is None does not apply; at least one is given)."""

    figure: str
    maximum: float | None = None
    minimum: float | None = None

    def met(self, values: np.ndarray) -> np.ndarray:
        """Which of the figure's ``values`` meet the constraint (NaN meets none)."""
        values = np.asarray(values, dtype=float)
        ok = np.isfinite(values)
        if self.minimum is not None:
            ok &= values >= self.minimum
        if self.maximum is not None:
            ok &= values <= self.maximum
        return ok

    @property
    def higher_is_better(self) -> bool:
        """A lower bound alone: the larger the figure, the further inside (a transmission
        angle, a conditioning)."""
        return self.maximum is None


@dataclass(frozen=True)
class Objective:
    """The figure to minimise, the constraints, and how many best designs to list."""

    minimize: str
    constraints: tuple = ()
    best: int = 5


@dataclass(frozen=True)
class Sampling:
    """How the designs are drawn: ``grid`` (``count`` values per parameter), ``random``
    or ``lhs`` (``count`` designs, from ``seed``)."""

    method: str
    count: int
    seed: int = 0


@dataclass(frozen=True)
class Kinetostatic:
    """Each design: one revolution of the crank at constant ``speed`` (rad/s), at
    ``points`` equally spaced angles."""

    speed: float
    points: int


@dataclass(frozen=True)
class Stroke:
    """Each design: a linear driver (a ram or a cylinder) moved once over its stroke,
    rest to rest in ``duration`` s (a cycloidal rise, :mod:`dyadfmu.sweep.stroke`), at
    ``points`` equally spaced instants, both ends included. ``over`` "stroke": the
    driver's coordinate (a ram's position, a cylinder's length, m) from ``low`` to
    ``high``; "angle": a cylinder's link turned from ``low`` to ``high`` (rad), the
    cylinder's length at each angle from the design's geometry."""

    over: str
    low: float
    high: float
    duration: float
    points: int


@dataclass(frozen=True)
class DriverRange:
    """One driver of a :class:`MultiStroke` run: ``name`` (a crank, a ram or a cylinder of
    the FMU) moved from ``start`` to ``end`` (either way; held still where they are
    equal): ``over`` "angle" (rad: a crank's angle, or a cylinder's link's angle, relative
    to the link carrying the cylinder's pins where they sit on a moving link) or "stroke"
    (m: a ram's position, a cylinder's length)."""

    name: str
    over: str
    start: float
    end: float


@dataclass(frozen=True)
class MultiStroke:
    """Each design: every driver of the FMU moved at once, each over its own range
    (``drivers``, :class:`DriverRange`, in the file's order), all rest to rest along the
    cycloidal rise of :mod:`dyadfmu.sweep.stroke` in one ``duration`` s, at ``points``
    equally spaced instants, both ends included."""

    duration: float
    points: int
    drivers: tuple


#: The runs over time under constant loads (no crank revolution, no load tables).
OVER_TIME = (Stroke, MultiStroke)


@dataclass(frozen=True)
class Driven:
    """Each design: the drive FMU and the mechanism FMU co-simulated (stabilised
    coupling) from ``start_speed`` (rad/s) for ``duration`` s at communication step
    ``step`` s; figures from ``settle`` s on. ``drive`` holds the drive's fixed
    parameters."""

    step: float
    duration: float
    settle: float
    start_speed: float
    start_angle: float = 0.0
    drive: tuple = ()  # ((name, value), ...)


@dataclass(frozen=True)
class Study:
    """A study file, read and checked."""

    path: Path
    description: str
    scene: Path | None
    fmu: Path | None
    fmi: int
    run: Kinetostatic | Stroke | MultiStroke | Driven
    parameters: tuple
    sampling: Sampling
    loads: tuple
    fixed: tuple  # ((mechanism parameter name, value), ...)
    figures: tuple
    objective: Objective
    text: str = field(repr=False, default="")
    min_digits: float = MIN_DIGITS

    @property
    def name(self) -> str:
        """The study's name: its file name without .toml."""
        return self.path.stem


# ---- locating a key ------------------------------------------------------------------------


_KEY_PART = re.compile(r"""\s*(?:"((?:[^"\\]|\\.)*)"|'([^']*)'|([A-Za-z0-9_-]+))\s*""")


def _key_path(line: str, pos: int) -> tuple[tuple, int] | None:
    """The parts of the TOML dotted key at ``pos`` (``a."b.c".d`` gives a, b.c, d) and
    where it ends, None where no key starts there."""
    parts = []
    while True:
        m = _KEY_PART.match(line, pos)
        if not m:
            return None
        basic, literal, bare = m.groups()
        parts.append(basic.replace('\\"', '"') if basic is not None else literal or bare or "")
        pos = m.end()
        if not line.startswith(".", pos):
            return tuple(parts), pos
        pos += 1


def _header(line: str) -> tuple | None:
    """The table name of a ``[a.b]`` or ``[[a.b]]`` line as its parts, None for another."""
    text = line.strip()
    opening = 2 if text.startswith("[[") else 1 if text.startswith("[") else 0
    found = _key_path(text, opening) if opening else None
    if found is None or not text.startswith("]" * opening, found[1]):
        return None
    rest = text[found[1] + opening :].strip()
    return found[0] if not rest or rest.startswith("#") else None


def _assigned_key(line: str) -> tuple | None:
    """The key a ``key = value`` line assigns, as its parts."""
    found = _key_path(line, 0)
    return found[0] if found and line.startswith("=", found[1]) else None


def line_of(text: str, table: str, index: int | None = None, key: str | None = None) -> int:
    """The line of ``key`` in ``[table]`` (or the ``index``-th ``[[table]]``), else of
    the table's header, else 1. ``table`` "" is the file's top level. A key written as a
    dotted key (``gravity.x = 1``) or as a sub-table (``[fixed.gravity]``) is found by its
    first part."""
    want = tuple(table.split(".")) if table else ()
    seen, inside, prefix, header_line = -1, not want, (), 0
    for number, line in _outside_strings(text):
        header = _header(line)
        if header is not None:
            inside, prefix = False, ()
            if header == want:
                seen += 1
                inside = index is None or seen == index
                header_line = number if inside else header_line
            elif header[: len(want)] == want and index is None:  # a sub-table of it
                inside, prefix = True, header[len(want) :]
                header_line = header_line or number
                if key is not None and prefix[0] == key:
                    return number
            continue
        assigned = _assigned_key(line) if inside and key is not None else None
        if assigned is not None and (prefix + assigned)[0] == key:
            return number
    if not header_line and want:  # written as a top-level key: run = { ... }, run.kind = ...
        return _top_level_line(text, want + ((key,) if key is not None else ()))
    return header_line or 1


def _top_level_line(text: str, path: tuple) -> int:
    """The line of the top-level dotted key that starts with most of ``path``."""
    best, best_length = 1, 0
    for number, line in _outside_strings(text):
        if _header(line) is not None:
            break
        assigned = _assigned_key(line) or ()
        length = next(
            (n for n in range(min(len(path), len(assigned)), 0, -1) if assigned[:n] == path[:n]), 0
        )
        if length > best_length:
            best, best_length = number, length
    return best


def _outside_strings(text: str):
    """(line number, line) of the lines that do not start inside a multi-line string."""
    quote = None
    for number, line in enumerate(text.splitlines(), start=1):
        if quote is None:
            yield number, line
        for delimiter in re.findall(r'"""|\'\'\'', line):
            if quote is None:
                quote = delimiter
            elif delimiter == quote:
                quote = None


class _Reader:
    """Reads values out of a parsed study file, refusing a bad one with its line."""

    def __init__(self, path: Path, text: str):
        self.path, self.text = path, text

    def fail(
        self, table: str, why: str, index: int | None = None, key: str | None = None
    ) -> NoReturn:
        """Raise StudyError at the key's line."""
        line = line_of(self.text, table, index, key)
        raise StudyError(f"{self.path}:{line}: {why}")

    def table(self, data: dict, name: str, required: bool = True) -> dict:
        """A table at the top of the file."""
        value = data.get(name)
        if value is None:
            if required:
                self.fail(name, f"a [{name}] table is required")
            return {}
        if not isinstance(value, dict):
            self.fail("", f"{name} must be a table: [{name}]", key=name)
        return value

    def number(
        self,
        t: dict,
        table: str,
        key: str,
        index: int | None = None,
        default: object = None,
        positive: bool = False,
    ) -> float:
        """A finite number (a positive one if ``positive``)."""
        value = t.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(table, f"{key} must be a number (got {_shown(value)})", index, key)
        x = finite(value)
        if x is None or (positive and not x > 0):
            kind = "a positive finite number" if positive else "a finite number"
            self.fail(table, f"{key} must be {kind} (got {_shown(value)})", index, key)
        return x

    def integer(
        self, t: dict, table: str, key: str, low: int, high: int, default: object = None
    ) -> int:
        """An integer in [low, high]."""
        value = t.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            self.fail(table, f"{key} must be an integer from {low} to {high}", None, key)
        return value

    def name(self, value: object, table: str, key: str, index: int | None = None) -> str:
        """A variable name: dot-separated identifiers."""
        if not isinstance(value, str) or not _NAME.match(value) or len(value) > 200:
            self.fail(table, f"{key} must be a variable name like 'crank.mass'", index, key)
        return value

    def unknown_keys(self, t: dict, table: str, allowed: tuple, index: int | None = None) -> None:
        """Refuse a key the format does not have (a misspelt one, say)."""
        for key in t:
            if key not in allowed:
                self.fail(table, f"unknown key {key!r}; expected {', '.join(allowed)}", index, key)


def _shown(value: object) -> str:
    """A value as a message shows it: short, one line."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 40 else text[:37] + "..."


# ---- the parts -----------------------------------------------------------------------------


def _sources(r: _Reader, study: dict) -> tuple:
    scene, fmu = study.get("scene"), study.get("fmu")
    if (scene is None) == (fmu is None):
        r.fail("study", "give exactly one of scene (a scene file) or fmu (an .fmu file)")
    key = "scene" if scene is not None else "fmu"
    value = scene if scene is not None else fmu
    if not isinstance(value, str) or not value or "\0" in value:
        r.fail("study", f"{key} must be a file name", key=key)
    suffix = ".toml" if key == "scene" else ".fmu"
    try:
        path = (r.path.parent / value).resolve()
        found = path.suffix == suffix and path.is_file()
    except (OSError, RuntimeError):  # a name too long, a loop of symbolic links
        found = False
    if not found:
        r.fail(
            "study", f"{key} = {_shown(value)}: no such {suffix} file next to the study", key=key
        )
    return (path, None) if key == "scene" else (None, path)


def _range(
    r: _Reader,
    t: dict,
    key: str,
    unit: str,
    bound: float,
    table: str = "run",
    index: int | None = None,
    rise: bool = True,
) -> tuple[float, float]:
    """A run's [low, high]: two finite numbers within +-bound, low below high where it
    must ``rise`` (else a driver's [start, end], either way)."""
    value = t[key]
    pair = [finite(v) for v in value] if isinstance(value, list) and len(value) == 2 else [None]
    if not all(v is not None and abs(v) <= bound for v in pair):
        r.fail(
            table,
            f"{key} must be [low, high] in {unit}, two finite numbers within +-{bound:g} "
            f"(got {_shown(value)})",
            index,
            key,
        )
    if rise and not pair[0] < pair[1]:
        r.fail(
            table,
            f"{key} must rise, low below high (got [{pair[0]:g}, {pair[1]:g}]): the run "
            "goes from low to high",
            index,
            key,
        )
    return pair[0], pair[1]


def _stroke(r: _Reader, t: dict, key: str) -> Stroke:
    """A run over a linear driver's stroke (``key`` "stroke") or a cylinder's link's
    angle (``key`` "angle")."""
    if key == "stroke":
        low, high = _range(r, t, key, "metres", MAX_STROKE)
    else:
        low, high = _range(r, t, key, "radians", MAX_ANGLE)
        if not high - low < math.pi:
            r.fail(
                "run",
                f"angle spans {high - low:.6g} rad: a cylinder turns its link by less than "
                "pi between its toggles (O, A and B in line)",
                key=key,
            )
    return Stroke(
        over=key,
        low=low,
        high=high,
        duration=r.number(t, "run", "duration", positive=True),
        points=r.integer(t, "run", "points", 8, 100_000, default=101),
    )


def _driver_range(r: _Reader, t: object, k: int, taken: set) -> DriverRange:
    """One [[run.driver]] table: a driver's name and its angle or stroke."""
    where = "run.driver"
    if not isinstance(t, dict):
        r.fail("run", "driver must be an array of tables: [[run.driver]]", key="driver")
    r.unknown_keys(t, where, ("name", "angle", "stroke"), k)
    name = r.name(t.get("name"), where, "name", k)
    if name in taken:
        r.fail(where, f"driver {name} is given twice: one [[run.driver]] per driver", k, "name")
    taken.add(name)
    given = [key for key in ("angle", "stroke") if key in t]
    if len(given) != 1:
        r.fail(
            where,
            f"driver {name}: give one of angle = [low, high] (rad: a crank's angle or a "
            "cylinder's link's) or stroke = [low, high] (m: a ram's position or a cylinder's "
            "length)",
            k,
            given[-1] if given else "name",
        )
    over = given[0]
    start, end = _range(
        r, t, over, "radians" if over == "angle" else "metres",
        MAX_ANGLE if over == "angle" else MAX_STROKE, where, k, rise=False,
    )  # fmt: skip
    return DriverRange(name, over, start, end)


def _multi_stroke(r: _Reader, t: dict) -> MultiStroke:
    """A run moving several drivers at once: [run] holds the duration and the points,
    each [[run.driver]] a driver's range."""
    for key in ("speed", "stroke", "angle"):
        if key in t:
            r.fail(
                "run",
                f"{key} moves a mechanism's only driver; with [[run.driver]] tables each "
                "driver's range is given in its own table (name and angle or stroke)",
                key=key,
            )
    r.unknown_keys(t, "run", ("kind", "duration", "points", "driver"))
    items = t["driver"]
    if not isinstance(items, list) or not items:
        r.fail("run", "driver must be an array of tables: [[run.driver]]", key="driver")
    if len(items) > MAX_RUN_DRIVERS:
        r.fail("run.driver", f"at most {MAX_RUN_DRIVERS} drivers", MAX_RUN_DRIVERS, "name")
    taken: set = set()
    drivers = tuple(_driver_range(r, d, k, taken) for k, d in enumerate(items))
    return MultiStroke(
        duration=r.number(t, "run", "duration", positive=True),
        points=r.integer(t, "run", "points", 8, 100_000, default=101),
        drivers=drivers,
    )


def _kinetostatic(r: _Reader, t: dict) -> Kinetostatic | Stroke:
    """A crank's revolution at ``speed``, or a linear driver's ``stroke`` or ``angle``."""
    r.unknown_keys(t, "run", ("kind", "speed", "points", "stroke", "angle", "duration"))
    given = [k for k in ("speed", "stroke", "angle") if k in t]
    if len(given) != 1:
        r.fail(
            "run",
            "a kinetostatic run takes one of speed (rad/s: a crank's revolution), stroke = "
            "[low, high] (m: a ram's position or a cylinder's length) or angle = [low, "
            "high] (rad: a cylinder's link)",
            # the second of them in the file, or the table where there is none
            key=max(given, key=lambda k: line_of(r.text, "run", key=k)) if given else "kind",
        )
    if given[0] != "speed":
        return _stroke(r, t, given[0])
    if "duration" in t:
        r.fail(
            "run",
            "duration belongs to a run over a stroke or an angle; a crank's run is one "
            "revolution at constant speed",
            key="duration",
        )
    return Kinetostatic(
        speed=r.number(t, "run", "speed", positive=True),
        points=r.integer(t, "run", "points", 8, 100_000, default=360),
    )


def _run(r: _Reader, data: dict) -> Kinetostatic | Stroke | MultiStroke | Driven:
    t = r.table(data, "run")
    kind = t.get("kind")
    if kind == "kinetostatic":
        if "drive" in data:
            r.fail(
                "drive", "[drive] sets the drive FMU's parameters: it needs [run] kind = 'driven'"
            )
        return _multi_stroke(r, t) if "driver" in t else _kinetostatic(r, t)
    if kind == "driven":
        if "driver" in t:
            r.fail(
                "run",
                "[[run.driver]] moves drivers over given ranges: it needs kind = "
                "'kinetostatic'; a driven run turns one crank by the drive FMU",
                key="kind",
            )
        return _driven(r, data, t)
    r.fail("run", f"kind must be 'kinetostatic' or 'driven' (got {kind!r})", key="kind")


def _driven(r: _Reader, data: dict, t: dict) -> Driven:
    """A run of the drive FMU and the mechanism FMU co-simulated, and its [drive]."""
    r.unknown_keys(t, "run", ("kind", "step", "duration", "settle", "start_speed", "start_angle"))
    step = r.number(t, "run", "step", positive=True)
    duration = r.number(t, "run", "duration", positive=True)
    settle = r.number(t, "run", "settle", default=0.0)
    if not 0 <= settle < duration:
        r.fail("run", "settle must be at least 0 and below duration", key="settle")
    if not 2 <= duration / step <= 10_000_000:
        r.fail("run", "duration / step must be from 2 to 1e7 steps", key="step")
    steps = round(duration / step)
    if abs(duration / step - steps) > 1e-9 * steps:
        r.fail(
            "run",
            f"duration must be a whole number of steps (duration / step = {duration / step:.6g})",
            key="duration",
        )
    if steps + 1 - recorded_from(settle, step) < MIN_RECORDED:
        r.fail(
            "run",
            f"settle leaves fewer than {MIN_RECORDED} communication points to take the "
            f"figures from: (duration - settle) / step must be at least {MIN_RECORDED - 1}",
            key="settle",
        )
    drive = r.table(data, "drive", required=False)
    for name in drive:
        if name not in DRIVE_PARAMETERS:
            r.fail(
                "drive",
                f"unknown drive parameter {name!r}; expected one of "
                f"{', '.join(DRIVE_PARAMETERS)} (a name with a dot is written in quotes: "
                '"motor.stall_torque" = 200)',
                key=name,
            )
    return Driven(
        step=step,
        duration=duration,
        settle=settle,
        start_speed=r.number(t, "run", "start_speed"),
        start_angle=r.number(t, "run", "start_angle", default=0.0),
        drive=tuple((n, r.number(drive, "drive", n, positive=True)) for n in drive),
    )


def recorded_from(settle: float, step: float) -> int:
    """The first communication point (its index) whose values a driven run's figures
    take: the first at or after ``settle``."""
    return int(math.ceil(settle / step - 1e-9))


def _parameter(r: _Reader, t: dict, k: int, driven: bool):
    allowed = ("name", "low", "high", "counterweight", "at")
    r.unknown_keys(t, "parameter", allowed, k)
    name = r.name(t.get("name"), "parameter", "name", k)
    if name in RESERVED_COLUMNS:
        r.fail("parameter", f"name {name} is a column of the table already", k, "name")
    low = r.number(t, "parameter", "low", k)
    high = r.number(t, "parameter", "high", k)
    if not low <= high:
        r.fail("parameter", f"{name}: low must not exceed high", k, "high")
    if not math.isfinite(high - low):
        r.fail("parameter", f"{name}: high - low is not a finite number", k, "high")
    if name.startswith("drive.") and not driven:
        r.fail("parameter", f"{name}: a drive parameter needs [run] kind = 'driven'", k, "name")
    if name.startswith("drive.") and name[6:] not in DRIVE_PARAMETERS:
        r.fail(
            "parameter",
            f"{name}: the drive's parameters are "
            f"{', '.join('drive.' + p for p in DRIVE_PARAMETERS)}",
            k,
            "name",
        )
    if "counterweight" not in t:
        if "at" in t:
            r.fail("parameter", "at belongs to a counterweight", k, "at")
        return Parameter(name, low, high)
    if name.startswith("drive."):
        r.fail(
            "parameter", f"{name}: a counterweight's name cannot be a drive parameter", k, "name"
        )
    link = r.name(t["counterweight"], "parameter", "counterweight", k)
    at = t.get("at")
    xy = [finite(v) for v in at] if isinstance(at, list) and len(at) == 2 else [None]
    if not all(v is not None and abs(v) <= MAX_COUNTERWEIGHT_AT for v in xy):
        r.fail(
            "parameter",
            f"at must be [x, y] in metres, each within +-{MAX_COUNTERWEIGHT_AT:g}",
            k,
            "at",
        )
    if low < 0:
        r.fail("parameter", f"{name}: a counterweight's mass cannot be negative", k, "low")
    if high > MAX_COUNTERWEIGHT_MASS:
        r.fail(
            "parameter",
            f"{name}: a counterweight above {MAX_COUNTERWEIGHT_MASS:g} kg",
            k,
            "high",
        )
    return Counterweight(name, low, high, link, (xy[0], xy[1]))


def _parameters(r: _Reader, data: dict, driven: bool) -> tuple:
    items = data.get("parameter")
    if not isinstance(items, list) or not items or not all(isinstance(t, dict) for t in items):
        r.fail("parameter", "at least one [[parameter]] table is required")
    if len(items) > 8:
        r.fail("parameter", "at most 8 parameters", 8)
    params = tuple(_parameter(r, t, k, driven) for k, t in enumerate(items))
    names = [p.name for p in params]
    for k, n in enumerate(names):
        if names.index(n) != k:
            r.fail("parameter", f"parameter {n} is given twice", k, "name")
    return params


def _sampling(r: _Reader, data: dict, n_params: int) -> Sampling:
    t = r.table(data, "sampling")
    r.unknown_keys(t, "sampling", ("method", "count", "seed"))
    method = t.get("method")
    if method not in SAMPLING_METHODS:
        r.fail("sampling", f"method must be one of {', '.join(SAMPLING_METHODS)}", key="method")
    count = r.integer(t, "sampling", "count", 1, 1_000_000)
    if method == "grid" and count**n_params > 1_000_000:
        r.fail("sampling", f"a grid of {count}^{n_params} designs is over a million", key="count")
    if method == "grid" and "seed" in t:
        r.fail("sampling", "a grid is not drawn: seed belongs to random and lhs", key="seed")
    seed = r.integer(t, "sampling", "seed", 0, 2**63 - 1, default=0)
    return Sampling(method, count, seed)


def _load(r: _Reader, name: str, value: object, stroke: bool) -> LoadTable:
    if isinstance(value, int | float) and not isinstance(value, bool):
        v = r.number({name: value}, "loads", name)
        if abs(v) > MAX_LOAD:
            r.fail("loads", f"{name}: a load beyond +-{MAX_LOAD:g}", key=name)
        return LoadTable(name, (0.0,), (v,))
    if stroke:
        r.fail(
            "loads",
            f"{name}: a run over a stroke takes constant loads (a number); a table is over "
            "a crank's angle",
            key=name,
        )
    if not isinstance(value, dict) or set(value) != {"angle", "value"}:
        r.fail(
            "loads",
            f"{name}: a number, or a table {{ angle = [...], value = [...] }} (a name with "
            'a dot is written in quotes: "piston.force" = ...)',
            key=name,
        )
    angle, val = value["angle"], value["value"]
    ok = isinstance(angle, list) and isinstance(val, list) and 1 <= len(angle) == len(val) <= 10_000
    angle = [finite(x) for x in angle] if ok else []
    val = [finite(x) for x in val] if ok else []
    if not ok or any(x is None for x in angle + val):
        r.fail(
            "loads",
            f"{name}: angle and value must be lists of finite numbers of one length",
            key=name,
        )
    if any(abs(x) > MAX_LOAD for x in val) or any(abs(a) > 100 for a in angle):
        r.fail(
            "loads", f"{name}: a load beyond +-{MAX_LOAD:g}, or an angle beyond +-100 rad", key=name
        )
    if (
        any(b < a for a, b in zip(angle, angle[1:], strict=False))
        or angle[-1] - angle[0] >= 2 * math.pi
    ):
        r.fail("loads", f"{name}: the angles must increase within one revolution (rad)", key=name)
    return LoadTable(name, tuple(angle), tuple(val))


def _figures(r: _Reader, data: dict, parameters: tuple, stroke: bool) -> tuple:
    items = data.get("figure")
    if not isinstance(items, list) or not items or not all(isinstance(t, dict) for t in items):
        r.fail("figure", "at least one [[figure]] table is required")
    figures = []
    for k, t in enumerate(items):
        r.unknown_keys(t, "figure", ("name", "of", "stat"), k)
        name = r.name(t.get("name"), "figure", "name", k)
        of = t.get("of")
        of = [of] if isinstance(of, str) else of
        if not isinstance(of, list) or not 1 <= len(of) <= 2:
            r.fail("figure", f"{name}: of must name one output or two (x and y)", k, "of")
        of = tuple(r.name(o, "figure", "of", k) for o in of)
        if t.get("stat") not in STATS:
            r.fail("figure", f"{name}: stat must be one of {', '.join(STATS)}", k, "stat")
        if stroke and t["stat"] == "work_per_revolution":
            r.fail("figure", f"{name}: a run over a stroke has no revolution", k, "stat")
        taken = {f.name for f in figures} | {p.name for p in parameters}
        if name in taken or name in RESERVED_COLUMNS:
            r.fail(
                "figure",
                f"figure name {name} is taken (by a parameter, another figure or a column)",
                k,
                "name",
            )
        figures.append(Figure(name, of, t["stat"]))
    return tuple(figures)


def _objective(r: _Reader, data: dict, figures: tuple) -> Objective:
    t = r.table(data, "objective")
    r.unknown_keys(t, "objective", ("minimize", "constraints", "best"))
    names = {f.name for f in figures}
    minimize = t.get("minimize")
    if not isinstance(minimize, str) or minimize not in names:
        r.fail(
            "objective", f"minimize must name a figure: {', '.join(sorted(names))}", key="minimize"
        )
    items = t.get("constraints", [])
    if not isinstance(items, list) or len(items) > 100:
        r.fail("objective", "constraints must be a list of constraints", key="constraints")
    constraints = [_constraint(r, c, names) for c in items]
    best = r.integer(t, "objective", "best", 1, 1000, default=5)
    return Objective(t["minimize"], tuple(constraints), best)


def _constraint(r: _Reader, c: object, names: set) -> Constraint:
    """One constraint: { figure = NAME, max = NUMBER }, { figure = NAME, min = NUMBER } or
    both bounds."""
    if (
        not isinstance(c, dict)
        or not set(c) <= {"figure", "min", "max"}
        or not {"min", "max"} & set(c)
        or not isinstance(c.get("figure"), str)
        or c["figure"] not in names
    ):
        r.fail(
            "objective",
            "a constraint is { figure = NAME, max = NUMBER }, { figure = NAME, min = NUMBER } "
            f"or both bounds, with NAME one of {', '.join(sorted(names))}",
            key="constraints",
        )
    bounds = {}
    for key in ("min", "max"):
        if key in c:
            bounds[key] = finite(c[key])
            if bounds[key] is None:
                r.fail(
                    "objective",
                    f"{c['figure']}: a constraint's {key} must be a finite number "
                    f"(got {_shown(c[key])})",
                    key="constraints",
                )
    if "min" in bounds and "max" in bounds and not bounds["min"] <= bounds["max"]:
        r.fail(
            "objective",
            f"{c['figure']}: a constraint's min {bounds['min']:g} is above its max "
            f"{bounds['max']:g}: no design could meet it",
            key="constraints",
        )
    return Constraint(c["figure"], maximum=bounds.get("max"), minimum=bounds.get("min"))


def _fixed_value(r: _Reader, fixed: dict, name: str) -> float:
    value = fixed[name]
    if isinstance(value, dict) and value:  # crank.mass = 1 reads as a table crank
        first = next(iter(value))
        r.fail(
            "fixed",
            f'{name}: a name with a dot is written in quotes: "{name}.{first}" = ...',
            key=name,
        )
    return r.number(fixed, "fixed", name)


def _check_assigned_once(r: _Reader, params: tuple, fixed: tuple, run: object) -> None:
    """Refuse an FMU parameter that two entries of the study set: the later one would
    silently override the earlier (two counterweights on one link, a counterweight and
    the link's varied mass, a parameter both varied and fixed)."""
    by: dict = {}

    def claim(name: str, what: str, table: str, index: int | None, key: str) -> None:
        if name in by:
            r.fail(table, f"{name} is set twice: by {by[name]} and by {what}", index, key)
        by[name] = what

    for k, p in enumerate(params):
        if isinstance(p, Counterweight):
            for n in p.needs():
                claim(n, f"counterweight {p.name}", "parameter", k, "counterweight")
        else:
            claim(p.name, f"parameter {p.name}", "parameter", k, "name")
    for n, _ in fixed:
        claim(n, "[fixed]", "fixed", None, n)
    for n, _ in getattr(run, "drive", ()):
        claim(f"drive.{n}", "[drive]", "drive", None, n)


def _check_work(r: _Reader, sampling: Sampling, n_params: int, run: object) -> None:
    designs = sampling.count**n_params if sampling.method == "grid" else sampling.count
    if isinstance(run, Kinetostatic):
        work, limit, what = designs * run.points, MAX_POSITIONS, "crank positions"
    elif isinstance(run, OVER_TIME):
        work, limit, what = designs * run.points, MAX_POSITIONS, "driver positions"
    else:
        steps = round(run.duration / run.step)
        work, limit, what = designs * steps, MAX_STEPS, "communication steps"
    if work > limit:
        r.fail(
            "sampling",
            f"{designs} designs make {work:.3g} {what} in all, over the limit of {limit:.0e}: "
            "split the study",
            key="count",
        )


def too_deep_line(text: str, limit: int = MAX_NESTING) -> int | None:
    """The line where arrays and inline tables first nest deeper than ``limit``, strings
    and comments skipped (the pattern's last branch, the end, scans the rest); None where
    they never do. (The generator's dyadgen/tomltext.py keeps the same check for scenes.)"""
    depth, line, pos = 0, 1, 0
    for found in _STRINGS_AND_COMMENTS.finditer(text):
        for ch in text[pos : found.start()]:
            line += ch == "\n"
            depth += (ch in "[{") - (ch in "]}")
            if depth > limit:
                return line
        line += found.group().count("\n")
        pos = found.end()
    return None


def _read_toml(path: Path) -> tuple[str, dict]:
    """The text of a study file (UTF-8, a byte order mark dropped) and its TOML, within
    MAX_STUDY_BYTES and MAX_NESTING; StudyError naming the file (and line) otherwise."""
    try:
        if not path.is_file() or path.stat().st_size > MAX_STUDY_BYTES:
            raise StudyError(f"{path}: not a study file (a regular file of at most 1 MB)")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as e:
        raise StudyError(f"{path}: cannot read: {e}") from None
    deep = too_deep_line(text)
    if deep is not None:
        raise StudyError(f"{path}:{deep}: arrays or tables nested more than {MAX_NESTING} deep")
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        at = re.search(r"\(at line (\d+), column \d+\)", str(e))
        line = f":{at.group(1)}" if at else ""
        raise StudyError(f"{path}{line}: not valid TOML: {e}") from None
    except RecursionError:  # not reached within MAX_NESTING; the last guard
        raise StudyError(f"{path}: arrays or tables nested too deeply") from None


def read_study(path: Path | str) -> Study:
    """Read and check a study file (StudyError naming FILE:LINE where it is wrong)."""
    path = Path(path)
    text, data = _read_toml(path)
    r = _Reader(path, text)
    r.unknown_keys(
        data,
        "",
        ("study", "run", "drive", "sampling", "parameter", "loads", "fixed", "figure", "objective"),
    )
    study = r.table(data, "study")
    r.unknown_keys(study, "study", ("description", "scene", "fmu", "fmi", "min_digits"))
    description = study.get("description", "")
    if not isinstance(description, str) or len(description) > 500:
        r.fail("study", "description must be one line of text", key="description")
    scene, fmu = _sources(r, study)
    if fmu is not None and "fmi" in study:
        r.fail(
            "study", "fmi chooses the version a scene is built for: an .fmu has its own", key="fmi"
        )
    fmi = r.integer(study, "study", "fmi", 2, 3, default=2)
    min_digits = r.number(study, "study", "min_digits", default=MIN_DIGITS)
    if not 0 <= min_digits <= DOUBLE_DIGITS:
        r.fail(
            "study",
            f"min_digits must be from 0 to {DOUBLE_DIGITS:.2f} (a double's digits), "
            f"got {min_digits:g}",
            key="min_digits",
        )
    run = _run(r, data)
    params = _parameters(r, data, isinstance(run, Driven))
    loads_t = r.table(data, "loads", False)
    stroke = isinstance(run, OVER_TIME)
    loads = tuple(_load(r, r.name(n, "loads", n), v, stroke) for n, v in loads_t.items())
    fixed_t = r.table(data, "fixed", False)
    fixed = tuple((r.name(n, "fixed", n), _fixed_value(r, fixed_t, n)) for n in fixed_t)
    _check_assigned_once(r, params, fixed, run)
    figures = _figures(r, data, params, stroke)
    sampling = _sampling(r, data, len(params))
    _check_work(r, sampling, len(params), run)
    return Study(
        path=path,
        description=" ".join(description.split()),
        scene=scene,
        fmu=fmu,
        fmi=fmi,
        run=run,
        parameters=params,
        sampling=sampling,
        loads=loads,
        fixed=fixed,
        figures=figures,
        objective=_objective(r, data, figures),
        text=text,
        min_digits=min_digits,
    )

"""The interface table of one FMU: its variables (names, value references, causalities,
units, start values, bounds, descriptions), where each value lives in the model's
structures and which inputs each output depends on.

A table written by hand (interface/drive.toml, interface/motor.toml) or derived from a
generic dyad scene is validated first; every problem is reported with the file and the
variable it concerns, and nothing is written unless the table is valid. A tailored scene's table is
made valid by construction (kinds.SceneKind).

Value references start at 1: in FMI 3 the value reference 0 is the independent
variable `time`, which the FMI 3 description declares and the FMI 3 shim serves
itself (the C table has no entry for it).

The instantiation token (FMI 3) / GUID (FMI 2) is "{" + a UUID formed from the SHA-256
of a canonical JSON serialization of the whole table + "}": it changes exactly when the
table does. Output is deterministic (no dates).
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Protocol

from dyadgen import textsafe
from dyadgen.catalogue import Entry
from dyadgen.dyadtypes import UNITS
from dyadgen.model import DEFAULT_EXPERIMENT, Experiment
from dyadgen.structs import Lives, Structs

CAUSALITIES = ("input", "parameter", "output")
VALUE_TYPES = ("Real", "Integer", "Enumeration")
VARIABLE_KEYS = {
    "name",
    "vr",
    "causality",
    "type",
    "unit",
    "start",
    "min",
    "max",
    "min_exclusive",
    "max_exclusive",
    "description",
    "lives",
    "depends",
}
#: [model]'s keys of the DefaultExperiment (s) and their values where not given
EXPERIMENT = {"stop_time": DEFAULT_EXPERIMENT.stop, "step_size": DEFAULT_EXPERIMENT.step}
MODEL_KEYS = {"kind", "type", "identifier", "description", "stop_time", "step_size"}
REQUIRED_KEYS = ("name", "vr", "causality", "type", "description", "lives")
_RANK = {"input": 0, "parameter": 1, "output": 2}
_REAL_KEYS = ("start", "min", "max")


class TableKind(Protocol):
    """What checking a table file needs of its kind of model (kinds.Kind)."""

    def parse_lives(self, text: object) -> Lives:
        """A `lives` of the kind's structs; ValueError with the reason."""

    def catalogue_for(self, model: dict) -> dict[str, Entry]:
        """Every variable a table of this [model] must have; ValueError if there is none."""

    def model_problems(self, model: dict) -> list[str]:
        """What is wrong with [model] for this kind."""

    def owner(self, model: dict) -> str:
        """The model, as messages name it."""

    def absence_reason(self, model: dict, lives: str) -> str:
        """Why a well-formed `lives` is not a variable of this model."""


class TableError(Exception):
    """The table is invalid; args[0] is the list of problems."""


class Variable:
    """One validated row of the table, with its index in file order."""

    def __init__(self, raw: dict, index: int, kind: Structs) -> None:
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
        self.lives = kind.parse_lives(raw["lives"])
        self.depends = list(raw.get("depends", []))


class Table:
    """A valid table: its model ([model]), its variables in value-reference order and
    the kind of model they belong to."""

    def __init__(self, path: Path, model: dict, rows: list[dict], kind: Structs) -> None:
        self.path = path
        self.model = model
        self.rows = rows
        self.kind = kind
        self.type = model.get("type")  # the dyad type; None for other kinds
        self.identifier = model["identifier"]
        self.description = model["description"]
        self.variables = [Variable(raw, k, kind) for k, raw in enumerate(rows)]
        self.by_name = {v.name: v for v in self.variables}
        #: the DefaultExperiment: [model] stop_time and step_size, else the project's default
        self.experiment = Experiment(*(float(model.get(k, v)) for k, v in EXPERIMENT.items()))

    @functools.cached_property
    def token(self) -> str:
        """The instantiation token, a hash of the whole table (computed when first asked
        for: the tables of the C names probe never need it)."""
        return instantiation_token(self.model, self.rows)

    def of(self, causality: str) -> list[Variable]:
        """The variables of one causality, in table order."""
        return [v for v in self.variables if v.causality == causality]

    def counts(self) -> dict[str, int]:
        """How many inputs, parameters and outputs."""
        return {c: len(self.of(c)) for c in CAUSALITIES}


def is_number(x: object) -> bool:
    """An int or a float, not a bool."""
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _finite(x: object) -> bool:
    return is_number(x) and math.isfinite(x)


def _article(word: str) -> str:
    return "an" if word[0] in "aeiou" else "a"


def show_bounds(b: dict) -> str:
    """Bounds as an interval: [min, max], an exclusive end in parentheses."""
    lo = "(" if b.get("min_exclusive") or "min" not in b else "["
    hi = ")" if b.get("max_exclusive") or "max" not in b else "]"
    return f"{lo}{b.get('min', '-inf')}, {b.get('max', 'inf')}{hi}"


def read_table_data(path: Path) -> dict:
    """The TOML of a table file; raises TableError if it cannot be read."""
    fname = Path(path).name
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except OSError as exc:
        raise TableError([f"{fname}: cannot read: {exc.strerror}"]) from None
    except tomllib.TOMLDecodeError as exc:
        raise TableError([f"{fname}: invalid TOML: {exc}"]) from None


class _Check:
    """The checks of one table: every problem, and what the rows seen so far took."""

    def __init__(self, fname: str) -> None:
        self.fname = fname
        self.problems: list[str] = []
        self.label = ""
        self.kind: TableKind | None = None
        self.known: dict[str, Entry] = {}
        self.owner = ""
        self.model: dict = {}
        self.seen_names: dict[str, int] = {}
        self.seen_vrs: dict[int, str] = {}
        self.seen_lives: dict[str, str] = {}
        self.last_rank = 0

    def fail(self, message: str) -> None:
        self.problems.append(f"{self.fname}: {message}")

    def bad(self, message: str) -> None:
        self.fail(f"{self.label}: {message}")

    def fatal(self, message: str) -> TableError:
        return TableError(self.problems + [f"{self.fname}: {message}"])

    # ---- [model]
    def check_model(self, data: dict, kinds: Mapping[str, TableKind]) -> dict:
        for key in sorted(set(data) - {"model", "variable"}):
            self.fail(f"unknown top-level key '{key}' (expected [model] and [[variable]])")
        model = data.get("model")
        if not isinstance(model, dict):
            raise TableError([f"{self.fname}: missing [model] table"])
        for key in sorted(set(model) - MODEL_KEYS):
            self.fail(f"[model]: unknown key '{key}'")
        kind_name = model.get("kind", "dyad")
        if not isinstance(kind_name, str) or kind_name not in kinds:
            raise self.fatal(f"[model]: kind {kind_name!r} is not one of {', '.join(kinds)}")
        self.kind = kinds[kind_name]
        try:
            self.known = self.kind.catalogue_for(model)
        except ValueError as exc:
            raise self.fatal(f"[model]: {exc}") from None
        for message in self.kind.model_problems(model):
            self.fail(f"[model]: {message}")
        self.owner = self.kind.owner(model)
        self.model = model
        identifier = model.get("identifier")
        if not isinstance(identifier, str) or not re.fullmatch(
            r"[A-Za-z_][A-Za-z0-9_]*", identifier
        ):
            self.fail(f"[model]: identifier {identifier!r} must be a C identifier")
        problem = textsafe.description_problem(model.get("description"))
        if problem:
            self.fail(f"[model]: description {problem}")
        self.check_experiment(model)
        return model

    def check_experiment(self, model: dict) -> None:
        """[model] stop_time and step_size (s): finite, positive, the step within the run."""
        run = {k: model.get(k, v) for k, v in EXPERIMENT.items()}
        for key, value in run.items():
            if not (_finite(value) and value > 0):
                self.fail(f"[model]: '{key}' must be a positive number of seconds, not {value!r}")
                return
        if run["step_size"] > run["stop_time"]:
            self.fail("[model]: 'step_size' must not exceed 'stop_time'")

    # ---- one row
    def row(self, k: int, raw: object) -> bool:
        """Check row k; whether it is valid."""
        name = raw.get("name") if isinstance(raw, dict) else None
        self.label = f"variable '{name}'" if isinstance(name, str) else f"variable #{k + 1}"
        if isinstance(raw, dict) and is_number(raw.get("vr")):
            self.label += f" (vr {raw['vr']})"
        if not isinstance(raw, dict):
            self.bad("must be a table")
            return False
        count_before = len(self.problems)
        for key in sorted(set(raw) - VARIABLE_KEYS):
            self.bad(f"unknown key '{key}'")
        for key in REQUIRED_KEYS:
            if key not in raw:
                self.bad(f"missing key '{key}'")
        if self.problems[count_before:]:
            return False
        self.name_and_vr(k, raw)
        causality, value_type, unit = self.causality_type_unit(raw)
        problem = textsafe.description_problem(raw["description"])
        if problem:
            self.bad(f"description {problem}")
        entry = self.lives(raw)
        if entry is not None:
            self.matches(entry, raw, causality, value_type, unit)
        self.start_and_bounds(raw, causality, entry)
        self.depends(raw, causality)
        return not self.problems[count_before:]

    def name_and_vr(self, k: int, raw: dict) -> None:
        name = raw["name"]
        structured = r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*"
        if not isinstance(name, str) or not re.fullmatch(structured, name):
            self.bad(f"name {name!r} is not a structured name (identifiers joined by '.')")
        elif name in self.seen_names:
            self.bad(f"duplicate name (also variable #{self.seen_names[name] + 1})")
        else:
            self.seen_names[name] = k
        vr = raw["vr"]
        if not isinstance(vr, int) or isinstance(vr, bool):
            self.bad(f"vr {vr!r} must be an integer")
            return
        if vr in self.seen_vrs:
            self.bad(f"duplicate vr {vr} (also '{self.seen_vrs[vr]}')")
        else:
            self.seen_vrs[vr] = name
        if vr != k + 1:
            self.bad(
                f"vr {vr} is not consecutive: variable #{k + 1} in file order must have "
                f"vr {k + 1} (vrs run 1, 2, 3, ...; vr 0 is FMI 3's time)"
            )

    def causality_type_unit(self, raw: dict) -> tuple:
        """The row's causality and type (None where invalid) and unit ('?' where invalid)."""
        causality = raw["causality"]
        if causality not in CAUSALITIES:
            self.bad(f"unknown causality {causality!r} (expected one of {', '.join(CAUSALITIES)})")
            causality = None
        else:
            if _RANK[causality] < self.last_rank:
                self.bad(
                    f"{causality} after {CAUSALITIES[self.last_rank]}s: the table must list "
                    "inputs, then parameters, then outputs"
                )
            self.last_rank = max(self.last_rank, _RANK[causality])
        value_type = raw["type"]
        if value_type not in VALUE_TYPES:
            self.bad(f"unknown type {value_type!r} (expected one of {', '.join(VALUE_TYPES)})")
            value_type = None
        unit = raw.get("unit")
        if unit is not None and unit not in UNITS:
            self.bad(f"unknown unit {unit!r} (known: {', '.join(UNITS)}; omit it if dimensionless)")
            unit = "?"
        return causality, value_type, unit

    def lives(self, raw: dict) -> Entry | None:
        """The catalogue's entry of the row's `lives`, or None where there is none."""
        try:
            self.kind.parse_lives(raw["lives"])
        except ValueError as exc:
            self.bad(f"bad lives {raw['lives']!r}: {exc}")
            return None
        key = raw["lives"]
        entry = self.known.get(key)
        if entry is None:
            self.bad(f"lives {key!r}: {self.kind.absence_reason(self.model, key)}")
        elif key in self.seen_lives:
            self.bad(f"lives {key!r} is also the home of '{self.seen_lives[key]}'")
            entry = None
        else:
            self.seen_lives[key] = raw["name"]
        return entry

    def matches(
        self,
        entry: Entry,
        raw: dict,
        causality: str | None,
        value_type: str | None,
        unit: str | None,
    ) -> None:
        name = raw["name"]
        if causality is not None and causality != entry.causality:
            self.bad(
                f"causality '{causality}' but {entry.lives} is "
                f"{_article(entry.causality)} {entry.causality} of the {self.owner}"
            )
        if isinstance(name, str) and name != entry.name:
            self.bad(f"name does not match lives {entry.lives!r}: expected '{entry.name}'")
        if value_type is not None and value_type != entry.value_type:
            self.bad(f"type '{value_type}' but {entry.lives} is {entry.value_type}")
        if unit != "?" and unit != entry.unit:
            want = f"unit '{entry.unit}'" if entry.unit else "no unit (dimensionless)"
            have = f"unit '{unit}'" if unit else "no unit"
            self.bad(f"{have}, but {entry.lives} takes {want}")

    # ---- start and bounds
    def start_and_bounds(self, raw: dict, causality: str | None, entry: Entry | None) -> None:
        has_start = "start" in raw
        if causality in ("input", "parameter"):
            if not has_start:
                self.bad(f"start is missing (every {causality} needs one)")
            elif not _finite(raw["start"]):
                self.bad(f"start {raw['start']!r} must be a finite number")
            elif raw["type"] == "Enumeration" and raw["start"] != int(raw["start"]):
                self.bad(f"start {raw['start']!r} of an Enumeration must be an item's value")
        elif causality == "output" and has_start:
            self.bad("start is present, but an output is calculated and must not have one")
        if not self.bounds(raw, causality):
            return
        if entry is not None and causality == entry.causality:
            self.domain(raw, entry)
        if has_start and _finite(raw["start"]):
            self.start_within(raw)

    def bounds(self, raw: dict, causality: str | None) -> bool:
        """Check min, max and their flags; whether they are well-formed."""
        ok = True
        for key in ("min", "max"):
            if key in raw and not _finite(raw[key]):
                self.bad(f"{key} {raw[key]!r} must be a finite number")
                ok = False
        for key in ("min_exclusive", "max_exclusive"):
            if key not in raw:
                continue
            if not isinstance(raw[key], bool):
                self.bad(f"{key} must be true or false")
                ok = False
            elif raw[key] and key[:3] not in raw:
                self.bad(f"{key} without {key[:3]}")
                ok = False
        if causality == "output" and any(k in raw for k in ("min", "max")):
            self.bad("outputs carry no bounds")
            ok = False
        if ok and "min" in raw and "max" in raw and not raw["min"] < raw["max"]:
            self.bad(f"min {raw['min']!r} is not below max {raw['max']!r}")
            ok = False
        return ok

    def domain(self, raw: dict, entry: Entry) -> None:
        declared = {key: raw[key] for key in ("min", "max") if key in raw}
        declared.update({key: True for key in ("min_exclusive", "max_exclusive") if raw.get(key)})
        wanted = {key: value for key, value in entry.domain.items() if value is not False}
        if {k: float(v) if k in ("min", "max") else v for k, v in declared.items()} != wanted:
            self.bad(
                f"bounds {show_bounds(declared)} differ from the solver's domain of "
                f"{entry.lives}: {show_bounds(wanted)}"
            )

    def start_within(self, raw: dict) -> None:
        s = raw["start"]
        low_ex, high_ex = raw.get("min_exclusive"), raw.get("max_exclusive")
        if "min" in raw and (s <= raw["min"] if low_ex else s < raw["min"]):
            self.bad(f"start {s!r} is below min {raw['min']!r}{' (exclusive)' if low_ex else ''}")
        if "max" in raw and (s >= raw["max"] if high_ex else s > raw["max"]):
            self.bad(f"start {s!r} is above max {raw['max']!r}{' (exclusive)' if high_ex else ''}")

    def depends(self, raw: dict, causality: str | None) -> None:
        if causality == "output":
            if "depends" not in raw:
                self.bad("depends is missing (list the inputs this output depends on; [] if none)")
            elif not isinstance(raw["depends"], list) or not all(
                isinstance(x, str) for x in raw["depends"]
            ):
                self.bad("depends must be a list of input names")
        elif "depends" in raw and causality is not None:
            self.bad(
                f"depends is present, but only outputs have dependencies (this is "
                f"{_article(causality)} {causality})"
            )

    # ---- across the rows
    def dependencies(self, variables: list[Variable]) -> None:
        by_name = {v.name: v for v in variables}
        for v in variables:
            if v.causality == "output":
                self.output_dependencies(v, by_name)
        for lives, entry in self.known.items():
            if lives not in self.seen_lives:
                self.fail(
                    f"missing variable '{entry.name}' ({entry.causality}, lives {lives!r}): "
                    f"every {self.owner} FMU has it"
                )

    def output_dependencies(self, v: Variable, by_name: dict) -> None:
        label = f"variable '{v.name}' (vr {v.vr})"
        seen = set()
        for dep in v.depends:
            if dep in seen:
                self.fail(f"{label}: depends lists '{dep}' twice")
            seen.add(dep)
            other = by_name.get(dep)
            if other is None:
                self.fail(f"{label}: depends on unknown variable '{dep}'")
            elif other.causality != "input":
                self.fail(
                    f"{label}: depends on '{dep}', which is {_article(other.causality)} "
                    f"{other.causality}, not an input"
                )
        entry = self.known[v.raw["lives"]]
        if entry.depends is not None and set(v.depends) != set(entry.depends):
            have, want = set(v.depends), set(entry.depends)
            self.fail(
                f"{label}: depends {sorted(have)} differ from the true "
                f"dependencies of {entry.lives}: {sorted(entry.depends)} "
                f"(missing {sorted(want - have)}, extra {sorted(have - want)})"
            )


def table_from_data(data: dict, path: Path, kinds: Mapping[str, TableKind]) -> Table:
    """Validate a table already read (a file's, or one a scene generates); `path` names
    it in messages and in the generated files; `kinds`: the kinds of model a table may
    be of, by name. Raises TableError listing every problem."""
    path = Path(path)
    check = _Check(path.name)
    model = check.check_model(data, kinds)
    rows = data.get("variable")
    if not isinstance(rows, list) or not rows:
        raise check.fatal("no [[variable]] entries")
    valid = [raw for k, raw in enumerate(rows) if check.row(k, raw)]
    if not check.problems:
        check.dependencies([Variable(raw, k, check.kind) for k, raw in enumerate(valid)])
    if check.problems:
        raise TableError(check.problems)
    return Table(path, model, rows, check.kind)


def canonical_table(model: dict, rows: list[dict]) -> str:
    """A canonical JSON text of the table: sorted keys, no spaces, numbers of
    Real-valued keys as floats (so `start = 0` and `start = 0.0` agree)."""
    norm = []
    for raw in rows:
        row = dict(raw)
        for key in _REAL_KEYS:
            if key in row and is_number(row[key]):
                row[key] = float(row[key])
        norm.append(row)
    return json.dumps(
        {"model": model, "variable": norm},
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=True,
        allow_nan=False,
    )


def instantiation_token(model: dict, rows: list[dict]) -> str:
    """ "{" + UUID (version 8, RFC 9562 variant) from SHA-256 of the table + "}"."""
    digest = bytearray(hashlib.sha256(canonical_table(model, rows).encode("ascii")).digest()[:16])
    digest[6] = (digest[6] & 0x0F) | 0x80
    digest[8] = (digest[8] & 0x3F) | 0x80
    h = digest.hex()
    return "{" + f"{h[0:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:32]}" + "}"

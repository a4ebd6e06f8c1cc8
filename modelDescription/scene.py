#!/usr/bin/env python3
"""Turn a scene into a tailored FMU: its variable table, its C model, both model
descriptions and its documentation.

A scene (TOML, see scenes/README.md for the schema) describes a mechanism: an
optional crank and a chain of Assur dyads, how each dyad's external links k and
p connect (the frame, the crank, a link of an earlier dyad, or an external link
whose motion is an input), which effects are present (inertia, gravity, active
forces and moments on which links), which outputs are wanted and which
parameters stay tunable (all others are baked into the C code as constants).

From it this module derives the FMU's variables (only those the scene needs)
and generates C that computes only what the scene needs: each link's resultant
load is written out term by term, and a term that the scene leaves out (no
inertia, no gravity, a centre of mass baked at the pair, a mass baked at 0) is
not generated at all. The chain is solved from the last dyad back to the
first: the reaction of a later dyad on a link of an earlier one enters that
link's resultant as a force at the pair point, and the crank's driving torque
and pivot reaction come last. The closed forms are the core's dyad_react_<type>
(src/include/dyadfmu/loaded.h).

Usage:
    scene.py SCENE.toml --out DIR    generate the FMU's files (see generate.py)
    scene.py SCENE.toml --check      validate only; print the variable counts

A malformed scene is rejected with every problem, each naming the file, the line
and what is wrong; nothing is written.

Python 3.11 standard library only.
"""

from __future__ import annotations

import argparse
import functools
import math
import re
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import cnames
import generate
import textsafe
from generate import Variable

TYPES = tuple(generate.PAIRS)          # RRR, RRT, RTR, TRT, RTT
#: The scene's identifier (it names the FMU, its files and C types) and the names of the
#: crank, the dyads and the links (they name variables and C names); matched whole.
IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
NAME = re.compile(r"[a-z][a-z0-9_]*")
#: The longest identifier or name. The generated C appends at most 16 characters to a
#: name (the member 'DYAD_guide_k_at_x') and 16 to the identifier ('DYADFMU_SCENE_..._H'),
#: which keeps every generated C name within the 63 characters that C99 guarantees to
#: be significant, and every file name (<identifier>_fmi3.fmu) far below 255 bytes.
MAX_NAME = 40
#: Names with a meaning in a scene: they cannot name a crank, dyad or link.
RESERVED = {"frame", "external", "gravity", "singular_threshold", "status", "time"}
#: Prefixes of the core's, the FMU layer's and the FMI standard's C names: no name may
#: start with one (nor be the prefix without its underscore, 'dyad' or 'fmu').
RESERVED_PREFIXES = ("dyad_", "fmu_", "fmi2", "fmi3")
_PREFIX_RULE = ("no name is " + " or ".join(p[:-1] for p in RESERVED_PREFIXES if p.endswith("_"))
                + " or starts with " + ", ".join(RESERVED_PREFIXES[:-1])
                + f" or {RESERVED_PREFIXES[-1]}")

SCENE_KEYS = {"identifier", "description", "outputs", "tunable", "singular_threshold"}
EFFECT_KEYS = {"inertia", "gravity"}
CRANK_KEYS = {"name", "length", "com", "mass", "inertia"}
DYAD_KEYS = {"name", "type", "m", "n", "k", "p"}
LINK_KEYS = {"name", "length", "angle", "com", "mass", "inertia"}
LOAD_KEYS = {"force", "moment"}
TOP_KEYS = {"scene", "effects", "gravity", "crank", "dyad", "link", "loads", "start"}

#: Per pair, the outputs a dyad offers: reactions always, normal force and
#: reactive moment where the pair is translational.
PAIR_NAMES = (("mk", 0), ("np", 2), ("mn", 1))   # (suffix, index into PAIRS[type])
#: What a dyad's amplification output means (README, "Status, conditioning, amplification").
AMPLIFICATION_TEXT = ("Data factor / conditioning: eps x amplification bounds the error of each "
                      "reaction relative to the largest reaction of its unit (N or N.m)")


class SceneError(Exception):
    """The scene is malformed; args[0] lists the problems."""


# ---------------------------------------------------------------------------
# Where things are in the file
# ---------------------------------------------------------------------------
class Locator:
    """Line numbers of tables and keys in a TOML text, for messages. The text is read as
    TOML reads it: strings (basic, literal, multi-line) and comments are skipped, so that a
    '[' or '#' inside a string moves nothing, and quoted keys and headers are decoded."""

    BARE = re.compile(r"[A-Za-z0-9_-]+")
    STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')

    def __init__(self, text: str):
        self.tables: dict[tuple[str, int], int] = {}
        self.keys: dict[tuple[str, int, str], int] = {}
        self._counts: dict[str, int] = {}
        self._section, self._index = "", 0
        depth = 0              # inside a multi-line array or inline table
        closing = None         # the closing quotes of an open multi-line string
        # TOML ends lines at LF only (str.splitlines would split at U+2028 and others too)
        for number, line in enumerate(text.split("\n"), start=1):
            line = line.removesuffix("\r")
            pos = 0
            if closing:
                end = line.find(closing)
                if end < 0:
                    continue
                pos, closing = end + 3, None
            if depth == 0 and pos == 0:
                pos = self._statement(line, number)
            depth, closing = self._scan(line, pos, depth)

    def _key(self, line: str, pos: int) -> tuple[list[str], int]:
        """The parts of the (dotted) key at `pos`, and where it ends; no parts if none."""
        parts = []
        while True:
            while pos < len(line) and line[pos] in " \t":
                pos += 1
            bare = self.BARE.match(line, pos)
            quoted = self.STRING.match(line, pos)
            if quoted:
                try:
                    parts.append(next(iter(tomllib.loads(quoted.group(0) + " = 0"))))
                except tomllib.TOMLDecodeError:
                    return [], pos
                pos = quoted.end()
            elif bare:
                parts.append(bare.group(0))
                pos = bare.end()
            else:
                return [], pos
            while pos < len(line) and line[pos] in " \t":
                pos += 1
            if not line.startswith(".", pos):
                return parts, pos
            pos += 1

    def _statement(self, line: str, number: int) -> int:
        """Record a table header or a key that starts `line`; where the value starts."""
        pos = len(line) - len(line.lstrip(" \t"))
        if line.startswith("[", pos):
            array = line.startswith("[[", pos)
            parts, end = self._key(line, pos + (2 if array else 1))
            if parts:
                section = ".".join(parts)
                if array:
                    self._index = self._counts.get(section, -1) + 1
                    self._counts[section] = self._index
                else:
                    self._index = 0
                self._section = section
                self.tables.setdefault((section, self._index), number)
            return len(line)
        parts, end = self._key(line, pos)
        if parts and line.startswith("=", end):
            self.keys.setdefault((self._section, self._index, parts[0]), number)
            return end + 1
        return len(line)

    @staticmethod
    def _scan(line: str, pos: int, depth: int) -> tuple[int, str | None]:
        """The bracket depth after a line's value from `pos`, and the closing quotes of a
        multi-line string the line leaves open."""
        while pos < len(line):
            ch = line[pos]
            if ch == "#":
                break
            if ch in "\"'":
                triple = ch * 3
                if line.startswith(triple, pos):
                    end = line.find(triple, pos + 3)
                    if end < 0:
                        return depth, triple
                    pos = end + 3
                    continue
                pos += 1
                while pos < len(line) and line[pos] != ch:
                    pos += 2 if ch == '"' and line[pos] == "\\" else 1
            elif ch in "[{":
                depth += 1
            elif ch in "]}":
                depth = max(depth - 1, 0)
            pos += 1
        return depth, None

    def line(self, section: str, index: int = 0, key: str | None = None) -> int | None:
        if key is not None and (section, index, key) in self.keys:
            return self.keys[(section, index, key)]
        return self.tables.get((section, index))


# ---------------------------------------------------------------------------
# The scene model
# ---------------------------------------------------------------------------
@dataclass
class Param:
    """A number of the scene: baked into the code, or an FMU parameter."""
    name: str            # FMU name, e.g. "lever.mass"
    value: float
    unit: str | None
    description: str
    domain: dict = field(default_factory=dict)
    tunable: bool = False
    member: str = ""     # C member of the input block when tunable

    def c(self) -> str:
        """The value in C: the input block's member, or the constant."""
        return f"in->{self.member}" if self.tunable else _c_num(self.value)

    def is_zero(self) -> bool:
        return not self.tunable and self.value == 0.0


@dataclass
class Attachment:
    """Where a dyad's outer pair meets its external link."""
    kind: str                      # "frame", "external", "crank", "link"
    link: str | None = None        # the moving link (crank or dyad link) it is on
    at: tuple[Param, Param] | None = None   # the point in that link's frame
    guide: Param | None = None     # guide angle on the frame, for a translational pair


@dataclass(eq=False)
class Link:
    name: str
    dyad: "Dyad"
    side: str                      # "m" or "n"
    line: int | None
    sliding: bool                  # its length varies (link m of RTR, RTT)
    translating: bool              # it cannot turn: its outer pair slides on the frame
    params: dict = field(default_factory=dict)   # key -> Param (length, angle, com.x, ...)
    force: bool = False
    moment: bool = False


@dataclass(eq=False)
class Dyad:
    name: str
    type: str
    index: int
    line: int | None
    m: str = ""
    n: str = ""
    k: Attachment | None = None
    p: Attachment | None = None

    def prefix(self) -> str:
        return f"{self.name}." if self.name else ""

    def pair_kind(self, pair: str) -> str:
        return generate.PAIRS[self.type][dict(PAIR_NAMES)[pair]]


@dataclass
class Crank:
    name: str
    line: int | None
    params: dict = field(default_factory=dict)


@dataclass(eq=False)
class Output:
    name: str
    unit: str | None
    description: str
    member: str
    integer: bool = False
    depends: list = field(default_factory=list)
    source: str = ""         # the dyad (by index, as text) or "crank" it comes from


@dataclass
class Scene:
    path: Path
    identifier: str
    description: str
    inertia: bool
    gravity: bool
    crank: Crank | None
    dyads: list
    links: dict                    # name -> Link
    gravity_params: tuple | None   # (Param, Param)
    threshold: Param
    outputs: list = field(default_factory=list)      # Output
    inputs: list = field(default_factory=list)       # Input, in table order
    #: dyad index -> the dyads that load it (see _loaders), computed once
    loaders: dict = field(default_factory=dict, repr=False)

    def parameters(self) -> list:
        """Every Param of the scene in table order."""
        out = []
        if self.crank:
            out += self.crank.params.values()
        for d in self.dyads:
            for g in (d.m, d.n):
                out += self.links[g].params.values()
            for a in (d.k, d.p):
                if a.at:
                    out += a.at
                if a.guide:
                    out.append(a.guide)
        if self.gravity_params:
            out += self.gravity_params
        out.append(self.threshold)
        return out


def _c_num(x: float) -> str:
    text = repr(float(x))
    return text if ("." in text or "e" in text or "inf" in text or "nan" in text) else text + ".0"


def _member(name: str) -> str:
    return name.replace(".", "_")


# ---------------------------------------------------------------------------
# Loading and validating
# ---------------------------------------------------------------------------
class _Problems:
    def __init__(self, path: Path, locator: Locator):
        self.path = path
        self.loc = locator
        self.items: list[str] = []

    def where(self, section: str = "", index: int = 0, key: str | None = None) -> str:
        """file:line of a table or key; a table written as a plain key (scene = 1) is
        found as that key, and what has no line of its own (a table that is missing)
        is placed on line 1."""
        line = self.loc.line(section, index, key) if section else self.loc.line("", 0, key)
        if line is None and section:
            line = self.loc.line("", 0, section.split(".")[0])
        return f"{textsafe.plain(self.path.name)}:{line or 1}"

    def add(self, message: str, section: str = "", index: int = 0, key: str | None = None):
        self.items.append(f"{self.where(section, index, key)}: {textsafe.plain(message)}")


def _real(value) -> float | None:
    """A TOML number as a finite double, or None: not a number (a bool is none), not
    finite, or an integer beyond the range of a double."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def _shown(value) -> str:
    """A value of the scene for a message, shortened (an integer of 400 digits stays
    readable)."""
    text = repr(value)
    return text if len(text) <= 60 else text[:40] + f"... ({len(text)} characters)"


def _number(p: _Problems, table: dict, key: str, where: str, sec, idx, *, positive=False,
            nonnegative=False, required=True):
    if key not in table:
        if required:
            p.add(f"{where}: missing parameter '{key}'", sec, idx)
        return None
    value = _real(table[key])
    if value is None:
        p.add(f"{where}: '{key}' must be a finite number (within the range of a double), "
              f"not {_shown(table[key])}", sec, idx, key)
        return None
    if positive and not value > 0:
        p.add(f"{where}: '{key}' must be positive, not {_shown(table[key])}", sec, idx, key)
        return None
    if nonnegative and not value >= 0:
        p.add(f"{where}: '{key}' must not be negative, not {_shown(table[key])}", sec, idx, key)
        return None
    return value


def _pair_of_numbers(p: _Problems, table: dict, key: str, where: str, sec, idx, required=True):
    if key not in table:
        if required:
            p.add(f"{where}: missing parameter '{key}' ([x, y] in m)", sec, idx)
        return None
    value = table[key]
    if (not isinstance(value, list) or len(value) != 2 or
            any(_real(v) is None for v in value)):
        p.add(f"{where}: '{key}' must be [x, y], two finite numbers (m), not {_shown(value)}",
              sec, idx, key)
        return None
    return _real(value[0]), _real(value[1])


def _unknown_keys(p: _Problems, table: dict, allowed: set, where: str, sec, idx):
    for key in table:
        if key not in allowed:
            p.add(f"{where}: unknown key '{key}' (expected one of {', '.join(sorted(allowed))})",
                  sec, idx, key)


def _name_problem(name) -> str | None:
    """Why `name` cannot name a crank, dyad or link (the message goes on "name ..."), or
    None. The C names it leads to are checked once every name is known (_c_name_clashes)."""
    if not isinstance(name, str):
        return f"must be a string, not {_shown(name)}"
    if not NAME.fullmatch(name):
        return (f"{_shown(name)} must be a lower-case identifier: a letter a-z, then letters "
                "a-z, digits 0-9 and '_'")
    if len(name) > MAX_NAME:
        return f"'{name[:20]}...' has {len(name)} characters; a name has at most {MAX_NAME}"
    if name in RESERVED:
        return (f"'{name}' is a word of the scene format (reserved: "
                f"{', '.join(sorted(RESERVED))})")
    if name in cnames.C_KEYWORDS:
        return f"'{name}' is a C keyword"
    for prefix in RESERVED_PREFIXES:
        if (name + "_").startswith(prefix):
            return (f"'{name}' starts with '{prefix}', which is reserved for the C names of "
                    f"the core, the FMU layer and FMI ({_PREFIX_RULE})")
    return None


def _identifier_problem(identifier) -> str | None:
    """Why `identifier` cannot name the FMU, or None."""
    if not isinstance(identifier, str):
        return f"must be a string (a C identifier that names the FMU), not {_shown(identifier)}"
    if not IDENT.fullmatch(identifier):
        return (f"{_shown(identifier)} must be a C identifier (it names the FMU): a letter, "
                "then letters, digits and '_'")
    if len(identifier) > MAX_NAME:
        return (f"'{identifier[:20]}...' has {len(identifier)} characters; an identifier has "
                f"at most {MAX_NAME}")
    if identifier in cnames.C_KEYWORDS:
        return f"'{identifier}' is a C keyword"
    return None


# ---------------------------------------------------------------------------
# C names
# ---------------------------------------------------------------------------
HERE = Path(__file__).resolve().parent
#: A scene with every feature of the generated code; see the file.
C_NAMES_PROBE = HERE / "c_names_probe.toml"
#: Where the headers the generated code includes are found.
HEADER_DIRS = (HERE.parent / "src" / "include", HERE.parent / "src", HERE.parent / "fmu")
_PROBE_NAME = re.compile(r"zq[a-z]{2}", re.IGNORECASE)


@dataclass(frozen=True)
class CNames:
    """What the generated C makes of a scene's names, learnt from the generated code of
    the probe scene: `reserved`, every identifier that code and the headers it includes
    use (C's keywords, the standard headers' names, the core's and the FMU layer's,
    the generated code's own: in, out, load, cos, ...); `patterns`, per kind of name
    (identifier, crank, dyad, link), the C names derived from a name as (scope, prefix,
    suffix, upper case): scope "code" for the names of the generated code's functions
    and files, "member" for the members of the scene's input and output blocks."""
    reserved: frozenset
    patterns: dict

    def derived(self, kind: str, name: str) -> list[tuple[str, str]]:
        """(scope, C name) of every C name derived from `name`, a name of `kind`."""
        return sorted((scope, prefix + (name.upper() if upper else name) + suffix)
                      for scope, prefix, suffix, upper in self.patterns[kind])


_C_NAMES: list = []


def c_names() -> CNames:
    """The C names of generated code (computed once per process from the probe scene)."""
    if not _C_NAMES:
        _C_NAMES.append(_learn_c_names())
    return _C_NAMES[0]


def _learn_c_names() -> CNames:
    probe = load_scene(C_NAMES_PROBE, check_c_names=False)
    table = scene_table(probe)
    header = f"{probe.identifier}_scene.h"
    files = {"scene.c": scene_c(table), "scene.h": scene_header(table),
             "model.c": generate.model_c(table)}
    kind_of = {probe.identifier: "identifier", probe.crank.name: "crank"}
    kind_of.update({d.name: "dyad" for d in probe.dyads})
    kind_of.update({g: "link" for g in probe.links})
    reserved = set(cnames.C_KEYWORDS) | cnames.COMMON_MACROS
    reserved |= cnames.headers_names("\n".join(files.values()), list(HEADER_DIRS),
                                     {header: files["scene.h"]})
    patterns: dict[str, set] = {kind: set() for kind in ("identifier", "crank", "dyad", "link")}
    for file, code in files.items():
        for t in cnames.identifiers(code):
            found = _PROBE_NAME.search(t.text)
            if found is None:
                # the header's own names came with headers_names (its struct members,
                # which no local can hide, do not count)
                if not t.member and file != "scene.h":
                    reserved.add(t.text)
                continue
            kind = kind_of[found.group().lower()]
            # a link's, dyad's or crank's name in the header or the variable table is a
            # member of the input or output block; in the code, after '.' or '->'
            member = t.member or (kind != "identifier" and file != "scene.c")
            patterns[kind].add(("member" if member else "code", t.text[:found.start()],
                                t.text[found.end():], found.group().isupper()))
    reserved = {n for n in reserved if not _PROBE_NAME.search(n)}
    return CNames(frozenset(reserved), {k: frozenset(v) for k, v in patterns.items()})


def _c_name_clashes(p: _Problems, objects: list):
    """Every clash of the C names the scene's names lead to: a name the generated code,
    the core or C already uses (a dyad 'in', 'load' or 'cos'), or one C name derived
    from two names (a dyad 'rod_f' beside the resultant force rod_f of a link 'rod').
    `objects`: (kind, name, label, (section, index, key)) in file order."""
    names = c_names()
    taken: dict[tuple[str, str], str] = {}
    for kind, name, label, where in objects:
        # an identifier itself too: 'EOF' or 'main' would name the FMU, its library and
        # files after a name of C (a dyad's name is a C name as it is: see the patterns)
        if kind == "identifier" and name in names.reserved:
            p.add(f"{label}: its name is already a name of C, its standard headers, the core "
                  f"or the generated code ('{name}'); choose another name", *where)
            continue
        for scope, cname in names.derived(kind, name):
            if scope == "code" and cname in names.reserved:
                what = "its name" if cname == name else f"the C name '{cname}' it leads to"
                p.add(f"{label}: {what} is already a name of C, its standard headers, the "
                      f"core or the generated code ('{cname}'); choose another name", *where)
                break
            other = taken.setdefault((scope, cname), label)
            if other != label:
                p.add(f"{label}: the generated C code would use the name '{cname}' both for "
                      f"{other} and for {label}; rename one of them", *where)
                break


def load_scene(path, *, check_c_names: bool = True) -> Scene:
    """Read and validate a scene; raises SceneError listing every problem.
    `check_c_names`: refuse names whose C names clash (off only for the C names
    probe, from which the clashes are learnt)."""
    path = Path(path)
    shown_name = textsafe.plain(path.name)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise SceneError([f"{shown_name}: cannot read: {exc.strerror}"]) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise SceneError([f"{shown_name}:{line}: not UTF-8 text (byte {exc.start + 1})"]) \
            from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = re.search(r"at line (\d+)", str(exc))
        where = f"{shown_name}:{line.group(1)}" if line else shown_name
        raise SceneError([f"{where}: invalid TOML: {textsafe.plain(exc)}"]) from None
    p = _Problems(path, Locator(text))

    for key in data:
        if key not in TOP_KEYS:
            p.add(f"unknown table '{key}' (expected {', '.join(sorted(TOP_KEYS))})", key, 0)
    scene_t = data.get("scene")
    if not isinstance(scene_t, dict):
        p.add("missing [scene] table (identifier, description, outputs)", "scene", 0)
        raise SceneError(p.items)
    _unknown_keys(p, scene_t, SCENE_KEYS, "[scene]", "scene", 0)
    identifier = scene_t.get("identifier")
    problem = _identifier_problem(identifier)
    if problem:
        p.add(f"[scene]: identifier {problem}", "scene", 0, "identifier")
        identifier = "scene"
    description = scene_t.get("description")
    problem = textsafe.description_problem(description)
    if problem:
        p.add(f"[scene]: description {problem}", "scene", 0, "description")
        description = ""

    effects_t = data.get("effects", {})
    if not isinstance(effects_t, dict):
        p.add("[effects] must be a table", "effects", 0)
        effects_t = {}
    _unknown_keys(p, effects_t, EFFECT_KEYS, "[effects]", "effects", 0)
    effects = {}
    for key in EFFECT_KEYS:
        value = effects_t.get(key, False)
        if not isinstance(value, bool):
            p.add(f"[effects]: '{key}' must be true or false, not {value!r}", "effects", 0, key)
            value = False
        effects[key] = value
    inertia, gravity = effects["inertia"], effects["gravity"]
    needs_mass = inertia or gravity

    gravity_params = None
    gravity_t = data.get("gravity")
    if gravity:
        if not isinstance(gravity_t, dict):
            p.add("[effects]: gravity = true, but there is no [gravity] table with x and y "
                  "(m/s2)", "effects", 0, "gravity")
        else:
            _unknown_keys(p, gravity_t, {"x", "y"}, "[gravity]", "gravity", 0)
            gx = _number(p, gravity_t, "x", "[gravity]", "gravity", 0)
            gy = _number(p, gravity_t, "y", "[gravity]", "gravity", 0)
            if gx is not None and gy is not None:
                gravity_params = (
                    Param("gravity.x", gx, "m/s2", "Gravitational acceleration, global x component"),
                    Param("gravity.y", gy, "m/s2", "Gravitational acceleration, global y component"))
    elif gravity_t is not None:
        p.add("[gravity] is given, but [effects] gravity is not true: set it or remove the "
              "table", "gravity", 0)

    threshold_value = _real(scene_t.get("singular_threshold", 1.4901161193847656e-8))
    if threshold_value is None or not 0 < threshold_value < 1:
        p.add(f"[scene]: singular_threshold must be in (0, 1), not "
              f"{_shown(scene_t.get('singular_threshold'))}", "scene", 0, "singular_threshold")
        threshold_value = 1.4901161193847656e-8
    threshold = Param("singular_threshold", threshold_value, None,
                      "Conditioning below which a dyad is reported singular (default "
                      "sqrt(eps) = 1.49e-8)",
                      {"min": 0.0, "max": 1.0, "min_exclusive": True, "max_exclusive": True})

    # ---- the crank
    crank = None
    crank_t = data.get("crank")
    if crank_t is not None:
        if not isinstance(crank_t, dict):
            p.add("[crank] must be a table", "crank", 0)
        else:
            _unknown_keys(p, crank_t, CRANK_KEYS, "[crank]", "crank", 0)
            cname = crank_t.get("name", "crank")
            problem = _name_problem(cname)
            if problem:
                p.add(f"[crank]: name {problem}", "crank", 0, "name")
                cname = "crank"
            crank = Crank(cname, p.loc.line("crank"))
            where = f"crank '{cname}'"
            length = _number(p, crank_t, "length", where, "crank", 0, positive=True)
            if length is not None:
                crank.params["length"] = Param(f"{cname}.length", length, "m",
                                               "Crank radius |O A|: the crank pin A lies at "
                                               "(length, 0) in the crank frame",
                                               {"min": 0.0, "min_exclusive": True})
            com = _pair_of_numbers(p, crank_t, "com", where, "crank", 0, required=needs_mass)
            if com is not None and needs_mass:
                crank.params["com.x"] = Param(f"{cname}.com.x", com[0], "m",
                                              "Crank's centre of mass, x in the crank frame "
                                              "{O; i_c, j_c}")
                crank.params["com.y"] = Param(f"{cname}.com.y", com[1], "m",
                                              "Crank's centre of mass, y in the crank frame")
            mass = _number(p, crank_t, "mass", where, "crank", 0, nonnegative=True,
                           required=needs_mass)
            if mass is not None and needs_mass:
                crank.params["mass"] = Param(f"{cname}.mass", mass, "kg", "Crank's mass",
                                             {"min": 0.0})
            inert = _number(p, crank_t, "inertia", where, "crank", 0, nonnegative=True,
                            required=inertia)
            if inert is not None and inertia:
                crank.params["inertia"] = Param(f"{cname}.inertia", inert, "kg.m2",
                                                "Crank's moment of inertia about its centre of "
                                                "mass", {"min": 0.0})

    # ---- links (tables first, so that dyads can refer to them)
    link_tables: dict[str, tuple[dict, int]] = {}
    rows = data.get("link", [])
    if not isinstance(rows, list):
        p.add("[[link]] must be an array of tables", "link", 0)
        rows = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            continue
        name = row.get("name")
        _unknown_keys(p, row, LINK_KEYS,
                      f"link '{name}'" if isinstance(name, str) else f"link #{i + 1}", "link", i)
        problem = _name_problem(name)
        if problem:
            p.add(f"link #{i + 1}: name {problem}", "link", i, "name")
            continue
        if name in link_tables:
            p.add(f"link '{name}' is described twice (also line "
                  f"{p.loc.line('link', link_tables[name][1])})", "link", i, "name")
            continue
        if crank and name == crank.name:
            p.add(f"link '{name}' has the crank's name", "link", i, "name")
            continue
        link_tables[name] = (row, i)

    # ---- dyads
    dyads: list[Dyad] = []
    links: dict[str, Link] = {}
    owner: dict[str, str] = {}   # link name -> "dyad 'x' as m"
    rows = data.get("dyad", [])
    if not isinstance(rows, list) or not rows:
        p.add("no [[dyad]] tables: a scene has at least one dyad", "scene", 0)
        rows = []
    names_seen: set = set()
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            p.add(f"dyad #{i + 1} must be a table", "dyad", i)
            continue
        _unknown_keys(p, row, DYAD_KEYS, f"dyad #{i + 1}", "dyad", i)
        name = row.get("name", "")
        if name == "" and len(rows) > 1:
            p.add(f"dyad #{i + 1}: a scene with several dyads must name each one", "dyad", i)
        elif name != "" and _name_problem(name):
            p.add(f"dyad #{i + 1}: name {_name_problem(name)}", "dyad", i, "name")
            name = f"dyad{i + 1}"
        elif name in names_seen:
            p.add(f"dyad '{name}' is named twice", "dyad", i, "name")
        names_seen.add(name)
        label = f"dyad '{name}'" if name else f"dyad #{i + 1}"
        dtype = row.get("type")
        if dtype not in TYPES:
            p.add(f"{label}: unknown dyad type {dtype!r} (expected one of {', '.join(TYPES)})",
                  "dyad", i, "type")
            for side in ("m", "n"):      # its links are not orphans
                if isinstance(row.get(side), str):
                    owner.setdefault(row[side], f"link {side} of {label}")
            continue
        dyad = Dyad(name, dtype, i, p.loc.line("dyad", i))
        d_m, e, d_n = generate.PAIRS[dtype]
        ok = True
        for side in ("m", "n"):
            lname = row.get(side)
            if not isinstance(lname, str):
                p.add(f"{label}: missing link '{side}' (the name of its link {side})", "dyad", i)
                ok = False
                continue
            if lname in owner:
                p.add(f"{label}: link '{lname}' is connected twice: it is already {owner[lname]}",
                      "dyad", i, side)
                ok = False
                continue
            if crank and lname == crank.name:
                p.add(f"{label}: link '{lname}' is the crank, which no dyad may contain",
                      "dyad", i, side)
                ok = False
                continue
            if lname not in link_tables:
                p.add(f"{label}: link '{lname}' has no [[link]] table (its length, centre of "
                      "mass, mass and inertia)", "dyad", i, side)
                ok = False
                continue
            owner[lname] = f"link {side} of {label}"
            setattr(dyad, side, lname)
        if not ok:
            continue
        # outer pairs
        for side, pair_kind, pair in (("k", d_m, "D_m"), ("p", d_n, "D_n")):
            att = _attachment(p, row.get(side, None), side, pair_kind, pair, label, i, crank,
                              links, dyad)
            setattr(dyad, side, att)
        if dyad.k is None or dyad.p is None:
            continue
        for side, outer in (("m", d_m), ("n", d_n)):
            lname = getattr(dyad, side)
            attached = dyad.k if side == "m" else dyad.p
            translating = outer == "T" and attached.kind == "frame"
            sliding = side == "m" and e == "T"
            links[lname] = Link(lname, dyad, side, p.loc.line("link", link_tables[lname][1]),
                                sliding, translating)
        dyads.append(dyad)

    for lname, (row, i) in link_tables.items():
        if lname not in links:
            if lname not in owner:
                p.add(f"link '{lname}' belongs to no dyad", "link", i)
            continue
        _link_params(p, links[lname], row, i, inertia, needs_mass)

    if check_c_names:
        objects = []
        if not _identifier_problem(identifier):
            objects.append(("identifier", identifier, f"[scene]: identifier '{identifier}'",
                            ("scene", 0, "identifier")))
        if crank:
            objects.append(("crank", crank.name, f"crank '{crank.name}'", ("crank", 0, "name")))
        objects += [("dyad", d.name, f"dyad '{d.name}'", ("dyad", d.index, "name"))
                    for d in dyads if d.name]
        objects += [("link", g, f"link '{g}'", ("link", i, "name"))
                    for g, (row, i) in link_tables.items()]
        _c_name_clashes(p, objects)

    # ---- loads
    loads_t = data.get("loads", {})
    if not isinstance(loads_t, dict):
        p.add("[loads] must be a table", "loads", 0)
        loads_t = {}
    _unknown_keys(p, loads_t, LOAD_KEYS, "[loads]", "loads", 0)
    for key in LOAD_KEYS:
        value = loads_t.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            p.add(f"[loads]: '{key}' must be a list of link names", "loads", 0, key)
            continue
        for lname in value:
            if lname not in links:
                p.add(f"[loads]: {key} on unknown link '{lname}' (links: "
                      f"{', '.join(links) or 'none'})", "loads", 0, key)
            elif getattr(links[lname], key):
                p.add(f"[loads]: {key} on '{lname}' is listed twice", "loads", 0, key)
            else:
                setattr(links[lname], key, True)

    scene = Scene(path, identifier, description, inertia, gravity, crank, dyads, links,
                  gravity_params, threshold)

    # ---- tunable parameters
    tunable = scene_t.get("tunable", [])
    params = {prm.name: prm for prm in scene.parameters()}
    if not isinstance(tunable, list) or not all(isinstance(t, str) for t in tunable):
        p.add("[scene]: tunable must be a list of parameter names", "scene", 0, "tunable")
        tunable = []
    for entry in tunable:
        if entry == "all":
            chosen = list(params)
        else:
            chosen = [n for n in params if n == entry or n.startswith(entry + ".")]
        if not chosen:
            p.add(f"[scene]: tunable '{entry}' is no parameter of this scene (parameters: "
                  f"{', '.join(params)})", "scene", 0, "tunable")
        for n in chosen:
            params[n].tunable = True
            params[n].member = _member(n)

    if not p.items:
        _derive_inputs(scene)
        candidates = {i.name for i in scene.inputs}
        _derive_outputs(p, scene, scene_t.get("outputs"))
        if not p.items:
            # only now is it known what the code computes, and so which inputs it reads;
            # the outputs' dependencies follow from those inputs
            _prune_inputs(scene)
            _derive_outputs(p, scene, scene_t.get("outputs"))
            _apply_starts(p, scene, data.get("start", {}), candidates)
    if p.items:
        raise SceneError(p.items)
    return scene


def _finite_number(value) -> bool:
    return _real(value) is not None


def _attachment(p, spec, side, pair_kind, pair, label, i, crank, links, dyad):
    """Parse k or p of a dyad."""
    if spec is None:
        p.add(f"{label}: missing '{side}', the external link at {pair} ('frame', "
              f"'external', the crank's name or {{ link = ..., at = [x, y] }})", "dyad", i)
        return None
    if isinstance(spec, str):
        spec = {"link": spec}
    if not isinstance(spec, dict):
        p.add(f"{label}: '{side}' must be a link name or a table", "dyad", i, side)
        return None
    for key in spec:
        if key not in ("link", "at", "guide"):
            p.add(f"{label}: '{side}' has unknown key '{key}' (expected link, at, guide)",
                  "dyad", i, side)
            return None
    target = spec.get("link")
    prefix = dyad.prefix()
    sliding = pair_kind == "T"
    if not isinstance(target, str):
        p.add(f"{label}: '{side}' needs link = <name>", "dyad", i, side)
        return None
    moving = (crank is not None and target == crank.name) or target in links
    if target not in ("frame", "external") and not moving:
        later = f" (a link of a later dyad or of this one: dyads are listed from the crank " \
                f"outwards)" if target else ""
        p.add(f"{label}: '{side}' names unknown link {target!r}{later}; expected 'frame', "
              f"'external'{', the crank' if crank else ''} or a link of an earlier dyad",
              "dyad", i, side)
        return None
    if not sliding and "guide" in spec:
        p.add(f"{label}: {pair} is a revolute pair and has no guide", "dyad", i, side)
        return None
    if target in ("frame", "external") and "at" in spec:
        p.add(f"{label}: '{side}': a pair on the {target} takes no 'at'", "dyad", i, side)
        return None
    if target == "external":
        if "guide" in spec:
            p.add(f"{label}: '{side}': an external link's guide is an input; drop 'guide'",
                  "dyad", i, side)
            return None
        return Attachment("external")
    if target == "frame" and not sliding:
        return Attachment("frame")
    kind = "frame" if target == "frame" else "crank" if crank and target == crank.name \
        else "link"

    guide = None
    if sliding:
        angle = spec.get("guide")
        if not _finite_number(angle):
            on = "the frame" if kind == "frame" else f"'{target}'"
            example = "0.0" if kind == "frame" else "0.0, at = [0.0, 0.0]"
            p.add(f"{label}: {pair} slides on {on}: '{side}' needs guide = <angle in rad> "
                  f"(e.g. {side} = {{ link = \"{target}\", guide = {example} }})",
                  "dyad", i, side)
            return None
        text = (f"Direction of the frame guide at {pair} (angle of i_{side} from x)"
                if kind == "frame" else
                f"Direction of the guide at {pair} on {target}: angle of i_{side} from "
                f"{target}'s i")
        guide = Param(f"{prefix}guide_{side}.angle", _real(angle), "rad", text)
        if kind == "frame":
            return Attachment("frame", guide=guide)

    at = spec.get("at")
    if at is None:
        if sliding:
            at = [0.0, 0.0]                  # the guide passes through the carrier's D (O)
        elif kind == "crank":
            return Attachment("crank", crank.name)       # the crank's pin
        else:
            p.add(f"{label}: '{side}' on link '{target}' needs at = [x, y], the pair's point "
                  f"in that link's frame (m)", "dyad", i, side)
            return None
    if not isinstance(at, list) or len(at) != 2 or not all(_finite_number(v) for v in at):
        p.add(f"{label}: '{side}': at must be [x, y], two finite numbers (m)", "dyad", i, side)
        return None
    frame = f"{target}'s frame"
    if sliding:
        pname, what = f"{prefix}guide_{side}.at", f"A point of the guide at {pair} on {target}"
    else:
        pname, what = f"{prefix}{pair}", f"Pair {pair} on {target}"
    return Attachment(kind, target,
                      (Param(f"{pname}.x", _real(at[0]), "m", f"{what}: x in the {frame}"),
                       Param(f"{pname}.y", _real(at[1]), "m", f"{what}: y in the {frame}")),
                      guide)


def _link_params(p, link: Link, row: dict, i: int, inertia: bool, needs_mass: bool):
    where = f"link '{link.name}'"
    may_be_zero = generate.MAY_BE_ZERO[link.dyad.type]["mn".index(link.side)]
    if link.sliding:
        if "length" in row:
            p.add(f"{where}: its length varies (pair E of the {link.dyad.type} dyad slides "
                  f"along it), so it is an input, not a parameter; drop 'length'",
                  "link", i, "length")
    else:
        length = _number(p, row, "length", where, "link", i, nonnegative=may_be_zero,
                         positive=not may_be_zero)
        if length is not None:
            text = "may be 0" if may_be_zero else "positive"
            link.params["length"] = Param(f"{link.name}.length", length, "m",
                                          f"Length |D E| of link {link.name} ({text})",
                                          {"min": 0.0, "min_exclusive": not may_be_zero})
    if link.translating:
        angle = _number(p, row, "angle", where + " (it translates on its frame guide)",
                        "link", i)
        if angle is not None:
            link.params["angle"] = Param(f"{link.name}.angle", angle, "rad",
                                         f"Direction of link {link.name} (it translates)")
    elif "angle" in row:
        p.add(f"{where}: its angle is an input (the link turns); drop 'angle'", "link", i,
              "angle")
    com = _pair_of_numbers(p, row, "com", where, "link", i, required=True)
    if com is not None:
        link.params["com.x"] = Param(f"{link.name}.com.x", com[0], "m",
                                     f"Centre of mass of {link.name}, x in its frame")
        link.params["com.y"] = Param(f"{link.name}.com.y", com[1], "m",
                                     f"Centre of mass of {link.name}, y in its frame")
    mass = _number(p, row, "mass", where, "link", i, nonnegative=True, required=needs_mass)
    if mass is not None and needs_mass:
        link.params["mass"] = Param(f"{link.name}.mass", mass, "kg", f"Mass of {link.name}",
                                    {"min": 0.0})
    inert = _number(p, row, "inertia", where, "link", i, nonnegative=True, required=inertia)
    if inert is not None and inertia:
        link.params["inertia"] = Param(f"{link.name}.inertia", inert, "kg.m2",
                                       f"Moment of inertia of {link.name} about its centre of "
                                       "mass", {"min": 0.0})


# ---------------------------------------------------------------------------
# Inputs and outputs
# ---------------------------------------------------------------------------
@dataclass
class Input:
    name: str
    unit: str | None
    description: str
    member: str
    angle: bool = False
    start: float = 0.0
    domain: dict = field(default_factory=dict)
    owner: str = ""          # link the input belongs to ("" for a dyad's guide)


def _link_inputs(scene: Scene, link: Link) -> list:
    g = link.name
    out = []
    if not link.translating:
        out.append(Input(f"{g}.angle", "rad", f"Direction of {g}: angle of i from D towards E, "
                         "counter-clockwise from x", _member(g) + "_dir", True, owner=g))
        if scene.inertia:
            out.append(Input(f"{g}.omega", "rad/s", f"Angular velocity of {g}",
                             _member(g) + "_omega", owner=g))
            out.append(Input(f"{g}.epsilon", "rad/s2", f"Angular acceleration of {g}",
                             _member(g) + "_epsilon", owner=g))
    if scene.inertia and _own_accel(scene, link):
        for c in "xy":
            out.append(Input(f"{g}.accel_d.{c}", "m/s2",
                             f"Acceleration of {g} at its outer pair D, global {c}",
                             f"{_member(g)}_accel_d_{c}", owner=g))
    if link.force:
        for c in "xy":
            out.append(Input(f"{g}.force.{c}", "N", f"Active force on {g} at its centre of "
                             f"mass, global {c}", f"{_member(g)}_force_{c}", owner=g))
    if link.moment:
        out.append(Input(f"{g}.moment", "N.m", f"Active moment on {g}, counter-clockwise",
                         _member(g) + "_moment", owner=g))
    if link.sliding:
        out.append(Input(f"{g}.length", "m", f"Current length |D E| of {g} (pair E slides "
                         "along it)", _member(g) + "_length", start=1.0,
                         domain={"min": 0.0, "min_exclusive": True}, owner=g))
    return out


def _own_accel(scene: Scene, link: Link) -> bool:
    """Whether the acceleration of D_g is an input: where D_g slides on a guide (of the frame
    or of a moving link) or sits on an external link. On a fixed pivot it is 0; on a point
    of the crank or of an earlier link the generated code derives it from that link's
    motion."""
    att = link.dyad.k if link.side == "m" else link.dyad.p
    return att.kind == "external" or att.guide is not None


def _derive_inputs(scene: Scene):
    inputs = []
    if scene.crank:
        c = scene.crank.name
        inputs.append(Input(f"{c}.angle", "rad", "Crank angle phi (i_c from O towards A)",
                            _member(c) + "_dir", True, owner=c))
        if scene.inertia:
            inputs.append(Input(f"{c}.omega", "rad/s", "Crank angular velocity",
                                _member(c) + "_omega", owner=c))
            inputs.append(Input(f"{c}.epsilon", "rad/s2", "Crank angular acceleration",
                                _member(c) + "_epsilon", owner=c))
    for d in scene.dyads:
        for g in (d.m, d.n):
            inputs += _link_inputs(scene, scene.links[g])
        for side, pair in (("k", "D_m"), ("p", "D_n")):
            att = getattr(d, side)
            if att.kind in ("crank", "link") and att.guide is not None:
                slider = d.m if side == "k" else d.n
                inputs.append(Input(f"{d.prefix()}slide_{side}", "m",
                                    f"Position of {pair} along the guide on {att.link}, from "
                                    f"the guide's point 'at'", f"{_member(d.prefix())}slide_{side}",
                                    owner=slider))
            if att.kind == "external" and d.pair_kind("mk" if side == "k" else "np") == "T":
                inputs.append(Input(f"{d.prefix()}guide_{side}.angle", "rad",
                                    f"Direction of the guide of the external link at {pair}",
                                    f"{_member(d.prefix())}guide_{side}", True))
    scene.inputs = inputs


def _apply_starts(p: _Problems, scene: Scene, starts, candidates: set):
    """[start]: start values of inputs (default 0, and 1 m for a sliding length). A start
    value of an input the scene's outputs turned out not to need is ignored."""
    if not isinstance(starts, dict):
        p.add("[start] must be a table of input names and values", "start", 0)
        return
    by_name = {i.name: i for i in scene.inputs}
    for name, value in starts.items():
        target = by_name.get(name)
        if target is None and name in candidates:
            continue
        if target is None:
            p.add(f"[start]: '{name}' is no input of this scene (inputs: "
                  f"{', '.join(by_name)})", "start", 0, name)
            continue
        number = _real(value)
        if number is None:
            p.add(f"[start]: '{name}' must be a finite number (within the range of a double), "
                  f"not {_shown(value)}", "start", 0, name)
            continue
        if "min" in target.domain and not number > target.domain["min"]:
            p.add(f"[start]: '{name}' must be positive, not {_shown(value)}", "start", 0, name)
            continue
        target.start = number


def _prune_inputs(scene: Scene):
    """Drop the candidate inputs the generated code never reads: a link's angular velocity
    where nothing of it lies off its pair D (its centripetal terms vanish), and the like."""
    probe = scene_table(scene, probe=True)
    code = scene_c(probe)
    used = set(re.findall(r"\bin->([A-Za-z0-9_]+)", code))
    scene.inputs = [i for i in scene.inputs if i.member in used]


def _carriers(scene: Scene) -> dict:
    """Link name -> the moving link (crank or dyad link) its pair D sits on, or None."""
    out = {}
    for name, link in scene.links.items():
        att = link.dyad.k if link.side == "m" else link.dyad.p
        out[name] = att.link if att.kind in ("crank", "link") else None
    if scene.crank:
        out[scene.crank.name] = None
    return out


def _ancestors(carrier_of: dict, names) -> set:
    """The moving links whose motion the accelerations of the links `names`' pairs D
    derive from: their carriers, the carriers' carriers, and so on (`carrier_of` from
    _carriers). Each link is visited once."""
    found: set = set()
    for name in names:
        carrier = carrier_of[name]
        while carrier is not None and carrier not in found:
            found.add(carrier)
            carrier = carrier_of[carrier]
    return found


def _loaders(scene: Scene, dyad: Dyad) -> list:
    """Dyads whose reactions load this dyad's links, directly or through others."""
    if not scene.loaders:
        # a dyad hangs only on links of earlier dyads: from the last dyad back, each one's
        # loaders are the dyads on its links and their loaders
        on_link: dict[str, list] = {}
        for d in scene.dyads:
            for a in (d.k, d.p):
                if a.kind == "link":
                    on_link.setdefault(a.link, []).append(d)
        for d in reversed(scene.dyads):
            found: dict[int, Dyad] = {}
            for g in (d.m, d.n):
                for child in on_link.get(g, []):
                    found[child.index] = child
                    found.update((o.index, o) for o in scene.loaders[child.index])
            found.pop(d.index, None)
            scene.loaders[d.index] = list(found.values())
    return scene.loaders[dyad.index]


def _inputs_of_links(scene: Scene, names: set) -> list:
    return [i.name for i in scene.inputs if i.owner in names]


def _derive_outputs(p: _Problems, scene: Scene, wanted):
    if wanted is None:
        p.add("[scene]: missing 'outputs' (a list such as [\"all\"] or [\"ram.R_np\", "
              "\"crank.torque\"])", "scene", 0)
        return
    if not isinstance(wanted, list) or not all(isinstance(w, str) for w in wanted) or not wanted:
        p.add("[scene]: outputs must be a non-empty list of output names", "scene", 0, "outputs")
        return
    offered: list[Output] = []
    by_name: dict[str, list[Output]] = {}
    geometry_inputs = {i.name for i in scene.inputs
                       if i.unit in ("rad", "m") and not i.name.endswith(".moment")}
    owner_of = {i.name: i.owner for i in scene.inputs}
    # the inputs of no link: the guides of external links, DYAD.guide_k.angle
    unowned = [i.name for i in scene.inputs if i.owner == ""]
    carrier_of = _carriers(scene)
    for d in scene.dyads:
        involved = {d.m, d.n}
        for other in _loaders(scene, d):
            involved |= {other.m, other.n}
        involved |= _ancestors(carrier_of, involved)
        guides = [n for n in unowned if n.startswith(d.prefix())]
        deps = _inputs_of_links(scene, involved) + guides
        # the conditioning: the dyad's own directions and lengths, and the direction of a
        # guide it slides on (an input, or a moving carrier's angle)
        own = {d.m, d.n} | {a.link for a in (d.k, d.p) if a.guide is not None and a.link}
        own_geometry = [n for n in deps if n in geometry_inputs and
                        (owner_of[n] in own or n in guides)]
        pre = d.prefix()
        for pair, idx in PAIR_NAMES:
            group = []
            for c in "xy":
                group.append(Output(f"{pre}R_{pair}.{c}", "N",
                                    _reaction_text(d, pair) + f", global {c}",
                                    f"{_member(pre)}r_{pair}_{c}", depends=deps,
                                    source=str(d.index)))
            by_name[f"{pre}R_{pair}"] = group
            offered += group
            if generate.PAIRS[d.type][idx] == "T":
                n_out = Output(f"{pre}N_{pair}", "N", f"Normal force of the sliding pair "
                               f"{_pair_label(pair)} of {d.name or 'the dyad'}",
                               f"{_member(pre)}n_{pair}", depends=deps, source=str(d.index))
                m_out = Output(f"{pre}M_{pair}", "N.m", f"Reactive moment of the sliding pair "
                               f"{_pair_label(pair)} of {d.name or 'the dyad'}",
                               f"{_member(pre)}m_{pair}", depends=deps, source=str(d.index))
                by_name[n_out.name] = [n_out]
                by_name[m_out.name] = [m_out]
                offered += [n_out, m_out]
        cond = Output(f"{pre}conditioning", None, f"Conditioning of {d.name or 'the dyad'} in "
                      "[0, 1]; below singular_threshold the dyad is singular",
                      f"{_member(pre)}conditioning", depends=own_geometry,
                      source=str(d.index))
        amp = Output(f"{pre}amplification", None, AMPLIFICATION_TEXT,
                     f"{_member(pre)}amplification", depends=deps, source=str(d.index))
        by_name[cond.name] = [cond]
        by_name[amp.name] = [amp]
        offered += [cond, amp]
    if scene.crank:
        c = scene.crank.name
        every = [i.name for i in scene.inputs]
        torque = Output(f"{c}.torque", "N.m", "Driving torque on the crank about O, "
                        "counter-clockwise", f"{_member(c)}_torque", depends=every,
                        source="crank")
        r_o = [Output(f"{c}.R_O.{x}", "N", f"Force on the crank from the frame at O, global {x}",
                      f"{_member(c)}_r_o_{x}", depends=every, source="crank")
               for x in "xy"]
        by_name[torque.name] = [torque]
        by_name[f"{c}.R_O"] = r_o
        offered += [torque] + r_o
    chosen: list[Output] = []
    picked: set[int] = set()
    for w in wanted:
        if w == "all":
            group = offered
        elif w in by_name:
            group = by_name[w]
        else:
            group = None
            for o in offered:
                if o.name == w:
                    group = [o]
            if group is None:
                p.add(f"[scene]: output '{w}': {_why_not(scene, w)}", "scene", 0, "outputs")
                continue
        for o in group:
            if id(o) not in picked:
                picked.add(id(o))
                chosen.append(o)
    position = {id(o): k for k, o in enumerate(offered)}
    chosen.sort(key=lambda o: position[id(o)])
    status = Output("status", None, "0 ok, 1 a dyad is singular, 3 a reaction overflows",
                    "status", integer=True, depends=[i.name for i in scene.inputs])
    scene.outputs = chosen + [status]


def _pair_label(pair: str) -> str:
    return {"mk": "D_m", "np": "D_n", "mn": "E"}[pair]


def _reaction_text(d: Dyad, pair: str) -> str:
    other = {"mk": "k", "np": "p"}.get(pair)
    if pair == "mn":
        return f"Force on {d.m} from {d.n} at E"
    link = d.m if pair == "mk" else d.n
    att = d.k if pair == "mk" else d.p
    source = att.link if att.kind in ("crank", "link") else att.kind
    return f"Force on {link} from {source} ({other}) at {_pair_label(pair)}"


def _why_not(scene: Scene, wanted: str) -> str:
    head, _, tail = wanted.rpartition(".")
    for d in scene.dyads:
        if head == d.name or (not d.name and not head):
            m = re.fullmatch(r"(N|M)_(mk|np|mn)", tail)
            if m:
                kind = d.pair_kind(m.group(2))
                if kind == "R":
                    return (f"no pair provides it: {_pair_label(m.group(2))} of the {d.type} "
                            f"dyad '{d.name}' is revolute (no normal force or reactive moment)")
            return (f"dyad '{d.name}' has no output '{tail}' (it has R_mk, R_np, R_mn, "
                    "conditioning, amplification and N_/M_ of its sliding pairs)")
    if scene.crank and head == scene.crank.name:
        return "the crank has only 'torque' and 'R_O'"
    names = [d.name for d in scene.dyads] + ([scene.crank.name] if scene.crank else [])
    return f"no dyad or crank is named '{head}' (known: {', '.join(names)})"


# ---------------------------------------------------------------------------
# The variable table
# ---------------------------------------------------------------------------
class SceneKind(generate.Kind):
    """A scene: flat input and output blocks generated with the scene's C."""

    def __init__(self, scene: Scene, input_members: dict, output_members: dict):
        ident = scene.identifier
        super().__init__("scene", f"{ident}_input", f"{ident}_output", input_members,
                         output_members, f"{ident}_scene.h", f"{ident}_behaviour")
        self.scene = scene


class SceneTable(generate.Table):
    def __init__(self, scene: Scene, rows: list[dict], kind: SceneKind):
        self.scene = scene
        self.path = scene.path
        self.model = {"kind": "scene", "identifier": scene.identifier,
                      "description": scene.description}
        self.kind = kind
        self.type = None
        self.identifier = scene.identifier
        self.description = scene.description
        self.variables = [Variable(raw, k, kind) for k, raw in enumerate(rows)]
        self.by_name = {v.name: v for v in self.variables}
        self.rows = rows

    @functools.cached_property
    def token(self) -> str:
        """The instantiation token, a hash of the whole table (computed when first asked
        for: the tables of the C names probe and of input pruning never need it)."""
        return generate.instantiation_token(self.model, self.rows)


def _bounds(raw: dict, domain: dict):
    for key in ("min", "max"):
        if key in domain:
            raw[key] = domain[key]
    for key in ("min_exclusive", "max_exclusive"):
        if domain.get(key):
            raw[key] = True


def scene_table(scene: Scene, probe: bool = False) -> SceneTable:
    """The variable table; `probe`: a table without outputs, to see what the code reads."""
    rows = []
    input_members: dict[str, str] = {}
    output_members: dict[str, str] = {}
    for i in scene.inputs:
        raw = {"name": i.name, "vr": len(rows) + 1, "causality": "input", "type": "Real",
               "start": i.start, "description": i.description,
               "lives": f"input.{i.member}{'@angle' if i.angle else ''}"}
        if i.unit:
            raw["unit"] = i.unit
        _bounds(raw, i.domain)
        rows.append(raw)
        input_members[i.member] = "dir" if i.angle else "real"
    for prm in scene.parameters():
        if not prm.tunable:
            continue
        raw = {"name": prm.name, "vr": len(rows) + 1, "causality": "parameter", "type": "Real",
               "start": prm.value, "description": prm.description,
               "lives": f"input.{prm.member}"}
        if prm.unit:
            raw["unit"] = prm.unit
        _bounds(raw, prm.domain)
        rows.append(raw)
        input_members[prm.member] = "real"
    for o in ([] if probe else scene.outputs):
        raw = {"name": o.name, "vr": len(rows) + 1, "causality": "output",
               "type": "Integer" if o.integer else "Real", "description": o.description,
               "lives": f"result.{o.member}", "depends": list(o.depends)}
        if o.unit:
            raw["unit"] = o.unit
        rows.append(raw)
        output_members[o.member] = "status" if o.integer else "real"
    return SceneTable(scene, rows, SceneKind(scene, input_members, output_members))


def is_generic(scene: Scene) -> bool:
    """A scene that is one whole dyad: every variable of its type, every parameter tunable,
    both external links free. It is realised by the generic dyad FMU (the core's validating
    solver with its exact directional derivatives) rather than by generated code."""
    if len(scene.dyads) != 1 or scene.crank is not None:
        return False
    d = scene.dyads[0]
    links = [scene.links[d.m], scene.links[d.n]]
    offered = 2 * 3 + 2 * sum(k == "T" for k in generate.PAIRS[d.type]) + 2 + 1
    return (d.name == "" and d.m == "link_m" and d.n == "link_n" and
            d.k.kind == "external" and d.p.kind == "external" and
            scene.inertia and scene.gravity and
            all(link.force and link.moment for link in links) and
            len(scene.outputs) == offered and
            all(prm.tunable for prm in scene.parameters()))


def generic_data(scene: Scene) -> dict:
    """The variable table (as generate.py reads it) of a generic scene."""
    d = scene.dyads[0]
    params = {prm.name: prm for prm in scene.parameters()}
    starts = {i.name: i.start for i in scene.inputs}
    rows = []
    for entry in generate.catalogue(d.type).values():
        raw = {"name": entry.name, "vr": len(rows) + 1, "causality": entry.causality,
               "type": entry.value_type}
        if entry.unit:
            raw["unit"] = entry.unit
        if entry.causality == "input":
            raw["start"] = starts[entry.name]
        elif entry.causality == "parameter":
            raw["start"] = params[entry.name].value
        for key, value in entry.domain.items():
            if value is not False:
                raw[key] = value
        raw["description"] = entry.description
        raw["lives"] = entry.lives
        if entry.causality == "output":
            raw["depends"] = list(entry.depends)
        rows.append(raw)
    return {"model": {"type": d.type, "identifier": scene.identifier,
                      "description": scene.description}, "variable": rows}


def build_table(scene: Scene):
    """The scene's variable table: generic (generate.Table of kind dyad) or tailored."""
    if is_generic(scene):
        try:
            return generate.table_from_data(generic_data(scene), scene.path)
        except generate.TableError as exc:
            raise SceneError(exc.args[0]) from None
    return scene_table(scene)


# ---------------------------------------------------------------------------
# The C model
# ---------------------------------------------------------------------------
def scene_header(table: SceneTable) -> str:
    scene = table.scene
    ident = scene.identifier
    guard = f"DYADFMU_SCENE_{ident.upper()}_H"
    lines = [f"/* {ident}_scene.h: the input and output blocks of the scene {ident}.",
             f" * Generated by modelDescription/scene.py from "
             f"{textsafe.c_comment(scene.path.name)}; do not edit. */",
             f"#ifndef {guard}", f"#define {guard}", "", '#include "dyadfmu/vec2.h"',
             '#include "fmu_model.h"', "",
             "/* Inputs and tunable parameters; an angle is kept as its unit vector. */",
             f"typedef struct {ident}_input {{"]
    units = {v.lives.path: v.unit for v in table.variables}
    for member, leaf in table.kind.input_members.items():
        ctype = "dyad_vec2" if leaf == "dir" else "double"
        lines.append(f"    {ctype} {member}; /* {units.get(member) or '-'} */")
    if not table.kind.input_members:
        lines.append("    double unused; /* the scene has no inputs */")
    lines += [f"}} {ident}_input;", "", f"typedef struct {ident}_output {{"]
    for member, leaf in table.kind.output_members.items():
        if leaf == "status":
            lines.append(f"    int {member}; /* 0 ok, 1 singular, 3 out of range */")
        else:
            lines.append(f"    double {member}; /* {units.get(member) or '-'} */")
    lines += [f"}} {ident}_output;", "", f"extern const fmu_behaviour {ident}_behaviour;", "",
              f"#endif /* {guard} */"]
    return "\n".join(lines) + "\n"


class _Code:
    def __init__(self):
        self.lines: list[str] = []

    def __call__(self, text: str = ""):
        self.lines.append(("    " + text) if text else "")


def _vec(x: str, y: str) -> str:
    return f"dyad_vec2_make({x}, {y})"


def scene_c(table: SceneTable) -> str:
    scene = table.scene
    ident = scene.identifier
    names = {i.name: i for i in scene.inputs}
    code = _Code()
    crank = scene.crank

    def inp(name: str) -> str:
        return f"in->{names[name].member}"

    def has(name: str) -> bool:
        return name in names

    # ---- what the requested outputs need: their dyads, the dyads loading those, and for
    # the crank's outputs every dyad on the crank
    crank_needed = any(o.source == "crank" for o in scene.outputs)
    needed = {int(o.source) for o in scene.outputs if o.source not in ("", "crank")}
    if crank_needed:
        needed |= {d.index for d in scene.dyads
                   if any(a.kind == "crank" for a in (d.k, d.p))}
    for d in list(scene.dyads):
        if d.index in needed:
            needed |= {other.index for other in _loaders(scene, d)}
    solved = [d for d in scene.dyads if d.index in needed]

    # ---- frames of every moving link
    code("/* Link frames: i from D towards E, j = k0 x i. */")
    everything = ([crank.name] if crank else []) + [g for d in scene.dyads for g in (d.m, d.n)]
    moving = ([crank.name] if crank_needed else []) + [g for d in solved for g in (d.m, d.n)]
    for g in everything:
        c = _member(g)
        link = scene.links.get(g)
        if link is not None and link.translating:
            a = link.params["angle"]
            if a.tunable:
                code(f"const dyad_vec2 {c}_i = dyad_dir_from_angle({a.c()});")
            else:
                code(f"const dyad_vec2 {c}_i = {_vec(_c_num(math.cos(a.value)), _c_num(math.sin(a.value)))};")
        elif has(g + ".angle"):
            code(f"const dyad_vec2 {c}_i = {inp(g + '.angle')};")
        else:
            continue   # a link the requested outputs do not involve
        code(f"const dyad_vec2 {c}_j = dyad_perp({c}_i);")

    def omega(g):
        return inp(g + ".omega") if has(g + ".omega") else None

    def epsilon(g):
        return inp(g + ".epsilon") if has(g + ".epsilon") else None

    def point(g, at):
        """C expression of a point's offset from D_g (O for the crank) given (Param, Param)."""
        c = _member(g)
        x, y = at
        if x.is_zero() and y.is_zero():
            return None
        if y.is_zero():
            return f"dyad_scale({x.c()}, {c}_i)"
        if x.is_zero():
            return f"dyad_scale({y.c()}, {c}_j)"
        return f"dyad_combine({x.c()}, {c}_i, {y.c()}, {c}_j)"

    def holder(g):
        return crank.params if crank and g == crank.name else scene.links[g].params

    def attachment_point(att: Attachment):
        """The pair's point (for a sliding pair: the guide's point) from the carrier's D."""
        if att.kind == "crank" and att.at is None:
            length = crank.params["length"]
            zero = Param("", 0.0, "m", "")
            return point(att.link, (length, zero))
        return point(att.link, att.at)

    # ---- accelerations of the outer pairs D
    accel: dict[str, str | None] = {}   # link -> C name of a_D or None for zero
    accel_size: dict[str, str] = {}     # link -> C expression of the size of a_D's terms
    if scene.inertia:
        code()
        code("/* Accelerations of the pairs D: 0 on a fixed pivot, an input on a guide or an")
        code(" * external link, and from the carrying link's motion on a moving link. */")
        if crank:
            accel[crank.name] = None
        for d in solved:
            for g, att in ((d.m, d.k), (d.n, d.p)):
                c = _member(g)
                if has(g + ".accel_d.x"):
                    code(f"const dyad_vec2 {c}_a_d = {_vec(inp(g + '.accel_d.x'), inp(g + '.accel_d.y'))};")
                    accel[g] = f"{c}_a_d"
                    accel_size[g] = f"dyad_norm1({c}_a_d)"
                elif att.kind in ("crank", "link"):
                    carrier = att.link
                    r = attachment_point(att)
                    terms = []
                    sizes = []
                    if accel.get(carrier):
                        terms.append(accel[carrier])
                        sizes.append(accel_size[carrier])
                    if r is not None:
                        code(f"const dyad_vec2 {c}_r_d = {r};")
                        w, e = omega(carrier), epsilon(carrier)
                        if e:
                            terms.append(f"dyad_scale({e}, dyad_perp({c}_r_d))")
                            sizes.append(f"fabs({e}) * dyad_norm1({c}_r_d)")
                        if w:
                            terms.append(f"dyad_scale(-{w} * {w}, {c}_r_d)")
                            sizes.append(f"{w} * {w} * dyad_norm1({c}_r_d)")
                    if terms:
                        expr = terms[0]
                        for t in terms[1:]:
                            expr = f"dyad_add({expr}, {t})"
                        code(f"const dyad_vec2 {c}_a_d = {expr};")
                        accel[g] = f"{c}_a_d"
                        code(f"const double {c}_a_d_size = {' + '.join(sizes)};")
                        accel_size[g] = f"{c}_a_d_size"
                    else:
                        accel[g] = None
                else:
                    accel[g] = None

    # ---- resultants
    code()
    code("/* Resultant of each link's active load, weight and inertia at its centre of mass:")
    code(" * force f, moment m about the centre of mass, moment m_d about D (without the")
    code(" * centripetal force, which points at D). Only the scene's terms are written. */")
    for g in moving:
        c = _member(g)
        params = holder(g)
        com = (params.get("com.x"), params.get("com.y"))
        r = None
        if com[0] is not None and not (com[0].is_zero() and com[1].is_zero()):
            r = point(g, com)
            code(f"const dyad_vec2 {c}_r = {r};")
        mass = params.get("mass")
        link = scene.links.get(g)
        force_terms = []
        force_sizes = []   # the sizes of the terms (dyadfmu/loaded.h), as the core forms them
        if link is not None and link.force:
            force_terms.append(_vec(inp(g + ".force.x"), inp(g + ".force.y")))
            force_sizes.append(f"dyad_norm1({force_terms[-1]})")
        massive = mass is not None and not mass.is_zero()
        if massive:
            inner = []
            inner_sizes = []
            if scene.gravity:
                gx, gy = scene.gravity_params
                inner.append(_vec(gx.c(), gy.c()))
                inner_sizes.append(f"dyad_norm1({inner[-1]})")
            if scene.inertia:
                tang = []
                if accel.get(g):
                    tang.append(accel[g])
                    inner_sizes.append(accel_size[g])
                e = epsilon(g)
                if e and r is not None:
                    tang.append(f"dyad_scale({e}, dyad_perp({c}_r))")
                    inner_sizes.append(f"fabs({e}) * dyad_norm1({c}_r)")
                for t in tang:
                    inner.append(f"dyad_neg({t})")
            if inner:
                expr = inner[0]
                for t in inner[1:]:
                    expr = f"dyad_add({expr}, {t})"
                force_terms.append(f"dyad_scale({mass.c()}, {expr})")
                force_sizes.append(f"{mass.c()} * ({' + '.join(inner_sizes)})")
        code(f"dyad_vec2 {c}_f = {_sum(force_terms)};")
        moment_terms = []
        moment_sizes = []
        if link is not None and link.moment:
            moment_terms.append(inp(g + ".moment"))
            moment_sizes.append(f"fabs({moment_terms[-1]})")
        inert = params.get("inertia")
        if scene.inertia and inert is not None and not inert.is_zero() and epsilon(g):
            moment_terms.append(f"-{inert.c()} * {epsilon(g)}")
            moment_sizes.append(f"{inert.c()} * fabs({epsilon(g)})")
        code(f"double {c}_m = {' + '.join(moment_terms) if moment_terms else '0.0'};")
        if r is not None and force_terms:
            code(f"double {c}_m_d = {c}_m + dyad_cross({c}_r, {c}_f);")
        else:
            code(f"double {c}_m_d = {c}_m;")
        code(f"double {c}_f_size = {' + '.join(force_sizes) or '0.0'};")
        if r is not None and force_terms:
            moment_sizes.append(f"dyad_norm1({c}_r) * {c}_f_size")
        code(f"double {c}_m_d_size = {' + '.join(moment_sizes) or '0.0'};")
        w = omega(g)
        if scene.inertia and massive and r is not None and w:
            code(f"{c}_f = dyad_add({c}_f, dyad_scale({mass.c()} * {w} * {w}, {c}_r));")
            code(f"{c}_f_size += {mass.c()} * {w} * {w} * dyad_norm1({c}_r);")
        code(f"(void){c}_m;")
        code(f"(void){c}_f_size;")
        code(f"(void){c}_m_d_size;")

    # ---- the chain, from the last dyad back
    code()
    code("/* The dyads from the last to the first: each one's reactions load the links")
    code(" * it is attached to, as forces at its pair points. */")
    for d in reversed(solved):
        dn = _member(d.name or "dyad")
        code(f"{{ /* dyad {d.name or ''} ({d.type}) */")
        code(f"    dyad_loaded load;")
        for side, g in (("m", d.m), ("n", d.n)):
            c = _member(g)
            link = scene.links[g]
            length = inp(g + ".length") if link.sliding else link.params["length"].c()
            code(f"    load.{side}.i = {c}_i;")
            code(f"    load.{side}.j = {c}_j;")
            code(f"    load.{side}.l = {length};")
            code(f"    load.{side}.f = {c}_f;")
            code(f"    load.{side}.m = {c}_m;")
            code(f"    load.{side}.m_d = {c}_m_d;")
            code(f"    load.{side}.f_size = {c}_f_size;")
            code(f"    load.{side}.m_d_size = {c}_m_d_size;")
        for side, att in (("k", d.k), ("p", d.p)):
            if d.pair_kind("mk" if side == "k" else "np") == "T":
                if att.kind == "external":
                    guide = inp(f"{d.prefix()}guide_{side}.angle")
                elif att.kind != "frame":
                    carrier = _member(att.link)
                    if att.guide.is_zero():
                        guide = f"{carrier}_i"
                    elif att.guide.tunable:
                        guide = (f"dyad_combine(cos({att.guide.c()}), {carrier}_i, "
                                 f"sin({att.guide.c()}), {carrier}_j)")
                    else:
                        guide = (f"dyad_combine({_c_num(math.cos(att.guide.value))}, "
                                 f"{carrier}_i, {_c_num(math.sin(att.guide.value))}, "
                                 f"{carrier}_j)")
                elif att.guide.tunable:
                    guide = f"dyad_dir_from_angle({att.guide.c()})"
                else:
                    guide = _vec(_c_num(math.cos(att.guide.value)),
                                 _c_num(math.sin(att.guide.value)))
                code(f"    load.i_{side} = {guide};")
            else:
                code(f"    load.i_{side} = dyad_vec2_make(1.0, 0.0);")
            code(f"    load.j_{side} = dyad_perp(load.i_{side});")
        code(f"    load.singular_threshold = {scene.threshold.c()};")
        code(f"    if (dyad_react_{d.type.lower()}(&load, &{dn}) != DYAD_STATUS_OK) {{")
        code(f"        fail(out, &{dn}, {textsafe.c_string(d.name or d.type)}, "
             f"{scene.threshold.c()}, evaluation);")
        code("        return;")
        code("    }")
        for side, att, pair_force in (("k", d.k, "r_mk"), ("p", d.p, "r_np")):
            if att.kind not in ("crank", "link") or att.link not in moving:
                continue
            carrier = _member(att.link)
            r = attachment_point(att)
            reactive = ""
            if att.guide is not None:
                # the pair point slides along the guide; the pair also carries a moment
                slide = f"dyad_scale({inp(d.prefix() + 'slide_' + side)}, load.i_{side})"
                r = slide if r is None else f"dyad_add({r}, {slide})"
                reactive = f" - {dn}.m_{pair_force[2:]}"
            code(f"    /* on {att.link}: -{pair_force.upper()} at the pair"
                 f"{' and the reactive moment' if reactive else ''} */")
            code(f"    {carrier}_f = dyad_sub({carrier}_f, {dn}.{pair_force});")
            code(f"    {carrier}_f_size += dyad_force_size(&{dn});")
            if r is not None:
                code(f"    {{ const dyad_real moment = -dyad_cross({r}, {dn}.{pair_force})"
                     f"{reactive};")
                code(f"      {carrier}_m_d += moment;")
                code(f"      {carrier}_m_d_size += dyad_norm1({r}) * dyad_force_size(&{dn})"
                     f"{f' + dyad_moment_size(&{dn})' if reactive else ''};")
                com = holder(att.link)
                if com.get("com.x") is not None and not (com["com.x"].is_zero() and
                                                          com["com.y"].is_zero()):
                    code(f"      {carrier}_m += moment + dyad_cross({carrier}_r, {dn}.{pair_force}); }}")
                else:
                    code(f"      {carrier}_m += moment; }}")
        code("}")

    # ---- the crank
    if crank_needed:
        c = _member(crank.name)
        code()
        code("/* The crank: the driving torque balances the moments about O, R_O the forces. */")
        if any(o.member == f"{c}_torque" for o in scene.outputs):
            code(f"{c}_torque = -{c}_m_d;")
        if any(o.member.startswith(f"{c}_r_o_") for o in scene.outputs):
            code(f"{c}_r_o = dyad_neg({c}_f);")
        code(f"(void){c}_m_d;")

    # ---- outputs
    code()
    code("/* Outputs */")
    exprs = _output_exprs(scene)
    for o in scene.outputs:
        if not o.integer:
            code(f"out->{o.member} = {exprs[o.member]};")
    code("out->status = 0;")
    code("check(out, evaluation);")

    dyad_decls = [f"    dyad_result {_member(d.name or 'dyad')};" for d in solved]
    crank_decls = []
    if crank_needed:
        c = _member(crank.name)
        if any(o.member == f"{c}_torque" for o in scene.outputs):
            crank_decls.append(f"    double {c}_torque;")
        if any(o.member.startswith(f"{c}_r_o_") for o in scene.outputs):
            crank_decls.append(f"    dyad_vec2 {c}_r_o;")
    reals = [o.member for o in scene.outputs if not o.integer]
    check_terms = " + ".join(f"(out->{m} - out->{m})" for m in reals) or "0.0"
    nan_lines = "\n".join(f"    out->{m} = NAN;" for m in reals)
    header = f'''/* {ident}_scene.c: the computation of the scene {ident}.
 * Generated by modelDescription/scene.py from {textsafe.c_comment(scene.path.name)}; do not
 * edit: change the scene and regenerate.
 *
 * {textsafe.c_comment(scene.description)}
 *
 * Effects: inertia {"on" if scene.inertia else "off"}, gravity {"on" if scene.gravity else "off"}.
 * Every parameter the scene does not list as tunable is a constant here, and a term
 * that is zero by the scene (a baked zero mass or centre of mass, no inertia, no gravity)
 * is not written at all. The chain is solved from its last dyad back to the first
 * (dyadfmu/loaded.h); the crank's driving torque and pivot reaction come last.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dyadfmu/loaded.h"
#include "dyadfmu/vec2.h"
#include "{ident}_scene.h"

static void set_nan({ident}_output* out)
{{
{nan_lines}
}}

static void fail({ident}_output* out, const dyad_result* dyad, const char* name,
                 double threshold, fmu_evaluation* evaluation)
{{
    set_nan(out);
    evaluation->status = FMU_DISCARD;
    evaluation->bad_variable = -1;
    if (dyad->status == DYAD_STATUS_SINGULAR) {{
        out->status = 1;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "dyad %s is singular: conditioning %.3g is below singular_threshold %.3g; "
                 "reactions are NaN", name, (double)dyad->conditioning, threshold);
    }} else {{
        out->status = 3;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the reactions of dyad %s overflow double; reactions are NaN", name);
    }}
}}

static void check({ident}_output* out, fmu_evaluation* evaluation)
{{
    /* x - x is 0 for a finite x and NaN otherwise */
    const double nonfinite = {check_terms};
    evaluation->bad_variable = -1;
    evaluation->reason[0] = '\\0';
    evaluation->status = FMU_OK;
    if (nonfinite != 0) {{
        set_nan(out);
        out->status = 3;
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the loads or reactions overflow double; outputs are NaN");
    }}
}}

static void initialise(const fmu_model* model, void* input)
{{
    (void)model;
    memset(input, 0, sizeof({ident}_input));
}}

static void evaluate(const fmu_model* model, const void* input, void* output,
                     fmu_evaluation* evaluation)
{{
    const {ident}_input* in = (const {ident}_input*)input;
    {ident}_output* out = ({ident}_output*)output;
{chr(10).join(dyad_decls)}
{chr(10).join(crank_decls)}
    (void)model;
    (void)in;
'''
    body = "\n".join(_drop_unused_constants(code.lines))
    footer = f'''
}}

const fmu_behaviour {ident}_behaviour = {{sizeof({ident}_input), sizeof({ident}_output),
                                          initialise, evaluate, NULL, NULL, NULL}};
'''
    return header + body + footer


def _drop_unused_constants(lines: list) -> list:
    """Remove `const ... name = ...;` lines whose name nothing else reads (a frame vector j
    that no term of the scene needs, say), until none is left. Each identifier's uses are
    counted once; removing a line takes its uses off the counts, which may free the
    constants it read in turn."""
    declaration = re.compile(r"^\s*const [A-Za-z0-9_]+ ([A-Za-z0-9_]+) = .*;$")
    word = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
    uses: dict[str, int] = {}
    declared: dict[str, int] = {}          # constant -> its line
    for k, line in enumerate(lines):
        for w in word.findall(line):
            uses[w] = uses.get(w, 0) + 1
        m = declaration.match(line)
        if m:
            declared[m.group(1)] = k
    removed: set[int] = set()
    pending = [name for name in declared if uses[name] == 1]
    while pending:
        name = pending.pop()
        k = declared[name]
        if k in removed or uses[name] != 1:
            continue
        removed.add(k)
        for w in word.findall(lines[k]):
            uses[w] -= 1
            if w != name and w in declared and uses[w] == 1:
                pending.append(w)
    return [line for k, line in enumerate(lines) if k not in removed]


def _sum(terms: list) -> str:
    if not terms:
        return "dyad_vec2_make(0.0, 0.0)"
    expr = terms[0]
    for t in terms[1:]:
        expr = f"dyad_add({expr}, {t})"
    return expr


def _output_exprs(scene: Scene) -> dict[str, str]:
    """The C expression of every output's value, by output member."""
    exprs = {}
    if scene.crank:
        c = _member(scene.crank.name)
        exprs[f"{c}_torque"] = f"{c}_torque"
        exprs[f"{c}_r_o_x"] = f"{c}_r_o.x"
        exprs[f"{c}_r_o_y"] = f"{c}_r_o.y"
    for d in scene.dyads:
        pre = _member(d.prefix())
        dn = _member(d.name or "dyad")
        for pair in ("mk", "np", "mn"):
            for c in "xy":
                exprs[f"{pre}r_{pair}_{c}"] = f"{dn}.r_{pair}.{c}"
            for kind in "nm":
                exprs[f"{pre}{kind}_{pair}"] = f"{dn}.{kind}_{pair}"
        for rest in ("conditioning", "amplification"):
            exprs[f"{pre}{rest}"] = f"{dn}.{rest}"
    return exprs



# ---------------------------------------------------------------------------
# Documentation
# ---------------------------------------------------------------------------
def _attachment_text(att: Attachment, pair: str) -> str:
    if att.kind == "frame":
        return "the frame" + (f" (guide at {_h(_num(att.guide))} rad)" if att.guide else "")
    if att.guide is not None:
        return (f"a guide on <code>{_h(att.link)}</code> at {_h(_num(att.guide))} rad from its "
                f"i, through ({_h(_num(att.at[0]))}, {_h(_num(att.at[1]))}) m in its frame")
    if att.kind == "external":
        return "an external link whose motion is an input"
    if att.at is None:
        return f"the pin of the crank <code>{_h(att.link)}</code>"
    return (f"<code>{_h(att.link)}</code> at ({_h(_num(att.at[0]))}, {_h(_num(att.at[1]))}) "
            "m in its frame")


def _num(prm: Param) -> str:
    return f"<code>{prm.name}</code>" if prm.tunable else repr(prm.value)


def _h(text) -> str:
    return textsafe.html(text)


def scene_documentation(table: SceneTable) -> str:
    scene = table.scene
    n = counts(table)
    o = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
         f"<title>{_h(scene.identifier)}: a dyadfmu scene</title>",
         f"<style>\n{generate._CSS}\n</style>", "</head>", "<body>",
         f"<h1>{_h(scene.identifier)}: a dyadfmu scene</h1>",
         f"<p>{_h(scene.description)}</p>",
         "<p>A co-simulation FMU (FMI 2.0 and FMI 3.0) generated from the scene file "
         f"<code>{_h(scene.path.name)}</code>. At every communication point it takes the "
         "links' current kinematics and active loads and returns the reactions the scene asks "
         "for. It carries only the scene's variables "
         f"({n['input']} inputs, {n['parameter']} parameters, {n['output']} outputs) and "
         "computes only the scene's terms: every parameter not listed as tunable is a "
         "constant of the C code, and a term that the scene makes zero is not computed.</p>",
         "<h2>Effects</h2><ul>",
         f"<li>Inertia (d'Alembert forces and moments): {'yes' if scene.inertia else 'no'}</li>",
         f"<li>Gravity: {'yes' if scene.gravity else 'no'}</li>"]
    loaded = [f"{g} (force)" for g, link in scene.links.items() if link.force]
    loaded += [f"{g} (moment)" for g, link in scene.links.items() if link.moment]
    o.append(f"<li>Active loads, inputs: {_h(', '.join(loaded) or 'none')}</li></ul>")
    o.append("<h2>Mechanism</h2>")
    if scene.crank:
        o.append(f"<p>Crank <code>{_h(scene.crank.name)}</code> about the fixed pivot O; its "
                 "pin A lies at (length, 0) in its frame. Its driving torque and the force of "
                 "the frame at O follow from its equilibrium once every dyad is solved.</p>")
    o.append("<table><tr><th>dyad</th><th>type</th><th>link m</th><th>link n</th>"
             "<th>D_m on</th><th>D_n on</th></tr>")
    for d in scene.dyads:
        o.append(f"<tr><td><code>{_h(d.name or '-')}</code></td><td>{d.type}</td>"
                 f"<td><code>{_h(d.m)}</code></td><td><code>{_h(d.n)}</code></td>"
                 f"<td>{_attachment_text(d.k, 'D_m')}</td><td>{_attachment_text(d.p, 'D_n')}"
                 "</td></tr>")
    o.append("</table>")
    o.append("<p>Conventions as in every dyadfmu FMU: link g's frame {D_g; i_g, j_g} with "
             "i_g from D_g towards E and j_g = k0 x i_g; the centre of mass is given in that "
             "frame; angles counter-clockwise from x; R_mk is the force on link m from link k "
             "at D_m, R_np on n from p at D_n, R_mn on m from n at E; N and M are the normal "
             "force and the reactive moment of a sliding pair. The dyads are solved from the "
             "last to the first: a later dyad's reaction loads the link it is attached to as a "
             "force at the pair point.</p>")
    baked = [prm for prm in scene.parameters() if not prm.tunable]
    if baked:
        o.append("<h2>Constants</h2>")
        o.append("<p>Fixed by the scene and compiled in:</p>")
        o.append("<table><tr><th>name</th><th>value</th><th>unit</th></tr>")
        for prm in baked:
            o.append(f"<tr><td><code>{_h(prm.name)}</code></td><td class=\"num\">"
                     f"{prm.value!r}</td><td>{_h(prm.unit or '-')}</td></tr>")
        o.append("</table>")
    o.append("<h2>Variables</h2>")
    o += generate._variable_rows(table)
    o.append("<p>A value outside its range, or not finite, is rejected by the setter with an "
             "error that names the variable.</p>")
    o.append("<h2>Status codes</h2>")
    o.append("<table><tr><th><code>status</code></th><th>meaning</th></tr>"
             "<tr><td class=\"num\">0</td><td>ok</td></tr>"
             "<tr><td class=\"num\">1</td><td>a dyad is singular (its conditioning is below "
             "<code>singular_threshold</code>): <code>doStep</code> returns Discard and logs "
             "which dyad; every real output is NaN</td></tr>"
             "<tr><td class=\"num\">3</td><td>a reaction overflows double: Discard, outputs "
             "NaN</td></tr></table>")
    o.append("<p>No directional derivatives: a tailored FMU declares "
             "<code>providesDirectionalDerivative(s)=\"false\"</code>.</p>")
    return generate._closing(o, table)


# ---------------------------------------------------------------------------
# Files
# ---------------------------------------------------------------------------
def outputs_of(table) -> dict[str, str]:
    if not isinstance(table, SceneTable):
        return generate.outputs_of(table)
    ident = table.identifier
    return {
        "fmi2/modelDescription.xml": generate.fmi2_model_description(table),
        "fmi3/modelDescription.xml": generate.fmi3_model_description(table),
        "fmi3/buildDescription.xml": generate.fmi3_build_description(table),
        f"{ident}_model.c": generate.model_c(table),
        f"{ident}_scene.c": scene_c(table),
        f"{ident}_scene.h": scene_header(table),
        "documentation/index.html": scene_documentation(table),
    }


def counts(table) -> dict[str, int]:
    return {c: len(table.of(c)) for c in ("input", "parameter", "output")}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        description="Generate a tailored FMU's model descriptions, C model and documentation "
                    "from a scene (see scenes/README.md).")
    parser.add_argument("scene", type=Path, help="the scene file (TOML)")
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--out", type=Path, help="directory to write the generated files to")
    what.add_argument("--check", action="store_true",
                      help="validate the scene and print its variable counts; write nothing")
    what.add_argument("--cmake-info", action="store_true",
                      help="print 'identifier;type;...' (its dyad types, lower case) for CMake")
    args = parser.parse_args(argv)
    try:
        scene = load_scene(args.scene)
        table = build_table(scene)
    except SceneError as exc:
        for problem in exc.args[0]:
            print(f"error: {problem}", file=sys.stderr)
        print(f"{args.scene}: rejected, nothing written", file=sys.stderr)
        return 1
    if args.cmake_info:
        types = sorted({d.type.lower() for d in scene.dyads})
        realisation = "tailored" if isinstance(table, SceneTable) else "generic"
        print(";".join([scene.identifier, realisation] + types))
        return 0
    if args.check:
        n = counts(table)
        kind = "tailored" if isinstance(table, SceneTable) else "generic dyad"
        print(f"{scene.identifier} ({kind}): {n['input']} inputs, {n['parameter']} "
              f"parameters, {n['output']} outputs")
        return 0
    for rel, text in outputs_of(table).items():
        generate._write(args.out / rel, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

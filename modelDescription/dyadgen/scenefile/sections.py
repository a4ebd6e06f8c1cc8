"""One parser per section of a scene file that is not the mechanism ([scene], [effects],
[gravity], [crank], [loads], the tunable parameters, [start]); mechanism.py parses the
links and dyads. Each parser records every problem it finds and returns what is valid."""

from __future__ import annotations

from pathlib import Path

from dyadgen import textsafe
from dyadgen.forward import DYNAMICS
from dyadgen.model import MOTOR_NUMBERS, Crank, Motor, Param, Scene, member
from dyadgen.scenefile.builtins import builtin_identifiers, is_builtin
from dyadgen.scenefile.names import (
    identifier_problem,
    name_problem,
    reserved_identifier_problem,
)
from dyadgen.scenefile.problems import (
    Problems,
    SceneError,
    number,
    pair_of_numbers,
    real,
    shown,
    unknown_keys,
)
from dyadgen.tomltext import TomlTextError, read_toml

SCENE_KEYS = {
    "identifier",
    "description",
    "outputs",
    "tunable",
    "singular_threshold",
    "kinematics",
    "dynamics",
}
EFFECT_KEYS = {"inertia", "gravity"}
CRANK_KEYS = {"name", "length", "com", "mass", "inertia", "at"}
RAM_KEYS = {"name", "guide", "at", "com", "mass", "inertia"}
CYLINDER_KEYS = {"name", "link", "at", "base", "pin", "branch", "com", "mass", "inertia"}
CYLINDER_KEYS |= {"barrel", "rod"}
CYLINDER_PART_KEYS = {"mass", "com", "inertia"}
DRIVERS = ("crank", "ram", "cylinder")
LOAD_KEYS = {"force", "moment"}
TOP_KEYS = {"scene", "effects", "gravity", "dyad", "link", "loads", "load", "start", "motor"}
TOP_KEYS |= {"experiment"}
TOP_KEYS |= set(DRIVERS)
MOTOR_KEYS = {"driver", *MOTOR_NUMBERS}
KINEMATICS = ("internal", "external")
#: sqrt(DBL_EPSILON), where round-off still leaves half of the digits.
DEFAULT_THRESHOLD = 1.4901161193847656e-8


def read_text(path: Path) -> tuple[str, dict]:
    """The text of a scene file and its TOML; raises SceneError where it is no TOML text
    (or too large, or nested too deeply: tomltext)."""
    try:
        return read_toml(path)
    except TomlTextError as exc:
        line = "" if exc.line is None else f":{exc.line}"
        raise SceneError(
            [f"{textsafe.plain(path.name)}{line}: {textsafe.plain(exc.message)}"]
        ) from None


def scene_section(p: Problems, data: dict) -> tuple[dict, str, str]:
    """The top-level tables, and [scene]: the table, the identifier and the description
    (stand-ins where they are invalid); raises SceneError where [scene] is missing."""
    for key in data:
        if key not in TOP_KEYS:
            p.add(f"unknown table '{key}' (expected {', '.join(sorted(TOP_KEYS))})", key, 0)
    scene_t = data.get("scene")
    if not isinstance(scene_t, dict):
        p.add("missing [scene] table (identifier, description, outputs)", "scene", 0)
        raise SceneError(p.items)
    unknown_keys(p, scene_t, SCENE_KEYS, "[scene]", "scene", 0)
    identifier = scene_t.get("identifier")
    problem = identifier_problem(identifier)
    if problem is None and not is_builtin(p.path, identifier):
        problem = reserved_identifier_problem(identifier, builtin_identifiers())
    if problem:
        p.add(f"[scene]: identifier {problem}", "scene", 0, "identifier")
        identifier = "scene"
    description = scene_t.get("description")
    problem = textsafe.description_problem(description)
    if problem:
        p.add(f"[scene]: description {problem}", "scene", 0, "description")
        description = ""
    return scene_t, identifier, description


def effects(p: Problems, data: dict) -> dict[str, bool]:
    """[effects]: inertia and gravity, each on or off."""
    effects_t = data.get("effects", {})
    if not isinstance(effects_t, dict):
        p.add("[effects] must be a table", "effects", 0)
        effects_t = {}
    unknown_keys(p, effects_t, EFFECT_KEYS, "[effects]", "effects", 0)
    found = {}
    for key in EFFECT_KEYS:
        value = effects_t.get(key, False)
        if not isinstance(value, bool):
            p.add(f"[effects]: '{key}' must be true or false, not {value!r}", "effects", 0, key)
            value = False
        found[key] = value
    return found


def gravity(p: Problems, data: dict, on: bool) -> tuple[Param, Param] | None:
    """[gravity]: its x and y (m/s2), where gravity is on."""
    gravity_t = data.get("gravity")
    if not on:
        if gravity_t is not None:
            p.add(
                "[gravity] is given, but [effects] gravity is not true: set it or remove the table",
                "gravity",
                0,
            )
        return None
    if not isinstance(gravity_t, dict):
        p.add(
            "[effects]: gravity = true, but there is no [gravity] table with x and y (m/s2)",
            "effects",
            0,
            "gravity",
        )
        return None
    unknown_keys(p, gravity_t, {"x", "y"}, "[gravity]", "gravity", 0)
    gx = number(p, gravity_t, "x", "[gravity]", "gravity", 0)
    gy = number(p, gravity_t, "y", "[gravity]", "gravity", 0)
    if gx is None or gy is None:
        return None
    return (
        Param("gravity.x", gx, "m/s2", "Gravitational acceleration, global x component"),
        Param("gravity.y", gy, "m/s2", "Gravitational acceleration, global y component"),
    )


def threshold(p: Problems, scene_t: dict) -> Param:
    """[scene] singular_threshold, in (0, 1). Where the scene does not set it, the C says
    DYAD_DEFAULT_SINGULAR_THRESHOLD: sqrt(eps) of the scalar it is compiled with (in float
    3.45e-4, not double's 1.49e-8, below which float keeps no digits worth a status 0)."""
    given = "singular_threshold" in scene_t
    value = real(scene_t.get("singular_threshold", DEFAULT_THRESHOLD))
    if value is None or not 0 < value < 1:
        p.add(
            f"[scene]: singular_threshold must be in (0, 1), not "
            f"{shown(scene_t.get('singular_threshold'))}",
            "scene",
            0,
            "singular_threshold",
        )
        value, given = DEFAULT_THRESHOLD, False
    return Param(
        "singular_threshold",
        value,
        None,
        "Conditioning below which a dyad is reported singular (default sqrt(eps) = 1.49e-8)",
        {"min": 0.0, "max": 1.0, "min_exclusive": True, "max_exclusive": True},
        macro="" if given else "DYAD_DEFAULT_SINGULAR_THRESHOLD",
    )


def kinematics(p: Problems, scene_t: dict, driven: bool) -> str:
    """[scene] kinematics: "internal" (the default with a driver) or "external"."""
    value = scene_t.get("kinematics", "internal" if driven else "external")
    if value not in KINEMATICS:
        p.add(
            f"[scene]: kinematics must be 'internal' or 'external', not {shown(value)}",
            "scene",
            0,
            "kinematics",
        )
        return "external"
    if value == "internal" and not driven:
        p.add(
            "[scene]: kinematics = 'internal' needs a driver ([crank], [ram] or [cylinder]) whose "
            "motion "
            "the chain follows; without one every link's motion is an input ('external')",
            "scene",
            0,
            "kinematics",
        )
        return "external"
    return value


def dynamics(p: Problems, scene_t: dict, internal: bool, inertia: bool) -> str:
    """[scene] dynamics: "inverse" (the default: the drivers' motion in) or "forward"
    (their efforts in, the motion integrated), which needs the kinematics inside and
    the inertia."""
    value = scene_t.get("dynamics", "inverse")
    if value not in DYNAMICS:
        p.add(
            f"[scene]: dynamics must be 'inverse' or 'forward', not {shown(value)}",
            "scene",
            0,
            "dynamics",
        )
        return "inverse"
    if value == "forward" and not (internal and inertia):
        p.add(
            "[scene]: dynamics = 'forward' integrates the drivers' motion from their efforts: "
            "it needs kinematics = 'internal' (a driver) and [effects] inertia = true",
            "scene",
            0,
            "dynamics",
        )
        return "inverse"
    return value


def _pivot(p: Problems, driver: Crank, table: dict, section: str, text: str) -> None:
    """The driver's point on the frame, `at` (m, global; default the origin)."""
    at = pair_of_numbers(p, table, "at", f"[{section}]", section, driver.index, required=False)
    x, y = at if at is not None else (0.0, 0.0)
    name = driver.name
    driver.params["at.x"] = Param(f"{name}.at.x", x, "m", f"{text}, global x")
    driver.params["at.y"] = Param(f"{name}.at.y", y, "m", f"{text}, global y")


def _crank_params(
    p: Problems, crank: Crank, crank_t: dict, inertia: bool, needs_mass: bool
) -> None:
    cname = crank.name
    where = f"crank '{cname}'"
    length = number(p, crank_t, "length", where, "crank", crank.index, positive=True)
    if length is not None:
        crank.params["length"] = Param(
            f"{cname}.length",
            length,
            "m",
            "Crank radius |O A|: the crank pin A lies at (length, 0) in the crank frame",
            {"min": 0.0, "min_exclusive": True},
        )
    _crank_mass(p, crank, crank_t, "crank", inertia, needs_mass)


def _crank_mass(
    p: Problems, driver: Crank, table: dict, section: str, inertia: bool, needs_mass: bool
) -> None:
    """The mass, centre of mass (in its frame {O; i, j}) and inertia of a link turning
    about the frame pivot O: a crank, or the link a cylinder turns."""
    name = driver.name
    label = "Crank" if section == "crank" else f"Link {name}"
    frame = "crank frame {O; i_c, j_c}" if section == "crank" else f"frame of {name} {{O; i, j}}"
    where = f"{section} '{driver.driver_name()}'"
    i = driver.index
    com = pair_of_numbers(p, table, "com", where, section, i, required=needs_mass)
    if com is not None and needs_mass:
        driver.params["com.x"] = Param(
            f"{name}.com.x", com[0], "m", f"{label}'s centre of mass, x in the {frame}"
        )
        driver.params["com.y"] = Param(
            f"{name}.com.y",
            com[1],
            "m",
            f"{label}'s centre of mass, y in the {frame.split(' {')[0]}",
        )
    mass = number(p, table, "mass", where, section, i, nonnegative=True, required=needs_mass)
    if mass is not None and needs_mass:
        driver.params["mass"] = Param(f"{name}.mass", mass, "kg", f"{label}'s mass", {"min": 0.0})
    inert = number(p, table, "inertia", where, section, i, nonnegative=True, required=inertia)
    if inert is not None and inertia:
        driver.params["inertia"] = Param(
            f"{name}.inertia",
            inert,
            "kg.m2",
            f"{label}'s moment of inertia about its centre of mass",
            {"min": 0.0},
        )


def _driver_tables(p: Problems, data: dict, section: str, keys: set) -> list[tuple[dict, str, int]]:
    """The driver tables of a section ([crank], or [[crank]] for several), their keys
    checked: (table, name, index), the name the section's where it is left out or
    invalid."""
    found = data.get(section)
    if found is None:
        return []
    rows = found if isinstance(found, list) else [found]
    out = []
    for i, table in enumerate(rows):
        if not isinstance(table, dict):
            p.add(f"[{section}] must be a table", section, i)
            continue
        unknown_keys(p, table, keys, f"[{section}]", section, i)
        name = table.get("name", section)
        problem = name_problem(name)
        if problem:
            p.add(f"[{section}]: name {problem}", section, i, "name")
            name = section if len(rows) == 1 else f"{section}{i + 1}"
        out.append((table, name, i))
    return out


def crank(
    p: Problems, row: tuple[dict, str, int], inertia: bool, needs_mass: bool, internal: bool
) -> Crank:
    """A crank: its name and numbers (and its pivot, for internal kinematics)."""
    crank_t, cname, index = row
    found = Crank(cname, p.loc.line("crank", index), index=index)
    if internal:
        _pivot(p, found, crank_t, "crank", "The crank's pivot O on the frame")
    elif "at" in crank_t:
        p.add(
            "[crank]: 'at' places the crank for internal kinematics; with kinematics = "
            "'external' nothing reads it",
            "crank",
            index,
            "at",
        )
    _crank_params(p, found, crank_t, inertia, needs_mass)
    return found


def _ram_params(p: Problems, ram_t: dict, found: Crank, needs_mass: bool) -> None:
    name, i = found.name, found.index
    where = f"ram '{name}'"
    angle = number(p, ram_t, "guide", where, "ram", i)
    if angle is not None:
        found.params["guide"] = Param(
            f"{name}.guide",
            angle,
            "rad",
            "Direction of the ram's frame guide (angle of i_r from x)",
        )
    _pivot(p, found, ram_t, "ram", "The ram's origin R at zero displacement")
    com = pair_of_numbers(p, ram_t, "com", where, "ram", i, required=needs_mass)
    if com is not None and needs_mass:
        found.params["com.x"] = Param(
            f"{name}.com.x", com[0], "m", "Ram's centre of mass, x in the ram frame {R; i_r, j_r}"
        )
        found.params["com.y"] = Param(
            f"{name}.com.y", com[1], "m", "Ram's centre of mass, y in the ram frame"
        )
    mass = number(p, ram_t, "mass", where, "ram", i, nonnegative=True, required=needs_mass)
    if mass is not None and needs_mass:
        found.params["mass"] = Param(f"{name}.mass", mass, "kg", "Ram's mass", {"min": 0.0})
    number(p, ram_t, "inertia", where, "ram", i, nonnegative=True, required=False)


def ram(p: Problems, row: tuple[dict, str, int], needs_mass: bool, internal: bool) -> Crank | None:
    """A ram: a linear actuator sliding on a frame guide."""
    ram_t, name, index = row
    if not internal:
        p.add("[ram]: a ram drives the chain only with kinematics = 'internal'", "ram", index)
        return None
    found = Crank(name, p.loc.line("ram", index), kind="ram", index=index)
    _ram_params(p, ram_t, found, needs_mass)
    return found


def _part_number(
    p: Problems, part_t: dict, key: str, part: str, required: bool, index: int
) -> float | None:
    """A number of the cylinder's barrel or rod table (located at that table's line)."""
    where = f"[cylinder] {part}"
    if key not in part_t:
        if required:
            p.add(f"{where}: missing '{key}'", "cylinder", index, part)
        return None
    value = real(part_t[key])
    if value is None or (key != "com" and not value >= 0):
        what = "a finite number" if key == "com" else "a finite number, not negative"
        p.add(f"{where}: '{key}' must be {what}, not {shown(part_t[key])}", "cylinder", index, part)
        return None
    return value


_PART_TEXT = {
    "barrel": ("Barrel", "from A along the cylinder's axis towards B"),
    "rod": ("Rod (with its piston)", "from B along the cylinder's axis towards A"),
}


def _cylinder_part(p: Problems, table: dict, found: Crank, part: str, inertia: bool) -> None:
    """The barrel's or the rod's mass, centre of mass on the axis and inertia, where the
    table gives them (a part left out is massless)."""
    if part not in table:
        return
    part_t = table[part]
    if not isinstance(part_t, dict):
        p.add(
            f"[cylinder]: '{part}' must be a table {{ mass = ..., com = ..., inertia = ... }}",
            "cylinder",
            found.index,
            part,
        )
        return
    unknown = sorted(set(part_t) - CYLINDER_PART_KEYS)
    if unknown:
        p.add(
            f"[cylinder] {part}: unknown key '{textsafe.plain(str(unknown[0]))}' (known: "
            f"{', '.join(sorted(CYLINDER_PART_KEYS))})",
            "cylinder",
            found.index,
            part,
        )
    label, along = _PART_TEXT[part]
    name = f"{found.actuator}.{part}"
    mass = _part_number(p, part_t, "mass", part, True, found.index)
    com = _part_number(p, part_t, "com", part, True, found.index)
    inert = _part_number(p, part_t, "inertia", part, inertia, found.index)
    if mass is not None:
        found.params[f"{part}.mass"] = Param(
            f"{name}.mass", mass, "kg", f"{label}'s mass", {"min": 0.0}
        )
    if com is not None:
        found.params[f"{part}.com"] = Param(
            f"{name}.com", com, "m", f"{label}'s centre of mass on the axis, {along}"
        )
    if inert is not None and inertia:
        found.params[f"{part}.inertia"] = Param(
            f"{name}.inertia",
            inert,
            "kg.m2",
            f"{label}'s moment of inertia about its centre of mass",
            {"min": 0.0},
        )


def _cylinder_point(
    p: Problems, table: dict, key: str, found: Crank
) -> tuple[tuple[float, float], str | None] | None:
    """A cylinder's pin O (`at`) or A (`base`): [x, y] on the frame (global), or
    { link = NAME, at = [x, y] } on a driver's link (in its frame); (point, carrier)."""
    where, i = f"cylinder '{found.actuator}'", found.index
    value = table.get(key, [0.0, 0.0] if key == "at" else None)
    if not isinstance(value, dict):
        point = pair_of_numbers(
            p, {key: value} if value is not None else {}, key, where, "cylinder", i
        )
        return None if point is None else (point, None)
    carrier = value.get("link")
    extra = sorted(set(value) - {"link", "at"})
    if extra or not isinstance(carrier, str) or name_problem(carrier):
        p.add(
            f"{where}: '{key}' must be [x, y] (m, on the frame) or "
            f'{{ link = "NAME", at = [x, y] }} (m, a point of a driver\'s link in its frame)'
            + (f", not with '{textsafe.plain(str(extra[0]))}'" if extra else ""),
            "cylinder",
            i,
            key,
        )
        return None
    if carrier == "frame":
        point = pair_of_numbers(p, value, "at", f"{where} {key}", "cylinder", i)
        return None if point is None else (point, None)
    point = pair_of_numbers(p, value, "at", f"{where} {key}", "cylinder", i)
    return None if point is None else (point, carrier)


def _cylinder_geometry(p: Problems, table: dict, found: Crank) -> None:
    """The pins O and A (on the frame or a driver's link), the pin B in the link's frame
    and the branch."""
    name, link, i = found.actuator, found.name, found.index
    where = f"cylinder '{name}'"
    for key, prefix, text in (
        ("at", f"{link}.at", f"The pivot O of {link} on"),
        ("base", f"{name}.base", "The barrel's pin A on"),
    ):
        placed = _cylinder_point(p, table, key, found)
        if placed is None:
            continue
        point, carrier = placed
        if key == "at":
            found.pivot_on = carrier
        else:
            found.base_on = carrier
        on = "the frame, global" if carrier is None else f"{carrier}, in its frame"
        for axis, value in zip("xy", point, strict=True):
            found.params[f"{key}.{axis}"] = Param(
                f"{prefix}.{axis}", value, "m", f"{text} {on} {axis}"
            )
    pin = pair_of_numbers(p, table, "pin", where, "cylinder", i)
    if pin is not None and pin == (0.0, 0.0):
        p.add(f"{where}: 'pin' must not be O itself, [0, 0]", "cylinder", i, "pin")
    elif pin is not None:
        for axis, value in zip("xy", pin, strict=True):
            text = f"The rod's pin B on {link}, in {link}'s frame {axis}"
            found.params[f"pin.{axis}"] = Param(f"{name}.pin.{axis}", value, "m", text)
    branch = table.get("branch")
    if branch not in (1, -1) or isinstance(branch, bool):
        p.add(
            f"{where}: 'branch' must be 1 (B to the left of the line from O to A) or -1 "
            f"(to its right), not {shown(branch)}",
            "cylinder",
            i,
            "branch" if "branch" in table else None,
        )
        branch = 1
    found.params["branch"] = Param(
        f"{name}.branch",
        float(branch),
        None,
        "Assembly branch of the cylinder's triangle O, A, B: +1 puts B to the left of the "
        "line from O to A, -1 to its right",
    )


def cylinder(
    p: Problems, row: tuple[dict, str, int], inertia: bool, needs_mass: bool, internal: bool
) -> Crank | None:
    """A hydraulic cylinder between the frame pin A and the pin B of a link that it turns
    about the frame pivot O."""
    table, name, index = row
    if not internal:
        p.add(
            "[cylinder]: a cylinder drives the chain only with kinematics = 'internal'",
            "cylinder",
            index,
        )
        return None
    link = table.get("link")
    problem = name_problem(link) if isinstance(link, str) else "must be a name (a string)"
    if link is None:
        problem = "is missing: the name of the link the cylinder turns"
    if problem:
        key = "link" if link is not None else None
        p.add(f"[cylinder]: link {problem}", "cylinder", index, key)
        link = f"{name}_link"
    if link == name:
        p.add(
            f"[cylinder]: the link and the cylinder need names of their own, not both '{name}'",
            "cylinder",
            index,
            "link",
        )
    found = Crank(link, p.loc.line("cylinder", index), kind="cylinder", actuator=name, index=index)
    _cylinder_geometry(p, table, found)
    _crank_mass(p, found, table, "cylinder", inertia, needs_mass)
    for part in ("barrel", "rod"):
        _cylinder_part(p, table, found, part, inertia)
    return found


def drivers(
    p: Problems, data: dict, inertia: bool, needs_mass: bool, internal: bool
) -> list[Crank]:
    """Every driver of the scene: its cranks, rams and cylinders, each kind in file order.
    Several drivers solve their chain's kinematics inside (kinematics = 'internal')."""
    rows = {
        "crank": _driver_tables(p, data, "crank", CRANK_KEYS),
        "ram": _driver_tables(p, data, "ram", RAM_KEYS),
        "cylinder": _driver_tables(p, data, "cylinder", CYLINDER_KEYS),
    }
    if sum(len(found) for found in rows.values()) > 1 and not internal:
        p.add(
            "[scene]: several drivers move the chain only with kinematics = 'internal'",
            "scene",
            0,
            "kinematics",
        )
        internal = True  # read on as they are meant, so that nothing else is told
    found = [crank(p, row, inertia, needs_mass, internal) for row in rows["crank"]]
    found += [ram(p, row, needs_mass, internal) for row in rows["ram"]]
    found += [cylinder(p, row, inertia, needs_mass, internal) for row in rows["cylinder"]]
    kept = _distinct([d for d in found if d is not None], p)
    _carriers_checked(p, kept)
    return kept


def _carriers_checked(p: Problems, drivers: list[Crank]) -> None:
    """A cylinder's pins sit on the frame or on an earlier driver's link (whose motion is
    known before its own), never on the link it turns."""
    earlier: set[str] = set()
    for driver in drivers:
        for key, carrier in (("at", driver.pivot_on), ("base", driver.base_on)):
            if carrier is None or carrier in earlier:
                continue
            where = f"cylinder '{driver.actuator}'"
            if carrier == driver.name:
                why = (
                    f"is on '{carrier}', the link the cylinder turns: a cylinder pinned to "
                    "it cannot turn it"
                )
            else:
                known = ", ".join(sorted(earlier)) or "none"
                why = (
                    f"names '{carrier}', which is no earlier driver's link (the frame or a "
                    f"crank's, a ram's or an earlier cylinder's link: {known})"
                )
            p.add(f"{where}: '{key}' {why}", "cylinder", driver.index, key)
        earlier.add(driver.name)


def _distinct(found: list[Crank], p: Problems) -> list[Crank]:
    """The drivers whose names (a cylinder's and its link's) no earlier driver has: two
    drivers of one link would over-determine its motion."""
    seen: dict[str, Crank] = {}
    kept = []
    for driver in found:
        names = [driver.name] + ([driver.actuator] if driver.actuator else [])
        clash = next((n for n in names if n in seen), None)
        if clash is None:
            seen.update((n, driver) for n in names)
            kept.append(driver)
            continue
        other = seen[clash]
        what = (
            "is driven twice" if driver.is_cylinder() or other.is_cylinder() else "is named twice"
        )
        p.add(
            f"{driver.kind} '{driver.driver_name()}': '{clash}' {what}: {other.kind} "
            f"'{other.driver_name()}' (line {other.line}) has that name too",
            driver.kind,
            driver.index,
            "link" if driver.is_cylinder() and clash == driver.name else "name",
        )
    return kept


def loads(p: Problems, data: dict, links: dict, known: set) -> None:
    """[loads]: the links an active force or moment acts on (an input each). A link of
    `known` that is not in `links` (its table or its dyad was refused) is not told
    again."""
    loads_t = data.get("loads", {})
    if not isinstance(loads_t, dict):
        p.add("[loads] must be a table", "loads", 0)
        loads_t = {}
    unknown_keys(p, loads_t, LOAD_KEYS, "[loads]", "loads", 0)
    for key in LOAD_KEYS:
        value = loads_t.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            p.add(f"[loads]: '{key}' must be a list of link names", "loads", 0, key)
            continue
        for lname in value:
            if lname not in links and lname in known:
                continue
            if lname not in links:
                p.add(
                    f"[loads]: {key} on unknown link '{lname}' (links: "
                    f"{', '.join(links) or 'none'})",
                    "loads",
                    0,
                    key,
                )
            elif getattr(links[lname], key):
                p.add(f"[loads]: {key} on '{lname}' is listed twice", "loads", 0, key)
            else:
                setattr(links[lname], key, True)


def _told(p: Problems, entry: str, tables_of: dict, scene: Scene) -> bool:
    """Whether a tunable entry that names no parameter names one of an object whose table
    had a problem (a value refused there: [gravity] y = nan, a link refused)."""
    head = entry.split(".")[0]
    tables = dict(tables_of, gravity=("gravity", 0))
    for driver in scene.drivers:
        tables[driver.name] = (driver.kind, driver.index)
    return head in tables and tables[head] in p.troubled


def tunable(p: Problems, scene_t: dict, scene: Scene, tables_of: dict) -> None:
    """[scene] tunable: the parameters that stay FMU parameters (all others are baked).
    `tables_of`: the link and dyad names -> (section, index) of their tables."""
    entries = scene_t.get("tunable", [])
    params = {prm.name: prm for prm in scene.parameters()}
    if not isinstance(entries, list) or not all(isinstance(t, str) for t in entries):
        p.add("[scene]: tunable must be a list of parameter names", "scene", 0, "tunable")
        entries = []
    for entry in entries:
        if entry == "all":
            chosen = list(params)
        else:
            chosen = [n for n in params if n == entry or n.startswith(entry + ".")]
        if not chosen and not _told(p, entry, tables_of, scene):
            p.add(
                f"[scene]: tunable '{entry}' is no parameter of this scene (parameters: "
                f"{', '.join(params)})",
                "scene",
                0,
                "tunable",
            )
        for n in chosen:
            params[n].tunable = True
            params[n].member = member(n)


def outputs(p: Problems, scene_t: dict) -> list[str] | None:
    """[scene] outputs: the names of the wanted outputs, or None where it is malformed."""
    wanted = scene_t.get("outputs")
    if wanted is None:
        p.add(
            '[scene]: missing \'outputs\' (a list such as ["all"] or ["ram.R_np", "crank.torque"])',
            "scene",
            0,
        )
        return None
    if not isinstance(wanted, list) or not all(isinstance(w, str) for w in wanted) or not wanted:
        p.add("[scene]: outputs must be a non-empty list of output names", "scene", 0, "outputs")
        return None
    return wanted


def starts(p: Problems, scene: Scene, starts_t: object, candidates: set) -> None:
    """[start]: start values of inputs (default 0, and 1 m for a sliding length). A start
    value of an input the scene's outputs turned out not to need is ignored."""
    if not isinstance(starts_t, dict):
        p.add("[start] must be a table of input names and values", "start", 0)
        return
    by_name = {i.name: i for i in scene.inputs}
    for name, value in starts_t.items():
        target = by_name.get(name)
        if target is None and name in candidates:
            continue
        if target is None:
            p.add(
                f"[start]: '{name}' is no input of this scene (inputs: {', '.join(by_name)})",
                "start",
                0,
                name,
            )
            continue
        found = real(value)
        if found is None:
            p.add(
                f"[start]: '{name}' must be a finite number (within the range of a double), "
                f"not {shown(value)}",
                "start",
                0,
                name,
            )
            continue
        if "min" in target.domain and not found > target.domain["min"]:
            p.add(f"[start]: '{name}' must be positive, not {shown(value)}", "start", 0, name)
            continue
        target.start = found


def motors(p: Problems, data: dict, drivers: list[Crank], forward: bool) -> list[Motor]:
    """[motor] or [[motor]]: a DC motor at a crank of a forward scene, each crank one at
    most."""
    tables = data.get("motor")
    if tables is None:
        return []
    rows = tables if isinstance(tables, list) else [tables]
    if not forward:
        p.add("[motor]: a motor drives a plant: it needs [scene] dynamics = 'forward'", "motor", 0)
        return []
    cranks = [d.name for d in drivers if d.kind == "crank"]
    found: list[Motor] = []
    for i, table in enumerate(rows):
        if not isinstance(table, dict):
            p.add("[motor] must be a table", "motor", i)
            continue
        unknown_keys(p, table, MOTOR_KEYS, "[motor]", "motor", i)
        driver = table.get("driver", cranks[0] if len(cranks) == 1 else None)
        if driver not in cranks:
            p.add(
                f"[motor]: 'driver' must name a crank of the scene ({', '.join(cranks) or 'none'}),"
                f" not {shown(driver)}",
                "motor",
                i,
                "driver" if "driver" in table else None,
            )
            continue
        if any(m.driver == driver for m in found):
            p.add(f"[motor]: crank '{driver}' has a motor already", "motor", i, "driver")
            continue
        numbers = {}
        for key, (_, _, default, least, strict) in MOTOR_NUMBERS.items():
            if key not in table and default is not None:
                numbers[key] = default
                continue
            value = number(
                p,
                table,
                key,
                f"motor of '{driver}'",
                "motor",
                i,
                positive=least == 0.0 and strict,
                nonnegative=least == 0.0 and not strict,
            )
            numbers[key] = value if value is not None else 1.0
        if numbers["inductance"] == 0 and "current" in table:
            p.add(
                f"[motor]: the motor of '{driver}' has no inductance, so its current is no "
                "state and has no start value: leave 'current' out",
                "motor",
                i,
                "current",
            )
            continue
        found.append(Motor(driver, p.loc.line("motor", i), numbers))
    return found

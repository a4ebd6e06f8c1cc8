"""[[load]]: loads where they act. Each names a link (any moving link, the driver
included), the point it acts at in that link's frame (default the centre of mass),
whether its force's components are global or the link's own (a follower force turns
with its link), and whether it has a force, a pure moment or both. Its inputs are
NAME.force.x, NAME.force.y (N) and NAME.moment (N.m); its point is the parameters
NAME.at.x, NAME.at.y (m), tunable like any other."""

from __future__ import annotations

from dyadgen.model import Crank, Param, PointLoad
from dyadgen.scenefile.names import name_problem
from dyadgen.scenefile.problems import Problems, real, shown, unknown_keys

POINT_LOAD_KEYS = {"name", "link", "at", "components", "force", "moment"}
COMPONENTS = ("global", "link")
#: A point farther than this from its link's origin (m) is a typing error, not a machine.
MAX_AT = 1.0e4
#: Names an input of a load's prefix would shadow: the scene's own variables.
RESERVED = {"gravity", "singular_threshold", "amplification", "status"}


def _raw_com(data: dict, drivers: list[Crank], link: str) -> tuple[float, float] | None:
    """The centre of mass a link's table gives (m, its frame), where it is valid."""
    driver = next((d for d in drivers if d.name == link), None)
    if driver is not None:
        table = data.get(driver.kind, {})
        if isinstance(table, list):  # [[crank]]: one of several
            table = table[driver.index]
    else:
        rows = data.get("link", [])
        found = [r for r in rows if isinstance(r, dict) and r.get("name") == link]
        table = found[0] if found else {}
    com = table.get("com") if isinstance(table, dict) else None
    if isinstance(com, list) and len(com) == 2 and all(real(v) is not None for v in com):
        return real(com[0]), real(com[1])
    return None


class _Reading:
    """The parse of the [[load]] tables, one by one."""

    def __init__(self, p: Problems, data: dict, drivers: list[Crank], names: set) -> None:
        self.p, self.data, self.drivers = p, data, drivers
        self.taken = set(names) | RESERVED  # the scene's other names
        self.seen: dict[str, int] = {}  # load name -> its table

    def name(self, i: int, row: dict) -> str | None:
        """The load's name: an identifier, neither another load's nor another object's."""
        name = row.get("name")
        problem = "is missing" if name is None else name_problem(name)
        if problem:
            self.p.add(f"load #{i + 1}: name {problem}", "load", i, "name" if name else None)
            return None
        if name in self.seen:
            also = self.p.loc.line("load", self.seen[name])
            self.p.add(f"load '{name}' is described twice (also line {also})", "load", i, "name")
            return None
        if name in self.taken:
            self.p.add(
                f"load '{name}': the name is already the scene's (a link, dyad, driver or "
                "a variable of the scene); the load's inputs would clash with its variables",
                "load",
                i,
                "name",
            )
            return None
        self.seen[name] = i
        return name

    def link(self, i: int, row: dict, name: str, links: dict) -> str | None:
        """The loaded link: a dyad's link or a driver's."""
        link = row.get("link")
        driven = [d.name for d in self.drivers]
        if link in driven or link in links:
            return link
        known = driven + list(links)
        self.p.add(
            f"load '{name}': on unknown link {shown(link)} (links: {', '.join(known) or 'none'})",
            "load",
            i,
            "link" if "link" in row else None,
        )
        return None

    def at(self, i: int, row: dict, name: str, link: str) -> tuple[float, float] | None:
        """The point it acts at, in the link's frame (m); default the centre of mass."""
        if "at" not in row:
            com = _raw_com(self.data, self.drivers, link)
            if com is None:
                self.p.add(
                    f"load '{name}': '{link}' has no centre of mass to default to: "
                    "give at = [x, y] (m, in the link's frame)",
                    "load",
                    i,
                )
            return com
        value = row["at"]
        ok = isinstance(value, list) and len(value) == 2
        ok = ok and all(real(v) is not None and abs(real(v)) <= MAX_AT for v in value)
        if not ok:
            self.p.add(
                f"load '{name}': 'at' must be [x, y], two finite numbers (m) within "
                f"{MAX_AT:g} m of the link's origin, not {shown(value)}",
                "load",
                i,
                "at",
            )
            return None
        return real(value[0]), real(value[1])

    def flags(self, i: int, row: dict, name: str) -> tuple[str, bool, bool] | None:
        """components, and whether the load has a force and a moment."""
        components = row.get("components", "global")
        if components not in COMPONENTS:
            self.p.add(
                f"load '{name}': components must be 'global' or 'link', not {shown(components)}",
                "load",
                i,
                "components",
            )
            return None
        force, moment = row.get("force", True), row.get("moment", False)
        for key, value in (("force", force), ("moment", moment)):
            if not isinstance(value, bool):
                self.p.add(
                    f"load '{name}': '{key}' must be true or false, not {shown(value)}",
                    "load",
                    i,
                    key,
                )
                return None
        if not force and not moment:
            self.p.add(f"load '{name}': neither a force nor a moment", "load", i)
            return None
        if components == "link" and not force:
            self.p.add(f"load '{name}': components = 'link' needs a force", "load", i)
            return None
        return components, force, moment

    def row(self, i: int, row: dict, links: dict) -> PointLoad | None:
        """One [[load]] table."""
        unknown_keys(self.p, row, POINT_LOAD_KEYS, f"load #{i + 1}", "load", i)
        name = self.name(i, row)
        link = None if name is None else self.link(i, row, name, links)
        at = None if link is None else self.at(i, row, name, link)
        flags = None if at is None else self.flags(i, row, name)
        if flags is None:
            return None
        frame = f"{link}'s frame"
        params = (
            Param(f"{name}.at.x", at[0], "m", f"Point of load {name}: x in the {frame}"),
            Param(f"{name}.at.y", at[1], "m", f"Point of load {name}: y in the {frame}"),
        )
        line = self.p.loc.line("load", i)
        return PointLoad(name, link, params, flags[0], flags[1], flags[2], line)


def point_loads(
    p: Problems, data: dict, drivers: list[Crank], links: dict, names: set
) -> list[PointLoad]:
    """The [[load]] tables, checked; `names` are the scene's other names (links, dyads,
    driver, identifier), which a load's name may not take."""
    rows = data.get("load", [])
    if not isinstance(rows, list):
        p.add("[[load]] must be an array of tables", "load", 0)
        return []
    reading = _Reading(p, data, drivers, names)
    found = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            p.add(f"load #{i + 1} must be a table", "load", i)
            continue
        load = reading.row(i, row, links)
        if load is not None:
            found.append(load)
    return found

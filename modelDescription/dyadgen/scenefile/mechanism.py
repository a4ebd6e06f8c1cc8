"""The parsers of a scene's mechanism: the [[link]] tables, the [[dyad]] tables with the
attachments of their outer pairs k and p, and each link's numbers."""

from __future__ import annotations

from dyadgen.dyadtypes import MAY_BE_ZERO, PAIRS, TYPES
from dyadgen.model import Attachment, Crank, Dyad, Link, Param
from dyadgen.scenefile.names import name_problem
from dyadgen.scenefile.problems import Problems, number, pair_of_numbers, real, shown, unknown_keys

DYAD_KEYS = {"name", "type", "m", "n", "k", "p", "branch"}
LINK_KEYS = {"name", "length", "angle", "turn", "com", "mass", "inertia"}
#: the types that close in two ways, so that the scene says which
TWO_BRANCHES = ("RRR", "RRT", "RTR")
ATTACHMENT_KEYS = ("link", "at", "guide")
#: The most dyads in one chain: a dyad and every dyad it hangs on, directly or through
#: others. Each output of a dyad depends on the inputs of every dyad that hangs on it,
#: and the model descriptions list those dependencies one by one (FMI has no shorter
#: form for them), so they grow as dyads x chain length: a chain of 1,000 dyads wrote
#: model descriptions of 162 MB each. Within the limit, checking and generating a scene
#: grow linearly with its dyads.
MAX_CHAIN = 200


def driver_text(driver: Crank) -> str:
    """A driver's moving link in words: "the crank", "ram 'r'", "the link of cylinder 'c'"."""
    if driver.is_cylinder():
        return f"the link of cylinder '{driver.actuator}'"
    return "the crank" if driver.kind == "crank" else f"{driver.kind} '{driver.name}'"


def link_tables(
    p: Problems, data: dict, drivers: list[Crank], refused: dict[str, int]
) -> dict[str, tuple[dict, int]]:
    """The [[link]] tables by name (tables first, so that dyads can refer to them); the
    index of each table whose name is refused goes to `refused`, by that name, so that
    what refers to it is not refused again."""
    tables: dict[str, tuple[dict, int]] = {}
    rows = data.get("link", [])
    if not isinstance(rows, list):
        p.add("[[link]] must be an array of tables", "link", 0)
        rows = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            continue
        name = row.get("name")
        label = f"link '{name}'" if isinstance(name, str) else f"link #{i + 1}"
        unknown_keys(p, row, LINK_KEYS, label, "link", i)
        problem = name_problem(name)
        if problem:
            p.add(f"link #{i + 1}: name {problem}", "link", i, "name")
            if isinstance(name, str):
                refused.setdefault(name, i)
        elif name in tables:
            also = p.loc.line("link", tables[name][1])
            p.add(f"link '{name}' is described twice (also line {also})", "link", i, "name")
        elif any(name == d.name for d in drivers):
            driver = next(d for d in drivers if d.name == name)
            p.add(f"link '{name}' has the name of {driver_text(driver)}", "link", i, "name")
        else:
            tables[name] = (row, i)
    return tables


class _Attaching:
    """The parse of one outer pair's attachment (k at D_m, or p at D_n) of a dyad."""

    def __init__(
        self, p: Problems, dyad: Dyad, side: str, label: str, drivers: list[Crank], internal: bool
    ) -> None:
        self.p = p
        self.internal = internal
        self.side = side
        self.pair = "D_m" if side == "k" else "D_n"
        self.sliding = dyad.pair_kind("mk" if side == "k" else "np") == "T"
        self.label = label
        self.index = dyad.index
        self.prefix = dyad.prefix()
        self.drivers = {d.name: d for d in drivers}

    def problem(self, message: str, key: bool = True) -> None:
        if key:
            self.p.add(f"{self.label}: {message}", "dyad", self.index, self.side)
        else:
            self.p.add(f"{self.label}: {message}", "dyad", self.index)

    def spec(self, spec: object) -> dict | None:
        """The attachment as a table (a bare name is its link), its keys checked."""
        if spec is None:
            self.problem(
                f"missing '{self.side}', the external link at {self.pair} ('frame', "
                f"'external', the crank's name or {{ link = ..., at = [x, y] }})",
                key=False,
            )
            return None
        if isinstance(spec, str):
            spec = {"link": spec}
        if not isinstance(spec, dict):
            self.problem(f"'{self.side}' must be a link name or a table")
            return None
        for key in spec:
            if key not in ATTACHMENT_KEYS:
                self.problem(f"'{self.side}' has unknown key '{key}' (expected link, at, guide)")
                return None
        return spec

    def target(self, spec: dict, links: dict) -> str | None:
        """The link the pair is on, if it is one the dyad may hang on."""
        target = spec.get("link")
        if not isinstance(target, str):
            self.problem(f"'{self.side}' needs link = <name>")
            return None
        moving = target in self.drivers or target in links
        if target not in ("frame", "external") and not moving:
            later = (
                " (a link of a later dyad or of this one: dyads are listed from the crank outwards)"
                if target
                else ""
            )
            self.problem(
                f"'{self.side}' names unknown link {target!r}{later}; expected 'frame', "
                f"'external'{', a driver' if self.drivers else ''} or a link of an earlier dyad"
            )
            return None
        return target

    def parse(self, spec: object, links: dict) -> Attachment | None:
        """The attachment, or None (and a problem)."""
        spec = self.spec(spec)
        target = None if spec is None else self.target(spec, links)
        if target is None:
            return None
        if not self.sliding and "guide" in spec:
            self.problem(f"{self.pair} is a revolute pair and has no guide")
            return None
        if target == "frame" and self.internal:
            return self.on_frame(spec)
        if target in ("frame", "external") and "at" in spec:
            self.problem(f"'{self.side}': a pair on the {target} takes no 'at'")
            return None
        if target == "external":
            if self.internal:
                self.problem(
                    f"'{self.side}': with kinematics = 'internal' every link's motion follows "
                    "from the driver's; an external link needs kinematics = 'external'"
                )
                return None
            if "guide" in spec:
                self.problem(f"'{self.side}': an external link's guide is an input; drop 'guide'")
                return None
            return Attachment("external")
        if target == "frame" and not self.sliding:
            return Attachment("frame")
        kind = "frame" if target == "frame" else "crank" if target in self.drivers else "link"
        guide = None
        if self.sliding:
            guide = self.guide(spec, target, kind)
            if guide is None:
                return None
            if kind == "frame":
                return Attachment("frame", guide=guide)
        return self.point(spec, target, kind, guide)

    def on_frame(self, spec: dict) -> Attachment | None:
        """Internal kinematics: a fixed pivot where it is, or a frame guide and a point of
        its line (default the origin), global."""
        guide = self.guide(spec, "frame", "frame") if self.sliding else None
        if self.sliding and guide is None:
            return None
        at = spec.get("at", [0.0, 0.0] if self.sliding else None)
        if at is None:
            self.problem(
                f"{self.pair} is a fixed pivot: with kinematics = 'internal' '{self.side}' "
                f'says where it is, {self.side} = {{ link = "frame", at = [x, y] }} (m)'
            )
            return None
        what = (
            f"A point of the frame guide at {self.pair}"
            if self.sliding
            else f"The fixed pivot {self.pair}"
        )
        point = self.point_params(at, what, None)
        return None if point is None else Attachment("frame", None, point, guide)

    def point_params(
        self, at: object, what: str, carrier: str | None
    ) -> tuple[Param, Param] | None:
        """`at` checked, as the two parameters of the pair's point (for a sliding pair a
        point of its guide), described as `what`: global on the frame (`carrier` None),
        else in the carrier's frame."""
        if not isinstance(at, list) or len(at) != 2 or not all(real(v) is not None for v in at):
            self.problem(f"'{self.side}': at must be [x, y], two finite numbers (m)")
            return None
        pname = (
            f"{self.prefix}guide_{self.side}.at" if self.sliding else f"{self.prefix}{self.pair}"
        )
        x, y = real(at[0]), real(at[1])
        if carrier is None:
            return (
                Param(f"{pname}.x", x, "m", f"{what}, global x"),
                Param(f"{pname}.y", y, "m", f"{what}, global y"),
            )
        frame = f"{carrier}'s frame"
        return (
            Param(f"{pname}.x", x, "m", f"{what}: x in the {frame}"),
            Param(f"{pname}.y", y, "m", f"{what}: y in the {frame}"),
        )

    def guide(self, spec: dict, target: str, kind: str) -> Param | None:
        """The angle of the guide a sliding pair runs on, on the frame or a moving link."""
        angle = spec.get("guide")
        side, pair = self.side, self.pair
        if real(angle) is None:
            on = "the frame" if kind == "frame" else f"'{target}'"
            example = "0.0" if kind == "frame" else "0.0, at = [0.0, 0.0]"
            self.problem(
                f"{pair} slides on {on}: '{side}' needs guide = <angle in rad> "
                f'(e.g. {side} = {{ link = "{target}", guide = {example} }})'
            )
            return None
        if kind == "frame":
            text = f"Direction of the frame guide at {pair} (angle of i_{side} from x)"
        else:
            text = (
                f"Direction of the guide at {pair} on {target}: angle of i_{side} from {target}'s i"
            )
        return Param(f"{self.prefix}guide_{side}.angle", real(angle), "rad", text)

    def point(self, spec: dict, target: str, kind: str, guide: Param | None) -> Attachment | None:
        """The pair's point on a moving link (for a sliding pair: a point of its guide)."""
        at = spec.get("at")
        if at is None:
            if self.sliding:
                at = [0.0, 0.0]  # the guide passes through the carrier's D (O)
            elif kind == "crank":
                return Attachment("crank", target)  # the crank's pin, a ram's R, a cylinder's B
            else:
                self.problem(
                    f"'{self.side}' on link '{target}' needs at = [x, y], the pair's point "
                    f"in that link's frame (m)"
                )
                return None
        what = (
            f"A point of the guide at {self.pair} on {target}"
            if self.sliding
            else f"Pair {self.pair} on {target}"
        )
        point = self.point_params(at, what, target)
        return None if point is None else Attachment(kind, target, point, guide)


class Mechanism:
    """The [[dyad]] tables parsed in order: the dyads, their links, and which dyad owns
    each link name."""

    def __init__(
        self,
        p: Problems,
        drivers: list[Crank],
        tables: dict,
        internal: bool,
        refused: dict[str, int] | None = None,
    ) -> None:
        self.p = p
        self.drivers = drivers
        self.internal = internal
        self.tables = tables
        self.refused = refused or {}  # link name -> its table, whose name was refused
        self.dyads: list[Dyad] = []
        self.links: dict[str, Link] = {}
        self.owner: dict[str, str] = {}  # link name -> "dyad 'x' as m"
        self.names_seen: set = set()
        #: each dyad's chain (the indices of the dyad and of every dyad it hangs on); None
        #: once a chain is refused, so that no later dyad is told again
        self.chains: dict[int, frozenset] | None = {}

    def parse(self, data: dict) -> None:
        """Every [[dyad]] table."""
        rows = data.get("dyad", [])
        cylinder = any(d.is_cylinder() for d in self.drivers)
        if not isinstance(rows, list) or not (rows or cylinder):
            # a cylinder and the link it turns are a mechanism of their own (a tipper body)
            self.p.add(
                "no [[dyad]] tables: a scene has at least one dyad (or a [cylinder])",
                "scene",
                0,
            )
            rows = []
        for i, row in enumerate(rows):
            if not isinstance(row, dict):
                self.p.add(f"dyad #{i + 1} must be a table", "dyad", i)
                continue
            self.dyad(i, row, several=len(rows) > 1)

    def name(self, i: int, row: dict, several: bool) -> str:
        """The dyad's name (a stand-in where it is invalid)."""
        p = self.p
        unknown_keys(p, row, DYAD_KEYS, f"dyad #{i + 1}", "dyad", i)
        name = row.get("name", "")
        if name == "" and several:
            p.add(f"dyad #{i + 1}: a scene with several dyads must name each one", "dyad", i)
        elif name != "" and name_problem(name):
            p.add(f"dyad #{i + 1}: name {name_problem(name)}", "dyad", i, "name")
            name = f"dyad{i + 1}"
        elif name in self.names_seen:
            p.add(f"dyad '{name}' is named twice", "dyad", i, "name")
        self.names_seen.add(name)
        return name

    def dyad(self, i: int, row: dict, several: bool) -> None:
        """One [[dyad]] table."""
        name = self.name(i, row, several)
        label = f"dyad '{name}'" if name else f"dyad #{i + 1}"
        dtype = row.get("type")
        if dtype not in TYPES:
            self.p.add(
                f"{label}: unknown dyad type {dtype!r} (expected one of {', '.join(TYPES)})",
                "dyad",
                i,
                "type",
            )
            for side in ("m", "n"):  # its links are not orphans
                if isinstance(row.get(side), str):
                    self.owner.setdefault(row[side], f"link {side} of {label}")
            return
        dyad = Dyad(name, dtype, i, self.p.loc.line("dyad", i), internal=self.internal)
        if not all([self.link(dyad, row, side, label) for side in ("m", "n")]):
            return
        for side in ("k", "p"):
            attaching = _Attaching(self.p, dyad, side, label, self.drivers, self.internal)
            setattr(dyad, side, attaching.parse(row.get(side, None), self.links))
        if dyad.k is None or dyad.p is None:
            return
        if self.internal and dyad.k.kind == dyad.p.kind == "frame":
            self.p.add(
                f"{label}: both its outer pairs are on the frame, so that no driver moves its "
                "links; attach k or p to a driver or to a link of an earlier dyad",
                "dyad",
                dyad.index,
            )
        dyad.branch = self.branch(dyad, row, label)
        d_m, e, d_n = PAIRS[dtype]
        for side, outer, attached in (("m", d_m, dyad.k), ("n", d_n, dyad.p)):
            lname = getattr(dyad, side)
            translating = outer == "T" and attached.kind == "frame"
            sliding = side == "m" and e == "T"
            line = self.p.loc.line("link", self.tables[lname][1])
            self.links[lname] = Link(lname, dyad, side, line, sliding, translating)
        self.dyads.append(dyad)
        self.chain(dyad, label)

    def chain(self, dyad: Dyad, label: str) -> None:
        """Records the dyad's chain, refused past MAX_CHAIN dyads (the first such dyad only)."""
        if self.chains is None:
            return
        chain = {dyad.index}
        for attached in (dyad.k, dyad.p):
            if attached is not None and attached.kind == "link" and attached.link in self.links:
                chain |= self.chains.get(self.links[attached.link].dyad.index, frozenset())
        if len(chain) > MAX_CHAIN:
            self.p.add(
                f"{label} hangs, directly or through other dyads, on {len(chain) - 1} dyads: "
                f"a chain of {len(chain)}, and a chain has at most {MAX_CHAIN} (the model "
                "descriptions list every output's dependency on every input of the dyads "
                "hanging on it, which grows as dyads x chain length)",
                "dyad",
                dyad.index,
            )
            self.chains = None
            return
        self.chains[dyad.index] = frozenset(chain)

    def branch(self, dyad: Dyad, row: dict, label: str) -> Param | None:
        """The assembly branch of a dyad that closes in two ways (internal kinematics)."""
        value = row.get("branch")
        closes_twice = dyad.type in TWO_BRANCHES
        if not self.internal or not closes_twice:
            if value is not None:
                why = (
                    "only internal kinematics read it"
                    if closes_twice
                    else f"a {dyad.type} dyad closes in one way only"
                )
                self.p.add(f"{label}: drop 'branch': {why}", "dyad", dyad.index, "branch")
            return None
        if value is None and dyad.type != "RTR":
            self.p.add(
                f"{label}: an {dyad.type} dyad closes in two ways: say which with branch = 1 "
                "or -1 (see modelDescription/scenes/README.md)",
                "dyad",
                dyad.index,
            )
            return None
        if value is None:
            value = 1
        if isinstance(value, bool) or value not in (1, -1):
            self.p.add(
                f"{label}: branch must be 1 or -1, not {shown(value)}", "dyad", dyad.index, "branch"
            )
            return None
        return Param(
            f"{dyad.prefix()}branch",
            float(value),
            None,
            f"Assembly branch of {dyad.name or 'the dyad'}: +1 or -1 (only the sign counts)",
        )

    def tables_of_names(self, rows: object) -> dict[str, tuple[str, int]]:
        """Every name a link or dyad table was given (valid or refused) -> (section,
        index) of its table: where a later check looks for a problem already told."""
        found = {name: ("link", i) for name, i in self.refused.items()}
        found.update({name: ("link", i) for name, (_, i) in self.tables.items()})
        for i, row in enumerate(rows if isinstance(rows, list) else []):
            name = row.get("name") if isinstance(row, dict) else None
            if isinstance(name, str):
                found.setdefault(name, ("dyad", i))
        return found

    def known(self) -> set[str]:
        """The link names the scene describes or connects, valid or refused: a later
        check refers to one of those without telling a problem of its own."""
        return set(self.tables) | set(self.owner) | set(self.refused)

    def link_numbers(self, inertia: bool, needs_mass: bool) -> None:
        """Every described link's numbers; a link of no dyad is a problem."""
        for lname, (row, i) in self.tables.items():
            if lname in self.links:
                link_params(self.p, self.links[lname], row, i, inertia, needs_mass)
            elif lname not in self.owner:
                self.p.add(f"link '{lname}' belongs to no dyad", "link", i)

    def link(self, dyad: Dyad, row: dict, side: str, label: str) -> bool:
        """Link m or n of a dyad: whether it names a described link no other dyad has."""
        p, i = self.p, dyad.index
        lname = row.get(side)
        if not isinstance(lname, str):
            p.add(f"{label}: missing link '{side}' (the name of its link {side})", "dyad", i)
            return False
        if lname in self.owner:
            p.add(
                f"{label}: link '{lname}' is connected twice: it is already {self.owner[lname]}",
                "dyad",
                i,
                side,
            )
            return False
        driver = next((d for d in self.drivers if d.name == lname), None)
        if driver is not None:
            p.add(
                f"{label}: link '{lname}' is {driver_text(driver)}, which no dyad may contain",
                "dyad",
                i,
                side,
            )
            return False
        if lname in self.refused:  # its table's name was refused there
            return False
        if lname not in self.tables:
            p.add(
                f"{label}: link '{lname}' has no [[link]] table (its length, centre of "
                "mass, mass and inertia)",
                "dyad",
                i,
                side,
            )
            return False
        self.owner[lname] = f"link {side} of {label}"
        setattr(dyad, side, lname)
        return True


def _length_and_angle(p: Problems, link: Link, row: dict, i: int) -> None:
    where = f"link '{link.name}'"
    may_be_zero = MAY_BE_ZERO[link.dyad.type]["mn".index(link.side)]
    if link.sliding:
        if "length" in row:
            p.add(
                f"{where}: its length varies (pair E of the {link.dyad.type} dyad slides "
                f"along it), so it is an input, not a parameter; drop 'length'",
                "link",
                i,
                "length",
            )
    else:
        length = number(
            p, row, "length", where, "link", i, nonnegative=may_be_zero, positive=not may_be_zero
        )
        if length is not None:
            text = "may be 0" if may_be_zero else "positive"
            link.params["length"] = Param(
                f"{link.name}.length",
                length,
                "m",
                f"Length |D E| of link {link.name} ({text})",
                {"min": 0.0, "min_exclusive": not may_be_zero},
            )
    if link.translating:
        _translating_angle(p, link, row, i, where)
    elif "angle" in row:
        p.add(f"{where}: its angle is an input (the link turns); drop 'angle'", "link", i, "angle")
    elif "turn" in row:
        _turn(p, link, row, i, where)


def locked_to(link: Link) -> str | None:
    """What a link keeps its direction on: 'guide' where its outer pair slides, 'm' for
    link n where E slides along link m, else None (it turns freely)."""
    d_m, e, d_n = PAIRS[link.dyad.type]
    if (d_m if link.side == "m" else d_n) == "T":
        return "guide"
    return "m" if link.side == "n" and e == "T" else None


def _turn(p: Problems, link: Link, row: dict, i: int, where: str) -> None:
    """turn: the angle of a locked link's direction from its guide's or link m's."""
    on = locked_to(link)
    if on is None or not link.dyad.internal:
        why = (
            "only internal kinematics read it"
            if on is not None
            else "the link turns freely: its direction follows from the chain"
        )
        p.add(f"{where}: drop 'turn': {why}", "link", i, "turn")
        return
    value = number(p, row, "turn", where, "link", i)
    if value is not None:
        what = "its guide's" if on == "guide" else "link m's"
        link.params["turn"] = Param(
            f"{link.name}.turn", value, "rad", f"Angle of {link.name}'s i from {what} direction"
        )


def _translating_angle(p: Problems, link: Link, row: dict, i: int, where: str) -> None:
    """A link on a frame guide keeps its angle: 'angle' (absolute) or, with internal
    kinematics, 'turn' from the guide."""
    guide = link.attachment().guide
    if "turn" in row and "angle" not in row and link.dyad.internal and guide is not None:
        turn = number(p, row, "turn", where, "link", i)
        angle = None if turn is None else guide.value + turn
    else:
        angle = number(p, row, "angle", where + " (it translates on its frame guide)", "link", i)
    if angle is not None:
        link.params["angle"] = Param(
            f"{link.name}.angle", angle, "rad", f"Direction of link {link.name} (it translates)"
        )


def link_params(
    p: Problems, link: Link, row: dict, i: int, inertia: bool, needs_mass: bool
) -> None:
    """A link's numbers: length (unless it slides), angle (if it translates), centre of
    mass, and mass and inertia where the effects need them."""
    _length_and_angle(p, link, row, i)
    g = link.name
    where = f"link '{g}'"
    com = pair_of_numbers(p, row, "com", where, "link", i, required=True)
    if com is not None:
        link.params["com.x"] = Param(
            f"{g}.com.x", com[0], "m", f"Centre of mass of {g}, x in its frame"
        )
        link.params["com.y"] = Param(
            f"{g}.com.y", com[1], "m", f"Centre of mass of {g}, y in its frame"
        )
    mass = number(p, row, "mass", where, "link", i, nonnegative=True, required=needs_mass)
    if mass is not None and needs_mass:
        link.params["mass"] = Param(f"{g}.mass", mass, "kg", f"Mass of {g}", {"min": 0.0})
    inert = number(p, row, "inertia", where, "link", i, nonnegative=True, required=inertia)
    if inert is not None and inertia:
        link.params["inertia"] = Param(
            f"{g}.inertia",
            inert,
            "kg.m2",
            f"Moment of inertia of {g} about its centre of mass",
            {"min": 0.0},
        )

"""Independent high-precision reference of a whole mechanism FMU (mpmath).

From a scene file with internal kinematics (``modelDescription/scenes/*.toml`` with one
or several drivers, ``[crank]``/``[[crank]]``, ``[ram]``/``[[ram]]``,
``[cylinder]``/``[[cylinder]]``, cranks and rams on the frame, a cylinder's pivot O and
barrel's pin A each on the frame or on the link of an earlier driver; schema in
modelDescription/scenes/README.md) and the FMU's input values, :func:`evaluate` gives
every Real output of the scene's mechanism FMU as an mpf at a chosen precision, and the
status. It is built from the two independent references of this package and the
cylinder's equations below, not from the C code or the generated code:

* a cylinder's triangle: pin B on the circle of radius |pin| about the link's pivot O
  and on the circle of radius s about the barrel's pin A, on the branch's side of the
  directed line O -> A; the link's angle turns ``pin`` (B in the link's frame) onto
  B - O; the rates by implicit differentiation of the closure O + B(theta) - A - s u(psi)
  = 0 (two 2 x 2 linear solves, ``mpmath.lu_solve``), O and A moving with their
  carriers (the frame, or an earlier driver's link, whose motion is solved first);
* kinematics, from the drivers outwards: each driver's body from its own motion inputs,
  then each dyad by :func:`.dyad_kinematics.solve` (the closure solved by findroot,
  rates by implicit differentiation), its mounts being points and guides of any
  driver's body or of the links of earlier dyads, moved as rigid
  bodies (v = v_D + w perp(r), a = a_D + e perp(r) - w^2 r) from that dyad's mpf
  results, never rounded to float;
* kinetostatics, from the last dyad back: each dyad's Newton-Euler equations (the system
  of :func:`.newton_euler.equilibrium_system`, solved by ``mpmath.lu_solve``), every later
  dyad's reactions loading the earlier link or driver it hangs on, at its pair point (a
  sliding pair's reactive moment too); each ``[[load]]`` of the scene as a force at its
  point of its link (the driver included) and a couple, its force global or turned by
  the link's angle (a follower force);
* each driver's balance: a crank's torque about O and the frame's force R_O on it; a ram's
  actuator force along its guide i_r, the guide's normal force N along j_r and reactive
  moment M about R; a cylinder's three bodies, the barrel (pinned at A, its centre of
  mass at A + com u), the rod (pinned to the link at B, at B - com u; both turn with the
  axis u, the rod slides along it) and the link (about O), each with its weight and
  d'Alembert force and couple, the link with its [[load]] tables and the reactions of the
  dyads on it: 9 equations in R_A, R_B, R_O, the axial force, N and M, solved by
  ``mpmath.lu_solve``; the drivers from the last back, so that a carrier (an earlier
  driver's link) bears minus R_A at A and minus R_O at O of each cylinder it carries;
* with inertia, the effective inertia J = sum m V.V + I W^2 over every moving body (the
  driver included) and dJ/dq = 2 sum (m V.V' + I W W'), V, W the centre of mass's
  velocity and the angular velocity per unit driver rate, V', W' their derivatives in the
  driver's coordinate q: the kinematics evaluated again at unit driver rate and zero
  driver acceleration; torque0 = torque - J q'' (a ram's and a cylinder's force0
  likewise; a cylinder's J counts the link, the barrel, the rod and every dyad link);
* with inertia and N >= 2 drivers (no J, dJdq), by the same route as J: the inertia
  matrix M.<a>.<b> = sum m V_a.V_b + I W_a W_b over every moving body (every driver's
  body, a cylinder's barrel and rod, every dyad link), V_a and W_a per unit rate of driver
  a, the kinematics evaluated once per driver at its unit rate, the other drivers' rates
  and every acceleration zero (the kinetic energy is q'.M q' / 2; M is symmetric by
  construction); each driver's torque0 / force0 (h_a) is its effort from the
  kinetostatics run again with every driver's acceleration zero, velocities, gravity
  and loads kept. The efforts are then M q'' + h, which the Newton-Euler balance
  checks rather than assumes.

A cylinder's link carries dyads and [[load]] tables as a crank does: a dyad names it
``{ link = "body", at = [x, y] }`` (a point of its frame {O; i, j}) or ``"body"`` alone,
which is pin B (as ``"crank"`` alone is a crank's pin A). Its outputs: ``body.angle``,
``hoist.angle`` (the axis u), with inertia their ``omega`` and ``epsilon``,
``hoist.B.position.x/.y``, ``hoist.force`` (> 0 pushes the pins apart), ``hoist.R_A``
(on the barrel from the frame), ``hoist.R_B`` (on the link from the rod), ``body.R_O``,
``hoist.N``, ``hoist.M`` (the barrel's action on the rod across the axis, at B),
``hoist.conditioning`` (|sin| of the angle between OB and AB) and, with inertia,
``hoist.J``, ``hoist.dJdq``, ``hoist.force0`` (``body`` and ``hoist`` standing for the
scene's names).

Every input is taken as the exact binary value of its float; every number of the scene
(and each parameter given with the inputs) likewise; trigonometric functions of them are
evaluated exactly. The arithmetic runs at ``dps + 20`` digits and the outputs are rounded
to ``dps``.

Several drivers: each has its own motion inputs and the outputs a single one of its kind
has (but J and dJdq); dyads and [[load]] tables name any driver's body; ``"crank"`` alone
names a scene's only crank. Driver order: cranks, rams, cylinders, each in file order.
A cylinder's ``at`` (O) or ``base`` (A) given as ``{ link = "boom", at = [x, y] }`` is a
point of the link of an earlier driver (in that link's frame; parameters ``body.at.x``,
``hoist.base.x`` ... as on the frame); its link's angle and omega and the axis's stay
absolute (global); ``hoist.R_A`` is the force on the barrel from A's carrier and
``body.R_O`` the force on the link from O's carrier. Refused (SceneError): a carrier
that is neither the frame nor an earlier driver's link, or the link the cylinder turns.

Units: m, s, rad, kg, N, N m. Driver coordinate q: the crank's angle (rad), the ram's
position or the cylinder's length s (m); J in kg m2 (crank) or kg (ram, cylinder); dJdq
in kg m2/rad or kg/m; M.<a>.<b> in kg m2 (angle-angle), kg m (angle-length) or kg
(length-length).

Status (:class:`Result`): ``"ok"``; ``"cannot assemble"`` (the first dyad, from the
drivers, whose closure has no real solution on its branch; or the cylinder, named by its
name, whose triangle does not close: s <= 0 or outside [| |OA| - |OB| |, |OA| + |OB|]);
``"singular"`` (a dyad at a dead point: its closure's Jacobian vanishes to the working
precision, which for the float inputs of an FMU means conditioning exactly 0, or TRT /
RTT guides exactly parallel; or the cylinder at its toggle, O, A and B in line, alike).
The outputs are empty unless the status is ok.

Not reproduced: ``amplification`` (a bound on the FMU's round-off, not a property of the
mechanism) and ``status``; ``singular_threshold`` and ``on_singular`` are accepted and
ignored.

Example::

    scene = read_scene("modelDescription/scenes/lift.toml")
    r = evaluate(scene, {"ram.position": 0.25, "ram.velocity": 0.3,
                         "ram.acceleration": -1.2, "platform.force.y": -900.0})
    r.status, r.outputs["ram.force"], r.outputs["lever.R_mk.x"]
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import mpmath
from mpmath import mpf

from . import dyad_kinematics as dk
from .newton_euler import PAIRS, equilibrium_system, reactions_of_unknowns

__all__ = [
    "CANNOT_ASSEMBLE",
    "OK",
    "SINGULAR",
    "Attachment",
    "Driver",
    "DyadSpec",
    "MechanismScene",
    "Result",
    "SceneError",
    "assembly_status",
    "evaluate",
    "read_scene",
]

#: The statuses of :class:`Result`.
OK = "ok"
CANNOT_ASSEMBLE = dk.CANNOT_ASSEMBLE
SINGULAR = dk.SINGULAR

_GUARD = 20  # decimal digits carried beyond the requested dps
#: Whether D_m and D_n slide on a guide of k and p, by dyad type.
_SLIDES = {t: (PAIRS[t][0] == "T", PAIRS[t][2] == "T") for t in PAIRS}
_TWO_BRANCHES = ("RRR", "RRT", "RTR")
_CRANK_MOTION = ("angle", "omega", "epsilon")
_RAM_MOTION = ("position", "velocity", "acceleration")
_CYLINDER_MOTION = ("length", "velocity", "acceleration")
_DRIVERS = ("crank", "ram", "cylinder")
_IGNORED = ("singular_threshold", "on_singular")
_NAME = re.compile(r"[a-z][a-z0-9_]{0,39}")

Vec = tuple


class SceneError(ValueError):
    """A scene or an input this reference refuses; the message names the file and field."""


# ---------------------------------------------------------------------------
# the scene
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Attachment:
    """An outer pair's external link: the frame (``body`` None), the driver or a link.

    ``guide``: the pair slides, on a guide of that body whose angle is the parameter
    ``<guide>`` (rad; from x on the frame, from the body's i otherwise). ``at``: the
    parameter prefix of the pair's point or of a point of its guide (``<at>.x``,
    ``<at>.y``, m; global on the frame, in the body's frame otherwise), or None for the
    crank's pin (length, 0) or the ram's point R.
    """

    body: str | None
    guide: str | None
    at: str | None


@dataclass(frozen=True)
class DyadSpec:
    """A [[dyad]]: name ("" when the scene's only dyad is unnamed), type, links, mounts."""

    name: str
    type: str
    m: str
    n: str
    k: Attachment
    p: Attachment

    @property
    def prefix(self) -> str:
        """The prefix of the dyad's FMU variables: ``"<name>."`` or ``""``."""
        return f"{self.name}." if self.name else ""


@dataclass(frozen=True)
class Driver:
    """A driver: ``kind`` ``"crank"``, ``"ram"`` or ``"cylinder"``, ``name`` its name in the
    FMU's variables, ``link`` the moving body dyads and [[load]] tables may name (the
    crank, the ram, or the link a cylinder turns). A cylinder's ``pivot_on`` and
    ``base_on``: the link of an earlier driver that carries its pivot O and its barrel's
    pin A (None: the frame)."""

    kind: str
    name: str
    link: str
    pivot_on: str | None = None
    base_on: str | None = None

    @property
    def effort(self) -> str:
        """Its effort's output name: ``torque`` (N m) or ``force`` (N)."""
        return "torque" if self.kind == "crank" else "force"

    def motion(self, inertia: bool) -> tuple[str, ...]:
        """Its coordinate, rate and acceleration inputs (the rates with inertia)."""
        names = {"ram": _RAM_MOTION, "cylinder": _CYLINDER_MOTION}.get(self.kind, _CRANK_MOTION)
        return tuple(f"{self.name}.{k}" for k in names[: 3 if inertia else 1])


@dataclass(frozen=True)
class MechanismScene:
    """A scene read for :func:`evaluate`.

    ``drivers``: the scene's drivers, cranks, rams, cylinders, each kind in file order;
    ``inputs`` the FMU's inputs with their start values (the drivers' motion: rad, rad/s,
    rad/s2 or m, m/s, m/s2; the loads: N, N m); ``parameters`` every parameter of the
    scene under the FMU's names (tunable or baked) with its value; ``translating``: the
    links that slide on a frame guide (no angle output). ``driver``, ``driver_name``,
    ``driven`` and ``carrier`` describe a scene's only driver (SceneError with several).
    """

    label: str
    drivers: tuple[Driver, ...]
    inertia: bool
    gravity: bool
    dyads: tuple[DyadSpec, ...]
    translating: frozenset[str]
    forces: tuple[str, ...]
    moments: tuple[str, ...]
    inputs: dict[str, float]
    parameters: dict[str, float]
    #: the [[load]] tables: (name, link, components, force?, moment?) each
    point_loads: tuple = ()

    @property
    def only_driver(self) -> Driver:
        """The scene's only driver (SceneError when it has several)."""
        if len(self.drivers) != 1:
            names = ", ".join(d.name for d in self.drivers)
            raise SceneError(f"{self.label}: {len(self.drivers)} drivers ({names}), not one")
        return self.drivers[0]

    @property
    def driver(self) -> str:
        """The only driver's kind: ``"crank"``, ``"ram"`` or ``"cylinder"``."""
        return self.only_driver.kind

    @property
    def driver_name(self) -> str:
        """The only driver's name."""
        return self.only_driver.name

    @property
    def driven(self) -> str:
        """The link the only driver, a cylinder, turns ("" for a crank or a ram)."""
        d = self.only_driver
        return d.link if d.kind == "cylinder" else ""

    @property
    def carrier(self) -> str:
        """The moving body of the only driver that dyads and [[load]] tables may name."""
        return self.only_driver.link

    @property
    def motion_inputs(self) -> tuple[str, ...]:
        """Every driver's coordinate, rate and acceleration inputs (the rates with
        inertia), driver after driver."""
        return tuple(n for d in self.drivers for n in d.motion(self.inertia))

    def driver_on(self, link: str) -> Driver | None:
        """The driver whose moving body is ``link``, or None."""
        return next((d for d in self.drivers if d.link == link), None)

    def split(self, values: Mapping[str, float]) -> tuple[dict, dict]:
        """(inputs, parameters): the start values and scene values with ``values`` over
        them; a name that is neither an input nor a parameter is refused."""
        inputs, params = dict(self.inputs), dict(self.parameters)
        for name, value in values.items():
            if name in inputs:
                inputs[name] = _finite(value, name, self.label)
            elif name in params:
                params[name] = _finite(value, name, self.label)
            elif name not in _IGNORED:
                raise SceneError(
                    f"{self.label}: {name!r} is no input or parameter of this mechanism FMU "
                    f"(inputs: {', '.join(self.inputs)})"
                )
        return inputs, params


def _finite(value: object, name: str, label: str) -> float:
    """A finite number (bool refused), as float."""
    if isinstance(value, bool) or not isinstance(value, int | float | mpf):
        raise SceneError(f"{label}: {name} must be a number, not {value!r}")
    number = float(value)
    if number != number or number in (float("inf"), float("-inf")):
        raise SceneError(f"{label}: {name} must be finite, not {value!r}")
    return number


class _Reader:
    """Reads a parsed scene into a :class:`MechanismScene`, naming the field of each fault."""

    def __init__(self, data: Mapping, label: str) -> None:
        self.data, self.label = data, label
        self.params: dict[str, float] = {}
        self.inputs: dict[str, float] = {}

    def fail(self, where: str, message: str) -> None:
        raise SceneError(f"{self.label}: {where}: {message}")

    def table(self, key: str, required: bool = False) -> dict:
        value = self.data.get(key)
        if value is None and not required:
            return {}
        if not isinstance(value, Mapping):
            self.fail(f"[{key}]", "missing or not a table")
        return dict(value)

    def number(self, table: Mapping, key: str, where: str, default: float | None = None) -> float:
        if key not in table:
            if default is None:
                self.fail(where, f"missing '{key}'")
            return default
        return _finite(table[key], f"{where}.{key}", self.label)

    def pair(self, table: Mapping, key: str, where: str, default: tuple | None = None) -> tuple:
        value = table.get(key, default)
        if not isinstance(value, list | tuple) or len(value) != 2:
            self.fail(where, f"'{key}' must be [x, y] (m)")
        return tuple(_finite(v, f"{where}.{key}", self.label) for v in value)

    def param(self, name: str, value: float) -> None:
        self.params[name] = value

    def param_pair(self, name: str, value: tuple) -> None:
        self.params[f"{name}.x"], self.params[f"{name}.y"] = value

    # ---- sections ---------------------------------------------------------------------
    def effects(self) -> tuple[bool, bool]:
        head = self.table("scene", required=True)
        kinematics = head.get("kinematics", "internal")
        if kinematics != "internal":
            self.fail("[scene].kinematics", "only a mechanism FMU (kinematics = 'internal')")
        eff = self.table("effects")
        inertia, gravity = bool(eff.get("inertia", False)), bool(eff.get("gravity", False))
        if gravity:
            g = self.table("gravity", required=True)
            self.param("gravity.x", self.number(g, "x", "[gravity]"))
            self.param("gravity.y", self.number(g, "y", "[gravity]"))
        return inertia, gravity

    def entries(self, kind: str) -> list[dict]:
        """A driver kind's tables: ``[kind]`` (one) or ``[[kind]]`` (an array of them)."""
        value = self.data.get(kind)
        if value is None:
            return []
        rows = [value] if isinstance(value, Mapping) else value
        if not isinstance(rows, list) or not all(isinstance(r, Mapping) for r in rows):
            self.fail(f"[{kind}]", "must be a table or an array of tables")
        return [dict(r) for r in rows]

    def drivers(self, needs_mass: bool, inertia: bool) -> list[Driver]:
        """Every driver, cranks, rams, cylinders, each kind in file order, its parameters
        and motion inputs recorded; names (a cylinder's and its link's) unique."""
        found: list[Driver] = []
        for kind in _DRIVERS:
            rows = self.entries(kind)
            for index, t in enumerate(rows):
                where = f"[{kind}]" if len(rows) == 1 else f"[[{kind}]] #{index + 1}"
                found.append(self.driver(kind, t, where, (needs_mass, inertia), found))
        if not found:
            self.fail("[crank]/[ram]/[cylinder]", "a mechanism FMU has at least one driver")
        names = [d.name for d in found] + [d.link for d in found if d.kind == "cylinder"]
        for name in names:
            if names.count(name) > 1:
                self.fail("[crank]/[ram]/[cylinder]", f"two drivers or links named {name!r}")
        return found

    def driver(self, kind: str, t: dict, where: str, needs: tuple, earlier: list) -> Driver:
        """One driver of ``kind`` from its table ``t``, after the drivers ``earlier``."""
        needs_mass, inertia = needs
        if kind == "cylinder":
            driver = _cylinder(self, t, where, needs, [d.link for d in earlier])
        else:
            name = str(t.get("name", kind))
            driver = Driver(kind, name, name)
            self.param_pair(f"{name}.at", self.pair(t, "at", where, (0.0, 0.0)))
            if kind == "crank":
                self.param(f"{name}.length", self.number(t, "length", where))
                self.param(f"{name}.inertia", self.number(t, "inertia", where) if inertia else 0.0)
            else:
                self.param(f"{name}.guide", self.number(t, "guide", where))
            com = self.pair(t, "com", where) if needs_mass else (0.0, 0.0)
            self.param_pair(f"{name}.com", com)
            self.param(f"{name}.mass", self.number(t, "mass", where) if needs_mass else 0.0)
        for key in driver.motion(inertia):
            self.inputs[key] = 0.0
        return driver

    def links(self, needs_mass: bool, inertia: bool) -> dict[str, dict]:
        rows = self.data.get("link", [])
        if not isinstance(rows, list):
            self.fail("[[link]]", "must be an array of tables")
        links = {}
        for row in rows:
            name = row.get("name") if isinstance(row, Mapping) else None
            if not isinstance(name, str) or name in links:
                self.fail("[[link]]", f"bad or repeated link name {name!r}")
            where = f"link '{name}'"
            self.param_pair(f"{name}.com", self.pair(row, "com", where))
            self.param(f"{name}.mass", self.number(row, "mass", where) if needs_mass else 0.0)
            self.param(f"{name}.inertia", self.number(row, "inertia", where) if inertia else 0.0)
            links[name] = dict(row)
        return links


_CYLINDER_KEYS = frozenset(
    ("name", "link", "at", "base", "pin", "branch", "com", "mass", "inertia", "barrel", "rod")
)


def _cylinder(rd: _Reader, t: dict, where: str, needs: tuple, carriers: list) -> Driver:
    """A [cylinder]: its geometry, the link's mass and the barrel's and the rod's, as
    parameters under the FMU's names; ``carriers``, the links of the drivers before it,
    may carry its O and A."""
    unknown = sorted(set(t) - _CYLINDER_KEYS)
    if unknown:
        rd.fail(where, f"unknown key {unknown[0]!r} (keys: {', '.join(sorted(_CYLINDER_KEYS))})")
    name, link = t.get("name"), t.get("link")
    for key, value in (("name", name), ("link", link)):
        if not isinstance(value, str) or not _NAME.fullmatch(value) or value == "frame":
            rd.fail(f"{where}.{key}", f"must be a lower-case name, not {value!r}")
    if name == link:
        rd.fail(where, f"the cylinder and the link it turns are both named {name!r}")
    pivot_on, pivot = _cylinder_point(rd, t, "at", where, (link, carriers))
    rd.param_pair(f"{link}.at", pivot)
    base_on, base = _cylinder_point(rd, t, "base", where, (link, carriers))
    pin = rd.pair(t, "pin", where)
    if pin == (0.0, 0.0):
        rd.fail(f"{where}.pin", "must not be [0, 0]: B must be off the pivot O (|pin| > 0)")
    if base_on == pivot_on and base == pivot:
        rd.fail(f"{where}.base", "A must differ from the link's pivot O ('at')")
    rd.param_pair(f"{name}.base", base)
    rd.param_pair(f"{name}.pin", pin)
    branch = t.get("branch")
    if branch not in (1, -1) or isinstance(branch, bool):
        rd.fail(f"{where}.branch", f"must be 1 or -1, not {branch!r}")
    rd.param(f"{name}.branch", float(branch))
    _cylinder_masses(rd, t, (name, link, where), needs)
    return Driver("cylinder", name, link, pivot_on, base_on)


def _cylinder_point(rd: _Reader, t: dict, key: str, where: str, links: tuple) -> tuple:
    """(carrier, (x, y)) of a cylinder's ``at`` (O) or ``base`` (A): ``[x, y]`` on the
    frame (carrier None, global) or ``{ link = NAME, at = [x, y] }`` on the link of an
    earlier driver (in that link's frame). ``links``: (the link the cylinder turns, the
    links of the drivers before it)."""
    own, carriers = links
    spec, here = t.get(key), f"{where}.{key}"
    if not isinstance(spec, Mapping):
        return None, rd.pair(t, key, where)
    carrier = spec.get("link")
    if set(spec) != {"link", "at"} or not isinstance(carrier, str):
        rd.fail(here, "must be [x, y] (m, the frame) or { link = NAME, at = [x, y] }")
    if carrier == own:
        rd.fail(here, f"on {own!r}, the link the cylinder turns: a cylinder cannot carry itself")
    if carrier != "frame" and carrier not in carriers:
        known = ", ".join(repr(c) for c in carriers) or "none"
        rd.fail(
            here,
            f"{carrier!r} is not the frame nor the link of a driver listed before this "
            f"cylinder (cranks, rams, then cylinders in file order; before it: {known})",
        )
    return (None if carrier == "frame" else carrier), rd.pair(spec, "at", here)


def _cylinder_masses(rd: _Reader, t: dict, names: tuple, needs: tuple) -> None:
    """The link's centre of mass, mass and inertia and the barrel's and the rod's (zero
    where the scene has no inertia or gravity, or no barrel or rod)."""
    needs_mass, inertia = needs
    name, link, where = names
    rd.param_pair(f"{link}.com", rd.pair(t, "com", where) if needs_mass else (0.0, 0.0))
    rd.param(f"{link}.mass", rd.number(t, "mass", where) if needs_mass else 0.0)
    rd.param(f"{link}.inertia", rd.number(t, "inertia", where) if inertia else 0.0)
    for part in ("barrel", "rod"):
        spec, here = t.get(part, {}), f"{where}.{part}"
        if not isinstance(spec, Mapping) or set(spec) - {"mass", "com", "inertia"}:
            rd.fail(here, "must be { mass = kg, com = m, inertia = kg m2 }")
        given = needs_mass and part in t
        rd.param(f"{name}.{part}.mass", rd.number(spec, "mass", here) if given else 0.0)
        rd.param(f"{name}.{part}.com", rd.number(spec, "com", here) if given else 0.0)
        held = inertia and part in t
        rd.param(f"{name}.{part}.inertia", rd.number(spec, "inertia", here) if held else 0.0)


def _attachment(rd: _Reader, spec: object, side: str, dyad: str, ctx: dict) -> Attachment:
    """The external link of pair D_m (side k) or D_n (side p) of a dyad, its parameters
    recorded under the FMU's names."""
    where = f"dyad '{dyad}'.{side}"
    pre = f"{dyad}." if dyad else ""
    slides = _SLIDES[ctx["type"]][side == "p"]
    spec = {"link": spec} if isinstance(spec, str) else spec
    if not isinstance(spec, Mapping) or not isinstance(spec.get("link"), str):
        rd.fail(where, "expected 'frame', the driver's name or { link = ..., at = [x, y] }")
    body = spec["link"]
    if body == "crank" and ctx["crank"]:
        body = ctx["crank"]
    if body in ctx["cylinders"]:
        rd.fail(where, f"a dyad hangs on the link the cylinder turns, {ctx['cylinders'][body]!r}")
    if body != "frame" and body not in ctx["carriers"] and body not in ctx["done"]:
        rd.fail(where, f"{body!r} is not the frame, the driver nor a link of an earlier dyad")
    pair = "D_m" if side == "k" else "D_n"
    if slides:
        if "guide" not in spec:
            rd.fail(where, f"{pair} slides: it needs guide = <angle in rad>")
        rd.param(f"{pre}guide_{side}.angle", rd.number(spec, "guide", where))
        rd.param_pair(f"{pre}guide_{side}.at", rd.pair(spec, "at", where, (0.0, 0.0)))
        return Attachment(
            None if body == "frame" else body, f"{pre}guide_{side}.angle", f"{pre}guide_{side}.at"
        )
    if "guide" in spec:
        rd.fail(where, f"{pair} is a revolute pair and has no guide")
    if "at" not in spec:
        if body == "frame" or body in ctx["done"]:
            rd.fail(where, f"{pair} needs at = [x, y] (m)")
        return Attachment(body, None, None)  # the crank's pin A, the ram's R, or pin B
    rd.param_pair(f"{pre}{pair}", rd.pair(spec, "at", where))
    return Attachment(None if body == "frame" else body, None, f"{pre}{pair}")


def _link_geometry(rd: _Reader, d: DyadSpec, links: dict, translating: set) -> None:
    """Lengths, and the angle (a link on a frame guide) or turn (a link locked to a moving
    guide or to link m) of a dyad's links, as parameters."""
    for side, g in (("m", d.m), ("n", d.n)):
        row, where = links[g], f"link '{g}'"
        att = d.k if side == "m" else d.p
        if not (side == "m" and d.type in ("RTR", "RTT")):
            rd.param(f"{g}.length", rd.number(row, "length", where))
        if att.guide is not None and att.body is None:  # translates on a frame guide
            translating.add(g)
            if "angle" in row:
                rd.param(f"{g}.angle", rd.number(row, "angle", where))
            else:
                guide = rd.params[att.guide]
                rd.param(f"{g}.angle", guide + rd.number(row, "turn", where, 0.0))
        else:
            rd.param(f"{g}.turn", rd.number(row, "turn", where, 0.0))


def _dyads(rd: _Reader, links: dict, drivers: list[Driver]) -> tuple[list, set]:
    rows = rd.data.get("dyad", [])
    cylinders = {d.name: d.link for d in drivers if d.kind == "cylinder"}
    # a cylinder and the link it turns are a mechanism of their own
    if not isinstance(rows, list) or not (rows or cylinders):
        rd.fail("[[dyad]]", "a scene has at least one dyad (or a [cylinder])")
    cranks = [d.name for d in drivers if d.kind == "crank"]
    # "crank" names a scene's only crank, whatever its name
    ctx = {"crank": cranks[0] if len(cranks) == 1 else None, "cylinders": cylinders}
    ctx.update(carriers={d.link for d in drivers}, done=set(), type="")
    dyads, translating = [], set()
    for row in rows:
        dname = str(row.get("name", "")) if isinstance(row, Mapping) else ""
        dtype = row.get("type") if isinstance(row, Mapping) else None
        if dtype not in PAIRS:
            rd.fail(f"dyad '{dname}'.type", f"expected one of {', '.join(PAIRS)}")
        m, n = row.get("m"), row.get("n")
        for g in (m, n):
            if g not in links or g in ctx["done"]:
                rd.fail(f"dyad '{dname}'", f"link {g!r} is unknown or already connected")
        ctx["type"] = dtype
        k = _attachment(rd, row.get("k"), "k", dname, ctx)
        p = _attachment(rd, row.get("p"), "p", dname, ctx)
        d = DyadSpec(dname, dtype, m, n, k, p)
        if dtype in _TWO_BRANCHES:
            default = 1.0 if dtype == "RTR" else None
            rd.param(f"{d.prefix}branch", rd.number(row, "branch", f"dyad '{dname}'", default))
        _link_geometry(rd, d, links, translating)
        ctx["done"].update((m, n))
        dyads.append(d)
    return dyads, translating


def _loads(rd: _Reader, links: dict) -> tuple[tuple, tuple]:
    loads = rd.table("loads")
    out = []
    for key in ("force", "moment"):
        names = loads.get(key, [])
        if not isinstance(names, list) or any(g not in links for g in names):
            rd.fail(f"[loads].{key}", "must be a list of link names")
        for g in names:
            components = (".x", ".y") if key == "force" else ("",)
            for c in components:
                rd.inputs[f"{g}.{key}{c}"] = 0.0
        out.append(tuple(names))
    return out[0], out[1]


def _point_loads(rd: _Reader, links: dict, carriers: set) -> tuple:
    """The [[load]] tables: each load's inputs (N, N m) and its point (m, the link's frame;
    default the link's centre of mass) as parameters NAME.at.x, NAME.at.y."""
    rows = rd.data.get("load", [])
    if not isinstance(rows, list):
        rd.fail("[[load]]", "must be an array of tables")
    out = []
    for row in rows:
        name, link = row.get("name"), row.get("link")
        where = f"load {name!r}"
        if not isinstance(name, str) or (link not in links and link not in carriers):
            rd.fail(where, "needs a name and the link it acts on (a dyad's link or the driver)")
        com = (rd.params[f"{link}.com.x"], rd.params[f"{link}.com.y"])
        rd.param_pair(f"{name}.at", rd.pair(row, "at", where, com))
        components = row.get("components", "global")
        force, moment = bool(row.get("force", True)), bool(row.get("moment", False))
        for key in (("force.x", "force.y") if force else ()) + (("moment",) if moment else ()):
            rd.inputs[f"{name}.{key}"] = 0.0
        out.append((name, link, components, force, moment))
    return tuple(out)


def read_scene(scene: Mapping | str | os.PathLike) -> MechanismScene:
    """A scene file (path) or its parsed table read for :func:`evaluate`."""
    if isinstance(scene, Mapping):
        data, label = scene, "scene"
    else:
        label = Path(scene).name
        try:
            with open(scene, "rb") as f:
                data = tomllib.load(f)
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise SceneError(f"{label}: cannot read the scene: {exc}") from None
    rd = _Reader(data, label)
    inertia, gravity = rd.effects()
    drivers = rd.drivers(inertia or gravity, inertia)
    links = rd.links(inertia or gravity, inertia)
    for taken in [d.name for d in drivers] + [d.link for d in drivers]:
        if taken in links:
            rd.fail(f"link '{taken}'", "a [[link]] named like the driver or the link it turns")
    dyads, translating = _dyads(rd, links, drivers)
    forces, moments = _loads(rd, links)
    placed = _point_loads(rd, links, {d.link for d in drivers})
    start = rd.table("start")
    for key, value in start.items():
        if key in rd.inputs:
            rd.inputs[key] = _finite(value, f"[start].{key}", label)
    return MechanismScene(
        label=label,
        drivers=tuple(drivers),
        inertia=inertia,
        gravity=gravity,
        dyads=tuple(dyads),
        translating=frozenset(translating),
        forces=forces,
        moments=moments,
        inputs=dict(rd.inputs),
        parameters=dict(rd.params),
        point_loads=placed,
    )


# ---------------------------------------------------------------------------
# rigid bodies (mpf)
# ---------------------------------------------------------------------------
def _perp(v: Vec) -> tuple:
    return (-v[1], v[0])


def _cross(a: Vec, b: Vec) -> mpf:
    return a[0] * b[1] - a[1] * b[0]


def _dot(a: Vec, b: Vec) -> mpf:
    return a[0] * b[0] + a[1] * b[1]


def _add(*vs: Vec) -> tuple:
    return (sum(v[0] for v in vs), sum(v[1] for v in vs))


def _scale(s: mpf, v: Vec) -> tuple:
    return (s * v[0], s * v[1])


def _unit(angle: mpf) -> tuple:
    return (mpmath.cos(angle), mpmath.sin(angle))


@dataclass(frozen=True)
class _Body:
    """A moving body at one instant: its frame's origin D (position, velocity,
    acceleration), its direction i, angular velocity and acceleration."""

    position: Vec
    velocity: Vec
    acceleration: Vec
    i: Vec
    omega: mpf
    epsilon: mpf

    def arm(self, local: Vec) -> tuple:
        """The vector from D to the point ``local`` of the body's frame (m)."""
        return _add(_scale(local[0], self.i), _scale(local[1], _perp(self.i)))

    def point(self, local: Vec) -> tuple:
        """(position, velocity, acceleration) of the body's point ``local``."""
        r = self.arm(local)
        w, e = self.omega, self.epsilon
        return (
            _add(self.position, r),
            _add(self.velocity, _scale(w, _perp(r))),
            _add(self.acceleration, _scale(e, _perp(r)), _scale(-w * w, r)),
        )


@dataclass(frozen=True)
class _Axis:
    """A cylinder's axis at one instant: the barrel's pin A, the unit vector u from A
    towards B, the length s = |AB| and its rates, and the axis's angular velocity and
    acceleration (the barrel's and the rod's: they turn together); ``conditioning`` is
    |sin| of the angle between OB and AB."""

    base: Vec
    u: Vec
    length: mpf
    rate: mpf
    accel: mpf
    omega: mpf
    epsilon: mpf
    conditioning: mpf
    #: A's velocity and acceleration (zero on the frame)
    base_motion: tuple = ((0, 0), (0, 0))

    def point(self, x: mpf, on_rod: bool) -> tuple:
        """(position, velocity, acceleration) of the point at x (m) from A along u: fixed
        on the barrel, or on the rod, where x = s - c grows at s' and s''; A's own motion
        added."""
        x1, x2 = (self.rate, self.accel) if on_rod else (mpf(0), mpf(0))
        w, e, u, n = self.omega, self.epsilon, self.u, _perp(self.u)
        v_a, a_a = self.base_motion
        return (
            _add(self.base, _scale(x, u)),
            _add(_scale(x1, u), _scale(x * w, n), v_a),
            _add(_scale(x2 - x * w * w, u), _scale(2 * x1 * w + x * e, n), a_a),
        )


# ---------------------------------------------------------------------------
# the evaluation
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Result:
    """What :func:`evaluate` gives: ``status`` (:data:`OK`, :data:`CANNOT_ASSEMBLE` or
    :data:`SINGULAR`), ``dyad`` (the name of the dyad that failed, "" for a scene's only,
    unnamed dyad, the cylinder's name for its triangle; None when ok), ``reason`` (why, ""
    when ok) and ``outputs`` (FMU output name -> mpf in the FMU's unit; empty unless ok)."""

    status: str
    dyad: str | None
    reason: str
    outputs: dict[str, mpf]


@dataclass(frozen=True)
class _Chain:
    """The solved chain: its bodies by name, each dyad's dyad_kinematics result and the
    unit directions of the guides of its sliding outer pairs (k, p; None where revolute)."""

    bodies: dict
    results: dict
    guides: dict
    axes: dict  # each cylinder's _Axis, by the cylinder's name


class _Failure(Exception):
    """A dyad (or the cylinder's triangle) that does not close: status, name, reason."""


class _Evaluation:
    """One evaluation of a scene at the working precision (set by the caller)."""

    def __init__(self, scene: MechanismScene, inputs: dict, params: dict, work: int) -> None:
        self.s, self.work = scene, work
        self.inp = {k: mpf(v) for k, v in inputs.items()}
        self.par = {k: mpf(v) for k, v in params.items()}
        self.gravity = (
            (self.par["gravity.x"], self.par["gravity.y"]) if scene.gravity else (mpf(0), mpf(0))
        )

    def vec(self, name: str) -> tuple:
        return (self.par[f"{name}.x"], self.par[f"{name}.y"])

    # ---- kinematics ---------------------------------------------------------------------
    def driver_body(self, drv: Driver, motion: tuple, bodies: dict) -> tuple[_Body, _Axis | None]:
        """The body dyads hang on (the crank, the ram or the link a cylinder turns) with
        driver ``drv`` at coordinate q moving at rate q' with q'' (``motion`` = (q, q',
        q'')), and a cylinder's axis (None for a crank or a ram); ``bodies``: the earlier
        drivers' bodies, which may carry a cylinder's O and A."""
        q, rate, accel = motion
        if drv.kind == "cylinder":
            return self.cylinder(drv, (q, rate, accel), bodies)
        c = drv.name
        at = self.vec(f"{c}.at")
        zero = mpf(0)
        if drv.kind == "crank":
            i = (mpmath.cos(q), mpmath.sin(q))
            return _Body(at, (zero, zero), (zero, zero), i, rate, accel), None
        i = (mpmath.cos(self.par[f"{c}.guide"]), mpmath.sin(self.par[f"{c}.guide"]))
        body = _Body(_add(at, _scale(q, i)), _scale(rate, i), _scale(accel, i), i, zero, zero)
        return body, None

    def carried(self, carrier: str | None, name: str, bodies: dict) -> tuple:
        """(position, velocity, acceleration) of the point ``name`` (parameters
        ``name.x``, ``name.y``): global on the frame (carrier None), else of the carrier's
        frame, moving with it."""
        if carrier is None:
            zero = (mpf(0), mpf(0))
            return self.vec(name), zero, zero
        return bodies[carrier].point(self.vec(name))

    def triangle(self, drv: Driver, s: mpf, o: Vec, a: Vec) -> tuple[Vec, Vec, mpf]:
        """(A - O, B - O, |sin| of the angle between OB and AB) of the cylinder at length s
        with its pivot at ``o`` and A at ``a``: B on the circle of radius |pin| about O and
        of radius s about A, on the branch's side of the directed line O -> A; _Failure
        where they do not meet or touch."""
        c = drv.name
        pin = self.vec(f"{c}.pin")
        with mpmath.extraprec(mpmath.mp.prec + 64):  # exact on the inputs' digits: 0 is 0
            d = (a[0] - o[0], a[1] - o[1])
            dd, rr = _dot(d, d), _dot(pin, pin)
            along = (dd + rr - s * s) / 2  # (B - O).(A - O)
            disc = rr * dd - along * along  # ((A - O) x (B - O))^2
        if dd == 0 and drv.pivot_on != drv.base_on:  # carried apart, met by the motion
            raise _Failure(SINGULAR, c, "its pivot O and its barrel's pin A coincide")
        for value, name in ((rr, f"{c}.pin"), (dd, f"{c}.base")):
            if value == 0:
                raise SceneError(f"{self.s.label}: {name}: O, A and B must be distinct points")
        if s <= 0 or disc < 0:
            span = (abs(mpmath.sqrt(dd) - mpmath.sqrt(rr)), mpmath.sqrt(dd) + mpmath.sqrt(rr))
            reason = f"its length {mpmath.nstr(s, 12)} m is outside the triangle's reach "
            reason += f"[{mpmath.nstr(span[0], 12)}, {mpmath.nstr(span[1], 12)}] m"
            raise _Failure(CANNOT_ASSEMBLE, c, reason)
        h = mpmath.sqrt(disc) * (-1 if self.par[f"{c}.branch"] < 0 else 1)
        b = ((along * d[0] - h * d[1]) / dd, (along * d[1] + h * d[0]) / dd)
        sine = abs(h) / (mpmath.sqrt(rr) * s)
        if sine < mpf(2) ** (-mpmath.mp.prec // 3):
            raise _Failure(SINGULAR, c, "O, A and B are in line (the toggle)")
        return d, b, sine

    def cylinder(self, drv: Driver, motion: tuple, bodies: dict) -> tuple[_Body, _Axis]:
        """The link a cylinder turns and the cylinder's axis at length s, s', s''
        (``motion``), O and A moving with their carriers (of ``bodies``): the closure
        O + B(theta) - A - s u(psi) = 0 differentiated once and twice in time with
        d = A - O, J (omega, psi')' = s' u + d' and J (epsilon, psi'')' = s'' u + 2 s' psi'
        perp(u) - s psi'^2 u + omega^2 (B - O) + d'', J = [perp(B - O), -s perp(u)]."""
        c, g = drv.name, drv.link
        s, rate, accel = motion
        o, v_o, a_o = self.carried(drv.pivot_on, f"{g}.at", bodies)
        a, v_a, a_a = self.carried(drv.base_on, f"{c}.base", bodies)
        d, b, sine = self.triangle(drv, s, o, a)
        pin = self.vec(f"{c}.pin")
        rr = _dot(pin, pin)
        u = ((b[0] - d[0]) / s, (b[1] - d[1]) / s)
        n, nb = _perp(u), _perp(b)
        jac = mpmath.matrix([[nb[0], -s * n[0]], [nb[1], -s * n[1]]])
        rhs = _add(_scale(rate, u), (v_a[0] - v_o[0], v_a[1] - v_o[1]))
        omega, psi1 = mpmath.lu_solve(jac, mpmath.matrix(list(rhs)))
        rhs = _add(_scale(accel - s * psi1 * psi1, u), _scale(2 * rate * psi1, n))
        rhs = _add(rhs, _scale(omega * omega, b), (a_a[0] - a_o[0], a_a[1] - a_o[1]))
        eps, psi2 = mpmath.lu_solve(jac, mpmath.matrix(list(rhs)))
        i = (_dot(pin, b) / rr, _cross(pin, b) / rr)  # R(theta) pin = B - O
        body = _Body(o, v_o, a_o, i, omega, eps)
        return body, _Axis(a, u, s, rate, accel, psi1, psi2, sine, (v_a, a_a))

    def mount(self, att: Attachment, bodies: dict) -> dk.Mount:
        """The motion of an outer pair's external link where the dyad meets it."""
        if att.body is None:  # the frame: a fixed pivot, or a point of a fixed guide
            angle = self.par[att.guide] if att.guide else mpf(0)
            return dk.Mount(self.vec(att.at), direction=angle)
        body, drv = bodies[att.body], self.s.driver_on(att.body)
        if att.at is not None:
            local = self.vec(att.at)
        elif drv.kind == "crank":
            local = (self.par[f"{att.body}.length"], mpf(0))  # the crank's pin A
        elif drv.kind == "cylinder":
            local = self.vec(f"{drv.name}.pin")  # the cylinder's pin B
        else:
            local = (mpf(0), mpf(0))  # the ram's R
        pos, vel, acc = body.point(local)
        if att.guide is None:
            return dk.Mount(pos, vel, acc)
        angle = mpmath.atan2(body.i[1], body.i[0]) + self.par[att.guide]
        return dk.Mount(pos, vel, acc, angle, body.omega, body.epsilon)

    def turn(self, d: DyadSpec, g: str, att: Attachment) -> mpf:
        """The turn of link g from its guide (or link m's) as dyad_kinematics reads it."""
        if g in self.s.translating:
            return self.par[f"{g}.angle"] - self.par[att.guide]
        return self.par[f"{g}.turn"]

    def dyad_inputs(self, d: DyadSpec, bodies: dict) -> dk.DyadInputs:
        branch = 1
        if d.type in _TWO_BRANCHES:
            branch = -1 if self.par[f"{d.prefix}branch"] < 0 else 1
        sliding_m = d.type in ("RTR", "RTT")
        return dk.DyadInputs(
            d.type,
            self.mount(d.k, bodies),
            self.mount(d.p, bodies),
            length_m=mpf(0) if sliding_m else self.par[f"{d.m}.length"],
            length_n=self.par[f"{d.n}.length"],
            turn_m=self.turn(d, d.m, d.k),
            turn_n=self.turn(d, d.n, d.p),
            com_m=self.vec(f"{d.m}.com"),
            com_n=self.vec(f"{d.n}.com"),
            branch=branch,
        )

    def kinematics(self, motions: list[tuple]) -> _Chain:
        """The chain's motion, from the drivers outwards, each driver at its (q, q', q'')
        of ``motions``; _Failure where a cylinder or a dyad does not close."""
        chain = _Chain({}, {}, {}, {})
        for drv, motion in zip(self.s.drivers, motions, strict=True):
            body, axis = self.driver_body(drv, motion, chain.bodies)
            chain.bodies[drv.link] = body
            if axis is not None:
                chain.axes[drv.name] = axis
        for d in self.s.dyads:
            inputs = self.dyad_inputs(d, chain.bodies)
            if _parallel(inputs):
                raise _Failure(SINGULAR, d.name, "its guides (or slot and guide) are parallel")
            r = dk.solve(inputs, dps=self.work)
            if r["status"] != "ok":
                raise _Failure(r["status"], d.name, r["reason"])
            chain.results[d.name] = r
            chain.guides[d.name] = tuple(
                _unit(mount.direction) if slides else None
                for mount, slides in zip((inputs.k, inputs.p), _SLIDES[d.type], strict=True)
            )
            for g, tag in ((d.m, "m"), (d.n, "n")):
                origin = f"{tag}.d"
                chain.bodies[g] = _Body(
                    r[f"{origin}.position"],
                    r[f"{origin}.velocity"],
                    r[f"{origin}.acceleration"],
                    r[f"i_{tag}"],
                    r[f"omega_{tag}"],
                    r[f"epsilon_{tag}"],
                )
        return chain

    def motion(self) -> list[tuple[mpf, mpf, mpf]]:
        """Each driver's coordinate, rate and acceleration inputs (rates 0 without inertia)."""
        motions = []
        for drv in self.s.drivers:
            names = drv.motion(self.s.inertia)
            values = [self.inp[n] for n in names] + [mpf(0)] * (3 - len(names))
            motions.append((values[0], values[1], values[2]))
        return motions

    def mass_terms(self, unit: _Chain) -> list[tuple]:
        """(m, I, V, V', W, W') of every moving body from a chain moved at a unit rate of
        one driver, zero rates of the others and zero accelerations: V and V' its centre
        of mass's velocity and acceleration, W and W' its omega and epsilon."""
        terms = []
        for drv in self.s.drivers:
            c, body = drv.link, unit.bodies[drv.link]
            _, v, a = body.point(self.vec(f"{c}.com"))
            inertia = self.par.get(f"{c}.inertia", mpf(0))
            terms.append((self.par[f"{c}.mass"], inertia, v, a, body.omega, body.epsilon))
            axis, h = unit.axes.get(drv.name), drv.name
            for part, on_rod in (("barrel", False), ("rod", True)) if axis else ():
                com = self.par[f"{h}.{part}.com"]
                _, v, a = axis.point(axis.length - com if on_rod else com, on_rod)
                mass, inertia = self.par[f"{h}.{part}.mass"], self.par[f"{h}.{part}.inertia"]
                terms.append((mass, inertia, v, a, axis.omega, axis.epsilon))
        for d in self.s.dyads:
            r = unit.results[d.name]
            for g, tag in ((d.m, "m"), (d.n, "n")):
                v, a = r[f"{tag}.s.velocity"], r[f"{tag}.s.acceleration"]
                w, e = r[f"omega_{tag}"], r[f"epsilon_{tag}"]
                terms.append((self.par[f"{g}.mass"], self.par[f"{g}.inertia"], v, a, w, e))
        return terms

    def effective_inertia(self, unit: _Chain) -> tuple[mpf, mpf]:
        """(J, dJ/dq) of a scene's only driver from the chain moved at unit driver rate
        and zero driver acceleration (:meth:`mass_terms`)."""
        terms = self.mass_terms(unit)
        j = sum((m * _dot(v, v) + i * w * w for m, i, v, _, w, _ in terms), mpf(0))
        dj = 2 * sum((m * _dot(v, a) + i * w * e for m, i, v, a, w, e in terms), mpf(0))
        return j, dj

    def inertia_matrix(self, motions: list[tuple]) -> dict[str, mpf]:
        """M.<a>.<b> = sum m V_a.V_b + I W_a W_b over every moving body, V_a and W_a its
        centre of mass's velocity and its angular velocity per unit rate of driver a
        (the kinetic energy is q'.M q' / 2)."""
        per_driver = []
        for a in range(len(self.s.drivers)):
            unit = [(q, mpf(1 if b == a else 0), mpf(0)) for b, (q, _, _) in enumerate(motions)]
            per_driver.append(self.mass_terms(self.kinematics(unit)))
        out = {}
        for da, ta in zip(self.s.drivers, per_driver, strict=True):
            for db, tb in zip(self.s.drivers, per_driver, strict=True):
                pairs = zip(ta, tb, strict=True)
                terms = (x[0] * _dot(x[2], y[2]) + x[1] * x[4] * y[4] for x, y in pairs)
                out[f"M.{da.name}.{db.name}"] = sum(terms, mpf(0))
        return out

    def outputs(self) -> dict[str, mpf]:
        """Every output, in the FMU's order; _Failure where a dyad does not close."""
        motions = self.motion()
        chain = self.kinematics(motions)
        reactions = _Kinetostatics(self, chain).run()
        out = {}
        for d in self.s.dyads:
            out.update(_motion_outputs(self.s, d, chain.results[d.name]))
            out.update(reactions[d.name])
            out[f"{d.prefix}conditioning"] = _conditioning(d, chain.results[d.name], chain)
        for drv in self.s.drivers:
            if drv.kind == "cylinder":
                out.update(self.cylinder_outputs(drv, chain))
        out.update(reactions[None])
        if not self.s.inertia:
            return out
        if len(self.s.drivers) == 1:
            drv, (q, _, accel) = self.s.drivers[0], motions[0]
            j, dj = self.effective_inertia(self.kinematics([(q, mpf(1), mpf(0))]))
            out[f"{drv.name}.J"], out[f"{drv.name}.dJdq"] = j, dj
            out[f"{drv.name}.{drv.effort}0"] = out[f"{drv.name}.{drv.effort}"] - j * accel
            return out
        out.update(self.inertia_matrix(motions))
        # h: the balance again with every driver's acceleration zero
        still = [(q, rate, mpf(0)) for q, rate, _ in motions]
        balance = _Kinetostatics(self, self.kinematics(still)).run()[None]
        for drv in self.s.drivers:
            out[f"{drv.name}.{drv.effort}0"] = balance[f"{drv.name}.{drv.effort}"]
        return out

    def cylinder_outputs(self, drv: Driver, chain: _Chain) -> dict[str, mpf]:
        """The link's and the cylinder's angles (rad) and, with inertia, their rates (rad/s,
        rad/s2); pin B (m); the triangle's conditioning."""
        c, g = drv.name, drv.link
        body, axis = chain.bodies[g], chain.axes[c]
        out = {}
        for name, i, w, e in (
            (g, body.i, body.omega, body.epsilon),
            (c, axis.u, axis.omega, axis.epsilon),
        ):
            out[f"{name}.angle"] = mpmath.atan2(i[1], i[0])
            if self.s.inertia:
                out[f"{name}.omega"], out[f"{name}.epsilon"] = w, e
        out[f"{c}.B.position.x"], out[f"{c}.B.position.y"] = axis.point(axis.length, True)[0]
        out[f"{c}.conditioning"] = axis.conditioning
        return out


def _parallel(inputs: dk.DyadInputs) -> bool:
    """Whether a TRT's guides or an RTT's slot and guide are exactly parallel (c = 0)."""
    if inputs.type == "TRT":
        angle = mpf(inputs.p.direction) - mpf(inputs.k.direction)
    elif inputs.type == "RTT":
        angle = mpf(inputs.turn_m)
    else:
        return False
    return mpmath.sin(angle) == 0


class _Loads:
    """The forces (at points) and couples later dyads put on earlier bodies."""

    def __init__(self) -> None:
        self.forces: dict[str, list] = {}
        self.couples: dict[str, list] = {}

    def add(self, body: str | None, point: Vec, force: Vec, couple: mpf) -> None:
        if body is not None:
            self.forces.setdefault(body, []).append((point, force))
            self.couples.setdefault(body, []).append(couple)

    def about(self, body: str, centre: Vec) -> tuple[tuple, mpf]:
        """Their resultant force (N) and moment about ``centre`` (N m) on ``body``."""
        force, moment = (mpf(0), mpf(0)), mpf(0)
        for point, f in self.forces.get(body, []):
            force = _add(force, f)
            moment += _cross((point[0] - centre[0], point[1] - centre[1]), f)
        return force, moment + sum(self.couples.get(body, []), mpf(0))


class _Kinetostatics:
    """The reactions of every dyad, from the last back, and the driver's balance."""

    def __init__(self, ev: _Evaluation, chain: _Chain) -> None:
        self.ev, self.bodies, self.results = ev, chain.bodies, chain.results
        self.guides, self.axes = chain.guides, chain.axes
        self.loads = _Loads()
        self.out: dict[str | None, dict[str, mpf]] = {}  # by dyad name; None: the driver

    def active(self, g: str) -> tuple[tuple, mpf]:
        """The active force (N, at the centre of mass) and moment (N m) inputs on link g."""
        s, inp = self.ev.s, self.ev.inp
        force = (inp[f"{g}.force.x"], inp[f"{g}.force.y"]) if g in s.forces else (0, 0)
        return tuple(mpf(c) for c in force), (inp[f"{g}.moment"] if g in s.moments else mpf(0))

    def link(self, g: str, tag: str, r: dict) -> dict:
        """Link g (``m`` or ``n`` of its dyad's result r) as newton_euler reads a link."""
        ev, inertia = self.ev, self.ev.s.inertia
        zero = mpf(0)
        com = ev.vec(f"{g}.com")
        force, moment = self.active(g)
        extra, extra_moment = self.loads.about(g, r[f"{tag}.s.position"])
        return {
            "dir": r[f"i_{tag}"],
            "length": r[f"l_{tag}"],
            "omega": r[f"omega_{tag}"] if inertia else zero,
            "epsilon": r[f"epsilon_{tag}"] if inertia else zero,
            "accel_d": r[f"{tag}.d.acceleration"] if inertia else (zero, zero),
            "com": com,
            "mass": ev.par[f"{g}.mass"],
            "inertia": ev.par[f"{g}.inertia"],
            "force": _add(force, extra),
            "moment": moment + extra_moment,
        }

    def dyad(self, d: DyadSpec) -> None:
        """One dyad's reactions (outputs), and their opposites on the bodies it hangs on."""
        r = self.results[d.name]
        kinds = PAIRS[d.type]
        gk, gp = self.guides[d.name]
        a, b = equilibrium_system(
            kinds,
            self.link(d.m, "m", r),
            self.link(d.n, "n", r),
            gk,
            gp,
            self.ev.gravity,
        )
        a = mpmath.matrix([[mpf(x) for x in row] for row in a])
        try:
            u = mpmath.lu_solve(a, mpmath.matrix([mpf(x) for x in b]))
        except ZeroDivisionError:
            raise _Failure(SINGULAR, d.name, "its Newton-Euler system is singular") from None
        zero = mpf(0)
        rx = reactions_of_unknowns(kinds, [u[i] for i in range(6)], gk, gp, r["i_m"], None, zero)
        pre, out = d.prefix, self.out.setdefault(d.name, {})
        for pair, kind in (("mk", kinds[0]), ("np", kinds[2]), ("mn", kinds[1])):
            out[f"{pre}R_{pair}.x"], out[f"{pre}R_{pair}.y"] = rx[f"r_{pair}"]
            if kind == "T":
                out[f"{pre}N_{pair}"], out[f"{pre}M_{pair}"] = rx[f"n_{pair}"], rx[f"m_{pair}"]
        minus = lambda v: (-v[0], -v[1])  # noqa: E731
        self.loads.add(d.k.body, r["m.d.position"], minus(rx["r_mk"]), -rx["m_mk"])
        self.loads.add(d.p.body, r["n.d.position"], minus(rx["r_np"]), -rx["m_np"])

    def driver(self, drv: Driver) -> None:
        """A driver's balance: a crank's torque and R_O, a ram's force, N and M."""
        ev = self.ev
        if drv.kind == "cylinder":
            self.cylinder(drv)
            return
        c, body = drv.name, self.bodies[drv.name]
        mass = ev.par[f"{c}.mass"]
        arm = body.arm(ev.vec(f"{c}.com"))
        _, _, a_s = body.point(ev.vec(f"{c}.com"))
        if not ev.s.inertia:
            a_s = (mpf(0), mpf(0))
        known = _add(_scale(mass, ev.gravity), _scale(-mass, a_s))  # weight + inertia, at S
        force, moment = self.loads.about(c, body.position)
        force = _add(force, known)
        moment += _cross(arm, known)
        out = self.out.setdefault(None, {})
        if drv.kind == "crank":
            if ev.s.inertia:
                moment -= ev.par[f"{c}.inertia"] * body.epsilon
            out[f"{c}.torque"] = -moment
            out[f"{c}.R_O.x"], out[f"{c}.R_O.y"] = -force[0], -force[1]
            return
        out[f"{c}.force"] = -_dot(force, body.i)  # the forces on the ram sum to 0
        out[f"{c}.N"] = -_dot(force, _perp(body.i))
        out[f"{c}.M"] = -moment

    def cylinder(self, drv: Driver) -> None:
        """The balance of the barrel (pinned at A, moments about A), the rod (pinned to the
        link at B, moments about B) and the link (about O, moments about O): 9 equations
        in x = (R_A, R_B, R_O, the axial force, N, M), solved by mpmath.lu_solve."""
        axis = self.axes[drv.name]
        h, g = drv.name, drv.link
        link, zero = self.bodies[g], mpf(0)
        u, n = axis.u, _perp(axis.u)
        a_pin, b_pin, o_pin = axis.base, axis.point(axis.length, True)[0], link.position
        ex, ey, none = (mpf(1), zero), (zero, mpf(1)), (zero, zero)
        minus = lambda v: (-v[0], -v[1])  # noqa: E731
        # each body: its moment centre, the unknowns' forces on it (index, force per unit,
        # point, couple per unit), and its known force and moment about the centre
        barrel = [(0, ex, a_pin, 0), (1, ey, a_pin, 0), (6, minus(u), b_pin, 0)]
        barrel += [(7, minus(n), b_pin, 0), (8, none, b_pin, -1)]
        rod = [(2, minus(ex), b_pin, 0), (3, minus(ey), b_pin, 0), (6, u, b_pin, 0)]
        rod += [(7, n, b_pin, 0), (8, none, b_pin, 1)]
        body = [(2, ex, b_pin, 0), (3, ey, b_pin, 0), (4, ex, o_pin, 0), (5, ey, o_pin, 0)]
        parts = [
            (a_pin, barrel, self.part_known(axis, f"{h}.barrel", a_pin, False)),
            (b_pin, rod, self.part_known(axis, f"{h}.rod", b_pin, True)),
            (o_pin, body, self.link_known(g)),
        ]
        rows, rhs = [], []
        for centre, unknowns, (force, moment) in parts:
            fx, fy, mz = ([zero] * 9 for _ in range(3))
            for k, f, point, couple in unknowns:
                fx[k], fy[k] = fx[k] + f[0], fy[k] + f[1]
                mz[k] += _cross(_add(point, minus(centre)), f) + couple
            rows += [fx, fy, mz]
            rhs += [-force[0], -force[1], -moment]
        x = mpmath.lu_solve(mpmath.matrix(rows), mpmath.matrix(rhs))
        out = self.out.setdefault(None, {})
        out[f"{h}.force"], out[f"{h}.N"], out[f"{h}.M"] = x[6], x[7], x[8]
        for name, k in ((f"{h}.R_A", 0), (f"{h}.R_B", 2), (f"{g}.R_O", 4)):
            out[f"{name}.x"], out[f"{name}.y"] = x[k], x[k + 1]
        # the carriers bear the opposites: of R_A at A (the barrel's pin), of R_O at O
        self.loads.add(drv.base_on, a_pin, (-x[0], -x[1]), zero)
        self.loads.add(drv.pivot_on, o_pin, (-x[4], -x[5]), zero)

    def part_known(self, axis: _Axis, prefix: str, centre: Vec, on_rod: bool) -> tuple:
        """The barrel's or the rod's weight and d'Alembert force and moment: (force, moment
        about ``centre``)."""
        ev = self.ev
        mass, com = ev.par[f"{prefix}.mass"], ev.par[f"{prefix}.com"]
        point, _, acc = axis.point(axis.length - com if on_rod else com, on_rod)
        return self.known(mass, ev.par[f"{prefix}.inertia"], point, acc, axis.epsilon, centre)

    def link_known(self, g: str) -> tuple[tuple, mpf]:
        """The cylinder's link's weight, d'Alembert force and moment, its [[load]] tables and
        the reactions of the dyads on it: (force, moment about its pivot O)."""
        ev, link = self.ev, self.bodies[g]
        point, _, acc = link.point(ev.vec(f"{g}.com"))
        mass, inertia = ev.par[f"{g}.mass"], ev.par[f"{g}.inertia"]
        force, moment = self.known(mass, inertia, point, acc, link.epsilon, link.position)
        extra, extra_moment = self.loads.about(g, link.position)
        return _add(force, extra), moment + extra_moment

    def known(self, mass: mpf, inertia: mpf, point: Vec, acc: Vec, eps: mpf, centre: Vec) -> tuple:
        """A body's weight and d'Alembert force m (g - a) at its centre of mass ``point``,
        and their moment about ``centre`` with the d'Alembert couple -I epsilon."""
        zero = mpf(0)
        if not self.ev.s.inertia:
            acc, eps = (zero, zero), zero
        force = _scale(mass, _add(self.ev.gravity, (-acc[0], -acc[1])))
        moment = _cross((point[0] - centre[0], point[1] - centre[1]), force) - inertia * eps
        return force, moment

    def place(self) -> None:
        """Each [[load]] as a force at its point P (the body's point `at`: global
        components, or the body's own turned by its angle) and a couple on its body."""
        ev = self.ev
        for name, link, components, has_force, has_moment in ev.s.point_loads:
            body = self.bodies[link]
            point, _, _ = body.point(ev.vec(f"{name}.at"))
            zero = mpf(0)
            local = (ev.inp[f"{name}.force.x"], ev.inp[f"{name}.force.y"]) if has_force else None
            force = (zero, zero) if local is None else local
            if local is not None and components == "link":
                force = body.arm(local)  # local[0] i + local[1] j
            couple = ev.inp[f"{name}.moment"] if has_moment else zero
            self.loads.add(link, point, force, couple)

    def run(self) -> dict:
        """The outputs: by dyad name, the drivers' under None (in the drivers' order)."""
        self.place()
        for d in reversed(self.ev.s.dyads):
            self.dyad(d)
        # from the last driver back: a cylinder's reactions load the earlier driver's link
        # that carries it before that driver's balance
        per_driver = {}
        for drv in reversed(self.ev.s.drivers):
            self.out[None] = {}
            self.driver(drv)
            per_driver[drv.name] = self.out[None]
        self.out[None] = {k: v for d in self.ev.s.drivers for k, v in per_driver[d.name].items()}
        return self.out


def _motion_outputs(s: MechanismScene, d: DyadSpec, r: dict) -> dict[str, mpf]:
    """A dyad's link angles (rad) and rates (rad/s, rad/s2), a sliding length, its pair
    points (m) and slides (m)."""
    out = {}
    for g, tag in ((d.m, "m"), (d.n, "n")):
        if g not in s.translating:
            out[f"{g}.angle"] = r[f"angle_{tag}"]
            if s.inertia:
                out[f"{g}.omega"], out[f"{g}.epsilon"] = r[f"omega_{tag}"], r[f"epsilon_{tag}"]
        if tag == "m" and d.type in ("RTR", "RTT"):
            out[f"{g}.length"] = r["l_m"]
    for pair, point in (("D_m", "m.d"), ("E", "e"), ("D_n", "n.d")):
        x, y = r[f"{point}.position"]
        out[f"{d.prefix}{pair}.position.x"], out[f"{d.prefix}{pair}.position.y"] = x, y
    for side, slides in zip("kp", _SLIDES[d.type], strict=True):
        if slides:
            out[f"{d.prefix}slide_{side}"] = r[f"s_{side}"]
    return out


def _conditioning(d: DyadSpec, r: dict, chain: _Chain) -> mpf:
    """The dyad's conditioning in [0, 1], as modelDescription/scenes/README.md and README.md
    define it: RRR |i_m . j_n|, RRT |i_n . i_k|, RTR the smaller of |i_beta . i_m| and |D_m D_n| /
    (l_m + l_n), TRT |j_k . i_p|, RTT |j_k . i_m|."""
    i_m, i_n = r["i_m"], r["i_n"]
    i_k, i_p = chain.guides[d.name]
    if d.type == "RRR":
        return abs(_dot(i_m, _perp(i_n)))
    if d.type == "RRT":
        return abs(_dot(i_n, i_k))
    if d.type == "TRT":
        return abs(_dot(_perp(i_k), i_p))
    if d.type == "RTT":
        return abs(_dot(_perp(i_k), i_m))
    dm_dn = _add(_scale(r["l_m"], i_m), _scale(-r["l_n"], i_n))  # D_n - D_m
    dist = mpmath.sqrt(_dot(dm_dn, dm_dn))
    slant = abs(_dot(dm_dn, i_m)) / dist if dist > 0 else mpf(0)
    return min(slant, dist / (r["l_m"] + r["l_n"]))


def _rounded(outputs: dict, dps: int) -> dict:
    with mpmath.workdps(dps):
        return {k: +v for k, v in outputs.items()}


def _run(
    scene: Mapping | str | os.PathLike | MechanismScene, values: Mapping, dps: int, what: str
) -> Result:
    """evaluate (``what`` = "outputs") or assembly_status ("status")."""
    if isinstance(dps, bool) or not isinstance(dps, int) or dps < 5:
        raise ValueError(f"dps must be an integer >= 5, not {dps!r}")
    ms = scene if isinstance(scene, MechanismScene) else read_scene(scene)
    inputs, params = ms.split(values)
    work = dps + _GUARD
    with mpmath.workdps(work):
        ev = _Evaluation(ms, inputs, params, work)
        try:
            if what == "status":
                ev.kinematics([(q, mpf(0), mpf(0)) for q, _, _ in ev.motion()])
                outputs = {}
            else:
                outputs = ev.outputs()
        except _Failure as failure:
            status, dyad, reason = failure.args
            return Result(status, dyad, reason, {})
    return Result(OK, None, "", _rounded(outputs, dps))


def evaluate(
    scene: Mapping | str | os.PathLike | MechanismScene,
    values: Mapping[str, float],
    dps: int = 50,
) -> Result:
    """Every Real output of the scene's mechanism FMU at the inputs ``values`` (mpf, dps digits).

    ``scene``: a scene file's path, its parsed table or :func:`read_scene`'s result (faster
    when called often). ``values``: FMU variable name -> float, the inputs (the driver's
    motion in rad, rad/s, rad/s2 or m, m/s, m/s2; the loads in N and N m; an input left out
    keeps its start value) and, optionally, any parameter of the scene under its FMU name
    (``gravity.y`` m/s2, ``engine.branch``, ``rocker.mass`` kg, ``hoist.pin.x`` m, ...;
    tunable or baked).
    Returns a :class:`Result`; its ``outputs`` (when ok) are named and scaled as the FMU's.
    """
    return _run(scene, values, dps, "outputs")


def assembly_status(
    scene: Mapping | str | os.PathLike | MechanismScene,
    values: Mapping[str, float],
    dps: int = 50,
) -> Result:
    """The status :func:`evaluate` would give, without its outputs: the chain's kinematics
    at zero driver rate, no reactions (about half the time of :func:`evaluate`)."""
    return _run(scene, values, dps, "status")

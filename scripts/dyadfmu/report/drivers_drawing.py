"""A mechanism with several drivers (cranks, rams, cylinders, cylinders pinned to moving
links) drawn to scale from its mechanism FMU's own outputs at poses along a motion, and
every driver's effort along that motion.

The motion: every driver given a range (``--range INPUT MIN MAX``, INPUT its coordinate:
``C.angle`` rad, ``R.position`` m, ``Y.length`` m) moves linearly from MIN to MAX while a
share of the motion goes from 0 to 1; the others stay at the FMU's start values. With a
duration the drivers move at the constant rates this gives (no acceleration).

The drawing (:func:`draw`, :func:`figure`) uses the parts of
:mod:`.cylinder_drawing`: the frame's pins as ground symbols; each driver's link as the
polygon of its points (its pivot, a crank's pin, a cylinder's pin B, the pins of the
cylinders it carries, the pairs of the dyads on it, its loads' points); each dyad's links
between their pair positions; each cylinder as a barrel from A and a rod to B, the
barrel's length a fixed share of its shortest length drawn. Several poses are overlaid,
the later fainter, numbered at the point farthest from the first driver's pivot. At one
pose the pair reactions (``L.R_O``, ``Y.R_A``, ``Y.R_B`` of a cylinder Y turning L, a
crank's ``C.R_O``, a ram's guide force ``R.N``, the dyads' ``R_mk``, ``R_mn``, ``R_np``)
and the loads are arrows on one scale, per kN (per N where every force is below 1 kN).

Every moving point is the FMU's output or is placed with its outputs: B
(``Y.B.position``), the dyads' pairs (``DYAD.D_m/E/D_n.position``); a cylinder's O and A
on a moving link and a load's point turned with the carrier's angle output (a crank's
angle and a ram's position are its inputs) from the carrier's origin. Each cylinder's
|O B| and |A B| are checked against its pin and its length, so that an FMU built from
another version of the scene is refused.

The effort figure (:func:`effort_curves`, :func:`effort_figure`): each cylinder's and
ram's force (kN) and each crank's torque (N m) along the motion, with the loads and
without them, at rest and (with a duration) moving.

Command: ``python -m dyadfmu.report.drivers_drawing SCENE.toml --range INPUT MIN MAX ...
--out DIR`` (``--help``).
"""

from __future__ import annotations

import argparse
import math
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from .. import argtypes, paths  # noqa: E402
from ..mechanisms import geometry as geo  # noqa: E402
from ..sweep.sources import SourceError, check_scene  # noqa: E402
from . import cylinder_drawing as cd  # noqa: E402
from . import sketch  # noqa: E402

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from matplotlib.axes import Axes

__all__ = [
    "Driver",
    "DriversScene",
    "Mechanism",
    "DriversPose",
    "read_scene",
    "motion",
    "evaluate",
    "pose",
    "draw",
    "figure",
    "effort_curves",
    "effort_figure",
    "main",
]

DrawingError = cd.DrawingError
#: Each kind's coordinate, rate, acceleration and effort (inputs and output), and units.
KINDS = {
    "crank": ("angle", "omega", "epsilon", "torque", "rad", "N m", 1.0),
    "ram": ("position", "velocity", "acceleration", "force", "m", "kN", 1e3),
    "cylinder": ("length", "velocity", "acceleration", "force", "m", "kN", 1e3),
}


# ---------------------------------------------------------------------------
# the scene
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Driver:
    """One driver of the scene: its kind, name, the link it moves (a crank's and a ram's
    own name) and its table."""

    kind: str
    name: str
    link: str
    table: dict

    def input(self, which: int) -> str:
        """Its coordinate (0), rate (1) or acceleration (2) input."""
        return f"{self.name}.{KINDS[self.kind][which]}"

    @property
    def effort(self) -> str:
        """Its effort output: a crank's torque, a ram's or a cylinder's force."""
        return f"{self.name}.{KINDS[self.kind][3]}"

    @property
    def unit(self) -> tuple[str, str, float]:
        """(the coordinate's unit, the effort's unit as drawn, N or N m per that unit)."""
        return KINDS[self.kind][4:]


@dataclass(frozen=True)
class DriversScene:
    """What the drawing takes of a scene: its drivers (cranks, rams, cylinders, each in
    file order), dyads, links' centres of mass and [[load]] tables."""

    path: Path
    identifier: str
    drivers: tuple
    dyads: tuple
    link_coms: dict
    loads: tuple

    def driver(self, link: str) -> Driver | None:
        """The driver moving ``link``, or None (the frame, a dyad's link)."""
        return next((d for d in self.drivers if d.link == link), None)


def _tables(data: dict, kind: str) -> list:
    """A driver kind's tables: ``[kind]`` (one) or ``[[kind]]`` (several)."""
    value = data.get(kind, [])
    return [value] if isinstance(value, dict) else list(value)


def read_scene(path: Path | str) -> DriversScene:
    """The scene file, checked by the scene generator (its messages name FILE:LINE); a
    DrawingError where it is invalid or has no driver this drawing knows."""
    path = Path(path)
    try:
        check_scene(path)
    except SourceError as e:
        raise DrawingError(str(e)) from None
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    drivers = []
    for kind in KINDS:
        for t in _tables(data, kind):
            name = t.get("name", kind)
            drivers.append(Driver(kind, name, t["link"] if kind == "cylinder" else name, t))
    if not drivers:
        raise DrawingError(f"{path}: no [crank], [ram] or [cylinder]: nothing drives it")
    # A scene with a driver has internal kinematics unless it says otherwise.
    if data["scene"].get("kinematics", "internal") != "internal":
        raise DrawingError(f'{path}: the drawing needs kinematics = "internal"')
    links = {t["name"]: tuple(t.get("com", (0.0, 0.0))) for t in data.get("link", [])}
    links.update({d.link: tuple(d.table.get("com", (0.0, 0.0))) for d in drivers})
    return DriversScene(
        path=path,
        identifier=data["scene"]["identifier"],
        drivers=tuple(drivers),
        dyads=tuple(data.get("dyad", [])),
        link_coms=links,
        loads=tuple(data.get("load", [])),
    )


def _mount(value: object) -> tuple[str, tuple]:
    """A cylinder's ``at`` or ``base``: (its carrier, "frame" or a driver's link; the point
    in the carrier's frame)."""
    if isinstance(value, dict):
        return value["link"], tuple(value["at"])
    return "frame", tuple(value)


# ---------------------------------------------------------------------------
# the FMU
# ---------------------------------------------------------------------------
class Mechanism(cd.Instance):
    """The scene's mechanism FMU, stepped at the drivers' coordinates: ``at`` gives its
    outputs; the drivers' fixed points and the loads' points are read once (the FMU's
    tunable parameters, else the scene's numbers)."""

    def _start(self) -> None:
        """The drivers' points (a cylinder's O, A, B in their carriers' frames; a crank's
        pivot and length; a ram's origin and guide) and the loads' points read."""
        self.fixed = {}
        for d in self.scene.drivers:
            t = d.table
            if d.kind == "cylinder":
                self.fixed[d.name] = {
                    "O": self._point(f"{d.link}.at", _mount(t.get("at", (0.0, 0.0)))[1]),
                    "A": self._point(f"{d.name}.base", _mount(t["base"])[1]),
                    "B": self._point(f"{d.name}.pin", t["pin"]),
                }
            elif d.kind == "crank":
                length = self._number(f"{d.name}.length", t["length"])
                self.fixed[d.name] = {"O": self._point(f"{d.name}.at", t.get("at", (0.0, 0.0)))}
                self.fixed[d.name]["A"] = np.array([length, 0.0])
            else:
                self.fixed[d.name] = {"O": self._point(f"{d.name}.at", t.get("at", (0.0, 0.0)))}
                self.fixed[d.name]["guide"] = self._number(f"{d.name}.guide", t.get("guide", 0.0))
        self.load_at = {
            load["name"]: self._point(
                f"{load['name']}.at", load.get("at", self.scene.link_coms.get(load["link"]))
            )
            for load in self.scene.loads
        }
        self.rated = all(d.input(1) in self.inputs for d in self.scene.drivers)

    def _number(self, name: str, default: float) -> float:
        """The parameter ``name``, the FMU's where it has it (tunable), else the default."""
        return float(self.slave.get(name) if name in self.slave.names else default)

    def _need(self) -> list:
        """The outputs drawn: each driver's effort, each cylinder's B, axis and link angle,
        each dyad's pairs, the angle of each dyad link a load is on."""
        need = []
        for d in self.scene.drivers:
            need.append(d.effort)
            if d.kind == "cylinder":
                need += [f"{d.name}.B.position.x", f"{d.name}.angle", f"{d.link}.angle"]
        for dyad in self.scene.dyads:
            p = cd._prefix(dyad)
            need += [f"{p}{pair}.position.x" for pair in ("D_m", "E", "D_n")]
        need += [
            f"{load['link']}.angle"
            for load in self.scene.loads
            if self.scene.driver(load["link"]) is None
        ]
        return need

    def motion_inputs(self) -> set:
        """Every driver's coordinate, rate and acceleration."""
        return {d.input(k) for d in self.scene.drivers for k in range(3)}

    def coordinates(self) -> dict:
        """Every driver's coordinate input and its start value."""
        return {d.input(0): self.inputs.get(d.input(0), 0.0) for d in self.scene.drivers}

    def at(self, coordinates: dict, loads: dict, rates: dict | None = None) -> dict:
        """Every Real output with the inputs set: the drivers at ``coordinates`` (input ->
        value; the others at their start values), moving at ``rates`` (coordinate input ->
        rate; 0 where not given) without acceleration, the loads (input -> value) and the
        other loads 0. A DrawingError naming the coordinates where the FMU has no answer."""
        values = {**self.coordinates(), **coordinates}
        where = ", ".join(f"{n} = {values[n]:.6g}" for n in coordinates)
        if self.rated:
            for d in self.scene.drivers:
                values[d.input(1)] = float((rates or {}).get(d.input(0), 0.0))
                values[d.input(2)] = 0.0
        return self.step({**loads, **values}, where)


# ---------------------------------------------------------------------------
# the motion
# ---------------------------------------------------------------------------
def motion(ranges: dict, shares: Sequence[float]) -> list:
    """The drivers' coordinates at each share (0 to 1) of the motion: [{input: value}],
    each input of ``ranges`` (input -> (min, max)) linear from its min to its max."""
    return [{n: lo + float(t) * (hi - lo) for n, (lo, hi) in ranges.items()} for t in shares]


def rates(ranges: dict, duration: float | None) -> dict:
    """Each ranged coordinate's rate when the motion takes ``duration`` s (none without)."""
    if not duration:
        return {}
    return {n: (hi - lo) / duration for n, (lo, hi) in ranges.items()}


def evaluate(
    mechanism: Mechanism, ranges: dict, shares: Sequence[float], loads: dict, speeds: dict | None
) -> tuple[list, list]:
    """The FMU's outputs at each share of the motion over ``ranges`` (see :func:`motion`),
    moving at ``speeds`` (see :meth:`Mechanism.at`): ([row, or None where the FMU has no
    answer], [None, or the reason])."""
    rows, reasons = [], []
    for coordinates in motion(ranges, shares):
        try:
            rows.append(mechanism.at(coordinates, loads, speeds))
            reasons.append(None)
        except DrawingError as e:
            rows.append(None)
            reasons.append(str(e))
    return rows, reasons


# ---------------------------------------------------------------------------
# one pose: the points, bodies and forces drawn
# ---------------------------------------------------------------------------
@dataclass(kw_only=True)
class DriversPose(cd.Drawn):
    """One pose as drawn: :class:`.cylinder_drawing.Drawn` with its share of the motion,
    the drivers' coordinates, each body's origin and angle and each cylinder's barrel and
    rod."""

    share: float
    coordinates: dict
    frames: dict = field(default_factory=dict)
    parts: dict = field(default_factory=dict)
    reactions: list = field(default_factory=list)

    def cylinders(self) -> dict:
        """Each cylinder's barrel and rod, by its name."""
        return self.parts


def _on(pose_: DriversPose, carrier: str, local: Sequence) -> np.ndarray:
    """A point given in a carrier's frame ("frame": global), in global coordinates."""
    if carrier == "frame":
        return np.asarray(local, dtype=float)
    origin, angle = pose_.frames[carrier]
    return origin + cd._turned(angle, np.asarray(local, dtype=float))


def _fix(pose_: DriversPose, key: str, carrier: str, at: np.ndarray) -> None:
    """A pin ``key`` at ``at`` on ``carrier``: a ground pivot on the frame, else a point of
    the carrier's polygon."""
    pose_.points[key] = _on(pose_, carrier, at)
    pose_.pins.append(key)
    if carrier == "frame":
        pose_.pivots.append(key)
    else:
        pose_.bodies.setdefault(carrier, []).append(key)


def _add_crank(pose_: DriversPose, d: Driver, fixed: dict) -> None:
    """A crank: its pivot O on the frame, its pin A at its angle (its input)."""
    angle = float(pose_.outputs[d.input(0)])
    _fix(pose_, f"{d.name}.O", "frame", fixed["O"])
    pose_.frames[d.link] = (pose_.points[f"{d.name}.O"], angle)
    _fix(pose_, f"{d.name}.A", d.link, fixed["A"])
    pose_.bodies[d.link].insert(0, f"{d.name}.O")
    pose_.reactions.append((f"{d.name}.R_O", d.link, f"{d.name}.O"))


def _add_ram(pose_: DriversPose, d: Driver, fixed: dict) -> None:
    """A ram: its point R along its guide (its position input), a block on a rail."""
    angle = fixed["guide"]
    key = f"{d.name}.R"
    pose_.points[key] = fixed["O"] + float(pose_.outputs[d.input(0)]) * geo.unit(angle)
    pose_.frames[d.link] = (pose_.points[key], angle)
    pose_.bodies.setdefault(d.link, []).append(key)
    pose_.sliders.append(key)
    pose_.guides.append((key, angle))
    normal = float(pose_.outputs.get(f"{d.name}.N", 0.0)) * geo.rot90(geo.unit(angle))
    pose_.forces.append((f"{d.name}.N", d.link, key, normal, False))


def _add_cylinder(pose_: DriversPose, d: Driver, fixed: dict, barrel: float) -> None:
    """A cylinder: O and A on their carriers, B the output, the barrel along its axis."""
    out, y = pose_.outputs, d.name
    o_on, a_on = _mount(d.table.get("at", (0.0, 0.0)))[0], _mount(d.table["base"])[0]
    _fix(pose_, f"{d.link}.O", o_on, fixed["O"])
    _fix(pose_, f"{y}.A", a_on, fixed["A"])
    b = cd._vector(out, f"{y}.B.position")
    pose_.points[f"{y}.B"] = b
    pose_.pins.append(f"{y}.B")
    pose_.frames[d.link] = (pose_.points[f"{d.link}.O"], float(out[f"{d.link}.angle"]))
    pose_.bodies.setdefault(d.link, [])[:0] = [f"{d.link}.O", f"{y}.B"]
    a = pose_.points[f"{y}.A"]
    mouth = a + barrel * geo.unit(float(out[f"{y}.angle"]))
    pose_.parts[y] = ((a, mouth), (mouth, b))
    pose_.reactions += [
        (f"{d.link}.R_O", d.link, f"{d.link}.O"),
        (f"{y}.R_A", f"{y} barrel", f"{y}.A"),
        (f"{y}.R_B", d.link, f"{y}.B"),
    ]


def _check_cylinder(mechanism: Mechanism, pose_: DriversPose, d: Driver) -> None:
    """|O B| and |A B| of the outputs against the pin B and the length (1e-9 relative)."""
    pts = pose_.points
    o, a, b = pts[f"{d.link}.O"], pts[f"{d.name}.A"], pts[f"{d.name}.B"]
    sides = (
        ("|O B|", np.hypot(*(b - o)), float(np.hypot(*mechanism.fixed[d.name]["B"]))),
        ("|A B|", np.hypot(*(b - a)), float(pose_.outputs[d.input(0)])),
    )
    for what, got, want in sides:
        if abs(got - want) > 1e-9 * max(want, np.hypot(*(a - o))):
            raise DrawingError(
                f"{mechanism.path.name} does not match {mechanism.scene.path}: {d.name} "
                f"{what} = {got:.9g} m from its outputs, {want:.9g} m from the scene and "
                "the parameters; build the FMU from this scene"
            )


def _add_loads(pose_: DriversPose, mechanism: Mechanism) -> None:
    """Each [[load]] on its link: a driver's link from its origin and angle, a dyad's link
    from its pair D_m or D_n and its angle output."""
    scene, out = mechanism.scene, pose_.outputs
    for load in scene.loads:
        link = load["link"]
        if link in pose_.frames:
            origin, angle = pose_.frames[link]
        else:
            dyad, side = next((d, s) for d in scene.dyads for s in ("m", "n") if d[s] == link)
            origin = pose_.points[cd._prefix(dyad) + ("D_m" if side == "m" else "D_n")]
            angle = float(out[f"{link}.angle"])
        cd.add_load(pose_, load, origin, angle, mechanism.load_at[load["name"]])


def pose(mechanism: Mechanism, out: dict, barrels: dict, share: float = 0.0) -> DriversPose:
    """What is drawn of the FMU's outputs ``out`` (from :meth:`Mechanism.at`), each
    cylinder's barrel ``barrels[name]`` m long. A DrawingError where the outputs disagree
    with the scene (the FMU built from another scene)."""
    scene = mechanism.scene
    coordinates = {d.input(0): out[d.input(0)] for d in scene.drivers}
    found = DriversPose(outputs=out, share=float(share), coordinates=coordinates)
    for d in scene.drivers:
        if d.kind == "crank":
            _add_crank(found, d, mechanism.fixed[d.name])
        elif d.kind == "ram":
            _add_ram(found, d, mechanism.fixed[d.name])
        else:
            _add_cylinder(found, d, mechanism.fixed[d.name], barrels[d.name])
            _check_cylinder(mechanism, found, d)
    cd._add_dyads(found, scene.dyads)
    _add_loads(found, mechanism)
    cd.add_reactions(found, found.reactions + cd.dyad_reactions(scene.dyads))
    size = max(np.ptp(np.array(list(found.points.values())), axis=0).max(), 1e-3)
    for body, keys in found.bodies.items():
        found.bodies[body] = cd._ordered(found.points, keys, size)
    return found


# ---------------------------------------------------------------------------
# the drawing
# ---------------------------------------------------------------------------
def force_unit(forces: list) -> tuple[str, float]:
    """The unit the arrows are scaled in: kN, or N where every force is below 1 kN."""
    largest = max((float(np.hypot(*f)) for *_, f, _ in forces), default=0.0)
    return ("kN", 1e3) if largest >= 1e3 else ("N", 1.0)


def body_colours(scene: DriversScene) -> dict:
    """Each moving body's colour: the drivers' links in the drivers' colours, the dyads'
    links in the links' colours, in turn."""
    palette = (sketch.DRIVER_COLOUR, "#c44e52", "#937860", "#da8bc3")
    colours = {d.link: palette[i % len(palette)] for i, d in enumerate(scene.drivers)}
    links = [d[side] for d in scene.dyads for side in ("m", "n")]
    colours.update(
        {g: sketch.LINK_COLOURS[i % len(sketch.LINK_COLOURS)] for i, g in enumerate(links)}
    )
    return colours


def point_labels(pose_: DriversPose, scene: DriversScene) -> dict:
    """The label of every point drawn: pivots O, cylinder pins A and B, crank pins, the
    dyads' pairs, the loads' names."""
    names = {}
    for d in scene.drivers:
        if d.kind == "cylinder":
            names.update({f"{d.link}.O": f"{d.link} O", f"{d.name}.A": f"{d.name} A"})
            names[f"{d.name}.B"] = f"{d.name} B"
        else:
            names.update({f"{d.name}.{k}": f"{d.name} {k}" for k in ("O", "A", "R")})
    for dyad in scene.dyads:
        p = cd._prefix(dyad)
        names.update({p + k: f"{p}{k}" for k in ("D_m", "E", "D_n")})
    names.update({load["name"]: load["name"] for load in scene.loads})
    return {k: v for k, v in names.items() if k in pose_.points}


def _efforts_text(mechanism: Mechanism, pose_: DriversPose) -> str:
    """Every driver's effort at the pose, in its unit."""
    parts = []
    for d in mechanism.scene.drivers:
        _, unit, per = d.unit
        parts.append(f"{d.effort} = {pose_.outputs[d.effort] / per:.4g} {unit}")
    return ", ".join(parts)


def draw(
    ax: Axes,
    mechanism: Mechanism,
    poses: list,
    reactions_at: int = -1,
    scale: float | None = None,
    unit: tuple[str, float] | None = None,
) -> dict:
    """Draw the poses (from :func:`pose`) overlaid on ``ax`` to scale, the later fainter,
    each numbered, and the forces of pose ``reactions_at`` as arrows on one scale:
    ``scale`` (``unit``, by default kN, or N where every force is below 1 kN, per m of
    arrow) if given, else a round one. Returns {"scale", "unit": (name, N), "arrows":
    {name: patch}, "size": m}."""
    scene, n = mechanism.scene, len(poses)
    size = cd._size(poses)
    u = 0.018 * size
    colours = body_colours(scene)
    cd._draw_frame(ax, poses[0], poses, u)
    origin = next(iter(poses[0].pivots))
    for i in reversed(range(n)):
        alpha = 1.0 - (1.0 - cd.FADED) * i / max(n - 1, 1)
        cd._draw_pose(ax, poses[i], colours, u, (alpha, 1.0 if i == 0 else 0.55), z=2.0 - 0.05 * i)
        cd.tag(ax, poses[i], list(poses[i].points), origin, str(i + 1), alpha)
    names = point_labels(poses[0], scene)
    drawn = cd._drawn_points(poses)
    sketch.label_points(
        ax, poses[0].points, names, size, fontsize=7, drop_dotted=False, avoid=drawn
    )
    cylinders = {d.name: d.name for d in scene.drivers if d.kind == "cylinder"}
    cd._label_bodies(ax, poses[0], cylinders, colours, u)
    loaded = poses[reactions_at]
    unit = unit or force_unit(loaded.forces)
    scale = sketch.checked_scale(scale) or cd.force_scale(loaded.forces, size, unit[1])
    arrows = cd._arrows(ax, loaded, scale, u, point_labels(loaded, scene), unit)
    if arrows:
        number = reactions_at % n + 1
        ax.legend(
            handles=list(arrows.values()),
            loc="upper center",
            bbox_to_anchor=(0.5, -0.08),
            ncol=2,
            fontsize=7,
            title=f"forces at pose {number}; scale {scale:g} {unit[0]} per m of arrow\n"
            + _efforts_text(mechanism, loaded),
            title_fontsize=7.5,
            framealpha=0.9,
        )
    sketch.finish_axes(ax, 0.05)
    return {"scale": scale, "unit": unit, "arrows": arrows, "size": size}


def _coordinate(d: Driver, value: float) -> str:
    """A driver's coordinate as written: a crank's angle in degrees, else metres."""
    return cd._degrees(value) if d.kind == "crank" else f"{value:.3g} m"


def _poses_text(mechanism: Mechanism, poses: list, ranges: dict) -> str:
    """The ranged coordinates at each pose, one line per driver."""
    lines = []
    for d in mechanism.scene.drivers:
        if d.input(0) in ranges:
            values = ", ".join(_coordinate(d, p.coordinates[d.input(0)]) for p in poses)
            lines.append(f"{d.input(0)}: {values}")
    return "\n".join(lines)


def barrels(mechanism: Mechanism, coordinates: list) -> dict:
    """Each cylinder's barrel: ``cd.BARREL_SHARE`` of its shortest length drawn."""
    start = mechanism.coordinates()
    return {
        d.name: cd.BARREL_SHARE * min(c.get(d.input(0), start[d.input(0)]) for c in coordinates)
        for d in mechanism.scene.drivers
        if d.kind == "cylinder"
    }


def figure(
    mechanism: Mechanism,
    ranges: dict,
    shares: Sequence[float],
    loads: dict,
    path: Path | str,
    reactions_at: int = -1,
) -> dict:
    """Save a PNG of the mechanism at the ``shares`` of the motion over ``ranges`` (input
    -> (min, max)) overlaid, with the ``loads`` (input -> value) and the forces at pose
    ``reactions_at``. Returns what :func:`draw` returns, with "poses" and "path"."""
    coordinates = motion(ranges, shares)
    lengths = barrels(mechanism, coordinates)
    poses = [
        pose(mechanism, mechanism.at(c, loads), lengths, t)
        for c, t in zip(coordinates, shares, strict=True)
    ]
    fig, ax = plt.subplots(figsize=(8.5, 8.0))
    drawn = draw(ax, mechanism, poses, reactions_at)
    ax.set_title(
        f"{mechanism.scene.identifier}, drawn to scale from the FMU's outputs; poses "
        f"1-{len(poses)}:\n" + _poses_text(mechanism, poses, ranges),
        fontsize=8.5,
    )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=80, bbox_inches="tight")
    plt.close(fig)
    return {**drawn, "poses": poses, "path": path}


# ---------------------------------------------------------------------------
# the efforts along the motion
# ---------------------------------------------------------------------------
def effort_curves(
    mechanism: Mechanism, ranges: dict, shares: Sequence[float], loads: dict, duration: float | None
) -> dict:
    """Every driver's effort along the motion: {(loaded, moving): {"share": array,
    effort output: array (N or N m)}} with the loads and without them (where any is not
    0), at rest and (where the FMU has inertia and a duration is given) moving over the
    motion in ``duration`` s."""
    cases = [(True, False)]
    if any(v != 0.0 for v in loads.values()):
        cases.append((False, False))
    if mechanism.rated and duration:
        cases += [(loaded, True) for loaded, _ in list(cases)]
    speeds = rates(ranges, duration)
    curves = {}
    for loaded, moving in cases:
        rows = [
            mechanism.at(c, loads if loaded else {}, speeds if moving else None)
            for c in motion(ranges, shares)
        ]
        curve = {"share": np.asarray(shares, dtype=float)}
        curve.update(
            {d.effort: np.array([r[d.effort] for r in rows]) for d in mechanism.scene.drivers}
        )
        curves[(loaded, moving)] = curve
    return curves


def _load_text(name: str, value: float) -> str:
    """A load input and its value, in kN from 1 kN on, else in N (N m for a moment)."""
    if name.endswith(".moment"):
        return f"{name} = {value:.4g} N m"
    return f"{name} = {value / 1e3:.4g} kN" if abs(value) >= 1e3 else f"{name} = {value:.4g} N"


def _case_label(loads: dict, loaded: bool, moving: bool, duration: float | None) -> str:
    """A curve's case: which loads, at rest or moving."""
    given = ", ".join(_load_text(k, v) for k, v in loads.items() if v != 0.0)
    what = f"with {given}" if loaded and given else "loads 0"
    return f"{what}, " + (f"moving over the motion in {duration:g} s" if moving else "at rest")


def _mark_poses(ax: Axes, marks: Sequence[float]) -> None:
    """The zero line, a grid, and the poses drawn (shares) as numbered vertical lines."""
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.grid(True, lw=0.3, alpha=0.5)
    for k, t in enumerate(marks):
        ax.axvline(100.0 * t, color="0.6", lw=0.6, ls=":")
        ax.annotate(
            str(k + 1),
            (100.0 * t, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(2, -10),
            textcoords="offset points",
            fontsize=8,
            color="0.4",
        )


def effort_figure(
    mechanism: Mechanism,
    curves: dict,
    loads: dict,
    ranges: dict,
    path: Path | str,
    duration: float | None = None,
    marks: Sequence[float] = (),
) -> dict:
    """Save a PNG of the curves of :func:`effort_curves`: the forces (kN) of the cylinders
    and rams in one panel, the cranks' torques (N m) in another, against the share of the
    motion (%), the poses drawn (``marks``, shares) as numbered lines. Returns
    {(effort output, loaded, moving): line} with "path"."""
    drivers = mechanism.scene.drivers
    groups = [[d for d in drivers if d.kind != "crank"], [d for d in drivers if d.kind == "crank"]]
    groups = [g for g in groups if g]
    fig, axes = plt.subplots(
        len(groups), 1, figsize=(8.0, 3.2 + 2.6 * len(groups)), sharex=True, squeeze=False
    )
    lines = {}
    styles = {(True, False): "-", (False, False): "--", (True, True): ":", (False, True): "-."}
    for ax, group in zip(axes[:, 0], groups, strict=True):
        for i, d in enumerate(group):
            _, unit, per = d.unit
            colour = sketch.ARROW_COLOURS[i % len(sketch.ARROW_COLOURS)]
            for (loaded, moving), c in curves.items():
                (lines[(d.effort, loaded, moving)],) = ax.plot(
                    100.0 * c["share"],
                    c[d.effort] / per,
                    color=colour,
                    ls=styles[(loaded, moving)],
                    lw=1.5,
                    label=d.effort if (loaded, moving) == (True, False) else None,
                )
        ax.set_ylabel("force [kN]" if group[0].kind != "crank" else "torque [N m]")
        _mark_poses(ax, marks)
        cases = [
            Line2D(
                [], [], color="0.2", ls=styles[k], lw=1.2, label=_case_label(loads, *k, duration)
            )
            for k in curves
        ]
        ax.legend(handles=ax.get_legend_handles_labels()[0] + cases, fontsize=7, loc="best")
    axes[0, 0].set_title(
        f"{mechanism.scene.identifier}: every driver's effort along the motion", fontsize=9
    )
    spans = ", ".join(f"{n} {lo:.4g} to {hi:.4g}" for n, (lo, hi) in ranges.items())
    axes[-1, 0].set_xlabel(f"share of the motion [%]: {spans}", fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=80, bbox_inches="tight")
    plt.close(fig)
    return {**lines, "path": path}


# ---------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------
def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m dyadfmu.report.drivers_drawing",
        description="Draw a mechanism with several drivers (cranks, rams, cylinders, "
        "cylinders pinned to moving links) to scale from its built mechanism FMU's outputs "
        "at poses along a motion in which every driver given a --range moves linearly from "
        "its MIN to its MAX (the others stay at the FMU's start values): the poses "
        "overlaid, the later fainter, with the pair reactions and applied loads at one of "
        "them as arrows on one scale (OUT/<identifier>.png); and every driver's effort "
        "along the motion, cylinder and ram forces in kN, crank torques in N m, with and "
        "without the loads (OUT/<identifier>_forces.png).",
    )
    p.add_argument("scene", type=Path, help="the scene file (TOML)")
    p.add_argument(
        "--range",
        nargs=3,
        action="append",
        required=True,
        metavar=("INPUT", "MIN", "MAX"),
        help="a driver's coordinate input (C.angle in rad, R.position or Y.length in m) and "
        "its value at the start and at the end of the motion; repeatable, one per driver",
    )
    p.add_argument(
        "--positions",
        type=argtypes.whole(2, 6),
        default=3,
        help="how many poses evenly along the motion, its ends included, are drawn (default 3)",
    )
    p.add_argument(
        "--reactions-at",
        type=argtypes.whole(1, 6),
        default=None,
        help="which pose (1 the start) carries the force arrows (default the middle one)",
    )
    cd.load_options(p)
    p.add_argument(
        "--duration",
        type=argtypes.real(0.0, 1e4, above=True),
        default=None,
        help="the motion's duration (s): adds the efforts moving at the constant rates this "
        "gives (default: at rest only)",
    )
    p.add_argument(
        "--samples",
        type=argtypes.whole(2, 10_000),
        default=101,
        help="points along the motion in the effort figure (default 101)",
    )
    cd.source_options(p, "drivers")
    return p


def ranges_given(mechanism: Mechanism, given: list) -> dict:
    """The --range triples as {input: (min, max)}: each a driver's coordinate, once, its
    ends finite numbers; a DrawingError naming the first that is not."""
    known = [d.input(0) for d in mechanism.scene.drivers]
    found = {}
    for name, low, high in given:
        if name not in known:
            raise DrawingError(
                f"--range {name}: not a driver's coordinate of {mechanism.path.name} (its "
                f"drivers: {', '.join(known)})"
            )
        if name in found:
            raise DrawingError(f"--range {name}: given twice")
        try:
            ends = (float(low), float(high))
        except ValueError:
            raise DrawingError(f"--range {name}: not numbers: {low!r} {high!r}") from None
        if not all(math.isfinite(v) for v in ends):
            raise DrawingError(f"--range {name}: not finite: {low} {high}")
        found[name] = ends
    return found


def _run(args: argparse.Namespace, say: Callable[[str], None]) -> list:
    """Read, evaluate, draw; returns the files written."""
    scene = read_scene(args.scene)
    fmu = paths.built_fmu(scene.identifier, args.fmi, args.build, how="cmake --build build")
    mechanism = Mechanism(scene, fmu, dict(args.set))
    try:
        loads = cd.loads_given(mechanism, args.load)
        ranges = ranges_given(mechanism, args.range)
        at = (args.positions - 1) // 2 if args.reactions_at is None else args.reactions_at - 1
        if at >= args.positions:
            raise DrawingError(f"--reactions-at {args.reactions_at}: only {args.positions} poses")
        shares = np.linspace(0.0, 1.0, args.positions)
        args.out.mkdir(parents=True, exist_ok=True)
        say(f"{scene.identifier}: {args.positions} poses from {fmu}")
        drawing = figure(mechanism, ranges, shares, loads, args.out / f"{scene.identifier}.png", at)
        say(f"{scene.identifier}: the efforts at {args.samples} points along the motion")
        curves = effort_curves(
            mechanism, ranges, np.linspace(0.0, 1.0, args.samples), loads, args.duration
        )
        efforts = effort_figure(
            mechanism,
            curves,
            loads,
            ranges,
            args.out / f"{scene.identifier}_forces.png",
            args.duration,
            shares,
        )
    finally:
        mechanism.close()
    return [drawing["path"], efforts["path"]]


def main(argv: list[str] | None = None) -> int:
    """The command: draw the scene's mechanism along the motion and its drivers' efforts;
    prints the files written."""
    return cd.run_command(_parser(), argv, _run)


if __name__ == "__main__":
    sys.exit(main())

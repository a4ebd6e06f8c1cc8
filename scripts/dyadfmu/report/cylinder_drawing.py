"""A mechanism driven by a hydraulic cylinder (a scene's ``[cylinder]``) drawn to scale from
its mechanism FMU's own outputs at chosen cylinder lengths, and the cylinder's axial force
over its stroke.

The drawing (:func:`draw`, :func:`figure`): the frame's pins (O, A and every fixed pivot of a
dyad) as ground symbols; the link the cylinder turns as the polygon of its points (O, B, the
pairs of the dyads on it, the points of its ``[[load]]`` tables); each dyad's links between
their pair positions (a link carrying more points as a polygon too); the cylinder as a
barrel from A and a thinner rod to B, the barrel's length a fixed share (``BARREL_SHARE``)
of the shortest length drawn, as a real barrel's does not change. Several lengths are
overlaid, the later ones fainter. At one of them the pair reactions (``LINK.R_O`` on the
link at O, ``NAME.R_A`` on the barrel at A, ``NAME.R_B`` on the link at B, each dyad's
``R_mk``, ``R_mn``, ``R_np``) and the applied forces of the ``[[load]]`` tables are arrows
from their points, all on one force scale (kN per metre of arrow, in the legend).

Every moving point is an output of the FMU at that length (``NAME.B.position``,
``DYAD.D_m/E/D_n.position``); a load's point, which is no output, is placed with the FMU's
``LINK.angle``. The frame's pins O and A and the points of loads are the FMU's parameters
where they are tunable, else the scene's numbers; the outputs are checked against them
(|O B| and |A B|), so that an FMU built from another version of the scene is refused.

The force figure (:func:`force_figure`): ``NAME.force`` (kN) against the link's angle (deg)
over the stroke, with the loads and without them, at rest and at a constant extension rate,
and below it what the rate adds.

Command: ``python -m dyadfmu.report.cylinder_drawing SCENE.toml --stroke MIN MAX --out DIR``
(``--help``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from .. import argtypes, paths  # noqa: E402
from ..fmi.slave import Slave, SlaveError  # noqa: E402
from ..mechanisms import geometry as geo  # noqa: E402
from ..sweep.sources import SourceError, check_scene  # noqa: E402
from . import sketch  # noqa: E402

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from matplotlib.axes import Axes

__all__ = [
    "BARREL_SHARE",
    "CylinderScene",
    "Machine",
    "Pose",
    "read_scene",
    "pose",
    "draw",
    "figure",
    "force_curves",
    "force_figure",
    "main",
]

#: The barrel's length as a share of the shortest cylinder length drawn.
BARREL_SHARE = 0.8
#: Line widths (points) of the barrel and of the rod.
BARREL_WIDTH, ROD_WIDTH = 3.0 * sketch.LINK_WIDTH, 1.2 * sketch.LINK_WIDTH
BARREL_COLOUR, ROD_COLOUR = "0.3", "0.62"
#: The opacity of the last length drawn (the first is opaque, those between in proportion).
FADED = 0.3
#: The longest arrow as a share of the mechanism's size, at most.
ARROW_SHARE = 0.4
#: Each step of a communication with the FMU (s); its outputs depend on its inputs alone.
STEP = 1e-3


class DrawingError(ValueError):
    """A scene, FMU or argument the drawing cannot use; one line naming it."""


# ---------------------------------------------------------------------------
# the scene
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class CylinderScene:
    """What the drawing takes of a scene with a ``[cylinder]``: its names, the frame pins O
    and A, the pin B in the link's frame, the dyads and links, the ``[[load]]`` tables."""

    path: Path
    identifier: str
    name: str
    link: str
    pivot: tuple
    base: tuple
    pin: tuple
    com: tuple
    dyads: tuple
    link_coms: dict
    loads: tuple
    gravity: bool


def read_scene(path: Path | str) -> CylinderScene:
    """The scene file, checked by the scene generator (its messages name FILE:LINE); a
    DrawingError where it is invalid or has no ``[cylinder]``."""
    path = Path(path)
    try:
        check_scene(path)
    except SourceError as e:
        raise DrawingError(str(e)) from None
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    cyl = data.get("cylinder")
    if not isinstance(cyl, dict):
        raise DrawingError(
            f"{path}: no [cylinder] table: this drawing is of a mechanism a hydraulic "
            "cylinder drives"
        )
    links = {t["name"]: tuple(t.get("com", (0.0, 0.0))) for t in data.get("link", [])}
    return CylinderScene(
        path=path,
        identifier=data["scene"]["identifier"],
        name=cyl.get("name", "cylinder"),
        link=cyl["link"],
        pivot=tuple(cyl.get("at", (0.0, 0.0))),
        base=tuple(cyl["base"]),
        pin=tuple(cyl["pin"]),
        com=tuple(cyl.get("com", (0.0, 0.0))),
        dyads=tuple(data.get("dyad", [])),
        link_coms=links,
        loads=tuple(data.get("load", [])),
        gravity=bool(data.get("effects", {}).get("gravity", False)),
    )


def _prefix(dyad: dict) -> str:
    """The prefix of a dyad's variables ("" for the one unnamed dyad of a scene)."""
    return f"{dyad['name']}." if "name" in dyad else ""


def _carrier(attachment: object) -> tuple[str, bool]:
    """(the link a dyad's outer pair sits on, whether it slides on a guide there): "frame",
    the cylinder's link (also for its name alone: the pair at B) or a dyad's link."""
    if isinstance(attachment, str):
        return attachment, False
    return attachment["link"], "guide" in attachment


# ---------------------------------------------------------------------------
# the FMU
# ---------------------------------------------------------------------------
class Instance:
    """A scene's mechanism FMU, opened with tunable parameters: its inputs (start values),
    its Real outputs, its parameters read as points, one step per set of inputs. Subclasses
    give ``_start`` (what they read once) and ``_need`` (the outputs they draw)."""

    def __init__(self, scene: object, fmu: Path | str, parameters: dict | None = None) -> None:
        self.scene, self.path = scene, Path(fmu)
        self.slave = Slave(self.path, instance_name=scene.identifier)
        try:
            self._open(parameters or {})
            self._start()
        except Exception:
            self.slave.close()
            raise

    def _open(self, parameters: dict) -> None:
        """The parameters' names checked, the outputs' names checked, the FMU initialised."""
        variables = self.slave.md.modelVariables
        self.inputs = {v.name: float(v.start or 0.0) for v in variables if v.causality == "input"}
        tunable = {v.name for v in variables if v.causality == "parameter" and v.type == "Real"}
        for name in parameters:
            if name not in tunable:
                raise DrawingError(
                    f"--set {name}: not a tunable parameter of {self.path.name} "
                    f"(tunable: {', '.join(sorted(tunable)) or 'none'})"
                )
        self.reals = tuple(
            v.name for v in variables if v.causality == "output" and v.type in ("Real", "Float64")
        )
        self._require()
        self.slave.initialize(parameters)
        self.time = 0.0

    def _start(self) -> None:
        """What is read once after initialisation (nothing here)."""

    def _need(self) -> list:
        """The outputs drawn (none here)."""
        return []

    def drawn_outputs(self) -> list:
        """The outputs the drawing needs of the FMU."""
        return self._need()

    def _point(self, prefix: str, default: Sequence) -> np.ndarray:
        """The point of the parameters prefix.x and prefix.y, each the FMU's where it has
        it (tunable), else the default's."""
        return np.array(
            [
                self.slave.get(f"{prefix}.{axis}") if f"{prefix}.{axis}" in self.slave.names else d
                for axis, d in zip("xy", default, strict=True)
            ],
            dtype=float,
        )

    def _require(self) -> None:
        """A DrawingError naming the first output the drawing needs that the FMU lacks."""
        for name in self._need():
            if name not in self.reals:
                raise DrawingError(
                    f"{self.path.name}: no output {name}: the drawing needs it (the scene's "
                    'outputs = ["all"] has it)'
                )

    def motion_inputs(self) -> set:
        """The inputs of the drivers' motion (none here)."""
        return set()

    def load_inputs(self) -> tuple:
        """The FMU's inputs but the drivers' motion: the loads."""
        motion = self.motion_inputs()
        return tuple(n for n in self.inputs if n not in motion)

    def step(self, values: dict, where: str) -> dict:
        """Every Real output and the inputs after one step with the inputs ``values`` (the
        loads not given 0); a DrawingError starting with ``where`` where the FMU has no
        answer there."""
        values = {**dict.fromkeys(self.load_inputs(), 0.0), **values}
        names = tuple(values)
        try:
            self.slave.set(names, [values[n] for n in names])
            self.slave.do_step(self.time, STEP)
        except SlaveError as e:
            raise DrawingError(f"{where}: {e}") from None
        self.time += STEP
        status = self.slave.get_status()
        if status != 0:
            said = self.slave.messages[-1] if self.slave.messages else ""
            raise DrawingError(f"{where}: status {status} {said}".strip())
        out = dict(zip(self.reals, self.slave.get(self.reals), strict=True))
        out.update(values)
        return out

    def close(self) -> None:
        """Free the FMU's instance."""
        self.slave.close()


class Machine(Instance):
    """The scene's mechanism FMU, stepped at cylinder lengths: ``at`` gives its outputs;
    the frame's pins and the loads' points are read once (the FMU's tunable parameters,
    else the scene's numbers)."""

    def _start(self) -> None:
        """The frame's pins and loads' points read."""
        scene = self.scene
        n = scene.name
        self.pivot = self._point(f"{scene.link}.at", scene.pivot)
        self.base = self._point(f"{n}.base", scene.base)
        self.pin = self._point(f"{n}.pin", scene.pin)
        self.load_at = {}
        for load in scene.loads:
            default = scene.com if load["link"] == scene.link else scene.link_coms[load["link"]]
            self.load_at[load["name"]] = self._point(f"{load['name']}.at", load.get("at", default))
        self.driver = f"{n}.length"
        self.rated = f"{n}.velocity" in self.inputs

    def _need(self) -> list:
        """The outputs drawn: B, the angles, the force, the dyads' pairs."""
        s = self.scene
        need = [f"{s.name}.B.position.x", f"{s.name}.angle", f"{s.name}.force", f"{s.link}.angle"]
        for dyad in s.dyads:
            p = _prefix(dyad)
            need += [f"{p}{pair}.position.x" for pair in ("D_m", "E", "D_n")]
        need += [f"{load['link']}.angle" for load in s.loads if load["link"] != s.link]
        return need

    def motion_inputs(self) -> set:
        """The cylinder's motion inputs."""
        return {f"{self.scene.name}.{k}" for k in ("length", "velocity", "acceleration")}

    def at(self, length: float, loads: dict, rate: float = 0.0) -> dict:
        """Every Real output with the inputs set: the cylinder at ``length`` (m), extending
        at ``rate`` (m/s) without acceleration, the loads (input -> value) and the other
        loads 0. A DrawingError where the FMU has no answer there."""
        values = {**loads, self.driver: float(length)}
        if self.rated:
            values[f"{self.scene.name}.velocity"] = float(rate)
            values[f"{self.scene.name}.acceleration"] = 0.0
        return self.step(values, f"{self.driver} = {length:.6g} m")


# ---------------------------------------------------------------------------
# one length: the points, bodies and forces drawn
# ---------------------------------------------------------------------------
@dataclass(kw_only=True)
class Drawn:
    """A mechanism as drawn at one position: every point (key -> (2,) m), the moving bodies
    (body -> keys of its points, in the order drawn), the pins and sliding pairs, the fixed
    pivots, the forces (output or load name, body, key of its point, force (2,) N, whether
    applied) and the FMU's outputs it comes from; subclasses give its cylinders."""

    outputs: dict
    points: dict = field(default_factory=dict)
    bodies: dict = field(default_factory=dict)
    pins: list = field(default_factory=list)
    sliders: list = field(default_factory=list)
    pivots: list = field(default_factory=list)
    guides: list = field(default_factory=list)
    forces: list = field(default_factory=list)

    def cylinders(self) -> dict:
        """Each cylinder drawn: {name: (barrel (A, mouth), rod (mouth, B))}."""
        return {}

    def segments(self) -> dict:
        """Every straight piece drawn (name -> (p0, p1)): each cylinder's barrel and rod
        ("barrel", "rod" of the cylinder named "", else "NAME.barrel", "NAME.rod"), and each
        body's bars (two points) or polygon edges."""
        out = {}
        for name, (barrel, rod) in self.cylinders().items():
            dot = f"{name}." if name else ""
            out[f"{dot}barrel"], out[f"{dot}rod"] = barrel, rod
        for body, keys in self.bodies.items():
            closing = keys[:1] if len(keys) > 2 else []  # a polygon closes, a bar does not
            for a, b in zip(keys, keys[1:] + closing, strict=False):
                out[f"{body}: {a}-{b}"] = (self.points[a], self.points[b])
        return out


@dataclass(kw_only=True)
class Pose(Drawn):
    """One cylinder length as drawn: :class:`Drawn` with the length, the link's angle, the
    barrel and the rod."""

    length: float
    angle: float
    barrel: tuple = ()
    rod: tuple = ()

    def cylinders(self) -> dict:
        """The one cylinder, named ""."""
        return {"": (self.barrel, self.rod)}


def _vector(out: dict, name: str) -> np.ndarray:
    return np.array([out[f"{name}.x"], out[f"{name}.y"]], dtype=float)


def _turned(angle: float, local: np.ndarray) -> np.ndarray:
    """A vector of a link's frame in global components, the link at ``angle`` (rad)."""
    i = geo.unit(angle)
    return local[0] * i + local[1] * geo.rot90(i)


def _add_dyads(pose: Pose, dyads: Sequence[dict]) -> None:
    """Each dyad's pair points (outputs), its links' points, pins, sliders and frame pairs."""
    out = pose.outputs
    for dyad in dyads:
        p = _prefix(dyad)
        for pair in ("D_m", "E", "D_n"):
            pose.points[p + pair] = _vector(out, f"{p}{pair}.position")
        for side, pair, letter in (("k", "D_m", 0), ("p", "D_n", 2)):
            link, slides = _carrier(dyad[side])
            if link == "frame" and slides:
                pose.guides.append((p + pair, float(dyad[side]["guide"])))
            elif link == "frame":
                pose.pivots.append(p + pair)
            else:
                pose.bodies.setdefault(link, []).append(p + pair)
            kind = dyad["type"][letter]
            (pose.sliders if kind == "T" else pose.pins).append(p + pair)
        (pose.sliders if dyad["type"][1] == "T" else pose.pins).append(p + "E")
        for side, pair in (("m", "D_m"), ("n", "D_n")):
            pose.bodies.setdefault(dyad[side], []).extend([p + pair, p + "E"])


def _add_loads(pose: Pose, machine: Machine) -> None:
    """Each [[load]]'s point (placed with its link's angle output) and its applied force."""
    scene, out = machine.scene, pose.outputs
    for load in scene.loads:
        name, link = load["name"], load["link"]
        if link == scene.link:
            origin = pose.points["O"]
        else:
            dyad, side = next((d, s) for d in scene.dyads for s in ("m", "n") if d[s] == link)
            origin = pose.points[_prefix(dyad) + ("D_m" if side == "m" else "D_n")]
        add_load(pose, load, origin, out[f"{link}.angle"], machine.load_at[name])


def add_load(pose: Drawn, load: dict, origin: np.ndarray, angle: float, at: np.ndarray) -> None:
    """A [[load]]'s point (``at`` in its link's frame, the link's origin and angle given)
    on its link, and its applied force (its inputs, in the link's components or global)."""
    name, link, out = load["name"], load["link"], pose.outputs
    pose.points[name] = origin + _turned(angle, at)
    pose.bodies.setdefault(link, []).append(name)
    if load.get("force", True):
        force = np.array([out.get(f"{name}.force.x", 0.0), out.get(f"{name}.force.y", 0.0)])
        if load.get("components", "global") == "link":
            force = _turned(angle, force)
        pose.forces.append((name, link, name, force, True))


def _add_reactions(pose: Pose, scene: CylinderScene) -> None:
    """The pair reactions the FMU has as outputs, each at its point."""
    n, link = scene.name, scene.link
    found = [(f"{link}.R_O", link, "O"), (f"{n}.R_A", "barrel", "A"), (f"{n}.R_B", link, "B")]
    add_reactions(pose, found + dyad_reactions(scene.dyads))


def dyad_reactions(dyads: Sequence[dict]) -> list:
    """Each dyad's pair reactions: (output, the body it acts on, the key of its point)."""
    found = []
    for dyad in dyads:
        p = _prefix(dyad)
        found += [
            (f"{p}R_mk", dyad["m"], f"{p}D_m"),
            (f"{p}R_mn", dyad["m"], f"{p}E"),
            (f"{p}R_np", dyad["n"], f"{p}D_n"),
        ]
    return found


def add_reactions(pose: Pose, found: list) -> None:
    """The reactions of ``found`` (output, body, key) the FMU has as outputs, as forces."""
    for name, body, key in found:
        if f"{name}.x" in pose.outputs:
            pose.forces.append((name, body, key, _vector(pose.outputs, name), False))


def _ordered(points: dict, keys: list, size: float) -> list:
    """A body's keys without repeated points, in the order of a simple polygon (by angle
    about their centre), or along their line where they are in one."""
    unique = []
    for k in dict.fromkeys(keys):
        if all(np.hypot(*(points[k] - points[j])) > 1e-9 * size for j in unique):
            unique.append(k)
    if len(unique) < 3:
        return unique
    xy = np.array([points[k] for k in unique])
    centre = xy.mean(axis=0)
    d = xy - centre
    _, sv, vt = np.linalg.svd(d)
    if sv[1] <= 1e-9 * max(sv[0], 1e-300):  # in one line: a bar through them
        return [unique[i] for i in np.argsort(d @ vt[0])]
    return [unique[i] for i in np.argsort(np.arctan2(d[:, 1], d[:, 0]))]


def pose(machine: Machine, out: dict, barrel: float) -> Pose:
    """What is drawn of the FMU's outputs ``out`` (from :meth:`Machine.at`), the barrel
    ``barrel`` m long. A DrawingError where the outputs disagree with the frame's pins
    (the FMU built from another scene)."""
    scene = machine.scene
    s = float(out[machine.driver])
    found = Pose(length=s, angle=float(out[f"{scene.link}.angle"]), outputs=out)
    found.points.update(O=machine.pivot, A=machine.base, B=_vector(out, f"{scene.name}.B.position"))
    _check_triangle(machine, found.points, s)
    found.bodies[scene.link] = ["O", "B"]
    found.pivots += ["O", "A"]
    found.pins += ["O", "A", "B"]
    _add_dyads(found, scene.dyads)
    _add_loads(found, machine)
    _add_reactions(found, scene)
    size = max(np.ptp(np.array(list(found.points.values())), axis=0).max(), 1e-3)
    for body, keys in found.bodies.items():
        found.bodies[body] = _ordered(found.points, keys, size)
    u = geo.unit(out[f"{scene.name}.angle"])
    found.barrel = (found.points["A"], found.points["A"] + barrel * u)
    found.rod = (found.barrel[1], found.points["B"])
    return found


def _check_triangle(machine: Machine, points: dict, length: float) -> None:
    """|O B| and |A B| of the outputs against the pin B and the length (1e-9 relative)."""
    o, a, b = points["O"], points["A"], points["B"]
    sides = (
        ("|O B|", np.hypot(*(b - o)), float(np.hypot(*machine.pin))),
        ("|A B|", np.hypot(*(b - a)), length),
    )
    for what, got, want in sides:
        if abs(got - want) > 1e-9 * max(want, np.hypot(*(a - o))):
            raise DrawingError(
                f"{machine.path.name} does not match {machine.scene.path}: {what} = {got:.9g} m "
                f"from its outputs, {want:.9g} m from the scene and the parameters; build the "
                "FMU from this scene"
            )


# ---------------------------------------------------------------------------
# the drawing
# ---------------------------------------------------------------------------
def _size(poses: list) -> float:
    """The extent (m) of every point of every pose."""
    xy = np.array([p for pose_ in poses for p in pose_.points.values()])
    return float(max(np.ptp(xy, axis=0).max(), 1e-3))


def _nice(value: float) -> float:
    """The smallest of 1, 2, 2.5, 5 times a power of ten that is at least ``value`` (> 0)."""
    power = 10.0 ** math.floor(math.log10(value))
    return next(m * power for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * power >= value * (1 - 1e-12))


def force_scale(forces: list, size: float, unit: float = 1e3) -> float:
    """The force scale (``unit`` N, by default kN, per m of arrow): a round number that
    makes the largest force's arrow at most ``ARROW_SHARE`` of ``size`` (1 where there is
    no force)."""
    largest = max((float(np.hypot(*f)) for *_, f, _ in forces), default=0.0) / unit
    return _nice(largest / (ARROW_SHARE * size)) if largest > 0 else 1.0


def _colours(scene: CylinderScene) -> dict:
    """Each moving body's colour: the driven link the driver's, the dyads' links in turn."""
    colours = {scene.link: sketch.DRIVER_COLOUR}
    links = [d[side] for d in scene.dyads for side in ("m", "n")]
    for i, g in enumerate(links):
        colours[g] = sketch.LINK_COLOURS[i % len(sketch.LINK_COLOURS)]
    return colours


def _draw_body(ax: Axes, pose_: Pose, body: str, colour: str, look: tuple, z: float) -> None:
    """A body: a bar between two points, or a shaded polygon with its edges; ``look`` is
    (opacity, share of the full line width)."""
    alpha, weight = look
    keys = pose_.bodies[body]
    if len(keys) > 2:
        xy = [tuple(pose_.points[k]) for k in keys]
        shade = (0.3 if weight == 1.0 else 0.1) * alpha
        ax.add_patch(
            Polygon(xy, closed=True, facecolor=colour, edgecolor="none", alpha=shade, zorder=z)
        )
    for name, (p0, p1) in pose_.segments().items():
        if name.startswith(f"{body}: "):
            sketch.bar(ax, p0, p1, colour, width=weight * sketch.LINK_WIDTH, z=z + 0.1, alpha=alpha)


def _draw_pose(ax: Axes, pose_: Pose, colours: dict, u: float, look: tuple, z: float) -> None:
    """One length: the cylinder, the bodies, the pins and sliders; ``look`` is (opacity,
    share of the full line widths)."""
    alpha, weight = look
    for (a, mouth), (_, b) in pose_.cylinders().values():
        sketch.bar(ax, mouth, b, ROD_COLOUR, width=weight * ROD_WIDTH, z=z + 0.2, alpha=alpha)
        sketch.bar(ax, a, mouth, BARREL_COLOUR, width=weight * BARREL_WIDTH, z=z + 0.3, alpha=alpha)
    for body in pose_.bodies:
        _draw_body(ax, pose_, body, colours.get(body, "0.5"), look, z)
    for key in pose_.sliders:
        along = next(
            (pose_.points[j] - pose_.points[key] for j in _neighbours(pose_, key)), (1.0, 0.0)
        )
        if np.hypot(*along) == 0:
            along = (1.0, 0.0)
        sketch.block(ax, pose_.points[key], along, 2.4 * u, 1.2 * u, "0.8", z=z + 3, alpha=alpha)
    for key in dict.fromkeys(pose_.pins):
        sketch.pin(ax, pose_.points[key], u * (0.5 + 0.5 * weight), z=z + 4, alpha=alpha)


def _neighbours(pose_: Pose, key: str) -> list:
    """The other points of the bodies a point belongs to."""
    return [j for keys in pose_.bodies.values() if key in keys for j in keys if j != key]


def _draw_frame(ax: Axes, first: Pose, poses: list, u: float) -> None:
    """The fixed pivots as ground symbols; a guide on the frame as a hatched rail along the
    stretch its pair takes."""
    for key in dict.fromkeys(first.pivots):
        sketch.ground_pivot(ax, first.points[key], u)
    for key, angle in first.guides:
        along = geo.unit(angle)
        reach = [float(p.points[key] @ along) for p in poses]
        foot = first.points[key] - float(first.points[key] @ along) * along
        p0, p1 = foot + (min(reach) - 2.0 * u) * along, foot + (max(reach) + 2.0 * u) * along
        side = geo.rot90(along)
        ax.plot(*np.transpose([p0, p1]), color=sketch.FRAME_COLOUR, lw=0.8, ls="-.", zorder=1)
        sketch.hatch(ax, p0 - 0.8 * u * side, p1 - 0.8 * u * side, -side, u)


def _names(pose_: Pose, scene: CylinderScene) -> dict:
    """The label of every point drawn: O, A, B, the dyads' pairs and the loads' names."""
    names = {"O": "O", "A": "A", "B": "B"}
    for dyad in scene.dyads:
        p = _prefix(dyad)
        names.update({p + k: f"{p}{k}" for k in ("D_m", "E", "D_n")})
    names.update({load["name"]: load["name"] for load in scene.loads})
    return {k: v for k, v in names.items() if k in pose_.points}


def _label_bodies(ax: Axes, pose_: Pose, names: dict, colours: dict, u: float) -> None:
    """The names of the bodies and of the cylinders (``names``: the key of
    :meth:`Pose.cylinders` -> its name), beside them."""
    for body, keys in pose_.bodies.items():
        xy = np.array([pose_.points[k] for k in keys])
        far = max(range(len(keys)), key=lambda i: float(np.hypot(*(xy[i] - xy[0]))))
        where = sketch.beside(xy[0], xy[far], u, up=False) if far else xy[0]
        if len(keys) > 2:
            where = xy.mean(axis=0)
        colour = colours.get(body, "black")
        sketch.label(ax, where, body, (0.0, 0.0), colour=colour, size=10, weight="bold", box=False)
    for key, ((a, mouth), _) in pose_.cylinders().items():
        where = sketch.beside(a, mouth, u, up=False)
        sketch.label(ax, where, names[key], (0.0, 0.0), size=10, weight="bold", box=False)


def _degrees(angle: float) -> str:
    """An angle (rad) in degrees to a tenth, without a sign on zero."""
    return f"{round(math.degrees(angle), 1) + 0.0:.1f}°"


def _tag(ax: Axes, pose_: Pose, scene: CylinderScene, alpha: float) -> None:
    """The length and the link's angle, just inside the link's point farthest from O."""
    text = f"{pose_.length:.3g} m, {_degrees(pose_.angle)}"
    tag(ax, pose_, pose_.bodies[scene.link], "O", text, alpha)


def tag(ax: Axes, pose_: Pose, keys: Sequence[str], origin: str, text: str, alpha: float) -> None:
    """``text`` just inside the point of ``keys`` farthest from the point ``origin``."""
    o = pose_.points[origin]
    far = max(keys, key=lambda k: float(np.hypot(*(pose_.points[k] - o))))
    inward = sketch.away(np.mean([pose_.points[k] for k in keys], axis=0), pose_.points[far])
    ax.annotate(
        text,
        xy=tuple(pose_.points[far]),
        xytext=tuple(36.0 * inward),
        textcoords="offset points",
        fontsize=8,
        color=(0.1, 0.1, 0.1, max(alpha, 0.6)),
        ha="center",
        va="center",
        zorder=9,
        bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.7),
    )


def _drawn_points(poses: list) -> np.ndarray:
    """The points of every pose and of every piece drawn (its ends, quarters and middle),
    which the labels keep away from."""
    found = []
    for p in poses:
        found += list(p.points.values())
        for p0, p1 in p.segments().values():
            found += [p0 + t * (p1 - p0) for t in (0.25, 0.5, 0.75)]
    return np.array(found)


def _label_moved(
    ax: Axes, first: Pose, other: Pose, names: dict, size: float, drawn: np.ndarray
) -> None:
    """Labels of the points of another pose that are not where the first pose has them."""
    moved = {
        k: v
        for k, v in names.items()
        if np.hypot(*(other.points[k] - first.points[k])) > 1e-9 * size
    }
    if moved:
        sketch.label_points(
            ax, other.points, moved, size, fontsize=8, drop_dotted=False, avoid=drawn
        )


def _arrows(
    ax: Axes, pose_: Pose, scale: float, u: float, labels: dict, unit: tuple = ("kN", 1e3)
) -> dict:
    """Every force of the pose as an arrow from its point, |F| / scale long (scale in
    ``unit`` (name, N) per m; applied loads black, reactions in colours), each labelled
    for the legend."""
    arrows, reaction = {}, 0
    for k, (name, body, key, force, applied) in enumerate(pose_.forces):
        magnitude = float(np.hypot(*force)) / unit[1]
        if magnitude == 0.0:
            continue
        if applied:
            colour, text = "black", f"{name} (applied) on {body} at {labels[key]}"
        else:
            colour = sketch.ARROW_COLOURS[reaction % len(sketch.ARROW_COLOURS)]
            text, reaction = f"{name} on {body} at {labels[key]}", reaction + 1
        # later arrows thinner and on top, so that coincident ones stay visible
        width = 0.2 * u * (1.0 - 0.4 * k / max(len(pose_.forces) - 1, 1))
        arrows[name] = sketch.force_arrow(
            ax,
            pose_.points[key],
            force / unit[1] / scale,
            u,
            colour,
            f"{text}: {magnitude:.3g} {unit[0]}",
            width=width,
            z=8 + 0.01 * k,
        )
    return arrows


def draw(
    ax: Axes, machine: Machine, poses: list, reactions_at: int = -1, scale: float | None = None
) -> dict:
    """Draw the poses (from :func:`pose`) overlaid on ``ax`` to scale, the later fainter,
    and the forces of pose ``reactions_at`` as arrows on one scale: ``scale`` kN per m of
    arrow if given, else a round one (:func:`force_scale`). Returns {"scale": kN/m,
    "arrows": {output or load name: arrow patch}, "size": m}."""
    scene, n = machine.scene, len(poses)
    size = _size(poses)
    u = 0.025 * size
    colours = _colours(scene)
    _draw_frame(ax, poses[0], poses, u)
    for i in reversed(range(n)):
        alpha = 1.0 - (1.0 - FADED) * i / max(n - 1, 1)
        look = (alpha, 1.0 if i == 0 else 0.55)
        _draw_pose(ax, poses[i], colours, u, look, z=2.0 - 0.05 * i)
        _tag(ax, poses[i], scene, alpha)
    names = _names(poses[0], scene)
    drawn = _drawn_points(poses)
    sketch.label_points(ax, poses[0].points, names, size, drop_dotted=False, avoid=drawn)
    _label_bodies(ax, poses[0], {"": scene.name}, colours, u)
    if poses[reactions_at] is not poses[0]:
        _label_moved(ax, poses[0], poses[reactions_at], names, size, drawn)
    loaded = poses[reactions_at]
    scale = sketch.checked_scale(scale) or force_scale(loaded.forces, size)
    arrows = _arrows(ax, loaded, scale, u, names)
    if arrows:
        ax.legend(
            handles=list(arrows.values()),
            loc="upper center",
            bbox_to_anchor=(0.5, -0.1),
            ncol=2,
            fontsize=8,
            title=_title(machine, loaded, scale),
            title_fontsize=8,
            framealpha=0.9,
        )
    sketch.finish_axes(ax, 0.06)
    return {"scale": scale, "arrows": arrows, "size": size}


def _title(machine: Machine, loaded: Pose, scale: float) -> str:
    """The legend's title: where the forces are drawn and their scale."""
    link = machine.scene.link
    return (
        f"forces at {machine.driver} = {loaded.length:.4g} m ({link} at "
        f"{_degrees(loaded.angle)}); scale {scale:g} kN per m of arrow"
    )


def stroke_lengths(stroke: Sequence[float], count: int) -> np.ndarray:
    """``count`` lengths evenly over the stroke (m), its ends included."""
    return np.linspace(float(stroke[0]), float(stroke[1]), int(count))


def figure(
    machine: Machine,
    lengths: Sequence[float],
    loads: dict,
    path: Path | str,
    reactions_at: int = -1,
) -> dict:
    """Save a PNG of the mechanism at the cylinder ``lengths`` (m) overlaid, with the
    ``loads`` (input -> value) and the forces at ``lengths[reactions_at]``. Returns what
    :func:`draw` returns, with "poses" and "path"."""
    outputs = [machine.at(s, loads) for s in lengths]
    barrel = BARREL_SHARE * min(float(s) for s in lengths)
    poses = [pose(machine, out, barrel) for out in outputs]
    fig, ax = plt.subplots(figsize=(10.0, 8.5))
    drawn = draw(ax, machine, poses, reactions_at)
    ax.set_title(
        f"{machine.scene.identifier}: {machine.driver} "
        + ", ".join(f"{p.length:.3g}" for p in poses)
        + " m, drawn to scale from the FMU's outputs",
        fontsize=10,
    )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return {**drawn, "poses": poses, "path": path}


# ---------------------------------------------------------------------------
# the force over the stroke
# ---------------------------------------------------------------------------
def force_curves(machine: Machine, lengths: Sequence[float], loads: dict, rate: float) -> dict:
    """The cylinder's axial force over ``lengths``: {(loaded, rate): {"length": m,
    "angle": the link's angle in deg, "force": N}} with the loads and without them (where
    any is not 0), at rest and extending at ``rate`` m/s (where the FMU has inertia and the
    rate is not 0)."""
    cases = [(True, 0.0)]
    if any(v != 0.0 for v in loads.values()):
        cases.append((False, 0.0))
    if machine.rated and rate != 0.0:
        cases += [(loaded, float(rate)) for loaded, _ in list(cases)]
    curves = {}
    for loaded, speed in cases:
        rows = [machine.at(s, loads if loaded else {}, speed) for s in lengths]
        curves[(loaded, speed)] = {
            "length": np.array([r[machine.driver] for r in rows]),
            "angle": np.degrees([r[f"{machine.scene.link}.angle"] for r in rows]),
            "force": np.array([r[f"{machine.scene.name}.force"] for r in rows]),
        }
    return curves


def _case_label(scene: CylinderScene, loads: dict, loaded: bool, speed: float) -> str:
    """A curve's legend: which loads, which rate."""
    given = ", ".join(f"{k} = {v / 1e3:.4g} kN" for k, v in loads.items() if v != 0.0)
    if loaded and given:
        what = f"with {given}"
    else:
        what = "loads 0" + (" (own weights only)" if scene.gravity else "")
    return f"{what}, " + (f"extending at {speed:g} m/s" if speed else "at rest")


def _length_axis(ax: Axes, curve: dict, driver: str) -> None:
    """The cylinder's length on the top axis, ticks within the stroke, where the angle
    follows the length one way."""
    angle, length = curve["angle"], curve["length"]
    step = np.diff(angle)
    if len(angle) < 2 or not (np.all(step > 0) or np.all(step < 0)):
        return
    order = np.argsort(angle)
    a, s = angle[order], length[order]
    by_length = np.argsort(s)
    top = ax.secondary_xaxis(
        "top",
        functions=(
            lambda x: np.interp(x, a, s),
            lambda y: np.interp(y, s[by_length], a[by_length]),
        ),
    )
    ticks = MaxNLocator(8).tick_values(s.min(), s.max())
    top.set_xticks(ticks[(ticks >= s.min() - 1e-9) & (ticks <= s.max() + 1e-9)])
    top.set_xlabel(f"{driver} [m]")


def _rate_panel(ax: Axes, curves: dict) -> None:
    """What the extension rate adds to the force at rest, per load case."""
    for (loaded, speed), c in curves.items():
        if speed:
            rest = curves[(loaded, 0.0)]
            ax.plot(
                c["angle"],
                (c["force"] - rest["force"]) / 1e3,
                color="tab:blue" if loaded else "tab:orange",
                ls="-" if loaded else "--",
                lw=3.5 if loaded else 1.4,
                alpha=0.45 if loaded else 1.0,
            )
    if ax.lines:
        speed = max(speed for _, speed in curves)
        ax.set_ylabel(f"extending at {speed:g} m/s\nminus at rest [kN]")
        ax.set_title(
            "what the rate adds, the same with and without the loads (forces, not masses): "
            "force = J s'' + dJ/ds s'²/2 + the force at rest",
            fontsize=8,
        )
    else:
        ax.text(
            0.5,
            0.5,
            "no extension rate (the scene has no inertia, or the rate is 0)",
            ha="center",
            va="center",
            transform=ax.transAxes,
            fontsize=8,
        )


def force_figure(machine: Machine, curves: dict, loads: dict, path: Path | str) -> dict:
    """Save a PNG of the curves of :func:`force_curves`: the axial force (kN) against the
    link's angle (deg), and below it what the extension rate adds (kN). Returns
    {(loaded, rate): the force's line} with "path"."""
    scene = machine.scene
    fig, (top, low) = plt.subplots(
        2, 1, figsize=(9.0, 7.5), sharex=True, gridspec_kw={"height_ratios": (3, 1.2)}
    )
    lines = {}
    for (loaded, speed), c in curves.items():
        (lines[(loaded, speed)],) = top.plot(
            c["angle"],
            c["force"] / 1e3,
            color="tab:blue" if loaded else "tab:orange",
            ls="--" if speed else "-",
            lw=1.6,
            label=_case_label(scene, loads, loaded, speed),
        )
    _mark_peak(top, curves[(True, 0.0)])
    _length_axis(top, curves[(True, 0.0)], machine.driver)
    top.set_ylabel(f"{scene.name}.force [kN] (> 0 pushes the pins apart)")
    top.set_title(f"{scene.identifier}: the cylinder's axial force over the stroke", fontsize=10)
    top.legend(fontsize=8, loc="best")
    low_end, high_end = top.get_ylim()
    top.set_ylim(min(low_end, 0.0), high_end + 0.08 * (high_end - min(low_end, 0.0)))
    _rate_panel(low, curves)
    low.set_xlabel(f"{scene.link}.angle [deg]")
    for ax in (top, low):
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return {**lines, "path": path}


def _mark_peak(ax: Axes, curve: dict) -> None:
    """The largest force of a curve, marked and written beside it."""
    i = int(np.argmax(np.abs(curve["force"])))
    x, y = float(curve["angle"][i]), float(curve["force"][i]) / 1e3
    ax.plot([x], [y], "o", color="black", ms=4, zorder=5)
    ax.annotate(
        f"largest {y:.4g} kN at {_degrees(math.radians(x))} ({curve['length'][i]:.3g} m)",
        xy=(x, y),
        xytext=(12, 4),
        textcoords="offset points",
        fontsize=8,
    )


# ---------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------
def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m dyadfmu.report.cylinder_drawing",
        description="Draw a mechanism a hydraulic cylinder drives (a scene with a [cylinder]) "
        "to scale from its built mechanism FMU's outputs: several cylinder lengths over the "
        "stroke overlaid, the later fainter, with the pair reactions and applied loads at one "
        "of them as arrows on one scale (OUT/<identifier>.png); and the cylinder's axial "
        "force against the link's angle over the stroke, with and without the loads, at "
        "rest and at a constant extension rate (OUT/<identifier>_force.png).",
    )
    p.add_argument("scene", type=Path, help="the scene file (TOML) with a [cylinder]")
    p.add_argument(
        "--stroke",
        nargs=2,
        type=argtypes.real(0.0, 1e4, above=True),
        metavar=("MIN", "MAX"),
        required=True,
        help="the cylinder's shortest and longest length (m): the ends of the stroke drawn "
        "and of the force figure",
    )
    p.add_argument(
        "--positions",
        type=argtypes.whole(2, 6),
        default=3,
        help="how many lengths evenly over the stroke, its ends included, are drawn (default 3)",
    )
    p.add_argument(
        "--reactions-at",
        type=argtypes.whole(1, 6),
        default=None,
        help="which of them (1 the shortest) carries the force arrows (default the last)",
    )
    _loads_and_sources(p)
    return p


def _loads_and_sources(p: argparse.ArgumentParser) -> None:
    """The options of the loads, the force figure and the FMU."""
    load_options(p)
    p.add_argument(
        "--rate",
        type=argtypes.real(-100.0, 100.0),
        default=0.1,
        help="the constant extension rate of the force figure's second curves (m/s; default 0.1)",
    )
    p.add_argument(
        "--samples",
        type=argtypes.whole(2, 10_000),
        default=101,
        help="lengths over the stroke in the force figure (default 101)",
    )
    source_options(p, "cylinder")


def load_options(p: argparse.ArgumentParser) -> None:
    """The options --load and --set."""
    p.add_argument(
        "--load",
        type=argtypes.assignment,
        action="append",
        default=None,
        metavar="INPUT=N",
        help="a load input and its value (N, or N m for a moment), repeatable; the loads "
        "not given are 0 (default: the FMU's start values, the scene's [start])",
    )
    p.add_argument(
        "--set",
        type=argtypes.assignment,
        action="append",
        default=[],
        metavar="PARAMETER=VALUE",
        help="a tunable parameter of the FMU and its value (SI units), repeatable",
    )


def source_options(p: argparse.ArgumentParser, out: str) -> None:
    """The options --fmi, --build and --out (default out/``out``)."""
    p.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default 2)")
    p.add_argument(
        "--build",
        type=Path,
        default=None,
        help="the build whose fmus/<identifier>_fmi<v>.fmu is drawn (default build/)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=paths.ROOT / "out" / out,
        help=f"output folder (default out/{out})",
    )


def loads_given(machine: Instance, given: list | None) -> dict:
    """The load inputs: those given (each checked to be one), else the FMU's start values."""
    names = machine.load_inputs()
    if given is None:
        return {n: machine.inputs[n] for n in names}
    for name, _ in given:
        if name not in names:
            raise DrawingError(
                f"--load {name}: not a load input of {machine.path.name} (its loads: "
                f"{', '.join(names) or 'none'})"
            )
    return dict(given)


def _run(args: argparse.Namespace, say: Callable[[str], None]) -> list:
    """Read, evaluate, draw; returns the files written."""
    scene = read_scene(args.scene)
    fmu = paths.built_fmu(scene.identifier, args.fmi, args.build, how="cmake --build build")
    machine = Machine(scene, fmu, dict(args.set))
    try:
        loads = loads_given(machine, args.load)
        stroke = sorted(args.stroke)
        if stroke[0] == stroke[1]:
            raise DrawingError(f"--stroke {stroke[0]:g} {stroke[1]:g}: the ends must differ")
        shown = stroke_lengths(stroke, args.positions)
        at = -1 if args.reactions_at is None else args.reactions_at - 1
        if at >= args.positions:
            raise DrawingError(
                f"--reactions-at {args.reactions_at}: only {args.positions} positions"
            )
        args.out.mkdir(parents=True, exist_ok=True)
        say(f"{scene.identifier}: {len(shown)} positions from {fmu}")
        drawing = figure(machine, shown, loads, args.out / f"{scene.identifier}.png", at)
        say(f"{scene.identifier}: the force at {args.samples} lengths over the stroke")
        curves = force_curves(machine, stroke_lengths(stroke, args.samples), loads, args.rate)
        force = force_figure(machine, curves, loads, args.out / f"{scene.identifier}_force.png")
    finally:
        machine.close()
    return [drawing["path"], force["path"]]


def main(argv: list[str] | None = None) -> int:
    """The command: draw the scene's mechanism and its cylinder's force; prints the files."""
    return run_command(_parser(), argv, _run)


def run_command(
    parser: argparse.ArgumentParser,
    argv: list[str] | None,
    run: Callable[[argparse.Namespace, Callable[[str], None]], list],
) -> int:
    """Parse (the scene a file, --out a folder, --build one given), then ``run`` with a
    function that prints a line with the seconds since the start; a DrawingError as one
    line and exit status 2; prints the files written."""
    args = paths.parse_checked(
        parser, argv, (("scene", "scene", paths.FILE), ("--out", "out", paths.OUT))
    )
    if args.build is not None:
        paths.refuse_bad_paths(parser, args, (("--build", "build", paths.FOLDER),))
    start = time.monotonic()

    def say(text: str) -> None:
        print(f"[{time.monotonic() - start:5.1f} s] {text}", flush=True)

    say(f"checking {args.scene}")
    try:
        written = run(args, say)
    except (DrawingError, FileNotFoundError) as e:
        parser.exit(2, f"{parser.prog}: error: {e}\n")
    for path in written:
        say(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

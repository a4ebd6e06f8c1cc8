"""Multi-dyad planar linkages ("chains"): a crank followed by several Assur dyads, with
exact kinematics, active loads and a whole-mechanism Newton-Euler reference for their
joint reactions.

=============  ============================================================================
name           mechanism (scene file ``modelDescription/scenes/<name>.toml``)
=============  ============================================================================
shaper         crank; dyad ``slot`` (RTR): slotted lever on the frame at O2 and a block on
               the crank pin; dyad ``ram`` (RRT): ram on a horizontal frame guide, rod from
               the lever's tip B to the ram's pin C. Cutting force on the ram.
sixbar         Watt II: crank; dyad ``first`` (RRR): coupler A-B and rocker C-B; dyad
               ``second`` (RRR): connector D-F from a point D of the rocker, output rocker
               G-F. Resisting torque on the output rocker.
rocker_slider  crank; dyad ``first`` (RRR) as in sixbar; dyad ``second`` (RRT): a slider on
               a guide carried by the rocker (along the rocker, through its pivot C), held
               by a rod from the frame pivot G. Resisting force on the slider along its
               guide.
lift           a ram (hydraulic cylinder) on a horizontal frame guide; dyad ``lever`` (RRR):
               an arm pivoted on the frame and a strut from the ram's pin; dyad ``hoist``
               (RRT): a platform on a vertical frame guide held by a rod from the arm's tip.
               Payload on the platform.
four_bar_      crank; dyad ``linkage`` (RRR): the crank-rocker four-bar of four_bar.toml.
payload        Loads where they act: a payload at a coupler point, a drag along the
               coupler, a follower force and a moment on the crank beyond its pin;
               resisting torque on the rocker.
lift_loads     the lift, loads where they act: a follower force and a moment on the ram,
               a payload at the platform's far edge.
tipper         a hydraulic cylinder between two pins ([cylinder]) tips a dump body about
               its rear hinge; dyad ``gate`` (RRR): a tailgate on the body opened by a rod
               from the chassis. A 10 t payload on the body.
cylinder_arm   (tests/scenes) a cylinder alone raises an arm; a payload at its tip.
cylinder_boom  (tests/scenes) a cylinder raises a boom; dyad ``hang`` (RRR): a platform
               from the boom's tip and a tie to the frame. A payload at the boom's tip.
=============  ============================================================================

The scene file gives the topology, lengths, mass properties, points of attachment on
links and which links carry loads; ``chains.toml`` next to this module gives the rest
(crank or ram motion, load model constants, drawing labels) and, where the scene does not
state them, the fixed pivots and guides and the assembly branches. A scene states a fixed
pivot as ``{ link = "frame", at = [x, y] }``, a point of a frame guide's line as
``{ link = "frame", guide = angle, at = [x, y] }``, a dyad's branch as ``branch = +-1``,
the crank's pivot as ``[crank] at`` (default (0, 0)), and a translating link's direction
as ``turn`` from its guide (or ``angle``, absolute).

The driver is a crank (``[crank]``) or a ram (``[ram]``: ``guide`` angle, ``at`` = its
point R at displacement 0, R = at + x i_guide, ``com`` in {R; i_guide, j_guide},
``mass``). A ram translates: its angle is the guide's, its omega and epsilon are 0. The
guide acts on it with a normal force N (along j_guide) and a moment M (about R),
``<ram>.N`` and ``<ram>.M``; its actuator force along the guide at R, ``<ram>.force``,
takes the place of the crank's driving torque. ``k`` or ``p = "ram"`` attaches a dyad at
R; ``{ link = "ram", at = [x, y] }`` at another point of the ram.

The driver may also be a hydraulic cylinder between two pins (``[cylinder]``): its
barrel pinned to the frame at A (``base``), its rod to the link it turns (``link``) at B
(``pin``, in that link's frame {O; i, j}), the link pivoted on the frame at O (``at``).
Its length s = |AB| is the driver's coordinate (``<cyl>.length``, ``.velocity``,
``.acceleration``). B closes the triangle O, A, B: with e the unit vector from O to A,
d = |OA|, r = |pin|, B - O = x e + y (k x e), x = (d^2 + r^2 - s^2) / (2 d) and
y = branch sqrt(r^2 - x^2) (``branch`` +1: B to the left of O -> A). The link's angle turns
``pin`` onto B - O. The cylinder's axis u = (B - A) / s, its angle ``<cyl>.angle`` and
j_c = k x u. Rates from the closure differentiated: B' = omega k x (B - O) and
(B - A) . B' = s s' give omega = s' / ((B - O) x u); B' . j_c = s Omega gives the axis's
rate Omega; along u, B'' . u = s'' - s Omega^2 gives epsilon, across it B'' . j_c =
s Omega' + 2 s' Omega gives Omega'. The barrel (frame {A; u, j_c}, centre of mass at
A + com u) and the rod (frame {B; u, j_c}, centre of mass at B - com u) turn with u; the
rod's point at B slides along the barrel's axis: its acceleration is (s'' - s Omega^2) u
+ (s Omega' + 2 s' Omega) j_c, the last term the Coriolis one. Pair forces: ``<link>.R_O``
on the link from the frame at O, ``<cyl>.R_A`` on the barrel from the frame at A,
``<cyl>.R_B`` on the link from the rod at B; the barrel acts on the rod with
``<cyl>.force`` u (the axial force, positive pushing the pins apart) and ``<cyl>.N`` j_c at
B and the couple ``<cyl>.M``, the rod on the barrel with the opposites. The link, the
barrel and the rod are three bodies of the Newton-Euler system, the force its driver's
unknown; ``<cyl>.conditioning`` is |(B - O) x u| / r. Dyads and [[load]] tables name the
link.

Loads. A link the scene lists under ``[loads]`` carries a force at its centre of mass
and a moment, from the model chains.toml gives it. Each ``[[load]]`` table of the scene
is a force at the point P = ``at`` of its link's frame (default the centre of mass) on
any moving body, the driver included, and/or a pure moment; its inputs
``NAME.force.x/.y`` are global components, or with ``components = "link"`` components
along the link's i and j (a follower force, F = fx i + fy j). It adds F to its body's
forces and (P - S) x F + M to its moments about S; chains.toml's model "swinging" gives
its inputs over the motion.

Conventions (those of the FMUs): global frame x, y, z out of the plane; angles
counter-clockwise from +x; moments are z components. The crank turns about O (default (0, 0)),
its frame is {O; i_c, j_c} with i_c = (cos phi, sin phi), j_c = k x i_c, its pin is
A = O + r i_c. Link g of a dyad has the frame {D_g; i_g, j_g}, i_g from D_g towards E,
E = D_m + l_m i_m = D_n + l_n i_n; all these frames are fixed in their links. Its centre
of mass is S_g = D_g + com[0] i_g + com[1] j_g. ``<g>.accel_d`` is the acceleration of
the material point of g at D_g. Pair kinds at (D_m, E, D_n): RRR (R, R, R), RRT (T on
the guide of link k, R, R), RTR (R, T along i_m, R).

The guide of an RRT dyad lies on the frame or on a moving link k. A guide on link k
(scene: ``k = { link = "<k>", guide = g, at = [x, y] }``) is the line fixed in k's frame
through the point ``at`` of that frame, with direction i_k = i_(link k) rotated by g.
The slider m then turns with k: its angle is k's angle + g (i_m = i_k), so its omega and
epsilon are those of k. ``<dyad>.slide_k`` is the signed position of D_m along the guide
from the point ``at``: D_m = D_k + x i_(link k) + y j_(link k) + slide_k i_k, with its
first and second time derivatives ``<dyad>.slide_k_rate`` (the slider's velocity
relative to k) and ``<dyad>.slide_k_accel``. The slider's ``accel_d`` is the absolute
acceleration of its material point at D_m: that of k's point at D_m, plus the relative
acceleration slide_k_accel i_k and the Coriolis term 2 omega_k x (slide_k_rate i_k).
The pair's reaction on the slider is R_mk = N_mk j_k at D_m plus the couple M_mk; link k
receives -R_mk at D_m and -M_mk.

Kinematics is exact: circle-circle intersection (RRR), circle-line intersection (RRT)
and atan2 (RTR) for positions, and the loop equations differentiated once and twice in
closed form and solved as 2 x 2 linear systems for velocities and accelerations.

:meth:`Chain.reference` writes the Newton-Euler equations of every moving body (crank
included), with weights, active loads and d'Alembert forces, and solves the square
linear system for all pair reactions and the crank's driving torque at once.

Example::

    chain = load("shaper")
    motion = chain.motion("constant", revolutions=1)
    t = np.linspace(0, motion.duration, 361)
    kin = chain.kinematics(t, motion)
    out = chain.reference(kin)
    assert chain.residuals(kin, out).max() < 1e-12
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path

import numpy as np

from ..paths import SCENES_DIR, TEST_SCENES_DIR
from . import geometry as geo
from . import motion as motion_
from .motion import CrankMotion

__all__ = ["NAMES", "RAM_NAMES", "CYLINDER_NAMES", "Chain", "load", "scene_path", "default_data"]

#: The chain mechanisms driven by a crank.
NAMES = ("shaper", "sixbar", "rocker_slider", "four_bar_payload")
#: The chain mechanisms driven by a ram (a linear actuator on a frame guide).
RAM_NAMES = ("lift", "lift_loads")
#: The chain mechanisms driven by a hydraulic cylinder between two pins.
CYLINDER_NAMES = ("tipper", "cylinder_arm", "cylinder_boom")
#: The mechanisms whose scenes are the build's test scenes (tests/scenes/), not examples.
_TEST_SCENES = ("cylinder_arm", "cylinder_boom")
_ALL_NAMES = NAMES + RAM_NAMES + CYLINDER_NAMES

#: The attachments that are guides (a translational pair at the dyad's outer pair).
_GUIDES = ("guide", "link_guide")

#: Dyad types handled, with the pair kinds at (D_m, E, D_n).
PAIR_KINDS = {"RRR": ("R", "R", "R"), "RRT": ("T", "R", "R"), "RTR": ("R", "T", "R")}

#: Output tag of each pair: D_m joins m and k, E joins m and n, D_n joins n and p.
_TAGS = (("D_m", "mk"), ("E", "mn"), ("D_n", "np"))


# ---------------------------------------------------------------------------
# vector helpers on arrays of shape (..., 2)
# ---------------------------------------------------------------------------
_norm = geo.norm
_angle = geo.angle


def _solve2(c1: np.ndarray, c2: np.ndarray, rhs: np.ndarray):
    """x, y with x c1 + y c2 = rhs (Cramer's rule), batched over the leading axis."""
    det = geo.cross(c1, c2)
    return geo.cross(rhs, c2) / det, geo.cross(c1, rhs) / det


# ---------------------------------------------------------------------------
# data
# ---------------------------------------------------------------------------
def scene_path(name: str) -> Path:
    """The scene file of mechanism ``name``: ``modelDescription/scenes/<name>.toml`` of the
    project, or for a test scene ``tests/scenes/<name>.toml``."""
    if name not in _ALL_NAMES:
        raise ValueError(
            f"unknown chain mechanism {name!r}; expected one of: {', '.join(_ALL_NAMES)}"
        )
    return (TEST_SCENES_DIR if name in _TEST_SCENES else SCENES_DIR) / f"{name}.toml"


def default_data() -> dict:
    """The packaged ``chains.toml`` as a dict (a fresh copy)."""
    text = resources.files(__package__ or "dyadfmu").joinpath("chains.toml").read_text("utf-8")
    return tomllib.loads(text)


def _sign(table: Mapping, key: str, where: str):
    value = geo.number(table, key, where)
    if value not in (1.0, -1.0):
        raise ValueError(f"{where}.{key}: expected +1 or -1, got {value!r}")
    return value


def _require_listed(listed: list, lname: str, what: str, where: str) -> None:
    """A load model on a link needs the scene's [loads] to list a `what` on it."""
    if lname not in listed:
        raise ValueError(f"{where}: the scene lists no {what} on {lname!r} ([loads].{what})")


#: The keys of model "swinging", by the input they shape.
_SWINGING = {"force": ("force", "force_swing"), "moment": ("moment", "moment_swing")}


def _swinging(model: Mapping, placed: Mapping, where: str) -> dict:
    """Model "swinging" of a [[load]]: each of its inputs a mean plus a swing times
    sin(omega t + phase), omega the motion's; keys only for the inputs the load has."""
    kind = model.get("model")
    if kind != "swinging":
        raise ValueError(f"{where}.model: a [[load]] takes model 'swinging', got {kind!r}")
    allowed = {"model", "phase"}
    for what, keys in _SWINGING.items():
        if placed[what]:
            allowed.update(keys)
    stray = sorted(set(model) - allowed)
    if stray:
        raise ValueError(
            f"{where}.{stray[0]}: not a key of this load's model (its inputs: "
            f"{', '.join(w for w in _SWINGING if placed[w])})"
        )

    def pair(key: str) -> tuple[float, float]:
        return geo.pair(model, key, where) if key in model else (0.0, 0.0)

    return {
        "model": kind,
        "force": pair("force"),
        "force_swing": pair("force_swing"),
        "moment": geo.number(model, "moment", where, default=0.0),
        "moment_swing": geo.number(model, "moment_swing", where, default=0.0),
        "phase": geo.number(model, "phase", where, default=0.0),
    }


def _sliding(
    key: str, first: str, second: str | None, point: str, guide: str, tag: str, prefix: str
) -> dict:
    """A driver's translational pair: ``first`` receives N j at ``point`` (j = k x the
    unit vector at the angle ``guide``) and the couple M, named ``prefix.N``, ``prefix.M``;
    ``second`` (None: the frame) the opposites."""
    return {
        "key": key,
        "kind": "T",
        "first": first,
        "second": second,
        "point": point,
        "guide": guide,
        "tag": tag,
        "n_name": f"{prefix}.N",
        "m_name": f"{prefix}.M",
    }


# ---------------------------------------------------------------------------
# the chains
# ---------------------------------------------------------------------------
class _Balance:
    """The sums of forces and of moments about S on every body, and the largest terms."""

    def __init__(self, names: list, bodies: dict, count: int) -> None:
        self.names, self.bodies = names, bodies
        self.fsum = {b: np.zeros((count, 2)) for b in names}
        self.msum = {b: np.zeros(count) for b in names}
        self.fmax, self.mmax = np.zeros(count), np.zeros(count)
        self.tangential = np.zeros(count)

    def force(self, body: str | None, point: np.ndarray, f: np.ndarray) -> None:
        """The force f at point on body (nothing for the frame)."""
        if body is None:
            return
        m = geo.cross(point - self.bodies[body]["S"], f)
        self.fsum[body] += f
        self.msum[body] += m
        self.fmax = np.maximum(self.fmax, _norm(f))
        self.mmax = np.maximum(self.mmax, np.abs(m))

    def couple(self, body: str | None, mu: np.ndarray) -> None:
        """The couple mu on body (nothing for the frame)."""
        if body is None:
            return
        self.msum[body] += mu
        self.mmax = np.maximum(self.mmax, np.abs(mu))

    def worst(self) -> np.ndarray:
        """The worst residual per sample, relative to the largest terms."""
        tiny = np.finfo(float).tiny
        fscale, mscale = np.maximum(self.fmax, tiny), np.maximum(self.mmax, tiny)
        worst = self.tangential / fscale
        for b in self.names:
            worst = np.maximum(worst, _norm(self.fsum[b]) / fscale)
            worst = np.maximum(worst, np.abs(self.msum[b]) / mscale)
        return worst


class Chain:
    """A crank plus the dyads of a scene file, with the harness data of ``chains.toml``.

    Attributes: ``name``; ``scene`` (the parsed scene file); ``data`` (this chain's table
    of ``chains.toml``, after overrides); ``dyads`` (the scene's [[dyad]] tables, in
    order); ``links`` (name -> the scene's [[link]] table, with ``length`` where it is
    constant); ``crank`` (the scene's [crank], [ram] or [cylinder] table); ``driver``
    ("crank", "ram" or "cylinder"); ``crank_name`` (the driver's body: the crank, the ram
    or the link a cylinder turns); ``cylinder_name`` (a cylinder's); ``gravity`` (gx, gy) [m/s2];
    ``effects`` {"inertia": bool, "gravity": bool}; ``plan`` (the dyads resolved: per
    dyad its name, type, links m and n, the attachments k and p, lengths and branch);
    ``pairs`` (every pair of the mechanism, crank pivot first, as used by
    :meth:`reference`); ``bodies`` (the moving bodies: the driver's (a cylinder's link,
    ``<cylinder>.barrel`` and ``<cylinder>.rod``), then the dyads' links);
    ``point_loads`` (name -> the scene's [[load]] read: its link, point ``at``,
    ``follower``, which inputs it has, its model).
    """

    def __init__(self, name: str, scene: Mapping, table: Mapping):
        self.name = name
        self.scene = copy.deepcopy(dict(scene))
        self.data = copy.deepcopy(dict(table))
        self.description = str(self.data.get("description", name))
        where = f"scene {name}"

        grav = self.scene.get("gravity", {})
        self.gravity = (
            geo.number(grav, "x", f"{where}.gravity"),
            geo.number(grav, "y", f"{where}.gravity"),
        )
        eff = self.scene.get("effects", {})
        self.effects = {
            "inertia": bool(eff.get("inertia", True)),
            "gravity": bool(eff.get("gravity", True)),
        }
        #: gravity as it enters the dynamics and the potential energy
        self._g = np.array(self.gravity if self.effects["gravity"] else (0.0, 0.0))
        self._read_driver(where)

        self._read_links(where)
        self.dyads = [dict(d) for d in self.scene.get("dyad", [])]
        if not self.dyads and not self._moves_alone:
            raise ValueError(f"{where}: no [[dyad]]")

        self._read_motion()
        self._resolve_dyads()
        self._resolve_loads()
        self.labels = {"O": "O", "A": "A"}
        for key, value in (self.data.get("labels") or {}).items():
            self.labels[str(key)] = str(value)
        self._build_pairs()
        self._frame_cache = None
        # every dyad must assemble over a full crank turn
        self._sweep()

    def _read_driver(self, where: str) -> None:
        """The driver: [crank] (pivot ``at``, default O = (0, 0)), [ram] (a slider on
        the frame guide at angle ``guide`` through ``at``, its point R = at + x i_guide)
        or [cylinder] (between the frame and a link it turns about O)."""
        tables = {k: self.scene[k] for k in ("crank", "ram", "cylinder") if k in self.scene}
        if len(tables) != 1:
            raise ValueError(f"{where}: expected one table [crank], [ram] or [cylinder]")
        ((self.driver, table),) = tables.items()
        if not isinstance(table, Mapping):
            raise ValueError(f"{where}: [{self.driver}] must be a table")
        self.crank = dict(table)
        #: the driver's moving bodies: name -> (mass, inertia, centre of mass in its frame)
        self._parts = {}
        self._read_one_driver(self.driver, table, f"{where}.{self.driver}")

    def _read_one_driver(self, kind: str, table: Mapping, w: str) -> None:
        """One driver's table of ``kind``: its names, pivot, pin and guide into
        ``crank_name``, ``_O``, ``_pin``, ``_guide`` (a crank's length ``_r``, a cylinder's
        own attributes), its bodies added to ``_parts``."""
        if kind == "cylinder":
            self._read_cylinder(table, w)
            return
        self.crank_name = str(table.get("name", kind))
        mass = geo.number(table, "mass", w, nonnegative=True)
        com = geo.pair(table, "com", w)
        self._O = geo.pair(table, "at", w) if "at" in table or kind == "ram" else (0.0, 0.0)
        if kind == "crank":
            self._r = geo.number(table, "length", w, positive=True)
            inertia = geo.number(table, "inertia", w, nonnegative=True)
            self._pin, self._guide = (self._r, 0.0), 0.0
        else:  # the ram translates: its inertia never enters
            inertia = geo.number(table, "inertia", w, nonnegative=True, default=0.0)
            self._guide = geo.number(table, "guide", w)
            self._pin = (0.0, 0.0)
        self._parts[self.crank_name] = (mass, inertia, com)

    def _read_cylinder(self, table: Mapping, w: str) -> None:
        """[cylinder]: its name, the link it turns (the driver's body ``crank_name``), the
        link's pivot O (``at``), the barrel's pin A (``base``), the rod's pin B in the
        link's frame (``pin``), the branch, the link's mass properties and the optional
        barrel and rod tables (a part left out is massless)."""
        self.cylinder_name = str(table.get("name", "cylinder"))
        link = table.get("link")
        if not isinstance(link, str) or not link.isidentifier() or link == self.cylinder_name:
            raise ValueError(f"{w}.link: expected the name of the link the cylinder turns")
        self.crank_name = link
        self._O = geo.pair(table, "at", w)
        self._base = geo.pair(table, "base", w)
        self._pin = geo.pair(table, "pin", w)
        self._guide = 0.0
        if math.hypot(*self._pin) == 0.0:
            raise ValueError(f"{w}.pin: B must be off the pivot O, got {self._pin!r}")
        if math.hypot(self._base[0] - self._O[0], self._base[1] - self._O[1]) == 0.0:
            raise ValueError(f"{w}.base: A must be off the pivot O, got {self._base!r}")
        self._cylinder_branch = _sign(table, "branch", w)
        heavy = self.effects["inertia"] or self.effects["gravity"]
        need = None if heavy else 0.0
        need_i = None if self.effects["inertia"] else 0.0
        mass = geo.number(table, "mass", w, nonnegative=True, default=need)
        inertia = geo.number(table, "inertia", w, nonnegative=True, default=need_i)
        com = geo.pair(table, "com", w) if "com" in table or heavy else (0.0, 0.0)
        self._parts[link] = (mass, inertia, com)
        for part, sign in (("barrel", 1.0), ("rod", -1.0)):
            spec = table.get(part, {"mass": 0.0, "com": 0.0, "inertia": 0.0})
            wp = f"{w}.{part}"
            if not isinstance(spec, Mapping):
                raise ValueError(f"{wp}: expected a table {{ mass, com, inertia }}")
            stray = sorted(set(spec) - {"mass", "com", "inertia"})
            if stray:
                raise ValueError(f"{wp}.{stray[0]}: not a key of the {part} (mass, com, inertia)")
            m = geo.number(spec, "mass", wp, nonnegative=True)
            along = geo.number(spec, "com", wp)
            i = geo.number(spec, "inertia", wp, nonnegative=True, default=need_i)
            # the barrel's frame is {A; u, j_c}, the rod's {B; u, j_c}: the rod's centre
            # of mass lies com back from B towards A
            self._parts[f"{self.cylinder_name}.{part}"] = (m, i, (sign * along, 0.0))

    @property
    def _moves_alone(self) -> bool:
        """Whether the driver is a mechanism without dyads: a cylinder turns its link."""
        return self.driver == "cylinder"

    @property
    def _driver_names(self) -> tuple:
        """The names the driver takes: its body's, and a cylinder's own."""
        return (self.crank_name, getattr(self, "cylinder_name", self.crank_name))

    @property
    def _driver_links(self) -> tuple:
        """The driver's links that dyads and [[load]]s may name: the crank, the ram or the
        link a cylinder turns."""
        return (self.crank_name,)

    def _driver_alias(self, name: object) -> object:
        """The driver link's name for ``name``: "crank" stands for a crank of another name."""
        return self.crank_name if name == "crank" and self.driver == "crank" else name

    def _driver_pin(self, spec: object) -> dict | None:
        """The attachment at a driver link's pin when ``spec`` names that link (a crank's
        pin A, a ram's point R, a cylinder's pin B), else None."""
        if not isinstance(spec, str) or self._driver_alias(spec) != self.crank_name:
            return None
        pin = {"crank": "A", "ram": "R", "cylinder": "B"}[self.driver]
        return {"kind": "point", "body": self.crank_name, "at": self._pin, "label": pin}

    def _read_links(self, where: str) -> None:
        self.links = {}
        for lt in self.scene.get("link", []):
            lname = str(lt.get("name", ""))
            if not lname or lname in self.links or lname in (*self._driver_names, "frame"):
                raise ValueError(f"{where}: bad or repeated link name {lname!r}")
            wl = f"{where}.link[{lname}]"
            link = dict(lt)
            link["mass"] = geo.number(lt, "mass", wl, nonnegative=True)
            link["inertia"] = geo.number(lt, "inertia", wl, nonnegative=True)
            link["com"] = geo.pair(lt, "com", wl)
            self.links[lname] = link

    def _read_motion(self) -> None:
        md = self.data.get("motion", {})
        wm = f"{self.name}.motion"
        self._w0 = geo.number(md, "omega", wm, positive=True)
        self._variation = geo.number(md, "variation", wm, default=0.3)
        if not 0.0 <= self._variation < 1.0:
            raise ValueError(f"{wm}.variation: must be in [0, 1), got {self._variation!r}")
        if self.driver == "crank":
            self._phi0 = geo.number(md, "phi0", wm, default=0.0)
            self._scale = self._r
        else:  # a ram from its position x0, a cylinder from its length s0
            cylinder = self.driver == "cylinder"
            self._x0 = geo.number(md, "s0" if cylinder else "x0", wm, positive=cylinder)
            self._stroke = geo.number(md, "stroke", wm, positive=True)
            self._scale = self._stroke

    # ---- resolution of the scene ------------------------------------------
    def _frame_table(
        self, frame: Mapping | None, dyad: str, pair: str, what: str, on: str
    ) -> tuple[str, str]:
        """Where the frame's table for ``dyad.pair`` stands, and its label; an error if
        it is missing."""
        where = f"{self.name}.frame.{dyad}.{pair}"
        if not isinstance(frame, Mapping):
            raise ValueError(f"{where}: missing {what} (the scene puts {dyad}.{pair} on {on})")
        return where, str(frame.get("label", f"{dyad}.{pair}"))

    def _frame_label(self, frame: Mapping | None, dyad: str, pair: str) -> str:
        """The label of a frame part the scene places itself: chains.toml's frame table,
        else its [labels], else ``dyad.pair``."""
        if isinstance(frame, Mapping) and "label" in frame:
            return str(frame["label"])
        return str((self.data.get("labels") or {}).get(f"{dyad}.{pair}", f"{dyad}.{pair}"))

    def _frame_pivot(self, spec: object, frame: Mapping | None, dyad: str, pair: str) -> dict:
        """A fixed pivot: where the scene says (``at``), else chains.toml's ``position``."""
        if isinstance(spec, Mapping):
            where = f"scene {self.name}.dyad[{dyad}].{'k' if pair == 'D_m' else 'p'}"
            pos = geo.pair(spec, "at", where)
            label = self._frame_label(frame, dyad, pair)
        else:
            where, label = self._frame_table(frame, dyad, pair, "fixed pivot", "the frame")
            pos = geo.pair(frame, "position", where)
        return {"kind": "pivot", "body": None, "position": pos, "label": label}

    def _frame_guide(
        self, spec: Mapping, frame: Mapping | None, dyad: str, pair: str, where: str
    ) -> dict:
        """A frame guide: its angle from the scene, its point from the scene's ``at`` or
        else (0, chains.toml's ``height``)."""
        angle = geo.number(spec, "guide", where)
        if "at" in spec:
            point, label = geo.pair(spec, "at", where), self._frame_label(frame, dyad, pair)
        else:
            at, label = self._frame_table(frame, dyad, pair, "guide height", "a frame guide")
            point = (0.0, geo.number(frame, "height", at))
        return {"kind": "guide", "body": None, "angle": angle, "point": point, "label": label}

    def _attachment(self, spec: Mapping, dyad: str, pair: str, done: dict):
        """The external link carrying pair ``pair`` ("D_m" or "D_n") of ``dyad``."""
        where = f"scene {self.name}.dyad[{dyad}].{'k' if pair == 'D_m' else 'p'}"
        frame = (self.data.get("frame") or {}).get(dyad, {}).get(pair)
        if spec == "frame":
            return self._frame_pivot(spec, frame, dyad, pair)
        pinned = self._driver_pin(spec)
        if pinned is not None:
            return pinned
        if isinstance(spec, Mapping):
            body = spec.get("link")
            if body == "frame" and "guide" in spec:
                return self._frame_guide(spec, frame, dyad, pair, where)
            if body == "frame":
                return self._frame_pivot(spec, frame, dyad, pair)
            body = self._driver_alias(body)
            if body not in self._driver_links and body not in done:
                raise ValueError(
                    f"{where}: link {body!r} is not the crank nor a link of an earlier dyad"
                )
            if "guide" in spec:
                # a guide fixed in the moving link: through ``at``, along i_body rotated
                # by ``guide``
                return {
                    "kind": "link_guide",
                    "body": body,
                    "at": geo.pair(spec, "at", where),
                    "angle": geo.number(spec, "guide", where),
                    "label": f"{dyad}.guide_k",
                }
            return {
                "kind": "point",
                "body": body,
                "at": geo.pair(spec, "at", where),
                "label": f"{dyad}.{pair}",
            }
        raise ValueError(f"{where}: expected 'frame', 'crank' or a table, got {spec!r}")

    def _checked_dyad(self, d: Mapping, done: set) -> tuple:
        """(name, type, m, n, where) of a [[dyad]] table, checked against the earlier ones."""
        dname = str(d.get("name", ""))
        where = f"scene {self.name}.dyad[{dname}]"
        taken = any(p["name"] == dname for p in self.plan) or dname in self._driver_names
        if not dname or taken:
            raise ValueError(f"{where}: bad or repeated dyad name")
        kind = str(d.get("type", "")).upper()
        if kind not in PAIR_KINDS:
            raise ValueError(f"{where}.type: expected one of {sorted(PAIR_KINDS)}, got {kind!r}")
        m, n = d.get("m"), d.get("n")
        for g in (m, n):
            if g not in self.links:
                raise ValueError(f"{where}: unknown link {g!r}")
            if g in done:
                raise ValueError(f"{where}: link {g!r} belongs to an earlier dyad")
        if m == n:
            raise ValueError(f"{where}: links m and n must differ")
        return dname, kind, m, n, where

    def _rrr_entry(self, entry: dict, where: str, branches: Mapping) -> None:
        k, p, m, n = entry["k"], entry["p"], entry["m"], entry["n"]
        if k["kind"] in _GUIDES or p["kind"] in _GUIDES:
            raise ValueError(f"{where}: an RRR dyad has revolute pairs at D_m and D_n")
        entry["lm"] = geo.number(self.links[m], "length", f"{where}.{m}", positive=True)
        entry["ln"] = geo.number(self.links[n], "length", f"{where}.{n}", positive=True)
        entry["branch"] = self._branch(entry, where, branches)

    def _branch(self, entry: dict, where: str, branches: Mapping) -> float:
        """A dyad's assembly branch: the scene's ``branch``, else chains.toml's."""
        if "branch" in entry["spec"]:
            return _sign(entry["spec"], "branch", where)
        return _sign(branches, entry["name"], f"{self.name}.branches")

    def _rrt_entry(self, entry: dict, where: str, branches: Mapping) -> None:
        k, p, m, n = entry["k"], entry["p"], entry["m"], entry["n"]
        lm_t = self.links[m]
        if k["kind"] not in _GUIDES:
            raise ValueError(
                f"{where}: an RRT dyad needs k = {{ link = 'frame', guide = angle }} "
                f"or a guide on a link, {{ link = '...', guide = angle, at = [x, y] }}"
            )
        if p["kind"] in _GUIDES:
            raise ValueError(f"{where}: an RRT dyad has a revolute pair at D_n")
        entry["lm"] = geo.number(lm_t, "length", f"{where}.{m}", nonnegative=True)
        entry["ln"] = geo.number(self.links[n], "length", f"{where}.{n}", positive=True)
        if "angle" in lm_t and "turn" in lm_t:
            raise ValueError(f"{where}.{m}: give its 'angle' or its 'turn', not both")
        if k["kind"] == "guide":
            # the slider translates on the fixed guide: its angle is constant, given
            # absolute (angle) or from the guide (turn)
            turn = geo.number(lm_t, "turn", f"{where}.{m}", default=0.0)
            entry["m_angle"] = geo.number(lm_t, "angle", f"{where}.{m}", default=k["angle"] + turn)
        elif "angle" in lm_t:
            raise ValueError(
                f"{where}.{m}.angle: the slider turns with link "
                f"{k['body']!r} (its angle is {k['body']}.angle + guide); "
                f"remove its 'angle'"
            )
        entry["branch"] = self._branch(entry, where, branches)

    def _rtr_entry(self, entry: dict, where: str) -> None:
        k, p, m, n = entry["k"], entry["p"], entry["m"], entry["n"]
        if "branch" in entry["spec"] and _sign(entry["spec"], "branch", where) != 1.0:
            raise ValueError(f"{where}.branch: only branch +1 (l_m > 0) is handled")
        if k["kind"] in _GUIDES or p["kind"] in _GUIDES:
            raise ValueError(f"{where}: an RTR dyad has revolute pairs at D_m and D_n")
        if "length" in self.links[m]:
            raise ValueError(
                f"{where}.{m}: the slotted link's length |D_m E| varies; remove its 'length'"
            )
        entry["ln"] = geo.number(self.links[n], "length", f"{where}.{n}", nonnegative=True)
        if entry["ln"] != 0.0:
            raise ValueError(
                f"{where}.{n}.length: only a block on the pin (length 0) "
                f"is handled, got {entry['ln']!r}"
            )

    def _resolve_dyads(self) -> None:
        done = set()
        branches = self.data.get("branches") or {}
        self.plan = []
        for d in self.dyads:
            dname, kind, m, n, where = self._checked_dyad(d, done)
            k = self._attachment(d.get("k"), dname, "D_m", done)
            p = self._attachment(d.get("p"), dname, "D_n", done)
            entry = {"name": dname, "type": kind, "m": m, "n": n, "k": k, "p": p, "spec": d}
            if kind == "RRR":
                self._rrr_entry(entry, where, branches)
            elif kind == "RRT":
                self._rrt_entry(entry, where, branches)
            else:  # RTR
                self._rtr_entry(entry, where)
            self.plan.append(entry)
            done.update((m, n))
        unused = set(self.links) - done
        if unused:
            raise ValueError(f"scene {self.name}: links {sorted(unused)} belong to no dyad")
        # derived constant lengths
        for entry in self.plan:
            if "lm" in entry:
                self.links[entry["m"]]["length"] = entry["lm"]
            self.links[entry["n"]]["length"] = entry["ln"]
        self.bodies = list(self._parts) + [g for e in self.plan for g in (e["m"], e["n"])]

    def _resolve_loads(self):
        """The load models of chains.toml's [.load]: one per link the scene's [loads]
        lists, one per [[load]] of the scene (by its name)."""
        loads = self.scene.get("loads", {})
        listed = {"force": list(loads.get("force", [])), "moment": list(loads.get("moment", []))}
        self.point_loads = self._read_point_loads()
        self._loads = {}
        for key, model in (self.data.get("load") or {}).items():
            where = f"{self.name}.load.{key}"
            if key in self.point_loads:
                self.point_loads[key]["model"] = _swinging(model, self.point_loads[key], where)
            elif key in self.links:
                self._loads[key] = self._link_model(key, model, listed, where)
            else:
                raise ValueError(f"{where}: unknown link or [[load]] {key!r}")
        for lname in listed["force"] + listed["moment"]:
            if lname not in self._loads:
                raise ValueError(
                    f"{self.name}.load: the scene loads link {lname!r} but "
                    f"chains.toml has no model for it"
                )
        for name, placed in self.point_loads.items():
            if "model" not in placed:
                raise ValueError(
                    f"{self.name}.load: the scene has the [[load]] {name!r} but "
                    f"chains.toml has no model for it"
                )

    def _link_model(self, lname: str, model: Mapping, listed: Mapping, where: str) -> dict:
        """The load model of a link the scene lists under [loads]."""
        kind = model.get("model")
        if kind == "cutting":
            _require_listed(listed["force"], lname, "force", where)
            return {
                "model": kind,
                "F0": geo.number(model, "F0", where),
                "v_ref": geo.number(model, "v_ref", where, positive=True),
                "s": _sign(model, "s", where) if "s" in model else 1.0,
            }
        if kind == "resisting-torque":
            _require_listed(listed["moment"], lname, "moment", where)
            return {
                "model": kind,
                "T0": geo.number(model, "T0", where),
                "w_ref": geo.number(model, "w_ref", where, positive=True),
                "c": geo.number(model, "c", where),
            }
        if kind == "payload":
            _require_listed(listed["force"], lname, "force", where)
            return {"model": kind, "force": geo.pair(model, "force", where)}
        if kind == "resisting-force":
            _require_listed(listed["force"], lname, "force", where)
            dyad = next((e for e in self.plan if e["type"] == "RRT" and e["m"] == lname), None)
            if dyad is None:
                raise ValueError(
                    f"{where}: model 'resisting-force' needs a slider (link m "
                    f"of an RRT dyad); {lname!r} is none"
                )
            return {
                "model": kind,
                "F0": geo.number(model, "F0", where),
                "v_ref": geo.number(model, "v_ref", where, positive=True),
                "dyad": dyad["name"],
            }
        raise ValueError(
            f"{where}.model: expected 'cutting', 'resisting-torque', "
            f"'resisting-force' or 'payload', got {kind!r}"
        )

    def _read_point_loads(self) -> dict:
        """The scene's [[load]] tables, by name: a force at a point ``at`` of a moving link
        (the driver included; default its centre of mass), its components global or the
        link's own (``components = "link"``: a follower force), and a pure moment."""
        rows = self.scene.get("load", [])
        if not isinstance(rows, list) or not all(isinstance(r, Mapping) for r in rows):
            raise ValueError(f"scene {self.name}: [[load]] must be an array of tables")
        taken = set(self.links) | {*self._driver_names, "frame", "gravity"}
        taken |= {e["name"] for e in self.plan}
        out = {}
        for row in rows:
            name = row.get("name")
            where = f"scene {self.name}.load[{name}]"
            if not isinstance(name, str) or not name.isidentifier() or name in taken | set(out):
                raise ValueError(
                    f"{where}.name: expected an identifier that names no link, dyad, "
                    "driver or other load"
                )
            link = row.get("link")
            if link not in self._driver_links and link not in self.links:
                raise ValueError(f"{where}.link: unknown link {link!r}")
            com = self._parts[link][2] if link in self._driver_links else self.links[link]["com"]
            components = row.get("components", "global")
            if components not in ("global", "link"):
                raise ValueError(
                    f"{where}.components: expected 'global' or 'link', got {components!r}"
                )
            force, moment = row.get("force", True), row.get("moment", False)
            if not (isinstance(force, bool) and isinstance(moment, bool) and (force or moment)):
                raise ValueError(f"{where}: 'force' and 'moment' are true or false, one true")
            out[name] = {
                "name": name,
                "link": link,
                "at": geo.pair(row, "at", where) if "at" in row else tuple(com),
                "follower": components == "link",
                "force": force,
                "moment": moment,
            }
        return out

    def _build_pairs(self):
        """Every pair: output key, kind, the body named first (it receives +R), the other
        body (None: the frame), kin key of its point, and for a translational pair the
        kin key of its guide's angle."""
        self.pairs = self._driver_pairs()
        for pr in self.pairs:
            pr.setdefault("second", None)
            pr["dyad"] = None
        for e in self.plan:
            kinds = PAIR_KINDS[e["type"]]
            others = {"D_m": e["k"]["body"], "E": e["n"], "D_n": e["p"]["body"]}
            firsts = {"D_m": e["m"], "E": e["m"], "D_n": e["n"]}
            for (point, tag), kind in zip(_TAGS, kinds, strict=False):
                guide = None
                if kind == "T":
                    # D_m: the guide of link k; E: the slot along i_m
                    guide = f"{e['name']}.guide_k.angle" if point == "D_m" else f"{e['m']}.angle"
                self.pairs.append(
                    {
                        "key": f"{e['name']}.R_{tag}",
                        "kind": kind,
                        "first": firsts[point],
                        "second": others[point],
                        "point": f"{e['name']}.{point}",
                        "guide": guide,
                        "dyad": e["name"],
                        "tag": tag,
                        "n_name": f"{e['name']}.N_{tag}",
                        "m_name": f"{e['name']}.M_{tag}",
                    }
                )

    def _driver_pairs(self) -> list:
        """The pairs of the driver's bodies with the frame (and with each other)."""
        c = self.crank_name
        if self.driver == "crank":
            return [{"key": f"{c}.R_O", "kind": "R", "first": c, "point": "O", "tag": "O"}]
        if self.driver == "ram":  # the ram on its frame guide: its force N j at R, couple M
            return [_sliding(f"{c}.R_G", c, None, "R", f"{c}.angle", "G", c)]
        return self._cylinder_pairs()

    def _cylinder_pairs(self) -> list:
        """The cylinder's pairs: the link's pivot O and the barrel's pin A on the frame, the
        rod's pin B on the link (``R_B`` the force on the link), and the sliding pair of
        the rod in the barrel (the rod receives N j_c at B and the couple M)."""
        c, cyl = self.crank_name, self.cylinder_name
        barrel, rod = f"{cyl}.barrel", f"{cyl}.rod"
        return [
            {"key": f"{c}.R_O", "kind": "R", "first": c, "point": "O", "tag": "O"},
            {"key": f"{cyl}.R_A", "kind": "R", "first": barrel, "point": "A", "tag": "A"},
            {"key": f"{cyl}.R_B", "kind": "R", "first": c, "second": rod, "point": f"{cyl}.B"}
            | {"tag": "B"},
            _sliding(f"{cyl}.R_slide", rod, barrel, f"{cyl}.B", f"{cyl}.angle", "slide", cyl),
        ]

    def output_names(self) -> list:
        """The names of the outputs of :meth:`reference`, in the order of the unknowns."""
        names = []
        for pr in self.pairs:
            names += [f"{pr['key']}.x", f"{pr['key']}.y"]
            if pr["kind"] == "T":
                names += [pr["n_name"], pr["m_name"]]
        return names + self.effort_names

    @property
    def effort_names(self) -> list:
        """The names of the drivers' efforts, in the order of their unknowns."""
        return [self.drive_output]

    @property
    def drive_output(self) -> str:
        """The name of the driver's effort: ``<crank>.torque`` (N m), ``<ram>.force``
        (N, along the ram's guide) or ``<cylinder>.force`` (N, the axial force)."""
        if self.driver == "cylinder":
            return f"{self.cylinder_name}.force"
        return f"{self.crank_name}.{'torque' if self.driver == 'crank' else 'force'}"

    @property
    def driver_name(self) -> str:
        """The prefix of the driver's motion: the crank's, the ram's or the cylinder's name."""
        return self.cylinder_name if self.driver == "cylinder" else self.crank_name

    @property
    def coordinate_names(self) -> tuple[str, str, str]:
        """The kinematics keys (and FMU inputs) of the driver's coordinate, rate and
        acceleration: ``crank.angle``, ``.omega``, ``.epsilon``; ``ram.position``,
        ``.velocity``, ``.acceleration``; ``cylinder.length``, ``.velocity``, ``.acceleration``."""
        names = {
            "crank": ("angle", "omega", "epsilon"),
            "ram": ("position", "velocity", "acceleration"),
            "cylinder": ("length", "velocity", "acceleration"),
        }[self.driver]
        return tuple(f"{self.driver_name}.{k}" for k in names)

    # ---- motion -----------------------------------------------------------
    def motion(
        self, kind: str = "constant", revolutions: float = 2.0
    ) -> CrankMotion | motion_.RamMotion:
        """The driver's motion. A crank: ``revolutions`` full turns (counter-clockwise);
        kind "constant": omega = w0; "varying": omega = w0 (1 + a sin(w0 t)), phi exact. A
        ram or a cylinder: ``revolutions`` strokes out and back (:func:`.motion.stroke`),
        the ram's position or the cylinder's length."""
        revolutions = motion_.checked_request(kind, revolutions)
        if self.driver != "crank":
            return motion_.stroke(
                kind, self._x0, self._stroke, self._w0, self._variation, revolutions
            )
        return motion_.rotating(kind, self._w0, self._variation, self._phi0, revolutions)

    # ---- kinematics -------------------------------------------------------
    def kinematics(self, t: np.ndarray, motion: CrankMotion | motion_.RamMotion) -> dict:
        """Positions, velocities, accelerations and active loads at the times ``t`` (N,)
        (complex ``t``: complex kinematics, analytic in t, for complex-step derivatives;
        the conditioning is then that of the real parts).

        Keys (arrays over the N samples; points and vectors (N, 2), scalars (N,)):
        ``t``; ``crank.angle``, ``crank.omega``, ``crank.epsilon`` (a ram: ``ram.position``,
        ``ram.velocity``, ``ram.acceleration``, its point ``R`` with ``v_R``, ``a_R``, and
        ``ram.angle`` = its guide's angle, ``ram.omega`` = ``ram.epsilon`` = 0); per link L of the
        scene: ``L.angle``, ``L.omega``, ``L.epsilon``, ``L.accel_d`` (and ``.x``, ``.y``),
        ``L.vel_d`` (velocity of the material point at D_L), ``L.length``,
        ``L.length_rate``, ``L.length_accel``, ``L.force`` (and ``.x``, ``.y``),
        ``L.moment``; points ``O``, ``A``, ``S_crank``, ``S_L``, ``<dyad>.D_m``,
        ``<dyad>.E``, ``<dyad>.D_n``; velocities ``v_A``, ``v_S_crank``, ``v_S_L``;
        accelerations ``a_A``, ``a_S_crank``, ``a_S_L``; ``<dyad>.conditioning``;
        per [[load]] NAME its inputs ``NAME.force.x``, ``NAME.force.y``, ``NAME.moment``
        (those it has, components as the scene gives them) and its point ``P_NAME`` with
        its velocity ``v_P_NAME``;
        ``<dyad>.guide_k.angle`` for a guide on link k; for a guide on a moving link also
        ``<dyad>.slide_k``, ``<dyad>.slide_k_rate``, ``<dyad>.slide_k_accel``.
        A cylinder CYL turning link L: ``CYL.length``, ``CYL.velocity``,
        ``CYL.acceleration`` (its motion), ``L.angle``, ``L.omega``, ``L.epsilon`` (the
        link's), ``CYL.angle``, ``CYL.omega``, ``CYL.epsilon`` (its axis u's, as those of
        ``CYL.barrel`` and ``CYL.rod``), the points ``O``, ``A``, ``CYL.B`` with ``v_B``,
        ``a_B``, ``CYL.conditioning``, and ``S_``, ``v_S_``, ``a_S_`` of the link, the
        barrel and the rod.
        Non-array entries: ``frame`` ({"pivots": {label: (x, y)}, "guides": {label:
        ((x0, y0), (x1, y1))}}, and "link_guides" with guides on moving links, see
        :meth:`_frame`) and ``mechanism`` (the name).
        """
        t, q, dq, ddq = motion.sampled(t)
        kin = self._solve(t, q, dq, ddq)
        kin["frame"] = self.frame()
        kin["mechanism"] = self.name
        return kin

    @staticmethod
    def _material(state: dict, at: Callable) -> dict:
        """Position, velocity, acceleration of the point fixed at ``at`` in a body's frame."""
        i = geo.unit(state["angle"])
        rel = at[0] * i + at[1] * geo.rot90(i)
        w, e = geo.col(state["omega"]), geo.col(state["epsilon"])
        return (
            state["D"] + rel,
            state["vD"] + w * geo.rot90(rel),
            state["aD"] + e * geo.rot90(rel) - w * w * rel,
        )

    def _point(self, att: dict, states: dict, shape: tuple):
        if att["kind"] == "pivot":
            z = np.zeros(shape + (2,))
            return z + np.asarray(att["position"]), z.copy(), z.copy()
        return self._material(states[att["body"]], att["at"])

    def _dyad_states(self, e: dict, states: dict, shape: tuple, kin: dict) -> tuple:
        """(state of m, state of n, E) of one dyad from the states of the links it is on;
        a guide's angle and slide go into kin."""
        dn = e["name"]
        P, vP, aP = self._point(e["p"], states, shape)  # D_n, on link p
        if e["type"] == "RRR":
            K, vK, aK = self._point(e["k"], states, shape)  # D_m, on link k
            return _rrr(K, vK, aK, P, vP, aP, e["lm"], e["ln"], e["branch"], dn)
        if e["type"] == "RRT" and e["k"]["kind"] == "link_guide":
            k = e["k"]
            sm, sn, E, slide = _rrt_on_link(
                states[k["body"]], k["at"], k["angle"], e["lm"], P, vP, aP, e["ln"], e["branch"], dn
            )
            kin[f"{dn}.guide_k.angle"] = sm["angle"].copy()
            kin[f"{dn}.slide_k"], kin[f"{dn}.slide_k_rate"], kin[f"{dn}.slide_k_accel"] = slide
            return sm, sn, E
        if e["type"] == "RRT":
            sm, sn, E = _rrt(
                e["k"]["angle"],
                e["k"]["point"],
                e["lm"],
                e["m_angle"],
                P,
                vP,
                aP,
                e["ln"],
                e["branch"],
                dn,
            )
            kin[f"{dn}.guide_k.angle"] = np.full(shape, e["k"]["angle"])
            return sm, sn, E
        K, vK, aK = self._point(e["k"], states, shape)
        return _rtr(K, vK, aK, P, vP, aP)

    @staticmethod
    def _store_dyad(e: dict, sm: dict, sn: dict, E: np.ndarray, shape: tuple, kin: dict) -> None:
        """A dyad's points and its links' motion under their kinematics names."""
        dn = e["name"]
        kin[f"{dn}.D_m"], kin[f"{dn}.E"], kin[f"{dn}.D_n"] = sm["D"], E, sn["D"]
        for g, st in ((e["m"], sm), (e["n"], sn)):
            for key in ("angle", "omega", "epsilon", "length", "length_rate", "length_accel"):
                kin[f"{g}.{key}"] = np.broadcast_to(geo.inexact(st[key]), shape).copy()
            kin[f"{g}.accel_d"] = st["aD"]
            kin[f"{g}.vel_d"] = st["vD"]

    def _active_load(self, g: str, kin: dict, zero: np.ndarray, z2: np.ndarray) -> tuple:
        """(force at S, moment) of link g's load model over the samples."""
        force, moment = z2.copy(), zero.copy()
        model = self._loads.get(g)
        if model and model["model"] == "payload":
            force = z2 + np.asarray(model["force"])
        elif model and model["model"] == "cutting":
            v, s = kin[f"v_S_{g}"][:, 0], model["s"]
            force[:, 0] = -s * model["F0"] * 0.5 * (1.0 + np.tanh(s * v / model["v_ref"]))
        elif model and model["model"] == "resisting-torque":
            om = kin[f"{g}.omega"]
            moment = -model["T0"] * np.tanh(om / model["w_ref"]) - model["c"] * om
        elif model and model["model"] == "resisting-force":
            dn = model["dyad"]
            i_k = geo.unit(kin[f"{dn}.guide_k.angle"])
            if f"{dn}.slide_k_rate" in kin:  # guide on a moving link
                v_rel = kin[f"{dn}.slide_k_rate"]
            else:  # frame guide
                v_rel = geo.dot(kin[f"{g}.vel_d"], i_k)
            force = geo.col(-model["F0"] * np.tanh(v_rel / model["v_ref"])) * i_k
        return force, moment

    def _place_load(self, placed: dict, state: dict, kin: dict, zero: np.ndarray) -> None:
        """A [[load]] over the samples: its point P with P's velocity (``P_NAME``,
        ``v_P_NAME``) and its inputs from its model, ``NAME.force.x/.y`` (as the scene's
        components say: global, or along the link's i and j) and ``NAME.moment``: each
        a mean plus a swing times sin(omega t + phase), omega the motion's."""
        name, model = placed["name"], placed["model"]
        kin[f"P_{name}"], kin[f"v_P_{name}"], _ = self._material(state, placed["at"])
        wave = np.sin(self._w0 * geo.inexact(kin["t"]) + model["phase"]) + zero
        if placed["force"]:
            for k, c in enumerate("xy"):
                kin[f"{name}.force.{c}"] = model["force"][k] + model["force_swing"][k] * wave
        if placed["moment"]:
            kin[f"{name}.moment"] = model["moment"] + model["moment_swing"] * wave

    def _driver(self, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> tuple:
        """The states of the driver's bodies and its kinematics entries, from its
        coordinate q (crank angle, ram position or cylinder length) and its first two time
        derivatives."""
        c = self.crank_name
        z2 = np.zeros(q.shape + (2,))
        pivot = z2 + np.asarray(self._O)
        if self.driver == "cylinder":
            states, kin = self._cylinder_states(q, dq, ddq)
        elif self.driver == "crank":
            state = {"angle": q, "omega": dq, "epsilon": ddq, "D": pivot, "vD": z2, "aD": z2}
            pin = self._material(state, self._pin)
            kin = {f"{c}.angle": q, f"{c}.omega": dq, f"{c}.epsilon": ddq, "O": pivot}
            kin.update(zip(("A", "v_A", "a_A"), pin, strict=True))
            states = {c: state}
        else:
            i_g = geo.unit(self._guide)
            zero = np.zeros(q.shape)
            R, vR, aR = pivot + geo.col(q) * i_g, geo.col(dq) * i_g, geo.col(ddq) * i_g
            state = {"angle": zero + self._guide, "omega": zero, "epsilon": zero}
            state.update(D=R, vD=vR, aD=aR)
            kin = {f"{c}.position": q, f"{c}.velocity": dq, f"{c}.acceleration": ddq}
            kin.update({f"{c}.angle": state["angle"], f"{c}.omega": zero, f"{c}.epsilon": zero})
            kin.update(R=R, v_R=vR, a_R=aR)
            states = {c: state}
        kin["t"] = t
        for b, state in states.items():
            kin[f"{b}.accel_d"] = state["aD"]
        return states, kin

    def _cylinder_states(self, s: np.ndarray, ds: np.ndarray, dds: np.ndarray) -> tuple:
        """The link's, the barrel's and the rod's states and the cylinder's kinematics
        entries at the lengths s with their rates (:func:`cylinder_triangle`, O and A
        at rest on the frame)."""
        c, cyl = self.crank_name, self.cylinder_name
        z2 = np.zeros(np.shape(s) + (2,))
        pivot, base = z2 + np.asarray(self._O), z2 + np.asarray(self._base)
        at_rest = (z2, z2)
        g = cylinder_triangle(
            (pivot, *at_rest), (base, *at_rest), self._pin, self._cylinder_branch, s, ds, dds, cyl
        )
        link = _state(g["theta"], g["omega"], g["epsilon"], pivot, z2, z2.copy(), 0.0)
        axis = (g["psi"], g["Omega"], g["Omega_dot"])
        barrel = _state(*axis, base, z2.copy(), z2.copy(), 0.0)
        rod = _state(*(a.copy() for a in axis), g["B"], g["v_B"], g["a_B"], 0.0)
        kin = {f"{cyl}.length": s, f"{cyl}.velocity": ds, f"{cyl}.acceleration": dds}
        for body, st in ((c, link), (cyl, barrel)):
            for key in ("angle", "omega", "epsilon"):
                kin[f"{body}.{key}"] = st[key]
        kin.update({"O": pivot, "A": base, f"{cyl}.B": g["B"], "v_B": g["v_B"], "a_B": g["a_B"]})
        kin[f"{cyl}.conditioning"] = g["conditioning"]
        states = {c: link, f"{cyl}.barrel": barrel, f"{cyl}.rod": rod}
        for body in (f"{cyl}.barrel", f"{cyl}.rod"):
            for key in ("angle", "omega", "epsilon"):
                kin[f"{body}.{key}"] = states[body][key]
        return states, kin

    def _solve(self, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> dict:
        states, kin = self._driver(t, q, dq, ddq)
        return self._completed(states, kin, q.shape, np.result_type(q, dq, ddq, float))

    def _completed(self, states: dict, kin: dict, shape: tuple, dtype: np.dtype) -> dict:
        """The kinematics from the driver's states on: the dyads, the centres of mass and
        the loads (``kin`` completed and returned)."""
        zero = np.zeros(shape, dtype=dtype)
        z2 = np.zeros(shape + (2,), dtype=zero.dtype)
        for e in self.plan:
            sm, sn, E = self._dyad_states(e, states, shape, kin)
            states[e["m"]], states[e["n"]] = sm, sn
            self._store_dyad(e, sm, sn, E, shape, kin)
            kin[f"{e['name']}.conditioning"] = self._conditioning(e, kin)
        # centres of mass (S = D + rel, rel fixed in the body)
        for b in self.bodies:
            com = self._parts[b][2] if b in self._parts else self.links[b]["com"]
            kin[f"S_{b}"], kin[f"v_S_{b}"], kin[f"a_S_{b}"] = self._material(states[b], com)
        for g in self.links:
            kin[f"{g}.force"], kin[f"{g}.moment"] = self._active_load(g, kin, zero, z2)
        for placed in self.point_loads.values():
            self._place_load(placed, states[placed["link"]], kin, zero)
        # scalar views with the FMU input names
        for g in self.links:
            for key in ("accel_d", "force"):
                kin[f"{g}.{key}.x"] = kin[f"{g}.{key}"][:, 0].copy()
                kin[f"{g}.{key}.y"] = kin[f"{g}.{key}"][:, 1].copy()
        return kin

    def _conditioning(self, e: dict, kin: dict) -> np.ndarray:
        """A dyad's conditioning, as the C core computes it, of the real parts."""
        kin = {key: np.real(v) for key, v in kin.items() if not isinstance(v, (str, dict))}
        i_m, i_n = geo.unit(kin[f"{e['m']}.angle"]), geo.unit(kin[f"{e['n']}.angle"])
        if e["type"] == "RRR":
            return np.abs(geo.dot(i_m, geo.rot90(i_n)))
        if e["type"] == "RRT" and e["k"]["kind"] == "link_guide":
            return np.abs(geo.dot(i_n, geo.unit(kin[f"{e['name']}.guide_k.angle"])))
        if e["type"] == "RRT":
            return np.abs(geo.dot(i_n, geo.unit(e["k"]["angle"])))
        lm, ln = kin[f"{e['m']}.length"], kin[f"{e['n']}.length"]
        beta = geo.col(lm) * i_m - geo.col(ln) * i_n  # D_n - D_m
        dist = _norm(beta)
        i_beta = beta / geo.col(np.where(dist > 0, dist, 1.0))
        return np.minimum(np.abs(geo.dot(i_beta, i_m)), dist / (lm + ln))

    def sweep_coordinates(self, count: int = 720) -> np.ndarray:
        """The driver's coordinate over its whole range: a full crank turn, or the ram's
        or the cylinder's stroke (both ends included)."""
        if self.driver == "crank":
            return self._phi0 + np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
        return self._x0 + np.linspace(0.0, self._stroke, count)

    def positions(self, q: np.ndarray, dq: np.ndarray | None = None) -> dict:
        """The kinematics at the driver coordinates ``q`` (N,) with the driver's speed
        ``dq`` (default 1) and no acceleration: at unit speed the velocities are the
        derivatives in q and the accelerations the second derivatives."""
        q = geo.inexact(np.atleast_1d(q))
        dq = np.ones_like(q) if dq is None else np.broadcast_to(geo.inexact(dq), q.shape)
        return self._solve(np.zeros(q.shape), q, dq, np.zeros_like(q))

    def _sweep(self, count: int = 720):
        """Positions over the driver's whole range (the motion does not matter for them)."""
        q = self.sweep_coordinates(count)
        zero = np.zeros_like(q)
        try:
            with np.errstate(invalid="raise", divide="raise"):
                return self._solve(zero, q, zero + self._w0, zero)
        except FloatingPointError:  # pragma: no cover - _rrr/_rrt raise first
            raise ValueError(
                f"{self.name}: a dyad does not assemble over the driver's range"
            ) from None

    def frame(self) -> dict:
        """Fixed pivots {label: (x, y)} and fixed guides {label: ((x0, y0), (x1, y1))};
        with guides on moving links also ``link_guides`` {label: {"link": k, "at": (x, y),
        "angle": guide, "range": (s0, s1)}}: the part s0 <= slide_k <= s1 of the guide
        that the slider uses over a crank turn, with some margin."""
        if self._frame_cache is None:
            pivots, guides, link_guides = {}, {}, {}
            if self.driver == "crank":
                pivots["O"] = tuple(self._O)
            elif self.driver == "cylinder":  # the link's pivot and the barrel's pin
                pivots["O"], pivots["A"] = tuple(self._O), tuple(self._base)
            else:  # the ram's guide over its stroke
                i = np.array([math.cos(self._guide), math.sin(self._guide)])
                pad = 0.25 * self._stroke
                span = (self._x0 - pad, self._x0 + self._stroke + pad)
                ends = [np.asarray(self._O) + x * i for x in span]
                guides[self.crank_name] = tuple(tuple(map(float, p)) for p in ends)
            sweep = None
            for e in self.plan:
                for att, pair in ((e["k"], "D_m"), (e["p"], "D_n")):
                    if att["kind"] == "pivot":
                        pivots[att["label"]] = tuple(att["position"])
                    elif att["kind"] == "guide":
                        sweep = self._sweep() if sweep is None else sweep
                        pts = sweep[f"{e['name']}.{pair}"]
                        i = np.array([math.cos(att["angle"]), math.sin(att["angle"])])
                        s = pts @ i
                        pad = 0.25 * float(np.ptp(s)) + 0.5 * self._scale
                        base = np.asarray(att["point"], dtype=float)
                        base = base - (base @ i) * i  # foot of O on the guide line
                        x0, x1 = base + (s.min() - pad) * i, base + (s.max() + pad) * i
                        guides[att["label"]] = (tuple(map(float, x0)), tuple(map(float, x1)))
                    elif att["kind"] == "link_guide":
                        sweep = self._sweep() if sweep is None else sweep
                        s = sweep[f"{e['name']}.slide_k"]
                        pad = 0.25 * float(np.ptp(s)) + 0.5 * self._scale
                        link_guides[att["label"]] = {
                            "link": att["body"],
                            "at": tuple(att["at"]),
                            "angle": att["angle"],
                            "range": (float(s.min() - pad), float(s.max() + pad + e["lm"])),
                        }
            self._frame_cache = {"pivots": pivots, "guides": guides}
            if link_guides:
                self._frame_cache["link_guides"] = link_guides
        return copy.deepcopy(self._frame_cache)

    # ---- dynamics ---------------------------------------------------------
    def _body_data(self, kin: dict):
        """Per body: mass, inertia, S (N, 2), a_S (N, 2) from accel_d, omega, epsilon and
        the centre of mass, epsilon, the load of its [loads] model (at S) and the
        [[load]]s on it, (P, F, M) each (:meth:`placed_load`)."""
        out = {}
        for b in self.bodies:
            mass, inertia = self._mass(b)
            com = self._parts[b][2] if b in self._parts else self.links[b]["com"]
            a_d = np.asarray(kin[f"{b}.accel_d"], dtype=float)
            i = geo.unit(kin[f"{b}.angle"])
            rel = com[0] * i + com[1] * geo.rot90(i)
            w, e = np.asarray(kin[f"{b}.omega"], float), np.asarray(kin[f"{b}.epsilon"], float)
            a_s = a_d + geo.col(e) * geo.rot90(rel) - geo.col(w * w) * rel
            # the driver's bodies carry [[load]]s only
            force = kin[f"{b}.force"] if b in self.links else np.zeros_like(a_d)
            moment = kin[f"{b}.moment"] if b in self.links else np.zeros(len(w))
            out[b] = {
                "mass": mass,
                "inertia": inertia,
                "S": np.asarray(kin[f"S_{b}"], float),
                "a_S": a_s,
                "epsilon": e,
                "force": force,
                "moment": moment,
                "placed": [
                    tuple(np.real(v) for v in self.placed_load(name, kin))
                    for name, placed in self.point_loads.items()
                    if placed["link"] == b
                ],
            }
        return out

    def placed_load(self, name: str, kin: dict) -> tuple:
        """(P, F, M) of the [[load]] ``name`` over the samples of ``kin``: its point P
        (N, 2), its force F (N, 2) in global components (a follower force's inputs,
        along its link's i and j, turned by the link's angle) and its moment M (N,);
        zero where the load has no such input."""
        placed = self.point_loads[name]
        angle = geo.inexact(kin[f"{placed['link']}.angle"])
        zero = np.zeros_like(angle)
        f = zero[..., None] + np.zeros(2)
        if placed["force"]:
            f = geo.vec(kin[f"{name}.force.x"], kin[f"{name}.force.y"])
        if placed["follower"]:
            i = geo.unit(angle)
            f = geo.col(f[..., 0]) * i + geo.col(f[..., 1]) * geo.rot90(i)
        moment = geo.inexact(kin[f"{name}.moment"]) if placed["moment"] else zero
        return geo.inexact(kin[f"P_{name}"]), f, moment + zero

    def _known(self, bd: dict):
        """The known terms of body bd: forces (at S) and moments: weight, active load,
        d'Alembert force and moment."""
        forces = [np.broadcast_to(bd["mass"] * self._g, bd["a_S"].shape), bd["force"]]
        moments = [bd["moment"]]
        if self.effects["inertia"]:
            forces.append(-bd["mass"] * bd["a_S"])
            moments.append(-bd["inertia"] * bd["epsilon"])
        return forces, moments

    def reference(self, kin: dict) -> dict:
        """Joint reactions and the crank's driving torque from the Newton-Euler equations
        of all moving bodies, solved together (a square linear system per sample).

        Unknowns: at each revolute pair the force's two components, at each translational
        pair the normal force N (along j of its guide) and the reactive moment M (the
        force is taken at the pair's named point), and the crank's driving torque.
        Equations: per body, sum of forces = 0 and sum of moments about its centre of
        mass = 0, with the weight, the active load and the d'Alembert force -m a_S and
        moment -J epsilon. Returns output name -> (N,) array (see :meth:`output_names`;
        for a translational pair also its force's x and y components).
        """
        K, rhs = self._system(kin, self._body_data(kin))
        x = np.linalg.solve(K, rhs[..., None])[..., 0]
        return self._outputs(kin, x)

    def _system(self, kin: dict, bodies: dict) -> tuple:
        """The matrix and right-hand side of the Newton-Euler system of every body."""
        row = {b: 3 * i for i, b in enumerate(self.bodies)}
        n_eq = 3 * len(self.bodies)
        count = len(np.atleast_1d(kin["t"]))
        K = np.zeros((count, n_eq, n_eq))
        rhs = np.zeros((count, n_eq))
        ex = np.broadcast_to(np.array([1.0, 0.0]), (count, 2))
        ey = np.broadcast_to(np.array([0.0, 1.0]), (count, 2))

        def put(
            col: int, body: str, point: np.ndarray, f: np.ndarray, mu: np.ndarray, sign: float
        ) -> None:
            """Unknown ``col`` acts on ``body`` as the force ``f`` at ``point`` plus the
            couple ``mu`` (per unit value), with ``sign``."""
            if body is None:
                return
            r = row[body]
            K[:, r, col] += sign * f[:, 0]
            K[:, r + 1, col] += sign * f[:, 1]
            K[:, r + 2, col] += sign * (geo.cross(point - bodies[body]["S"], f) + mu)

        col = 0
        zero = np.zeros(count)
        for pr in self.pairs:
            P = np.asarray(kin[pr["point"]], dtype=float)
            if pr["kind"] == "R":
                columns = ((ex, zero), (ey, zero))
            else:
                j = geo.rot90(geo.unit(kin[pr["guide"]]))
                columns = ((j, zero), (0.0 * j, zero + 1.0))
            for f, mu in columns:
                put(col, pr["first"], P, f, mu, 1.0)
                put(col, pr["second"], P, f, mu, -1.0)
                col += 1
        for actions in self._effort_actions(kin).values():
            for body, point, f, mu, sign in actions:
                put(col, body, point, f, mu, sign)
            col += 1
        assert col == n_eq
        for b, bd in bodies.items():
            forces, moments = self._known(bd)
            r = row[b]
            rhs[:, r : r + 2] -= sum(forces)  # all act at S: no moment about S
            rhs[:, r + 2] -= sum(moments)
            for P, f, mu in bd["placed"]:  # a force at P: its moment about S too
                rhs[:, r : r + 2] -= f
                rhs[:, r + 2] -= geo.cross(P - bd["S"], f) + mu
        return K, rhs

    def _outputs(self, kin: dict, x: np.ndarray) -> dict:
        """The solution of the system under the output names."""
        out, col = {}, 0
        for pr in self.pairs:
            if pr["kind"] == "R":
                out[f"{pr['key']}.x"], out[f"{pr['key']}.y"] = (
                    x[:, col].copy(),
                    x[:, col + 1].copy(),
                )
            else:
                j = geo.rot90(geo.unit(kin[pr["guide"]]))
                N, M = x[:, col].copy(), x[:, col + 1].copy()
                out[f"{pr['key']}.x"], out[f"{pr['key']}.y"] = N * j[:, 0], N * j[:, 1]
                out[pr["n_name"]], out[pr["m_name"]] = N, M
            col += 2
        for name in self.effort_names:
            out[name] = x[:, col].copy()
            col += 1
        return out

    def residuals(self, kin: dict, out: dict) -> np.ndarray:
        """Worst Newton-Euler residual per sample of the output set ``out`` (keys of
        :meth:`reference`), over all bodies: |sum of forces| relative to the largest force
        term of the sample and |sum of moments about S| relative to the largest moment
        term. A translational pair's force must also lie along j of its guide and equal
        N j (both relative to the largest force term)."""
        bodies = self._body_data(kin)
        balance = _Balance(self.bodies, bodies, len(np.atleast_1d(kin["t"])))
        for b, bd in bodies.items():
            forces, moments = self._known(bd)
            for f in forces:
                balance.force(b, bd["S"], f)
            for mu in moments:
                balance.couple(b, mu)
            for P, f, mu in bd["placed"]:
                balance.force(b, P, f)
                balance.couple(b, mu)
        for pr in self.pairs:
            P = np.asarray(kin[pr["point"]], dtype=float)
            R = np.stack(
                [
                    np.asarray(out[f"{pr['key']}.x"], float),
                    np.asarray(out[f"{pr['key']}.y"], float),
                ],
                axis=-1,
            )
            balance.force(pr["first"], P, R)
            balance.force(pr["second"], P, -R)
            if pr["kind"] == "T":
                i = geo.unit(kin[pr["guide"]])
                N = np.asarray(out[pr["n_name"]], float)
                M = np.asarray(out[pr["m_name"]], float)
                balance.couple(pr["first"], M)
                balance.couple(pr["second"], -M)
                balance.tangential = np.maximum(
                    balance.tangential,
                    np.maximum(np.abs(geo.dot(R, i)), np.abs(N - geo.dot(R, geo.rot90(i)))),
                )
        for name, actions in self._effort_actions(kin).items():
            drive = np.asarray(out[name], float)
            for body, point, f, mu, sign in actions:
                balance.force(body, point, geo.col(sign * drive) * f)
                balance.couple(body, sign * drive * mu)
        return balance.worst()

    def _effort_actions(self, kin: dict) -> dict:
        """Effort name -> what that effort does per unit (:meth:`_drive_actions`)."""
        return {self.drive_output: self._drive_actions(kin)}

    def _drive_actions(self, kin: dict) -> list:
        """What the driver's effort does per unit, as (body, point, force, couple, sign):
        the crank's torque a couple on the crank; the ram's force along its guide at R;
        the cylinder's axial force along u at B, on the rod (+) and the barrel (-)."""
        count = len(np.atleast_1d(kin["t"]))
        zero, z2 = np.zeros(count), np.zeros((count, 2))
        if self.driver == "crank":
            return [(self.crank_name, np.asarray(kin["O"], dtype=float), z2, zero + 1.0, 1.0)]
        if self.driver == "ram":
            i_g = np.broadcast_to(geo.unit(self._guide), (count, 2))
            return [(self.crank_name, np.asarray(kin["R"], dtype=float), i_g, zero, 1.0)]
        cyl = self.cylinder_name
        u = geo.unit(np.real(kin[f"{cyl}.angle"]))
        B = np.asarray(np.real(kin[f"{cyl}.B"]), dtype=float)
        return [(f"{cyl}.rod", B, u, zero, 1.0), (f"{cyl}.barrel", B, u, zero, -1.0)]

    # ---- energy -----------------------------------------------------------
    def _mass(self, b: str):
        if b in self._parts:
            return self._parts[b][:2]
        return self.links[b]["mass"], self.links[b]["inertia"]

    def mass_properties(self, body: str) -> tuple[float, float]:
        """(mass [kg], inertia about the centre of mass [kg m2]) of a moving body: the
        driver (crank or ram) or a link."""
        return self._mass(body)

    def kinetic_energy(self, kin: dict) -> np.ndarray:
        """Kinetic energy [J] of all moving bodies, crank included."""
        total = 0.0
        for b in self.bodies:
            m, J = self._mass(b)
            v = geo.inexact(kin[f"v_S_{b}"])
            w = geo.inexact(kin[f"{b}.omega"])
            total = total + 0.5 * m * geo.dot(v, v) + 0.5 * J * w * w
        return geo.inexact(total)

    def potential_energy(self, kin: dict) -> np.ndarray:
        """Potential energy [J] of the weights of all moving bodies (crank included),
        zero at the origin: -sum m g . S (zero when the scene turns gravity off)."""
        total = 0.0
        for b in self.bodies:
            m, _ = self._mass(b)
            total = total - m * (geo.inexact(kin[f"S_{b}"]) @ self._g)
        return geo.inexact(total)

    def load_power(self, kin: dict) -> np.ndarray:
        """Power [W] of the active loads (weights excluded): sum F . v_S + M omega over
        the links' loads, F . v_P + M omega over the [[load]]s (P their points)."""
        total = 0.0
        for g in self.links:
            total = total + geo.dot(geo.inexact(kin[f"{g}.force"]), geo.inexact(kin[f"v_S_{g}"]))
            total = total + geo.inexact(kin[f"{g}.moment"]) * geo.inexact(kin[f"{g}.omega"])
        for name, placed in self.point_loads.items():
            _, f, mu = self.placed_load(name, kin)
            total = total + geo.dot(f, geo.inexact(kin[f"v_P_{name}"]))
            total = total + mu * geo.inexact(kin[f"{placed['link']}.omega"])
        return geo.inexact(total)

    def driver_power(self, kin: dict, out: dict) -> np.ndarray:
        """Power [W] the driver puts in: its effort of ``out`` (:meth:`reference`) times
        its rate, torque x omega (a crank) or force x velocity (a ram; a cylinder, its
        axial force times ds/dt)."""
        rate = np.asarray(kin[self.coordinate_names[1]], dtype=float)
        return np.asarray(out[self.drive_output], dtype=float) * rate

    def __repr__(self):
        return (
            f"<Chain {self.name}: "
            + ", ".join(f"{e['name']} ({e['type']})" for e in self.plan)
            + ">"
        )


# ---------------------------------------------------------------------------
# the dyads
# ---------------------------------------------------------------------------
def _state(
    angle: np.ndarray,
    omega: np.ndarray,
    epsilon: np.ndarray,
    D: np.ndarray,
    vD: np.ndarray,
    aD: np.ndarray,
    length: np.ndarray | float,
    rate: np.ndarray | float = 0.0,
    accel: np.ndarray | float = 0.0,
):
    return {
        "angle": angle,
        "omega": omega,
        "epsilon": epsilon,
        "D": D,
        "vD": vD,
        "aD": aD,
        "length": length,
        "length_rate": rate,
        "length_accel": accel,
    }


def _rrr(
    K: np.ndarray,
    vK: np.ndarray,
    aK: np.ndarray,
    P: np.ndarray,
    vP: np.ndarray,
    aP: np.ndarray,
    lm: np.ndarray,
    ln: np.ndarray,
    branch: float,
    name: str,
):
    """RRR: link m pinned at D_m = K (on link k), link n at D_n = P (on link p), joined
    at E. ``branch`` +1: E on the left of the directed line K -> P."""
    d = P - K
    dist = _norm(d)
    u = d / geo.col(dist)
    a = (lm * lm - ln * ln + dist * dist) / (2.0 * dist)  # along u from K to the chord
    h2 = lm * lm - a * a
    if np.any(~(np.real(h2) > 0.0)):
        raise ValueError(
            f"dyad {name}: the circles about D_m ({lm} m) and D_n ({ln} m) do not "
            f"intersect at every crank angle (|D_m D_n| from {dist.min():.4g} to "
            f"{dist.max():.4g} m)"
        )
    E = K + geo.col(a) * u + branch * geo.col(np.sqrt(h2)) * geo.rot90(u)
    i_m, i_n = (E - K) / lm, (E - P) / ln
    j_m, j_n = geo.rot90(i_m), geo.rot90(i_n)
    # vK + lm wm j_m = vP + ln wn j_n, differentiated once more for the accelerations
    c1, c2 = lm * j_m, -ln * j_n
    wm, wn = _solve2(c1, c2, vP - vK)
    em, en = _solve2(c1, c2, aP - aK + geo.col(lm * wm * wm) * i_m - geo.col(ln * wn * wn) * i_n)
    sm = _state(_angle(i_m), wm, em, K, vK, aK, lm)
    sn = _state(_angle(i_n), wn, en, P, vP, aP, ln)
    return sm, sn, E


def _along_guide(
    along: np.ndarray, across: np.ndarray, ln: np.ndarray, branch: float, name: str
) -> np.ndarray:
    """Where the rod (length ``ln``) from P meets the guide line: the offset s of E along
    the line from its origin, given P's offsets ``along`` and ``across`` the line from that
    origin; ``branch`` +1: E ahead of the foot of P."""
    root2 = ln * ln - across * across
    if np.any(~(np.real(root2) > 0.0)):
        raise ValueError(
            f"dyad {name}: the rod ({ln} m) does not reach the guide line at every "
            f"crank angle (distance up to {np.abs(across).max():.4g} m)"
        )
    return along + branch * np.sqrt(root2)


def _rrt(
    guide: np.ndarray,
    point: tuple[float, float],
    lm: np.ndarray,
    m_angle: np.ndarray,
    P: np.ndarray,
    vP: np.ndarray,
    aP: np.ndarray,
    ln: np.ndarray,
    branch: float,
    name: str,
):
    """RRT: slider m on the fixed guide (direction ``guide``, through ``point``), its
    pin E = D_m + lm i_m; rod n from D_n = P (on link p) to E. ``branch`` +1: E ahead
    of the foot of P on E's line along the guide direction."""
    i_k = np.array([math.cos(guide), math.sin(guide)])
    j_k = np.array([-i_k[1], i_k[0]])
    i_m = np.array([math.cos(m_angle), math.sin(m_angle)])
    base = np.asarray(point, dtype=float)
    line = base + lm * i_m  # E = line + s i_k
    d = P - line
    along, across = d @ i_k, d @ j_k
    s = _along_guide(along, across, ln, branch, name)
    E = line + geo.col(s) * i_k
    i_n = (E - P) / ln
    j_n = geo.rot90(i_n)
    # ds i_k = vP + ln wn j_n, and its derivative
    ik = np.broadcast_to(i_k, P.shape)
    ds, wn = _solve2(ik, -ln * j_n, vP)
    dds, en = _solve2(ik, -ln * j_n, aP - geo.col(ln * wn * wn) * i_n)
    zero = np.zeros(len(s))
    Dm = base + geo.col(s) * i_k
    sm = _state(zero + m_angle, zero, zero, Dm, geo.col(ds) * i_k, geo.col(dds) * i_k, lm)
    sn = _state(_angle(i_n), wn, en, P, vP, aP, ln)
    return sm, sn, E


def _rrt_on_link(
    ks: dict,
    at: Callable,
    guide: np.ndarray,
    lm: np.ndarray,
    P: np.ndarray,
    vP: np.ndarray,
    aP: np.ndarray,
    ln: np.ndarray,
    branch: float,
    name: str,
):
    """RRT with the guide on the moving link k (state ``ks``): the line through the point
    ``at`` of k's frame, along i_k = i_(link k) rotated by ``guide``. The slider m turns
    with k (i_m = i_k); D_m = Q + s i_k, Q the guide's point ``at``; E = D_m + lm i_k;
    rod n from D_n = P (on link p) to E. ``branch`` +1: E ahead of the foot of P on the
    guide line along i_k. Returns the states of m and n, E and (s, s', s'')."""
    Q, vQ, aQ = Chain._material(ks, at)
    angle = geo.inexact(ks["angle"]) + guide
    w, e = geo.inexact(ks["omega"]), geo.inexact(ks["epsilon"])
    i_k = geo.unit(angle)
    j_k = geo.rot90(i_k)
    d = P - (Q + lm * i_k)  # E = Q + (s + lm) i_k
    along, across = geo.dot(d, i_k), geo.dot(d, j_k)
    s = _along_guide(along, across, ln, branch, name)
    Dm = Q + geo.col(s) * i_k
    E = Dm + lm * i_k
    i_n = (E - P) / ln
    j_n = geo.rot90(i_n)
    q = s + lm  # E = Q + q i_k
    # v_E = v_Q + s' i_k + q w j_k = v_P + ln wn j_n
    ds, wn = _solve2(i_k, -ln * j_n, vP - vQ - geo.col(q * w) * j_k)
    # a_E = a_Q + (s'' - q w^2) i_k + (q e + 2 s' w) j_k = a_P + ln en j_n - ln wn^2 i_n
    rhs = (
        aP
        - geo.col(ln * wn * wn) * i_n
        - aQ
        + geo.col(q * w * w) * i_k
        - geo.col(q * e + 2.0 * ds * w) * j_k
    )
    dds, en = _solve2(i_k, -ln * j_n, rhs)
    # the slider's material point at D_m: k's point there, plus relative and Coriolis terms
    vDm = vQ + geo.col(ds) * i_k + geo.col(s * w) * j_k
    aDm = aQ + geo.col(dds - s * w * w) * i_k + geo.col(s * e + 2.0 * ds * w) * j_k
    sm = _state(angle, w.copy(), e.copy(), Dm, vDm, aDm, lm)
    sn = _state(_angle(i_n), wn, en, P, vP, aP, ln)
    return sm, sn, E, (s, ds, dds)


def _rtr(
    K: np.ndarray, vK: np.ndarray, aK: np.ndarray, P: np.ndarray, vP: np.ndarray, aP: np.ndarray
):
    """RTR with the block n on the pin D_n = P (l_n = 0, E = P): link m pinned at
    D_m = K, its slot along i_m through P; l_m = |K P| varies. The block turns with m."""
    d, vd, ad = P - K, vP - vK, aP - aK
    L = _norm(d)
    i_m = d / geo.col(L)
    j_m = geo.rot90(i_m)
    # d = L i_m: vd = L' i_m + L w j_m; ad = (L'' - L w^2) i_m + (L eps + 2 L' w) j_m
    Ld = geo.dot(vd, i_m)
    w = geo.dot(vd, j_m) / L
    Ldd = geo.dot(ad, i_m) + L * w * w
    e = (geo.dot(ad, j_m) - 2.0 * Ld * w) / L
    angle = _angle(i_m)
    sm = _state(angle, w, e, K, vK, aK, L, Ld, Ldd)
    sn = _state(angle.copy(), w.copy(), e.copy(), P, vP, aP, 0.0)
    return sm, sn, P.copy()


def _check_closes(y2: np.ndarray, s: np.ndarray, reach: tuple, name: str) -> None:
    """A ValueError naming the cylinder where its triangle does not close (y2, the square
    of B's distance from the line O A, not positive) at some length s; ``reach`` the
    lengths between which it closes."""
    if np.any(~(np.real(y2) > 0.0)):
        s = np.real(s)
        raise ValueError(
            f"cylinder {name}: the triangle O, A, B does not close at every length "
            f"(s from {s.min():.4g} to {s.max():.4g} m; it closes for "
            f"{reach[0]:.4g} < s < {reach[1]:.4g} m)"
        )


def cylinder_triangle(
    pivot: tuple,
    base: tuple,
    pin: tuple,
    branch: float,
    s: np.ndarray,
    ds: np.ndarray,
    dds: np.ndarray,
    name: str,
) -> dict:
    """The triangle O, A, B of a cylinder of length s = |AB| whose link's pivot O and
    barrel's pin A may move (carried by other links; on the frame, at rest): ``pivot``
    (O) and ``base`` (A) each (position, velocity, acceleration), (N, 2) arrays;
    ``pin``: B in the link's frame; s' = ``ds``, s'' = ``dds``. Returns the link's angle
    ``theta``, ``omega``, ``epsilon``; B, ``v_B``, ``a_B`` (also the rod's point at B);
    the axis u's angle ``psi`` and rates ``Omega``, ``Omega_dot``; the ``conditioning``
    |(B - O) x u| / |pin| of the real parts.

    B - O = rho = x e + y (k x e), e from O to A, |rho| = |pin|, |B - A| = s. The rates
    follow from B = O + rho turning with the link, differentiated: u . (B' - A') = s'
    gives omega; (B - A) . (B'' - A'') = s s'' + s'^2 - |B' - A'|^2 gives epsilon."""
    (pO, vO, aO), (pA, vA, aA) = pivot, base
    d = geo.norm(pA - pO)
    e = (pA - pO) / geo.col(d)
    r = math.hypot(*pin)
    x = (d * d + r * r - s * s) / (2.0 * d)
    y2 = r * r - x * x
    reach = (float(np.max(np.abs(np.real(r - d)))), float(np.min(np.real(r + d))))
    _check_closes(y2, s, reach, name)
    rho = geo.col(x) * e + geo.col(branch * np.sqrt(y2)) * geo.rot90(e)
    B = pO + rho
    cb, sb = pin[0] / r, pin[1] / r  # the link turns pin onto rho
    theta = geo.angle(geo.vec(cb * rho[:, 0] + sb * rho[:, 1], cb * rho[:, 1] - sb * rho[:, 0]))
    u = (B - pA) / geo.col(s)
    j_c = geo.rot90(u)
    lever = geo.cross(rho, u)  # u . (k x rho)
    omega = (ds - geo.dot(u, vO - vA)) / lever
    v_B = vO + geo.col(omega) * geo.rot90(rho)
    v_rel = v_B - vA  # = s' u + s Omega j_c
    Omega = geo.dot(v_rel, j_c) / s
    along = (s * dds + ds * ds - geo.dot(v_rel, v_rel)) / s  # u . (B'' - A'')
    epsilon = (along - geo.dot(u, aO - aA - geo.col(omega * omega) * rho)) / lever
    a_B = aO + geo.col(epsilon) * geo.rot90(rho) - geo.col(omega * omega) * rho
    Omega_dot = (geo.dot(a_B - aA, j_c) - 2.0 * ds * Omega) / s
    return {
        "theta": theta,
        "omega": omega,
        "epsilon": epsilon,
        "B": B,
        "v_B": v_B,
        "a_B": a_B,
        "psi": geo.angle(u),
        "Omega": Omega,
        "Omega_dot": Omega_dot,
        "conditioning": np.abs(np.real(lever)) / r,
    }


# ---------------------------------------------------------------------------
# loading
# ---------------------------------------------------------------------------
def load(
    name: str, data: Mapping | None = None, branches: Mapping[str, int] | None = None
) -> Chain:
    """The chain ``name`` (one of :data:`NAMES`, :data:`RAM_NAMES`,
    :data:`CYLINDER_NAMES`): its scene file plus its table of the
    packaged ``chains.toml``. ``data`` overrides that table key by key (nested tables
    merged): a mapping, either the whole document (with a table ``name``) or the
    mechanism's own table, or the path of a TOML file of the same form. ``branches``
    {dyad or cylinder: +1 or -1} takes the place of the scene's branch of those."""
    if name not in _ALL_NAMES:
        raise ValueError(
            f"unknown chain mechanism {name!r}; expected one of: {', '.join(_ALL_NAMES)}"
        )
    table = geo.overridden(default_data()[name], name, data)
    with open(scene_path(name), "rb") as f:
        scene = tomllib.load(f)
    dyads = {str(d.get("name")): d for d in scene.get("dyad", [])}
    cylinder = scene.get("cylinder")
    if isinstance(cylinder, dict):  # the cylinder's triangle closes in two ways too
        dyads[str(cylinder.get("name", "cylinder"))] = cylinder
    for dyad, branch in (branches or {}).items():
        if dyad not in dyads:
            raise ValueError(f"branches: {name} has no dyad or cylinder {dyad!r}")
        dyads[dyad]["branch"] = branch
    return Chain(name, scene, table)

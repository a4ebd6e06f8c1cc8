"""Scenes with several drivers: the whole-mechanism Newton-Euler reference of
:mod:`.chains` for any mix of cranks, rams and cylinders, a cylinder on the frame or on an
earlier driver's link.

=================  ========================================================================
name               mechanism (scene file)
=================  ========================================================================
leg                ``modelDescription/scenes/leg.toml``: two hip cranks ``front`` and
                   ``rear`` and dyad ``knees`` (RRR), the shanks meeting at the foot; a
                   ground force at the foot.
three_drivers      ``tests/scenes/three_drivers.toml``: crank ``wheel``, cylinder ``jack``
                   (turning link ``arm``), ram ``slide``; dyads ``tie`` and ``hang`` (RRR);
                   a follower force and moment ``tool`` on the hanger.
carried_cylinders  ``tests/scenes/carried_cylinders.toml``: cylinder ``lift`` raises a
                   boom; cylinder ``reach``, pinned to the boom at both ends, turns an arm;
                   a payload at the arm's tip.
excavator          ``modelDescription/scenes/excavator.toml``: cylinders ``boom_cyl``,
                   ``stick_cyl`` (on the boom) and ``bucket_cyl`` (on the stick, turning
                   the rocker); dyad ``linkage`` (RRR) turns the bucket; a digging force
                   ``dig`` at the bucket's tip.
loader             ``modelDescription/scenes/loader.toml``: cylinder ``lift_cyl`` raises
                   the lift arm; cylinder ``tilt_cyl`` (barrel on the frame) turns the
                   ``bellcrank`` about its pivot on the arm; dyad ``zbar`` (RRR) turns the
                   bucket; a ``payload`` in the bucket.
=================  ========================================================================

A cylinder's O and A may ride on an earlier driver's link (``{ link = NAME, at = [x,
y] }``): they move with it, and it receives minus the cylinder's R_O and R_A there.

Each driver is read as :class:`.chains.Chain` reads a single one (``[crank]`` or
``[[crank]]`` and so on), in the order cranks, rams, cylinders, each in file order. Its
coordinate q (a crank's angle, a ram's position, a cylinder's length), rate and
acceleration are inputs; its effort (a crank's torque, a ram's force along its guide, a
cylinder's axial force) is an unknown of the Newton-Euler system, which holds every
moving body's three equations: the pairs' reactions plus one effort per driver make it
square. Kinematics keys are those of a single driver's with the driver's points named
after it: ``<crank>.O``, ``<crank>.A``; ``<ram>.R``; ``<link>.O``, ``<cyl>.A``,
``<cyl>.B`` of a cylinder.

The inertia matrix M(q) (``M.<a>.<b>`` = d effort_a / d q''_b) is solved for, not
derived from the efforts' formula: its column b is the efforts at q, every rate zero,
no gravity and no loads, driver b's acceleration 1 and the others' 0; the efforts at
zero accelerations (rates, gravity and loads kept) are h (``<crank>.torque0``,
``<ram>.force0``, ``<cyl>.force0``), so that efforts = M q'' + h.
:func:`inertia_from_energy` gives M from the kinetic energy alone, T = q'^T M q' / 2;
:func:`energy_balance` checks the efforts' power against the rate of T + V along a
motion of every driver (chains.toml's ``drivers`` table).

Example::

    leg = load("leg")
    kin = leg.state({"front": -1.0, "rear": -2.0}, {"front": 1.0, "rear": -2.0})
    out = leg.outputs(kin)          # reactions, efforts, M.front.rear, front.torque0, ...
    assert leg.residuals(kin, out).max() < 1e-12
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..paths import SCENES_DIR, TEST_SCENES_DIR
from . import chains
from . import geometry as geo

__all__ = [
    "NAMES",
    "Driver",
    "DriverMotion",
    "MultiChain",
    "energy_balance",
    "inertia_from_energy",
    "load",
    "scene_path",
]

#: The mechanisms with several drivers.
NAMES = ("leg", "three_drivers", "carried_cylinders", "excavator", "loader")
_TEST_SCENES = ("three_drivers", "carried_cylinders")

#: Driver kinds in their order, with the names of their coordinate, rate and acceleration.
COORDINATES = {
    "crank": ("angle", "omega", "epsilon"),
    "ram": ("position", "velocity", "acceleration"),
    "cylinder": ("length", "velocity", "acceleration"),
}


@dataclass(frozen=True)
class Driver:
    """One driver: ``kind``; ``name`` (its inputs' prefix: a cylinder's own name);
    ``link`` (the body dyads attach to: the crank, the ram, a cylinder's link);
    ``pivot`` (a crank's or a cylinder's link's O, a ram's point at q = 0); ``pin`` (in
    the link's frame: a crank's A, a ram's R = (0, 0), a cylinder's B); ``guide`` (a ram's
    angle); ``base`` (a cylinder's A) and ``branch`` (its triangle's); ``pivot_on`` and
    ``base_on``: the earlier driver's link that carries a cylinder's O or A (None: the
    frame), ``pivot`` and ``base`` then in that link's frame."""

    kind: str
    name: str
    link: str
    pivot: tuple
    pin: tuple
    guide: float = 0.0
    base: tuple | None = None
    branch: float = 1.0
    pivot_on: str | None = None
    base_on: str | None = None

    @property
    def coordinates(self) -> tuple[str, str, str]:
        """Its coordinate, rate and acceleration inputs."""
        return tuple(f"{self.name}.{k}" for k in COORDINATES[self.kind])

    @property
    def effort(self) -> str:
        """Its effort's output: ``<crank>.torque``, ``<ram>.force``, ``<cyl>.force``."""
        return f"{self.name}.{'torque' if self.kind == 'crank' else 'force'}"

    @property
    def effort0(self) -> str:
        """Its effort at zero accelerations: ``<crank>.torque0``, ``<ram>.force0``..."""
        return f"{self.effort}0"

    @property
    def pin_label(self) -> str:
        """Its pin's label: a crank's A, a ram's R, a cylinder's B."""
        return {"crank": "A", "ram": "R", "cylinder": "B"}[self.kind]


@dataclass(frozen=True)
class DriverMotion:
    """Every driver's motion, q_i(t) = mid_i + rate_i t + swing_i sin(omega_i t + phase_i),
    analytic in t (a complex step passes through). ``duration``: one period of the
    loads' swing."""

    names: tuple
    mid: np.ndarray
    rate: np.ndarray
    swing: np.ndarray
    omega: np.ndarray
    phase: np.ndarray
    duration: float

    def sampled(self, t: np.ndarray) -> tuple:
        """t (N,), and q, q', q'' (N, drivers) at t (complex where t is)."""
        t = np.atleast_1d(geo.inexact(t))
        if t.ndim != 1:
            raise ValueError(f"t: expected shape (N,), got {t.shape}")
        arg = t[:, None] * self.omega + self.phase
        q = self.mid + self.rate * t[:, None] + self.swing * np.sin(arg)
        dq = self.rate + self.swing * self.omega * np.cos(arg)
        ddq = -self.swing * self.omega**2 * np.sin(arg)
        return t, q, dq + 0.0 * t[:, None], ddq


def _tables(value: object, kind: str, where: str) -> list:
    """A driver kind's tables: none, one ``[kind]`` or several ``[[kind]]``."""
    if value is None:
        return []
    rows = [value] if isinstance(value, Mapping) else value
    if not isinstance(rows, list) or not all(isinstance(r, Mapping) for r in rows):
        raise ValueError(f"{where}.{kind}: expected a table or an array of tables")
    return rows


class MultiChain(chains.Chain):
    """A scene with several drivers (see the module's docstring). Beyond
    :class:`.chains.Chain`'s attributes: ``drivers`` (:class:`Driver` each, in order)
    and ``ranges`` (driver name -> its working range of chains.toml)."""

    driver = "several"

    # ---- reading -------------------------------------------------------------
    def _read_driver(self, where: str) -> None:
        self._parts, self.drivers, self.crank = {}, [], {}
        for kind in COORDINATES:
            for table in _tables(self.scene.get(kind), kind, where):
                self._read_one_driver(kind, table, f"{where}.{kind}[{table.get('name')}]")
                self.drivers.append(self._harvested(kind))
        if len(self.drivers) < 2:
            raise ValueError(f"{where}: a scene of several drivers needs two or more")
        names = [n for d in self.drivers for n in {d.name, d.link}]
        if len(set(names)) != len(names):
            raise ValueError(f"{where}: driver names must differ, got {names}")
        self.crank_name = None  # no single driver: every use goes through self.drivers

    def _harvested(self, kind: str) -> Driver:
        """The driver :meth:`_read_one_driver` has just read, from what it set."""
        if kind != "cylinder":
            return Driver(kind, self.crank_name, self.crank_name, self._O, self._pin, self._guide)
        name, base, branch = self.cylinder_name, self._base, self._cylinder_branch
        del self.cylinder_name
        carriers = self._carriers
        return Driver(kind, name, self.crank_name, self._O, self._pin, 0.0, base, branch, *carriers)

    def _read_cylinder(self, table: Mapping, w: str) -> None:
        """As :meth:`.chains.Chain._read_cylinder`, with O (``at``) and A (``base``) each a
        point of the frame, [x, y], or of an earlier driver's link, { link = NAME, at =
        [x, y] } in that link's frame (spec part 2); the carriers in ``_carriers``."""
        local, carriers = dict(table), []
        for key in ("at", "base"):
            carrier, point = self._carried(table, key, w)
            carriers.append(carrier)
            local[key] = list(point)
        if carriers[0] != carriers[1]:
            # O and A in different frames: their coordinates are not comparable, so the
            # check that A is off O has no meaning here (the triangle's closure checks it)
            local["base"] = [local["at"][0] + 1.0, local["at"][1]]
        super()._read_cylinder(local, w)
        self._base = tuple(self._carried(table, "base", w)[1])
        self._carriers = tuple(carriers)

    def _carried(self, table: Mapping, key: str, w: str) -> tuple:
        """(carrier, point) of a cylinder's ``at`` or ``base``: (None, global point) on
        the frame, else (the earlier driver's link, the point in its frame)."""
        spec = table.get(key)
        if not isinstance(spec, Mapping):
            return None, geo.pair(table, key, w)
        where = f"{w}.{key}"
        stray = sorted(set(spec) - {"link", "at"})
        if stray:
            raise ValueError(f"{where}.{stray[0]}: not a key of a carried point (link, at)")
        carrier = spec.get("link")
        if carrier == "frame":
            return None, geo.pair(spec, "at", where)
        if carrier == table.get("link"):
            raise ValueError(f"{where}.link: a cylinder's {key!r} is not on the link it turns")
        earlier = [d.link for d in self.drivers]
        if carrier not in earlier:
            raise ValueError(
                f"{where}.link: {carrier!r} is neither the frame nor an earlier driver's "
                f"link ({', '.join(earlier) or 'none'})"
            )
        return carrier, geo.pair(spec, "at", where)

    @property
    def _moves_alone(self) -> bool:
        """Several drivers are a mechanism without dyads too (e.g. a cylinder on a boom)."""
        return True

    @property
    def _driver_names(self) -> tuple:
        return tuple(n for d in self.drivers for n in (d.link, d.name))

    @property
    def _driver_links(self) -> tuple:
        return tuple(d.link for d in self.drivers)

    def _driver_alias(self, name: object) -> object:
        return name

    def _driver_pin(self, spec: object) -> dict | None:
        for d in self.drivers:
            if isinstance(spec, str) and spec == d.link:
                return {"kind": "point", "body": d.link, "at": d.pin, "label": d.pin_label}
        return None

    def _read_motion(self) -> None:
        """The loads' swing (``motion.omega``) and each driver's motion and working range
        (``drivers.<name>``) from chains.toml."""
        wm = f"{self.name}.motion"
        self._w0 = geo.number(self.data.get("motion", {}), "omega", wm, positive=True)
        table = self.data.get("drivers") or {}
        rows, self.ranges = [], {}
        for d in self.drivers:
            w = f"{self.name}.drivers.{d.name}"
            spec = table.get(d.name)
            if not isinstance(spec, Mapping):
                raise ValueError(f"{w}: missing (the driver's motion and working range)")
            keys = ("mid", "rate", "swing", "omega", "phase")
            rows.append([geo.number(spec, k, w, default=0.0) for k in keys])
            low, high = geo.pair(spec, "range", w)
            if not low < high:
                raise ValueError(f"{w}.range: expected [low, high], low < high")
            self.ranges[d.name] = (low, high)
        cols = np.array(rows).T
        self._motion = DriverMotion(self.coordinate_names, *cols, 2.0 * math.pi / self._w0)
        self._scale = max(h - lo for lo, h in self.ranges.values())

    # ---- names -----------------------------------------------------------------
    @property
    def coordinate_names(self) -> tuple:
        """The drivers' coordinates (a crank's angle, ...), in the drivers' order."""
        return tuple(d.coordinates[0] for d in self.drivers)

    @property
    def driver_names(self) -> tuple:
        """The drivers' names (a cylinder's own), in order."""
        return tuple(d.name for d in self.drivers)

    @property
    def effort_names(self) -> list:
        """The drivers' efforts, in the drivers' order."""
        return [d.effort for d in self.drivers]

    @property
    def drive_output(self) -> str:
        """No single effort: see :attr:`effort_names`."""
        raise AttributeError("a scene of several drivers has effort_names, no drive_output")

    def inertia_names(self) -> list:
        """``M.<a>.<b>`` for every ordered pair of drivers, row a, column b."""
        return [f"M.{a}.{b}" for a in self.driver_names for b in self.driver_names]

    # ---- pairs and efforts -------------------------------------------------------
    def _driver_pairs(self) -> list:
        pairs = []
        for d in self.drivers:
            c = d.link
            if d.kind == "crank":
                pairs.append(
                    {"key": f"{c}.R_O", "kind": "R", "first": c, "point": f"{c}.O", "tag": "O"}
                )
            elif d.kind == "ram":
                pairs.append(chains._sliding(f"{c}.R_G", c, None, f"{c}.R", f"{c}.angle", "G", c))
            else:
                cyl = d.name
                barrel, rod = f"{cyl}.barrel", f"{cyl}.rod"
                # O's and A's carriers (None: the frame) receive minus R_O and minus R_A
                pairs += [
                    {"key": f"{c}.R_O", "kind": "R", "first": c, "second": d.pivot_on}
                    | {"point": f"{c}.O"},
                    {"key": f"{cyl}.R_A", "kind": "R", "first": barrel, "second": d.base_on}
                    | {"point": f"{cyl}.A"},
                    {"key": f"{cyl}.R_B", "kind": "R", "first": c, "second": rod}
                    | {"point": f"{cyl}.B"},
                    chains._sliding(
                        f"{cyl}.R_slide", rod, barrel, f"{cyl}.B", f"{cyl}.angle", "slide", cyl
                    ),
                ]
        return pairs

    def _effort_actions(self, kin: dict) -> dict:
        """Per driver what its effort does per unit, as (body, point, force, couple,
        sign): a crank's torque a couple on it, a ram's force along its guide at R, a
        cylinder's axial force along u at B on the rod (+) and the barrel (-)."""
        count = len(np.atleast_1d(kin["t"]))
        zero, z2 = np.zeros(count), np.zeros((count, 2))
        out = {}
        for d in self.drivers:
            if d.kind == "crank":
                acts = [(d.link, np.real(kin[f"{d.link}.O"]), z2, zero + 1.0, 1.0)]
            elif d.kind == "ram":
                i_g = np.broadcast_to(geo.unit(d.guide), (count, 2))
                acts = [(d.link, np.real(kin[f"{d.link}.R"]), i_g, zero, 1.0)]
            else:
                u = geo.unit(np.real(kin[f"{d.name}.angle"]))
                B = np.real(kin[f"{d.name}.B"])
                acts = [(f"{d.name}.rod", B, u, zero, 1.0), (f"{d.name}.barrel", B, u, zero, -1.0)]
            out[d.effort] = acts
        return out

    # ---- kinematics ----------------------------------------------------------------
    def _solve(self, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> dict:
        """The kinematics at q, q', q'' (N, drivers)."""
        states, kin = {}, {"t": t}
        for i, d in enumerate(self.drivers):
            st, entries = self._driver_state(d, q[:, i], dq[:, i], ddq[:, i], states)
            states.update(st)
            kin.update(entries)
        for b, state in states.items():
            kin[f"{b}.accel_d"] = state["aD"]
        return self._completed(states, kin, q.shape[:1], np.result_type(q, dq, ddq, float))

    def _driver_state(
        self, d: Driver, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, states: dict
    ) -> tuple:
        """The states of one driver's bodies and its kinematics entries (``states``:
        those of the earlier drivers' bodies, a cylinder's carriers among them)."""
        c = d.link
        z2 = np.zeros(q.shape + (2,), dtype=np.result_type(q, float))
        pivot = z2 + np.asarray(d.pivot)
        names = d.coordinates
        kin = {names[0]: q, names[1]: dq, names[2]: ddq}
        if d.kind == "crank":
            state = {"angle": q, "omega": dq, "epsilon": ddq, "D": pivot, "vD": z2, "aD": z2}
            kin.update({f"{c}.O": pivot, f"{c}.A": self._material(state, d.pin)[0]})
            return {c: state}, kin
        if d.kind == "ram":
            i_g, zero = geo.unit(d.guide), np.zeros_like(q)
            R = pivot + geo.col(q) * i_g
            state = {"angle": zero + d.guide, "omega": zero, "epsilon": zero}
            state.update(D=R, vD=geo.col(dq) * i_g, aD=geo.col(ddq) * i_g)
            kin.update({f"{c}.angle": state["angle"], f"{c}.omega": zero, f"{c}.epsilon": zero})
            kin[f"{c}.R"] = R
            return {c: state}, kin
        return self._cylinder_state(d, q, dq, ddq, kin, states)

    def _carried_point(self, carrier: str | None, at: tuple, states: dict, shape: tuple):
        """Position, velocity and acceleration of a cylinder's O or A: fixed on the frame
        (carrier None) or moving with an earlier driver's link."""
        if carrier is None:
            z2 = np.zeros(shape + (2,))
            return z2 + np.asarray(at), z2.copy(), z2.copy()
        return self._material(states[carrier], at)

    def _cylinder_state(
        self, d: Driver, s: np.ndarray, ds: np.ndarray, dds: np.ndarray, kin: dict, done: dict
    ) -> tuple:
        """A cylinder's link, barrel and rod (:func:`.chains.cylinder_triangle`), O and A moving
        with their carriers (``done``: the earlier drivers' states)."""
        c, cyl = d.link, d.name
        O = self._carried_point(d.pivot_on, d.pivot, done, np.shape(s))  # noqa: E741
        A = self._carried_point(d.base_on, d.base, done, np.shape(s))
        g = chains.cylinder_triangle(O, A, d.pin, d.branch, s, ds, dds, cyl)
        axis = (g["psi"], g["Omega"], g["Omega_dot"])
        pivot, base = O[0], A[0]
        states = {
            c: chains._state(g["theta"], g["omega"], g["epsilon"], *O, 0.0),
            f"{cyl}.barrel": chains._state(*axis, *A, 0.0),
            f"{cyl}.rod": chains._state(*(a.copy() for a in axis), g["B"], g["v_B"], g["a_B"], 0.0),
        }
        for body in (c, cyl, f"{cyl}.barrel", f"{cyl}.rod"):
            st = states[f"{cyl}.barrel" if body == cyl else body]
            for key in ("angle", "omega", "epsilon"):
                kin[f"{body}.{key}"] = st[key]
        kin.update({f"{c}.O": pivot, f"{cyl}.A": base, f"{cyl}.B": g["B"]})
        kin[f"{cyl}.conditioning"] = g["conditioning"]
        return states, kin

    def _coordinates(self, q: object, what: str, count: int | None = None) -> np.ndarray:
        """q, q' or q'' as (N, drivers): from an array, or a mapping driver name -> values
        (a driver left out: 0)."""
        if isinstance(q, Mapping):
            stray = set(q) - set(self.driver_names)
            if stray:
                raise ValueError(f"{what}: no driver {sorted(stray)[0]!r}")
            cols = [np.atleast_1d(geo.inexact(q.get(n, 0.0))) for n in self.driver_names]
            cols = np.broadcast_arrays(*cols, np.zeros(count or 1))[:-1]
            return np.stack(cols, axis=-1)
        q = geo.inexact(q)
        q = q.reshape(-1, len(self.drivers)) if q.ndim < 2 else q
        return q if count is None else np.broadcast_to(q, (count, q.shape[1])).copy()

    def state(
        self,
        q: object,
        dq: object = None,
        ddq: object = None,
        loads: Mapping | None = None,
        t: np.ndarray | float = 0.0,
    ) -> dict:
        """The kinematics at the drivers' coordinates q, rates dq and accelerations ddq
        (each (N, drivers) or {driver name: (N,)}; dq, ddq default 0), with the [[load]]
        inputs ``loads`` ({input name: values}; one left out keeps its model's value at
        the times t)."""
        q = self._coordinates(q, "q")
        count = q.shape[0]
        dq = self._coordinates({} if dq is None else dq, "dq", count)
        ddq = self._coordinates({} if ddq is None else ddq, "ddq", count)
        t = np.broadcast_to(geo.inexact(t), (count,)).copy()
        kin = self._solve(t, q, dq, ddq)
        for key, value in (loads or {}).items():
            if key not in self.load_inputs():
                raise ValueError(f"loads: {key!r} is no [[load]] input of {self.name}")
            kin[key] = np.broadcast_to(geo.inexact(value), (count,)).copy()
        kin["mechanism"] = self.name
        return kin

    def load_inputs(self) -> list:
        """The [[load]] inputs: ``NAME.force.x/.y``, ``NAME.moment`` of those it has."""
        names = []
        for name, placed in self.point_loads.items():
            names += [f"{name}.force.x", f"{name}.force.y"] if placed["force"] else []
            names += [f"{name}.moment"] if placed["moment"] else []
        return names

    def motion(self, kind: str = "varying", revolutions: float = 1.0) -> DriverMotion:
        """Every driver's motion of chains.toml (one kind only; ``revolutions`` periods of
        the loads' swing)."""
        if kind != "varying":
            raise ValueError(f"{self.name}: its drivers' motion is 'varying', not {kind!r}")
        m = self._motion
        return DriverMotion(
            m.names, m.mid, m.rate, m.swing, m.omega, m.phase, revolutions * m.duration
        )

    def working_points(self, count: int, seed: int = 0) -> dict:
        """``count`` random points of the working ranges: the kinematics (:meth:`state`)
        at coordinates uniform over each driver's range, rates and accelerations uniform
        within the peaks of chains.toml's motion (|rate| + swing omega, swing omega^2 +
        1), loads uniform within their models' mean +- twice the swing."""
        rng = np.random.default_rng(seed)
        m, n = self._motion, len(self.drivers)
        low, high = np.array([self.ranges[d] for d in self.driver_names]).T
        q = rng.uniform(low, high, (count, n))
        dq = rng.uniform(-1.0, 1.0, (count, n)) * (np.abs(m.rate) + np.abs(m.swing * m.omega))
        ddq = rng.uniform(-1.0, 1.0, (count, n)) * (np.abs(m.swing) * m.omega**2 + 1.0)
        loads = {}
        for name, placed in self.point_loads.items():
            model = placed["model"]
            parts = [
                (f"{name}.force.{c}", model["force"][k], model["force_swing"][k])
                for k, c in enumerate("xy")
            ]
            parts.append((f"{name}.moment", model["moment"], model["moment_swing"]))
            for key, mean, swing in parts:
                if key in self.load_inputs():
                    loads[key] = mean + (2.0 * abs(swing) + 1.0) * rng.uniform(-1.0, 1.0, count)
        return self.state(q, dq, ddq, loads)

    def kinematics(self, t: np.ndarray, motion: DriverMotion) -> dict:
        """The kinematics along ``motion`` at the times t (complex t: a complex step)."""
        kin = self._solve(*motion.sampled(t))
        kin["mechanism"] = self.name
        return kin

    def sweep_coordinates(self, count: int = 5) -> np.ndarray:
        """A grid of ``count`` values per driver over the working ranges, (count^n, n)."""
        axes = [np.linspace(*self.ranges[n], count) for n in self.driver_names]
        return np.stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")], axis=-1)

    def _sweep(self, count: int = 5) -> dict:
        """Every dyad assembles over the working ranges (a grid, ends included)."""
        q = self.sweep_coordinates(count)
        zero = np.zeros_like(q)
        with np.errstate(invalid="raise", divide="raise"):
            return self._solve(zero[:, 0], q, zero + 1.0, zero)

    def frame(self) -> dict:
        """The fixed pivots {label: (x, y)} (drivers' and dyads') and the rams' guides
        {name: ((x0, y0), (x1, y1))} over their working ranges."""
        pivots, guides = {}, {}
        for d in self.drivers:
            if d.kind == "ram":
                i = geo.unit(d.guide)
                ends = [np.asarray(d.pivot) + x * i for x in self.ranges[d.name]]
                guides[d.link] = tuple(tuple(map(float, p)) for p in ends)
            elif d.kind == "crank" or d.pivot_on is None:  # a carried O or A moves
                pivots[f"{d.link}.O"] = tuple(d.pivot)
            if d.kind == "cylinder" and d.base_on is None:
                pivots[f"{d.name}.A"] = tuple(d.base)
        for e in self.plan:
            for att in (e["k"], e["p"]):
                if att["kind"] == "pivot":
                    pivots[att["label"]] = tuple(att["position"])
        return {"pivots": pivots, "guides": guides}

    # ---- dynamics ----------------------------------------------------------------------
    def _known(self, bd: dict):
        """As :meth:`.chains.Chain._known`, with gravity ``bd["g"]`` where set."""
        g = bd.get("g", self._g)
        forces = [np.broadcast_to(bd["mass"] * g, bd["a_S"].shape), bd["force"]]
        moments = [bd["moment"]]
        if self.effects["inertia"]:
            forces.append(-bd["mass"] * bd["a_S"])
            moments.append(-bd["inertia"] * bd["epsilon"])
        return forces, moments

    def _efforts(self, kin: dict, gravity: bool = True, loads: bool = True) -> np.ndarray:
        """The drivers' efforts (N, drivers) from the whole Newton-Euler system, the
        weights and the loads in or left out."""
        bodies = self._body_data(kin)
        for bd in bodies.values():
            if not gravity:
                bd["g"] = np.zeros(2)
            if not loads:
                bd["force"], bd["moment"] = np.zeros_like(bd["force"]), np.zeros_like(bd["moment"])
                bd["placed"] = []
        K, rhs = self._system(kin, bodies)
        x = np.linalg.solve(K, rhs[..., None])[..., 0]
        return x[:, -len(self.drivers) :]

    def _motion_of(self, kin: dict) -> tuple:
        """q, q', q'' (N, drivers) of a kinematics."""
        return tuple(
            np.stack([geo.inexact(kin[d.coordinates[k]]) for d in self.drivers], axis=-1)
            for k in range(3)
        )

    def inertia_matrix(self, kin: dict) -> np.ndarray:
        """M (N, drivers, drivers) at kin's positions: column b the efforts with every rate
        zero, no weights, no loads, driver b's acceleration 1, the others' 0."""
        q, _, _ = self._motion_of(kin)
        t, n = np.real(kin["t"]), len(self.drivers)
        M = np.empty((q.shape[0], n, n))
        for b in range(n):
            unit = np.zeros_like(q)
            unit[:, b] = 1.0
            M[:, :, b] = self._efforts(self._solve(t, q, 0.0 * q, unit), False, False)
        return M

    def bias(self, kin: dict) -> np.ndarray:
        """h (N, drivers): the efforts at kin's positions, rates and loads with every
        acceleration zero."""
        q, dq, _ = self._motion_of(kin)
        still = self._solve(np.real(kin["t"]), q, dq, 0.0 * q)
        for key in self.load_inputs():
            still[key] = kin[key]
        return self._efforts(still)

    def outputs(self, kin: dict) -> dict:
        """:meth:`reference` plus ``M.<a>.<b>`` and each driver's effort at zero
        accelerations (``<crank>.torque0``, ``<ram>.force0``, ``<cyl>.force0``)."""
        out = self.reference(kin)
        M, h = self.inertia_matrix(kin), self.bias(kin)
        for a, da in enumerate(self.drivers):
            out[da.effort0] = h[:, a]
            for b, db in enumerate(self.drivers):
                out[f"M.{da.name}.{db.name}"] = M[:, a, b]
        return out

    def driver_power(self, kin: dict, out: dict) -> np.ndarray:
        """Power [W] the drivers put in: the sum of effort x rate."""
        return sum(np.asarray(out[d.effort]) * np.real(kin[d.coordinates[1]]) for d in self.drivers)

    def fmu_outputs(self, kin: dict) -> dict:
        """Every output the scene's FMU has, by its name, at kin: the links' and the
        cylinders' motion, the pair points, B and conditionings, the reactions (a
        driver's sliding pair by its N and M only), the efforts, M and h."""
        out = {}
        links = list(self.links) + [
            n for d in self.drivers if d.kind == "cylinder" for n in (d.link, d.name)
        ]
        for g in links:
            for what in COORDINATES["crank"]:
                out[f"{g}.{what}"] = np.real(kin[f"{g}.{what}"]).copy()
        points = {
            f"{e['name']}.{p}": f"{e['name']}.{p}" for e in self.plan for p in ("D_m", "E", "D_n")
        }
        points.update({f"{d.name}.B": f"{d.name}.B" for d in self.drivers if d.kind == "cylinder"})
        for name, key in points.items():
            p = np.real(kin[key])
            out[f"{name}.position.x"], out[f"{name}.position.y"] = p[:, 0].copy(), p[:, 1].copy()
        for e in self.plan:
            out[f"{e['name']}.conditioning"] = np.real(kin[f"{e['name']}.conditioning"]).copy()
        for d in self.drivers:
            if d.kind == "cylinder":
                out[f"{d.name}.conditioning"] = np.real(kin[f"{d.name}.conditioning"]).copy()
        skip = {
            f"{pr['key']}.{c}"
            for pr in self.pairs
            if pr["dyad"] is None and pr["kind"] == "T"
            for c in "xy"
        }
        out.update({k: v for k, v in self.outputs(kin).items() if k not in skip})
        return out


def inertia_from_energy(chain: MultiChain, q: np.ndarray) -> np.ndarray:
    """M (N, drivers, drivers) from the kinetic energy alone, T = q'^T M q' / 2: M_aa =
    2 T(e_a), M_ab = T(e_a + e_b) - T(e_a) - T(e_b) (rates e the unit vectors)."""
    q = chain._coordinates(q, "q")
    n = len(chain.drivers)

    def energy(*which: int) -> np.ndarray:
        dq = np.zeros_like(q)
        dq[:, list(which)] = 1.0
        return chain.kinetic_energy(chain._solve(0.0 * q[:, 0], q, dq, 0.0 * q))

    single = [energy(a) for a in range(n)]
    M = np.empty((q.shape[0], n, n))
    for a in range(n):
        M[:, a, a] = 2.0 * single[a]
        for b in range(a + 1, n):
            M[:, a, b] = M[:, b, a] = energy(a, b) - single[a] - single[b]
    return M


def energy_balance(chain: MultiChain, count: int = 150, revolutions: float = 1.0) -> dict:
    """The energy balance along chains.toml's motion of every driver at once, at ``count``
    times: the drivers' power sum effort x rate (``drivers``), the loads' (``loads``) and
    d(T + V)/dt (``rate``), a five-point central difference in time of the reference's
    own kinetic and potential energies; ``residual`` = max |drivers + loads - rate| /
    max |drivers|."""
    motion = chain.motion("varying", revolutions)
    t = (np.arange(count) + 0.37) * motion.duration / count
    kin = chain.kinematics(t, motion)
    out = chain.reference(kin)
    step = 2e-4 * motion.duration / revolutions

    def energy(at: np.ndarray) -> np.ndarray:
        k = chain.kinematics(at, motion)
        return chain.kinetic_energy(k) + chain.potential_energy(k)

    e = [energy(t + k * step) for k in (-2, -1, 1, 2)]
    rate = (e[0] - 8.0 * e[1] + 8.0 * e[2] - e[3]) / (12.0 * step)
    drivers, loads = chain.driver_power(kin, out), chain.load_power(kin)
    peak = float(np.max(np.abs(drivers)))
    residual = float(np.max(np.abs(drivers + loads - rate))) / peak
    return {"t": t, "kin": kin, "out": out, "drivers": drivers, "loads": loads} | {
        "rate": rate,
        "peak": peak,
        "residual": residual,
    }


def scene_path(name: str) -> Path:
    """The scene file of ``name`` (one of :data:`NAMES`)."""
    if name not in NAMES:
        raise ValueError(f"unknown mechanism {name!r}; expected one of: {', '.join(NAMES)}")
    return (TEST_SCENES_DIR if name in _TEST_SCENES else SCENES_DIR) / f"{name}.toml"


def load(name: str, data: Mapping | None = None) -> MultiChain:
    """The mechanism ``name`` of several drivers: its scene plus its table of chains.toml
    (``data`` overrides it as :func:`.chains.load` says)."""
    path = scene_path(name)
    table = geo.overridden(chains.default_data()[name], name, data)
    with open(path, "rb") as f:
        scene = tomllib.load(f)
    return MultiChain(name, scene, table)

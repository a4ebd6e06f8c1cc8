"""What a mechanism FMU exchanges, computed by the harness: its input time series (the
driver's motion and the active loads) and the reference values of its outputs.

A mechanism FMU (a scene with ``kinematics = "internal"``) takes only the driver's
motion, ``crank.angle``, ``crank.omega``, ``crank.epsilon``, ``ram.position``,
``ram.velocity``, ``ram.acceleration`` or ``hoist.length``, ``hoist.velocity``,
``hoist.acceleration`` (a cylinder), and the loads the scene lists
(``LINK.force.x/.y``, ``LINK.moment``, and ``NAME.force.x/.y``, ``NAME.moment`` of each
``[[load]]``), and solves the kinematics itself. Its outputs:
``LINK.angle``, ``LINK.omega``, ``LINK.epsilon``; ``DYAD.D_m.position.x/.y``,
``DYAD.E.position.x/.y``, ``DYAD.D_n.position.x/.y`` (pair points, m); the reactions
``DYAD.R_mk.x/.y`` ... and
``DYAD.N_..``, ``DYAD.M_..`` of the sliding pairs; for a crank ``crank.torque``,
``crank.R_O.x/.y``; for a ram ``ram.force`` (along the guide), ``ram.N`` (the guide's
normal force, along j_guide), ``ram.M`` (the guide's moment about R); for a cylinder
turning link L ``hoist.force`` (axial), ``hoist.R_A``, ``hoist.R_B``, ``L.R_O``,
``hoist.N``, ``hoist.M``, the motions ``L.angle/.omega/.epsilon`` and
``hoist.angle/.omega/.epsilon``, ``hoist.B.position.x/.y`` and ``hoist.conditioning``;
and the driver's
effective inertia ``J``, its derivative ``dJdq`` and ``torque0`` (``force0``), the
effort at zero driver acceleration:

    J(q) = sum over moving bodies (driver included) of m |v_S / q'|^2 + I (omega / q')^2
    effort = J q'' + effort0.

J and dJdq come from the kinematics at unit driver speed and no acceleration, where
v_S / q' = dS/dq and the accelerations are the second derivatives in q:
dJ/dq = 2 sum (m dS/dq . d2S/dq2 + I dtheta/dq d2theta/dq2).

Example::

    chain = chains.load("lift")
    motion = chain.motion("constant", 1)
    t = np.linspace(0, motion.duration, 201)
    series = driver_motion_inputs(chain, t, motion)
    series.inputs["ram.position"], series.outputs["ram.force"], series.outputs["ram.J"]
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..paths import SCENES_DIR
from ..reference import newton_euler
from . import builtin, chains
from . import crank as crank_balance
from . import geometry as geo
from .motion import CrankMotion, RamMotion

__all__ = [
    "SCENE_OF",
    "DrivenSeries",
    "builtin_outputs",
    "driver_motion_inputs",
    "effective_inertia",
]

#: The mechanism FMU scene (``modelDescription/scenes/<name>.toml``) of each built-in mechanism.
SCENE_OF = {
    "slider-crank": "slider_crank",
    "four-bar": "four_bar",
    "quick-return": "quick_return",
    "scotch-yoke": "scotch_yoke",
    "trt-slot": "trt_slot",
}

#: A crank's angle, speed and acceleration inputs, and a link's motion outputs' suffixes.
_CRANK = ("angle", "omega", "epsilon")

Driven = builtin.Mechanism | chains.Chain


@dataclass(frozen=True)
class DrivenSeries:
    """A mechanism FMU's inputs and reference outputs at the times ``t`` (N,): name ->
    (N,) float array, named as the FMU names them; ``driver`` is the driver's name
    (``crank``, ``ram``) and ``effort`` its output (``crank.torque``, ``ram.force``)."""

    t: np.ndarray
    inputs: dict[str, np.ndarray]
    outputs: dict[str, np.ndarray]
    driver: str
    effort: str


def _scene_of(mechanism: Driven, scene: Mapping | str | os.PathLike | None) -> dict:
    """The scene: given, read from a path, or the mechanism's own."""
    if isinstance(scene, Mapping):
        return dict(scene)
    if scene is None:
        if isinstance(mechanism, chains.Chain):
            return dict(mechanism.scene)
        scene = SCENES_DIR / f"{SCENE_OF[mechanism.name]}.toml"
    with open(scene, "rb") as f:
        return tomllib.load(f)


def _unit_motion(q: np.ndarray, ram: bool) -> CrankMotion | RamMotion:
    """A motion whose 'time' is the driver coordinate itself: unit speed, no acceleration."""
    one = lambda t: np.ones_like(t)  # noqa: E731
    zero = lambda t: np.zeros_like(t)  # noqa: E731
    same = lambda t: t  # noqa: E731
    span = float(np.ptp(np.real(q))) or 1.0
    if ram:
        return RamMotion("unit", same, one, zero, span, 1.0, "x = t")
    return CrankMotion("unit", same, one, zero, span, 1.0, "phi = t")


def _bodies(mechanism: Driven, kin: dict) -> list[tuple]:
    """(mass, inertia, v_S, omega, a_S, epsilon) of every moving body, driver included."""
    if isinstance(mechanism, chains.Chain):
        return [
            (*mechanism.mass_properties(b), kin[f"v_S_{b}"], kin[f"{b}.omega"])
            + (kin[f"a_S_{b}"], kin[f"{b}.epsilon"])
            for b in mechanism.bodies
        ]
    c = mechanism.crank
    out = [(c["mass"], c["inertia"], kin["v_S_c"], kin["crank.omega"], kin["a_S_c"])]
    out[0] += (kin["crank.epsilon"],)
    for g in ("m", "n"):
        link = mechanism.links[g]
        out.append(
            (link["mass"], link["inertia"], kin[f"v_S_{g}"], kin[f"{g}.omega"], kin[f"a_S_{g}"])
            + (kin[f"{g}.epsilon"],)
        )
    return out


def effective_inertia(
    mechanism: Driven, q: np.ndarray, branch: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(J, dJ/dq)`` at the driver coordinates ``q`` (N,): the effective inertia at the
    driver (kg m2 for a crank, kg for a ram) of every moving body, driver included, and
    its derivative in q (see the module's docstring)."""
    q = np.atleast_1d(geo.inexact(q))
    if isinstance(mechanism, chains.Chain):
        kin = mechanism.positions(q)
    else:
        kin = mechanism.kinematics(q, _unit_motion(q, False), branch)
    J, dJ = 0.0, 0.0
    for mass, inertia, v, w, a, e in _bodies(mechanism, kin):
        J = J + mass * geo.dot(v, v) + inertia * w * w
        dJ = dJ + 2.0 * (mass * geo.dot(v, a) + inertia * w * e)
    return np.broadcast_to(J, q.shape).copy(), np.broadcast_to(dJ, q.shape).copy()


def generalized_gravity(
    mechanism: Driven, q: np.ndarray, branch: float | None = None
) -> np.ndarray:
    """Q_g (N m for a crank, N for a ram) at the driver coordinates ``q`` (N,): the
    generalised force of the weights, sum m g . V_S with V_S every centre of mass's
    velocity per unit driver rate (-dV/dq, V the potential energy)."""
    q = np.atleast_1d(geo.inexact(q))
    if isinstance(mechanism, chains.Chain):
        kin = mechanism.positions(q)
        gravity = mechanism.gravity if mechanism.effects["gravity"] else (0.0, 0.0)
    else:
        kin = mechanism.kinematics(q, _unit_motion(q, False), branch)
        gravity = mechanism.gravity
    g = np.asarray(gravity, dtype=float)
    Q = 0.0
    for mass, _inertia, v, _w, _a, _e in _bodies(mechanism, kin):
        Q = Q + mass * geo.dot(v, g)
    return np.broadcast_to(np.real(Q), q.shape).copy()


def _loads_in(scene: Mapping, kin: dict, role: Mapping) -> dict:
    """The load inputs the scene lists, by FMU name: those of [loads] (``role`` maps a
    scene link to its key prefix in ``kin``) and those of each [[load]] (under their
    own names in ``kin``, which only a chain's kinematics hold)."""
    loads, out = scene.get("loads", {}), {}
    for link in loads.get("force", []):
        force = np.real(kin[f"{role[link]}.force"])
        out[f"{link}.force.x"], out[f"{link}.force.y"] = force[:, 0].copy(), force[:, 1].copy()
    for link in loads.get("moment", []):
        out[f"{link}.moment"] = np.real(np.asarray(kin[f"{role[link]}.moment"])).copy()
    for placed in scene.get("load", []):
        keys = ("force.x", "force.y") if placed.get("force", True) else ()
        keys += ("moment",) if placed.get("moment", False) else ()
        for key in (f"{placed['name']}.{k}" for k in keys):
            if key not in kin:
                raise ValueError(f"{key}: the mechanism has no model of this [[load]] input")
            out[key] = np.real(np.asarray(kin[key])).copy()
    return out


def _link_and_points(kin: dict, links: Mapping, points: Mapping) -> dict:
    """``LINK.angle/.omega/.epsilon`` (``links``: FMU link name -> kin prefix) and the pair
    points ``DYAD.P.x/.y`` (``points``: FMU prefix -> kin key)."""
    out = {}
    for link, key in links.items():
        for what in _CRANK:
            out[f"{link}.{what}"] = np.asarray(kin[f"{key}.{what}"], dtype=float).copy()
    for name, key in points.items():
        p = np.asarray(kin[key], dtype=float)
        out[f"{name}.x"], out[f"{name}.y"] = p[:, 0].copy(), p[:, 1].copy()
    return out


def builtin_outputs(mech: builtin.Mechanism, kin: dict, scene: Mapping) -> dict:
    """The reference outputs of a built-in mechanism under its scene's names."""
    dyad = scene["dyad"][0]
    d, c = dyad["name"], scene.get("crank", {}).get("name", "crank")
    links = {dyad["m"]: "m", dyad["n"]: "n"}
    points = {f"{d}.{p}.position": p for p in _POINTS}
    out = _link_and_points(kin, links, points)
    r = newton_euler.solve(mech.dyad, *mech.reference_inputs(kin))
    for pair in ("mk", "np", "mn"):
        out[f"{d}.R_{pair}.x"], out[f"{d}.R_{pair}.y"] = r[f"r_{pair}"][:, 0], r[f"r_{pair}"][:, 1]
        if not np.all(np.isnan(r[f"n_{pair}"])):  # a sliding pair
            out[f"{d}.N_{pair}"], out[f"{d}.M_{pair}"] = r[f"n_{pair}"], r[f"m_{pair}"]
    bal = crank_balance.balance(mech, kin, r["r_np"], r["m_np"])
    out[f"{c}.torque"] = bal["torque"]
    out[f"{c}.R_O.x"], out[f"{c}.R_O.y"] = bal["R_O"][:, 0], bal["R_O"][:, 1]
    return out


def _chain_outputs(chain: chains.Chain, kin: dict) -> dict:
    """The reference outputs of a chain under its scene's names: a cylinder's also the
    motion of the link it turns and of its axis, its pin B and its conditioning."""
    points = {f"{e['name']}.{p}.position": f"{e['name']}.{p}" for e in chain.plan for p in _POINTS}
    links = {g: g for g in chain.links}
    if chain.driver == "cylinder":
        cyl = chain.cylinder_name
        links.update({chain.crank_name: chain.crank_name, cyl: cyl})
        points[f"{cyl}.B.position"] = f"{cyl}.B"
    out = _link_and_points(kin, links, points)
    if chain.driver == "cylinder":
        out[f"{cyl}.conditioning"] = np.asarray(kin[f"{cyl}.conditioning"], dtype=float).copy()
    ref = chain.reference(kin)
    # the vector of a driver's sliding pair (the ram's guide, the rod in the barrel) is
    # no FMU output: its N and M are
    skip = {
        f"{pr['key']}.{c}"
        for pr in chain.pairs
        if pr["dyad"] is None and pr["kind"] == "T"
        for c in "xy"
    }
    out.update({k: v for k, v in ref.items() if k not in skip})
    return out


_POINTS = ("D_m", "E", "D_n")

#: Which outer pairs slide, by dyad type: (D_m, D_n).
_SLIDING = {"RRR": (0, 0), "RRT": (1, 0), "RTR": (0, 0), "TRT": (1, 1), "RTT": (1, 0)}


def _slide(scene: Mapping, spec: Mapping, out: dict, point: str, kin: dict, key: str) -> np.ndarray:
    """Where a sliding outer pair sits on its guide, from the guide's point 'at': on a
    frame guide or the crank's from the pair's position, on a link's from the kinematics."""
    at = np.asarray(spec.get("at", (0.0, 0.0)), dtype=float)
    crank = scene.get("crank", {})
    if spec.get("link") == "frame":
        origin, turn = np.zeros(2), 0.0
    elif spec.get("link") == crank.get("name", "crank"):
        origin, turn = np.asarray(crank.get("at", (0.0, 0.0)), dtype=float), kin["crank.angle"]
    else:
        return np.asarray(kin[key], dtype=float).copy()
    i, j = geo.unit(turn), geo.rot90(geo.unit(turn))
    g = geo.unit(turn + float(spec["guide"]))
    guide_x = origin[0] + at[0] * i[..., 0] + at[1] * j[..., 0]
    guide_y = origin[1] + at[0] * i[..., 1] + at[1] * j[..., 1]
    return (out[f"{point}.x"] - guide_x) * g[..., 0] + (out[f"{point}.y"] - guide_y) * g[..., 1]


def _dyad_extras(scene: Mapping, kin: dict, out: dict, role: Mapping, conditioning: dict) -> None:
    """The sliding lengths, the slides of sliding outer pairs and each dyad's
    conditioning, under the FMU's names (added to ``out``)."""
    for dyad in scene.get("dyad", []):
        d = dyad.get("name", "")
        pre = f"{d}." if d else ""
        out[f"{pre}conditioning"] = np.asarray(conditioning[d], dtype=float)
        if dyad["type"] in ("RTR", "RTT"):  # E slides along link m: its length varies
            link = dyad["m"]
            out[f"{link}.length"] = np.asarray(kin[f"{role[link]}.length"], dtype=float).copy()
        for side, pair, slides in zip("kp", ("D_m", "D_n"), _SLIDING[dyad["type"]], strict=True):
            if slides:
                key = f"{pre}slide_{side}"
                out[key] = _slide(scene, dyad[side], out, f"{pre}{pair}.position", kin, key)


def driver_motion_inputs(
    mechanism: Driven,
    t: np.ndarray,
    motion: CrankMotion | RamMotion,
    scene: Mapping | str | os.PathLike | None = None,
    branch: float | None = None,
) -> DrivenSeries:
    """The input time series of ``mechanism``'s mechanism FMU at the times ``t`` (N,) of
    ``motion``, and the reference values of its outputs, all by FMU name.

    ``mechanism``: a built-in mechanism (:func:`.builtin.load`; its scene, which names
    its crank, dyad and links, is ``modelDescription/scenes/<SCENE_OF[name]>.toml`` unless ``scene``
    is given, as a parsed table or a path) or a chain (:func:`.chains.load`; its own scene).
    ``branch``: the assembly branch of a built-in mechanism (default its own).
    Inputs: the driver's motion and the loads the scene lists. Outputs: see the
    module's docstring; ``J``, ``dJdq`` and ``torque0`` (``force0``) of the driver.
    """
    scene = _scene_of(mechanism, scene)
    if isinstance(mechanism, chains.Chain):
        kin = mechanism.kinematics(t, motion)
        driver = mechanism.driver_name
        role = {g: g for g in mechanism.links}
        out = _chain_outputs(mechanism, kin)
        effort = mechanism.drive_output
        dyads = scene.get("dyad", [])
        conditioning = {d["name"]: kin[f"{d['name']}.conditioning"] for d in dyads}
        keys = list(mechanism.coordinate_names)
        names = [k.rpartition(".")[2] for k in keys]
    else:
        kin = mechanism.kinematics(t, motion, branch)
        driver = scene.get("crank", {}).get("name", "crank")
        dyad = scene["dyad"][0]
        role = {dyad["m"]: "m", dyad["n"]: "n"}
        out = builtin_outputs(mechanism, kin, scene)
        effort = f"{driver}.torque"
        conditioning = {dyad.get("name", ""): mechanism.conditioning(kin)}
        names, keys = _CRANK, [f"crank.{k}" for k in _CRANK]
    q, _, ddq = (np.asarray(kin[k], dtype=float) for k in keys)
    inputs = {
        f"{driver}.{k}": np.asarray(kin[key], dtype=float)
        for k, key in zip(names, keys, strict=True)
    }
    inputs.update(_loads_in(scene, kin, role))
    _dyad_extras(scene, kin, out, role, conditioning)
    J, dJ = effective_inertia(mechanism, q, branch)
    out[f"{driver}.J"], out[f"{driver}.dJdq"] = J, dJ
    out[f"{effort}0"] = out[effort] - J * ddq
    return DrivenSeries(np.asarray(kin["t"], dtype=float), inputs, out, driver, effort)

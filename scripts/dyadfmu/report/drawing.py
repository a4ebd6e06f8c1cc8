"""Drawing of a mechanism of :mod:`dyadfmu.mechanisms.builtin` to scale on a matplotlib Axes,
optionally with joint reactions as arrows on one force scale.

Symbols: the frame k as hatched ground under fixed pivots and along fixed guides,
the crank p, links m and n as bars (slotted where a block slides in them), revolute
pairs as small white circles, translational pairs as small rectangles aligned with
their guide, centres of mass as dots (S_c, S_m, S_n), and labels.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from . import sketch

if TYPE_CHECKING:
    from collections.abc import Callable

    from matplotlib.axes import Axes

    from ..mechanisms.builtin import Mechanism

__all__ = ["draw", "mechanism_size", "APPLICATION"]

#: Where each reaction acts: R_mk on m at D_m, R_np on n at D_n, R_mn on m at E,
#: R_O on the crank at O (from the frame).
APPLICATION = {"R_mk": "D_m", "R_np": "D_n", "R_mn": "E", "R_O": "O"}
_ARROW_COLOURS = {"R_mk": "tab:red", "R_np": "tab:blue", "R_mn": "tab:purple", "R_O": "tab:green"}
_COLOUR = {"p": "tab:orange", "m": "tab:blue", "n": "tab:olive", "k": "0.35"}


def mechanism_size(mechanism: Mechanism, kin: dict) -> float:
    """Extent (m) of the mechanism over all samples of ``kin``: the larger side of the
    bounding box of its pairs, fixed pivots, fixed guides and the crank's circle."""
    pts = [np.asarray(kin[k], dtype=float).reshape(-1, 2) for k in ("O", "A", "D_m", "E", "D_n")]
    frame = kin.get("frame") or {}
    for p in (frame.get("pivots") or {}).values():
        pts.append(np.asarray(p, dtype=float).reshape(-1, 2))
    for seg in (frame.get("guides") or {}).values():
        pts.append(np.asarray(seg, dtype=float).reshape(-1, 2))
    r = mechanism.crank["radius"]
    pts.append(np.array([[-r, -r], [r, r]]))
    allp = np.concatenate(pts)
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    extent = np.ptp(allp, axis=0)
    return float(max(extent.max(), 2.0 * r))


# ---------------------------------------------------------------------------
# primitives
# ---------------------------------------------------------------------------
def _unit(angle: float):
    return np.array([math.cos(angle), math.sin(angle)])


def _rot90(v: np.ndarray):
    return np.array([-v[1], v[0]])


# ---------------------------------------------------------------------------
# the mechanisms
# ---------------------------------------------------------------------------
def _draw_slider_crank(ax: Axes, mech: Mechanism, at: Callable, u: float):
    A, B = at("A"), at("D_m")
    x0, x1 = (p[0] for p in mech.frame()["guides"]["k"])
    e = mech.e
    hb = 1.0 * u  # half height of the slider
    ax.plot([x0, x1], [e, e], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)  # guide line
    sketch.hatch(ax, (x0, e - hb), (x1, e - hb), (0.0, -1.0), u)  # rail below
    sketch.hatch(ax, (x0, e + hb), (x1, e + hb), (0.0, 1.0), u)  # and above
    sketch.block(ax, B, (1.0, 0.0), 3.0 * u, 2.0 * hb, _COLOUR["m"])
    sketch.bar(ax, A, B, _COLOUR["n"], z=3)
    return {
        "m": B + np.array([0.0, 2.6 * u]),
        "n": sketch.beside(A, B, u),
        "k": np.array([x1, e - hb]) + np.array([-0.5 * u, -1.8 * u]),
    }


def _draw_four_bar(ax: Axes, mech: Mechanism, at: Callable, u: float):
    A, E, O4 = at("A"), at("E"), at("D_m")
    sketch.ground_pivot(ax, O4, u)
    sketch.bar(ax, O4, E, _COLOUR["m"], z=2.5)
    sketch.bar(ax, A, E, _COLOUR["n"], z=3)
    return {
        "m": sketch.beside(O4, E, u, up=False),
        "n": sketch.beside(A, E, u),
        "k": O4 + np.array([3.4 * u, -1.0 * u]),
    }


def _draw_quick_return(ax: Axes, mech: Mechanism, at: Callable, u: float):
    A, O2 = at("A"), at("D_m")
    i_m = _unit(at("m.angle"))
    d = math.hypot(*mech.O2)
    r = mech.crank["radius"]
    tip = O2 + mech.lever_length * i_m
    sketch.ground_pivot(ax, O2, u)
    sketch.bar(ax, O2, tip, _COLOUR["m"], width=sketch.LINK_WIDTH * 1.6, z=2.5)
    sketch.slot(
        ax, O2 + (d - r - 1.2 * u) * i_m, O2 + min(d + r + 1.2 * u, mech.lever_length) * i_m, z=2.6
    )
    sketch.block(ax, A, i_m, 2.4 * u, 1.1 * u, _COLOUR["n"], z=4)
    return {
        "m": O2 + 0.5 * (d - r) * i_m + 1.8 * u * _rot90(i_m),
        "n": A - 2.0 * u * _rot90(i_m) - 1.0 * u * i_m,
        "k": O2 + np.array([3.4 * u, -1.0 * u]),
    }


def _draw_scotch_yoke(ax: Axes, mech: Mechanism, at: Callable, u: float):
    A, Dm = at("A"), at("D_m")
    r, h = mech.crank["radius"], mech.h
    (x0, _), (x1, _) = mech.frame()["guides"]["k"]
    x0, x1 = min(x0, -r - 3 * u), max(x1, r + 3 * u)
    hf = 0.8 * u  # half height of the yoke's foot
    ax.plot([x0, x1], [-h, -h], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)
    sketch.hatch(ax, (x0, -h - hf), (x1, -h - hf), (0.0, -1.0), u)
    top = np.array([Dm[0], r + 2.0 * u])
    sketch.bar(ax, Dm, top, _COLOUR["m"], width=sketch.LINK_WIDTH * 1.6, z=2.5)
    sketch.slot(ax, (Dm[0], -r - 1.0 * u), (Dm[0], r + 1.0 * u), z=2.6)
    sketch.block(ax, Dm, (1.0, 0.0), 4.0 * u, 2.0 * hf, _COLOUR["m"], z=3)  # foot on k
    sketch.block(ax, A, (0.0, 1.0), 2.4 * u, 1.1 * u, _COLOUR["n"], z=4)  # block in slot
    return {
        "m": top + np.array([1.5 * u, -0.5 * u]),
        "n": A + np.array([1.8 * u, -1.2 * u]),
        "k": np.array([x1 - 0.5 * u, -h - hf - 1.6 * u]),
    }


def _draw_trt_slot(ax: Axes, mech: Mechanism, at: Callable, u: float):
    E = at("E")
    phi = at("crank.angle")
    i_p = _unit(phi)
    h = mech.h
    (x0, _), (x1, _) = mech.frame()["guides"]["k"]
    hs = 1.0 * u  # half height of the slider
    ax.plot([x0, x1], [h, h], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)
    sketch.hatch(ax, (x0, h + hs), (x1, h + hs), (0.0, 1.0), u)
    sketch.hatch(ax, (x0, h - hs), (x1, h - hs), (0.0, -1.0), u)
    sketch.block(ax, E, (1.0, 0.0), 4.0 * u, 2.0 * hs, _COLOUR["m"], z=3)  # slider on k
    sketch.block(ax, E, i_p, 2.4 * u, 1.1 * u, _COLOUR["n"], z=4.5)  # block in slot
    return {
        "m": E + np.array([2.8 * u, -2.0 * u]),
        "n": E + 2.2 * u * _rot90(i_p) - 1.0 * u * i_p,
        "k": np.array([x1 - 0.5 * u, h + hs + 1.6 * u]),
    }


_DRAW_DYAD = {
    "RRT": _draw_slider_crank,
    "RRR": _draw_four_bar,
    "RTR": _draw_quick_return,
    "RTT": _draw_scotch_yoke,
    "TRT": _draw_trt_slot,
}
#: The revolute pairs drawn as pins, per dyad type.
_PINS = {
    "RRT": ("O", "A", "E"),
    "RRR": ("O", "A", "E", "D_m"),
    "RTR": ("O", "A", "D_m"),
    "RTT": ("O", "A"),
    "TRT": ("O", "E"),
}


def _draw_crank(ax: Axes, mechanism: Mechanism, at: Callable, u: float) -> np.ndarray:
    """The frame's pivot and the crank p (slotted for the TRT slot); returns where the
    crank's label goes."""
    pivot, A = at("O"), at("A")
    phi = float(at("crank.angle"))
    sketch.ground_pivot(ax, pivot, u)
    side = _rot90(_unit(phi))  # the crank's label goes on the side away from E
    if np.dot(side, at("E") - pivot) > 0:
        side = -side
    if mechanism.dyad == "TRT":
        tip = pivot + mechanism.crank["radius"] * _unit(phi)
        sketch.bar(ax, pivot, tip, _COLOUR["p"], width=sketch.LINK_WIDTH * 1.6, z=2.0)
        sketch.slot(
            ax,
            pivot + 0.35 * (tip - pivot),
            pivot + (tip - pivot) * (1 - 1.2 * u / mechanism.crank["radius"]),
            z=2.1,
        )
        return pivot + 0.25 * (tip - pivot) + 1.6 * u * side
    sketch.bar(ax, pivot, A, _COLOUR["p"], z=2.0)
    return 0.5 * (pivot + A) + 1.6 * u * side


def _label_points(ax: Axes, at: Callable, size: float) -> None:
    """The point labels, coincident points merged ("A = D_n = E")."""
    names = [("O", "O"), ("A", "A"), ("D_m", "$D_m$"), ("E", "$E$"), ("D_n", "$D_n$")]
    pts = [at(k) for k, _ in names]
    centre = np.mean([at(k) for k in ("O", "A", "D_m", "E")], axis=0)
    done = [False] * len(names)
    for a in range(len(names)):
        if done[a]:
            continue
        group = [names[a][1]]
        for b in range(a + 1, len(names)):
            if not done[b] and np.hypot(*(pts[a] - pts[b])) <= 1e-9 * size:
                group.append(names[b][1])
                done[b] = True
        off = 10.0 * sketch.away(pts[a], centre, default=(-1.0, 1.0))
        sketch.label(ax, pts[a], " = ".join(group), off, size=10)


def _finite_forces(reactions: dict) -> dict:
    """The reactions as 2-vectors, checked by name; those not finite left out."""
    forces = {}
    for name, f in reactions.items():
        if name not in APPLICATION:
            raise ValueError(f"unknown reaction {name!r}; expected some of {sorted(APPLICATION)}")
        f = np.asarray(f, dtype=float).reshape(2)
        if np.all(np.isfinite(f)):
            forces[name] = f
    return forces


def _draw_reactions(
    ax: Axes, at: Callable, u: float, size: float, forces: dict, scale: float
) -> None:
    """Each force as an arrow from its point of application (a cross where it is too
    short to draw), with a legend."""
    handles = []
    for name, f in forces.items():
        p = at(APPLICATION[name])
        vec = f / scale
        length = float(np.hypot(*vec))
        label = f"{name} = {np.hypot(*f):.4g} N"
        if length <= 1e-12 * size:
            handles += ax.plot(
                [p[0]], [p[1]], "x", color=_ARROW_COLOURS[name], label=label, zorder=8
            )[:1]
            continue
        head = min(1.1 * u, 0.5 * length)
        handles.append(
            ax.arrow(
                p[0],
                p[1],
                vec[0],
                vec[1],
                width=0.16 * u,
                head_width=0.65 * u,
                head_length=head,
                length_includes_head=True,
                color=_ARROW_COLOURS[name],
                alpha=0.85,
                zorder=8,
                label=label,
            )
        )
    if handles:
        ax.legend(
            handles=handles,
            loc="best",
            fontsize=8,
            title=f"force scale {scale:.3g} N/m\n(1 mm = {scale / 1000:.3g} N)",
            title_fontsize=8,
            framealpha=0.85,
        )


def draw(
    ax: Axes,
    mechanism: Mechanism,
    kin: dict,
    index: int,
    reactions: dict | None = None,
    scale: float | None = None,
) -> float:
    """Draw ``mechanism`` at sample ``index`` of ``kin`` (from ``mechanism.kinematics``)
    on ``ax`` to scale, with equal aspect.

    reactions: optional dict name -> (Fx, Fy) in N, names among ``R_mk`` (at D_m),
    ``R_np`` (at D_n), ``R_mn`` (at E) and ``R_O`` (the frame on the crank at pivot); each
    is drawn as an arrow from its point of application, all with one force scale in
    N per m of drawing: ``scale`` if given, else chosen so that the largest arrow is
    40 % of the mechanism's size. Returns the scale used (N/m).
    """
    _, at = sketch.sample_at(kin, index)
    size = mechanism_size(mechanism, kin)
    u = 0.035 * size  # size of the symbols
    p_label = _draw_crank(ax, mechanism, at, u)
    where = _DRAW_DYAD[mechanism.dyad](ax, mechanism, at, u)
    for key in _PINS[mechanism.dyad]:
        sketch.pin(ax, at(key), u)
    for key, colour in (("S_c", _COLOUR["p"]), ("S_m", _COLOUR["m"]), ("S_n", _COLOUR["n"])):
        s = at(key)
        ax.plot([s[0]], [s[1]], "o", ms=4.5, mfc=colour, mec="black", mew=0.8, zorder=7)
    _label_points(ax, at, size)
    link_at = {"p": p_label, "m": where["m"], "n": where["n"], "k": where["k"]}
    for link, p in link_at.items():
        sketch.label(
            ax,
            p,
            link,
            (0.0, 0.0),
            colour=_COLOUR[link] if link != "k" else "black",
            size=12,
            weight="bold",
            box=False,
        )
    scale = sketch.checked_scale(scale)
    if reactions:
        forces = _finite_forces(reactions)
        largest = max((float(np.hypot(*f)) for f in forces.values()), default=0.0)
        if scale is None:
            scale = largest / (0.4 * size) if largest > 0 else 1.0
        _draw_reactions(ax, at, u, size, forces, scale)
    elif scale is None:
        scale = 1.0
    sketch.finish_axes(ax, 0.08)
    return scale

"""Drawing of a chain mechanism of :mod:`dyadfmu.mechanisms.chains` to scale, at one sample, with
its joint reactions as arrows on one force scale.

Symbols (those of :mod:`dyadfmu.report.drawing`): fixed pivots as triangles on hatched ground,
fixed guides as hatched rails, the crank and the links as bars (a ternary link also as a
shaded triangle, a slotted link with its groove, a link carrying a guide with a widened
grooved part along the stretch the slider uses), blocks and sliders as rectangles,
revolute pairs as white pins, centres of mass as dots, and labels for links and points.

Reaction arrows: every pair force on the link named first in its output name, drawn from
its point of application: ``<dyad>.R_mk`` on m at D_m, ``<dyad>.R_np`` on n at D_n,
``<dyad>.R_mn`` on m at E and ``crank.R_O`` on the crank at O (from the frame).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from typing import TYPE_CHECKING

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import sketch  # noqa: E402

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..mechanisms.chains import Chain

__all__ = ["draw", "figure", "reaction_vectors", "chain_size"]

_CRANK_COLOUR = sketch.DRIVER_COLOUR
_LINK_COLOURS = sketch.LINK_COLOURS
_ARROW_COLOURS = sketch.ARROW_COLOURS
_WIDTH = 5.0


def _u2(angle: float):
    return np.array([math.cos(angle), math.sin(angle)])


def _r90(v: np.ndarray):
    return np.array([-v[1], v[0]])


def reaction_vectors(chain: Chain, reactions: dict | None, index: int) -> dict:
    """The pair forces at sample ``index``: list of (output name, body it acts on, kin key
    of its point, force (2,) [N]), crank pivot first, then per dyad R_mk, R_mn, R_np."""
    out = []
    for pr in chain.pairs:
        f = np.array(
            [
                float(np.asarray(reactions[f"{pr['key']}.x"])[index]),
                float(np.asarray(reactions[f"{pr['key']}.y"])[index]),
            ]
        )
        out.append((pr["key"], pr["first"], pr["point"], f))
    return out


def chain_size(chain: Chain, kin: dict) -> float:
    """Extent (m) of the mechanism over all samples of ``kin``: the larger side of the
    bounding box of its pair points, centres of mass, fixed pivots and guides."""
    keys = ["O", "A"] + [f"S_{b}" for b in chain.bodies]
    keys += [f"{e['name']}.{p}" for e in chain.plan for p in ("D_m", "E", "D_n")]
    pts = [np.asarray(kin[k], dtype=float).reshape(-1, 2) for k in keys]
    frame = kin.get("frame") or {}
    for p in (frame.get("pivots") or {}).values():
        pts.append(np.asarray(p, dtype=float).reshape(-1, 2))
    for seg in (frame.get("guides") or {}).values():
        pts.append(np.asarray(seg, dtype=float).reshape(-1, 2))
    allp = np.concatenate(pts)
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    return float(max(np.ptp(allp, axis=0).max(), 1e-3))


def _point_labels(chain: Chain):
    """kin key of every pair point -> its name in the drawing."""
    names = {"O": "O", "A": chain.labels.get("A", "A")}
    for e in chain.plan:
        for pair, att in (("D_m", e["k"]), ("D_n", e["p"])):
            key = f"{e['name']}.{pair}"
            if key in chain.labels:
                names[key] = chain.labels[key]
            elif att["kind"] == "pivot":
                names[key] = att["label"]
            elif (
                att["kind"] == "point"
                and att["body"] == chain.crank_name
                and tuple(att["at"]) == (float(chain.crank["length"]), 0.0)
            ):
                names[key] = names["A"]
            else:
                names[key] = key
        key = f"{e['name']}.E"
        names[key] = chain.labels.get(key, key)
    return names


def _link_guides(ax: Axes, frame: dict, g: str, D: np.ndarray, angle: float, colour: str):
    """The guides carried by link ``g`` (origin D, angle ``angle`` at this sample): a wide
    bar from the link's guide point to the stretch the slider uses, grooved along it."""
    i_g = _u2(angle)
    j_g = _r90(i_g)
    for lg in (frame.get("link_guides") or {}).values():
        if lg["link"] != g:
            continue
        Q = D + lg["at"][0] * i_g + lg["at"][1] * j_g
        i_k = _u2(angle + lg["angle"])
        s0, s1 = lg["range"]
        if np.hypot(*(Q - D)) > 0.0:
            sketch.bar(ax, D, Q, colour, z=2.2)
        sketch.bar(
            ax, Q + min(s0, 0.0) * i_k, Q + max(s1, 0.0) * i_k, colour, width=_WIDTH * 1.6, z=2.5
        )
        sketch.slot(ax, Q + s0 * i_k, Q + s1 * i_k, z=2.6)


@dataclass
class _Canvas:
    """What the parts of one chain drawing share: the axes, the sample's values, the
    drawing unit, the mechanism's size, each body's colour and where its name goes."""

    ax: Axes
    at: Callable
    u: float
    size: float
    colours: dict
    link_label_at: dict = field(default_factory=dict)


def _draw_frame(c: _Canvas, frame: dict) -> None:
    """Fixed pivots on hatched ground; fixed guides as hatched rails with their name."""
    u = c.u
    for p in frame["pivots"].values():
        sketch.ground_pivot(c.ax, p, u)
    hs = 1.0 * u  # half height of a slider on a guide
    for label, (p0, p1) in frame["guides"].items():
        p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
        n = _r90((p1 - p0) / np.hypot(*(p1 - p0)))
        c.ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color="0.35", lw=0.8, ls="-.", zorder=1)
        sketch.hatch(c.ax, p0 - hs * n, p1 - hs * n, -n, u)
        sketch.hatch(c.ax, p0 + hs * n, p1 + hs * n, n, u)
        sketch.label(c.ax, p1 + 2.5 * u * n, label, (0.0, 0.0), colour="0.3", size=8, box=False)


def _draw_crank(c: _Canvas, chain: Chain, frame: dict) -> np.ndarray:
    """The crank from O to A with the guides it carries; returns O."""
    pivot, A = c.at("O"), c.at("A")
    sketch.bar(c.ax, pivot, A, _CRANK_COLOUR, z=2.0)
    angle = float(c.at(f"{chain.crank_name}.angle"))
    i_c = _u2(angle)
    _link_guides(c.ax, frame, chain.crank_name, pivot, angle, _CRANK_COLOUR)
    c.link_label_at[chain.crank_name] = 0.5 * (pivot + A) - 1.8 * c.u * _r90(i_c)
    return pivot


def _own_points(
    c: _Canvas, chain: Chain, g: str, D: np.ndarray, E: np.ndarray, i_g: np.ndarray, j_g: np.ndarray
) -> list:
    """The link's own points: D, E (if apart) and the pairs of later dyads on it."""
    own = [D]
    if np.hypot(*(E - D)) > 1e-9 * c.size:
        own.append(E)
    for later in chain.plan:
        for att in (later["k"], later["p"]):
            if att["kind"] == "point" and att["body"] == g:
                own.append(D + att["at"][0] * i_g + att["at"][1] * j_g)
    return own


def _draw_slider(
    c: _Canvas, g: str, D: np.ndarray, own: list, i_g: np.ndarray, j_g: np.ndarray
) -> None:
    """A slider on its guide, long enough for its own points and centre of mass."""
    u, hs = c.u, 1.0 * c.u
    rel = [p - D for p in own + [c.at(f"S_{g}")]]
    xs = [float(r @ i_g) for r in rel]
    ys = [float(r @ j_g) for r in rel]
    x0, x1 = min(xs) - 1.5 * u, max(xs) + 1.5 * u
    y0, y1 = min(min(ys), -hs), max(max(ys), hs)
    centre = D + 0.5 * (x0 + x1) * i_g + 0.5 * (y0 + y1) * j_g
    sketch.block(c.ax, centre, i_g, x1 - x0, y1 - y0, c.colours[g], z=3.0)
    c.link_label_at[g] = D + 0.5 * (x0 + x1) * i_g + (y1 + 1.6 * u) * j_g


def _draw_slotted(
    c: _Canvas, kin: dict, g: str, D: np.ndarray, own: list, i_g: np.ndarray, j_g: np.ndarray
) -> None:
    """A slotted link, its groove along the stretch the block uses."""
    u = c.u
    lengths = np.asarray(kin[f"{g}.length"], dtype=float)
    reach = max([float(lengths.max())] + [float((p - D) @ i_g) for p in own]) + 1.2 * u
    tip = D + reach * i_g
    sketch.bar(c.ax, D, tip, c.colours[g], width=_WIDTH * 1.6, z=2.5)
    sketch.slot(
        c.ax, D + (lengths.min() - 1.0 * u) * i_g, D + (lengths.max() + 1.0 * u) * i_g, z=2.6
    )
    c.link_label_at[g] = D + 0.3 * reach * i_g + 2.0 * u * j_g


def _draw_bar_link(c: _Canvas, g: str, D: np.ndarray, own: list, i_g: np.ndarray) -> None:
    """A bar from D to each of its own points (a ternary link also as a shaded plate)."""
    col = c.colours[g]
    if len(own) >= 3:
        c.ax.add_patch(
            plt.Polygon(
                [tuple(p) for p in own],
                closed=True,
                facecolor=col,
                edgecolor="none",
                alpha=0.25,
                zorder=1.8,
            )
        )
    for p in own[1:]:
        sketch.bar(c.ax, D, p, col, z=2.2)
    far = max(own[1:], key=lambda p: np.hypot(*(p - D))) if len(own) > 1 else D + c.u * i_g
    side = _r90((far - D) / max(np.hypot(*(far - D)), 1e-300))
    c.link_label_at[g] = 0.5 * (D + far) + 1.8 * c.u * side


def _draw_link(
    c: _Canvas,
    chain: Chain,
    kin: dict,
    frame: dict,
    dyad: dict,
    g: str,
    D: np.ndarray,
    E: np.ndarray,
) -> None:
    """Link g of a dyad, whose pair to the rest of the mechanism is D."""
    i_g = _u2(float(c.at(f"{g}.angle")))
    j_g = _r90(i_g)
    own = _own_points(c, chain, g, D, E, i_g, j_g)
    _link_guides(c.ax, frame, g, D, float(c.at(f"{g}.angle")), c.colours[g])
    if dyad["type"] == "RTR" and g == dyad["n"]:  # block in the slot of m
        sketch.block(c.ax, E, i_g, 2.4 * c.u, 1.1 * c.u, c.colours[g], z=4.5)
        c.link_label_at[g] = E - 2.2 * c.u * j_g - 1.2 * c.u * i_g
    elif dyad["type"] == "RRT" and g == dyad["m"]:  # slider on the guide
        _draw_slider(c, g, D, own, i_g, j_g)
    elif dyad["type"] == "RTR" and g == dyad["m"]:  # slotted link
        _draw_slotted(c, kin, g, D, own, i_g, j_g)
    else:  # bar (or ternary plate)
        _draw_bar_link(c, g, D, own, i_g)


def _draw_links(c: _Canvas, chain: Chain, kin: dict, frame: dict, pivot: np.ndarray) -> None:
    """Every dyad's links, then the revolute pairs as pins and the centres of mass."""
    pins = [pivot]
    for e in chain.plan:
        dn = e["name"]
        Dm, E, Dn = c.at(f"{dn}.D_m"), c.at(f"{dn}.E"), c.at(f"{dn}.D_n")
        kinds = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR"}[e["type"]]
        pins += [point for point, kind in zip((Dm, E, Dn), kinds, strict=True) if kind == "R"]
        for g, D in ((e["m"], Dm), (e["n"], Dn)):
            _draw_link(c, chain, kin, frame, e, g, D, E)
    for p in pins:
        sketch.pin(c.ax, p, c.u)
    for b in chain.bodies:
        s = c.at(f"S_{b}")
        c.ax.plot([s[0]], [s[1]], "o", ms=4.5, mfc=c.colours[b], mec="black", mew=0.8, zorder=7)


def _label_points(c: _Canvas, names: dict) -> dict:
    """The point labels, coincident points merged; returns the label shown for each key."""
    return sketch.label_points(c.ax, {k: c.at(k) for k in names}, names, c.size)


def _draw_reactions(c: _Canvas, vectors: list, scale: float, labels: dict) -> dict:
    """Every pair force as an arrow from its point of application, with a legend."""
    u, arrows = c.u, {}
    for k, (name, body, point, f) in enumerate(vectors):
        p = c.at(point)
        label = f"{name} on {body} at {labels[point]}: {np.hypot(*f):.4g} N"
        # later arrows thinner and on top, so that coincident ones stay visible
        width = 0.2 * u * (1.0 - 0.5 * k / max(len(vectors) - 1, 1))
        arrows[name] = sketch.force_arrow(
            c.ax,
            p,
            f / scale,
            u,
            _ARROW_COLOURS[k % len(_ARROW_COLOURS)],
            label,
            width=width,
            z=8 + 0.01 * k,
        )
    c.ax.legend(
        handles=list(arrows.values()),
        loc="upper center",
        bbox_to_anchor=(0.5, -0.13),
        ncol=2,
        fontsize=7,
        title=f"reactions; force scale {scale:.4g} N/m (1 mm = {scale / 1000:.3g} N)",
        title_fontsize=7,
        framealpha=0.9,
    )
    return arrows


def draw(
    ax: Axes,
    chain: Chain,
    kin: dict,
    index: int,
    reactions: dict | None = None,
    scale: float | None = None,
) -> dict:
    """Draw ``chain`` at sample ``index`` of ``kin`` (from ``chain.kinematics``) on ``ax``
    to scale, with equal aspect.

    reactions: optional dict output name -> (N,) array (the keys of ``chain.reference``);
    every pair force is drawn as an arrow from its point of application on the body
    named first, all on one force scale in N per m of drawing: ``scale`` if given, else
    chosen so that the largest arrow is 40 % of the mechanism's size. Returns
    {"scale": N/m, "arrows": {output name: arrow patch}}.
    """
    index, at = sketch.sample_at(kin, index)
    size = chain_size(chain, kin)
    colours = {chain.crank_name: _CRANK_COLOUR}
    for i, g in enumerate(chain.links):
        colours[g] = _LINK_COLOURS[i % len(_LINK_COLOURS)]
    c = _Canvas(ax, at, 0.03 * size, size, colours)
    names = _point_labels(chain)
    frame = kin.get("frame") or chain.frame()
    _draw_frame(c, frame)
    pivot = _draw_crank(c, chain, frame)
    _draw_links(c, chain, kin, frame, pivot)
    shown = _label_points(c, names)
    for b, p in c.link_label_at.items():
        sketch.label(ax, p, b, (0.0, 0.0), colour=colours[b], size=9, weight="bold", box=False)
    scale = sketch.checked_scale(scale)
    arrows = {}
    if reactions:
        vectors = reaction_vectors(chain, reactions, index)
        largest = max(float(np.hypot(*f)) for *_, f in vectors)
        if scale is None:
            scale = largest / (0.4 * size) if largest > 0 else 1.0
        labels = {point: shown.get(point, names[point]) for _, _, point, _ in vectors}
        arrows = _draw_reactions(c, vectors, scale, labels)
    elif scale is None:
        scale = 1.0
    sketch.finish_axes(ax, 0.06)
    return {"scale": scale, "arrows": arrows}


def figure(
    chain: Chain, kin: dict, reactions: dict | None, indices: list[int], path: Path | str
) -> Path:
    """Save a PNG of ``chain`` at 2 to 4 samples ``indices`` of ``kin``, one panel each,
    all with the reactions on one force scale (the largest arrow of all panels is 40 %
    of the mechanism's size). Returns the path."""
    indices = [int(i) for i in indices]
    if not 2 <= len(indices) <= 4:
        raise ValueError(f"indices: expected 2 to 4 samples, got {len(indices)}")
    scale = None
    if reactions:
        largest = max(
            float(np.hypot(*f)) for i in indices for *_, f in reaction_vectors(chain, reactions, i)
        )
        scale = largest / (0.4 * chain_size(chain, kin)) if largest > 0 else 1.0
    cols = 2 if len(indices) == 4 else len(indices)
    rows = 2 if len(indices) == 4 else 1
    fig, axes = plt.subplots(rows, cols, figsize=(6.4 * cols, 7.4 * rows), squeeze=False)
    c = chain.crank_name
    for ax, i in zip(axes.flat, indices, strict=False):
        draw(ax, chain, kin, i, reactions, scale)
        phi = math.degrees(float(kin[f"{c}.angle"][i])) % 360.0
        ax.set_title(
            f"{chain.name}: {c} angle {phi:.1f} deg, t = {float(kin['t'][i]):.4g} s", fontsize=10
        )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path

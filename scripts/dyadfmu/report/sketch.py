"""The parts the mechanism drawings are made of, on a matplotlib Axes: bars, slots, pins,
blocks, hatched ground, fixed pivots and labels; ``u`` is the drawing's unit length."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.patches import Circle, FancyArrow, Polygon

from ..mechanisms import geometry as geo

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: Line width of a link drawn as a bar (points).
LINK_WIDTH = 5.0
#: Colour of the frame: ground, fixed guides, fixed pivots.
FRAME_COLOUR = "0.35"
#: Colour of the driver (the crank, or the link a cylinder turns).
DRIVER_COLOUR = "#dd8452"
#: Colours of the other links, in turn.
LINK_COLOURS = ("#4c72b0", "#8c8c3c", "#7f7f7f", "#c49c3c", "#64b5cd", "#8172b3")
#: Colours of force arrows, in turn.
ARROW_COLOURS = (
    "tab:red",
    "tab:green",
    "tab:purple",
    "tab:brown",
    "tab:pink",
    "tab:cyan",
    "black",
    "magenta",
    "tab:blue",
    "tab:olive",
)


def bar(
    ax: Axes,
    p0: np.ndarray,
    p1: np.ndarray,
    colour: str,
    width: float = LINK_WIDTH,
    z: float = 2.0,
    alpha: float = 1.0,
) -> None:
    """A link as a bar from p0 to p1 (``alpha`` below 1 fades it)."""
    ax.plot(
        [p0[0], p1[0]],
        [p0[1], p1[1]],
        color=colour,
        lw=width,
        solid_capstyle="round",
        zorder=z,
        alpha=alpha,
    )


def slot(ax: Axes, p0: np.ndarray, p1: np.ndarray, z: float) -> None:
    """A slot along a bar: a white groove drawn over it."""
    ax.plot(
        [p0[0], p1[0]],
        [p0[1], p1[1]],
        color="white",
        lw=LINK_WIDTH * 0.35,
        solid_capstyle="round",
        zorder=z,
    )


def pin(ax: Axes, p: np.ndarray, u: float, z: float = 6.0, alpha: float = 1.0) -> None:
    """A revolute pair: a white pin at p (``alpha`` below 1 fades its outline)."""
    ax.add_patch(
        Circle(
            tuple(p),
            0.42 * u,
            facecolor="white",
            edgecolor=(0.0, 0.0, 0.0, alpha),
            lw=1.2,
            zorder=z,
        )
    )


def block(
    ax: Axes,
    centre: np.ndarray,
    direction: np.ndarray,
    length: float,
    width: float,
    colour: str,
    z: float = 4.0,
    alpha: float = 0.9,
) -> None:
    """A rectangle centred at ``centre`` with its long side along ``direction``."""
    i = np.asarray(direction, dtype=float)
    i = i / np.hypot(*i)
    j = geo.rot90(i)
    c = np.asarray(centre, dtype=float)
    a, b = 0.5 * length * i, 0.5 * width * j
    corners = [c - a - b, c + a - b, c + a + b, c - a + b]
    ax.add_patch(
        Polygon(
            corners, closed=True, facecolor=colour, edgecolor="black", lw=1.0, alpha=alpha, zorder=z
        )
    )


def hatch(
    ax: Axes, p0: np.ndarray, p1: np.ndarray, side: np.ndarray, u: float, z: float = 1.0
) -> None:
    """A fixed surface from p0 to p1 with hatch strokes on the side ``side`` (a vector)."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color=FRAME_COLOUR, lw=1.5, zorder=z)
    along = p1 - p0
    length = float(np.hypot(*along))
    if length == 0:
        return
    t = along / length
    s = np.asarray(side, dtype=float)
    s = s / np.hypot(*s)
    step = 0.7 * u
    count = max(int(length / step), 1)
    for k in range(count + 1):
        q = p0 + t * (k * length / count)
        q1 = q + 0.8 * u * s - 0.6 * u * t
        ax.plot([q[0], q1[0]], [q[1], q1[1]], color=FRAME_COLOUR, lw=0.8, zorder=z)


def ground_pivot(ax: Axes, p: np.ndarray, u: float) -> None:
    """A fixed pivot: a triangle standing on a hatched base."""
    p = np.asarray(p, dtype=float)
    base = p - np.array([0.0, 1.5 * u])
    tri = [p, base + np.array([-0.9 * u, 0.0]), base + np.array([0.9 * u, 0.0])]
    ax.add_patch(
        Polygon(tri, closed=True, facecolor="0.85", edgecolor=FRAME_COLOUR, lw=1.0, zorder=1.5)
    )
    hatch(ax, base - np.array([1.4 * u, 0.0]), base + np.array([1.4 * u, 0.0]), (0.0, -1.0), u)


def _side(d: float, r: float, negative: str, positive: str) -> str:
    """The alignment of text offset by d (of length r) along one axis: it grows away."""
    return positive if d > 0.35 * r else negative if d < -0.35 * r else "center"


def label(
    ax: Axes,
    p: np.ndarray,
    text: str,
    offset: tuple[float, float],
    colour: str = "black",
    size: float = 9,
    weight: str = "normal",
    box: bool = True,
) -> None:
    """Text near p, ``offset`` in points; aligned so that it grows away from p."""
    dx, dy = offset
    r = math.hypot(dx, dy)
    ha, va = _side(dx, r, "right", "left"), _side(dy, r, "top", "bottom")
    bbox = dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75) if box else None
    ax.annotate(
        text,
        xy=(p[0], p[1]),
        xytext=(dx, dy),
        textcoords="offset points",
        ha=ha,
        va=va,
        fontsize=size,
        color=colour,
        weight=weight,
        zorder=9,
        bbox=bbox,
    )


def beside(p0: np.ndarray, p1: np.ndarray, u: float, up: bool = True) -> np.ndarray:
    """A point 1.8 u beside the middle of the bar p0-p1 (on its upper side if ``up``)."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    t = p1 - p0
    n = geo.rot90(t) / max(float(np.hypot(*t)), 1e-300)
    if (n[1] < 0) == up:
        n = -n
    return 0.5 * (p0 + p1) + 1.8 * u * n


def away(
    p: np.ndarray, centre: np.ndarray, default: tuple[float, float] = (1.0, 1.0)
) -> np.ndarray:
    """The unit vector from centre towards p (default where they coincide)."""
    d = np.asarray(p, dtype=float) - centre
    n = float(np.hypot(*d))
    if n < 1e-12:
        d, n = np.asarray(default, dtype=float), float(np.hypot(*default))
    return d / n


def label_points(
    ax: Axes,
    points: dict,
    names: dict,
    size: float,
    offset: float = 11.0,
    fontsize: float = 9,
    drop_dotted: bool = True,
    avoid: np.ndarray | None = None,
) -> dict:
    """Label every point (key -> (2,) point) with its name (key -> text), coincident points
    (within 1e-9 of ``size``) merged into one label "a = b" away from the points' centre,
    or, given ``avoid`` (an (N, 2) array of points drawn), on the side of the eight where
    the nearest of them is farthest; with ``drop_dotted`` a name with a dot is left out
    where one without names the same point. Returns the label shown for each key."""
    keys = list(names)
    pts = {k: np.asarray(points[k], dtype=float) for k in keys}
    centre = np.mean([pts[k] for k in keys], axis=0)
    done, shown = set(), {}
    for a in keys:
        if a in done:
            continue
        same = [b for b in keys if np.hypot(*(pts[a] - pts[b])) <= 1e-9 * size]
        group = list(dict.fromkeys(names[b] for b in same if b == a or b not in done))
        done.update(same)
        if drop_dotted:
            group = [g for g in group if "." not in g] or group
        for b in same:
            shown[b] = group[0]
        d = away(pts[a], centre, default=(-1.0, 1.0))
        if avoid is not None:
            d = clearest_side(pts[a], d, avoid, 0.04 * size)
        label(ax, pts[a], " = ".join(group), tuple(offset * d), size=fontsize)
    return shown


def clearest_side(
    p: np.ndarray, preferred: np.ndarray, avoid: np.ndarray, reach: float
) -> np.ndarray:
    """Of the eight unit directions from p (and ``preferred``, which wins ties), the one
    whose point ``reach`` away is farthest from the nearest point of ``avoid`` (points
    within 1e-9 ``reach`` of p do not count)."""
    others = np.asarray(avoid, dtype=float).reshape(-1, 2)
    others = others[np.hypot(*(others - p).T) > 1e-9 * reach]
    if len(others) == 0:
        return preferred
    turns = np.linspace(0.0, 2.0 * math.pi, 8, endpoint=False)
    sides = [preferred] + [np.array([math.cos(t), math.sin(t)]) for t in turns]
    clear = [float(np.hypot(*(others - (p + reach * d)).T).min()) for d in sides]
    return sides[int(np.argmax(clear))]


def force_arrow(
    ax: Axes,
    p: np.ndarray,
    vec: np.ndarray,
    u: float,
    colour: str,
    text: str,
    width: float | None = None,
    z: float = 8.0,
) -> FancyArrow:
    """A force drawn from its point of application p as the arrow vec (m of drawing, the
    head included), labelled ``text`` for a legend; its head at most half its length."""
    width = 0.2 * u if width is None else width
    length = float(np.hypot(*vec))
    return ax.arrow(
        p[0],
        p[1],
        vec[0],
        vec[1],
        width=width,
        head_width=max(0.6 * u, 2.0 * width),
        head_length=min(1.0 * u, 0.5 * length),
        length_includes_head=True,
        color=colour,
        alpha=0.85,
        zorder=z,
        label=text,
    )


def sample_at(kin: dict, index: int) -> tuple[int, Callable[[str], np.ndarray]]:
    """Sample ``index`` of ``kin`` (negative counts from the end): the index made
    non-negative and a function key -> that sample's value as a float array."""
    n_samples = len(np.atleast_1d(kin["t"]))
    if not -n_samples <= index < n_samples:
        raise IndexError(f"index {index} out of range for {n_samples} samples")
    index = int(index) % n_samples

    def at(key: str) -> np.ndarray:
        return np.asarray(kin[key][index], dtype=float)

    return index, at


def checked_scale(scale: float | None) -> float | None:
    """A force scale (N/m) as a float, or None; a ValueError unless positive and finite."""
    if scale is not None:
        scale = float(scale)
        if not (scale > 0 and math.isfinite(scale)):
            raise ValueError(f"scale must be a positive number (N/m), got {scale!r}")
    return scale


def finish_axes(ax: Axes, margin: float) -> None:
    """Equal aspect, autoscaled with ``margin``, axes in metres, a light grid."""
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.margins(margin)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, lw=0.3, alpha=0.5)

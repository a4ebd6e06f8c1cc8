"""Drawing of a mechanism of :mod:`dyadfmu.mechanisms` to scale on a matplotlib Axes,
optionally with joint reactions as arrows on one force scale.

Symbols: the frame k as hatched ground under fixed pivots and along fixed guides,
the crank p, links m and n as bars (slotted where a block slides in them), revolute
pairs as small white circles, translational pairs as small rectangles aligned with
their guide, centres of mass as dots (S_c, S_m, S_n), and labels.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.patches import Circle, Polygon

__all__ = ["draw", "mechanism_size", "APPLICATION"]

#: Where each reaction acts: R_mk on m at D_m, R_np on n at D_n, R_mn on m at E,
#: R_O on the crank at O (from the frame).
APPLICATION = {"R_mk": "D_m", "R_np": "D_n", "R_mn": "E", "R_O": "O"}
_ARROW_COLOURS = {"R_mk": "tab:red", "R_np": "tab:blue", "R_mn": "tab:purple",
                  "R_O": "tab:green"}
_COLOUR = {"p": "tab:orange", "m": "tab:blue", "n": "tab:olive", "k": "0.35"}
_LINK_WIDTH = 5.0


def mechanism_size(mechanism, kin) -> float:
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
def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def _rot90(v):
    return np.array([-v[1], v[0]])


def _bar(ax, p0, p1, colour, width=_LINK_WIDTH, z=2.0):
    ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color=colour, lw=width,
            solid_capstyle="round", zorder=z)


def _slot(ax, p0, p1, z):
    """A slot along a bar: a white groove drawn over it."""
    ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color="white", lw=_LINK_WIDTH * 0.35,
            solid_capstyle="round", zorder=z)


def _pin(ax, p, u, z=6.0):
    ax.add_patch(Circle(tuple(p), 0.42 * u, facecolor="white", edgecolor="black",
                        lw=1.2, zorder=z))


def _block(ax, centre, direction, length, width, colour, z=4.0):
    """A rectangle centred at ``centre`` with its long side along ``direction``."""
    i = np.asarray(direction, dtype=float)
    i = i / np.hypot(*i)
    j = _rot90(i)
    c = np.asarray(centre, dtype=float)
    a, b = 0.5 * length * i, 0.5 * width * j
    corners = [c - a - b, c + a - b, c + a + b, c - a + b]
    ax.add_patch(Polygon(corners, closed=True, facecolor=colour, edgecolor="black",
                         lw=1.0, alpha=0.9, zorder=z))


def _hatch(ax, p0, p1, side, u, z=1.0):
    """A fixed surface from p0 to p1 with hatch strokes on the side ``side`` (a vector)."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color=_COLOUR["k"], lw=1.5, zorder=z)
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
        ax.plot([q[0], q1[0]], [q[1], q1[1]], color=_COLOUR["k"], lw=0.8, zorder=z)


def _ground_pivot(ax, p, u):
    """A fixed pivot: a triangle standing on a hatched base."""
    p = np.asarray(p, dtype=float)
    base = p - np.array([0.0, 1.5 * u])
    tri = [p, base + np.array([-0.9 * u, 0.0]), base + np.array([0.9 * u, 0.0])]
    ax.add_patch(Polygon(tri, closed=True, facecolor="0.85", edgecolor=_COLOUR["k"],
                         lw=1.0, zorder=1.5))
    _hatch(ax, base - np.array([1.4 * u, 0.0]), base + np.array([1.4 * u, 0.0]),
           (0.0, -1.0), u)


def _label(ax, p, text, offset, colour="black", size=9, weight="normal", box=True):
    """Text near p, ``offset`` in points; aligned so that it grows away from p."""
    dx, dy = offset
    ha = "left" if dx > 0.35 * math.hypot(dx, dy) else "right" if dx < -0.35 * math.hypot(dx, dy) else "center"
    va = "bottom" if dy > 0.35 * math.hypot(dx, dy) else "top" if dy < -0.35 * math.hypot(dx, dy) else "center"
    bbox = dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75) if box else None
    ax.annotate(text, xy=(p[0], p[1]), xytext=(dx, dy), textcoords="offset points",
                ha=ha, va=va, fontsize=size, color=colour, weight=weight, zorder=9, bbox=bbox)


def _beside(p0, p1, u, up=True):
    """A point 1.8 u beside the middle of the bar p0-p1 (on its upper side if ``up``)."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    t = p1 - p0
    n = _rot90(t) / max(float(np.hypot(*t)), 1e-300)
    if (n[1] < 0) == up:
        n = -n
    return 0.5 * (p0 + p1) + 1.8 * u * n


def _away(p, centre, default=(1.0, 1.0)):
    d = np.asarray(p, dtype=float) - centre
    n = float(np.hypot(*d))
    if n < 1e-12:
        d, n = np.asarray(default, dtype=float), float(np.hypot(*default))
    return d / n


# ---------------------------------------------------------------------------
# the mechanisms
# ---------------------------------------------------------------------------
def _draw_slider_crank(ax, mech, at, u):
    A, B = at("A"), at("D_m")
    x0, x1 = (p[0] for p in mech._frame()["guides"]["k"])
    e = mech.e
    hb = 1.0 * u                                  # half height of the slider
    ax.plot([x0, x1], [e, e], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)     # guide line
    _hatch(ax, (x0, e - hb), (x1, e - hb), (0.0, -1.0), u)                       # rail below
    _hatch(ax, (x0, e + hb), (x1, e + hb), (0.0, 1.0), u)                        # and above
    _block(ax, B, (1.0, 0.0), 3.0 * u, 2.0 * hb, _COLOUR["m"])
    _bar(ax, A, B, _COLOUR["n"], z=3)
    return {"m": B + np.array([0.0, 2.6 * u]), "n": _beside(A, B, u),
            "k": np.array([x1, e - hb]) + np.array([-0.5 * u, -1.8 * u])}


def _draw_four_bar(ax, mech, at, u):
    A, E, O4 = at("A"), at("E"), at("D_m")
    _ground_pivot(ax, O4, u)
    _bar(ax, O4, E, _COLOUR["m"], z=2.5)
    _bar(ax, A, E, _COLOUR["n"], z=3)
    return {"m": _beside(O4, E, u, up=False), "n": _beside(A, E, u),
            "k": O4 + np.array([3.4 * u, -1.0 * u])}


def _draw_quick_return(ax, mech, at, u):
    A, O2 = at("A"), at("D_m")
    i_m = _unit(at("m.angle"))
    d = math.hypot(*mech.O2)
    r = mech.crank["radius"]
    tip = O2 + mech.lever_length * i_m
    _ground_pivot(ax, O2, u)
    _bar(ax, O2, tip, _COLOUR["m"], width=_LINK_WIDTH * 1.6, z=2.5)
    _slot(ax, O2 + (d - r - 1.2 * u) * i_m, O2 + min(d + r + 1.2 * u, mech.lever_length) * i_m,
          z=2.6)
    _block(ax, A, i_m, 2.4 * u, 1.1 * u, _COLOUR["n"], z=4)
    return {"m": O2 + 0.5 * (d - r) * i_m + 1.8 * u * _rot90(i_m),
            "n": A - 2.0 * u * _rot90(i_m) - 1.0 * u * i_m,
            "k": O2 + np.array([3.4 * u, -1.0 * u])}


def _draw_scotch_yoke(ax, mech, at, u):
    A, Dm = at("A"), at("D_m")
    r, h = mech.crank["radius"], mech.h
    (x0, _), (x1, _) = mech._frame()["guides"]["k"]
    x0, x1 = min(x0, -r - 3 * u), max(x1, r + 3 * u)
    hf = 0.8 * u                                  # half height of the yoke's foot
    ax.plot([x0, x1], [-h, -h], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)
    _hatch(ax, (x0, -h - hf), (x1, -h - hf), (0.0, -1.0), u)
    top = np.array([Dm[0], r + 2.0 * u])
    _bar(ax, Dm, top, _COLOUR["m"], width=_LINK_WIDTH * 1.6, z=2.5)
    _slot(ax, (Dm[0], -r - 1.0 * u), (Dm[0], r + 1.0 * u), z=2.6)
    _block(ax, Dm, (1.0, 0.0), 4.0 * u, 2.0 * hf, _COLOUR["m"], z=3)             # foot on k
    _block(ax, A, (0.0, 1.0), 2.4 * u, 1.1 * u, _COLOUR["n"], z=4)               # block in slot
    return {"m": top + np.array([1.5 * u, -0.5 * u]), "n": A + np.array([1.8 * u, -1.2 * u]),
            "k": np.array([x1 - 0.5 * u, -h - hf - 1.6 * u])}


def _draw_trt_slot(ax, mech, at, u):
    E = at("E")
    phi = at("crank.angle")
    i_p = _unit(phi)
    r, h = mech.crank["radius"], mech.h
    (x0, _), (x1, _) = mech._frame()["guides"]["k"]
    hs = 1.0 * u                                  # half height of the slider
    ax.plot([x0, x1], [h, h], color=_COLOUR["k"], lw=0.8, ls="-.", zorder=1)
    _hatch(ax, (x0, h + hs), (x1, h + hs), (0.0, 1.0), u)
    _hatch(ax, (x0, h - hs), (x1, h - hs), (0.0, -1.0), u)
    _block(ax, E, (1.0, 0.0), 4.0 * u, 2.0 * hs, _COLOUR["m"], z=3)              # slider on k
    _block(ax, E, i_p, 2.4 * u, 1.1 * u, _COLOUR["n"], z=4.5)                    # block in slot
    return {"m": E + np.array([2.8 * u, -2.0 * u]), "n": E + 2.2 * u * _rot90(i_p) - 1.0 * u * i_p,
            "k": np.array([x1 - 0.5 * u, h + hs + 1.6 * u])}


def draw(ax, mechanism, kin, index, reactions=None, scale=None):
    """Draw ``mechanism`` at sample ``index`` of ``kin`` (from ``mechanism.kinematics``)
    on ``ax`` to scale, with equal aspect.

    reactions: optional dict name -> (Fx, Fy) in N, names among ``R_mk`` (at D_m),
    ``R_np`` (at D_n), ``R_mn`` (at E) and ``R_O`` (the frame on the crank at O); each
    is drawn as an arrow from its point of application, all with one force scale in
    N per m of drawing: ``scale`` if given, else chosen so that the largest arrow is
    40 % of the mechanism's size. Returns the scale used (N/m).
    """
    n_samples = len(kin["t"])
    if not -n_samples <= index < n_samples:
        raise IndexError(f"index {index} out of range for {n_samples} samples")
    index = int(index) % n_samples

    def at(key):
        return np.asarray(kin[key][index], dtype=float)

    size = mechanism_size(mechanism, kin)
    u = 0.035 * size                               # size of the symbols
    O, A = at("O"), at("A")
    phi = float(at("crank.angle"))

    # frame k at O, the crank p
    _ground_pivot(ax, O, u)
    side = _rot90(_unit(phi))                      # the crank's label goes on the side away from E
    if np.dot(side, at("E") - O) > 0:
        side = -side
    if mechanism.dyad == "TRT":
        tip = O + mechanism.crank["radius"] * _unit(phi)
        _bar(ax, O, tip, _COLOUR["p"], width=_LINK_WIDTH * 1.6, z=2.0)
        _slot(ax, O + 0.35 * (tip - O), O + (tip - O) * (1 - 1.2 * u / mechanism.crank["radius"]),
              z=2.1)
        p_label = O + 0.25 * (tip - O) + 1.6 * u * side
    else:
        _bar(ax, O, A, _COLOUR["p"], z=2.0)
        p_label = 0.5 * (O + A) + 1.6 * u * side

    if mechanism.dyad == "RRT":
        where = _draw_slider_crank(ax, mechanism, at, u)
    elif mechanism.dyad == "RRR":
        where = _draw_four_bar(ax, mechanism, at, u)
    elif mechanism.dyad == "RTR":
        where = _draw_quick_return(ax, mechanism, at, u)
    elif mechanism.dyad == "RTT":
        where = _draw_scotch_yoke(ax, mechanism, at, u)
    else:
        where = _draw_trt_slot(ax, mechanism, at, u)

    # revolute pairs
    pins = {"RRT": ("O", "A", "E"), "RRR": ("O", "A", "E", "D_m"),
            "RTR": ("O", "A", "D_m"), "RTT": ("O", "A"), "TRT": ("O", "E")}[mechanism.dyad]
    for key in pins:
        _pin(ax, at(key), u)

    # centres of mass
    for key, colour in (("S_c", _COLOUR["p"]), ("S_m", _COLOUR["m"]), ("S_n", _COLOUR["n"])):
        s = at(key)
        ax.plot([s[0]], [s[1]], "o", ms=4.5, mfc=colour, mec="black", mew=0.8, zorder=7)

    # point labels, coincident points merged ("A = D_n = E")
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
        off = 10.0 * _away(pts[a], centre, default=(-1.0, 1.0))
        _label(ax, pts[a], " = ".join(group), off, size=10)

    # link labels
    link_at = {"p": p_label, "m": where["m"], "n": where["n"], "k": where["k"]}
    for link, p in link_at.items():
        _label(ax, p, link, (0.0, 0.0), colour=_COLOUR[link] if link != "k" else "black",
               size=12, weight="bold", box=False)

    # reactions
    if scale is not None:
        scale = float(scale)
        if not (scale > 0 and math.isfinite(scale)):
            raise ValueError(f"scale must be a positive number (N/m), got {scale!r}")
    if reactions:
        forces = {}
        for name, f in reactions.items():
            if name not in APPLICATION:
                raise ValueError(f"unknown reaction {name!r}; expected some of {sorted(APPLICATION)}")
            f = np.asarray(f, dtype=float).reshape(2)
            if np.all(np.isfinite(f)):
                forces[name] = f
        largest = max((float(np.hypot(*f)) for f in forces.values()), default=0.0)
        if scale is None:
            scale = largest / (0.4 * size) if largest > 0 else 1.0
        handles = []
        for name, f in forces.items():
            p = at(APPLICATION[name])
            vec = f / scale
            length = float(np.hypot(*vec))
            label = f"{name} = {np.hypot(*f):.4g} N"
            if length <= 1e-12 * size:
                handles.append(ax.plot([p[0]], [p[1]], "x", color=_ARROW_COLOURS[name],
                                       label=label, zorder=8)[0])
                continue
            head = min(1.1 * u, 0.5 * length)
            handles.append(ax.arrow(p[0], p[1], vec[0], vec[1], width=0.16 * u,
                                    head_width=0.65 * u, head_length=head,
                                    length_includes_head=True, color=_ARROW_COLOURS[name],
                                    alpha=0.85, zorder=8, label=label))
        if handles:
            ax.legend(handles=handles, loc="best", fontsize=8,
                      title=f"force scale {scale:.3g} N/m\n(1 mm = {scale / 1000:.3g} N)",
                      title_fontsize=8, framealpha=0.85)
    elif scale is None:
        scale = 1.0

    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.margins(0.08)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, lw=0.3, alpha=0.5)
    return scale

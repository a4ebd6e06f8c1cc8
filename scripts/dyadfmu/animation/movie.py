"""The animation as an animated GIF (Pillow, which matplotlib brings): at left the
mechanism to scale with its forces on one scale for the whole run
(:func:`dyadfmu.report.drivers_drawing.draw`), at right the curves, one panel per unit,
with a cursor at the frame's instant. An instant with no answer shows the nearest
answered pose faded and the reason in red; the curves mark those instants in red."""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from PIL import Image  # noqa: E402

from ..report import cylinder_drawing as cd  # noqa: E402
from ..report import drivers_drawing as dd  # noqa: E402
from .frames import Frames  # noqa: E402

FADED_POSE = "the pose drawn faded is the nearest answered one"
#: At most this many frames in the GIF (the run's instants evenly thinned beyond it).
MOST_FRAMES = 180


def chosen(count: int, most: int = MOST_FRAMES) -> list[int]:
    """The instants drawn: every one, or ``most`` evenly spread with the first and last."""
    if count <= most:
        return list(range(count))
    return sorted({int(round(k)) for k in np.linspace(0, count - 1, most)})


def _scale(frames: Frames, size: float) -> tuple[float, tuple]:
    """One force scale for the whole run (per m of arrow, in kN or N)."""
    forces = [f for k in frames.answered for f in frames.poses[k].forces]
    unit = dd.force_unit(forces)
    return cd.force_scale(forces, size, unit[1]), unit


def _curve_axes(fig: plt.Figure, grid: object, frames: Frames) -> list:
    """A panel per unit with its curves and the instants without an answer; the cursors."""
    units = list(dict.fromkeys(c.unit for c in frames.curves))
    t = frames.run.times
    failed = [t[k] for k, why in enumerate(frames.run.reasons) if why]
    cursors, handles = [], []
    for row, unit in enumerate(units):
        ax = fig.add_subplot(grid[row, 1])
        for c in (c for c in frames.curves if c.unit == unit):
            handles += ax.plot(t, c.values, lw=1.0, label=c.name)
        for at in failed:
            ax.axvline(at, color="red", alpha=0.25, lw=1.5)
        ax.set_ylabel(f"[{unit}]" if unit else "")
        ax.grid(alpha=0.3)
        cursors.append(ax.axvline(t[0], color="black", lw=1.0))
        if row == len(units) - 1:
            ax.set_xlabel("t [s]")
    fig.legend(handles=handles, loc="lower right", bbox_to_anchor=(0.99, 0.01), ncol=3, fontsize=6)
    return cursors


def _no_answer(ax: plt.Axes, why: str) -> None:
    """The nearest answered pose faded, its forces' legend replaced by the reason."""
    for artist in [*ax.lines, *ax.patches, *ax.collections, *ax.texts]:
        artist.set_alpha(0.2)
    if ax.get_legend():
        ax.get_legend().remove()
    ax.legend(
        handles=[Patch(color="red", alpha=0.3)],
        labels=[f"no answer at this instant (marked red on the curves);\n{FADED_POSE}"],
        loc="upper center",
        bbox_to_anchor=(0.5, -0.08),
        fontsize=7,
        title="\n".join(textwrap.wrap(why, 90)[:6]),
        title_fontsize=7,
        labelcolor="red",
    )


def _drawer(mechanism: dd.Mechanism, frames: Frames, ax: plt.Axes, cursors: list) -> Callable:
    """The function that draws instant ``k``."""
    answered = np.array(frames.answered)
    every = [frames.poses[k] for k in answered]
    size = cd._size(every)
    scale, unit = _scale(frames, size)
    per_metre = scale * unit[1]  # N per m of arrow
    xy = [p for pose in every for p in pose.points.values()]
    xy += [pose.points[f[2]] + np.asarray(f[3]) / per_metre for pose in every for f in pose.forces]
    low, high = np.min(xy, axis=0) - 0.1 * size, np.max(xy, axis=0) + 0.1 * size

    def draw(k: int) -> None:
        ax.clear()
        shown = int(answered[np.argmin(np.abs(answered - k))])
        dd.draw(ax, mechanism, [frames.poses[shown]], 0, scale, unit)
        t = frames.run.times[k]
        why = frames.run.reasons[k]
        if why:
            _no_answer(ax, why)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_title(f"{frames.identifier}, t = {t:.4f} s", fontsize=9)
        for cursor in cursors:
            cursor.set_xdata([t, t])

    return draw


def write(mechanism: dd.Mechanism, frames: Frames, path: Path, say: Callable) -> Path:
    """Write the GIF to ``path`` (one frame per instant of :func:`chosen`), saying how far
    it is every 30 frames; returns it."""
    units = len(dict.fromkeys(c.unit for c in frames.curves)) or 1
    fig = plt.figure(figsize=(11.0, 7.5), dpi=72)
    # room below the mechanism for the legend of its forces (drivers_drawing.draw)
    grid = fig.add_gridspec(units, 2, width_ratios=(1.25, 1.0), bottom=0.27, top=0.95)
    ax = fig.add_subplot(grid[:, 0])
    draw = _drawer(mechanism, frames, ax, _curve_axes(fig, grid, frames))
    instants = chosen(len(frames.poses))
    images = []
    for n, k in enumerate(instants):
        if n % 30 == 0:
            say(f"{path.name}: frame {n + 1} of {len(instants)}")
        draw(k)
        fig.canvas.draw()
        images.append(Image.fromarray(np.asarray(fig.canvas.buffer_rgba())).convert("RGB"))
    plt.close(fig)
    span = float(frames.run.times[-1] - frames.run.times[0])
    period = int(round(max(40.0, 1000.0 * span / len(instants))))
    images[0].save(path, save_all=True, append_images=images[1:], duration=period, loop=0)
    return path

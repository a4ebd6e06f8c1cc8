"""The animation as one self-contained HTML page (no file or network fetched): the
mechanism drawn in SVG frame by frame, a time slider and a play button, the curves beside
it with a cursor at the frame's instant, and a table of the curves' and forces' values.

The frames go into the page as JSON in a ``<script type="application/json">`` element,
every ``<``, ``>`` and ``&`` written as a JSON escape, so that no name from a scene file can
close the element; the page's script puts names into the document as text only. Every
number is rounded to :data:`DIGITS` significant digits (plotting precision). Each pair is
drawn as an SVG circle with ``data-point`` its name and its centre at (x, -y) m; each force
as a line with ``data-force`` its name."""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

import numpy as np

from .frames import Frames

#: Significant digits of every number in the page.
DIGITS = 9
#: The largest force's arrow as a share of the mechanism's size.
ARROW_SHARE = 0.3
TEMPLATE = Path(__file__).with_name("page.html")


def _n(value: float) -> float | None:
    """A number at plotting precision; None (JSON null) where it is not finite."""
    value = float(value)
    return float(f"{value:.{DIGITS}g}") if math.isfinite(value) else None


def _xy(point: object) -> list:
    return [_n(point[0]), _n(point[1])]


def _slider_angle(pose: object, key: str) -> float:
    """The direction a sliding pair's block is drawn along: towards the first other point of
    a body it belongs to."""
    for keys in pose.bodies.values():
        for other in keys:
            if key in keys and other != key:
                d = pose.points[other] - pose.points[key]
                if np.hypot(*d) > 0:
                    return math.atan2(d[1], d[0])
    return 0.0


def _frame(pose: object) -> dict:
    """One pose as the page draws it."""
    return {
        "points": {k: _xy(p) for k, p in pose.points.items()},
        "bodies": [[b, list(keys)] for b, keys in pose.bodies.items()],
        "cylinders": [
            [_xy(a), _xy(mouth), _xy(b)] for (a, mouth), (_, b) in pose.cylinders().values()
        ],
        "pins": list(dict.fromkeys(pose.pins)),
        "pivots": list(dict.fromkeys(pose.pivots)),
        "sliders": [[k, _n(_slider_angle(pose, k))] for k in dict.fromkeys(pose.sliders)],
        "guides": [[k, _n(angle)] for k, angle in pose.guides],
        "forces": [[n, key, *_xy(f), bool(applied)] for n, _, key, f, applied in pose.forces],
    }


def _extent(frames: Frames) -> tuple[list, float, float]:
    """[x0, y0, x1, y1] m around every pose and its arrows, the size (m) and the arrows'
    scale (m per N)."""
    poses = [frames.poses[k] for k in frames.answered]
    xy = np.array([p for pose in poses for p in pose.points.values()])
    size = max(float(np.ptp(xy, axis=0).max()), 1e-3)
    largest = max((float(np.hypot(*f[3])) for pose in poses for f in pose.forces), default=0.0)
    scale = ARROW_SHARE * size / largest if largest > 0 else 0.0
    tips = [pose.points[f[2]] + scale * np.asarray(f[3]) for pose in poses for f in pose.forces]
    every = np.vstack([xy, *tips]) if tips else xy
    margin = 0.08 * size
    low, high = every.min(axis=0) - margin, every.max(axis=0) + margin
    return [_n(low[0]), _n(low[1]), _n(high[0]), _n(high[1])], size, scale


def data(frames: Frames) -> dict:
    """Everything the page shows, as JSON-ready values."""
    bounds, size, scale = _extent(frames)
    run = frames.run
    return {
        "identifier": frames.identifier,
        "source": run.source,
        "times": [_n(t) for t in run.times],
        "reasons": list(run.reasons),
        "frames": [None if p is None else _frame(p) for p in frames.poses],
        "curves": [
            {"name": c.name, "unit": c.unit, "values": [_n(v) for v in c.values]}
            for c in frames.curves
        ],
        "labels": frames.labels,
        "colours": frames.colours,
        "efforts": list(frames.efforts),
        "bounds": bounds,
        "size": _n(size),
        "scale": _n(scale),
    }


def script_json(value: object) -> str:
    """JSON safe inside an HTML ``<script>`` element: no ``<``, ``>`` or ``&`` in it."""
    text = json.dumps(value, ensure_ascii=True, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def write(frames: Frames, path: Path) -> Path:
    """Write the page to ``path``; returns it."""
    title = f"{frames.identifier}: the mechanism in motion"
    text = TEMPLATE.read_text(encoding="utf-8")
    text = text.replace("__DYADFMU_TITLE__", html.escape(title))
    text = text.replace("__DYADFMU_DATA__", script_json(data(frames)))
    path.write_text(text, encoding="utf-8")
    return path

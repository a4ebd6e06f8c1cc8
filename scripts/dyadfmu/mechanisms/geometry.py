"""Shared helpers of the mechanisms: vectors on arrays of shape (..., 2) and the checked
reading of numbers and pairs from the data tables."""

from __future__ import annotations

import copy
import math
import os
import tomllib
from collections.abc import Mapping

import numpy as np


def inexact(x: object) -> np.ndarray:
    """x as a float array, or as a complex one where x is complex (so that the
    kinematics carry a complex step through)."""
    x = np.asarray(x)
    return x.astype(np.result_type(x.dtype, float), copy=False)


def unit(angle: float) -> np.ndarray:
    """Unit vectors at the given angles (rad); complex angles give complex vectors."""
    angle = inexact(angle)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def norm(v: np.ndarray) -> np.ndarray:
    """The lengths of the vectors: hypot for real ones, the analytic sqrt(v . v) for
    complex ones (a complex step passes through)."""
    v = inexact(v)
    if np.iscomplexobj(v):
        return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1])
    return np.hypot(v[..., 0], v[..., 1])


def angle(v: np.ndarray) -> np.ndarray:
    """The angles (rad) of the vectors: atan2 for real ones; for complex ones atan2 of
    the real parts plus the analytic rest, atan((v0 x v) / (v0 . v)), v0 = Re v."""
    v = inexact(v)
    if not np.iscomplexobj(v):
        return np.arctan2(v[..., 1], v[..., 0])
    v0 = v.real
    base = np.arctan2(v0[..., 1], v0[..., 0])
    return base + np.arctan(cross(v0, v) / dot(v0, v))


def rot90(v: np.ndarray) -> np.ndarray:
    """The vectors turned by +90 degrees."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The dot products of a and b."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The z components of the cross products a x b."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def col(x: object) -> np.ndarray:
    """The values as a column (a trailing axis of length 1); float, or complex where x is."""
    return inexact(x)[..., None]


def vec(x: object, y: object) -> np.ndarray:
    """Vectors from their x and y components, broadcast together (float, or complex
    where a component is)."""
    x, y = np.broadcast_arrays(inexact(x), inexact(y))
    return np.stack([x, y], axis=-1)


def merge(base: Mapping, over: Mapping) -> dict:
    """A deep copy of base with the tables of over merged in, key by key."""
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def overridden(table: Mapping, name: str, data: Mapping | str | os.PathLike | None) -> dict:
    """``table`` with ``data`` merged in key by key: a mapping, either the whole document
    (with a table ``name``) or ``name``'s own table, or the path of a TOML file of that form."""
    if data is None:
        return table
    if isinstance(data, (str, os.PathLike)):
        with open(data, "rb") as f:
            data = tomllib.load(f)
    if not isinstance(data, Mapping):
        raise ValueError(f"data: expected a mapping or a TOML path, got {type(data).__name__}")
    over = data[name] if name in data else data
    if not isinstance(over, Mapping):
        raise ValueError(f"data[{name!r}]: expected a table")
    return merge(table, over)


def number(
    table: Mapping,
    key: str,
    where: str,
    positive: bool = False,
    nonnegative: bool = False,
    default: tuple[float, float] = None,
) -> float:
    """The finite number table[key] (or the default), checked; errors name where."""
    if key not in table:
        if default is not None:
            return float(default)
        raise ValueError(f"{where}: missing key {key!r}")
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where}.{key}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise ValueError(f"{where}.{key}: must be > 0, got {value!r}")
    if nonnegative and value < 0:
        raise ValueError(f"{where}.{key}: must be >= 0, got {value!r}")
    return float(value)


def pair(table: Mapping, key: str, where: str) -> tuple[float, float]:
    """The pair of finite numbers table[key]; errors name where."""
    value = table.get(key)
    if value is None:
        raise ValueError(f"{where}: missing key {key!r}")
    try:
        x, y = (float(c) for c in value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}.{key}: expected two numbers, got {value!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ValueError(f"{where}.{key}: expected finite numbers, got {value!r}")
    return (x, y)

"""Python binding of the C kinetostatic core (``libdyadfmu.so``) through ctypes.

The inputs are the dicts of :mod:`dyadfmu.reference.newton_euler` (same keys, same units), so
one configuration can be given to both. The library is looked up in
``$DYADFMU_LIB``, else in ``build/`` beside ``scripts/``.
"""

from __future__ import annotations

import ctypes
import os
from pathlib import Path
from typing import TYPE_CHECKING

from .paths import ROOT

if TYPE_CHECKING:
    import numpy as np

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
STATUS = {0: "ok", 1: "singular", 2: "invalid input", 3: "out of range", 4: "cannot assemble"}
#: The scalar reactions of a solve: joint-normal forces and moments.
REACTION_SCALARS = ("n_mk", "n_np", "n_mn", "m_mk", "m_np", "m_mn")
LINK_KEYS = (
    "dir",
    "length",
    "omega",
    "epsilon",
    "accel_d",
    "com",
    "mass",
    "inertia",
    "force",
    "moment",
)


class _Vec2(ctypes.Structure):
    _fields_ = [("x", ctypes.c_double), ("y", ctypes.c_double)]


class _Link(ctypes.Structure):
    _fields_ = [
        ("dir", _Vec2),
        ("length", ctypes.c_double),
        ("omega", ctypes.c_double),
        ("epsilon", ctypes.c_double),
        ("accel_d", _Vec2),
        ("com", _Vec2),
        ("mass", ctypes.c_double),
        ("inertia", ctypes.c_double),
        ("force", _Vec2),
        ("moment", ctypes.c_double),
    ]


class _Input(ctypes.Structure):
    _fields_ = [
        ("m", _Link),
        ("n", _Link),
        ("guide_k", _Vec2),
        ("guide_p", _Vec2),
        ("gravity", _Vec2),
        ("singular_threshold", ctypes.c_double),
    ]


class _Result(ctypes.Structure):
    _fields_ = [
        ("status", ctypes.c_int),
        ("field", ctypes.c_int),
        ("r_mk", _Vec2),
        ("r_np", _Vec2),
        ("r_mn", _Vec2),
        ("n_mk", ctypes.c_double),
        ("n_np", ctypes.c_double),
        ("n_mn", ctypes.c_double),
        ("m_mk", ctypes.c_double),
        ("m_np", ctypes.c_double),
        ("m_mn", ctypes.c_double),
        ("denominator", ctypes.c_double),
        ("conditioning", ctypes.c_double),
        ("amplification", ctypes.c_double),
    ]


def library_path() -> Path:
    """Where the shared core is expected."""
    env = os.environ.get("DYADFMU_LIB")
    if env:
        return Path(env)
    return ROOT / "build" / "libdyadfmu.so"


class Core:
    """The double-precision C core. ``Core().solve(...)`` mirrors ``reference.solve_mp``
    for one configuration and adds ``status``, ``field``, ``conditioning``,
    ``amplification`` and ``denominator``."""

    def __init__(self, path: os.PathLike | str | None = None):
        path = Path(path) if path else library_path()
        if not path.is_file():
            raise FileNotFoundError(
                f"C core not found at {path}; build it with "
                "'cmake -S . -B build && cmake --build build'"
            )
        self._lib = ctypes.CDLL(str(path))
        self._lib.dyad_input_default.restype = _Input
        self._lib.dyad_solve.argtypes = [
            ctypes.c_int,
            ctypes.POINTER(_Input),
            ctypes.POINTER(_Result),
        ]
        self._lib.dyad_solve.restype = ctypes.c_int
        self._lib.dyad_solve_tangent.argtypes = [
            ctypes.c_int,
            ctypes.POINTER(_Input),
            ctypes.POINTER(_Input),
            ctypes.POINTER(_Result),
            ctypes.POINTER(_Result),
        ]
        self._lib.dyad_solve_tangent.restype = ctypes.c_int
        self._lib.dyad_field_name.argtypes = [ctypes.c_int]
        self._lib.dyad_field_name.restype = ctypes.c_char_p

    @staticmethod
    def _fill_link(dst: _Link, src: dict) -> None:
        for key in LINK_KEYS:
            value = src[key]
            if key in ("dir", "accel_d", "com", "force"):
                setattr(dst, key, _Vec2(float(value[0]), float(value[1])))
            else:
                setattr(dst, key, float(value))

    def _input(
        self,
        m: dict,
        n: dict,
        guide_k: np.ndarray | None,
        guide_p: np.ndarray | None,
        gravity: tuple[float, float],
        singular_threshold: float = None,
    ) -> _Input:
        inp = self._lib.dyad_input_default()
        self._fill_link(inp.m, m)
        self._fill_link(inp.n, n)
        if guide_k is not None:
            inp.guide_k = _Vec2(float(guide_k[0]), float(guide_k[1]))
        if guide_p is not None:
            inp.guide_p = _Vec2(float(guide_p[0]), float(guide_p[1]))
        inp.gravity = _Vec2(float(gravity[0]), float(gravity[1]))
        if singular_threshold is not None:
            inp.singular_threshold = float(singular_threshold)
        return inp

    def _output(self, res: _Result) -> dict:
        out = {
            name: (getattr(res, name).x, getattr(res, name).y) for name in ("r_mk", "r_np", "r_mn")
        }
        for name in (*REACTION_SCALARS, "denominator", "conditioning", "amplification"):
            out[name] = getattr(res, name)
        out["status"] = STATUS.get(res.status, "?")
        out["field"] = self._lib.dyad_field_name(res.field).decode()
        return out

    def solve(
        self,
        dyad_type: str,
        m: dict,
        n: dict,
        guide_k: np.ndarray | None = None,
        guide_p: np.ndarray | None = None,
        gravity: tuple[float, float] = (0.0, 0.0),
        singular_threshold: float | None = None,
    ) -> dict:
        """One configuration solved by the C core: the reactions with status, field,
        conditioning, amplification and denominator."""
        if dyad_type not in TYPES:
            raise ValueError(f"unknown dyad type {dyad_type!r}; expected one of {TYPES}")
        inp = self._input(m, n, guide_k, guide_p, gravity, singular_threshold)
        res = _Result()
        self._lib.dyad_solve(TYPES.index(dyad_type), ctypes.byref(inp), ctypes.byref(res))
        return self._output(res)

    def solve_tangent(
        self, dyad_type: str, inputs: tuple, seeds: tuple, singular_threshold: float | None = None
    ) -> tuple[dict, dict]:
        """The reactions and their directional derivative. `inputs` and `seeds` are
        (m, n, guide_k, guide_p, gravity) tuples of the same form as solve's
        arguments; a seed direction is the derivative of the unit vector."""
        if dyad_type not in TYPES:
            raise ValueError(f"unknown dyad type {dyad_type!r}; expected one of {TYPES}")
        zero = (0.0, 0.0)
        inp = self._input(*inputs, singular_threshold=singular_threshold)
        sm, sn, sk, sp, sg = seeds
        seed = self._input(
            sm, sn, sk if sk is not None else zero, sp if sp is not None else zero, sg
        )
        value, derivative = _Result(), _Result()
        self._lib.dyad_solve_tangent(
            TYPES.index(dyad_type),
            ctypes.byref(inp),
            ctypes.byref(seed),
            ctypes.byref(value),
            ctypes.byref(derivative),
        )
        return self._output(value), self._output(derivative)

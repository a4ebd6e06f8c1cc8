"""Python binding of the C kinetostatic core (``libdyadfmu.so``) through ctypes.

The inputs are the dicts of :mod:`dyadfmu.reference.newton_euler` (same keys, same units), so
one configuration can be given to both. The library is ``$DYADFMU_LIB`` when set, else the
one an installed package bundles (``dyadfmu/_lib/libdyadfmu.so``, ``pip install ./scripts``),
else ``build/libdyadfmu.so`` of the checkout (:func:`library_candidates`).

The kinematics (``dyadfmu/kinematics.h``) take a dict shaped like ``dyad_kin_input``:
``{"k": {"position", "velocity", "acceleration", "guide", "omega", "epsilon"}, "p": {...},
"length_m", "length_n", "turn_m", "turn_n", "com_m", "com_n", "branch",
"singular_threshold", "mount_amplification"}``; a missing key keeps the value of
``dyad_kin_input_default()``.
"""

from __future__ import annotations

import ctypes
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

from . import paths

if TYPE_CHECKING:
    import numpy as np

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
STATUS = {0: "ok", 1: "singular", 2: "invalid input", 3: "out of range", 4: "cannot assemble"}
#: The scalar reactions of a solve: joint-normal forces and moments.
REACTION_SCALARS = ("n_mk", "n_np", "n_mn", "m_mk", "m_np", "m_mn")
#: Keys of a mount (external link k or p) in a kinematics input.
MOUNT_POINT_KEYS = ("position", "velocity", "acceleration")
MOUNT_KEYS = (*MOUNT_POINT_KEYS, "guide", "omega", "epsilon")
#: Vector and scalar keys of a kinematics input besides the mounts.
KIN_VECTORS = ("turn_m", "turn_n", "com_m", "com_n")
KIN_SCALARS = ("length_m", "length_n", "singular_threshold", "mount_amplification")
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


#: The columns of dyad_solve_batch (dyadfmu/batch.h): dyad_input's scalars and
#: dyad_result's after status and field, in their C order.
INPUT_COLUMN_COUNT = 35
OUTPUT_COLUMN_COUNT = 15


class InputArray(ctypes.Structure):
    """dyad_input_array: row r reads data[r * stride]; stride 0 repeats data[0]; NULL data
    keeps the default."""

    _fields_ = [("data", ctypes.c_void_p), ("stride", ctypes.c_ssize_t)]


class OutputArray(ctypes.Structure):
    """dyad_output_array: row r writes data[r * stride]; NULL data: not written."""

    _fields_ = [("data", ctypes.c_void_p), ("stride", ctypes.c_ssize_t)]


class BatchInput(ctypes.Structure):
    """dyad_batch_input: one InputArray per input column."""

    _fields_ = [("column", InputArray * INPUT_COLUMN_COUNT)]


class BatchOutput(ctypes.Structure):
    """dyad_batch_output: one OutputArray per output column, and per-row status and field
    (unsigned char arrays)."""

    _fields_ = [
        ("column", OutputArray * OUTPUT_COLUMN_COUNT),
        ("status", ctypes.c_void_p),
        ("field", ctypes.c_void_p),
    ]


class _PointMotion(ctypes.Structure):
    _fields_ = [("position", _Vec2), ("velocity", _Vec2), ("acceleration", _Vec2)]


class _Mount(ctypes.Structure):
    _fields_ = [
        ("point", _PointMotion),
        ("guide", _Vec2),
        ("omega", ctypes.c_double),
        ("epsilon", ctypes.c_double),
    ]


class _KinInput(ctypes.Structure):
    _fields_ = [
        ("k", _Mount),
        ("p", _Mount),
        ("length_m", ctypes.c_double),
        ("length_n", ctypes.c_double),
        ("turn_m", _Vec2),
        ("turn_n", _Vec2),
        ("com_m", _Vec2),
        ("com_n", _Vec2),
        ("branch", ctypes.c_int),
        ("singular_threshold", ctypes.c_double),
        ("mount_amplification", ctypes.c_double),
    ]


class _KinLink(ctypes.Structure):
    _fields_ = [
        ("dir", _Vec2),
        ("omega", ctypes.c_double),
        ("epsilon", ctypes.c_double),
        ("length", ctypes.c_double),
        ("length_rate", ctypes.c_double),
        ("length_accel", ctypes.c_double),
        ("d", _PointMotion),
        ("com", _PointMotion),
    ]


class _Slide(ctypes.Structure):
    _fields_ = [("s", ctypes.c_double), ("rate", ctypes.c_double), ("accel", ctypes.c_double)]


class _KinResult(ctypes.Structure):
    _fields_ = [
        ("status", ctypes.c_int),
        ("field", ctypes.c_int),
        ("failure", ctypes.c_int),
        ("gap", ctypes.c_double),
        ("m", _KinLink),
        ("n", _KinLink),
        ("e", _PointMotion),
        ("slide_k", _Slide),
        ("slide_p", _Slide),
        ("conditioning", ctypes.c_double),
        ("closure", ctypes.c_double),
        ("amplification", ctypes.c_double),
    ]


def _pair(v: _Vec2) -> tuple[float, float]:
    return (v.x, v.y)


def _point_motion(p: _PointMotion) -> dict:
    return {key: _pair(getattr(p, key)) for key in MOUNT_POINT_KEYS}


def _kin_link(link: _KinLink, angle: float) -> dict:
    out = {"dir": _pair(link.dir), "angle": angle}
    for key in ("omega", "epsilon", "length", "length_rate", "length_accel"):
        out[key] = getattr(link, key)
    out["d"] = _point_motion(link.d)
    out["com"] = _point_motion(link.com)
    return out


def _fill_kin_input(dst: _KinInput, src: dict) -> None:
    """Writes the keys present in `src` into `dst` (the rest keep their values)."""
    for name in ("k", "p"):
        mount = getattr(dst, name)
        for key, value in src.get(name, {}).items():
            if key not in MOUNT_KEYS:
                raise KeyError(f"unknown key {name}.{key!r}; expected one of {MOUNT_KEYS}")
            target = mount.point if key in MOUNT_POINT_KEYS else mount
            if key in ("omega", "epsilon"):
                setattr(target, key, float(value))
            else:
                setattr(target, key, _Vec2(float(value[0]), float(value[1])))
    for key in KIN_VECTORS:
        if key in src:
            setattr(dst, key, _Vec2(float(src[key][0]), float(src[key][1])))
    for key in KIN_SCALARS:
        if key in src:
            setattr(dst, key, float(src[key]))
    if "branch" in src:
        dst.branch = int(src["branch"])


def _real(what: str, value: object) -> float:
    """A real number of a solve's input, or an error naming it and the value given."""
    try:
        if isinstance(value, complex) or getattr(getattr(value, "dtype", None), "kind", "") == "c":
            raise TypeError("complex")
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{what} must be a real number, not {value!r}") from None


def _vec2(what: str, value: object) -> _Vec2:
    """A vector (x, y) of a solve's input, or an error naming it and the value given."""
    try:
        size = len(value)
    except TypeError:
        size = None
    if size != 2:
        raise ValueError(f"{what} must be a vector (x, y) of two numbers, not {value!r}")
    return _Vec2(_real(f"{what}[0]", value[0]), _real(f"{what}[1]", value[1]))


def type_index(dyad_type: object) -> int:
    """The index of a dyad type, in either case ("RRT", "rrt"), as dyadfmu.solve takes it."""
    kind = dyad_type.upper() if isinstance(dyad_type, str) else dyad_type
    if kind not in TYPES:
        raise ValueError(f"unknown dyad type {dyad_type!r}; expected one of {', '.join(TYPES)}")
    return TYPES.index(kind)


def library_candidates() -> list[Path]:
    """Where the shared core is looked for, in order: $DYADFMU_LIB alone when set (the test
    suite and scripts/run-tests set it); else the library the installed package bundles,
    then build/ of the checkout."""
    env = os.environ.get("DYADFMU_LIB")
    if env:
        return [Path(env)]
    candidates = [paths.BUNDLED_LIB]
    if paths.in_checkout():
        candidates.append(paths.ROOT / "build" / "libdyadfmu.so")
    return candidates


def library_path() -> Path:
    """The shared core: the first of library_candidates() that exists, else the last (the
    one to build)."""
    candidates = library_candidates()
    return next((path for path in candidates if path.is_file()), candidates[-1])


def _missing_library(tried: list[Path], given: bool = False) -> str:
    looked = ", ".join(str(path) for path in tried)
    if given:
        return f"C core not found at {looked}"
    if os.environ.get("DYADFMU_LIB"):
        return f"C core not found at $DYADFMU_LIB={looked}: point DYADFMU_LIB at libdyadfmu.so"
    if paths.in_checkout():
        how = "build it: cmake -S . -B build && cmake --build build (or pip install ./scripts)"
    else:
        how = "this installed dyadfmu lacks its bundled core: reinstall it, or set DYADFMU_LIB"
    return f"C core (libdyadfmu.so) not found; looked for {looked}: {how}"


class Core:
    """The double-precision C core. ``Core().solve(...)`` mirrors ``reference.solve_mp``
    for one configuration and adds ``status``, ``field``, ``conditioning``,
    ``amplification`` and ``denominator``."""

    def __init__(self, path: os.PathLike | str | None = None):
        tried = [Path(path)] if path else library_candidates()
        found = next((p for p in tried if p.is_file()), None)
        if found is None:
            raise FileNotFoundError(_missing_library(tried, given=bool(path)))
        self._lib = ctypes.CDLL(str(found))
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
        self._lib.dyad_solve_batch.argtypes = [
            ctypes.c_int,
            ctypes.c_size_t,
            ctypes.POINTER(BatchInput),
            ctypes.POINTER(BatchOutput),
        ]
        self._lib.dyad_solve_batch.restype = ctypes.c_size_t
        self._lib.dyad_angle_cos_sin.argtypes = [
            ctypes.c_double,
            ctypes.POINTER(ctypes.c_double),
            ctypes.POINTER(ctypes.c_double),
        ]
        self._lib.dyad_angle_cos_sin.restype = None
        self._bind_kinematics()

    def _bind_kinematics(self) -> None:
        lib = self._lib
        lib.dyad_kin_input_default.restype = _KinInput
        lib.dyad_kinematics.argtypes = [
            ctypes.c_int,
            ctypes.POINTER(_KinInput),
            ctypes.POINTER(_KinResult),
        ]
        lib.dyad_kinematics.restype = ctypes.c_int
        lib.dyad_kinematics_tangent.argtypes = [
            ctypes.c_int,
            ctypes.POINTER(_KinInput),
            ctypes.POINTER(_KinInput),
            ctypes.POINTER(_KinResult),
            ctypes.POINTER(_KinResult),
        ]
        lib.dyad_kinematics_tangent.restype = ctypes.c_int
        for name in ("dyad_kin_field_name", "dyad_kin_failure_name"):
            getattr(lib, name).argtypes = [ctypes.c_int]
            getattr(lib, name).restype = ctypes.c_char_p

    @staticmethod
    def _fill_link(dst: _Link, src: dict, name: str) -> None:
        unknown = sorted(set(src) - set(LINK_KEYS), key=str)
        missing = [key for key in LINK_KEYS if key not in src]
        if unknown or missing:
            wrong = [f"unknown keys {unknown}"] if unknown else []
            wrong += [f"missing keys {missing}"] if missing else []
            raise ValueError(
                f"link {name}: {' and '.join(wrong)} (a link has exactly {', '.join(LINK_KEYS)})"
            )
        for key in LINK_KEYS:
            value = src[key]
            if key in ("dir", "accel_d", "com", "force"):
                setattr(dst, key, _vec2(f"{name}[{key!r}]", value))
            else:
                setattr(dst, key, _real(f"{name}[{key!r}]", value))

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
        self._fill_link(inp.m, m, "m")
        self._fill_link(inp.n, n, "n")
        if guide_k is not None:
            inp.guide_k = _vec2("guide_k", guide_k)
        if guide_p is not None:
            inp.guide_p = _vec2("guide_p", guide_p)
        inp.gravity = _vec2("gravity", gravity)
        if singular_threshold is not None:
            inp.singular_threshold = _real("singular_threshold", singular_threshold)
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
        index = type_index(dyad_type)
        inp = self._input(m, n, guide_k, guide_p, gravity, singular_threshold)
        res = _Result()
        self._lib.dyad_solve(index, ctypes.byref(inp), ctypes.byref(res))
        return self._output(res)

    def solve_batch(
        self, dyad_type: str, count: int, columns: BatchInput, results: BatchOutput
    ) -> int:
        """dyad_solve_batch on columns the caller holds alive: `count` rows solved in one
        call; returns how many have status ok. ``dyadfmu.solve`` builds the columns from
        NumPy arrays."""
        index = type_index(dyad_type)
        return self._lib.dyad_solve_batch(
            index, count, ctypes.byref(columns), ctypes.byref(results)
        )

    def direction(self, angle: float) -> tuple[float, float]:
        """(cos, sin) of `angle` (rad) as the FMUs convert a link angle."""
        c, s = ctypes.c_double(), ctypes.c_double()
        self._lib.dyad_angle_cos_sin(float(angle), ctypes.byref(c), ctypes.byref(s))
        return c.value, s.value

    def field_name(self, field: int) -> str:
        """The dotted name of a dyad_field ("link_m.mass", ...); "" for none."""
        return self._lib.dyad_field_name(int(field)).decode()

    def solve_tangent(
        self, dyad_type: str, inputs: tuple, seeds: tuple, singular_threshold: float | None = None
    ) -> tuple[dict, dict]:
        """The reactions and their directional derivative. `inputs` and `seeds` are
        (m, n, guide_k, guide_p, gravity) tuples of the same form as solve's
        arguments; a seed direction is the derivative of the unit vector."""
        index = type_index(dyad_type)
        zero = (0.0, 0.0)
        inp = self._input(*inputs, singular_threshold=singular_threshold)
        sm, sn, sk, sp, sg = seeds
        seed = self._input(
            sm, sn, sk if sk is not None else zero, sp if sp is not None else zero, sg
        )
        value, derivative = _Result(), _Result()
        self._lib.dyad_solve_tangent(
            index,
            ctypes.byref(inp),
            ctypes.byref(seed),
            ctypes.byref(value),
            ctypes.byref(derivative),
        )
        return self._output(value), self._output(derivative)

    # ---- kinematics (dyadfmu/kinematics.h) ------------------------------------------------

    def _kin_output(self, res: _KinResult, rate_of: _KinResult | None = None) -> dict:
        """A result as a dict. With `rate_of` (the value of a tangent), `res` holds rates and
        each link's "angle" is the angle's rate, dir x d(dir); else atan2 of dir."""

        def angle(link: str) -> float:
            d = getattr(res, link).dir
            if rate_of is None:
                return math.atan2(d.y, d.x)
            v = getattr(rate_of, link).dir
            return v.x * d.y - v.y * d.x

        return {
            "status": STATUS.get(res.status, "?"),
            "field": self._lib.dyad_kin_field_name(res.field).decode(),
            "failure": self._lib.dyad_kin_failure_name(res.failure).decode(),
            "gap": res.gap,
            "m": _kin_link(res.m, angle("m")),
            "n": _kin_link(res.n, angle("n")),
            "e": _point_motion(res.e),
            "slide_k": {key: getattr(res.slide_k, key) for key in ("s", "rate", "accel")},
            "slide_p": {key: getattr(res.slide_p, key) for key in ("s", "rate", "accel")},
            "conditioning": res.conditioning,
            "closure": res.closure,
            "amplification": res.amplification,
        }

    def kin_input(self, inputs: dict, base: _KinInput | None = None) -> _KinInput:
        """The C input of a kinematics dict: `base` (default dyad_kin_input_default())
        with the keys of `inputs` written over it."""
        inp = base if base is not None else self._lib.dyad_kin_input_default()
        _fill_kin_input(inp, inputs)
        return inp

    def kinematics(self, dyad_type: str, inputs: dict) -> dict:
        """The closed-form kinematics of one dyad: status, field and failure names, gap,
        links m and n (dir, angle, omega, epsilon, length with its rates, D_g and centre of
        mass with position, velocity, acceleration), E, the slides, conditioning and
        amplification. Units as in kinematics.h (m, s, rad)."""
        index = type_index(dyad_type)
        inp = self.kin_input(inputs)
        res = _KinResult()
        self._lib.dyad_kinematics(index, ctypes.byref(inp), ctypes.byref(res))
        return self._kin_output(res)

    def kinematics_tangent(self, dyad_type: str, inputs: dict, seed: dict) -> tuple[dict, dict]:
        """The kinematics and their exact directional derivative along `seed`, a dict of the
        same shape as `inputs` holding each field's rate (missing keys: 0; a unit vector's
        rate counts by its part normal to it). Returns (value, derivative)."""
        index = type_index(dyad_type)
        inp = self.kin_input(inputs)
        rate = self.kin_input(seed, base=_KinInput())
        value, derivative = _KinResult(), _KinResult()
        self._lib.dyad_kinematics_tangent(
            index,
            ctypes.byref(inp),
            ctypes.byref(rate),
            ctypes.byref(value),
            ctypes.byref(derivative),
        )
        return self._kin_output(value), self._kin_output(derivative, rate_of=value)

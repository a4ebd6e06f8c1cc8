"""Independent high-precision reference for the kinematics of planar Assur dyads (mpmath).

Derived from first principles, without any closed-form dyad formula: for every type the
closure of the dyad is written as two scalar equations in two unknowns q,

    Phi(q, t) = D_m(q, t) + l_m(q) i_m(q, t) - D_n(q, t) - l_n i_n(q, t) = 0,

q(0) is found by a coarse multi-start Newton search in floats, polished by
``mpmath.findroot`` and chosen by the branch rule; the time derivatives come from the
implicit differentiation of Phi (q' = -J^-1 Phi_t, then q'' from the second total
derivative), every partial derivative taken with ``mpmath.diff``.  A second, independent
route (``method="findroot"``) solves the closure at the step points of ``mpmath.diff``.

Near an assembly limit of RRR, RRT or RTR (the squared distance between the two roots
below 1e-6 of the figure's, where a float search cannot tell them apart and mistakes near
misses for roots) the roots are started instead from the figure's intersection (circle
with circle, line with circle) at the working precision, then polished the same way (a
start only: the roots are still the closure's): a negative discriminant means no real
root, a zero one a double root (a dead point).  TRT
and RTT within a sine of 0.5 of parallel guides (or slot and guide), whose root runs
beyond the float search's steps, start from their closure solved as the linear system it
is.  Elsewhere the float search's roots are kept.

Conventions (SI units: m, s, rad)
---------------------------------
* Angles counter-clockwise from +x; perp(v) = (-v.y, v.x); cross(a, b) = a.x b.y - a.y b.x.
* Links m and n, pairs D_m (m-k), E (m-n), D_n (n-p); i_g is the unit vector of link g
  from D_g towards E, j_g = perp(i_g); E = D_m + l_m i_m = D_n + l_n i_n.
* A turn (``turn_m``, ``turn_n``, a guide's ``direction``) is an angle or a vector (its
  angle is used, its length is not).  Composing a turn with a unit vector adds angles.
* Unknowns q per type (:data:`UNKNOWNS`):

  RRR  (angle_m, angle_n)  D_m, D_n pins, l_m, l_n constant
  RRT  (s_k, angle_n)      D_m = G_k + s_k i_k, angle_m = angle_k + turn_m, D_n pin
  RTR  (angle_m, l_m)      D_m, D_n pins, angle_n = angle_m + turn_n, l_m > 0
  TRT  (s_k, s_p)          D_m = G_k + s_k i_k, D_n = G_p + s_p i_p, angle_m = angle_k +
                           turn_m, angle_n = angle_p + turn_n
  RTT  (s_k, l_m)          D_m = G_k + s_k i_k, angle_m = angle_k + turn_m,
                           angle_n = angle_m + turn_n, D_n pin

* Branch: RRR +1 puts E left of the directed line D_m -> D_n (-1 right); RRT +1 is the
  larger s_k, -1 the smaller; RTR +1 the larger l_m, -1 the smaller (which must still be
  > 0); TRT and RTT have one solution (for RTT l_m is reported with its sign: negative
  puts E behind D_m on the line of m).
* A mount moves within the window as point(t) = p + v t + a t^2/2, its guide angle as
  theta0 + omega t + epsilon t^2/2; all outputs are at t = 0.

Outputs of :func:`solve` (mpf, vectors as (x, y) tuples)
---------------------------------------------------------
``status`` ("ok", :data:`CANNOT_ASSEMBLE` or :data:`SINGULAR`, the latter two with a
``reason`` and no numbers), ``type``, ``branch``, ``residual`` (|Phi|),
``i_m``, ``i_n``, ``angle_m``, ``angle_n`` (in (-pi, pi]), ``omega_m``, ``omega_n``,
``epsilon_m``, ``epsilon_n``, ``l_m``, ``l_m_dot``, ``l_m_ddot`` (zero rates when l_m is
constant), ``l_n``, ``s_k``, ``s_k_dot``, ``s_k_ddot`` (RRT, TRT, RTT), ``s_p``,
``s_p_dot``, ``s_p_ddot`` (TRT), and ``<point>.position``, ``<point>.velocity``,
``<point>.acceleration`` for the points (:data:`POINTS`) ``m.d`` (m's point at D_m),
``n.d`` (n's point at D_n), ``e`` (n's point at E), ``m.s`` and ``n.s`` (centres of mass
S_g = D_g + com_g.x i_g + com_g.y j_g).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import mpmath
from mpmath import mpf

__all__ = [
    "CANNOT_ASSEMBLE",
    "POINTS",
    "SINGULAR",
    "SEED_KEYS",
    "TYPES",
    "UNKNOWNS",
    "DyadInputs",
    "Mount",
    "as_floats",
    "configuration",
    "derivative",
    "solve",
]

Real = float | int | mpf
Vec = tuple[Real, Real]
Angle = Real | Vec

#: The dyad types, pairs at (D_m, E, D_n).
TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
#: The status of a dyad whose closure has no real solution on the requested branch.
CANNOT_ASSEMBLE = "cannot assemble"
#: The status of an assembled dyad at a dead point (singular closure Jacobian).
SINGULAR = "singular"
#: The points whose position, velocity and acceleration are output.
POINTS = ("m.d", "n.d", "e", "m.s", "n.s")
#: The two unknowns of the closure of each type.
UNKNOWNS = {
    "RRR": ("angle_m", "angle_n"),
    "RRT": ("s_k", "angle_n"),
    "RTR": ("angle_m", "l_m"),
    "TRT": ("s_k", "s_p"),
    "RTT": ("s_k", "l_m"),
}
_MOUNT_FIELDS = ("position", "velocity", "acceleration", "direction", "omega", "epsilon")
#: The input fields a seed of :func:`derivative` may carry a rate for.
SEED_KEYS = tuple(f"{g}.{f}" for g in "kp" for f in _MOUNT_FIELDS) + (
    "length_m",
    "length_n",
    "turn_m",
    "turn_n",
    "com_m",
    "com_n",
)
_GUARD = 10  # decimal digits carried beyond the requested dps
_MP = (mpmath.cos, mpmath.sin)
_FLOAT = (math.cos, math.sin)
_ANGLE_STARTS = tuple(2 * math.pi * (j + 0.37) / 12 for j in range(12))
_LINEAR_STARTS = (-2.0, -1.0, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0, 2.0)


@dataclass(frozen=True)
class Mount:
    """Motion of an external link at the dyad: pin or guide point, and guide if sliding."""

    position: Vec
    velocity: Vec = (0, 0)
    acceleration: Vec = (0, 0)
    direction: Angle = (1, 0)
    omega: Real = 0
    epsilon: Real = 0


@dataclass(frozen=True)
class DyadInputs:
    """Inputs of one dyad: type, mounts k and p, lengths, turns, centres of mass, branch."""

    type: str
    k: Mount
    p: Mount
    length_m: Real = 0
    length_n: Real = 0
    turn_m: Angle = 0
    turn_n: Angle = 0
    com_m: Vec = (0, 0)
    com_n: Vec = (0, 0)
    branch: int = 1


class _Layout(NamedTuple):
    """Where each quantity of the figure comes from: an index into q, or None / a rule."""

    s_k: int | None  # D_m slides on k's guide (index of s_k) or is k's pin (None)
    s_p: int | None
    angle_m: int | None  # index, or None: angle of k's guide + turn_m
    angle_n: int | str  # index, "m": angle_m + turn_n, "p": angle of p's guide + turn_n
    l_m: int | None  # index, or None: the constant length_m


_LAYOUT = {
    "RRR": _Layout(None, None, 0, 1, None),
    "RRT": _Layout(0, None, None, 1, None),
    "RTR": _Layout(None, None, 0, "m", 1),
    "TRT": _Layout(0, 1, None, "p", None),
    "RTT": _Layout(0, None, None, "m", 1),
}


class _Model(NamedTuple):
    """The inputs as numbers of one kind (mpf or float), turns and guides as angles."""

    type: str
    k: tuple  # (position, velocity, acceleration, angle, omega, epsilon)
    p: tuple
    length_m: Real
    length_n: Real
    turn_m: Real
    turn_n: Real
    com_m: Vec
    com_n: Vec
    branch: int


class _Config(NamedTuple):
    """The figure at one time: pair points, link angles and lengths, slides."""

    d_m: Vec
    d_n: Vec
    angle_m: Real
    angle_n: Real
    l_m: Real
    l_n: Real
    s_k: Real | None
    s_p: Real | None


# ---------------------------------------------------------------------------
# inputs
# ---------------------------------------------------------------------------
def _angle_of(value: Angle) -> mpf:
    """The angle of a turn given as an angle or as a vector."""
    if isinstance(value, tuple | list):
        return mpmath.atan2(mpf(value[1]), mpf(value[0]))
    return mpf(value)


def _angle_rate(value: Angle, rate: Angle) -> mpf:
    """Rate of the angle of a turn whose value moves at ``rate`` (angle or vector rate)."""
    if not isinstance(rate, tuple | list):
        return mpf(rate)
    if not isinstance(value, tuple | list):
        raise ValueError("a vector rate needs a turn given as a vector")
    u = (mpf(value[0]), mpf(value[1]))
    return (u[0] * mpf(rate[1]) - u[1] * mpf(rate[0])) / (u[0] ** 2 + u[1] ** 2)


def _check(inputs: DyadInputs) -> None:
    """Reject an unknown type or branch and lengths the type does not allow."""
    if inputs.type not in TYPES:
        raise ValueError(f"unknown dyad type {inputs.type!r}; expected one of {TYPES}")
    if inputs.branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {inputs.branch!r}")
    lm, ln = mpf(inputs.length_m), mpf(inputs.length_n)
    need_m = {"RRR": lm > 0, "RRT": lm >= 0, "TRT": lm >= 0}.get(inputs.type, True)
    need_n = ln > 0 if inputs.type in ("RRR", "RRT") else ln >= 0
    if not (need_m and need_n):
        raise ValueError(f"lengths l_m={inputs.length_m}, l_n={inputs.length_n} invalid")


def _model(inputs: DyadInputs, seed: dict | None = None, e: Real = 0) -> _Model:
    """The inputs moved by ``e`` times ``seed`` along the seed line, as mpf."""
    seed = seed or {}
    unknown = set(seed) - set(SEED_KEYS)
    if unknown:
        raise ValueError(f"unknown seed keys {sorted(unknown)}; expected some of {SEED_KEYS}")
    e = mpf(e)

    def vec(name: str, value: Vec) -> tuple:
        rate = seed.get(name, (0, 0))
        return tuple(mpf(value[c]) + e * mpf(rate[c]) for c in (0, 1))

    def scalar(name: str, value: Real) -> mpf:
        return mpf(value) + e * mpf(seed.get(name, 0))

    def angle(name: str, value: Angle) -> mpf:
        return _angle_of(value) + e * _angle_rate(value, seed.get(name, 0))

    def mount(g: str, mt: Mount) -> tuple:
        return (
            vec(f"{g}.position", mt.position),
            vec(f"{g}.velocity", mt.velocity),
            vec(f"{g}.acceleration", mt.acceleration),
            angle(f"{g}.direction", mt.direction),
            scalar(f"{g}.omega", mt.omega),
            scalar(f"{g}.epsilon", mt.epsilon),
        )

    return _Model(
        inputs.type,
        mount("k", inputs.k),
        mount("p", inputs.p),
        scalar("length_m", inputs.length_m),
        scalar("length_n", inputs.length_n),
        angle("turn_m", inputs.turn_m),
        angle("turn_n", inputs.turn_n),
        vec("com_m", inputs.com_m),
        vec("com_n", inputs.com_n),
        inputs.branch,
    )


def _floated(x: object) -> object:
    """The same structure with every mpf made a float."""
    if isinstance(x, str | int):
        return x
    if hasattr(x, "_make"):
        return x._make(_floated(v) for v in x)
    if isinstance(x, tuple):
        return tuple(_floated(v) for v in x)
    return float(x)


# ---------------------------------------------------------------------------
# the figure and its closure (backend-neutral: floats with math, mpf with mpmath)
# ---------------------------------------------------------------------------
def _mount_at(mount: tuple, t: Real) -> tuple:
    """Point and guide angle of a mount at time t (second-order Taylor motion)."""
    pos, vel, acc, ang, omega, eps = mount
    point = tuple(pos[c] + vel[c] * t + acc[c] * t * t / 2 for c in (0, 1))
    return point, ang + omega * t + eps * t * t / 2


def _config(model: _Model, q: Sequence, t: Real, trig: tuple) -> _Config:
    """The figure for unknowns q at time t."""
    cos, sin = trig
    lay = _LAYOUT[model.type]
    pk, ak = _mount_at(model.k, t)
    pp, ap = _mount_at(model.p, t)
    s_k = None if lay.s_k is None else q[lay.s_k]
    s_p = None if lay.s_p is None else q[lay.s_p]
    d_m = pk if s_k is None else (pk[0] + s_k * cos(ak), pk[1] + s_k * sin(ak))
    d_n = pp if s_p is None else (pp[0] + s_p * cos(ap), pp[1] + s_p * sin(ap))
    th_m = ak + model.turn_m if lay.angle_m is None else q[lay.angle_m]
    if lay.angle_n == "m":
        th_n = th_m + model.turn_n
    elif lay.angle_n == "p":
        th_n = ap + model.turn_n
    else:
        th_n = q[lay.angle_n]
    l_m = model.length_m if lay.l_m is None else q[lay.l_m]
    return _Config(d_m, d_n, th_m, th_n, l_m, model.length_n, s_k, s_p)


def _closure(cfg: _Config, trig: tuple) -> list:
    """Phi = D_m + l_m i_m - D_n - l_n i_n (two components)."""
    cos, sin = trig
    return [
        cfg.d_m[0] + cfg.l_m * cos(cfg.angle_m) - cfg.d_n[0] - cfg.l_n * cos(cfg.angle_n),
        cfg.d_m[1] + cfg.l_m * sin(cfg.angle_m) - cfg.d_n[1] - cfg.l_n * sin(cfg.angle_n),
    ]


def _phi(model: _Model, q: Sequence, t: Real, trig: tuple = _MP) -> list:
    """The closure residual Phi(q, t)."""
    return _closure(_config(model, q, t, trig), trig)


def _points(model: _Model, cfg: _Config) -> dict:
    """Positions of the output points of a figure (mpf)."""
    cos, sin = _MP
    i_m, i_n = (cos(cfg.angle_m), sin(cfg.angle_m)), (cos(cfg.angle_n), sin(cfg.angle_n))

    def body(d: Vec, i: Vec, local: Vec) -> tuple:
        return tuple(d[c] + local[0] * i[c] + local[1] * (-i[1], i[0])[c] for c in (0, 1))

    return {
        "m.d": cfg.d_m,
        "n.d": cfg.d_n,
        "e": body(cfg.d_n, i_n, (cfg.l_n, 0)),
        "m.s": body(cfg.d_m, i_m, model.com_m),
        "n.s": body(cfg.d_n, i_n, model.com_n),
    }


def _scale(model: _Model, t: Real) -> Real:
    """A length of the size of the figure."""
    pk, _ = _mount_at(model.k, t)
    pp, _ = _mount_at(model.p, t)
    size = math.hypot(pk[0] - pp[0], pk[1] - pp[1]) + abs(model.length_m) + model.length_n
    return size if size > 0 else 1


def _angle_slots(model: _Model) -> set:
    """Indices of the unknowns that are angles."""
    lay = _LAYOUT[model.type]
    return {i for i in (lay.angle_m, lay.angle_n) if isinstance(i, int)}


# ---------------------------------------------------------------------------
# numerical tools
# ---------------------------------------------------------------------------
def _memo(fn: Callable) -> Callable:
    """fn cached by (argument, working precision): mpmath.diff may ask several times."""
    cache = {}

    def call(x: Real) -> object:
        key = (mpf(x), mpmath.mp.prec)
        if key not in cache:
            cache[key] = fn(x)
        return cache[key]

    return call


def _diff_vec(fn: Callable, x: Real, n: int, size: int = 2) -> list:
    """The n-th derivatives at x of the ``size`` components of a vector function (mpmath.diff)."""
    f = _memo(fn)
    return [mpmath.diff(lambda h, c=c: f(h)[c], x, n) for c in range(size)]


def _solve2(a: list, b: Sequence) -> list:
    """Solve the 2x2 system a x = b (Cramer)."""
    det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    return [(b[0] * a[1][1] - a[0][1] * b[1]) / det, (a[0][0] * b[1] - b[0] * a[1][0]) / det]


def _jacobian(model: _Model, q: Sequence, t: Real) -> list:
    """dPhi/dq at (q, t) by mpmath.diff along each unknown."""
    cols = []
    for i in (0, 1):

        def along(h: Real, i: int = i) -> list:
            moved = list(q)
            moved[i] = moved[i] + h
            return _phi(model, moved, t)

        cols.append(_diff_vec(along, 0, 1))
    return [[cols[0][0], cols[1][0]], [cols[0][1], cols[1][1]]]


# ---------------------------------------------------------------------------
# roots of the closure
# ---------------------------------------------------------------------------
def _newton_float(fun: Callable, q: list, scale: float, angles: set) -> list | None:
    """Damped Newton in floats from one start; None when it does not converge."""
    caps = [0.5 if i in angles else 0.5 * scale for i in (0, 1)]
    for _ in range(80):
        f = fun(q)
        cols = []
        for i in (0, 1):
            h = 1e-7 * (1 if i in angles else scale)
            moved = list(q)
            moved[i] += h
            g = fun(moved)
            cols.append(((g[0] - f[0]) / h, (g[1] - f[1]) / h))
        jac = [[cols[0][0], cols[1][0]], [cols[0][1], cols[1][1]]]
        if jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0] == 0:
            return None
        step = _solve2(jac, f)
        if not all(math.isfinite(s) for s in step):
            return None
        damp = min([1.0] + [caps[i] / abs(step[i]) for i in (0, 1) if step[i]])
        q = [q[i] - damp * step[i] for i in (0, 1)]
        if max(abs(s) for s in step) < 1e-13 * scale:
            break
    return q if max(abs(r) for r in fun(q)) < 1e-7 * scale else None


def _same(a: Sequence, b: Sequence, tol: Real, angles: set) -> bool:
    """Whether two unknown vectors are one root (angles modulo 2 pi)."""
    for i in (0, 1):
        d = a[i] - b[i]
        if i in angles:
            d = abs(mpmath.sin(d / 2)) * 2 if isinstance(d, mpf) else abs(math.sin(d / 2)) * 2
        if abs(d) > tol:
            return False
    return True


def _coarse_roots(model: _Model, t: Real) -> list:
    """Float approximations of every root: Newton from a grid of starts."""
    fmodel, ft = _floated(model), float(t)
    angles = _angle_slots(model)
    scale = _scale(fmodel, ft)
    grid = [_ANGLE_STARTS if i in angles else [scale * f for f in _LINEAR_STARTS] for i in (0, 1)]
    roots = []
    for a in grid[0]:
        for b in grid[1]:
            q = _newton_float(lambda q: _phi(fmodel, q, ft, _FLOAT), [a, b], scale, angles)
            if q is not None and not any(_same(q, r, 1e-9 * scale, angles) for r in roots):
                roots.append(q)
    return roots


def _polish(model: _Model, start: Sequence, t: Real) -> list | None:
    """A root polished to the working precision by mpmath.findroot; None if none."""
    t = mpf(t)

    def fun(*q: mpf) -> list:
        return _phi(model, q, t)

    def jac(*q: mpf) -> mpmath.matrix:
        return mpmath.matrix(_jacobian(model, q, t))

    try:
        x = mpmath.findroot(fun, [mpf(s) for s in start], J=jac, maxsteps=60, verify=False)
    except (ZeroDivisionError, ValueError):
        return None
    q = [x[0], x[1]]
    tol = mpf(2) ** (-mpmath.mp.prec + 24) * _scale(model, t)
    return q if max(abs(r) for r in fun(*q)) <= tol else None


def _branch_key(model: _Model, q: Sequence, t: Real) -> Real:
    """The quantity the branch rule orders the roots by."""
    if model.type == "RRR":
        cfg = _config(model, q, t, _MP)
        e = _points(model, cfg)["e"]
        d, r = [cfg.d_n[c] - cfg.d_m[c] for c in (0, 1)], [e[c] - cfg.d_m[c] for c in (0, 1)]
        return d[0] * r[1] - d[1] * r[0]
    lay = _LAYOUT[model.type]
    index = {"RRT": lay.s_k, "RTR": lay.l_m}.get(model.type)
    return mpf(0) if index is None else q[index]


def _is_root(model: _Model, q: Sequence, t: Real) -> bool:
    """Whether q closes the figure to the tolerance of :func:`_polish`, on the scale of the
    figure or of q's lengths where these are larger (a root run far away)."""
    lengths = [abs(q[i]) for i in (0, 1) if i not in _angle_slots(model)]
    tol = mpf(2) ** (-mpmath.mp.prec + 24) * max([mpf(_scale(model, t))] + lengths)
    return max(abs(r) for r in _phi(model, q, t)) <= tol


def _roots(model: _Model, t: Real) -> list:
    """Every distinct real root of the closure at time t, at the working precision."""
    angles = _angle_slots(model)
    tol = mpf(2) ** (-mpmath.mp.prec // 2) * _scale(model, t)
    starts = _near_limit_starts(model, t)
    near = starts is not None
    roots = []
    for start in starts if near else _coarse_roots(model, t):
        q = _polish(model, start, t)
        if q is None and near and _is_root(model, start, t):
            q = list(start)  # a double root, where Newton's step is undefined
        if q is not None and not any(_same(q, r, tol, angles) for r in roots):
            roots.append(q)
    return roots


# ---------------------------------------------------------------------------
# near an assembly limit: the roots from the figure's intersection
# ---------------------------------------------------------------------------
#: Below this squared separation of its two roots (relative to the figure) a dyad is
#: near its assembly limit: its roots are started from the figure's intersection.
_NEAR_LIMIT = 1e-6
#: Below this squared sine between the columns of TRT's and RTT's linear closure, its root
#: is started from the closure solved as the linear system it is: already at a sine of
#: 0.02 the root lies beyond the float search's steps.
_LINEAR_NEAR = 0.25


def _sub(a: Vec, b: Vec) -> tuple:
    return (a[0] - b[0], a[1] - b[1])


def _dot(a: Vec, b: Vec) -> mpf:
    return a[0] * b[0] + a[1] * b[1]


def _cross(a: Vec, b: Vec) -> mpf:
    return a[0] * b[1] - a[1] * b[0]


def _atan2(v: Vec) -> mpf:
    return mpmath.atan2(v[1], v[0])


def _unit(angle: Real) -> tuple:
    return (mpmath.cos(angle), mpmath.sin(angle))


def _split(discriminant: mpf, size: mpf) -> list | None:
    """The two signed square roots of a discriminant (one where it is 0, none where it is
    negative), or None where it is at least _NEAR_LIMIT times ``size``: away from the limit."""
    if size <= 0 or discriminant >= _NEAR_LIMIT * size:
        return None
    if discriminant < 0:
        return []
    root = mpmath.sqrt(discriminant)
    return [root] if root == 0 else [root, -root]


def _rrr_starts(model: _Model, d_m: Vec, d_n: Vec) -> list | None:
    """E on the circles about D_m (radius l_m) and D_n (l_n): E = D_m + (a d + h perp(d)) /
    |d|^2 with d = D_n - D_m, a = (|d|^2 + l_m^2 - l_n^2) / 2 and h^2 = l_m^2 |d|^2 - a^2."""
    lm, ln = model.length_m, model.length_n
    with mpmath.extraprec(mpmath.mp.prec + 64):  # exact on the inputs' digits: 0 is 0
        d = _sub(d_n, d_m)
        dd = _dot(d, d)
        a = (dd + lm * lm - ln * ln) / 2
        disc = lm * lm * dd - a * a
    roots = _split(disc, lm * lm * dd)
    out = []
    for h in roots or []:
        e = tuple(d_m[c] + (a * d[c] + h * (-d[1], d[0])[c]) / dd for c in (0, 1))
        out.append([_atan2(_sub(e, d_m)), _atan2(_sub(e, d_n))])
    return None if roots is None else out


def _rrt_starts(model: _Model, g_k: Vec, ang_k: Real, d_n: Vec) -> list | None:
    """D_m = G_k + s i_k with E = D_m + l_m i_m on the circle about D_n (radius l_n): with
    w = D_n - G_k - l_m i_m, s = w . i_k +- sqrt(l_n^2 - (i_k x w)^2)."""
    i_k, i_m = _unit(ang_k), _unit(ang_k + model.turn_m)
    base = tuple(g_k[c] + model.length_m * i_m[c] for c in (0, 1))
    ln = model.length_n
    with mpmath.extraprec(mpmath.mp.prec + 64):
        w = _sub(d_n, base)
        disc = ln * ln - _cross(i_k, w) ** 2
    roots = _split(disc, ln * ln)
    out = []
    for h in roots or []:
        s = _dot(w, i_k) + h
        e = tuple(base[c] + s * i_k[c] for c in (0, 1))
        out.append([s, _atan2(_sub(e, d_n))])
    return None if roots is None else out


def _rtr_starts(model: _Model, d_m: Vec, d_n: Vec, size: mpf) -> list | None:
    """D_n - D_m = l_m i_m - l_n i_n with i_n = i_m turned by turn_n: |D_n - D_m|^2 =
    (l_m - l_n cos turn_n)^2 + (l_n sin turn_n)^2 gives l_m, the direction of D_n - D_m
    then angle_m."""
    ln, turn = model.length_n, model.turn_n
    c, s = ln * mpmath.cos(turn), ln * mpmath.sin(turn)
    with mpmath.extraprec(mpmath.mp.prec + 64):
        d = _sub(d_n, d_m)
        disc = _dot(d, d) - s * s
    roots = _split(disc, size * size)
    out = []
    for h in roots or []:
        lm = c + h
        out.append([_atan2(d) - mpmath.atan2(-s, lm - c), lm])
    return None if roots is None else out


def _linear_start(model: _Model, pk: Vec, ak: Real, pp: Vec, ap: Real) -> list | None:
    """TRT and RTT, whose closure is linear in q (the angles are fixed): u q[0] + v q[1] = b
    solved by Cramer at the working precision where the sine between u and v is below
    sqrt(_LINEAR_NEAR), the start findroot polishes (the float search's steps do not reach
    a root that runs far away as u and v turn parallel); none where they are parallel."""
    i_k, i_m = _unit(ak), _unit(ak + model.turn_m)
    if model.type == "TRT":  # s_k i_k - s_p i_p = G_p + l_n i_n - G_k - l_m i_m
        i_p = _unit(ap)
        i_n = _unit(ap + model.turn_n)
        u, v = i_k, (-i_p[0], -i_p[1])
        b = tuple(pp[c] + model.length_n * i_n[c] - pk[c] - model.length_m * i_m[c] for c in (0, 1))
    else:  # RTT: s_k i_k + l_m i_m = D_n + l_n i_n - G_k
        i_n = _unit(ak + model.turn_m + model.turn_n)
        u, v = i_k, i_m
        b = tuple(pp[c] + model.length_n * i_n[c] - pk[c] for c in (0, 1))
    det = _cross(u, v)
    if det * det >= _LINEAR_NEAR:
        return None
    return [] if det == 0 else [[_cross(b, v) / det, _cross(u, b) / det]]


def _near_limit_starts(model: _Model, t: Real) -> list | None:
    """The roots' starts of a dyad within a relative _NEAR_LIMIT of its assembly limit
    (RRR, RRT, RTR) or of parallel guides or slot (TRT, RTT); none where it cannot
    assemble; None elsewhere, where the float search finds them."""
    (pk, ak), (pp, ap) = _mount_at(model.k, t), _mount_at(model.p, t)
    if model.type == "RRR":
        return _rrr_starts(model, pk, pp)
    if model.type == "RRT":
        return _rrt_starts(model, pk, ak, pp)
    if model.type == "RTR":
        return _rtr_starts(model, pk, pp, mpf(_scale(model, t)))
    return _linear_start(model, pk, ak, pp, ap)


def _root(model: _Model, t: Real) -> tuple[list | None, str]:
    """The root of the closure on the requested branch, or None and the reason."""
    roots = _roots(model, t)
    if not roots:
        return None, "the closure has no real solution"
    if model.type in ("TRT", "RTT"):
        return roots[0], ""
    ranked = sorted(roots, key=lambda q: _branch_key(model, q, t))
    q = ranked[-1] if model.branch > 0 else ranked[0]
    key = _branch_key(model, q, t)
    tiny = mpf(2) ** (-mpmath.mp.prec // 2) * _scale(model, t) ** 2
    if model.type == "RRR" and key * model.branch < 0 and abs(key) > tiny:
        return None, "no solution on the requested side of D_m D_n"
    if model.type == "RTR" and q[_LAYOUT["RTR"].l_m] <= 0:
        return None, "l_m of the requested branch is not positive"
    return q, ""


# ---------------------------------------------------------------------------
# motion
# ---------------------------------------------------------------------------
def _implicit_motion(model: _Model, q0: list) -> Callable:
    """q(t) = q0 + q1 t + q2 t^2/2 with q1, q2 from the implicit derivatives of Phi."""
    jac = _jacobian(model, q0, 0)
    phi_t = _diff_vec(lambda t: _phi(model, q0, t), 0, 1)
    q1 = _solve2(jac, [-x for x in phi_t])
    # d2/dt2 Phi(q0 + q1 t + q2 t^2/2, t) = J q2 + d2/dt2 Phi(q0 + q1 t, t) = 0 at t = 0
    g2 = _diff_vec(lambda t: _phi(model, [q0[i] + q1[i] * t for i in (0, 1)], t), 0, 2)
    q2 = _solve2(jac, [-x for x in g2])
    return lambda t: [q0[i] + q1[i] * t + q2[i] * t * t / 2 for i in (0, 1)]


def _findroot_motion(model: _Model, q0: list) -> Callable:
    """q(t) by findroot at every t asked (continued from q0)."""

    def q_at(t: Real) -> list:
        q = _polish(model, q0, t)
        if q is None:
            raise RuntimeError(f"findroot lost the root at t = {t}")
        return q

    return _memo(q_at)


def _flat(model: _Model, q: Sequence, t: Real) -> list:
    """The time-dependent outputs as one list: angles, l_m, slides, point coordinates."""
    cfg = _config(model, q, t, _MP)
    values = [cfg.angle_m, cfg.angle_n, cfg.l_m]
    values += [s for s in (cfg.s_k, cfg.s_p) if s is not None]
    for point in _points(model, cfg).values():
        values += list(point)
    return values


def _pack(model: _Model, series: list, residual: mpf) -> dict:
    """The output dict from the series (value, rate, acceleration) of the flat outputs."""
    out = {"status": "ok", "type": model.type, "branch": model.branch, "residual": residual}
    it = iter(series)
    for g in ("m", "n"):
        th, omega, eps = next(it)
        out[f"i_{g}"] = (mpmath.cos(th), mpmath.sin(th))
        out[f"angle_{g}"] = mpmath.atan2(mpmath.sin(th), mpmath.cos(th))
        out[f"omega_{g}"], out[f"epsilon_{g}"] = omega, eps
    out["l_m"], out["l_m_dot"], out["l_m_ddot"] = next(it)
    out["l_n"] = model.length_n
    lay = _LAYOUT[model.type]
    for name, index in (("s_k", lay.s_k), ("s_p", lay.s_p)):
        if index is not None:
            out[name], out[f"{name}_dot"], out[f"{name}_ddot"] = next(it)
    for point in POINTS:
        x, y = next(it), next(it)
        for order, what in enumerate(("position", "velocity", "acceleration")):
            out[f"{point}.{what}"] = (x[order], y[order])
    return out


def _singular(model: _Model, q0: list) -> bool:
    """Whether the columns of dPhi/dq are parallel to within 2^(-prec/3) (a dead point)."""
    jac = _jacobian(model, q0, 0)
    norms = [mpmath.hypot(jac[0][i], jac[1][i]) for i in (0, 1)]
    if min(norms) == 0:
        return True
    sine = (jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]) / (norms[0] * norms[1])
    return abs(sine) < mpf(2) ** (-mpmath.mp.prec // 3)


def _solve_here(model: _Model, method: str) -> dict:
    """:func:`solve` at the working precision."""
    q0, reason = _root(model, 0)
    if q0 is None:
        return {
            "status": CANNOT_ASSEMBLE,
            "type": model.type,
            "branch": model.branch,
            "reason": reason,
        }
    if _singular(model, q0):
        reason = "the closure's Jacobian is singular (dead point): rates undefined"
        return {"status": SINGULAR, "type": model.type, "branch": model.branch, "reason": reason}
    motions = {"implicit": _implicit_motion, "findroot": _findroot_motion}
    if method not in motions:
        raise ValueError(f"unknown method {method!r}; expected one of {sorted(motions)}")
    q_of_t = motions[method](model, q0)

    def flat(t: Real) -> list:
        return _flat(model, q_of_t(t), t)

    values = flat(0)
    rates, accels = _diff_vec(flat, 0, 1, len(values)), _diff_vec(flat, 0, 2, len(values))
    residual = max(abs(r) for r in _phi(model, q0, 0))
    return _pack(model, list(zip(values, rates, accels, strict=True)), residual)


def _rounded(x: object, dps: int) -> object:
    """The same structure with every mpf rounded to dps digits."""
    if isinstance(x, dict):
        return {k: _rounded(v, dps) for k, v in x.items()}
    if isinstance(x, tuple):
        return tuple(_rounded(v, dps) for v in x)
    if isinstance(x, mpf):
        with mpmath.workdps(dps):
            return +x
    return x


# ---------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------
def solve(inputs: DyadInputs, dps: int = 40, method: str = "implicit") -> dict:
    """Positions, velocities and accelerations of the dyad at t = 0 (see module doc).

    ``method="implicit"`` differentiates the closure implicitly; ``"findroot"`` solves it
    by findroot at the step points of mpmath.diff (slower, independent).
    """
    _check(inputs)
    with mpmath.workdps(dps + _GUARD):
        result = _solve_here(_model(inputs), method)
    return _rounded(result, dps)


def configuration(inputs: DyadInputs, t: Real = 0, dps: int = 40) -> dict:
    """The figure at time t (closure solved by findroot, branch rule): positions only."""
    _check(inputs)
    with mpmath.workdps(dps + _GUARD):
        model, t = _model(inputs), mpf(t)
        q, reason = _root(model, t)
        if q is None:
            return {"status": CANNOT_ASSEMBLE, "reason": reason}
        cfg = _config(model, q, t, _MP)
        out = {"status": "ok", "angle_m": cfg.angle_m, "angle_n": cfg.angle_n, "l_m": cfg.l_m}
        out.update(
            {name: getattr(cfg, name) for name in ("s_k", "s_p") if getattr(cfg, name) is not None}
        )
        out.update({f"{k}.position": v for k, v in _points(model, cfg).items()})
        out["residual"] = max(abs(r) for r in _phi(model, q, t))
    return _rounded(out, dps)


def _numeric_keys(result: dict) -> list:
    """(key, component) of every number of a result: scalars (key, None)."""
    slots = []
    for key, value in result.items():
        if isinstance(value, tuple):
            slots += [(key, c) for c in range(len(value))]
        elif isinstance(value, mpf):
            slots.append((key, None))
    return slots


def derivative(inputs: DyadInputs, seed: dict, dps: int = 40) -> dict:
    """Directional derivative of every output of :func:`solve` along a seed of the inputs.

    ``seed`` maps keys of :data:`SEED_KEYS` to rates (vectors as (x, y); a turn or guide
    direction as an angle rate, or as a vector rate when the input is a vector).
    """
    _check(inputs)
    with mpmath.workdps(dps + _GUARD):
        base = _solve_here(_model(inputs, seed), "implicit")
        if base["status"] != "ok":
            return base
        slots = [s for s in _numeric_keys(base) if s[0] != "residual"]

        def along(e: Real) -> list:
            moved = _solve_here(_model(inputs, seed, e), "implicit")
            if moved["status"] != "ok":
                raise ValueError(f"the dyad cannot assemble along the seed line (at {e})")
            return [moved[k] if c is None else moved[k][c] for k, c in slots]

        rates = _diff_vec(along, 0, 1, len(slots))
    out = {"status": "ok", "type": inputs.type, "branch": inputs.branch}
    for (key, c), rate in zip(slots, rates, strict=True):
        if c is None:
            out[key] = rate
        else:
            out[key] = out.get(key, ()) + (rate,)
    return _rounded(out, dps)


def as_floats(result: dict) -> dict:
    """A result with every mpf made a float (vectors stay tuples)."""
    return {
        k: tuple(float(c) for c in v)
        if isinstance(v, tuple)
        else (float(v) if isinstance(v, mpf) else v)
        for k, v in result.items()
    }

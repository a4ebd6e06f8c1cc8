"""Independent Newton-Euler reference for the joint reactions of planar Assur dyads.

Derived from first principles: d'Alembert equilibrium (force x, force y, moment)
of each of the two links, assembled as a 6x6 linear system in the six unknown
reaction components and solved numerically -- no closed-form dyad formulas.

Conventions (SI units throughout: m, s, kg, N, N m, rad)
--------------------------------------------------------
* Plane with global axes x, y; z out of the plane.  Moments and angular
  quantities are scalar z-components, counter-clockwise positive.
  ``cross(a, b) = a.x*b.y - a.y*b.x`` and ``rot90(v) = (-v.y, v.x)``.
* Links m and n; pairs D_m (m-k), E (m-n), D_n (n-p).  Pair kinds per type are
  in :data:`PAIRS` (order D_m, E, D_n).  R transmits a force only; T transmits
  a force normal to its guide plus a reactive moment.  Guides: D_m -> guide_k,
  D_n -> guide_p, E -> dir_m.  A guide's normal is ``j = rot90(i)``.
* Link dict keys (g in {m, n}):

  ``dir``      unit vector i_g from D_g towards E (not renormalised) [-]
  ``length``   l_g >= 0, E = D_g + l_g i_g                        [m]
  ``omega``    angular velocity                                   [rad/s]
  ``epsilon``  angular acceleration                               [rad/s^2]
  ``accel_d``  absolute acceleration of D_g (global)              [m/s^2]
  ``com``      (x_S, y_S) in link frame, S = D + x_S i + y_S j     [m]
  ``mass``     mass                                               [kg]
  ``inertia``  moment of inertia about S                          [kg m^2]
  ``force``    active load force at S (global)                    [N]
  ``moment``   active load moment                                 [N m]

  a_S = a_D + epsilon rot90(r) - omega^2 r with r = S - D; inertia force
  -mass a_S at S, inertia moment -inertia epsilon, weight mass*gravity at S.

Unknown vector ``u`` (6 entries), one slot of two per pair
----------------------------------------------------------
  u[0:2]  pair D_m   R: (r_mk.x, r_mk.y)   T: (n_mk, m_mk)
  u[2:4]  pair D_n   R: (r_np.x, r_np.y)   T: (n_np, m_np)
  u[4:6]  pair E     R: (r_mn.x, r_mn.y)   T: (n_mn, m_mn)

For a T pair the force is ``n * j`` (j = normal of its guide) acting at the
pair point, and the moment is the reactive couple.  r_mk acts on m at D_m,
r_np acts on n at D_n, r_mn (and m_mn) act on m at E, their negatives on n.

Equation rows: 0,1,2 = link m (force x, force y, moment about D_m);
3,4,5 = link n (force x, force y, moment about D_n).  ``A u = b`` with ``b``
the negated sum of known loads (active + weight + inertia).
"""

from __future__ import annotations

import numpy as np

try:  # mpmath is needed only by solve_mp
    import mpmath
except ImportError:  # pragma: no cover
    mpmath = None

__all__ = [
    "PAIRS",
    "LINK_KEYS",
    "UNKNOWNS",
    "assemble",
    "equilibrium_system",
    "reactions_of_unknowns",
    "solve",
    "solve_mp",
]

#: Pair kinds (D_m, E, D_n) of each dyad type.
PAIRS = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}

#: Required keys of the link dicts ``m`` and ``n``.
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
_VEC_KEYS = ("dir", "accel_d", "com", "force")

#: Names of the six unknowns per dyad type (ordering of ``u``, see module doc).
UNKNOWNS = {
    t: tuple(
        name
        for pair, kind in zip(("mk", "np", "mn"), (p[0], p[2], p[1]), strict=False)
        for name in ((f"r_{pair}.x", f"r_{pair}.y") if kind == "R" else (f"n_{pair}", f"m_{pair}"))
    )
    for t, p in PAIRS.items()
}


# ---------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------
def _kinds(dyad_type: str, guide_k: np.ndarray | None, guide_p: np.ndarray | None):
    """Return pair kinds (D_m, E, D_n) after validating type and guides."""
    key = dyad_type.upper() if isinstance(dyad_type, str) else dyad_type
    if key not in PAIRS:
        raise ValueError(f"unknown dyad type {dyad_type!r}; expected one of {sorted(PAIRS)}")
    k_dm, k_e, k_dn = PAIRS[key]
    if k_dm == "T" and guide_k is None:
        raise ValueError(f"guide_k is required for dyad type {key} (T pair at D_m)")
    if k_dn == "T" and guide_p is None:
        raise ValueError(f"guide_p is required for dyad type {key} (T pair at D_n)")
    return key, (k_dm, k_e, k_dn)


def _check_link(name: str, link: dict):
    missing = [k for k in LINK_KEYS if k not in link]
    if missing:
        raise ValueError(f"link {name!r} is missing keys {missing}")


# ---------------------------------------------------------------------------
# backend-neutral physics (works on numpy arrays of shape (N,) or mpf scalars)
# vectors are (x, y) tuples of components
# ---------------------------------------------------------------------------
def _rot90(v: np.ndarray):
    return (-v[1], v[0])


def _cross(a: np.ndarray, b: np.ndarray):
    return a[0] * b[1] - a[1] * b[0]


def _known_loads(L: dict, grav: np.ndarray):
    """Resultant known force and its moment about D of one link.

    Sum of active load, weight and d'Alembert inertia force (all at S) and of
    active and inertia moments.  Returns (F, M_about_D).
    """
    i = L["dir"]
    j = _rot90(i)
    xs, ys = L["com"]
    r = (xs * i[0] + ys * j[0], xs * i[1] + ys * j[1])  # S - D
    w2, eps = L["omega"] * L["omega"], L["epsilon"]
    er = _rot90(r)
    a_s = tuple(L["accel_d"][c] + eps * er[c] - w2 * r[c] for c in (0, 1))
    mass = L["mass"]
    F = tuple(L["force"][c] + mass * grav[c] - mass * a_s[c] for c in (0, 1))
    M = L["moment"] - L["inertia"] * eps + _cross(r, F)
    return F, M


def equilibrium_system(
    kinds: tuple, m: dict, n: dict, gk: np.ndarray | None, gp: np.ndarray | None, grav: np.ndarray
) -> tuple[list, list]:
    """Assemble A (6x6 nested list) and b (list of 6) of the dyad equations."""
    A = [[0] * 6 for _ in range(6)]
    k_dm, k_e, k_dn = kinds

    def put_force(col: int, row0: int, sign: float, f: np.ndarray, arm: np.ndarray):
        # force f (per unit unknown) at a point with arm (point - D_link)
        A[row0][col] = A[row0][col] + sign * f[0]
        A[row0 + 1][col] = A[row0 + 1][col] + sign * f[1]
        A[row0 + 2][col] = A[row0 + 2][col] + sign * _cross(arm, f)

    def put_pair(kind: str, col: int, links: tuple, guide: np.ndarray):
        # links: sequence of (row0, sign, arm) the pair acts on
        for row0, sign, arm in links:
            if kind == "R":
                put_force(col, row0, sign, (1, 0), arm)
                put_force(col + 1, row0, sign, (0, 1), arm)
            else:
                put_force(col, row0, sign, _rot90(guide), arm)
                A[row0 + 2][col + 1] = A[row0 + 2][col + 1] + sign

    zero = (0, 0)
    arm_em = tuple(m["length"] * c for c in m["dir"])  # E - D_m
    arm_en = tuple(n["length"] * c for c in n["dir"])  # E - D_n
    put_pair(k_dm, 0, [(0, 1, zero)], gk)
    put_pair(k_dn, 2, [(3, 1, zero)], gp)
    put_pair(k_e, 4, [(0, 1, arm_em), (3, -1, arm_en)], m["dir"])

    Fm, Mm = _known_loads(m, grav)
    Fn, Mn = _known_loads(n, grav)
    b = [-Fm[0], -Fm[1], -Mm, -Fn[0], -Fn[1], -Mn]
    return A, b


def reactions_of_unknowns(
    kinds: tuple,
    u: np.ndarray,
    gk: np.ndarray | None,
    gp: np.ndarray | None,
    dir_m: np.ndarray,
    nan: np.ndarray,
    zero: np.ndarray,
) -> dict:
    """Map the unknown vector u (indexable, 6 entries) to the output dict."""
    out = {}
    for pair, kind, col, guide in (
        ("mk", kinds[0], 0, gk),
        ("np", kinds[2], 2, gp),
        ("mn", kinds[1], 4, dir_m),
    ):
        if kind == "R":
            out[f"r_{pair}"] = (u[col], u[col + 1])
            out[f"m_{pair}"] = zero
            out[f"n_{pair}"] = nan
        else:
            j = _rot90(guide)
            out[f"r_{pair}"] = (u[col] * j[0], u[col] * j[1])
            out[f"m_{pair}"] = u[col + 1]
            out[f"n_{pair}"] = u[col]  # = r . j for a unit guide
    return out


# ---------------------------------------------------------------------------
# numpy backend
# ---------------------------------------------------------------------------
def _np_inputs(
    m: dict,
    n: dict,
    guide_k: np.ndarray | None,
    guide_p: np.ndarray | None,
    gravity: tuple[float, float],
):
    """Convert inputs to component tuples of arrays, broadcast to a batch N."""
    _check_link("m", m)
    _check_link("n", n)
    raw = {}
    for lname, link in (("m", m), ("n", n)):
        for key in LINK_KEYS:
            raw[(lname, key)] = (np.asarray(link[key], dtype=float), key in _VEC_KEYS)
    for name, v in (("guide_k", guide_k), ("guide_p", guide_p), ("gravity", gravity)):
        if v is not None:
            raw[name] = (np.asarray(v, dtype=float), True)
    lead = []
    for name, (arr, is_vec) in raw.items():
        if is_vec:
            if arr.ndim not in (1, 2) or arr.shape[-1] != 2:
                raise ValueError(
                    f"{name}: expected a vector of shape (2,) or (N, 2), got {arr.shape}"
                )
            lead.append(arr.shape[:-1])
        else:
            if arr.ndim > 1:
                raise ValueError(f"{name}: expected a scalar or shape (N,), got {arr.shape}")
            lead.append(arr.shape)
    N = np.broadcast_shapes(*lead, (1,))[0]

    def conv(arr: object, is_vec: bool):
        if is_vec:
            a = np.broadcast_to(arr, (N, 2))
            return (a[:, 0], a[:, 1])
        return np.broadcast_to(arr, (N,))

    links = []
    for lname in ("m", "n"):
        links.append({key: conv(*raw[(lname, key)]) for key in LINK_KEYS})
    gk = conv(*raw["guide_k"]) if "guide_k" in raw else None
    gp = conv(*raw["guide_p"]) if "guide_p" in raw else None
    return N, links[0], links[1], gk, gp, conv(*raw["gravity"])


def assemble(
    dyad_type: str,
    m: dict,
    n: dict,
    guide_k: np.ndarray | None = None,
    guide_p: np.ndarray | None = None,
    gravity: tuple[float, float] = (0.0, 0.0),
) -> tuple:
    """Build the batched Newton-Euler system ``A u = b`` of a dyad.

    Parameters
    ----------
    dyad_type : {"RRR", "RRT", "RTR", "TRT", "RTT"}
    m, n : dict
        Link data with keys :data:`LINK_KEYS` (see module docstring for units).
        Vectors shape (2,) or (N, 2); scalars () or (N,); broadcast together.
    guide_k, guide_p : array_like (2,) or (N, 2), optional
        Unit guide directions of the T pairs at D_m / D_n (required only when
        the type has a T pair there).
    gravity : array_like (2,) or (N, 2)
        Gravitational acceleration [m/s^2].

    Returns
    -------
    A : ndarray (N, 6, 6), b : ndarray (N, 6)
        Rows: link m (Fx, Fy, moment about D_m), link n (Fx, Fy, moment about
        D_n).  Columns: unknown ordering of :data:`UNKNOWNS` [N or N m].
    """
    _, kinds = _kinds(dyad_type, guide_k, guide_p)
    return _assemble_np(kinds, *_np_inputs(m, n, guide_k, guide_p, gravity))


def _assemble_np(
    kinds: tuple,
    N: int,
    mm: dict,
    nn: dict,
    gk: np.ndarray | None,
    gp: np.ndarray | None,
    grav: np.ndarray,
):
    A_l, b_l = equilibrium_system(kinds, mm, nn, gk, gp, grav)
    A = np.empty((N, 6, 6))
    for r in range(6):
        for c in range(6):
            A[:, r, c] = A_l[r][c]
    b = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in b_l], axis=-1)
    return A, b


def solve(
    dyad_type: str,
    m: dict,
    n: dict,
    guide_k: np.ndarray | None = None,
    guide_p: np.ndarray | None = None,
    gravity: tuple[float, float] = (0.0, 0.0),
) -> dict:
    """Solve the dyad reactions for a batch of N configurations (float64).

    Returns a dict with
      ``r_mk, r_np, r_mn``  (N, 2) reaction forces [N] (see module docstring),
      ``m_mk, m_np, m_mn``  (N,)  reactive moments [N m] (0 for R pairs),
      ``n_mk, n_np, n_mn``  (N,)  signed normal forces of T pairs [N] (NaN for R),
      ``u``                 (N, 6) raw unknown vector, ``cond`` (N,) 2-norm
                            condition number of A (inf/NaN results where singular).
    """
    _, kinds = _kinds(dyad_type, guide_k, guide_p)
    N, mm, nn, gk, gp, grav = _np_inputs(m, n, guide_k, guide_p, gravity)
    A, b = _assemble_np(kinds, N, mm, nn, gk, gp, grav)
    try:
        u = np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:  # some sample exactly singular: do one by one
        u = np.full(b.shape, np.nan)
        for s in range(A.shape[0]):
            try:
                u[s] = np.linalg.solve(A[s], b[s])
            except np.linalg.LinAlgError:
                pass
    cols = [u[:, c] for c in range(6)]
    raw = reactions_of_unknowns(kinds, cols, gk, gp, mm["dir"], np.full(N, np.nan), np.zeros(N))
    out = {}
    for k, v in raw.items():
        out[k] = np.stack(v, axis=-1) if k.startswith("r_") else np.asarray(v, dtype=float)
    out["u"] = u
    out["cond"] = np.linalg.cond(A)
    return out


# ---------------------------------------------------------------------------
# mpmath backend
# ---------------------------------------------------------------------------
def _mpf_exact(x: float):
    """Exact conversion of a double (or int) to mpf (mpf(float) is exact)."""
    return mpmath.mpf(float(x))


def solve_mp(
    dyad_type: str,
    m: dict,
    n: dict,
    guide_k: np.ndarray | None = None,
    guide_p: np.ndarray | None = None,
    gravity: tuple[float, float] = (0.0, 0.0),
    dps: int = 50,
) -> dict:
    """High-precision solve of ONE configuration with mpmath (``dps`` digits).

    Inputs are plain floats / length-2 sequences, converted exactly from double
    to mpf; the same system as :func:`assemble` is built in mpmath and solved
    with ``mpmath.lu_solve``.  Returns the keys of :func:`solve` as Python
    floats (vectors as 2-tuples, rounded from the high-precision values, NaN
    for n_* of R pairs), ``u`` (6 floats), ``cond`` (2-norm condition number of
    the double-rounded A, via numpy) and ``mp``: the same quantities as mpf.
    Raises ``numpy.linalg.LinAlgError`` if A is exactly singular.
    """
    if mpmath is None:  # pragma: no cover
        raise ImportError("solve_mp requires mpmath")
    key, kinds = _kinds(dyad_type, guide_k, guide_p)
    _check_link("m", m)
    _check_link("n", n)

    def vec(v: np.ndarray, name: str):
        v = tuple(v)
        if len(v) != 2:
            raise ValueError(f"{name}: expected a length-2 vector")
        return (_mpf_exact(v[0]), _mpf_exact(v[1]))

    with mpmath.workdps(dps):
        links = [
            {k: (vec(L[k], k) if k in _VEC_KEYS else _mpf_exact(L[k])) for k in LINK_KEYS}
            for L in (m, n)
        ]
        gk = vec(guide_k, "guide_k") if guide_k is not None else None
        gp = vec(guide_p, "guide_p") if guide_p is not None else None
        A_l, b_l = equilibrium_system(kinds, links[0], links[1], gk, gp, vec(gravity, "gravity"))
        A = mpmath.matrix([[mpmath.mpf(x) for x in row] for row in A_l])
        try:
            u = mpmath.lu_solve(A, mpmath.matrix([mpmath.mpf(x) for x in b_l]))
        except ZeroDivisionError as exc:
            raise np.linalg.LinAlgError(f"singular {key} dyad configuration") from exc
        u = [u[c] for c in range(6)]
        mp_out = reactions_of_unknowns(kinds, u, gk, gp, links[0]["dir"], mpmath.nan, mpmath.mpf(0))
        A_float = np.array([[float(x) for x in row] for row in A_l])

    out = {}
    for k, v in mp_out.items():
        out[k] = tuple(float(c) for c in v) if k.startswith("r_") else float(v)
    out["u"] = [float(x) for x in u]
    out["cond"] = float(np.linalg.cond(A_float))
    mp_out["u"] = u
    out["mp"] = mp_out
    return out

"""Tests of the independent Newton-Euler dyad reference
(scripts/dyadfmu/reference/newton_euler.py)."""

import math

import numpy as np
import pytest
from dyadfmu.reference import newton_euler as ref

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
# pair kinds (D_m, E, D_n) written out independently of ref.PAIRS
KINDS = {
    "RRR": ("R", "R", "R"),
    "RRT": ("T", "R", "R"),
    "RTR": ("R", "T", "R"),
    "TRT": ("T", "R", "T"),
    "RTT": ("T", "T", "R"),
}


def rot90(v):
    v = np.asarray(v, dtype=float)
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def link(**kw):
    """Massless, unloaded, non-moving link with overridable fields."""
    d = dict(
        dir=(1.0, 0.0),
        length=1.0,
        omega=0.0,
        epsilon=0.0,
        accel_d=(0.0, 0.0),
        com=(0.0, 0.0),
        mass=0.0,
        inertia=0.0,
        force=(0.0, 0.0),
        moment=0.0,
    )
    d.update(kw)
    return d


# ---------------------------------------------------------------------------
# hand cases
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("solver", ["np", "mp"])
def test_symmetric_static_rrr_three_hinged_arch(solver):
    # D_m=(-a,0), D_n=(a,0), E=(0,h); massless links, -P/2 vertical at E on
    # each link (com=(l,0) puts S at E).  Each link is a two-force member, so
    # r_mk is along i_m; symmetry gives r_mk.y = r_np.y = P/2, hence
    # r_mk = P/(2 sin(alpha)) i_m with sin(alpha) = h/l.  The coefficient is
    # positive: the support pushes the link towards E (the arch is in
    # compression).  The pin force on m from n is then a pure horizontal thrust
    # r_mn = -r_mk - (0,-P/2) = (-P/(2 tan(alpha)), 0): n pushes m to the left.
    a, h, P = 0.7, 0.4, 250.0
    length = math.hypot(a, h)
    i_m = np.array([a, h]) / length
    i_n = np.array([-a, h]) / length
    m = link(dir=i_m, length=length, com=(length, 0.0), force=(0.0, -P / 2))
    n = link(dir=i_n, length=length, com=(length, 0.0), force=(0.0, -P / 2))
    res = _run(solver, "RRR", m, n)
    sin_a, tan_a = h / length, h / a
    np.testing.assert_allclose(res["r_mk"], P / (2 * sin_a) * i_m, rtol=1e-13)
    np.testing.assert_allclose(res["r_np"], P / (2 * sin_a) * i_n, rtol=1e-13)
    np.testing.assert_allclose(res["r_mn"], [-P / (2 * tan_a), 0.0], rtol=1e-13, atol=1e-12)
    for k in ("m_mk", "m_np", "m_mn"):
        assert res[k] == 0.0
    for k in ("n_mk", "n_np", "n_mn"):
        assert math.isnan(res[k])


@pytest.mark.parametrize("phi_deg", [20.0, -35.0])
@pytest.mark.parametrize("solver", ["np", "mp"])
def test_rrt_slider_crank_static(solver, phi_deg):
    # Link m = slider (T pair at D_m on the horizontal guide_k=(1,0), l_m=0,
    # dir_m=guide_k, com at D_m), link n = massless connecting rod from the
    # crank pin D_n to the slider pin E, inclined at phi to the guide:
    # D_n = E - l_n i_n with i_n = (cos phi, -sin phi) (for phi>0 the crank pin
    # lies up-left of the slider).  Load on the slider: (-P, 0).
    # Rod = two-force member -> r_mn = F i_n.  Slider, x: -P + F cos(phi) = 0
    # -> F = P/cos(phi) > 0: the rod pushes the slider along i_n (rod in
    # compression).  Slider, y: n_mk + r_mn.y = n_mk - F sin(phi) = 0 ->
    # n_mk = +P tan(phi) (normal j_k = (0,1): for phi>0 the rod presses the
    # slider down and the guide pushes up).  All slider forces act at one
    # point and no moment is applied, so m_mk = 0.  Rod: r_np = r_mn.
    P, l_n = 120.0, 0.3
    phi = math.radians(phi_deg)
    i_n = np.array([math.cos(phi), -math.sin(phi)])
    m = link(dir=(1.0, 0.0), length=0.0, com=(0.0, 0.0), force=(-P, 0.0))
    n = link(dir=i_n, length=l_n, com=(0.5 * l_n, 0.0))
    res = _run(solver, "RRT", m, n, guide_k=(1.0, 0.0))
    F = P / math.cos(phi)
    np.testing.assert_allclose(res["r_mn"], F * i_n, rtol=1e-13)
    assert np.linalg.norm(res["r_mn"]) == pytest.approx(P / math.cos(phi), rel=1e-13)
    assert res["n_mk"] == pytest.approx(P * math.tan(phi), rel=1e-13)
    np.testing.assert_allclose(res["r_mk"], [0.0, P * math.tan(phi)], rtol=1e-13, atol=1e-12)
    assert abs(res["m_mk"]) <= 1e-12 * P
    np.testing.assert_allclose(res["r_np"], F * i_n, rtol=1e-13)
    assert res["m_np"] == 0.0 and res["m_mn"] == 0.0


@pytest.mark.parametrize("solver", ["np", "mp"])
def test_trt_cross_slides_with_mass_gravity_and_acceleration(solver):
    # Link m slides on the horizontal guide_k=(1,0) (normal j_k=(0,1)) and has
    # its point mass M at E = D_m + L (cos th, sin th); link n is a massless
    # slider (l_n=0, D_n=E) on the vertical guide_p=(0,1) (normal j_p=(-1,0)).
    # m translates (omega=eps=0) with a_D = (ax, ay); active force (Fx, Fy) at
    # E on m, active moment M0 on m; gravity (0,-g).
    # Known resultant on m at E: Q = (Fx - M ax, Fy - M g - M ay).
    # Link n: r_np - r_mn = 0 and r_np = n_np (-1, 0) -> r_mn = (-n_np, 0);
    # moment of n about D_n (=E): m_np = 0.
    # Link m, x: Q.x - n_np = 0 -> n_np = Q.x (the p-guide must push the
    #   system in -x by -Q.x, i.e. it supplies M ax to accelerate it).
    # Link m, y: Q.y + n_mk = 0 -> n_mk = -Q.y (guide k carries the weight).
    # Moment about D_m: m_mk + M0 + cross(L i, Q + r_mn) = 0 with
    #   Q + r_mn = (0, Q.y) -> m_mk = -M0 - L cos(th) Q.y.
    L, th, M, g = 0.8, math.radians(50.0), 3.0, 9.81
    ax, ay, Fx, Fy, M0 = 2.0, -0.5, 7.0, 4.0, 1.5
    i_m = np.array([math.cos(th), math.sin(th)])
    m = link(
        dir=i_m,
        length=L,
        com=(L, 0.0),
        mass=M,
        inertia=0.2,
        accel_d=(ax, ay),
        force=(Fx, Fy),
        moment=M0,
    )
    n = link(dir=(0.0, 1.0), length=0.0)
    res = _run(solver, "TRT", m, n, guide_k=(1.0, 0.0), guide_p=(0.0, 1.0), gravity=(0.0, -g))
    Qx, Qy = Fx - M * ax, Fy - M * g - M * ay
    assert res["n_np"] == pytest.approx(Qx, rel=1e-13)
    np.testing.assert_allclose(res["r_np"], [-Qx, 0.0], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(res["r_mn"], [-Qx, 0.0], rtol=1e-13, atol=1e-13)
    assert res["n_mk"] == pytest.approx(-Qy, rel=1e-13)
    np.testing.assert_allclose(res["r_mk"], [0.0, -Qy], rtol=1e-13, atol=1e-13)
    assert res["m_mk"] == pytest.approx(-M0 - L * math.cos(th) * Qy, rel=1e-13)
    assert abs(res["m_np"]) <= 1e-13 and res["m_mn"] == 0.0 and math.isnan(res["n_mn"])


def _run(solver, t, m, n, **kw):
    """Call solve (batch of one, squeezed) or solve_mp with the same inputs."""
    if solver == "mp":
        return ref.solve_mp(t, m, n, **kw)
    out = ref.solve(t, m, n, **kw)
    assert out["cond"].shape == (1,) and np.isfinite(out["cond"][0])
    return {k: (v[0] if k != "u" else v) for k, v in out.items()}


# ---------------------------------------------------------------------------
# random configurations
# ---------------------------------------------------------------------------
def random_case(rng, N, t):
    """Random dyad data; positions are consistent: D_n = D_m + l_m i_m - l_n i_n."""

    def vec(scale=1.0):
        return rng.uniform(-scale, scale, (N, 2))

    def lnk():
        return dict(
            dir=unit(rng.uniform(-np.pi, np.pi, N)),
            length=rng.uniform(0.05, 2.0, N),
            omega=rng.uniform(-20, 20, N),
            epsilon=rng.uniform(-200, 200, N),
            accel_d=vec(50.0),
            com=vec(1.0),
            mass=rng.uniform(0.1, 5.0, N),
            inertia=rng.uniform(1e-3, 0.5, N),
            force=vec(100.0),
            moment=rng.uniform(-50, 50, N),
        )

    kw = dict(
        guide_k=unit(rng.uniform(-np.pi, np.pi, N)) if KINDS[t][0] == "T" else None,
        guide_p=unit(rng.uniform(-np.pi, np.pi, N)) if KINDS[t][2] == "T" else None,
        gravity=vec(10.0),
    )
    return lnk(), lnk(), kw


def balance_residuals(m, n, res, gravity, rng):
    """Independent d'Alembert check of both links, moments about a random point.

    Returns (residual, scale) arrays of shape (N, 6): force x, y, moment for m
    then n; scale = sum of absolute values of the contributing terms.
    """
    N = len(res["m_mk"])
    D_m = rng.uniform(-3, 3, (N, 2))
    Q = rng.uniform(-3, 3, (N, 2))
    E = D_m + m["length"][:, None] * m["dir"]
    D_n = E - n["length"][:, None] * n["dir"]
    # link n sees -r_mn and -m_mn at E
    reac = {
        "m": [(D_m, res["r_mk"], res["m_mk"]), (E, res["r_mn"], res["m_mn"])],
        "n": [(D_n, res["r_np"], res["m_np"]), (E, -res["r_mn"], -res["m_mn"])],
    }
    resid, scale = [], []
    for name, L, D in (("m", m, D_m), ("n", n, D_n)):
        i = L["dir"]
        S = D + L["com"][:, :1] * i + L["com"][:, 1:] * rot90(i)
        r = S - D
        a_S = L["accel_d"] + L["epsilon"][:, None] * rot90(r) - (L["omega"] ** 2)[:, None] * r
        forces = [
            (S, L["force"]),
            (S, L["mass"][:, None] * gravity),
            (S, -L["mass"][:, None] * a_S),
        ] + [(P, f) for P, f, _ in reac[name]]
        couples = [L["moment"], -L["inertia"] * L["epsilon"]] + [c for _, _, c in reac[name]]
        fsum = sum(f for _, f in forces)
        fabs = sum(np.abs(f) for _, f in forces)
        mterms = [cross(P - Q, f) for P, f in forces] + couples
        resid += [fsum[:, 0], fsum[:, 1], sum(mterms)]
        scale += [fabs[:, 0], fabs[:, 1], sum(np.abs(x) for x in mterms)]
    return np.stack(resid, -1), np.stack(scale, -1)


@pytest.mark.parametrize("t", TYPES)
def test_random_solution_satisfies_balance_and_pair_constraints(t):
    rng = np.random.default_rng(11 + TYPES.index(t))
    N = 400
    m, n, kw = random_case(rng, N, t)
    res = ref.solve(t, m, n, **kw)
    assert res["r_mk"].shape == (N, 2) and res["m_np"].shape == (N,) and res["cond"].shape == (N,)
    ok = res["cond"] < 1e8  # drop near-singular configurations
    assert ok.mean() > 0.9
    resid, scale = balance_residuals(m, n, res, kw["gravity"], rng)
    rel = np.abs(resid[ok]) / scale[ok]
    assert rel.max() < 1e-12, rel.max()
    # pair-kind constraints
    kinds = dict(zip(("mk", "mn", "np"), KINDS[t], strict=True))
    guides = {"mk": kw["guide_k"], "np": kw["guide_p"], "mn": m["dir"]}
    for pair, kind in kinds.items():
        r = res[f"r_{pair}"]
        if kind == "R":
            assert np.all(res[f"m_{pair}"] == 0.0) and np.all(np.isnan(res[f"n_{pair}"]))
        else:
            g = guides[pair]
            # force normal to the guide, n = r . rot90(guide)
            np.testing.assert_allclose(np.sum(r * g, -1)[ok], 0.0, atol=1e-12 * np.abs(r).max())
            np.testing.assert_allclose(
                np.sum(r * rot90(g), -1)[ok],
                res[f"n_{pair}"][ok],
                rtol=1e-13,
                atol=1e-13 * np.abs(r).max(),
            )


@pytest.mark.parametrize("t", TYPES)
def test_random_solve_matches_solve_mp(t):
    rng = np.random.default_rng(100 + TYPES.index(t))
    N = 40
    m, n, kw = random_case(rng, N, t)
    res = ref.solve(t, m, n, **kw)
    checked = 0
    for s in range(N):
        if res["cond"][s] > 1e6:
            continue

        def pick(d, s=s):
            return {k: (v[s] if np.ndim(v) else v) for k, v in d.items()}

        kws = {k: (None if v is None else v[s]) for k, v in kw.items()}
        mp = ref.solve_mp(t, pick(m), pick(n), **kws)
        # normwise over all reactions of the sample (forces and moments in one scale)
        vals_np = np.concatenate(
            [np.ravel(res[k][s]) for k in ("r_mk", "r_np", "r_mn", "m_mk", "m_np", "m_mn")]
        )
        vals_mp = np.concatenate(
            [np.ravel(mp[k]) for k in ("r_mk", "r_np", "r_mn", "m_mk", "m_np", "m_mn")]
        )
        sc = np.abs(vals_mp).max()
        assert np.abs(vals_np - vals_mp).max() <= 1e-12 * sc
        np.testing.assert_array_equal(np.isnan(res["n_mk"][s]), math.isnan(mp["n_mk"]))
        # float outputs are the rounded high-precision values
        assert mp["m_mk"] == float(mp["mp"]["m_mk"])
        checked += 1
    assert checked >= 0.8 * N


def test_solve_mp_uses_high_precision():
    # exact double inputs: mp result must be closer to the 80-digit one than
    # the double solve is allowed to be, i.e. agree to full double rounding
    rng = np.random.default_rng(7)
    m, n, kw = random_case(rng, 1, "RRR")
    pick = lambda d: {k: (v[0] if np.ndim(v) else v) for k, v in d.items()}  # noqa: E731
    kw1 = {k: (None if v is None else v[0]) for k, v in kw.items()}
    a = ref.solve_mp("RRR", pick(m), pick(n), dps=50, **kw1)
    b = ref.solve_mp("RRR", pick(m), pick(n), dps=80, **kw1)
    for k in ("r_mk", "r_np", "r_mn"):
        assert a[k] == b[k]
        assert abs(a["mp"][k][0] - b["mp"][k][0]) < 1e-40 * (1 + abs(b["mp"][k][0]))


def test_broadcasting_and_assemble_shapes():
    m = link(
        dir=(0.6, 0.8), length=1.2, com=(0.4, 0.1), mass=np.array([1.0, 2.0, 3.0]), inertia=0.1
    )
    n = link(dir=(-0.8, 0.6), length=0.9, com=(0.3, -0.05), mass=1.5, inertia=0.05, omega=2.0)
    A, b = ref.assemble("RRR", m, n, gravity=(0.0, -9.81))
    assert A.shape == (3, 6, 6) and b.shape == (3, 6)
    res = ref.solve("RRR", m, n, gravity=(0.0, -9.81))
    u = np.linalg.solve(A, b[..., None])[..., 0]
    np.testing.assert_allclose(res["u"], u)
    # weight-dependent only through mass of m: sample-wise solves agree
    for s in range(3):
        one = ref.solve("RRR", dict(m, mass=m["mass"][s]), n, gravity=(0.0, -9.81))
        np.testing.assert_allclose(one["r_mk"][0], res["r_mk"][s], rtol=1e-14)


# ---------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("bad", ["RRRR", "TTT", "", None, 3])
def test_unknown_type_raises(bad):
    m, n = link(), link(dir=(0.0, 1.0))
    with pytest.raises(ValueError):
        ref.solve(bad, m, n)
    with pytest.raises(ValueError):
        ref.assemble(bad, m, n)
    with pytest.raises(ValueError):
        ref.solve_mp(bad, m, n)


@pytest.mark.parametrize(
    "t,missing,given",
    [
        ("RRT", "guide_k", {}),
        ("TRT", "guide_k", {"guide_p": (0.0, 1.0)}),
        ("TRT", "guide_p", {"guide_k": (1.0, 0.0)}),
        ("RTT", "guide_k", {"guide_p": (0.0, 1.0)}),
    ],
)
def test_missing_guide_raises_naming_it(t, missing, given):
    m, n = link(), link(dir=(0.0, 1.0))
    for f in (ref.solve, ref.assemble, ref.solve_mp):
        with pytest.raises(ValueError, match=missing):
            f(t, m, n, **given)


def test_pair_table_and_unknown_ordering():
    assert {t: tuple(ref.PAIRS[t]) for t in TYPES} == KINDS and set(ref.PAIRS) == set(TYPES)
    assert ref.UNKNOWNS["RRR"] == ("r_mk.x", "r_mk.y", "r_np.x", "r_np.y", "r_mn.x", "r_mn.y")
    assert ref.UNKNOWNS["RTT"] == ("n_mk", "m_mk", "r_np.x", "r_np.y", "n_mn", "m_mn")


@pytest.mark.parametrize("t", TYPES)
def test_guides_not_needed_are_not_required(t):
    # only the guides of the type's own T pairs are needed; the result must not
    # depend on a superfluous guide
    m = link(force=(1.0, 2.0), com=(0.5, 0.1), length=0.7)
    n = link(dir=(0.6, 0.8), length=0.5, force=(-3.0, 0.5), com=(0.2, 0.0))
    kw = {"guide_k": (0.6, -0.8)} if KINDS[t][0] == "T" else {}
    if KINDS[t][2] == "T":
        kw["guide_p"] = (0.0, 1.0)
    a = ref.solve(t, m, n, **kw)
    b = ref.solve(t, m, n, **dict({"guide_k": (1.0, 0.0), "guide_p": (1.0, 0.0)}, **kw))
    c = ref.solve_mp(t, m, n, **kw)
    np.testing.assert_array_equal(a["u"], b["u"])
    np.testing.assert_allclose(a["u"][0], c["u"], rtol=1e-12, atol=1e-12)


def test_singular_configuration_is_flagged():
    # RRT dead position: connecting rod n perpendicular to the slider guide ->
    # the guide-direction balance of the slider cannot be met (A singular).
    m = link(dir=(1.0, 0.0), length=0.0, force=(-1.0, 0.0))
    n = link(dir=(0.6, 0.8), length=0.5)
    res = ref.solve("RRT", m, n, guide_k=(0.8, -0.6))
    assert res["cond"][0] > 1e14
    with pytest.raises(np.linalg.LinAlgError):
        ref.solve_mp("RRT", m, n, guide_k=(0.8, -0.6))

"""Directional derivatives of the C core (dyad_solve_tangent) against complex-step
derivatives of the independent reference and against central finite differences."""

import math

import numpy as np
import pytest
from dyadfmu.core import Core, library_path
from dyadfmu.reference import newton_euler as reference
from dyadfmu.study import configurations as cfg

pytestmark = pytest.mark.skipif(
    not library_path().is_file(), reason=f"C core not built at {library_path()}"
)

OUTPUTS = ("r_mk", "r_np", "r_mn", "n_mk", "n_np", "n_mn", "m_mk", "m_np", "m_mn")
SCALARS = ("length", "omega", "epsilon", "mass", "inertia", "moment")
VECTORS = ("accel_d", "com", "force")


@pytest.fixture(scope="module")
def core():
    return Core()


def _perturbed(dyad, row, seed, h):
    """The configuration moved by h along the seed; h may be imaginary (complex
    step). Angles move by h * rate, so directions stay on the unit circle."""
    m, n, gk, gp, grav = cfg.reference_args(dyad, row)
    sm, sn, sgk, sgp, sgrav = seed

    def turn(d, rate):
        angle = math.atan2(d[1], d[0])
        return (np.cos(angle + h * rate), np.sin(angle + h * rate))

    def link(k, s):
        out = {"dir": turn(k["dir"], s["angle"])}
        for key in SCALARS:
            out[key] = k[key] + h * s[key]
        for key in VECTORS:
            out[key] = (k[key][0] + h * s[key][0], k[key][1] + h * s[key][1])
        return out

    return (
        link(m, sm),
        link(n, sn),
        None if gk is None else turn(gk, sgk),
        None if gp is None else turn(gp, sgp),
        (grav[0] + h * sgrav[0], grav[1] + h * sgrav[1]),
    )


def _reference_scalar(dyad, m, n, gk, gp, grav):
    """The reference's Newton-Euler solve for one configuration, in whatever
    number type the inputs carry (complex for the complex step)."""
    kinds = tuple(reference.PAIRS[dyad])
    a_rows, b_rows = reference.equilibrium_system(kinds, m, n, gk, gp, grav)
    a = np.array([[complex(x) for x in row] for row in a_rows])
    b = np.array([complex(x) for x in b_rows])
    u = list(np.linalg.solve(a, b))
    out = reference.reactions_of_unknowns(kinds, u, gk, gp, m["dir"], 0j, 0j)
    flat = []
    for name in OUTPUTS:
        v = out[name]
        flat.extend(v if isinstance(v, tuple) else [v])
    return np.array(flat, dtype=complex)


def _core_flat(result):
    flat = []
    for name in OUTPUTS:
        v = result[name]
        flat.extend(v if isinstance(v, tuple) else [v])
    return np.array(flat)


def _random_seed(rng, dyad):
    def link():
        s = {"angle": rng.normal()}
        for key in SCALARS:
            s[key] = rng.normal()
        for key in VECTORS:
            s[key] = tuple(rng.normal(size=2))
        return s

    return link(), link(), rng.normal(), rng.normal(), tuple(rng.normal(size=2))


def _core_seed(dyad, row, seed):
    """The seed in the core's form: a direction's rate as the derivative of its
    unit vector."""
    m, n, gk, gp, _ = cfg.reference_args(dyad, row)
    sm, sn, sgk, sgp, sgrav = seed

    def rate(d, w):
        return (-d[1] * w, d[0] * w)

    def link(k, s):
        out = {"dir": rate(k["dir"], s["angle"])}
        out.update({key: s[key] for key in SCALARS + VECTORS})
        return out

    return (
        link(m, sm),
        link(n, sn),
        None if gk is None else rate(gk, sgk),
        None if gp is None else rate(gp, sgp),
        sgrav,
    )


@pytest.mark.parametrize("dyad", cfg.TYPES)
def test_tangent_matches_complex_step_and_finite_differences(core, dyad):
    rng = np.random.default_rng(cfg.TYPES.index(dyad))
    rows = cfg.random_set(dyad, 25, seed=500 + cfg.TYPES.index(dyad))
    rows[:, cfg.COL["m.length"]] = np.maximum(rows[:, cfg.COL["m.length"]], 0.05)
    worst_cs = worst_fd = 0.0
    for row in rows:
        seed = _random_seed(rng, dyad)
        if row[cfg.COL["m.length"]] == 0 or row[cfg.COL["n.length"]] == 0:
            continue
        value, derivative = core.solve_tangent(
            dyad, cfg.reference_args(dyad, row), _core_seed(dyad, row, seed)
        )
        assert value["status"] == "ok" and derivative["status"] == "ok", derivative
        got = _core_flat(derivative)
        h = 1e-30
        complex_step = _reference_scalar(dyad, *_perturbed(dyad, row, seed, 1j * h)).imag / h
        step = 1e-6
        central = (
            _reference_scalar(dyad, *_perturbed(dyad, row, seed, step)).real
            - _reference_scalar(dyad, *_perturbed(dyad, row, seed, -step)).real
        ) / (2 * step)
        scale = np.max(np.abs(complex_step))
        worst_cs = max(worst_cs, np.max(np.abs(got - complex_step)) / scale)
        worst_fd = max(worst_fd, np.max(np.abs(got - central)) / scale)
    print(f"{dyad}: tangent vs complex step {worst_cs:.1e}, vs central differences {worst_fd:.1e}")
    assert worst_cs < 1e-10
    assert worst_fd < 1e-5  # truncation error of the central difference


@pytest.mark.parametrize("dyad", cfg.TYPES)
def test_conditioning_rate(core, dyad):
    rng = np.random.default_rng(7)
    rows = cfg.random_set(dyad, 10, seed=900)
    for row in rows:
        seed = _random_seed(rng, dyad)
        for link in seed[:2]:  # the conditioning depends on angles and lengths only
            for key in ("omega", "epsilon", "mass", "inertia", "moment"):
                link[key] = 0.0
            for key in VECTORS:
                link[key] = (0.0, 0.0)
        if row[cfg.COL["m.length"]] == 0 or row[cfg.COL["n.length"]] == 0:
            continue
        _, derivative = core.solve_tangent(
            dyad, cfg.reference_args(dyad, row), _core_seed(dyad, row, seed)
        )
        step = 1e-7

        def conditioning(h, row=row, seed=seed):
            p = _perturbed(dyad, row, seed, h)
            return core.solve(dyad, *p)["conditioning"]

        central = (conditioning(step) - conditioning(-step)) / (2 * step)
        assert derivative["conditioning"] == pytest.approx(central, rel=1e-5, abs=1e-7)


def _amplification_rates(core, dyad, row, seed):
    """The core's rate of the amplification along the seed and the central difference
    of its values, or None where the one-sided differences disagree (a max, a clamp or
    a choice of form switches within the step: no derivative there)."""
    value, derivative = core.solve_tangent(
        dyad, cfg.reference_args(dyad, row), _core_seed(dyad, row, seed)
    )
    step = 1e-7 * value["amplification"] / max(1.0, abs(derivative["amplification"]))

    def amplification(h):
        return core.solve(dyad, *_perturbed(dyad, row, seed, h))["amplification"]

    left, right = amplification(-step), amplification(step)
    central = (right - left) / (2 * step)
    right_slope = (right - value["amplification"]) / step
    left_slope = (value["amplification"] - left) / step
    if abs(right_slope - left_slope) > 1e-3 * abs(central) + 1e-9:
        return None
    return derivative["amplification"], central


@pytest.mark.parametrize("dyad", cfg.TYPES)
def test_amplification_rate(core, dyad):
    """The amplification depends on every input, the loads too (the data factor sums
    the magnitude of every load term); its rate is exact where it is smooth, which is
    almost everywhere: against central differences of the core, along random seeds
    and along seeds that move only the loads and motion."""
    rng = np.random.default_rng(11)
    rows = cfg.random_set(dyad, 25, seed=950 + cfg.TYPES.index(dyad))
    for g, floor in (("m", 0.05), ("n", 0.07)):  # a length of 0 may not move down; and
        # l_m = l_n would put RTR on the kink of its conditioning (both forms equal)
        rows[:, cfg.COL[f"{g}.length"]] = np.maximum(rows[:, cfg.COL[f"{g}.length"]], floor)
    checked = moved_by_loads = 0
    for row in rows:
        seed = _random_seed(rng, dyad)
        for g, link in zip(
            "mn", seed[:2], strict=True
        ):  # quantities >= 0 move relative to their size
            for key in ("length", "mass", "inertia"):
                link[key] *= row[cfg.COL[f"{g}.{key}"]]
        loads_only = (
            dict(seed[0], angle=0.0, length=0.0),
            dict(seed[1], angle=0.0, length=0.0),
            0.0,
            0.0,
            (0.0, 0.0),
        )
        for s, counts in ((seed, False), (loads_only, True)):
            rates = _amplification_rates(core, dyad, row, s)
            if rates is None:
                continue
            checked += 1
            assert rates[0] == pytest.approx(rates[1], rel=1e-5, abs=1e-9), row
            moved_by_loads += counts and rates[0] != 0
    assert checked >= 40
    assert moved_by_loads >= 15

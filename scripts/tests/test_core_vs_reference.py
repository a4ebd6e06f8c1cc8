"""The C core against the independent Newton-Euler reference (NumPy and mpmath)."""

import math

import numpy as np
import pytest
from dyadfmu.core import Core, library_path
from dyadfmu.reference import newton_euler as ref

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
OUTPUTS = ("r_mk", "r_np", "r_mn", "m_mk", "m_np", "m_mn")

pytestmark = pytest.mark.skipif(
    not library_path().is_file(), reason=f"C core not built at {library_path()}"
)


@pytest.fixture(scope="module")
def core():
    return Core()


def random_link(rng, may_be_zero):
    length = 0.0 if (may_be_zero and rng.random() < 0.1) else 10 ** rng.uniform(-3, 3)
    size = length if length > 0 else 10 ** rng.uniform(-3, 0)
    mass = 10 ** rng.uniform(-3, 3)
    angle = rng.uniform(0, 2 * math.pi)
    return dict(
        dir=(math.cos(angle), math.sin(angle)),
        length=length,
        omega=rng.choice([-1, 1]) * 10 ** rng.uniform(-2, 2),
        epsilon=rng.choice([-1, 1]) * 10 ** rng.uniform(-2, 3),
        accel_d=tuple(rng.uniform(-1e3, 1e3, 2)),
        com=(size * rng.uniform(-0.5, 1.5), size * rng.uniform(-0.5, 0.5)),
        mass=mass,
        inertia=mass * (size * rng.uniform(0.05, 0.6)) ** 2,
        force=tuple(rng.uniform(-1e4, 1e4, 2)),
        moment=rng.uniform(-1e4, 1e4) * size,
    )


# Lengths that may be zero in each type, as the paper states (D_m, D_n links).
ZERO_OK = {
    "RRR": (False, False),
    "RRT": (True, False),
    "RTR": (False, True),
    "TRT": (True, True),
    "RTT": (False, True),
}


def configurations(dyad_type, count, seed):
    rng = np.random.default_rng(seed)
    zero_m, zero_n = ZERO_OK[dyad_type]
    produced = 0
    while produced < count:
        m, n = random_link(rng, zero_m), random_link(rng, zero_n)
        gk = tuple(np.array([1.0, 0.0]) @ _rotation(rng.uniform(0, 2 * math.pi)))
        gp = tuple(np.array([1.0, 0.0]) @ _rotation(rng.uniform(0, 2 * math.pi)))
        gravity = (0.0, -9.81) if rng.random() < 0.5 else (0.0, 0.0)
        cond = np.linalg.cond(ref.assemble(dyad_type, m, n, gk, gp, gravity)[0][0])
        if cond > 1e8:  # keep to configurations the reference solves well
            continue
        produced += 1
        yield m, n, gk, gp, gravity


def _rotation(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, s], [-s, c]])


def flat(result, dyad_type):
    """The six unknowns of a result as one vector, in the order of OUTPUTS."""
    values = []
    for name in OUTPUTS:
        v = result[name]
        values.extend(v if isinstance(v, (tuple, list, np.ndarray)) else [v])
    return np.asarray(values, dtype=float)


@pytest.mark.parametrize("dyad_type", TYPES)
def test_core_matches_numpy_reference(core, dyad_type):
    worst = 0.0
    for m, n, gk, gp, gravity in configurations(dyad_type, 400, seed=TYPES.index(dyad_type)):
        got = core.solve(dyad_type, m, n, gk, gp, gravity)
        assert got["status"] == "ok", got
        want = ref.solve(dyad_type, m, n, gk, gp, gravity)
        want = {k: np.asarray(v)[0] for k, v in want.items()}
        a, b = flat(got, dyad_type), flat(want, dyad_type)
        worst = max(worst, np.max(np.abs(a - b)) / np.max(np.abs(b)))
        for name in ("n_mk", "n_np", "n_mn"):  # normal forces where the pair slides
            if not math.isnan(want[name]):
                assert got[name] == pytest.approx(
                    want[name], rel=1e-9, abs=1e-11 * np.max(np.abs(b))
                )
    print(f"{dyad_type}: worst difference to numpy.linalg.solve {worst:.2e} of the largest output")
    assert worst < 1e-11


@pytest.mark.parametrize("dyad_type", TYPES)
def test_core_matches_mpmath_truth(core, dyad_type):
    worst = 0.0
    for m, n, gk, gp, gravity in configurations(dyad_type, 40, seed=100 + TYPES.index(dyad_type)):
        got = core.solve(dyad_type, m, n, gk, gp, gravity)
        truth = ref.solve_mp(dyad_type, m, n, gk, gp, gravity, dps=40)
        a, b = flat(got, dyad_type), flat(truth, dyad_type)
        worst = max(worst, np.max(np.abs(a - b)) / np.max(np.abs(b)))
    print(f"{dyad_type}: worst error against 40-digit truth {worst:.2e} of the largest output")
    assert worst < 1e-12


def test_core_reports_invalid_field(core):
    m = dict(
        dir=(1.0, 0.0),
        length=1.0,
        omega=0.0,
        epsilon=0.0,
        accel_d=(0.0, 0.0),
        com=(0.5, 0.0),
        mass=-2.0,
        inertia=0.1,
        force=(0.0, 0.0),
        moment=0.0,
    )
    n = dict(m, mass=1.0, dir=(0.0, 1.0))
    got = core.solve("RRR", m, n)
    assert got["status"] == "invalid input"
    assert got["field"] == "link_m.mass"
    assert all(math.isnan(v) for v in got["r_mk"])

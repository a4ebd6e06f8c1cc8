"""The coefficients of the explicit integrator DOP853 in src/dyad_ode.c are those of the
method (Hairer, Norsett, Wanner, dop853.f), compared number by number with SciPy's own
table of the same method; dyad_ode_tests measures its order 8 on exact solutions."""

from __future__ import annotations

import re

import numpy as np
import pytest
from dyadfmu import paths

TABLES = ("dop_c", "dop_a", "dop_b", "dop_e5", "dop_e3")


def _tables() -> dict:
    text = (paths.ROOT / "src" / "dyad_ode.c").read_text(encoding="utf-8")
    found = {}
    for name in TABLES:
        match = re.search(rf"static const dyad_real {name}\[[^=]*=\s*\{{(.*?)\}};", text, re.S)
        assert match, f"{name} not found in src/dyad_ode.c"
        numbers = re.findall(r"-?\d+\.\d+(?:e-?\d+)?", match.group(1))
        found[name] = np.array([float(x) for x in numbers])
    return found


def test_the_dop853_table_is_the_method():
    scipy_table = pytest.importorskip("scipy.integrate._ivp.dop853_coefficients")
    stages = scipy_table.N_STAGES
    ours = _tables()
    want = {
        "dop_c": scipy_table.C[:stages],
        "dop_a": scipy_table.A[:stages, : stages - 1].ravel(),
        "dop_b": scipy_table.B,
        "dop_e5": scipy_table.E5[:stages],
        "dop_e3": scipy_table.E3[:stages],
    }
    for name in TABLES:
        assert ours[name].shape == want[name].shape, name
        assert np.array_equal(ours[name], want[name]), name
    # the stages' nodes are the rows' sums, and the weights sum to 1
    a = ours["dop_a"].reshape(stages, stages - 1)
    assert np.allclose(a.sum(axis=1), ours["dop_c"], rtol=0, atol=1e-15)
    assert abs(ours["dop_b"].sum() - 1) < 1e-15

"""The plant study's reference for a machine with two drivers
(:mod:`dyadfmu.cosim.chain_reference`): its series of M(q) and h against the harness at
states it was not fitted at, rates included; its refusals (a motion that leaves the
series' domain, a chain whose loads are on)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dyadfmu.cosim import chain_reference
from dyadfmu.cosim import plant_study as study
from dyadfmu.mechanisms import multidriver

LEG = study.MACHINES["leg"]


def _series() -> chain_reference.ChainSeries:
    return chain_reference.series(study.unloaded_chain(LEG.chain), LEG.domain)


def test_the_series_give_the_harness_efforts_at_any_state():
    """M and h from the series against the harness's own Newton-Euler solve at 200
    random positions in the domain with random rates (h's terms were fitted at the rates
    0 and 1 only: a term of h not quadratic in the rates would show here)."""
    fit = _series()
    rng = np.random.default_rng(5)
    q = fit.positions(rng.uniform(-1.0, 1.0, (200, 2)))
    dq = rng.uniform(-8.0, 8.0, (200, 2))
    kin = fit.chain.state(q, dq)
    M, h = fit.chain.inertia_matrix(kin), fit.chain.bias(kin)
    series = [fit.efforts(a, b) for a, b in zip(q, dq, strict=True)]
    m_error = max(np.max(np.abs(s[0] - t)) for s, t in zip(series, M, strict=True))
    h_error = max(np.max(np.abs(s[1] - t)) for s, t in zip(series, h, strict=True))
    m_scale, h_scale = np.max(np.abs(M)), np.max(np.abs(h))
    print(f"M within {m_error / m_scale:.1e}, h within {h_error / h_scale:.1e} of their peaks")
    assert m_error < 1e-12 * m_scale and h_error < 1e-12 * h_scale
    assert fit.fit_error < 1e-12


def test_a_motion_leaving_the_domain_is_refused():
    """The series hold only over their domain: a reference whose motion leaves it refuses,
    saying where it went."""
    narrow = dataclasses.replace(LEG, domain=((-1.1, -0.9), (-2.2, -1.9)))
    t = np.linspace(0.0, 0.2, 201)
    with pytest.raises(ValueError, match="leaves the domain of its series"):
        study.reference(next(iter(study.CIRCUITS)), t, "DOP853", 1e-8, narrow)


def test_the_reactions_refuse_a_loaded_chain():
    """The plants' load inputs stay at zero; the leg of chains.toml carries its foot's
    load, and its reactions along a motion are refused by the load's name."""
    t = np.linspace(0.0, 0.01, 3)
    q = np.tile(LEG.start, (3, 1))
    motion = chain_reference.Motion(t, q, np.zeros_like(q), np.zeros_like(q))
    quiet = chain_reference.reactions(study.unloaded_chain(LEG.chain), motion)
    assert quiet and all(np.all(np.isfinite(v)) for v in quiet.values())
    with pytest.raises(ValueError, match=r"the harness applies the load foot\.force"):
        chain_reference.reactions(multidriver.load(LEG.chain), motion)

"""The Python API as a user calls it: one dyad through the C core and through the NumPy
reference (``from dyadfmu import reference``), a batch over NumPy arrays
(``dyadfmu.solve``), and a built-in mechanism's motion solved as one batch against the
reference. The code is the README's Python examples, line for line."""

from __future__ import annotations

import numpy as np
import pytest


def test_one_dyad_through_the_core_and_the_reference():
    from dyadfmu import reference  # the independent Newton-Euler solve
    from dyadfmu.core import Core  # $DYADFMU_LIB, the bundled core or build/libdyadfmu.so

    link = dict(dir=(1, 0), length=0.5, omega=0, epsilon=0, accel_d=(0, 0), com=(0.25, 0),
                mass=1, inertia=0.02, force=(0, -10), moment=0)  # fmt: skip
    core = Core().solve("RRR", link, dict(link, dir=(0, 1)), gravity=(0, -9.81))
    ref = reference.solve("RRR", link, dict(link, dir=(0, 1)), gravity=(0, -9.81))

    from dyadfmu.reference import newton_euler

    assert reference.solve is newton_euler.solve and reference.solve_mp is newton_euler.solve_mp
    assert core["status"] == "ok"
    for key in ("r_mk", "r_np", "r_mn"):
        assert np.allclose(core[key], ref[key][0], rtol=0, atol=1e-13), key
    # the ground pins K and P carry both links' weights and their 10 N loads
    assert core["r_mk"][1] + core["r_np"][1] == pytest.approx(2 * (10 + 9.81), rel=1e-14)


def test_a_batch_over_numpy_arrays():
    import dyadfmu

    theta = np.linspace(0, 2 * np.pi, 1_000_000)
    r = dyadfmu.solve("RRT", n_dir=np.stack([np.cos(theta), np.sin(theta)], axis=-1),
                      n_length=0.2, m_length=0.0, m_mass=0.45, m_force=[-8000.0, 0.0],
                      guide_k=[1.0, 0.0])  # fmt: skip
    assert (r.r_mk.shape, r.status.shape) == ((1_000_000, 2), (1_000_000,))
    assert r.ok.all() and r.reason(0) == "ok"


def test_a_mechanisms_motion_as_one_batch():
    import dyadfmu
    from dyadfmu import reference
    from dyadfmu.mechanisms import builtin

    mech = builtin.load("slider-crank")  # dyadfmu list: the five mechanisms
    motion = mech.motion("varying", revolutions=1.0)
    kin = mech.kinematics(np.linspace(0.0, motion.duration, 3601), motion)
    m, n, guide_k, guide_p, gravity = mech.reference_inputs(kin)  # every link's motion, loads
    fields = {f"m_{k}": v for k, v in m.items()} | {f"n_{k}": v for k, v in n.items()}
    guides = {"guide_k": guide_k, "guide_p": guide_p}
    r = dyadfmu.solve(mech.dyad, **fields, **{k: g for k, g in guides.items() if g is not None},
                      gravity=gravity)  # fmt: skip
    ref = reference.solve(mech.dyad, m, n, guide_k, guide_p, gravity)  # NumPy Newton-Euler

    assert r.r_np.shape == (3601, 2) and r.ok.all()
    for key in ("r_mk", "r_np", "r_mn"):
        error = np.max(np.abs(getattr(r, key) - ref[key]))
        assert error <= 1e-12 * np.max(np.abs(ref[key])), key

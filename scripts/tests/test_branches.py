"""Both assembly branches of the built-in slider-crank (RRT) and four-bar (RRR), and the
kinematics of all five built-in mechanisms in complex time.

- branch +1 is the default and the assembly of mechanisms.toml; a bad branch is refused;
- on either branch the loop closes (E from both links, A on the crank circle, D_m on its
  guide or pivot), and the -1 branch's positions are those geometry gives: the piston
  mirrored about the normal to the guide through the crank pin, the four-bar's E mirrored
  about the line O4 A (both written out here);
- velocities and accelerations (points, angles, lengths, ``accel_d``) against complex-step
  derivatives in time of the positions and of the velocities;
- the -1 branch assembles over a whole revolution, finite and well conditioned;
- on the -1 branch the reference reactions and the crank balance satisfy the energy
  balance of the whole mechanism, with dT/dt by complex step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from dyadfmu.mechanisms import builtin
from dyadfmu.mechanisms import crank as crank_balance
from dyadfmu.reference import newton_euler

BRANCHED = ("slider-crank", "four-bar")
KINDS = ("constant", "varying")
H = 1e-30  # the complex step (s)


def unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def samples(mech, kind, count=97):
    motion = mech.motion(kind, 1.0)
    return motion, (np.arange(count) + 0.31) * motion.duration / count


def rel_err(got, want):
    got, want = np.asarray(got), np.asarray(want)
    return float(np.max(np.abs(got - want)) / max(np.max(np.abs(want)), 1e-300))


def test_default_branch_and_bad_branches():
    for name in builtin.NAMES:
        mech = builtin.load(name)
        assert mech.branch == 1.0
        motion, t = samples(mech, "constant", 7)
        a, b = mech.kinematics(t, motion), mech.kinematics(t, motion, 1)
        assert np.array_equal(a["E"], b["E"]) and a["branch"] == 1.0
        with pytest.raises(ValueError, match="branch"):
            mech.kinematics(t, motion, 0)
        if name not in BRANCHED:
            with pytest.raises(ValueError, match="branch"):
                mech.kinematics(t, motion, -1)
    for name in BRANCHED:
        with pytest.raises(ValueError, match="branch"):
            builtin.load(name, {"geometry": {"branch": 0.5}})
        assert builtin.load(name, {"geometry": {"branch": -1}}).branch == -1.0


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("branch", (1, -1))
@pytest.mark.parametrize("name", BRANCHED)
def test_closure(name, branch, kind):
    mech = builtin.load(name)
    motion, t = samples(mech, kind)
    kin = mech.kinematics(t, motion, branch)
    r = mech.crank["radius"]
    phi = motion.phi(t)
    assert np.max(np.abs(kin["A"] - r * unit(phi))) < 1e-15
    assert np.max(np.abs(kin["D_n"] - kin["A"])) == 0.0
    for g, d in (("m", "D_m"), ("n", "D_n")):
        e = kin[d] + kin[f"{g}.length"][:, None] * unit(kin[f"{g}.angle"])
        assert np.max(np.abs(e - kin["E"])) < 1e-15
    if name == "slider-crank":
        e = mech.data["geometry"]["offset"]
        assert np.max(np.abs(kin["D_m"][:, 1] - e)) < 1e-17
        assert np.all(branch * (kin["E"][:, 0] - kin["A"][:, 0]) > 0)
    else:
        o4 = np.array(mech.data["geometry"]["O4"])
        assert np.max(np.abs(kin["D_m"] - o4)) == 0.0
        # branch +1: E on the left of the directed line A -> O4
        assert np.all(branch * cross(o4 - kin["A"], kin["E"] - kin["A"]) > 0)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", BRANCHED)
def test_other_branch_is_the_mirror_image(name, kind):
    mech = builtin.load(name)
    motion, t = samples(mech, kind)
    up, down = mech.kinematics(t, motion, 1), mech.kinematics(t, motion, -1)
    A = up["A"]
    if name == "slider-crank":
        rod, e = mech.data["link_n"]["length"], mech.data["geometry"]["offset"]
        x = A[:, 0] - np.sqrt(rod * rod - (e - A[:, 1]) ** 2)  # by hand, behind the pin
        assert np.max(np.abs(down["E"][:, 0] - x)) < 1e-15
        assert np.max(np.abs(down["E"][:, 0] - (2 * A[:, 0] - up["E"][:, 0]))) < 1e-15
        turn = np.mod(down["n.angle"] + up["n.angle"] - math.pi, 2 * math.pi)
        assert np.max(np.minimum(turn, 2 * math.pi - turn)) < 1e-14
    else:
        o4 = np.array(mech.data["geometry"]["O4"])
        u = (A - o4) / np.hypot(*(A - o4).T)[:, None]
        d = up["E"] - o4
        mirror = o4 + 2 * np.sum(d * u, axis=-1)[:, None] * u - d
        assert np.max(np.abs(down["E"] - mirror)) < 1e-15
    # the same distances on both branches; the conditioning is that of the mirror image
    assert rel_err(down["conditioning"], up["conditioning"]) < 1e-12


def complex_step_pairs(kin):
    """(position key, velocity key, acceleration key) triples of the kinematics."""
    triples = [("A", "v_A", "a_A"), ("E", "v_E", "a_E")]
    triples += [(f"S_{g}", f"v_S_{g}", f"a_S_{g}") for g in ("m", "n", "c")]
    triples += [(f"D_{g}", f"v_D_{g}", f"{g}.accel_d") for g in ("m", "n")]
    triples += [(f"{g}.angle", f"{g}.omega", f"{g}.epsilon") for g in ("m", "n", "crank")]
    triples += [(f"{g}.length", f"{g}.length_rate", f"{g}.length_accel") for g in ("m", "n")]
    return triples


CS_CASES = [(n, k, b) for n in builtin.NAMES for k in KINDS for b in builtin.load(n).branches]


@pytest.mark.parametrize(("name", "kind", "branch"), CS_CASES)
def test_complex_step_derivatives(name, kind, branch):
    mech = builtin.load(name)
    motion, t = samples(mech, kind, 61)
    kin = mech.kinematics(t, motion, branch)
    cs = mech.kinematics(t + 1j * H, motion, branch)
    assert np.iscomplexobj(cs["E"])
    for p, v, a in complex_step_pairs(kin):
        for x, dx in ((p, v), (v, a)):
            got, want = np.imag(cs[x]) / H, kin[dx]
            err = np.max(np.abs(got - want))
            assert err <= 1e-12 * np.max(np.abs(want)), (x, dx, err)


@pytest.mark.parametrize("name", BRANCHED)
def test_other_branch_over_a_revolution(name):
    mech = builtin.load(name)
    motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration, 3601)
    kin = mech.kinematics(t, motion, -1)
    for key in ("E", "m.angle", "n.angle", "m.epsilon", "n.epsilon", "a_S_m", "a_S_n"):
        assert np.all(np.isfinite(kin[key])), key
    worst = float(np.min(kin["conditioning"]))
    assert worst >= 0.2, f"{name} branch -1: conditioning down to {worst:.3g}"


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", BRANCHED)
def test_reference_and_crank_balance_on_the_other_branch(name, kind):
    mech = builtin.load(name)
    motion, t = samples(mech, kind)
    kin = mech.kinematics(t, motion, -1)
    r = newton_euler.solve(mech.dyad, *mech.reference_inputs(kin))
    bal = crank_balance.balance(mech, kin, r["r_np"], r["m_np"])
    power = bal["torque"] * kin["crank.omega"]
    # the load power includes gravity's: the balance is with the kinetic energy alone
    rate = np.imag(crank_balance.kinetic_energy(mech, mech.kinematics(t + 1j * H, motion, -1))) / H
    residual = power + crank_balance.load_power(mech, kin) - rate
    assert np.max(np.abs(residual)) < 1e-9 * np.max(np.abs(power))
    # the reactions differ from branch +1's: the branch reaches the reference
    up = newton_euler.solve(mech.dyad, *mech.reference_inputs(mech.kinematics(t, motion, 1)))
    assert np.max(np.abs(up["r_np"] - r["r_np"])) > 1e-3 * np.max(np.abs(r["r_np"]))


def test_gas_force_on_the_other_branch():
    """On branch -1 the piston runs left of O: the gas force pushes it towards +x and
    peaks psi_peak after the crank angle where the piston is farthest from O."""
    mech = builtin.load("slider-crank")
    motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, motion.duration, 36001)[:-1]
    kin = mech.kinematics(t, motion, -1)
    fx = kin["m.force"][:, 0]
    assert np.all(fx > 0)
    phi = kin["crank.angle"]
    tdc = phi[np.argmax(np.abs(kin["E"][:, 0]))]
    peak = phi[np.argmax(fx)]
    lag = np.mod(peak - tdc, 2 * math.pi)
    assert abs(lag - mech.data["load"]["psi_peak"]) < 2e-3

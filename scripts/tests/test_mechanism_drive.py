"""The stabilised co-simulation of the drive FMU with mechanism FMUs (no kinematics in
Python): J from the FMU's directional derivative equals its own crank.J, the torque is
affine in the acceleration, the run converges on the one-ODE machine at first order in
the communication step, and the master never calls the harness's kinematics."""

import inspect

import pytest
from dyadfmu.cosim import mechanism_drive as md

FINE = {"slider_crank": 2.5e-4, "four_bar": 2.5e-4, "shaper": 2.5e-3}


@pytest.mark.parametrize("name", list(md.MACHINES))
def test_converges_on_the_machine(name):
    fine = md.run(name, FINE[name])
    coarse = md.run(name, 4 * FINE[name])
    e_fine, e_coarse = md.errors(fine), md.errors(coarse)
    assert fine.inertia_mismatch < 1e-14 and coarse.inertia_mismatch < 1e-14
    assert fine.affine_residual < 1e-11
    # zero-order hold of the load over a step: first order, a quarter of the error
    assert 3.0 < e_coarse["phi"] / e_fine["phi"] < 5.0
    assert e_fine["omega"] < 2e-2
    assert e_fine["phi"] < 3e-2


def test_the_master_has_no_kinematics():
    """The master's communication point reads and writes the crank's state and the torque
    only: no reference kinematics, no positions."""
    source = inspect.getsource(md._point) + inspect.getsource(md.run)
    for forbidden in ("kinematics", "state_kinematics", "effective_inertia", "position"):
        assert forbidden not in source

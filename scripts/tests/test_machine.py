"""Tests of the motor-driven machine (scripts/dyadfmu/reference/machine.py).

- J(phi) is twice the kinetic energy of crank.kinetic_energy at unit crank speed, its
  exact derivative matches a 4th-order central difference, and Q equals
  load_power / omega (and is continuous at omega = 0);
- Lagrange against kinetostatics: the crank torque from reference.solve + crank.balance
  equals J epsilon + J' omega^2 / 2 - Q for every mechanism at many phi and several
  (omega, epsilon); its slope in epsilon (the effective inertia) is J(phi); leaving out
  J' breaks the agreement;
- the monolithic machine run from rest: speed positive (no stall), energy balance
  motor work + load work = change of kinetic energy, a periodic steady state reached
  near the motor's design speed, the shaft torque equal to the kinetostatic torque;
  a wrong equation of motion breaks the energy balance, a weak motor stalls;
- rotor inertias for mechanism-to-rotor inertia ratios 0.1, 1, 10, 100 all run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from dyadfmu.mechanisms import builtin as mechanisms
from dyadfmu.mechanisms import crank
from dyadfmu.reference import machine

NAMES = mechanisms.NAMES
RATIOS = (0.1, 1.0, 10.0, 100.0)


def _nominal_speed(mech):
    return float(mech.data["motion"]["omega"])


def _phi_grid(mech, n=361):
    rng = machine.phi_range(mech)
    if rng is None:
        return np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.linspace(rng[0], rng[1], n)


def _start_angle(mech):
    rng = machine.phi_range(mech)
    return 0.0 if rng is None else rng[0]


# ---------------------------------------------------------------------------
# J, J', Q
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_reduced_inertia_is_twice_the_kinetic_energy_at_unit_speed(name):
    mech = mechanisms.load(name)
    phi = _phi_grid(mech)
    J, _ = machine.reduced_inertia(mech, phi)
    for omega in (1.0, 7.5, -3.0):
        kin = machine.state_kinematics(mech, phi, omega, 0.3)
        ke = crank.kinetic_energy(mech, kin)
        np.testing.assert_allclose(J, 2.0 * ke / omega**2, rtol=1e-12, atol=0)
    assert np.all(J > 0)
    # shapes follow the input
    J2, dJ2 = machine.reduced_inertia(mech, phi.reshape(19, 19))
    assert J2.shape == dJ2.shape == (19, 19)
    assert np.ndim(machine.reduced_inertia(mech, phi[3])[0]) == 0


@pytest.mark.parametrize("name", NAMES)
def test_exact_inertia_derivative_matches_finite_differences(name):
    mech = mechanisms.load(name)
    phi = _phi_grid(mech, 181)[1:-1]
    J, dJ = machine.reduced_inertia(mech, phi)
    h = 1e-3

    def f(p):
        return machine.reduced_inertia(mech, p)[0]

    fd = (f(phi - 2 * h) - 8 * f(phi - h) + 8 * f(phi + h) - f(phi + 2 * h)) / (12 * h)
    peak = np.max(np.abs(dJ))
    err = np.max(np.abs(fd - dJ)) / peak
    print(f"{name}: |J'| peak {peak:.4g} kg m2/rad, exact vs 4th-order FD {err:.1e}")
    assert peak > 1e-3 * np.max(J)  # J really varies
    assert err < 1e-8


@pytest.mark.parametrize("name", NAMES)
def test_generalized_load_is_load_power_over_speed(name):
    mech = mechanisms.load(name)
    phi = _phi_grid(mech)
    w0 = _nominal_speed(mech)
    for omega in (w0, -0.4 * w0, 1e-3):
        kin = machine.state_kinematics(mech, phi, omega, 0.0)
        Q = machine.generalized_load(mech, phi, omega)
        ref = crank.load_power(mech, kin) / omega
        np.testing.assert_allclose(Q, ref, rtol=0, atol=1e-11 * np.max(np.abs(ref)))
    # continuous at rest (the speed-dependent loads vanish smoothly with the speed)
    Q0 = machine.generalized_load(mech, phi, 0.0)
    Qs = machine.generalized_load(mech, phi, 1e-9)
    assert np.all(np.isfinite(Q0))
    assert np.max(np.abs(Q0 - Qs)) <= 1e-6 * max(1.0, np.max(np.abs(Q0)))


# ---------------------------------------------------------------------------
# Lagrange against kinetostatics
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_kinetostatic_torque_matches_lagrange(name):
    mech = mechanisms.load(name)
    phi = _phi_grid(mech)
    w0 = _nominal_speed(mech)
    J, dJ = machine.reduced_inertia(mech, phi)
    worst = 0.0
    for omega, eps in (
        (w0, 0.0),
        (w0, 0.3 * w0 * w0),
        (0.4 * w0, -0.5 * w0 * w0),
        (-0.8 * w0, 0.2 * w0 * w0),
        (0.0, 0.0),
        (0.0, w0 * w0),
    ):
        torque = machine.crank_torque_from_kinetostatics(mech, phi, omega, eps)
        lagrange = J * eps + 0.5 * dJ * omega**2 - machine.generalized_load(mech, phi, omega)
        peak = np.max(np.abs(torque))
        rel = np.max(np.abs(torque - lagrange)) / peak
        worst = max(worst, rel)
        assert peak > 0
        assert rel <= 1e-9, f"{name} omega {omega:.4g} eps {eps:.4g}: {rel:.2e}"
        if omega != 0.0:
            # the test can fail: without the J' term the agreement is lost
            wrong = J * eps - machine.generalized_load(mech, phi, omega)
            assert np.max(np.abs(torque - wrong)) / peak > 1e-4
    # effective inertia: d(torque)/d(epsilon) = J(phi), the torque being linear in epsilon
    e1, e2 = -0.5 * w0 * w0, 0.7 * w0 * w0
    slope = (
        machine.crank_torque_from_kinetostatics(mech, phi, w0, e2)
        - machine.crank_torque_from_kinetostatics(mech, phi, w0, e1)
    ) / (e2 - e1)
    rel_j = np.max(np.abs(slope - J)) / np.max(J)
    print(
        f"{name}: kinetostatic vs Lagrange torque {worst:.1e} of the peak; "
        f"effective inertia vs J {rel_j:.1e}"
    )
    assert rel_j <= 1e-9


# ---------------------------------------------------------------------------
# the monolithic machine
# ---------------------------------------------------------------------------
def _energy_error(run):
    scale = max(
        np.max(np.abs(run.motor_work)), np.max(np.abs(run.load_work)), np.max(run.kinetic_energy)
    )
    return np.max(np.abs(run.energy_residual())) / scale


def _speed_over_revolution(run, phi0, k, phi_grid):
    """omega at phi0 + 2 pi k + phi_grid (the run must turn forwards)."""
    return np.interp(phi0 + 2 * math.pi * k + phi_grid, run.phi, run.omega)


@pytest.mark.parametrize("name", NAMES)
def test_monolithic_runs_up_and_conserves_energy(name):
    mech = mechanisms.load(name)
    motor = machine.default_motor(mech)
    phi0 = _start_angle(mech)
    w0 = _nominal_speed(mech)
    revolving = machine.phi_range(mech) is None
    # the slider-crank's gas load takes a revolution longer to settle
    periods = 4.6 if name == "slider-crank" else 3.3
    t_end = periods * 2 * math.pi / w0 if revolving else 5.0
    run = machine.monolithic(mech, motor, t_end, phi0, 0.0, rtol=1e-8, atol=1e-10)
    energy = _energy_error(run)

    # the shaft torque on the crank is what kinetostatics asks for
    shaft = motor.torque(run.omega) - motor.rotor_inertia * run.epsilon
    kinetostatic = machine.crank_torque_from_kinetostatics(mech, run.phi, run.omega, run.epsilon)
    shaft_err = np.max(np.abs(shaft - kinetostatic)) / np.max(np.abs(kinetostatic))

    assert np.all(run.omega[1:] > 0), f"{name}: the crank stalled"
    assert np.all(np.diff(run.phi) > 0)
    assert energy <= 1e-6
    assert shaft_err <= 1e-8
    msg = f"{name}: {len(run.t)} steps, energy residual {energy:.1e}, shaft torque {shaft_err:.1e}"
    if revolving:
        assert not run.stopped and run.t[-1] == pytest.approx(t_end)
        revs = (run.phi[-1] - phi0) / (2 * math.pi)
        assert revs > 3.0
        grid = np.linspace(0.0, 2 * math.pi, 73)[:-1]
        last, before = (
            _speed_over_revolution(run, phi0, k, grid) for k in (int(revs) - 1, int(revs) - 2)
        )
        change = np.max(np.abs(last - before)) / np.mean(last)
        mean = np.mean(last)
        msg += (
            f", {revs:.2f} rev, mean speed of the last revolution {mean:.4g} rad/s "
            f"(nominal {w0:.4g}), range {last.min():.4g}..{last.max():.4g}, change over "
            f"the last revolution {change:.1e}"
        )
        assert change < 5e-3, "not near a periodic steady state"
        assert abs(mean - w0) < 0.1 * w0
    else:
        # one stroke across the admissible range, then the run stops there
        assert run.stopped
        assert run.phi[-1] == pytest.approx(machine.phi_range(mech)[1], abs=1e-9)
        assert run.omega[-1] > 0.5 * motor.no_load_speed
        msg += f", stroke in {run.t[-1]:.4g} s, final speed {run.omega[-1]:.4g} rad/s"
    print(msg)


def test_monolithic_energy_balance_detects_a_wrong_equation(monkeypatch):
    """Drop J' from the equation of motion: the energy balance breaks."""
    mech = mechanisms.load("slider-crank")
    motor = machine.default_motor(mech)
    right = machine.machine_terms

    def wrong(mech_, phi, omega):
        J, dJ, Q = right(mech_, phi, omega)
        return J, 0.0 * dJ, Q

    monkeypatch.setattr(machine, "machine_terms", wrong)
    run = machine.monolithic(mech, motor, 0.03, 0.0, 0.0, rtol=1e-6, atol=1e-8)
    assert _energy_error(run) > 1e-3


def test_weak_motor_stalls():
    """The no-stall check can fail: a motor weaker than the compression stalls."""
    mech = mechanisms.load("slider-crank")
    # from rest 86 deg before TDC: the compression resists with up to 141 N m
    weak = machine.Motor(stall_torque=40.0, no_load_speed=290.0, rotor_inertia=5e-3)
    run = machine.monolithic(mech, weak, 0.05, -1.5, 0.0, rtol=1e-6, atol=1e-8)
    assert np.min(run.omega[1:]) <= 0
    assert _energy_error(run) <= 1e-6


def test_t_eval_gives_dense_output_at_default_tolerances():
    mech = mechanisms.load("four-bar")
    motor = machine.default_motor(mech)
    t_eval = np.linspace(0.0, 0.03, 31)
    w0 = _nominal_speed(mech)
    dense = machine.monolithic(mech, motor, 0.03, 0.0, w0, t_eval=t_eval)
    steps = machine.monolithic(mech, motor, 0.03, 0.0, w0)
    np.testing.assert_array_equal(dense.t, t_eval)
    np.testing.assert_allclose(dense.phi[-1], steps.phi[-1], rtol=1e-10)
    np.testing.assert_allclose(
        dense.omega,
        np.interp(t_eval, steps.t, steps.omega),
        rtol=0,
        atol=1e-3 * np.max(steps.omega),
    )
    assert _energy_error(steps) <= 1e-9
    assert np.all(steps.omega[1:] > 0)


# ---------------------------------------------------------------------------
# inertia ratios
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_inertia_ratios_run(name):
    mech = mechanisms.load(name)
    base = machine.default_motor(mech)
    phi0 = _start_angle(mech)
    w0 = _nominal_speed(mech)
    # the mean J against an independent average of 2 KE / omega^2 over a constant-speed
    # motion (uniform in phi for a revolving crank)
    mean_j = machine.mean_reduced_inertia(mech)
    if machine.phi_range(mech) is None:
        motion = mech.motion("constant", 1.0)
        t = np.linspace(0.0, motion.duration, 1441)[:-1]
        kin = mech.kinematics(t, motion)
        independent = np.mean(2.0 * crank.kinetic_energy(mech, kin) / kin["crank.omega"] ** 2)
        assert mean_j == pytest.approx(independent, rel=1e-12)
    revolving = machine.phi_range(mech) is None
    t_end = 1.3 * 2 * math.pi / w0 if revolving else 5.0
    lines = []
    for ratio in RATIOS:
        jr = machine.rotor_inertia_for_ratio(mech, ratio)
        assert mean_j / jr == pytest.approx(ratio, rel=1e-12)
        run = machine.monolithic(
            mech, base.with_rotor_inertia(jr), t_end, phi0, 0.0, rtol=1e-6, atol=1e-8
        )
        energy = _energy_error(run)
        assert run.solution.success
        assert np.all(run.omega[1:] > 0), f"{name} ratio {ratio}: stalled"
        assert energy <= 1e-6
        assert run.stopped == (not revolving)
        fluct = np.max(run.omega[run.t > 0.5 * run.t[-1]]) - np.min(
            run.omega[run.t > 0.5 * run.t[-1]]
        )
        lines.append(
            f"ratio {ratio:g} (J_r {jr:.3g}): {len(run.t)} steps, "
            f"phi {run.phi[-1] - phi0:.3g} rad, speed swing {fluct:.3g} rad/s, "
            f"energy {energy:.1e}"
        )
    print(f"{name}: mean J {mean_j:.4g} kg m2; " + "; ".join(lines))

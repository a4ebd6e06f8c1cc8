"""The harness: every mechanism's FMU against the reference, the crank's driving
torque against an energy balance, and the command line."""

import subprocess
import sys

import markdown_check
import numpy as np
import pytest
from dyadfmu.cosim import harness
from dyadfmu.mechanisms import builtin as mechanisms
from dyadfmu.mechanisms import crank
from dyadfmu.reference import newton_euler as reference
from dyadfmu.report import tables

MECHANISMS = mechanisms.NAMES


@pytest.mark.parametrize("version", (2, 3))
@pytest.mark.parametrize("mechanism", MECHANISMS)
def test_fmu_matches_reference(mechanism, version):
    result = harness.run_mechanism(mechanism, version, revolutions=2.0, steps=90)
    assert result.steps == 180
    assert result.valid.mean() > 0.95, "too many near-singular samples"
    # fmpy applies the inputs of t_k before the step to t_k+1: every sample but
    # the last (a repeat of the first over whole revolutions) reaches the FMU.
    assert sorted(set(result.sample)) == list(range(180))
    assert sum(error.peak > 0 for error in result.errors) >= 5, "too few non-zero outputs"
    for error in result.errors:
        # An output may vanish by construction (R_mk.x on a horizontal guide), then exactly.
        assert error.relative <= 1e-9 if error.peak > 0 else error.max_abs == 0, (
            f"{mechanism} FMI {version}: {error}"
        )
    print(harness.summary(result))


def _fd_derivative(f, t, h):
    """Fourth-order central difference of f at t."""
    return (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h)


@pytest.mark.parametrize("motion", ("constant", "varying"))
@pytest.mark.parametrize("mechanism", MECHANISMS)
def test_driving_torque_satisfies_energy_balance(mechanism, motion):
    """Driving power + power of loads and gravity = rate of change of kinetic
    energy, with the kinetic energy differentiated numerically in time."""
    mech = mechanisms.load(mechanism)
    crank_motion = mech.motion(motion, 1.0)
    t = np.linspace(0.0, crank_motion.duration, 241)[1:-1]
    kin = mech.kinematics(t, crank_motion)
    ref = reference.solve(mech.dyad, *mech.reference_inputs(kin))
    m_np = ref["m_np"] if mech.dyad == "TRT" else None
    torque = crank.balance(mech, kin, ref["r_np"], m_np)["torque"]
    driving = torque * kin["crank.omega"]

    def energy(times):
        return crank.kinetic_energy(mech, mech.kinematics(times, crank_motion))

    h = crank_motion.duration * 1e-4
    energy_rate = _fd_derivative(energy, t, h)
    residual = driving + crank.load_power(mech, kin) - energy_rate
    scale = np.max(np.abs(driving))
    print(
        f"{mechanism} ({motion}): energy residual {np.max(np.abs(residual)) / scale:.2e} "
        f"of the peak driving power {scale:.4g} W"
    )
    assert scale > 0
    assert np.max(np.abs(residual)) <= 1e-6 * scale


def test_energy_balance_detects_a_wrong_torque():
    """The balance above can fail: a torque off by 1 % of its peak breaks it."""
    mech = mechanisms.load("four-bar")
    crank_motion = mech.motion("constant", 1.0)
    t = np.linspace(0.0, crank_motion.duration, 121)[1:-1]
    kin = mech.kinematics(t, crank_motion)
    ref = reference.solve(mech.dyad, *mech.reference_inputs(kin))
    torque = crank.balance(mech, kin, ref["r_np"])["torque"]
    torque = torque + 0.01 * np.max(np.abs(torque))
    h = crank_motion.duration * 1e-4
    rate = _fd_derivative(
        lambda s: crank.kinetic_energy(mech, mech.kinematics(s, crank_motion)), t, h
    )
    residual = torque * kin["crank.omega"] + crank.load_power(mech, kin) - rate
    assert np.max(np.abs(residual)) > 1e-6 * np.max(np.abs(torque * kin["crank.omega"]))


def _cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "dyadfmu.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


@pytest.mark.parametrize("mechanism", MECHANISMS)
def test_cli_runs_each_mechanism(mechanism, tmp_path):
    done = _cli(
        "run",
        mechanism,
        "--fmi",
        "both",
        "--revolutions",
        "1",
        "--steps",
        "36",
        "--out",
        str(tmp_path),
    )
    assert done.returncode == 0, done.stderr
    assert "worst relative error of any output" in done.stdout
    for version in (2, 3):
        for suffix in ("errors.md", "errors.csv", "reactions.png", "mechanism.png"):
            path = tmp_path / f"{mechanism}_fmi{version}_{suffix}"
            assert path.is_file() and path.stat().st_size > 0, path
        # the errors table read back by a Markdown parser: its five columns, every output
        (errors,) = markdown_check.check_file(tmp_path / f"{mechanism}_fmi{version}_errors.md")
        assert errors.texts(0) == tables.ERROR_HEADER and len(errors.rows) > 1


def test_cli_help_list_and_errors(tmp_path):
    assert _cli("--help").returncode == 0
    assert "--revolutions" in _cli("run", "--help").stdout
    listing = _cli("list")
    assert listing.returncode == 0 and all(s in listing.stdout for s in MECHANISMS)
    wrong = _cli("run", "no-such-mechanism", "--out", str(tmp_path))
    assert wrong.returncode == 2 and "unknown mechanism" in wrong.stderr
    assert _cli("run", "--steps", "0").returncode == 2

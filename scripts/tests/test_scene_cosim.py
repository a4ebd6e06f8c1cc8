"""`dyadfmu cosim --scene FILE.toml` and `python -m dyadfmu.cosim.ssp --scene`: a user's own
mechanism turned by the drive FMU. The shipped four-bar's scene file moves as the shipped
co-simulation does; a crank-rocker the project does not ship keeps its energy balance and
runs the same in its SSP package (the project's master and fmpy's); scenes the drive cannot
turn and bad options are refused by name."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import build_scene, paths
from dyadfmu.cosim import mechanism_drive, scene_drive, ssp
from dyadfmu.fmi.slave import Slave
from dyadfmu.reference import machine
from dyadfmu.report import cosim
from dyadfmu.sweep import scenebuild
from tool_checks import required_tool

SCENES = paths.ROOT / "modelDescription" / "scenes"
FOUR_BAR = SCENES / "four_bar.toml"

#: A crank-rocker (crank + RRR) with weights and a resisting moment on the rocker of
#: ROCKER_MOMENT (its start value), modelled on four_bar.toml with other dimensions.
ROCKER = """
[scene]
identifier = "users_crank_rocker"
description = "a crank-rocker (crank + RRR) turned by the drive FMU"
kinematics = "internal"
outputs = ["all"]

[effects]
inertia = true
gravity = true

[gravity]
x = 0.0
y = -9.81

[crank]
name = "crank"
length = 0.04
com = [0.015, 0.0]
mass = 0.2
inertia = 5.0e-5

[[dyad]]
name = "linkage"
type = "RRR"
m = "rocker"
n = "coupler"
k = { link = "frame", at = [0.14, 0.0] }
p = "crank"
branch = -1

[[link]]
name = "rocker"
length = 0.10
com = [0.05, 0.0]
mass = 0.25
inertia = 3.0e-4

[[link]]
name = "coupler"
length = 0.16
com = [0.08, 0.004]
mass = 0.3
inertia = 7.0e-4

[loads]
moment = ["rocker"]

[start]
"rocker.moment" = -0.4
"""
ROCKER_MOMENT, GRAVITY = -0.4, 9.81
#: Each body's mass [kg] and centre of mass in its frame [m]: the crank's about O.
BODIES = {
    "crank": (0.2, (0.015, 0.0)),
    "rocker": (0.25, (0.05, 0.0)),
    "coupler": (0.3, (0.08, 0.004)),
}
#: The machine of the crank-rocker's runs: the four-bar's motor, from its default start.
MACHINE = ["--motor", "four-bar", "--duration", "0.5", "--step", "1e-4"]


@pytest.fixture(scope="module")
def rocker(tmp_path_factory) -> Path:
    """The crank-rocker's scene file, its FMU and the four-bar's scene's built (once)."""
    required_tool("cmake")
    scene = tmp_path_factory.mktemp("scene") / "users_crank_rocker.toml"
    scene.write_text(ROCKER)
    build_scene.build([scene, FOUR_BAR], scenebuild.build_folder(scene.parent), windows="off")
    return scene


def _cosim(capsys, *args: object) -> tuple[int, str, str]:
    status = cosim.main([str(a) for a in args])
    said = capsys.readouterr()
    return status, said.out, said.err


def _csv(path: Path) -> dict[str, np.ndarray]:
    """The run's columns by name (the unit in brackets dropped), and the header's units."""
    header = path.read_text().splitlines()[0].split(",")
    values = np.loadtxt(path, delimiter=",", skiprows=1)
    return {h.split(" [")[0]: values[:, k] for k, h in enumerate(header)}


def test_the_four_bar_scene_moves_as_the_shipped_co_simulation(rocker, tmp_path, capsys):
    """four_bar.toml given the harness's machine (its motor, 31.4 rad/s, 0.25 s in 1 ms
    steps): the rotor inertia derived from the scene's FMU is the harness's mean J, and the
    motion and torque are the shipped run's (measured: J within 6e-16, angle within 5e-12
    rad, speed and torque within 1.4e-12 and 4.3e-12 of their scale: the CSV's 12 digits)."""
    options = ["--motor", "four-bar", "--start-speed", "31.4", "--duration", "0.25"]
    status, out, err = _cosim(
        capsys, "--scene", FOUR_BAR, *options, "--step", "1e-3", "--out", tmp_path
    )
    assert status == 0, err
    shipped = mechanism_drive.run("four_bar", 1e-3)
    run = _csv(tmp_path / "four_bar_cosim.csv")
    assert len(run["t"]) == len(shipped.t) == 251
    fmu = scenebuild.build_folder(tmp_path) / "fmus" / "four_bar_fmi2.fmu"
    harness = mechanism_drive.machine_of("four_bar").motor.rotor_inertia
    assert abs(scene_drive.revolution_means(fmu)[0] / harness - 1) < 1e-12
    assert np.max(np.abs(run["crank.angle"] - shipped.phi)) < 1e-9
    assert np.max(np.abs(run["crank.omega"] - shipped.omega)) < 1e-9 * 31.4
    assert np.max(np.abs(run["crank.torque"] - shipped.torque)) < 1e-9 * np.max(
        np.abs(shipped.torque)
    )
    assert f"{np.mean(shipped.omega):.6g} rad/s" in out


def _potential_and_rocker(fmu: Path, run: dict, k: int) -> tuple[float, float, float]:
    """At row k of the run: the mechanism's kinetic energy J omega^2 / 2 [J] (J the FMU's),
    the weights' potential [J] from the FMU's link angles and pair points, the rocker's angle."""
    y = Slave(fmu, "energy")
    y.initialize()
    try:
        state = (run["crank.angle"][k], run["crank.omega"][k], run["crank.epsilon"][k])
        y.set(("crank.angle", "crank.omega", "crank.epsilon"), state)
        names = ("crank.J", "rocker.angle", "coupler.angle", "linkage.D_m.position.y")
        inertia, rocker, coupler, pivot, pin = y.get((*names, "linkage.D_n.position.y"))
    finally:
        y.close()
    frames = {"crank": (0.0, state[0]), "rocker": (pivot, rocker), "coupler": (pin, coupler)}
    height = 0.0
    for body, (mass, (cx, cy)) in BODIES.items():
        origin, angle = frames[body]
        height += mass * (origin + cx * math.sin(angle) + cy * math.cos(angle))
    return inertia * state[1] ** 2 / 2, GRAVITY * height, rocker


def _energy_terms(scene: Path, out: Path, capsys, step: str) -> dict[str, float]:
    """The run's energy terms [J]: the motor's work and what it went into."""
    options = [*MACHINE[:-1], step]
    status, _, err = _cosim(capsys, "--scene", scene, *options, "--out", out)
    assert status == 0, err
    run = _csv(out / "users_crank_rocker_cosim.csv")
    fmu = scenebuild.build_folder(out) / "fmus" / "users_crank_rocker_fmi2.fmu"
    motor = machine.MOTORS["four-bar"]
    power = motor.torque(run["crank.omega"]) * run["crank.omega"]
    rotor = scene_drive.revolution_means(fmu)[0]
    (k0, v0, r0), (k1, v1, r1) = (_potential_and_rocker(fmu, run, k) for k in (0, -1))
    omega = run["crank.omega"]
    return {
        "motor": float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(run["t"]))),
        "rotor": rotor * (omega[-1] ** 2 - omega[0] ** 2) / 2,
        "mechanism": k1 - k0,
        "weights": v1 - v0,
        "load": -ROCKER_MOMENT * (r1 - r0),
    }


def test_the_motor_s_work_is_the_energy_it_gave(rocker, tmp_path, capsys):
    """Over 0.5 s (3 revolutions) the motor's work (its line at the run's speeds, the
    trapezoid over the points) is the kinetic energy the rotor and the mechanism gained plus
    the weights' potential plus the work against the rocker's moment, within 0.5 % of it at
    a 0.1 ms step (measured 0.28 %; 2.3 % at 1 ms: the coupling's first order). Each term
    is above 2 % of the work, so leaving out any one fails the bound."""
    fine = _energy_terms(rocker, tmp_path / "fine", capsys, "1e-4")
    coarse = _energy_terms(rocker, tmp_path / "coarse", capsys, "1e-3")
    residual = {}
    for name, terms in (("fine", fine), ("coarse", coarse)):
        residual[name] = terms["motor"] - sum(v for k, v in terms.items() if k != "motor")
    assert abs(residual["fine"]) < 5e-3 * fine["motor"], (residual, fine)
    assert 5.0 < residual["coarse"] / residual["fine"] < 15.0, residual
    for name in ("rotor", "mechanism", "weights", "load"):
        assert abs(fine[name]) > 2e-2 * fine["motor"], (name, fine)


def test_the_ssp_package_runs_as_the_command(rocker, tmp_path, capsys):
    """The package of the crank-rocker with the machine of the command: schema-valid, the
    drive's parameters the machine's, and its mean crank speed in the project's master and
    in fmpy's simulate_ssp within 0.5 % of the command's (measured 5e-15 and 1.5e-7 of the
    mean; every point of the project's master within 1.4e-12, the CSV's 12 digits, and of
    fmpy's explicit coupling within 0.18 %)."""
    status, _, err = _cosim(capsys, "--scene", rocker, *MACHINE, "--out", tmp_path)
    assert status == 0, err
    command = _csv(tmp_path / "users_crank_rocker_cosim.csv")
    assert ssp.main(["--scene", str(rocker), *MACHINE, "--out", str(tmp_path)]) == 0
    package = Path(capsys.readouterr().out.strip())
    assert package == tmp_path / "drive_users_crank_rocker_fmi2.ssp"
    ssp.validate(package)
    read = ssp.read_package(package)
    assert (read.step, read.stop_time) == (1e-4, 0.5)
    assert read.parameters["drive"]["motor.stall_torque"] == machine.MOTORS["four-bar"].stall_torque
    ours = ssp.simulate(package)["drive.crank.omega"]
    fmpy = ssp.simulate_fmpy(package)["drive.crank.omega"]
    mean = np.mean(command["crank.omega"])
    assert len(ours) == len(command["t"]) and len(fmpy) == len(command["t"]) - 1
    assert abs(np.mean(ours) - mean) < 5e-3 * mean
    assert np.max(np.abs(ours - command["crank.omega"])) < 1e-9 * mean
    assert abs(np.mean(fmpy) - np.mean(command["crank.omega"][1:])) < 5e-3 * mean


@pytest.mark.parametrize(
    "scene, why",
    [
        ("lift.toml", "no crank, its driver is ram 'ram': one drive turns one crank"),
        ("leg.toml", "2 drivers (crank 'front', crank 'rear'): one drive turns one crank"),
    ],
)
def test_a_scene_the_drive_cannot_turn_is_refused_in_one_line(scene, why, tmp_path, capsys):
    status, out, err = _cosim(capsys, "--scene", SCENES / scene, "--out", tmp_path)
    assert status == 1 and out == ""
    assert err == f"dyadfmu cosim: error: {SCENES / scene}: {why}\n"
    assert not list(tmp_path.iterdir())


def test_a_mechanism_that_does_not_go_through_a_turn_is_refused_in_one_line(tmp_path, capsys):
    """A slider-crank whose rod is shorter than the crank: no assembly over part of the turn."""
    required_tool("cmake")
    text = (SCENES / "slider_crank.toml").read_text().replace("length = 0.18", "length = 0.05")
    scene = tmp_path / "short_rod.toml"
    scene.write_text(text.replace('identifier = "slider_crank"', 'identifier = "short_rod"'))
    status, out, err = _cosim(capsys, "--scene", scene, "--out", tmp_path / "out")
    said = err.strip().splitlines()[-1]  # after the build's progress, one line
    assert status == 1 and said.startswith("dyadfmu cosim: error: "), err
    assert "no answer at 73 of 360 crank angles (the first 4.084 rad)" in said
    assert "a drive cannot turn it" in said and not (tmp_path / "out").exists()


def test_an_fmu_without_the_drive_s_outputs_is_named():
    """The press (no inertia) has no crank.J nor crank.torque0: the refusal says so."""
    fmu = paths.built_fmu("press", 2)
    with pytest.raises(
        scene_drive.SceneRefused, match=r"press_fmi2.fmu: no output crank.J or crank.torque0"
    ):
        scene_drive.revolution_means(fmu)


@pytest.mark.parametrize(
    "given, said",
    [
        (["--stall-torque", "-3"], "argument --stall-torque: must be a number above 0"),
        (["--no-load-speed", "fast"], "argument --no-load-speed: not a number: 'fast'"),
        (["--start-speed", "nan"], "argument --start-speed: must be a number from 0"),
        (["--duration", "0"], "argument --duration: must be a number above 0"),
        (["--step", "inf"], "argument --step: must be a number above 0"),
        (["--motor", "turbine"], "argument --motor: invalid choice: 'turbine'"),
        (["--step", "3e-3"], "--duration 1 s is not a whole number of --step 0.003 s"),
        (["--duration", "1e4", "--step", "1e-6"], "makes 10,000,000,000 steps; at most 10,000,000"),
        (["--quick"], "--quick is the study's, not a scene's"),
    ],
)
def test_a_bad_option_is_refused_by_name(given, said, tmp_path, capsys):
    with pytest.raises(SystemExit) as stopped:
        cosim.main(["--scene", str(FOUR_BAR), *given, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert stopped.value.code == 2 and said in err, err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("main", [cosim.main, ssp.main])
def test_a_machine_option_needs_a_scene(main, capsys):
    with pytest.raises(SystemExit):
        main(["--start-speed", "10"])
    assert "error: --start-speed needs --scene" in capsys.readouterr().err


def test_every_machine_option_gives_its_unit(capsys):
    with pytest.raises(SystemExit):
        cosim.main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    for option, unit in [
        ("--stall-torque N.m", "N m"),
        ("--no-load-speed RAD/S", "rad/s"),
        ("--start-speed RAD/S", "rad/s"),
        ("--duration S", "s"),
        ("--step S", "s"),
    ]:
        help_text = text.split(f"{option} ")[-1].split(" --")[0]
        assert f", {unit} (default" in help_text, (option, help_text)


@pytest.mark.parametrize("speed, step", [(36.0, 1e-3), (290.0, 2e-4), (600.0, 1e-4), (1e4, 5e-6)])
def test_the_default_step_takes_a_hundred_steps_a_revolution(speed, step):
    assert scene_drive.default_step(speed) == step
    assert 2 * math.pi / speed / step >= 100

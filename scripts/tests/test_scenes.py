"""Scenes: the generator on every example scene (valid and malformed), every tailored FMU
validated by fmpy and compared with its independent reference in co-simulation, the
chains' driving torque against the energy balance, the declared dependencies against the
FMUs' behaviour, and the compile-time omission of what a scene leaves out."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import scenes
from dyadfmu.fmi import slave as fmi_slave
from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

ROOT = Path(__file__).resolve().parents[2]
SCENE_TOOL = ROOT / "modelDescription" / "scene.py"
SCENES_DIR = ROOT / "modelDescription" / "scenes"
MALFORMED = sorted((SCENES_DIR / "malformed").glob("*.toml"))
VERSIONS = (2, 3)
GENERATED = paths.build_dir() / "generated"


def run_tool(*args):
    return subprocess.run(
        [sys.executable, str(SCENE_TOOL), *map(str, args)], capture_output=True, text=True
    )


def variables(name, version=2):
    md = read_model_description(str(scenes.fmu_path(name, version)))
    return {
        c: [v.name for v in md.modelVariables if v.causality == c]
        for c in ("input", "parameter", "output")
    }


# ---------------------------------------------------------------------------
# the generator
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("path", sorted(SCENES_DIR.glob("*.toml")), ids=lambda p: p.stem)
def test_every_example_scene_is_accepted(path, tmp_path):
    check = run_tool(path, "--check")
    assert check.returncode == 0, check.stderr
    out = tmp_path / path.stem
    done = run_tool(path, "--out", out)
    assert done.returncode == 0, done.stderr
    for rel in (
        "fmi2/modelDescription.xml",
        "fmi3/modelDescription.xml",
        "fmi3/buildDescription.xml",
        "documentation/index.html",
    ):
        assert (out / rel).is_file(), rel
    # the same scene gives the same files, byte for byte
    again = tmp_path / (path.stem + "_again")
    assert run_tool(path, "--out", again).returncode == 0
    for file in out.rglob("*"):
        if file.is_file():
            assert (again / file.relative_to(out)).read_bytes() == file.read_bytes()


#: A driver's motion, the only inputs of a mechanism FMU besides its loads.
DRIVER_MOTION = {
    "crank": ("angle", "omega", "epsilon"),
    "ram": ("position", "velocity", "acceleration"),
    "cylinder": ("length", "velocity", "acceleration"),
}


#: The scenes whose FMU gets a scene's page: all but the generic dyads (a dyad's page).
SCENE_PAGES = [p for p in sorted(SCENES_DIR.glob("*.toml")) if not p.stem.startswith("dyad_")]


@pytest.mark.parametrize("path", SCENE_PAGES, ids=lambda p: p.stem)
def test_the_documentation_says_what_the_fmu_takes(path):
    """A mechanism FMU (kinematics inside) takes its driver's motion and the loads, not the
    links' kinematics: its page names the motion inputs and counts the loads, which are
    every other input; a scene with external kinematics takes every link's motion."""
    from dyadgen import pipeline

    table = pipeline.build_table(pipeline.load_scene(path))
    page = pipeline.outputs_of(table)["documentation/index.html"]
    said = re.search(r"At every communication point it takes (.*?) and returns", page, re.S)
    inputs = [v.name for v in table.of("input")]
    scene = table.scene
    if scene.kinematics == "external":
        assert said.group(1) == "the links' current kinematics and active loads"
        return
    assert "current kinematics" not in page
    if scene.forward():
        # a plant takes what drives it: no motion is an input
        driving = [n for n in inputs if n.endswith((".torque", ".force", ".motor.voltage"))]
        assert driving and said.group(1).startswith("only what drives it (")
        assert all(f"<code>{n}</code>" in said.group(1) for n in driving)
        assert "no motion is an input" in said.group(1)
        return
    motion = [
        f"{driver.driver_name()}.{q}"
        for driver in scene.drivers
        for q in DRIVER_MOTION[driver.kind]
    ]
    loads = [n for n in inputs if n not in motion]
    assert set(motion) <= set(inputs)
    assert all(re.fullmatch(r"\w+\.(force\.[xy]|moment)", n) for n in loads), loads
    named = ", ".join(f"<code>{n}</code>" for n in motion)
    count = "(1 input)" if len(loads) == 1 else f"({len(loads)} inputs)"
    several = len(scene.drivers) > 1
    who = f"its {len(scene.drivers)} drivers'" if several else f"the {scene.crank.kind}'s"
    assert said.group(1).startswith(f"only {who} motion ({named}) and the active")
    assert count in said.group(1) and "no link's motion is an input" in said.group(1)


def test_malformed_examples_exist():
    kinds = {p.stem for p in MALFORMED}
    assert {"unknown_type", "link_twice", "output_no_pair_provides", "missing_parameter"} <= kinds
    assert len(kinds) >= 10


@pytest.mark.parametrize("path", MALFORMED, ids=lambda p: p.stem)
def test_malformed_scene_is_rejected_naming_line_and_problem(path, tmp_path):
    expect = re.match(r"# expect: line (\d+): (.*)$", path.read_text().splitlines()[0])
    assert expect, f"{path.name}: first line must be '# expect: line N: message'"
    line, fragment = expect.group(1), expect.group(2)
    out = tmp_path / "out"
    done = run_tool(path, "--out", out)
    assert done.returncode == 1
    errors = [ln for ln in done.stderr.splitlines() if ln.startswith("error:")]
    assert any(f"{path.name}:{line}:" in ln and fragment in ln for ln in errors), done.stderr
    assert "nothing written" in done.stderr
    assert not out.exists()  # nothing built


def test_cmake_stops_on_a_malformed_scene(tmp_path):
    """One CMake call per scene; a malformed one stops the configuration with the
    generator's message."""
    build = tmp_path / "build"
    done = subprocess.run(
        [
            "cmake",
            "-S",
            str(ROOT),
            "-B",
            str(build),
            "-DDYADFMU_BUILD_TESTS=OFF",
            "-DDYADFMU_BUILD_BENCH=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DDYADFMU_SCENES={SCENES_DIR / 'malformed' / 'link_twice.toml'}",
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode != 0
    assert "link_twice.toml:43:" in done.stderr and "connected twice" in done.stderr


# ---------------------------------------------------------------------------
# what a scene leaves out
# ---------------------------------------------------------------------------
def test_static_press_takes_no_motion_and_computes_no_inertia_or_weight():
    v = variables("press")
    assert v["input"] == ["crank.angle", "ram.force.x", "ram.force.y", "rod.angle"]
    assert v["parameter"] == ["on_singular"]  # the FMU layer's setting alone
    assert v["output"] == ["press.N_mk", "press.R_np.x", "press.R_np.y", "crank.torque", "status"]
    code = (GENERATED / "press" / "press_scene.c").read_text()
    body = code[code.index("void press_evaluate(") :]
    for absent in ("omega", "epsilon", "gravity", "accel", "crank_r_o"):
        assert absent not in body, absent
    # baked constants, not parameters: the rod length and the crank radius
    assert "DYAD_R(0.18)" in body and "dyad_scale(DYAD_R(0.05), crank_i)" in body


def test_horizontal_monitor_has_no_weight_and_one_reaction():
    v = variables("monitor")
    assert v["output"] == ["agitator.R_mk.x", "agitator.R_mk.y", "amplification", "status"]
    assert v["parameter"] == ["rocker.mass", "on_singular"]
    assert not any("gravity" in n for n in v["input"] + v["parameter"])
    code = (GENERATED / "monitor" / "monitor_scene.c").read_text()
    body = code[code.index("void monitor_evaluate(") :]
    assert "gravity" not in body
    assert "crank_torque" not in body and "crank_r_o" not in body  # no crank balance
    assert "in->rocker_mass" in body


def test_outputs_of_one_dyad_solve_only_what_loads_it(tmp_path):
    """Asking the six-bar for the second dyad's reactions only solves that dyad."""
    text = (
        (SCENES_DIR / "sixbar.toml")
        .read_text()
        .replace('outputs = ["all"]', 'outputs = ["second.R_np"]')
    )
    scene = tmp_path / "sixbar_second.toml"
    scene.write_text(text.replace('identifier = "sixbar"', 'identifier = "sixbar_second"'))
    out = tmp_path / "gen"
    assert run_tool(scene, "--out", out).returncode == 0
    code = (out / "sixbar_second_scene.c").read_text()
    assert "dyad_react_rrr(&load, &second)" in code
    assert "dyad_react_rrr(&load, &first)" not in code  # no reactions of the first dyad
    assert "dyad_kinematics_rrr(&k, &kin->first)" in code  # but its motion carries D
    md = (out / "fmi2" / "modelDescription.xml").read_text()
    inputs = re.findall(r'name="([^"]+)"[^>]*causality="input"', md)
    assert inputs == ["crank.angle", "crank.omega", "crank.epsilon", "output.moment"]


def test_a_mechanism_fmu_always_bounds_what_it_reports(tmp_path):
    """A mechanism FMU's own amplification is always an output: with reactions asked,
    the bound of each dyad solved; with the motion alone, three times the motion's
    amplification of each dyad whose kinematics run, every one carried to the next."""
    text = (SCENES_DIR / "sixbar.toml").read_text()
    for wanted, terms in (
        ('["second.R_np"]', ["second_bound", "DYAD_R(3.0) * kin.first.amplification"]),
        ('["rocker.omega"]', ["DYAD_R(3.0) * kin.first.amplification"]),
        (
            '["output.epsilon"]',
            ["DYAD_R(3.0) * kin.first.amplification", "DYAD_R(3.0) * kin.second.amplification"],
        ),
    ):
        scene = tmp_path / "sixbar_some.toml"
        scene.write_text(
            text.replace('outputs = ["all"]', f"outputs = {wanted}").replace(
                'identifier = "sixbar"', 'identifier = "sixbar_some"'
            )
        )
        out = tmp_path / "gen"
        assert run_tool(scene, "--out", out).returncode == 0
        code = (out / "sixbar_some_scene.c").read_text()
        line = re.search(r"out->amplification = ([^N].*);", code).group(1)
        assert line == " + ".join(["DYAD_R(1.0)", *terms]), (wanted, line)
        carried = "k.mount_amplification = kin->first.amplification;" in code
        assert carried == any("second" in t for t in terms), wanted  # where second moves
        md = (out / "fmi2" / "modelDescription.xml").read_text()
        assert 'name="amplification"' in md


def test_the_generic_scenes_are_the_per_type_fmus():
    for t in ("rrr", "rrt", "rtr", "trt", "rtt"):
        done = run_tool(SCENES_DIR / f"dyad_{t}.toml", "--cmake-info")
        assert done.returncode == 0 and done.stdout.split(";")[:2] == [f"dyad_{t}", "generic"]
    for name in scenes.NAMES:
        done = run_tool(SCENES_DIR / f"{name}.toml", "--cmake-info")
        # the press is the tailored example of external kinematics; the rest solve their own
        assert done.stdout.split(";")[1] == ("tailored" if name == "press" else "mechanism")


@pytest.mark.parametrize(
    "name, lanes",
    [("dyad_rtr", "scheduled"), ("slider_crank", "scheduled"), ("shaper", "scheduled"),
     ("tipper", "scheduled"), ("excavator", "plain"), ("loader", "plain"),
     ("press", "plain"), ("slider_crank_forward", "plain")],
)  # fmt: skip
def test_the_build_schedules_the_lanes_of_scenes_of_two_stages_at_most(name, lanes):
    """--cmake-info's third field: a generic dyad's lanes, the shaper's two dyads and the
    tipper's dyad and cylinder compile scheduled for register pressure (fmu/CMakeLists.txt);
    the excavator's dyad and three cylinders and the loader's dyad and two do not (GCC's
    time for it grows faster than the loop body), nor a scene without a batch (the press,
    tailored; a plant)."""
    done = run_tool(SCENES_DIR / f"{name}.toml", "--cmake-info")
    assert done.returncode == 0 and done.stdout.split(";")[2] == lanes, done.stdout


# ---------------------------------------------------------------------------
# the tailored FMUs
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", scenes.NAMES)
def test_tailored_fmus_validate(name):
    for version in VERSIONS:
        assert validate_fmu(str(scenes.fmu_path(name, version))) == []


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", scenes.NAMES)
def test_tailored_fmu_matches_the_reference(name, version):
    result = scenes.run(name, version, revolutions=1.0, steps=120)
    assert result.valid.all()
    # each output to 1e-12 of the largest output of its unit (a reaction moment that is
    # small beside the mechanism's moments is held to the moments' scale)
    scale = {}
    for e in result.errors:
        scale[e.unit] = max(scale.get(e.unit, 0.0), e.peak)
    for e in result.errors:
        assert e.max_abs <= 1e-12 * max(scale[e.unit], 1e-300), (e.name, e.max_abs, e.peak)
    assert {e.name for e in result.errors} == {
        n
        for n in variables(name, version)["output"]
        if n != "status" and not n.endswith("amplification")
    }


@pytest.mark.parametrize("motion", ("constant", "varying"))
@pytest.mark.parametrize("name", ("shaper", "sixbar", "rocker_slider"))
def test_chain_driving_torque_against_the_energy_balance(name, motion):
    result = scenes.run(name, 2, revolutions=1.0, steps=180, motion=motion)
    assert result.energy_residual < 1e-9, result.energy_residual
    torque = result.fmu["crank.torque"]
    assert np.ptp(torque) > 0.1 * np.max(np.abs(torque))  # a varying load


def test_energy_balance_detects_a_wrong_torque():
    source = scenes.Source("shaper")
    motion = source.motion("constant", 1.0)
    t = (np.arange(90) + 0.5) * motion.duration / 90
    kin = source.kinematics(t, motion)
    torque = source.reference(kin)["crank.torque"]
    good = scenes.energy_balance(source, motion, t, torque, t)
    bad = scenes.energy_balance(source, motion, t, torque * (1 + 1e-6), t)
    assert good < 1e-9 < bad


class Slave:
    """A scene FMU initialised at t = 0 and stepped by 1 ms (dyadfmu's fmpy wrapper)."""

    def __init__(self, name, version, tmp_path):
        self.slave = fmi_slave.Slave(scenes.fmu_path(name, version), instance_name=name)
        self.md = self.slave.md
        self.slave.initialize()
        self.t = 0.0

    def set(self, values: dict):
        self.slave.set(tuple(values), list(values.values()))

    def get(self, names):
        return np.array(self.slave.get(tuple(names)))

    def status(self):
        return self.slave.get_status()

    def log_text(self):
        return "\n".join(self.slave.messages)

    def step(self):
        self.slave.do_step(self.t, 1e-3)
        self.t += 1e-3


@pytest.mark.parametrize("name", scenes.NAMES)
def test_declared_dependencies_cover_every_true_one(name, tmp_path):
    """Perturb each input: an output that changes must list it in its dependencies."""
    md = read_model_description(str(scenes.fmu_path(name, 2)))
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    declared = {u.variable.name: {d.name for d in (u.dependencies or [])} for u in md.outputs}
    source = scenes.Source(name)
    motion = source.motion("varying", 1.0)
    kin = source.kinematics(np.array([0.37 * motion.duration]), motion)
    base = {n: float(np.asarray(kin[n])[0]) for n in inputs}
    s = Slave(name, 2, tmp_path)
    names = [v.name for v in outputs]
    s.set(base)
    s.step()
    before = s.get(names)
    for n in inputs:
        s.set({**base, n: base[n] + 1e-3 * (abs(base[n]) + 1.0)})
        s.step()
        changed = [o for o, a, b in zip(names, before, s.get(names), strict=True) if a != b]
        for o in changed:
            assert n in declared[o], f"{o} changes with {n} but does not declare it"
    s.set(base)
    s.step()
    assert np.array_equal(s.get(names), before)


@pytest.mark.parametrize("version", VERSIONS)
def test_a_singular_dyad_discards_and_names_itself(version, tmp_path):
    """External kinematics (the press): a rod normal to the guide is singular."""
    s = Slave("press", version, tmp_path)
    source = scenes.Source("press")
    motion = source.motion("constant", 1.0)
    kin = source.kinematics(np.array([0.1]), motion)
    inputs = [v.name for v in s.md.modelVariables if v.causality == "input"]
    base = {n: float(np.asarray(kin[n])[0]) for n in inputs}
    s.set(base)
    s.step()
    assert s.status() == 0
    s.set({"rod.angle": math.pi / 2})  # rod normal to the guide: i_n . i_k = 0
    with pytest.raises(FMICallException) as error:
        s.step()
    assert error.value.status == 2  # discard
    assert s.status() == 1
    assert all(math.isnan(x) for x in s.get(["crank.torque", "press.R_np.x", "press.N_mk"]))
    s.set(base)
    s.step()
    assert s.status() == 0 and math.isfinite(s.get(["crank.torque"])[0])


@pytest.mark.parametrize("version", VERSIONS)
def test_a_mechanism_that_cannot_assemble_discards_names_the_gap_and_recovers(version, tmp_path):
    """The lift's ram pushed beyond reach: doStep discards, status 4, the log names the
    dyad, the failed figure and the gap in metres, every output is NaN; back in reach it
    works again."""
    s = Slave("lift", version, tmp_path)
    outputs = [
        v.name for v in s.md.modelVariables if v.causality == "output" and v.name != "status"
    ]
    s.set({"ram.position": 0.2})
    s.step()
    assert s.status() == 0
    s.set({"ram.position": 1.5})
    with pytest.raises(FMICallException) as error:
        s.step()
    assert error.value.status == 2  # discard
    assert s.status() == 4
    assert all(math.isnan(x) for x in s.get(outputs))
    found = re.search(
        r"dyad lever cannot assemble at this driver position: \|D_m D_n\| > l_m \+ l_n "
        r"by ([0-9.e+-]+) m",
        s.log_text(),
    )
    assert found, s.log_text()
    # the gap, from the scene's geometry: O1 = (0.2, 0.4), R = (1.5, 0), arm 0.25, strut 0.4
    assert float(found.group(1)) == pytest.approx(math.hypot(1.3, 0.4) - 0.65, rel=1e-5)
    s.set({"ram.position": 0.2})
    s.step()
    assert s.status() == 0 and all(math.isfinite(x) for x in s.get(outputs))


@pytest.mark.parametrize("version", VERSIONS)
def test_a_mechanism_at_a_dead_point_is_singular(version, tmp_path):
    """The TRT slot's crank along the guide: slot and guide parallel, conditioning 0."""
    s = Slave("trt_slot", version, tmp_path)
    s.set({"crank.angle": 0.0})
    with pytest.raises(FMICallException):
        s.step()
    assert s.status() == 1
    assert "dead centre or branch point" in s.log_text()


@pytest.mark.parametrize("version", VERSIONS)
def test_a_derivative_that_overflows_says_so(version, tmp_path):
    """A seed of 1e308 given twice for the same known: the press's reactions are fine,
    their rates overflow; the derivative discards saying that, not that the reactions
    overflow."""
    s = Slave("press", version, tmp_path)
    s.set({"crank.angle": 0.3, "ram.force.x": 100.0})
    s.step()
    with pytest.raises(FMICallException) as error:
        s.slave.directional_derivative(("press.R_np.x",), ("ram.force.x",) * 2, (1e308, 1e308))
    assert error.value.status == 2  # discard
    assert "the directional derivative of dyad press is not finite" in s.log_text()
    assert "overflow double" not in s.log_text()
    assert s.status() == 0 and math.isfinite(s.get(["press.R_np.x"])[0])


@pytest.mark.parametrize("version", VERSIONS)
def test_tailored_fmu_rejects_a_bad_value_by_name(version, tmp_path):
    s = Slave("shaper", version, tmp_path)
    for name, value in (
        ("slider.force.x", math.nan),
        ("lever.length", -0.1),
        ("lever.omega", math.inf),
    ):
        with pytest.raises(FMICallException):
            s.set({name: value})
    s.step()
    assert s.status() == 0


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("dyad", ("rrr", "rrt", "rtr", "trt", "rtt"))
def test_generated_code_agrees_with_the_generic_fmu(dyad, version, tmp_path):
    """tests/scenes/tailored_<type>.toml is the generic dyad with every parameter baked in,
    so generated code on dyad_react_<type> does the work of the validating solver; on
    varied inputs around the start values both give the same outputs."""
    generic = Slave(f"dyad_{dyad}", version, tmp_path / "generic")
    tailored = Slave(f"tailored_{dyad}", version, tmp_path / "tailored")
    inputs = [v for v in tailored.md.modelVariables if v.causality == "input"]
    outputs = [
        v.name
        for v in tailored.md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    generic_outputs = [v.name for v in generic.md.modelVariables if v.causality == "output"]
    assert set(outputs) | {"status"} == set(generic_outputs)
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(200):
        values = {}
        for v in inputs:
            start = float(v.start)
            if v.unit == "rad":
                values[v.name] = start + rng.uniform(-0.3, 0.3)
            elif v.unit == "m":  # a sliding length
                values[v.name] = start * rng.uniform(0.7, 1.3)
            else:
                values[v.name] = start + rng.uniform(-1, 1) * (abs(start) + 10.0)
        generic.set(values)
        tailored.set(values)
        generic.step()
        tailored.step()
        want, got = generic.get(outputs), tailored.get(outputs)
        scale = np.max(np.abs(want[:-2]))  # the reactions, not the conditioning
        worst = max(worst, float(np.max(np.abs(got - want)[:-2]) / scale))
        assert np.allclose(got[-2:], want[-2:], rtol=1e-14)  # conditioning, amplification
    print(f"tailored_{dyad} FMI {version}: worst difference {worst:.2e} of the largest reaction")
    assert worst < 1e-13, worst

"""Mechanism FMUs driven by a hydraulic cylinder between two pins ([cylinder]), checked
by means independent of the generated code: the axial force against the virtual work of
gravity and the loads, computed from the FMU's own positions; the effective inertia J
against the kinetic energy from finite differences of those positions; Lagrange's
equation force = J s'' + dJ/dq s'^2 / 2 + (the static force); and the statuses at the
ends of the stroke (singular before the triangle stops closing, then cannot assemble, the
log naming the cylinder and the gap). Their directional derivatives are in
test_scene_derivatives, which covers every FMU of the harness's registry."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi import slave as fmi_slave

ROOT = Path(__file__).resolve().parents[2]
#: scene file -> the cylinder's working stroke (m) and the loads applied (input -> value)
SCENES = {
    ROOT / "tests" / "scenes" / "cylinder_arm.toml": (
        (0.6, 1.9),
        {"payload.force.x": -800.0, "payload.force.y": -4000.0},
    ),
    ROOT / "tests" / "scenes" / "cylinder_boom.toml": (
        (0.95, 1.45),
        {"payload.force.x": 1500.0, "payload.force.y": -6000.0},
    ),
}
GRAVITY = "gravity"


class Machine:
    """A cylinder scene's FMU with the scene's geometry, evaluated at a cylinder motion."""

    def __init__(self, scene_path: Path, version: int = 2) -> None:
        self.data = tomllib.loads(scene_path.read_text())
        ident = self.data["scene"]["identifier"]
        path = paths.built_fmu(ident, version, None, how="scripts/run-tests")
        self.slave = fmi_slave.Slave(path, instance_name=ident)
        self.slave.initialize()
        self.cyl = self.data["cylinder"]
        self.name, self.link = self.cyl["name"], self.cyl["link"]
        variables = self.slave.md.modelVariables
        self.inputs = [v.name for v in variables if v.causality == "input"]
        self.reals = [
            v.name for v in variables if v.causality == "output" and v.type in ("Real", "Float64")
        ]
        self.time = 0.0

    def at(self, length, rate=0.0, accel=0.0, loads=None) -> dict:
        """Every Real output at the cylinder's motion and the loads (a step taken)."""
        values = {f"{self.name}.length": length}
        if f"{self.name}.velocity" in self.inputs:
            values[f"{self.name}.velocity"] = rate
            values[f"{self.name}.acceleration"] = accel
        values.update(loads or {})
        self.slave.set(tuple(values), list(values.values()))
        self.slave.do_step(self.time, 1e-3)
        self.time += 1e-3
        return dict(zip(self.reals, self.slave.get(tuple(self.reals)), strict=True))

    def bodies(self, out: dict) -> dict:
        """name -> (mass, inertia, centre of mass (global), angle) of every moving body,
        from the outputs' positions and angles and the scene's numbers."""
        c, link = self.cyl, self.link
        u = _unit(out[f"{self.name}.angle"])
        a = np.array(c["base"], float)
        b = np.array([out[f"{self.name}.B.position.{x}"] for x in "xy"])
        o = np.array(c["at"], float)
        found = {
            link: (
                c["mass"],
                c["inertia"],
                o + _turn(out[f"{link}.angle"], c["com"]),
                out[f"{link}.angle"],
            )
        }
        for part, pin, sign in (("barrel", a, 1.0), ("rod", b, -1.0)):
            if part in c:
                p = c[part]
                found[part] = (
                    p["mass"],
                    p["inertia"],
                    pin + sign * p["com"] * u,
                    out[f"{self.name}.angle"],
                )
        tables = {t["name"]: t for t in self.data.get("link", [])}
        for d in self.data.get("dyad", []):
            for side, pair in (("m", "D_m"), ("n", "D_n")):
                g = d[side]
                t = tables[g]
                origin = np.array([out[f"{d['name']}.{pair}.position.{x}"] for x in "xy"])
                found[g] = (
                    t["mass"],
                    t["inertia"],
                    origin + _turn(out[f"{g}.angle"], t["com"]),
                    out[f"{g}.angle"],
                )
        return found

    def load_points(self, out: dict) -> dict:
        """[[load]] name -> its point (global), from the outputs."""
        frames = {self.link: (np.array(self.cyl["at"], float), out[f"{self.link}.angle"])}
        points = {}
        for load in self.data.get("load", []):
            origin, angle = frames[load["link"]]
            points[load["name"]] = origin + _turn(angle, load["at"])
        return points

    def potential(self, out: dict, loads: dict) -> float:
        """The potential of gravity and of the constant global loads (J)."""
        g = np.array([self.data[GRAVITY]["x"], self.data[GRAVITY]["y"]])
        v = -sum(m * g @ p for m, _, p, _ in self.bodies(out).values())
        for name, p in self.load_points(out).items():
            force = np.array([loads.get(f"{name}.force.{x}", 0.0) for x in "xy"])
            v -= force @ p
        return float(v)


def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def _turn(angle, local):
    c, s = math.cos(angle), math.sin(angle)
    x, y = local
    return np.array([c * x - s * y, s * x + c * y])


def _lengths(stroke, n=7):
    lo, hi = stroke
    return np.linspace(lo, hi, n)


@pytest.fixture(params=list(SCENES), ids=lambda p: p.stem, scope="module")
def machine(request):
    m = Machine(request.param)
    m.stroke, m.loads = SCENES[request.param]
    yield m
    m.slave.close()


def test_static_force_is_the_virtual_work_of_gravity_and_loads(machine):
    """At rest F_ax = dV/ds, V from the FMU's own positions: the force is what the
    potential of the weights and loads asks along the stroke (central differences of
    fourth order, h = 1e-4 m)."""
    h = 1e-4
    for s in _lengths(machine.stroke):
        force = machine.at(s, loads=machine.loads)[f"{machine.name}.force"]
        v = [
            machine.potential(machine.at(s + k * h, loads=machine.loads), machine.loads)
            for k in (-2, -1, 1, 2)
        ]
        dv = (v[0] - 8 * v[1] + 8 * v[2] - v[3]) / (12 * h)
        assert force == pytest.approx(dv, rel=1e-8, abs=1e-8 * abs(force)), s


def test_effective_inertia_is_the_kinetic_energy_per_unit_rate(machine):
    """J = sum m |dS/ds|^2 + I (dtheta/ds)^2 over every moving body (the link, the barrel,
    the rod, the dyads' links), the velocity ratios from central differences of the
    FMU's positions; dJ/dq against central differences of J."""
    h = 1e-5
    for s in _lengths(machine.stroke):
        out = machine.at(s)
        around = [machine.bodies(machine.at(s + k * h)) for k in (-2, -1, 1, 2)]
        j = 0.0
        for name, (mass, inertia, _, _) in around[0].items():
            p = [b[name][2] for b in around]
            a = [b[name][3] for b in around]
            v = (p[0] - 8 * p[1] + 8 * p[2] - p[3]) / (12 * h)
            w = (a[0] - 8 * a[1] + 8 * a[2] - a[3]) / (12 * h)
            j += mass * v @ v + inertia * w * w
        assert out[f"{machine.name}.J"] == pytest.approx(j, rel=1e-8), s
        js = [machine.at(s + k * h)[f"{machine.name}.J"] for k in (-2, -1, 1, 2)]
        djdq = (js[0] - 8 * js[1] + 8 * js[2] - js[3]) / (12 * h)
        assert out[f"{machine.name}.dJdq"] == pytest.approx(djdq, rel=1e-6, abs=1e-6 * abs(j)), s


def test_force_obeys_lagranges_equation(machine):
    """F(s, s', s'') = J s'' + dJ/dq s'^2 / 2 + F(s, 0, 0): the force at rest, J and dJ/dq
    each checked above, the dynamic force against them to round-off; force0 is the
    force at s'' = 0."""
    name = machine.name
    for s in _lengths(machine.stroke):
        rest = machine.at(s, loads=machine.loads)
        for rate, accel in ((0.12, 0.0), (-0.2, 0.7), (0.05, -1.5)):
            moving = machine.at(s, rate, accel, machine.loads)
            expected = (
                rest[f"{name}.J"] * accel
                + 0.5 * rest[f"{name}.dJdq"] * rate**2
                + rest[f"{name}.force"]
            )
            scale = abs(rest[f"{name}.force"]) + abs(rest[f"{name}.J"] * accel)
            assert moving[f"{name}.force"] == pytest.approx(expected, abs=1e-12 * scale)
            zero = moving[f"{name}.force"] - moving[f"{name}.J"] * accel
            assert moving[f"{name}.force0"] == pytest.approx(zero, abs=1e-12 * scale)


def test_pin_b_and_the_link_agree(machine):
    """B = O + R(theta) pin and |AB| = s, u = (B - A)/s: the outputs' geometry closes."""
    c = machine.cyl
    for s in _lengths(machine.stroke):
        out = machine.at(s)
        b = np.array([out[f"{machine.name}.B.position.{x}"] for x in "xy"])
        expected = np.array(c["at"], float) + _turn(out[f"{machine.link}.angle"], c["pin"])
        assert np.allclose(b, expected, rtol=0, atol=1e-14 * 4)
        ab = b - np.array(c["base"], float)
        assert np.linalg.norm(ab) == pytest.approx(s, rel=1e-14)
        assert np.allclose(ab / s, _unit(out[f"{machine.name}.angle"]), atol=1e-14)


def _status_at(machine, s):
    """(status, log text) of a step at length s."""
    try:
        machine.at(s)
    except fmi_slave.SlaveError as error:
        return machine.slave.get("status"), str(error)
    return 0, ""


@pytest.mark.parametrize("end", ["longest", "shortest"])
def test_stroke_ends_are_singular_then_cannot_assemble(end):
    """Towards either end of the stroke, where O, A and B fall in line (the toggle, the
    triangle's limit): status 0, then 1 within about 1e-8 of the limit (before the motion
    loses half its digits), then beyond it 4, the refused step naming the cylinder and the
    gap in metres."""
    machine = Machine(ROOT / "tests" / "scenes" / "cylinder_arm.toml")
    c = machine.cyl
    oa = float(np.linalg.norm(np.array(c["base"], float) - np.array(c["at"], float)))
    ob = math.hypot(*c["pin"])
    limit, inward = (oa + ob, -1.0) if end == "longest" else (ob - oa, 1.0)
    statuses = {}
    for k in range(1, 13):
        status, text = _status_at(machine, limit + inward * 10.0**-k)
        statuses[k] = status
        assert status in (0, 1), (k, text)
        assert status == 0 or f"cylinder {machine.name} is at or near" in text
    assert statuses[2] == 0 and statuses[12] == 1, statuses
    assert sorted(statuses.values()) == list(statuses.values())  # 0 until it turns 1
    for gap in (1e-6, 1e-3, 0.05):
        status, text = _status_at(machine, limit - inward * gap)
        assert status == 4, text
        assert f"cylinder {machine.name} cannot assemble" in text
        said = float(text.split(" by ")[1].split(" m")[0])
        assert said == pytest.approx(gap, rel=1e-5)
    machine.slave.close()

"""Loads where they act ([[load]] tables, modelDescription/scenes/four_bar_payload.toml):

- every Real output of the scene's FMU against the mpmath Newton-Euler reference of the
  whole mechanism (dyadfmu.reference.scene_mp, which places each load as a force at its
  point), over the crank's turn and both branches, within 1e-12 of its unit's peak;
- a load at a point equals the same load at the centre of mass plus its moment r x F;
- a follower force on the crank turns with it: its torque about O is the same at every
  angle, its share of R_O turns with the crank;
- (the directional derivatives: test_scene_derivatives, which covers every FMU of the
  harness's registry, this scene's among them);
- the energy balance over the turn: the driver's and the loads' power equal the rate of
  kinetic and potential energy;
- the refusals of malformed [[load]] tables, each at its file:line.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest
from dyadfmu.reference import scene_mp
from test_scene_mp import inputs_at, run_fmu, scene_file, unit_errors

NAME = "four_bar_payload"
ANGLES = tuple(2 * math.pi * (k + 0.3) / 12 for k in range(12))
COM = (0.075, 0.006)  # the coupler's centre of mass (m, its frame)
TOOL_AT = (0.07, 0.01)  # the tool load's point on the crank (m, its frame)
SCENE_TOOL = Path(__file__).resolve().parents[2] / "modelDescription" / "scene.py"


def test_every_output_against_the_reference_over_the_turn():
    """Every Real output but the amplification within 1e-12 of its unit's peak."""
    scene = scene_mp.read_scene(scene_file(NAME))
    cases = [({"linkage.branch": b}, [inputs_at(scene, q) for q in ANGLES]) for b in (1.0, -1.0)]
    runs = iter(run_fmu(NAME, cases))
    worst = (0.0, "")
    for params, rows in cases:
        for values in rows:
            status, got, units = next(runs)
            assert status == 0
            ref = scene_mp.evaluate(scene, {**values, **params}, dps=30)
            assert ref.status == scene_mp.OK, ref.reason
            units = {k: u for k, u in units.items() if not k.endswith("amplification")}
            for key, err in unit_errors(got, ref.outputs, units).items():
                worst = max(worst, (err, f"{key} at {values['crank.angle']:.3f} {params}"))
    print("worst error / unit peak:", worst)
    assert worst[0] < 1e-12, worst


def _quiet(scene, q):
    """The inputs at crank angle q, every load 0."""
    values = inputs_at(scene, q)
    return {k: (0.0 if k.split(".")[0] != "crank" else v) for k, v in values.items()}


def test_load_at_a_point_equals_it_at_the_centre_of_mass_plus_r_x_f():
    """The payload at P against the payload at the centre of mass C with the moment
    (P - C) x F, P - C turned by the coupler's angle: every output alike to round-off."""
    scene = scene_mp.read_scene(scene_file(NAME))
    point = (0.11, 0.045)
    force = (-310.0, 570.0)
    at_point, at_com = [], []
    for q in ANGLES[:6]:
        values = {**_quiet(scene, q), "payload.force.x": force[0], "payload.force.y": force[1]}
        at_point.append(values)
        at_com.append(dict(values))
    params_p = {"payload.at.x": point[0], "payload.at.y": point[1]}
    params_c = {"payload.at.x": COM[0], "payload.at.y": COM[1]}
    first = run_fmu(NAME, [(params_p, at_point)])
    for values, (_, got, _) in zip(at_com, first, strict=True):
        theta = got["coupler.angle"]
        dx, dy = point[0] - COM[0], point[1] - COM[1]
        rx, ry = (
            dx * math.cos(theta) - dy * math.sin(theta),
            dx * math.sin(theta) + dy * math.cos(theta),
        )
        values["payload.moment"] = rx * force[1] - ry * force[0]
    second = run_fmu(NAME, [(params_c, at_com)])
    worst = 0.0
    for (_, a, units), (_, b, _) in zip(first, second, strict=True):
        units = {k: u for k, u in units.items() if not k.endswith("amplification")}
        worst = max(worst, *unit_errors(a, b, units).values())
    print("moved load, worst difference / unit peak:", worst)
    assert worst < 1e-13


def test_a_follower_force_turns_with_the_crank():
    """The tool's follower force adds -(at x F_local) to the torque at every angle, and
    -R(phi) F_local to R_O (the loads on the crank reach no dyad)."""
    scene = scene_mp.read_scene(scene_file(NAME))
    local = (120.0, -45.0)
    base = [_quiet(scene, q) for q in ANGLES]
    loaded = [{**v, "tool.force.x": local[0], "tool.force.y": local[1]} for v in base]
    without = run_fmu(NAME, [({}, base)])
    with_tool = run_fmu(NAME, [({}, loaded)])
    torque = -(TOOL_AT[0] * local[1] - TOOL_AT[1] * local[0])
    for q, (_, a, _), (_, b, _) in zip(ANGLES, without, with_tool, strict=True):
        c, s = math.cos(q), math.sin(q)
        assert b["crank.torque"] - a["crank.torque"] == pytest.approx(torque, abs=1e-11)
        fx, fy = c * local[0] - s * local[1], s * local[0] + c * local[1]
        assert b["crank.R_O.x"] - a["crank.R_O.x"] == pytest.approx(-fx, abs=1e-10)
        assert b["crank.R_O.y"] - a["crank.R_O.y"] == pytest.approx(-fy, abs=1e-10)


BAD = {
    "unknown link": ('name = "w"\nlink = "boom"\nat = [0.1, 0.0]\n', "unknown link 'boom'"),
    "non-finite at": ('name = "w"\nlink = "coupler"\nat = [nan, 0.0]\n', "'at' must be"),
    "absurd at": ('name = "w"\nlink = "coupler"\nat = [1e9, 0.0]\n', "'at' must be"),
    "clash": ('name = "rocker"\nlink = "coupler"\n', "already the scene's"),
    "unknown key": ('name = "w"\nlink = "coupler"\nwhere = 1\n', "unknown key 'where'"),
    "components": ('name = "w"\nlink = "coupler"\ncomponents = "local"\n', "components must"),
}


@pytest.mark.parametrize("case", sorted(BAD) + ["duplicate"])
def test_malformed_loads_are_refused_at_their_line(case, tmp_path):
    """Each malformed [[load]] refused in one line naming the file and the table's line."""
    text = scene_file(NAME).read_text(encoding="utf-8")
    if case == "duplicate":
        table, words = 'name = "payload"\nlink = "rocker"\n', "described twice"
    else:
        table, words = BAD[case]
    text += "\n[[load]]\n" + table
    line = text.count("\n", 0, text.rindex("[[load]]")) + 1
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    done = subprocess.run(
        [sys.executable, str(SCENE_TOOL), str(path), "--check"], capture_output=True, text=True
    )
    assert done.returncode != 0
    found = [x for x in done.stderr.splitlines() if words in x]
    assert found, done.stderr
    where = found[0].removeprefix("error: ")
    assert where.startswith("bad.toml:"), found
    assert line <= int(where.split(":")[1]) <= line + 4, (line, found)


def _rot(theta, p):
    c, s = math.cos(theta), math.sin(theta)
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


class _Body:
    """A link at one instant, from the FMU's outputs: origin D with its velocity and
    acceleration, angle, angular velocity and acceleration."""

    def __init__(self, d, v_d, a_d, theta, w, e):
        self.d, self.v_d, self.a_d, self.theta, self.w, self.e = d, v_d, a_d, theta, w, e

    def velocity(self, p):
        r = _rot(self.theta, p)
        return (self.v_d[0] - self.w * r[1], self.v_d[1] + self.w * r[0])

    def acceleration(self, p):
        r = _rot(self.theta, p)
        w2 = self.w * self.w
        return (
            self.a_d[0] - self.e * r[1] - w2 * r[0],
            self.a_d[1] + self.e * r[0] - w2 * r[1],
        )


#: (mass kg, inertia kg m2, centre of mass m) of the scene's links
LINKS = {
    "crank": (0.25, 8.0e-5, (0.02, 0.003)),
    "rocker": (0.30, 4.0e-4, (0.05, -0.008)),
    "coupler": (0.35, 6.6e-4, COM),
}


def _bodies(values, got):
    """The three moving links from the crank's inputs and the FMU's outputs alone."""
    q, w, e = values["crank.angle"], values["crank.omega"], values["crank.epsilon"]
    zero = (0.0, 0.0)
    crank = _Body(zero, zero, zero, q, w, e)
    a_pin = (got["linkage.D_n.position.x"], got["linkage.D_n.position.y"])
    o4 = (got["linkage.D_m.position.x"], got["linkage.D_m.position.y"])
    pin_local = _rot(-q, a_pin)
    coupler = _Body(
        a_pin,
        crank.velocity(pin_local),
        crank.acceleration(pin_local),
        got["coupler.angle"],
        got["coupler.omega"],
        got["coupler.epsilon"],
    )
    rocker = _Body(o4, zero, zero, got["rocker.angle"], got["rocker.omega"], got["rocker.epsilon"])
    return {"crank": crank, "rocker": rocker, "coupler": coupler}


def _power_terms(values, got, at):
    """(rate of kinetic + potential energy, driver's power, loads' powers) in W."""
    bodies = _bodies(values, got)
    gravity = (0.0, -9.81)
    rate = 0.0
    for name, (mass, inertia, com) in LINKS.items():
        b = bodies[name]
        a = b.acceleration(com)
        rate += mass * _dot(b.velocity(com), (a[0] - gravity[0], a[1] - gravity[1]))
        rate += inertia * b.w * b.e
    c, k = bodies["crank"], bodies["coupler"]
    loads = [
        values["rocker.moment"] * bodies["rocker"].w,
        _dot((values["payload.force.x"], values["payload.force.y"]), k.velocity(at)),
        values["payload.moment"] * k.w,
        _dot(_rot(k.theta, (values["drag.force.x"], values["drag.force.y"])), k.velocity(COM)),
        _dot(_rot(c.theta, (values["tool.force.x"], values["tool.force.y"])), c.velocity(TOOL_AT)),
        values["tool.moment"] * c.w,
    ]
    return rate, got["crank.torque"] * c.w, loads


def test_energy_balance_over_the_turn():
    """The driver's power plus the loads' power equals the rate of kinetic and potential
    energy, every term from the crank's inputs and the FMU's outputs (no reference
    kinematics), within 1e-9 of the peak power over the turn."""
    scene = scene_mp.read_scene(scene_file(NAME))
    rows = []
    for k, q in enumerate(ANGLES):
        values = inputs_at(scene, q)
        for n, key in enumerate(sorted(values)):
            if values[key] in (-850.0, 420.0, -3.5):  # every load its own number
                values[key] *= 1.0 + 0.37 * ((n + k) % 5)
        rows.append(values)
    at = (0.11, 0.045)
    runs = run_fmu(NAME, [({}, rows)])
    residuals, peak = [], 0.0
    for values, (_, got, _) in zip(rows, runs, strict=True):
        rate, driver, loads = _power_terms(values, got, at)
        residuals.append(abs(driver + sum(loads) - rate))
        peak = max(peak, abs(rate), abs(driver), *(abs(x) for x in loads))
    print("energy balance, worst residual / peak power:", max(residuals) / peak)
    assert max(residuals) < 1e-9 * peak

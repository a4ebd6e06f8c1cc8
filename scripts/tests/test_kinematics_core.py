"""The Python binding of the core's kinematics (Core.kinematics, Core.kinematics_tangent):
statuses, names, a failure with its gap, an invalid field, a slider-crank against its
textbook closed form, and the tangent along the motion."""

import math

import pytest
from dyadfmu.core import Core, library_path

pytestmark = pytest.mark.skipif(
    not library_path().is_file(), reason=f"C core not built at {library_path()}"
)


@pytest.fixture(scope="module")
def core():
    return Core()


def _slider_crank(theta=0.4, omega=3.0, r=0.5, rod=1.7):
    """Crank pin D_n on a circle of radius r about the origin, turning at omega; the slider
    D_m on the x axis, its pin on the guide (l_m = 0)."""
    c, s = math.cos(theta), math.sin(theta)
    return {
        "k": {"guide": (1.0, 0.0)},
        "p": {
            "position": (r * c, r * s),
            "velocity": (-r * omega * s, r * omega * c),
            "acceleration": (-r * omega**2 * c, -r * omega**2 * s),
        },
        "length_m": 0.0,
        "length_n": rod,
        "branch": 1,
    }


def test_slider_crank_matches_its_closed_form(core):
    theta, omega, r, rod = 0.4, 3.0, 0.5, 1.7
    out = core.kinematics("RRT", _slider_crank(theta, omega, r, rod))
    assert out["status"] == "ok" and out["field"] == "" and out["failure"] == ""

    def x(t):
        return r * math.cos(t) + math.sqrt(rod**2 - (r * math.sin(t)) ** 2)

    h = 1e-4
    assert out["slide_k"]["s"] == pytest.approx(x(theta), rel=1e-14)
    rate = (x(theta + h) - x(theta - h)) / (2 * h) * omega
    accel = (x(theta + h) - 2 * x(theta) + x(theta - h)) / h**2 * omega**2
    assert out["slide_k"]["rate"] == pytest.approx(rate, rel=1e-7)
    assert out["slide_k"]["accel"] == pytest.approx(accel, rel=1e-5)
    assert out["m"]["d"]["position"] == pytest.approx((x(theta), 0.0))
    # E is D_m (l_m = 0); link n points from the crank pin to it.
    dx, dy = x(theta) - r * math.cos(theta), -r * math.sin(theta)
    assert out["n"]["angle"] == pytest.approx(math.atan2(dy, dx), rel=1e-13)
    assert out["conditioning"] == pytest.approx(abs(dx) / rod, rel=1e-13)
    # the rod's end E = D_m runs on the guide line, which passes r sin(theta) from the pin:
    # the closure is (rod - |dy|) over the size of the terms it is formed from
    size = rod + abs(dy) + abs(r * math.cos(theta)) + abs(r * math.sin(theta))
    closure = (rod - abs(dy)) / size
    assert out["closure"] == pytest.approx(closure, rel=1e-13)
    assert out["amplification"] == pytest.approx(
        1 + 1 / out["closure"] + 1 / out["conditioning"], rel=1e-15
    )


def test_failure_reports_its_figure_and_gap(core):
    inputs = {"p": {"position": (5.0, 0.0)}, "length_m": 1.0, "length_n": 2.0}
    out = core.kinematics("RRR", inputs)
    assert out["status"] == "cannot assemble"
    assert out["failure"] == "|D_m D_n| > l_m + l_n"
    assert out["gap"] == pytest.approx(2.0, rel=1e-15)
    assert math.isnan(out["m"]["omega"]) and math.isnan(out["conditioning"])
    value, rate = core.kinematics_tangent("RRR", inputs, {"p": {"position": (1.0, 0.0)}})
    assert value["gap"] == out["gap"] and rate["gap"] == pytest.approx(1.0)


def test_singular_and_invalid_are_named(core):
    out = core.kinematics("TRT", {"p": {"position": (1.0, 1.0), "guide": (-1.0, 0.0)}})
    assert out["status"] == "singular" and out["conditioning"] == 0.0
    out = core.kinematics("RRT", {"k": {"guide": (0.0, 2.0)}})
    assert out["status"] == "invalid input" and out["field"] == "k.guide"
    out = core.kinematics("RTR", {"branch": 0})
    assert out["status"] == "invalid input" and out["field"] == "branch"
    out = core.kinematics("RRR", {"length_m": float("nan")})
    assert out["field"] == "length_m"
    # RRR reads no guide: a NaN there changes nothing.
    good = core.kinematics("RRR", {"p": {"position": (1.0, 1.0)}})
    bad = core.kinematics("RRR", {"p": {"position": (1.0, 1.0)}, "k": {"guide": (math.nan, 0)}})
    assert good["status"] == bad["status"] == "ok" and good["m"] == bad["m"]
    with pytest.raises(ValueError):
        core.kinematics("RRX", {})


def test_tangent_along_the_motion_gives_the_velocities(core):
    inputs = _slider_crank()
    p = inputs["p"]
    seed = {"p": {"position": p["velocity"], "velocity": p["acceleration"]}}
    value, rate = core.kinematics_tangent("RRT", inputs, seed)
    assert value == core.kinematics("RRT", inputs)
    assert rate["slide_k"]["s"] == pytest.approx(value["slide_k"]["rate"], rel=1e-13)
    assert rate["slide_k"]["rate"] == pytest.approx(value["slide_k"]["accel"], rel=1e-12)
    assert rate["n"]["angle"] == pytest.approx(value["n"]["omega"], rel=1e-13)
    assert rate["n"]["omega"] == pytest.approx(value["n"]["epsilon"], rel=1e-12)
    assert rate["e"]["position"] == pytest.approx(value["e"]["velocity"], rel=1e-13)

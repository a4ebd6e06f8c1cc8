"""The core's closed-form kinematics (C) against the independent mpmath reference
(dyadfmu.reference.dyad_kinematics: the closure solved by findroot, its derivatives by
implicit differentiation at 40 digits), on random dyads of every type and both branches,
and on the way to a branch point, where the conditioning falls and the flag must trip
before the outputs lose half their digits."""

import math

import mpmath
import numpy as np
import pytest
from dyadfmu.core import Core, library_path
from dyadfmu.reference import dyad_kinematics as ref

pytestmark = pytest.mark.skipif(
    not library_path().is_file(), reason=f"C core not built at {library_path()}"
)
EPS = np.finfo(float).eps
TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
BRANCHED = ("RRR", "RRT", "RTR")


@pytest.fixture(scope="module")
def core():
    return Core()


def _vec(rng, scale):
    return tuple(float(x) for x in rng.normal(0.0, scale, 2))


def _case(rng, dyad_type, branch):
    """A random dyad built so that it closes: its pins and guides around a random E."""
    e = np.array(_vec(rng, 0.5))
    angle_m, angle_n = rng.uniform(-math.pi, math.pi, 2)
    l_m, l_n = rng.uniform(0.3, 1.2, 2)
    i_m = np.array([math.cos(angle_m), math.sin(angle_m)])
    i_n = np.array([math.cos(angle_n), math.sin(angle_n)])
    d_m, d_n = e - l_m * i_m, e - l_n * i_n
    guide_k, guide_p = rng.uniform(-math.pi, math.pi, 2)
    turn_m, turn_n = (float(x) for x in rng.uniform(-0.6, 0.6, 2))
    mount = {}
    for side, point, guide in (("k", d_m, guide_k), ("p", d_n, guide_p)):
        g = np.array([math.cos(guide), math.sin(guide)])
        mount[side] = {
            "point": tuple(point - rng.uniform(-0.5, 0.5) * g),  # a point of the guide line
            "velocity": _vec(rng, 1.0),
            "acceleration": _vec(rng, 3.0),
            "guide": guide,
            "omega": float(rng.normal(0.0, 1.0)),
            "epsilon": float(rng.normal(0.0, 3.0)),
        }
    return {
        "type": dyad_type,
        "mount": mount,
        "l_m": float(l_m),
        "l_n": float(l_n),
        "turn_m": turn_m,
        "turn_n": turn_n,
        "com_m": _vec(rng, 0.2),
        "com_n": _vec(rng, 0.2),
        "branch": branch,
    }


def _as_core(case):
    slides = {"RRR": "", "RRT": "k", "RTR": "", "TRT": "kp", "RTT": "k"}[case["type"]]
    inputs = {}
    for side in "kp":
        m = case["mount"][side]
        # a revolute outer pair: the pin is the link's D (on the guide line only for a slide)
        inputs[side] = {
            "position": m["point"],
            "velocity": m["velocity"],
            "acceleration": m["acceleration"],
            "guide": (math.cos(m["guide"]), math.sin(m["guide"])),
            "omega": m["omega"] if side in slides else 0.0,
            "epsilon": m["epsilon"] if side in slides else 0.0,
        }
    for key in ("turn_m", "turn_n"):
        inputs[key] = (math.cos(case[key]), math.sin(case[key]))
    inputs.update(
        length_m=case["l_m"],
        length_n=case["l_n"],
        com_m=case["com_m"],
        com_n=case["com_n"],
        branch=case["branch"],
    )
    return inputs


def _as_reference(case):
    slides = {"RRR": "", "RRT": "k", "RTR": "", "TRT": "kp", "RTT": "k"}[case["type"]]
    mounts = {}
    for side in "kp":
        m = case["mount"][side]
        sliding = side in slides
        mounts[side] = ref.Mount(
            m["point"],
            m["velocity"],
            m["acceleration"],
            direction=m["guide"],
            omega=m["omega"] if sliding else 0.0,
            epsilon=m["epsilon"] if sliding else 0.0,
        )
    return ref.DyadInputs(
        case["type"],
        mounts["k"],
        mounts["p"],
        length_m=case["l_m"],
        length_n=case["l_n"],
        turn_m=case["turn_m"],
        turn_n=case["turn_n"],
        com_m=case["com_m"],
        com_n=case["com_n"],
        branch=case["branch"],
    )


def _pairs(c, r):
    """(name, C value, reference value) of every output both give."""
    out = []
    for g in "mn":
        cg = c[g]
        out += [
            (f"i_{g}", cg["dir"], r[f"i_{g}"]),
            (f"omega_{g}", cg["omega"], r[f"omega_{g}"]),
            (f"epsilon_{g}", cg["epsilon"], r[f"epsilon_{g}"]),
        ]
        for what, key in (("position", "position"), ("velocity", "velocity")):
            out.append((f"{g}.d.{what}", cg["d"][key], r[f"{g}.d.{what}"]))
            out.append((f"{g}.com.{what}", cg["com"][key], r[f"{g}.s.{what}"]))
        out.append((f"{g}.d.acceleration", cg["d"]["acceleration"], r[f"{g}.d.acceleration"]))
        out.append((f"{g}.com.acceleration", cg["com"]["acceleration"], r[f"{g}.s.acceleration"]))
    out += [
        ("l_m", c["m"]["length"], r["l_m"]),
        ("l_m_dot", c["m"]["length_rate"], r["l_m_dot"]),
        ("l_m_ddot", c["m"]["length_accel"], r["l_m_ddot"]),
        ("e.position", c["e"]["position"], r["e.position"]),
        ("e.velocity", c["e"]["velocity"], r["e.velocity"]),
        ("e.acceleration", c["e"]["acceleration"], r["e.acceleration"]),
    ]
    for side in "kp":
        if f"s_{side}" in r:
            slide = c[f"slide_{side}"]
            out += [
                (f"s_{side}", slide["s"], r[f"s_{side}"]),
                (f"s_{side}_dot", slide["rate"], r[f"s_{side}_dot"]),
                (f"s_{side}_ddot", slide["accel"], r[f"s_{side}_ddot"]),
            ]
    return out


def _errors(c, r):
    """Each output's error relative to the largest output of its kind (position,
    velocity or acceleration level), as numbers."""
    worst = {}
    for name, got, want in _pairs(c, r):
        got = np.atleast_1d(np.asarray(got, dtype=float))
        want = np.atleast_1d(np.array([float(x) for x in np.atleast_1d(want)]))
        worst[name] = (float(np.max(np.abs(got - want))), float(np.max(np.abs(want))))
    return worst


def _level(name):
    if "acceleration" in name or "epsilon" in name or name.endswith("ddot"):
        return "acceleration"
    if "velocity" in name or "omega" in name or name.endswith("dot"):
        return "velocity"
    return "position"


@pytest.mark.parametrize("dyad_type", TYPES)
def test_random_dyads_agree_with_mpmath(core, dyad_type):
    """Every output within 1e3 eps x amplification of the largest output of its level."""
    rng = np.random.default_rng(sum(map(ord, dyad_type)))
    checked = 0
    for _ in range(6):
        for branch in (1, -1) if dyad_type in BRANCHED else (1,):
            case = _case(rng, dyad_type, branch)
            c = core.kinematics(dyad_type, _as_core(case))
            r = ref.solve(_as_reference(case), dps=30)
            if r["status"] != "ok" or c["status"] != "ok":
                assert r["status"] == c["status"] or c["conditioning"] < 1e-6
                continue
            errors = _errors(c, r)
            scale = {}
            for name, (_, peak) in errors.items():
                scale[_level(name)] = max(scale.get(_level(name), 0.0), peak)
            for name, (error, _) in errors.items():
                bound = 1e3 * EPS * c["amplification"] * scale[_level(name)]
                assert error <= bound, (dyad_type, branch, name, error, bound)
            checked += 1
    assert checked >= 4


def test_rrr_towards_full_extension_keeps_half_the_digits_until_the_flag(core):
    """An RRR opened towards full extension: the conditioning falls like the gap's
    square root; until it falls below the singular threshold every output's error
    against mpmath stays within 10 eps x amplification of its level, which is at most
    sqrt(eps) of it at the flag; past it the status is singular."""
    l_m, l_n = 0.7, 0.5
    mpmath.mp.dps = 40
    tripped = False
    for gap in [10.0 ** (-k) for k in range(1, 16)] + [0.0]:  # |D_m D_n| = l_m + l_n - gap
        reach = l_m + l_n - gap
        inputs = {
            "k": {"position": (0.0, 0.0), "velocity": (0.1, -0.2), "acceleration": (0.3, 0.1)},
            "p": {"position": (reach, 0.0), "velocity": (0.05, 0.4), "acceleration": (-0.2, 0.5)},
            "length_m": l_m,
            "length_n": l_n,
            "branch": 1,
        }
        c = core.kinematics("RRR", inputs)
        if c["status"] == "singular":
            tripped = True
            assert c["conditioning"] < 1.4901161193847656e-8
            assert math.isnan(c["m"]["omega"]) and math.isnan(c["e"]["position"][0])
            break
        assert c["status"] == "ok"
        case = ref.DyadInputs(
            "RRR",
            ref.Mount((0.0, 0.0), (0.1, -0.2), (0.3, 0.1)),
            ref.Mount((reach, 0.0), (0.05, 0.4), (-0.2, 0.5)),
            length_m=l_m,
            length_n=l_n,
        )
        r = ref.solve(case, dps=40)
        errors = _errors(c, r)
        scale = {}
        for name, (_, peak) in errors.items():
            scale[_level(name)] = max(scale.get(_level(name), 0.0), peak)
        for name, (error, _) in errors.items():
            bound = 10 * EPS * c["amplification"] * scale[_level(name)]
            assert error <= bound, (gap, name, error, bound)
    assert tripped, "the flag never tripped on the way to full extension"
    assert gap < 1e-15  # it held every output to 10 eps x amplification down to gap 1e-15

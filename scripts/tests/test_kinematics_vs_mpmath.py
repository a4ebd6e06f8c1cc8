"""The core's closed-form kinematics (C) against the independent mpmath reference
(dyadfmu.reference.dyad_kinematics: the closure solved by findroot, its derivatives by
implicit differentiation), on random dyads of every type and both branches, and on the
way to each toggle or branch point of the types that close in two ways, where the
closure's root loses digits like eps / conditioning^2: every output stays within
10 eps x amplification of the largest of its level, and the status turns singular before
the outputs lose half their digits and before the dyad stops closing."""

import math

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
    """Every output within 10 eps x amplification of the largest output of its level."""
    rng = np.random.default_rng(sum(map(ord, dyad_type)))
    checked = 0
    for _ in range(6):
        for branch in (1, -1) if dyad_type in BRANCHED else (1,):
            case = _case(rng, dyad_type, branch)
            c = core.kinematics(dyad_type, _as_core(case))
            r = ref.solve(_as_reference(case), dps=30)
            if r["status"] != "ok" or c["status"] != "ok":
                assert r["status"] == c["status"] or c["amplification"] > 1e6
                continue
            for name, error, scale in _scaled_errors(c, r):
                bound = 10 * EPS * c["amplification"] * scale
                assert error <= bound, (dyad_type, branch, name, error, bound)
            checked += 1
    assert checked >= 4


def _scaled_errors(c, r):
    """(name, error, largest output of its level) of every output."""
    errors = _errors(c, r)
    scale = {}
    for name, (_, peak) in errors.items():
        scale[_level(name)] = max(scale.get(_level(name), 0.0), peak)
    return [(name, error, scale[_level(name)]) for name, (error, _) in errors.items()]


def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def _toggle_case(rng, limit, gap):
    """A dyad whose closure's root has the argument `gap` (m, before the inputs are
    rounded to double): RRR near full extension ("far") or folding ("near"), RRT with
    D_n `gap` inside reach of the line E runs on, RTR with the slot `gap` inside reach
    of D_n. Positions and directions in general position, so that every coordinate is
    rounded."""
    dyad_type = {"far": "RRR", "near": "RRR", "line": "RRT", "slot": "RTR"}[limit]
    l_m, l_n = (float(x) for x in rng.uniform(0.3, 1.2, 2))
    d_m = rng.normal(0.0, 1.0, 2)
    u = _unit(rng.uniform(-math.pi, math.pi))
    guide = float(rng.uniform(-math.pi, math.pi))
    turn_m, turn_n = (float(x) for x in rng.uniform(-1.2, 1.2, 2))
    if limit == "far":
        d_n = d_m + (l_m + l_n - gap) * u
    elif limit == "near":
        d_n = d_m + (abs(l_m - l_n) + gap) * u
    elif limit == "line":  # E runs on the line through D_m + l_m i_m along the guide
        i_k = _unit(guide)
        foot = d_m + l_m * _unit(guide + turn_m) + rng.uniform(-0.5, 0.5) * i_k
        d_n = foot + (l_n - gap) * _unit(guide + math.pi / 2)
    else:  # the slot reaches l_n |sin turn_n| from D_m; its E stays ahead of D_m
        turn_n = math.copysign(rng.uniform(0.3, 1.2), turn_n)
        d_n = d_m + (l_n * abs(math.sin(turn_n)) + gap) * u
    mounts = {}
    for side, point in (("k", d_m), ("p", d_n)):
        mounts[side] = {
            "point": tuple(float(x) for x in point),
            "velocity": tuple(float(x) for x in rng.normal(0.0, 1.0, 2)),
            "acceleration": tuple(float(x) for x in rng.normal(0.0, 3.0, 2)),
            "guide": guide,
            "omega": float(rng.normal(0.0, 1.0)),
            "epsilon": float(rng.normal(0.0, 3.0)),
        }
    return {
        "type": dyad_type,
        "mount": mounts,
        "l_m": l_m,
        "l_n": l_n,
        "turn_m": turn_m,
        "turn_n": turn_n,
        "com_m": (0.1, -0.05),
        "com_n": (0.2, 0.03),
        "branch": 1 if limit != "slot" else int(np.sign(math.cos(turn_n)) or 1),
    }


LIMITS = ("far", "near", "line", "slot")


@pytest.mark.parametrize("limit", LIMITS)
def test_toggles_are_bounded_by_the_amplification(core, limit):
    """On the way to the toggle, gap 1e-2 to 1e-16 m, with a threshold that never trips:
    every output within 10 eps x amplification of the largest of its level against
    mpmath at 50 digits, though the error itself grows to 1e-3 and beyond."""
    rng = np.random.default_rng(LIMITS.index(limit) + 11)
    checked, largest = 0, 0.0
    for first in (2, 3):
        for k in range(first, 17, 2):
            case = _toggle_case(rng, limit, 10.0**-k)
            inputs = _as_core(case) | {"singular_threshold": 1e-300}
            c = core.kinematics(case["type"], inputs)
            r = ref.solve(_as_reference(case), dps=50)
            if c["status"] != "ok" or r["status"] != "ok":
                continue  # rounded past the limit
            for name, error, scale in _scaled_errors(c, r):
                largest = max(largest, error / scale)
                assert error <= 10 * EPS * c["amplification"] * scale, (limit, k, name)
            checked += 1
    assert checked >= 12
    assert largest > 1e-6  # the toggle was reached: the bound held where it mattered


@pytest.mark.parametrize("limit", LIMITS)
def test_singular_before_cannot_assemble_and_half_the_digits(core, limit):
    """Closing in on the toggle with the default threshold: the status goes from ok to
    singular (never straight to cannot assemble), and at the last ok gap every output
    keeps half its digits (error below sqrt(eps) of the largest of its level)."""
    rng = np.random.default_rng(LIMITS.index(limit) + 23)
    for _ in range(2):
        seed = int(rng.integers(1 << 30))
        last_ok, statuses = None, []
        for k in np.arange(2.0, 16.5, 0.25):
            case = _toggle_case(np.random.default_rng(seed), limit, 10.0**-k)
            c = core.kinematics(case["type"], _as_core(case))
            statuses.append(c["status"])
            if c["status"] == "ok":
                last_ok = case
            else:
                assert c["status"] == "singular", (limit, k, c["status"])
                assert 1 / c["amplification"] < 1.4901161193847656e-8
                break
        assert "singular" in statuses, (limit, statuses)
        c = core.kinematics(last_ok["type"], _as_core(last_ok))
        r = ref.solve(_as_reference(last_ok), dps=50)
        assert EPS * c["amplification"] <= math.sqrt(EPS)
        for name, error, scale in _scaled_errors(c, r):
            assert error <= math.sqrt(EPS) * scale, (limit, name, error / scale)

"""Input sets for the accuracy and speed study, as arrays of configurations in
the benchmark's row layout (35 float64 per configuration, see COLUMNS).

- ``random``: well-conditioned random configurations (conditioning >= 0.1);
- ``sweep``: configurations whose type denominator runs from 1e-1 down to 1e-16;
- ``extreme``: extreme scales and stiff mixtures in one dyad;
- ``cancelling``: loads that nearly cancel as they are summed.

Every direction is a unit vector to double precision. Generation is
deterministic for a given seed.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from ..core import REACTION_SCALARS

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
PAIRS = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}
# Lengths that may be zero (m, n), as the paper states.
ZERO_OK = {
    "RRR": (False, False),
    "RRT": (True, False),
    "RTR": (False, True),
    "TRT": (True, True),
    "RTT": (False, True),
}

LINK_COLUMNS = (
    "dir.x",
    "dir.y",
    "length",
    "omega",
    "epsilon",
    "accel_d.x",
    "accel_d.y",
    "com.x",
    "com.y",
    "mass",
    "inertia",
    "force.x",
    "force.y",
    "moment",
)
COLUMNS = (
    tuple(f"m.{c}" for c in LINK_COLUMNS)
    + tuple(f"n.{c}" for c in LINK_COLUMNS)
    + (
        "guide_k.x",
        "guide_k.y",
        "guide_p.x",
        "guide_p.y",
        "gravity.x",
        "gravity.y",
        "singular_threshold",
    )
)
COL = {name: k for k, name in enumerate(COLUMNS)}

#: Output columns of the benchmark (and of `outputs_of`).
OUTPUT_COLUMNS = (
    "r_mk.x",
    "r_mk.y",
    "r_np.x",
    "r_np.y",
    "r_mn.x",
    "r_mn.y",
    *REACTION_SCALARS,
)

#: Threshold given to the solvers in the study: low enough that the core
#: solves right down to the singular position, so its error can be measured
#: (and still a normal number in float).
STUDY_THRESHOLD = 1e-30


def _unit(angle: np.ndarray):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _random_links(
    rng: np.random.Generator,
    dyad: str,
    count: int,
    length_range: tuple[float, float] = (-3, 3),
    mass_range: tuple[float, float] = (-3, 3),
    omega_max: float = 100.0,
    load_range: tuple[float, float] = (-2, 4),
):
    rows = np.zeros((count, len(COLUMNS)))
    for g, zero_ok in zip(("m", "n"), ZERO_OK[dyad], strict=False):
        length = 10.0 ** rng.uniform(*length_range, count)
        if zero_ok:
            length[rng.random(count) < 0.1] = 0.0
        size = np.where(length > 0, length, 10.0 ** rng.uniform(length_range[0], 0, count))
        mass = 10.0 ** rng.uniform(*mass_range, count)
        rows[:, [COL[f"{g}.dir.x"], COL[f"{g}.dir.y"]]] = _unit(rng.uniform(0, 2 * math.pi, count))
        rows[:, COL[f"{g}.length"]] = length
        rows[:, COL[f"{g}.omega"]] = rng.uniform(-omega_max, omega_max, count)
        rows[:, COL[f"{g}.epsilon"]] = rng.uniform(-10 * omega_max, 10 * omega_max, count)
        rows[:, [COL[f"{g}.accel_d.x"], COL[f"{g}.accel_d.y"]]] = (
            rng.uniform(-1, 1, (count, 2)) * (omega_max**2) * size[:, None]
        )
        rows[:, COL[f"{g}.com.x"]] = size * rng.uniform(-0.5, 1.5, count)
        rows[:, COL[f"{g}.com.y"]] = size * rng.uniform(-0.5, 0.5, count)
        rows[:, COL[f"{g}.mass"]] = mass
        rows[:, COL[f"{g}.inertia"]] = mass * (size * rng.uniform(0.05, 0.6, count)) ** 2
        load = 10.0 ** rng.uniform(*load_range, count)
        rows[:, [COL[f"{g}.force.x"], COL[f"{g}.force.y"]]] = load[:, None] * _unit(
            rng.uniform(0, 2 * math.pi, count)
        )
        rows[:, COL[f"{g}.moment"]] = load * size * rng.uniform(-1, 1, count)
    rows[:, [COL["guide_k.x"], COL["guide_k.y"]]] = _unit(rng.uniform(0, 2 * math.pi, count))
    rows[:, [COL["guide_p.x"], COL["guide_p.y"]]] = _unit(rng.uniform(0, 2 * math.pi, count))
    rows[:, COL["gravity.y"]] = np.where(rng.random(count) < 0.5, -9.81, 0.0)
    rows[:, COL["singular_threshold"]] = STUDY_THRESHOLD
    return rows


def conditioning(dyad: str, rows: np.ndarray) -> np.ndarray:
    """The type's conditioning from the double inputs (float64 arithmetic)."""
    i_m = rows[:, [COL["m.dir.x"], COL["m.dir.y"]]]
    i_n = rows[:, [COL["n.dir.x"], COL["n.dir.y"]]]
    i_k = rows[:, [COL["guide_k.x"], COL["guide_k.y"]]]
    i_p = rows[:, [COL["guide_p.x"], COL["guide_p.y"]]]

    def perp(v: np.ndarray):
        return np.stack([-v[:, 1], v[:, 0]], axis=-1)

    def dot(a: np.ndarray, b: np.ndarray):
        return np.sum(a * b, axis=-1)

    if dyad == "RRR":
        return np.abs(dot(i_m, perp(i_n)))
    if dyad == "RRT":
        return np.abs(dot(i_n, i_k))
    if dyad == "TRT":
        return np.abs(dot(perp(i_k), i_p))
    if dyad == "RTT":
        return np.abs(dot(perp(i_k), i_m))
    l_m, l_n = rows[:, COL["m.length"]], rows[:, COL["n.length"]]
    d = l_m[:, None] * i_m - l_n[:, None] * i_n
    dist = np.linalg.norm(d, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        slant = np.abs(dot(d / dist[:, None], i_m))
    return np.minimum(np.nan_to_num(slant), dist / (l_m + l_n))


#: Output columns by unit: the forces (N) and the reactive moments (N m).
UNITS = (slice(0, 9), slice(9, 12))


def contract_ratio(
    values: np.ndarray, truth: np.ndarray, amplification: np.ndarray, eps: float
) -> np.ndarray:
    """The contract of the core's ``amplification`` output (src/dyad_amplification.h),
    per configuration: the worst |value - truth| of an output over eps x amplification
    x the largest reported |output| of its unit. With status ok it is at most a small
    constant (test_accuracy.py: 16). 0 where eps x amplification >= 1, which promises
    no digit; inf where a unit reports only zeros and is wrong."""
    ratio = np.zeros(len(values))
    promised = eps * amplification < 1
    with np.errstate(invalid="ignore", divide="ignore"):
        for unit in UNITS:
            error = np.max(np.abs(values[:, unit] - truth[:, unit]), axis=1)
            bound = eps * amplification * np.max(np.abs(values[:, unit]), axis=1)
            unit_ratio = np.where(error > 0, error / bound, 0.0)
            ratio = np.fmax(ratio, np.where(promised, unit_ratio, 0.0))
    return ratio


def random_set(dyad: str, count: int, seed: int) -> np.ndarray:
    """Well-conditioned random configurations: conditioning >= 0.1."""
    rng = np.random.default_rng(seed)
    chunks, have = [], 0
    while have < count:
        rows = _random_links(rng, dyad, 2 * count)
        rows = rows[conditioning(dyad, rows) >= 0.1]
        chunks.append(rows)
        have += len(rows)
    return np.concatenate(chunks)[:count]


def _rotated(base_angle: np.ndarray, delta: np.ndarray):
    """(cos, sin) of base_angle + delta, rounded once from 50-digit values."""
    with mpmath.workdps(50):
        a = mpmath.mpf(float(base_angle)) + mpmath.mpf(delta)
        return float(mpmath.cos(a)), float(mpmath.sin(a))


def sweep_set(
    dyad: str, per_decade: int, instances: int, seed: int, decades: tuple[int, int] = (1, 16)
) -> np.ndarray:
    """Configurations approaching the type's singular position: the geometric
    distance delta from it runs over 10^-1 ... 10^-16."""
    rng = np.random.default_rng(seed)
    exponents = np.linspace(-decades[0], -decades[1], per_decade * (decades[1] - decades[0]) + 1)
    rows = []
    for _ in range(instances):
        base = _random_links(rng, dyad, 1, length_range=(-1, 0.5), load_range=(0, 3))[0]
        theta = rng.uniform(0, 2 * math.pi)
        for e in exponents:
            delta = 10.0**e
            row = base.copy()
            if dyad == "RRR":  # links aligned: i_n along i_m
                m_dir, n_dir = _rotated(theta, 0), _rotated(theta, delta)
                row[[COL["m.dir.x"], COL["m.dir.y"]]] = m_dir
                row[[COL["n.dir.x"], COL["n.dir.y"]]] = n_dir
            elif dyad == "RRT":  # rod normal to the guide
                row[[COL["guide_k.x"], COL["guide_k.y"]]] = _rotated(theta, 0)
                row[[COL["n.dir.x"], COL["n.dir.y"]]] = _rotated(theta, math.pi / 2 - delta)
            elif dyad == "TRT":  # parallel guides
                row[[COL["guide_k.x"], COL["guide_k.y"]]] = _rotated(theta, 0)
                row[[COL["guide_p.x"], COL["guide_p.y"]]] = _rotated(theta, delta)
            elif dyad == "RTT":  # slot parallel to the guide
                row[[COL["guide_k.x"], COL["guide_k.y"]]] = _rotated(theta, 0)
                row[[COL["m.dir.x"], COL["m.dir.y"]]] = _rotated(theta, delta)
            else:  # RTR: slot normal to D_m D_n
                l_m = row[COL["m.length"]]
                row[[COL["m.dir.x"], COL["m.dir.y"]]] = _rotated(theta, 0)
                # l_n i_n = l_m i_m - l_m (delta i_m + j_m): D_m D_n nearly along j_m
                with mpmath.workdps(50):
                    c, s = mpmath.cos(theta), mpmath.sin(theta)
                    lm = mpmath.mpf(float(l_m))
                    vx = lm * c - lm * (mpmath.mpf(delta) * c - s)
                    vy = lm * s - lm * (mpmath.mpf(delta) * s + c)
                    ln = mpmath.sqrt(vx**2 + vy**2)
                    row[COL["n.length"]] = float(ln)
                    row[[COL["n.dir.x"], COL["n.dir.y"]]] = (float(vx / ln), float(vy / ln))
            rows.append(row)
    return np.asarray(rows)


def extreme_set(dyad: str, count: int, seed: int) -> np.ndarray:
    """Extreme scales and stiff mixtures, all well-conditioned geometrically:
    lengths 1e-6..1e4 m, masses 1e-6..1e6 kg, |omega| up to 1e4 rad/s, loads
    1e-9..1e9 N; a quarter with one link 1e6 times heavier than the other, a
    quarter with inertia forces about 1e8 times the weight, a quarter with tiny
    loads on top of huge inertia."""
    rng = np.random.default_rng(seed)
    chunks, have = [], 0
    while have < count:
        rows = _random_links(
            rng,
            dyad,
            2 * count,
            length_range=(-6, 4),
            mass_range=(-6, 6),
            omega_max=1e4,
            load_range=(-9, 9),
        )
        rows = rows[conditioning(dyad, rows) >= 0.1]
        chunks.append(rows)
        have += len(rows)
    rows = np.concatenate(chunks)[:count]
    quarter = count // 4
    heavy = slice(0, quarter)  # one link 1e6 times heavier
    rows[heavy, COL["m.mass"]] = rows[heavy, COL["n.mass"]] * 1e6
    rows[heavy, COL["m.inertia"]] = rows[heavy, COL["n.inertia"]] * 1e6
    stiff = slice(quarter, 2 * quarter)  # inertia ~1e8 x weight
    for g in ("m", "n"):
        size = np.maximum(rows[stiff, COL[f"{g}.length"]], 1e-3)
        rows[stiff, COL[f"{g}.omega"]] = np.sqrt(1e8 * 9.81 / size)
        rows[stiff, COL["gravity.y"]] = -9.81
    tiny = slice(2 * quarter, 3 * quarter)  # tiny loads on huge inertia
    for g in ("m", "n"):
        rows[tiny, COL[f"{g}.force.x"]] *= 1e-12
        rows[tiny, COL[f"{g}.force.y"]] *= 1e-12
        rows[tiny, COL[f"{g}.moment"]] *= 1e-12
        rows[tiny, COL[f"{g}.omega"]] = 1e4
    return rows


def cancelling_set(dyad: str, count: int, seed: int) -> np.ndarray:
    """Loads that cancel as they are summed, well-conditioned geometrically: on one
    link an active force and moment that balance its weight and inertia force and
    moment but for a residue of 1e-3 to 1e-12 of them, the other link's loads that
    much smaller. The reactions are then the residue of terms 1e3 to 1e12 times
    larger, and so is their round-off: the data factor of the amplification."""
    rows = random_set(dyad, count, seed)
    rng = np.random.default_rng(seed + 1)
    for row in rows:
        residue = 10.0 ** rng.uniform(-12, -3)
        g, other = ("m", "n") if rng.random() < 0.5 else ("n", "m")
        i = row[[COL[f"{g}.dir.x"], COL[f"{g}.dir.y"]]]
        j = np.array([-i[1], i[0]])
        r = row[COL[f"{g}.com.x"]] * i + row[COL[f"{g}.com.y"]] * j
        mass, omega, epsilon = (row[COL[f"{g}.{k}"]] for k in ("mass", "omega", "epsilon"))
        gravity = row[[COL["gravity.x"], COL["gravity.y"]]]
        accel_d = row[[COL[f"{g}.accel_d.x"], COL[f"{g}.accel_d.y"]]]
        # weight and inertia force: m (g - a_D - epsilon k0 x r + omega^2 r)
        passive = mass * (gravity - accel_d - epsilon * np.array([-r[1], r[0]]) + omega**2 * r)
        row[[COL[f"{g}.force.x"], COL[f"{g}.force.y"]]] = -passive * (1 - residue)
        row[COL[f"{g}.moment"]] = row[COL[f"{g}.inertia"]] * epsilon * (1 - residue)
        for k in ("mass", "inertia", "force.x", "force.y", "moment"):
            row[COL[f"{other}.{k}"]] *= residue
    return rows


def reference_args(dyad: str, row: np.ndarray) -> tuple:
    """One configuration as the arguments of reference.solve / solve_mp."""

    def link(g: str):
        return dict(
            dir=(row[COL[f"{g}.dir.x"]], row[COL[f"{g}.dir.y"]]),
            length=row[COL[f"{g}.length"]],
            omega=row[COL[f"{g}.omega"]],
            epsilon=row[COL[f"{g}.epsilon"]],
            accel_d=(row[COL[f"{g}.accel_d.x"]], row[COL[f"{g}.accel_d.y"]]),
            com=(row[COL[f"{g}.com.x"]], row[COL[f"{g}.com.y"]]),
            mass=row[COL[f"{g}.mass"]],
            inertia=row[COL[f"{g}.inertia"]],
            force=(row[COL[f"{g}.force.x"]], row[COL[f"{g}.force.y"]]),
            moment=row[COL[f"{g}.moment"]],
        )

    pairs = PAIRS[dyad]
    guide_k = (row[COL["guide_k.x"]], row[COL["guide_k.y"]]) if pairs[0] == "T" else None
    guide_p = (row[COL["guide_p.x"]], row[COL["guide_p.y"]]) if pairs[2] == "T" else None
    return link("m"), link("n"), guide_k, guide_p, (row[COL["gravity.x"]], row[COL["gravity.y"]])


def batched_reference_args(dyad: str, rows: np.ndarray) -> tuple:
    """All configurations at once, for the batched reference.solve."""

    def link(g: str):
        def vec(a: np.ndarray, b: np.ndarray):
            return rows[:, [COL[f"{g}.{a}"], COL[f"{g}.{b}"]]]

        return dict(
            dir=vec("dir.x", "dir.y"),
            length=rows[:, COL[f"{g}.length"]],
            omega=rows[:, COL[f"{g}.omega"]],
            epsilon=rows[:, COL[f"{g}.epsilon"]],
            accel_d=vec("accel_d.x", "accel_d.y"),
            com=vec("com.x", "com.y"),
            mass=rows[:, COL[f"{g}.mass"]],
            inertia=rows[:, COL[f"{g}.inertia"]],
            force=vec("force.x", "force.y"),
            moment=rows[:, COL[f"{g}.moment"]],
        )

    pairs = PAIRS[dyad]
    guide_k = rows[:, [COL["guide_k.x"], COL["guide_k.y"]]] if pairs[0] == "T" else None
    guide_p = rows[:, [COL["guide_p.x"], COL["guide_p.y"]]] if pairs[2] == "T" else None
    return link("m"), link("n"), guide_k, guide_p, rows[:, [COL["gravity.x"], COL["gravity.y"]]]


def outputs_of(result: dict, dyad: str) -> np.ndarray:
    """A reference result (batched or one configuration) as rows of OUTPUT_COLUMNS,
    with 0 for the normal forces of revolute pairs (as the C core reports)."""
    cols = []
    for name in OUTPUT_COLUMNS:
        key, _, comp = name.partition(".")
        value = np.asarray(result[key], dtype=float)
        if comp:
            value = value[..., 0 if comp == "x" else 1]
        cols.append(np.nan_to_num(value, nan=0.0) if key.startswith("n_") else value)
    return np.stack(cols, axis=-1)

"""The core's conversion of an angle to its direction (dyadfmu/angle.h), which every FMU
applies to its angle inputs: against mpmath's cos and sin at 40 digits."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from dyadfmu import angle_table, paths
from dyadfmu.batch import default_core

#: The bound angle.h states: about half a unit in the last place of 1.
BOUND = 1.1e-16


def hard_angles() -> np.ndarray:
    """Random angles of a few turns and up to the fast path's limit, the points next to
    multiples of pi/4 (where the reduction and the quadrant change) and the limit."""
    rng = np.random.default_rng(15)
    multiples = np.arange(-4000, 4001) * (math.pi / 4)
    return np.concatenate(
        [
            rng.uniform(-7.0, 7.0, 3000),
            rng.uniform(-1e6, 1e6, 1000),
            multiples,
            np.nextafter(multiples, np.inf),
            np.nextafter(multiples, -np.inf),
            rng.uniform(-1e-9, 1e-9, 50),
            [0.0, -0.0, 1e6, -1e6, math.nextafter(1e6, 2e6), 3e9],
        ]
    )


def test_direction_within_an_ulp_of_mpmath():
    core = default_core()
    worst, where = 0.0, None
    with mpmath.workdps(40):
        for angle in hard_angles():
            c, s = core.direction(angle)
            exact = mpmath.mpf(float(angle))
            error = float(max(abs(c - mpmath.cos(exact)), abs(s - mpmath.sin(exact))))
            if error > worst:
                worst, where = error, float(angle)
    print(f"worst error of the direction {worst:.2e} at {where!r} rad")
    assert worst <= BOUND


@pytest.mark.parametrize("angle", [math.nan, math.inf, -math.inf])
def test_direction_of_a_non_finite_angle_is_nan(angle):
    c, s = default_core().direction(angle)
    assert math.isnan(c) and math.isnan(s)


def test_the_header_holds_the_constants_mpmath_gives():
    """angle.h's split of pi/32 and its table are what angle_table.py computes now."""
    header = (paths.ROOT / "src" / "include" / "dyadfmu" / "angle.h").read_text()
    start = header.index(angle_table.BEGIN)
    end = header.index(angle_table.END) + len(angle_table.END)
    assert header[start:end] == angle_table.block()

"""The core's conversion of an angle to its direction (dyadfmu/angle.h), which every FMU
applies to its angle inputs: against mpmath's cos and sin at 40 digits."""

from __future__ import annotations

import math
import platform
import subprocess

import mpmath
import numpy as np
import pytest
from dyadfmu import angle_table, paths
from dyadfmu.batch import default_core
from tool_checks import required_tool

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


#: The wide functions against the single one, compiled apart (a program's two files), over
#: the angles on stdin: the count of angles whose bits differ in either width.
WIDE_PROGRAM = r"""#include <stdio.h>
#include <string.h>
#include "dyadfmu/angle.h"
void single(const double* a, double* c, double* s, size_t n);
int main(void)
{
    static double a[400000], c1[400000], s1[400000], c2[400000], s2[400000];
    size_t n = 0, i;
    long differ = 0;
    while (n < 400000 && scanf("%la", &a[n]) == 1) {
        ++n;
    }
    single(a, c1, s1, n);
    if (__builtin_cpu_supports("avx2")) {
        for (i = 0; i < n; i += i % 13 + 1) { /* calls of 1 to 13: the tails too */
            dyad_cos_sin_avx2(a + i, c2 + i, s2 + i, i % 13 + 1 < n - i ? i % 13 + 1 : n - i);
        }
        for (i = 0; i < n; ++i) {
            differ += memcmp(&c1[i], &c2[i], 8) != 0 || memcmp(&s1[i], &s2[i], 8) != 0;
        }
    }
    if (__builtin_cpu_supports("avx512f")) {
        for (i = 0; i < n; i += i % 19 + 1) {
            dyad_cos_sin_avx512(a + i, c2 + i, s2 + i, i % 19 + 1 < n - i ? i % 19 + 1 : n - i);
        }
        for (i = 0; i < n; ++i) {
            differ += memcmp(&c1[i], &c2[i], 8) != 0 || memcmp(&s1[i], &s2[i], 8) != 0;
        }
    }
    printf("%zu %ld\n", n, differ);
    return 0;
}
"""
SINGLE_FILE = r"""#include "dyadfmu/angle.h"
void single(const double* a, double* c, double* s, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        dyad_cos_sin(a[i], &c[i], &s[i]);
    }
}
"""


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="x86-64 only")
@pytest.mark.parametrize("compiler", [["cc", "-O2"], ["clang", "-std=c99", "-O2"]])
def test_the_wide_functions_keep_the_bits_in_a_compilers_default_mode(compiler, tmp_path):
    """dyad_cos_sin_avx2 and _avx512 compiled as an importer's rebuild of an FMU's sources
    may be (GCC's GNU mode, which fuses a * b + c in the AVX-512 target's FMA unless told
    not to; Clang, which fuses within an expression by default) give dyad_cos_sin's bits."""
    required_tool(compiler[0])
    (tmp_path / "main.c").write_text(WIDE_PROGRAM)
    (tmp_path / "single.c").write_text(SINGLE_FILE)
    include = f"-I{paths.ROOT / 'src' / 'include'}"
    flags = [*compiler, "-Wall", "-Wextra", "-Werror", include]
    built = subprocess.run(
        [*flags, str(tmp_path / "main.c"), str(tmp_path / "single.c"), "-lm", "-o",
         str(tmp_path / "wide")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert built.returncode == 0, built.stderr
    rng = np.random.default_rng(16)
    angles = np.concatenate(
        [hard_angles(), rng.uniform(-1e6, 1e6, 300000), [math.inf, -math.inf, math.nan]]
    )
    ran = subprocess.run(
        [str(tmp_path / "wide")],
        input="\n".join(float(a).hex() for a in angles),
        capture_output=True,
        text=True,
    )
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.split() == [str(len(angles)), "0"]

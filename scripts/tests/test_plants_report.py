"""dyadfmu plants: the callgrind figures it reads, and one case measured for real."""

from __future__ import annotations

import math
import shutil
from dataclasses import asdict, replace
from pathlib import Path

import pytest
from dyadfmu import paths
from dyadfmu.report import plants

#: A callgrind output of the compressed form: a name given once with its number, the
#: number alone after that, calls of the same function from two callers.
CALLGRIND = """\
version: 1
creator: callgrind-3.19.0
events: Ir
fn=(1) fmu_do_step
0 10
cfn=(2) rhs
calls=3 0
0 300
cfn=(3) jacobian
calls=1 0
0 500
fn=(3)
0 20
cfn=(2)
calls=4 0
0 400
fn=(2)
0 700
"""


def test_the_calls_of_each_function_are_summed_over_its_callers(tmp_path):
    out = tmp_path / "callgrind.out"
    out.write_text(CALLGRIND)
    assert plants._callgrind_calls(out) == {"rhs": 7, "jacobian": 1}


def _fmu(identifier: str) -> str:
    try:
        return str(paths.built_fmu(identifier, 2))
    except FileNotFoundError as missing:
        pytest.skip(str(missing))


def test_the_counters_are_per_millisecond_of_motion():
    case = plants.CASES[0]
    fmu = _fmu(case.identifier)
    short, long = (plants.drive(fmu, asdict(case), 1e-3, stop) for stop in (0.01, 0.02))
    assert short["steps_per_ms"] > 0
    # over twice the motion, about the same per ms (the speed barely changes)
    assert long["evaluations_per_ms"] == pytest.approx(short["evaluations_per_ms"], rel=0.3)


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_callgrind_splits_a_rosenbrock_plants_work(tmp_path: Path):
    """The motor with RODASP kept throughout, under callgrind: a Jacobian costs several
    evaluations, an evaluation a little more than the inverse step inside it, and the
    instructions per ms cover at least the evaluations and Jacobians counted."""
    case = replace(plants.CASES[2], stop=0.005)
    assert case.label == plants.RODASP_THROUGHOUT
    fmu = _fmu(case.identifier)
    figures = plants.instructions(fmu, case, case.stop, tmp_path)
    counted = plants.drive(fmu, asdict(case), plants.TABLE_STEP, case.stop)
    print({k: round(v) for k, v in figures.items()})
    assert (
        figures["per_inverse_step"] < figures["per_evaluation"] < 1.2 * figures["per_inverse_step"]
    )
    assert 2 * figures["per_evaluation"] < figures["per_jacobian"]
    assert figures["jacobians_per_ms"] > 0.9 * counted["steps_per_ms"]
    spent = counted["evaluations_per_ms"] * figures["per_evaluation"]
    spent += figures["jacobians_per_ms"] * figures["per_jacobian"]
    assert spent < figures["per_ms"] < 1.3 * spent
    assert all(math.isfinite(v) for v in figures.values())


def test_the_report_gives_the_plants_own_default_tolerances():
    """Read from the model description, not written into the report's text."""
    fmu = _fmu(plants.CASES[0].identifier)
    assert plants.default_tolerances(fmu) == "solver.rtol = 1e-08, solver.atol = 1e-08"

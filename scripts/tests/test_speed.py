"""The speed table's counting: floating-point operations per mnemonic, callgrind's
compressed per-instruction positions, and the closed forms' counts atop each type's file."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from dyadfmu.study import flops
from dyadfmu.study.configurations import TYPES
from dyadfmu.study.speed import closed_form_flops, opening_comment


@pytest.mark.parametrize(
    ("mnemonic", "count"),
    [
        ("addsd", 1),
        ("vmulsd", 1),
        ("sqrtsd", 1),
        ("divpd", 2),
        ("vfmadd231sd", 2),
        ("vfnmsub132pd", 2),
        ("comisd", 0),
        ("maxsd", 0),
        ("andpd", 0),
        ("movsd", 0),
        ("cvtsi2sd", 0),
    ],
)
def test_operations_per_mnemonic(mnemonic, count):
    assert flops.operations_of(mnemonic) == count


def test_executed_reads_compressed_positions_and_skips_calls(tmp_path: Path):
    out = tmp_path / "callgrind.out"
    out.write_text(
        "positions: instr\nevents: Ir\n"
        "ob=(1) /lib/a.so\nfn=(1) f\n"
        "0x10 5\n+4 5\n"
        "cob=(2) /lib/b.so\ncfn=(2) g\ncalls=5 0x99\n"
        "* 1000\n"  # the call's inclusive cost, at 0x14: not f's own
        "+3 5\n-7 2\n"
        "ob=(2)\nfn=(2)\n0x99 5\n"
    )
    counts = flops.executed(out)
    assert counts["/lib/a.so"] == {0x10: 7, 0x14: 5, 0x17: 5}
    assert counts["/lib/b.so"] == {0x99: 5}


@pytest.mark.parametrize("dyad", TYPES)
def test_closed_form_count_adds_up_its_parts(dyad):
    """The total atop each type's file is the sum of the parts it lists: the resultants,
    the reactions, and the amplification (the links' sizes, the type's output sizes, the
    inverse divisor, the data factors)."""
    _, text = opening_comment(dyad)
    resultants = re.search(r"resultants 2 x 28 = (\d+)", text)
    reactions = re.search(r"the reactions above (\d+)", text)
    amplification = re.search(
        r"the amplification (\d+) \(dyad_amplification\.h: the links' sizes 2 x 17, this "
        r"type's output sizes (\d+), 1/\|[^|]+\| (\d+) and .*? conditioning (\d+)\)",
        text,
    )
    assert resultants and reactions and amplification, text
    total, sizes, inverse, factors = map(int, amplification.groups())
    assert int(resultants.group(1)) == 2 * 28
    assert total == 2 * 17 + sizes + inverse + factors
    assert closed_form_flops(dyad) == 56 + int(reactions.group(1)) + total


def test_a_missing_count_is_named(tmp_path: Path):
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "dyad_rrr.c").write_text("/* no count */\n")
    with pytest.raises(ValueError, match="dyad_rrr.c"):
        closed_form_flops("RRR", tmp_path)


def test_speed_command_names_a_missing_benchmark(tmp_path: Path):
    done = subprocess.run(
        [sys.executable, "-m", "dyadfmu.cli", "speed", "--build", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    if shutil.which("valgrind") is None:
        assert done.returncode == 2 and "valgrind" in done.stderr
        return
    assert done.returncode == 2 and "dyad_bench is missing" in done.stderr, done.stderr


def test_generic_fmu_rows_come_from_the_build_given(tmp_path: Path, monkeypatch):
    """The scenes report's generic FMUs are those of its --build, not of $DYADFMU_BUILD or
    build/: an empty build is named in the error, and the build that has the FMU gives its
    inputs."""
    from dyadfmu import paths
    from dyadfmu.study import bench

    built = paths.built_fmu("dyad_rrt", 2).parents[1]
    monkeypatch.setenv("DYADFMU_BUILD", str(tmp_path / "elsewhere"))
    with pytest.raises(FileNotFoundError, match=re.escape(str(tmp_path / "empty"))):
        bench.fmu_rows("RRT", 4, seed=1, build=tmp_path / "empty")
    md, inputs, outputs, rows = bench.fmu_rows("RRT", 4, seed=1, build=built)
    assert md.modelName and rows.shape == (4, len(inputs)) and outputs


@pytest.mark.parametrize("before", [None, "avx2"])
def test_the_batch_kinds_are_timed_in_turn_and_the_lanes_restored(before, monkeypatch):
    """batch_seconds calls each kind once a round, in turn (a slow spell then slows one
    call of each kind, not every call of one), each in its lanes (DYADFMU_LANES, "" the
    widest) and asking its outputs, those that say so into the arrays of one earlier call
    that asked the same outputs, and leaves DYADFMU_LANES as it was, set or not."""
    from dyadfmu import mechanism_batch
    from dyadfmu.study import speed

    real = mechanism_batch.evaluate
    calls = []

    def evaluate(scene, given, asked, out=None):
        done = real(scene, given, asked, out=out)
        calls.append((os.environ.get("DYADFMU_LANES"), tuple(asked), out, done))
        return done

    monkeypatch.setattr(mechanism_batch, "evaluate", evaluate)
    if before is None:
        monkeypatch.delenv("DYADFMU_LANES", raising=False)
    else:
        monkeypatch.setenv("DYADFMU_LANES", before)
    kinds = {"wide": (False, "", False), "every": (True, "", False),
             "baseline into": (False, "baseline", True),
             "every avx2 into": (True, "avx2", True)}  # fmt: skip
    seconds = speed.batch_seconds("slider_crank", 50, kinds, rounds=3)
    assert list(seconds) == list(kinds) and all(0 < s < 1e-3 for s in seconds.values())
    assert os.environ.get("DYADFMU_LANES") == before
    loading, few_arrays, every_arrays = calls[:3]
    few, every = few_arrays[1], every_arrays[1]
    assert loading[1] == every and len(few) < len(every)
    timed = calls[3:]
    assert [lanes for lanes, *_ in timed] == ["", "", "baseline", "avx2"] * 3
    assert [asked for _, asked, *_ in timed] == [few, every, few, every] * 3
    outs = [out for _, _, out, _ in timed]
    assert outs[0::4] == outs[1::4] == [None] * 3
    assert all(out is few_arrays[3] for out in outs[2::4])
    assert all(out is every_arrays[3] for out in outs[3::4])


def test_a_second_pass_keeps_each_batch_figure_the_better_of_two(monkeypatch):
    """_time_batch times every kind and size, the rows entry and the NumPy yardstick, and a
    second call keeps for each the lower of its figure and the first call's: a slow spell
    in one pass spoils none of them."""
    from dyadfmu.study import speed

    calls: dict = {}

    def one_pass(count):
        calls[count] = calls.get(count, 0) + 1
        return calls[count] == 1

    def batch_seconds(scene, count, kinds, rounds):
        first = one_pass(count)  # the first pass slow for every other kind, the second else
        return {k: 2.0 if (i % 2 == 0) == first else 1.0 for i, k in enumerate(kinds)}

    monkeypatch.setattr(speed, "batch_seconds", batch_seconds)
    monkeypatch.setattr(speed, "rows_seconds", lambda scene, n, r: 5.0 - calls[n])
    monkeypatch.setattr(speed, "numpy_yardstick_seconds", lambda scene, n, r: 9.0 + calls[n])
    figures = speed.SceneSpeed("slider_crank", lanes="avx512")
    speed._time_batch(figures, quick=True)
    first = dict(figures.samples)
    speed._time_batch(figures, quick=True)
    sizes = speed.BATCH_SIZES[:2]
    kinds = {kind for _, kind in first} - {"rows", "numpy"}
    assert {False, True, "into", "baseline", "baseline into", "avx2 into"} <= kinds
    assert list(first.values()).count(2.0) == (len(kinds) + 1) // 2 * len(sizes)
    assert all(figures.samples[n, kind] == 1.0 for n in sizes for kind in kinds)
    assert all(figures.samples[n, "rows"] == 3.0 and first[n, "rows"] == 4.0 for n in sizes)
    assert all(figures.samples[n, "numpy"] == 10.0 for n in sizes)
    assert set(figures.samples) == set(first)

"""``dyadfmu.evaluate``: a whole mechanism over NumPy arrays in one call of its FMU binary.
Each sample is the FMU's own answer, bit for bit what fmpy's FMI calls give (run here row
by row through ``run_table``), the physics against the harness's Newton-Euler reference,
a sample without an answer NaN with its status, and every bad argument refused by name
before anything runs."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import evaluate, paths, run_table
from dyadfmu.cosim import mechanism_fmus
from dyadfmu.mechanism_batch import _finite_owners
from tool_checks import required_tool

OUTPUTS = ["crank.torque", "crank.R_O.x", "crank.R_O.y", "engine.R_mk.x", "engine.R_np.y"]
SLIDER_CRANK = paths.SCENES_DIR / "slider_crank.toml"


def test_every_sample_is_what_the_fmi_calls_give_bit_for_bit():
    angle = np.linspace(-1.0, 7.0, 257)
    omega = 50.0 + 10.0 * np.sin(angle)
    found = evaluate("slider_crank", {"crank.angle": angle, "crank.omega": omega}, OUTPUTS)
    assert found.ok.all() and found["crank.torque"].shape == (257,)
    table = {"time": np.arange(257) * 1e-3, "crank.angle": angle, "crank.omega": omega}
    rows = run_table(paths.built_fmu("slider_crank", 2), table, OUTPUTS)
    for name in OUTPUTS:
        assert np.array_equal(found[name], rows[name]), name
    assert found.units["crank.torque"] == "N.m" and found.units["crank.R_O.x"] == "N"


def test_the_reactions_are_the_reference_s():
    """Against the harness's NumPy kinematics and Newton-Euler reference over a turn of
    varying speed (the inputs and reference outputs of dyadfmu.cosim.mechanism_fmus)."""
    co, series, _ = mechanism_fmus.setup("slider_crank", 2, motion="varying", revolutions=1)
    found = evaluate("slider_crank", co.inputs, OUTPUTS)
    for name in OUTPUTS:
        want = np.asarray(series.outputs[name])
        assert np.max(np.abs(found[name] - want)) <= 1e-13 * np.max(np.abs(want)), name


def test_numbers_broadcast_to_the_batch_shape_and_parameters_apply():
    angle = np.linspace(0.0, 1.0, 12).reshape(3, 4)
    found = evaluate(
        "shaper",
        {"crank.angle": angle, "crank.omega": 6.0},
        ["crank.torque", "crank.J"],
        parameters={"slider.mass": 20.0},
    )
    assert found["crank.J"].shape == (3, 4) and found.status.shape == (3, 4)
    light = evaluate("shaper", {"crank.angle": angle, "crank.omega": 6.0}, ["crank.J"])
    assert np.all(found["crank.J"] > light["crank.J"])  # the heavier ram: more inertia
    empty = evaluate("shaper", {"crank.angle": np.empty(0)}, ["crank.torque"])
    assert empty["crank.torque"].shape == (0,) and empty.status.shape == (0,)


def test_more_samples_than_a_chunk_are_all_there():
    from dyadfmu import mechanism_batch

    count = mechanism_batch.CHUNK + 5
    angle = np.linspace(0.0, 2.0 * math.pi, count)
    found = evaluate("four_bar", {"crank.angle": angle}, ["crank.torque"])
    again = evaluate("four_bar", {"crank.angle": angle[-7:]}, ["crank.torque"])
    assert np.array_equal(found["crank.torque"][-7:], again["crank.torque"])


def test_a_scene_file_is_built_and_samples_without_an_answer_are_nan(tmp_path):
    required_tool("cmake")
    text = SLIDER_CRANK.read_text().replace('identifier = "slider_crank"', 'identifier = "rod5"')
    scene = tmp_path / "rod5.toml"
    scene.write_text(text.replace("length = 0.18", "length = 0.05"))
    angle = np.linspace(0.0, 2.0 * math.pi, 361)
    found = evaluate(scene, {"crank.angle": angle}, ["crank.torque"])
    failed = ~found.ok
    assert 0 < failed.sum() < 361
    assert np.all(np.isnan(found["crank.torque"][failed]))
    assert np.all(np.isfinite(found["crank.torque"][~failed]))
    fmu = next(Path(paths.ROOT / "build-scene" / "fmus").glob("rod5_fmi2.fmu"))
    by_file = evaluate(fmu, {"crank.angle": angle}, ["crank.torque"])
    assert np.array_equal(by_file["crank.torque"], found["crank.torque"], equal_nan=True)


@pytest.mark.parametrize(
    "args, message",
    [
        (("nonesuch", {}, ["x"]), "unknown mechanism 'nonesuch'"),
        (("x.fmu", {}, ["x"]), "x.fmu: no such FMU"),
        (("slider_crank", {"crank.speed": 1.0}, OUTPUTS), "crank.speed: not inputs of"),
        (("slider_crank", {}, ["crank.torque", "crank.force"]), "outputs: crank.force"),
        (("slider_crank", {}, []), "outputs: none asked"),
        (("slider_crank", {"crank.angle": [0.0, np.nan]}, OUTPUTS), "crank.angle[1] is nan"),
        (("slider_crank", {"crank.omega": np.inf}, OUTPUTS), "crank.omega is inf"),
        (("slider_crank", {"crank.angle": "fast"}, OUTPUTS), "crank.angle must be real numbers"),
        (
            ("slider_crank", {"crank.angle": np.zeros(3), "crank.omega": np.zeros(4)}, OUTPUTS),
            "do not broadcast to one batch shape: crank.angle (3,), crank.omega (4,)",
        ),
    ],
)
def test_bad_arguments_are_refused_by_name(args, message):
    with pytest.raises(ValueError) as refused:
        evaluate(*args)
    assert message in str(refused.value)


def test_a_parameter_that_is_not_tunable_is_refused():
    with pytest.raises(ValueError, match="slider.length: not tunable parameters of shaper_fmi2"):
        evaluate("shaper", {}, ["crank.torque"], parameters={"slider.length": 1.0})


def test_strided_and_reversed_inputs_give_what_their_contiguous_copies_give():
    """Views NumPy hands over as they are (every other sample, a reversed array, a column
    of a matrix): read in place by the binary, with the values a contiguous copy gives."""
    table = np.linspace(0.0, 7.0, 600).reshape(200, 3)
    angle, omega = table[:, 0], table[::-1, 1] * 10.0  # a column, a reversed column
    found = evaluate("slider_crank", {"crank.angle": angle, "crank.omega": omega}, OUTPUTS)
    copies = {"crank.angle": angle.copy(), "crank.omega": omega.copy()}
    want = evaluate("slider_crank", copies, OUTPUTS)
    every_other = evaluate("slider_crank", {"crank.angle": angle[::2]}, OUTPUTS)
    plain = evaluate("slider_crank", {"crank.angle": angle[::2].copy()}, OUTPUTS)
    for name in OUTPUTS:
        assert np.array_equal(found[name], want[name]), name
        assert np.array_equal(every_other[name], plain[name]), name


@pytest.mark.parametrize("columns", [2, 3])
def test_the_columns_of_a_table_are_checked_in_one_pass_and_a_bad_value_named(columns):
    """Inputs that are the columns of one table of samples are checked in one pass over it
    where they are the whole table (2 columns), column by column where it has more (3):
    either way a value that is not finite is named with its row, one in a column the call
    does not read refuses nothing, and the results are the contiguous copies'."""
    table = np.zeros((300, columns))
    table[:, 0], table[:, 1] = np.linspace(0.0, 7.0, 300), 10.0
    given = {"crank.angle": table[:, 0], "crank.omega": table[:, 1]}
    assert _finite_owners(given) == (set(given) if columns == 2 else set())
    if columns == 3:
        table[5, 2] = np.nan  # read by no input
    found = evaluate("slider_crank", given, OUTPUTS)
    want = evaluate("slider_crank", {n: a.copy() for n, a in given.items()}, OUTPUTS)
    for name in OUTPUTS:
        assert np.array_equal(found[name], want[name]), name
    table[7, 1] = -np.inf
    with pytest.raises(ValueError, match=r"crank.omega\[7\] is -inf"):
        evaluate("slider_crank", given, OUTPUTS, out=found)
    assert np.array_equal(found["crank.torque"], want["crank.torque"])  # nothing written


def test_a_view_across_its_table_s_values_is_checked_on_its_own():
    """A view that reads doubles made of two halves of its table's (bytes 4 on): the table
    is all finite, the view's first value NaN, and it is refused by name."""
    table = np.zeros(200)
    nan = np.frombuffer(np.array([np.nan]).tobytes(), np.uint8)
    table.view(np.uint8)[4:12] = nan  # the high half of value 0, the low half of value 1
    across = table.view(np.uint8)[4 : 4 + 8 * 100].view(np.float64)
    assert np.isfinite(table).all() and np.isnan(across[0])
    with pytest.raises(ValueError, match=r"crank.angle\[0\] is nan"):
        evaluate("slider_crank", {"crank.angle": across, "crank.omega": table[100:]}, OUTPUTS)


def test_ten_million_samples_with_one_bad_value_are_refused_before_anything_runs():
    angle = np.zeros(10_000_000)
    angle[-1] = np.inf
    with pytest.raises(ValueError, match=r"crank.angle\[9999999\] is inf"):
        evaluate("slider_crank", {"crank.angle": angle}, OUTPUTS)


def test_out_takes_the_results_into_an_earlier_evaluation_s_arrays():
    """``out``: the arrays of an earlier call of the same shape and outputs written in
    place and returned, each value what a fresh call gives; by the columns entry and by a
    plant's rows entry alike."""
    angle = np.linspace(0.0, 6.0, 2 * 150).reshape(2, 150)
    cases = [
        ("slider_crank", "crank.angle", {"crank.omega": 80.0}, ["crank.torque", "crank.R_O.x"]),
        ("slider_crank_forward", "crank.torque", {"piston.force.x": -3.0}, ["crank.R_O.x"]),
    ]
    for scene, swept, other, asked in cases:
        earlier = evaluate(scene, {swept: angle}, asked)
        kept = {n: earlier[n] for n in asked}
        changed = {swept: angle[::-1], **other}
        again = evaluate(scene, changed, asked, out=earlier)
        fresh = evaluate(scene, changed, asked)
        assert again.status is earlier.status and np.array_equal(again.status, fresh.status)
        for name in asked:
            assert again[name] is kept[name], name
            assert again[name].tobytes() == fresh[name].tobytes(), (scene, name)
            assert not np.array_equal(fresh[name], evaluate(scene, {swept: angle}, asked)[name])


def _filled(values: dict, shape: tuple) -> object:
    from dyadfmu.mechanism_batch import Evaluation

    return Evaluation(values, {}, np.full(shape, 9, dtype=np.intc))


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda a, t: {"crank.torque": t}, "out has no array for engine.R_mk.x"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": t.astype(np.float32)}, "float64"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": t[:-1].copy()}, "of shape (40,)"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": np.full(80, 5.0)[::2]}, "contiguous"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": _read_only(40)}, "a read-only"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": t}, "share memory"),
        (lambda a, t: {"crank.torque": t, "engine.R_mk.x": a}, "shares memory with an input"),
    ],
)
def test_an_unfit_out_is_refused_by_name_and_nothing_is_written(make, message):
    angle = np.linspace(0.0, 6.0, 40)
    torque = np.full(40, 5.0)
    out = _filled(make(angle, torque), (40,))
    before = {n: np.array(a) for n, a in out.values.items()}
    with pytest.raises(ValueError, match="out") as refused:
        evaluate("slider_crank", {"crank.angle": angle}, ["crank.torque", "engine.R_mk.x"],
                 out=out)  # fmt: skip
    assert message in str(refused.value)
    for name, array in out.values.items():
        assert np.array_equal(array, before[name]), name
    assert (out.status == 9).all() and np.array_equal(angle, np.linspace(0.0, 6.0, 40))


def test_out_of_another_kind_or_with_unfit_statuses_is_refused():
    angle = np.linspace(0.0, 6.0, 40)
    with pytest.raises(TypeError, match="out must be the Evaluation of an earlier"):
        evaluate("slider_crank", {"crank.angle": angle}, ["crank.torque"], out={})
    from dyadfmu.mechanism_batch import Evaluation

    with pytest.raises(ValueError, match="out has no array for crank.torque"):
        out = Evaluation([np.zeros(40)], {}, np.zeros(40, np.intc))
        evaluate("slider_crank", {"crank.angle": angle}, ["crank.torque"], out=out)
    for status, why in [(np.zeros(40, np.int64), "int64"), (np.zeros(41, np.intc), "(41,)")]:
        out = Evaluation({"crank.torque": np.zeros(40)}, {}, status)
        with pytest.raises(ValueError, match=r"out.status must be .*" + re.escape(why)):
            evaluate("slider_crank", {"crank.angle": angle}, ["crank.torque"], out=out)
        assert not out["crank.torque"].any()


def _read_only(count: int) -> np.ndarray:
    array = np.zeros(count)
    array.flags.writeable = False
    return array


def test_an_out_that_overlaps_an_input_only_in_a_later_chunk_is_refused(monkeypatch):
    """Chunk by chunk no output meets its own chunk's inputs, yet the first chunk's
    results would become a later chunk's angles: refused before any chunk runs."""
    from dyadfmu import mechanism_batch

    monkeypatch.setattr(mechanism_batch, "CHUNK", 16)
    shared = np.linspace(0.0, 6.0, 16 + 40)
    angle, torque = shared[:40], shared[16:]
    before = shared.copy()
    out = _filled({"crank.torque": torque}, (40,))
    with pytest.raises(ValueError, match=r"out\['crank.torque'\] shares memory with an input"):
        evaluate("slider_crank", {"crank.angle": angle}, ["crank.torque"], out=out)
    assert np.array_equal(shared, before) and (out.status == 9).all()

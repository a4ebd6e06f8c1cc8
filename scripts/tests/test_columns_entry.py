"""``dyadfmu_evaluate_columns``, the model of an FMU without states at many samples given in
columns: every sample's outputs and status are bit for bit what ``dyadfmu_evaluate_rows``
gives (each row of which goes through the FMI set and get), on every built-in scene (all its
outputs, the first half's, and those but the bounds, which lanes of their own serve), with
parameters varied per sample and refused values, non-finite inputs and samples without an
answer mixed in at random places; columns with strides and held values; the calls it
refuses write nothing."""

from __future__ import annotations

import ctypes
import re

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.sweep import rows as entries

SAMPLES = 400
#: FMUs whose model has states (a plant, the drive, the motor): the columns entry refuses
#: them. A plant's scene identifier ends in one of these.
WITH_STATES, PLANT_ENDINGS = ("drive", "motor"), ("_forward", "_motor", "_rotor")


def _all_fmus() -> list:
    folder = paths.built_fmu("slider_crank", 2).parent
    return sorted(p.stem.removesuffix("_fmi2") for p in folder.glob("*_fmi2.fmu"))


def _scene_fmus() -> list:
    return [n for n in _all_fmus() if n not in WITH_STATES and not n.endswith(PLANT_ENDINGS)]


def _reals(md, causality: str) -> list:
    return [
        v for v in md.modelVariables if v.type in ("Real", "Float64") and v.causality == causality
    ]


def _value_range(v) -> tuple[float, float]:
    start = float(v.start) if v.start is not None else 0.0
    if v.unit == "rad":
        return -7.0, 7.0
    spread = max(abs(start), 1.0)
    return start - 0.2 * spread, start + 0.2 * spread


def _samples(md, rng) -> tuple[dict, dict]:
    """(inputs, tunable parameters): name -> SAMPLES values, some out of their bounds or
    not finite, at random places."""
    drawn = {}
    for kind in ("input", "parameter"):
        out = {}
        for v in _reals(md, kind):
            low, high = _value_range(v)
            values = rng.uniform(low, high, SAMPLES)
            if v.min is not None:
                values[rng.integers(0, SAMPLES, 3)] = float(v.min) - 1.0  # refused
            values[rng.integers(0, SAMPLES, 2)] = rng.choice([np.nan, np.inf, -np.inf])
            out[v.name] = values
        drawn[kind] = out
    return drawn["input"], drawn["parameter"]


@pytest.mark.parametrize("lanes", ["", "avx2", "baseline"], ids=["widest", "avx2", "baseline"])
@pytest.mark.parametrize("name", _scene_fmus())
def test_each_sample_is_what_the_rows_entry_gives_bit_for_bit(name, lanes, monkeypatch):
    """In the widest lanes this CPU runs, and capped at AVX2's and the baseline's
    (DYADFMU_LANES, fmu/README.md)."""
    monkeypatch.setenv("DYADFMU_LANES", lanes)
    fmu = paths.built_fmu(name, 2)
    columns, rows = entries.columns_entry(fmu), entries.rows_entry(fmu)
    md = rows.md
    x, p = _samples(md, np.random.default_rng(abs(hash(name)) % 2**32))
    outputs = tuple(v.name for v in _reals(md, "output"))
    later = tuple(n for n in outputs if n.endswith((".J", ".dJdq", ".torque0", ".force0")))
    bounds = tuple(n for n in outputs if n.split(".")[-1] == "amplification")
    asked = {
        "every output": outputs,
        "without the later ones": tuple(n for n in outputs if n not in later),
        "without the later ones and the bounds (the lanes without the bounds)": tuple(
            n for n in outputs if n not in later and n not in bounds
        ),
        "one output and an input": (*outputs[-1:], *list(x)[:1]),
    }
    for what, wanted in asked.items():
        if not wanted:
            continue
        y_rows, status_rows = rows.evaluate(
            tuple(p), np.column_stack(list(p.values())) if p else np.empty((SAMPLES, 0)),
            tuple(x), np.column_stack(list(x.values())), wanted,
        )  # fmt: skip
        found = columns.evaluate({**p, **x}, wanted, SAMPLES)
        assert found is not None, f"{name}: the columns entry refused a model without states"
        y, status = found
        assert np.array_equal(status, status_rows), (name, what)
        for k, n in enumerate(wanted):
            assert np.array_equal(y[n], y_rows[:, k], equal_nan=True), (name, what, n)
        assert (status == 3).any() and (status == 0).any(), (name, "the samples mix outcomes")


def test_a_lanes_name_the_binary_would_not_know_is_refused_by_name(monkeypatch):
    """DYADFMU_LANES=avx-2 (a typo) would run in the widest lanes, whatever it meant: it is
    refused, naming the variable and its value; avx512 is taken."""
    fmu = paths.built_fmu("dyad_rrr", 2)
    columns = entries.columns_entry(fmu)
    angle = np.linspace(0.4, 0.6, 5)
    monkeypatch.setenv("DYADFMU_LANES", "avx-2")
    with pytest.raises(ValueError, match=r"DYADFMU_LANES = 'avx-2': not one of baseline, avx2"):
        columns.evaluate({"link_m.angle": angle}, ("R_mk.x",), 5)
    monkeypatch.setenv("DYADFMU_LANES", "avx512")
    y, status = columns.evaluate({"link_m.angle": angle}, ("R_mk.x",), 5)
    assert (status == 0).all() and np.isfinite(y["R_mk.x"]).all()


def test_a_scene_with_samples_without_an_answer_gives_their_status():
    """The toggles scene, which turns through part of a revolution only: the samples where
    it does not assemble or sits at a dead centre have status 1 (Warning, as a get reports
    it) and NaN outputs, exactly as the rows entry gives them."""
    fmu = paths.built_fmu("toggles", 2)
    columns, rows = entries.columns_entry(fmu), entries.rows_entry(fmu)
    angle = np.random.default_rng(5).permutation(np.linspace(-7.0, 7.0, SAMPLES))
    wanted = tuple(v.name for v in _reals(rows.md, "output"))
    y, status = columns.evaluate({"crank.angle": angle}, wanted, SAMPLES)
    y_rows, status_rows = rows.evaluate((), np.empty((SAMPLES, 0)), ("crank.angle",),
                                        angle[:, None], wanted)  # fmt: skip
    assert np.array_equal(status, status_rows)
    assert (status == 1).sum() > SAMPLES // 10 and (status == 0).sum() > SAMPLES // 10
    for k, name in enumerate(wanted):
        assert np.array_equal(y[name], y_rows[:, k], equal_nan=True), name
        assert np.isnan(y[name][status != 0]).all(), name


def _call(fmu, x_names, x_columns, x_steps, y_names, y_columns, y_steps, count):
    """dyadfmu_evaluate_columns through ctypes with the columns as given (any strides)."""
    entry = entries.columns_entry(fmu)
    vr = {v.name: v.valueReference for v in entry.md.modelVariables}

    def pointers(arrays, offsets):
        addresses = [a.ctypes.data + 8 * o for a, o in zip(arrays, offsets, strict=True)]
        return (ctypes.c_void_p * max(len(arrays), 1))(*addresses)

    status = np.full(max(count, 1), -7, dtype=np.intc)
    done = entry._f(
        entry.md.guid.encode(),
        (ctypes.c_uint * max(len(x_names), 1))(*(vr[n] for n in x_names)), len(x_names),
        pointers([c for c, _ in x_columns], [o for _, o in x_columns]),
        (ctypes.c_ssize_t * max(len(x_steps), 1))(*x_steps),
        (ctypes.c_uint * max(len(y_names), 1))(*(vr[n] for n in y_names)), len(y_names),
        pointers([c for c, _ in y_columns], [o for _, o in y_columns]),
        (ctypes.c_ssize_t * max(len(y_steps), 1))(*y_steps),
        status.ctypes.data, count,
    )  # fmt: skip
    return done, status


def test_columns_with_strides_and_held_values_read_and_write_where_they_say():
    fmu = paths.built_fmu("slider_crank", 2)
    n = 97
    angle = np.linspace(0.0, 6.0, n)
    table = np.column_stack([angle, 100.0 + angle])  # rows: angle, omega
    held = np.array([-500.0])
    out = np.full((n, 3), 12345.0)  # the outputs interleaved in the rows of one matrix
    names = ("crank.torque", "crank.R_O.x", "crank.omega")
    done, status = _call(
        fmu, ("crank.angle", "crank.omega", "piston.force.x"),
        [(table, 0), (table, 1), (held, 0)], [2, 2, 0],
        names, [(out, 0), (out, 1), (out, 2)], [3, 3, 3], n,
    )  # fmt: skip
    assert done == 0 and (status[:n] == 0).all()
    plain = entries.columns_entry(fmu).evaluate(
        {"crank.angle": angle, "crank.omega": 100.0 + angle, "piston.force.x": -500.0}, names, n
    )
    for k, name in enumerate(names):
        assert np.array_equal(out[:, k], plain[0][name]), name
    assert np.array_equal(out[:, 2], 100.0 + angle)  # an input read back as set


def _raw(fmu, vr_x, x_column, vr_y, out, status, token=None) -> int:
    """One call with one x column (contiguous) and one y column, raw."""
    entry = entries.columns_entry(fmu)
    return entry._f(
        token or entry.md.guid.encode(), (ctypes.c_uint * 1)(vr_x), 1,
        (ctypes.c_void_p * 1)(x_column.ctypes.data if x_column is not None else None),
        (ctypes.c_ssize_t * 1)(1), (ctypes.c_uint * 1)(vr_y), 1,
        (ctypes.c_void_p * 1)(out.ctypes.data), (ctypes.c_ssize_t * 1)(1),
        status.ctypes.data if status is not None else None, len(out),
    )  # fmt: skip


CRANK_ANGLE, CRANK_TORQUE = "crank.angle", "crank.torque"
REFUSED = {
    "an output as an input": ("slider_crank", CRANK_TORQUE, {}),
    "an unknown reference": ("slider_crank", 99999, {}),
    "a model with states": ("slider_crank_forward", CRANK_ANGLE, {}),
    "a wrong token": ("slider_crank", CRANK_ANGLE, {"token": b"{not-this-fmu}"}),
    "no status array": ("slider_crank", CRANK_ANGLE, {"status": None}),
    "no column": ("slider_crank", CRANK_ANGLE, {"column": None}),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_a_refused_call_writes_nothing(case):
    name, x_name, how = REFUSED[case]
    fmu = paths.built_fmu(name, 2)
    md = entries.rows_entry(fmu).md
    vr = {v.name: v.valueReference for v in md.modelVariables}
    output = next(v.name for v in _reals(md, "output"))
    out, status = np.full(8, 12345.0), np.full(8, -7, dtype=np.intc)
    column = how.get("column", np.linspace(0.0, 1.0, 8))
    done = _raw(fmu, vr.get(x_name, x_name), column, vr[output], out,
                how.get("status", status), how.get("token"))  # fmt: skip
    assert done in (3, 4), case  # Error, or Fatal where no instance can be made
    assert (out == 12345.0).all() and (status == -7).all(), case


def test_zero_samples_is_a_call_that_does_nothing():
    fmu = paths.built_fmu("slider_crank", 2)
    y, status = entries.columns_entry(fmu).evaluate(
        {"crank.angle": np.empty(0)}, ("crank.torque",), 0
    )
    assert y["crank.torque"].shape == (0,) and status.shape == (0,)


def test_exactly_the_models_with_states_are_refused_their_callers_take_the_rows_entry():
    refused = []
    for name in _all_fmus():
        fmu = paths.built_fmu(name, 2)
        outputs = tuple(v.name for v in _reals(entries.rows_entry(fmu).md, "output"))[:1]
        if entries.columns_entry(fmu).evaluate({}, outputs, 4) is None:
            refused.append(name)
    assert refused == [n for n in _all_fmus() if n not in _scene_fmus()]
    assert "slider_crank_forward" in refused and "slider_crank" not in refused


def test_outputs_written_in_place_into_strided_views_are_the_same_bits():
    """``out``: the outputs written straight into views of larger arrays (what
    dyadfmu.evaluate does chunk by chunk), every other value left as it was; wrong types
    and shapes refused before the call."""
    entry = entries.columns_entry(paths.built_fmu("slider_crank", 2))
    angle = np.linspace(-7.0, 7.0, 301)
    wanted = ("crank.torque", "engine.R_mn.x", "crank.J")
    fresh, fresh_status = entry.evaluate({"crank.angle": angle}, wanted, 301)
    big = np.full((7, 3 * 301 + 4), 12345.0)
    flags = np.full(2 * 301, -7, dtype=np.intc)
    block, status = big[1::2, 2 : 2 + 3 * 301 : 3], flags[301:]
    entry.evaluate({"crank.angle": angle}, wanted, 301, out=(block, status))
    for k, name in enumerate(wanted):
        assert fresh[name].tobytes() == block[k].copy().tobytes(), name
    assert np.array_equal(status, fresh_status) and (flags[:301] == -7).all()
    untouched = np.ones(big.shape, bool)
    untouched[1::2, 2 : 2 + 3 * 301 : 3] = False
    assert (big[untouched] == 12345.0).all()
    for out in [
        (np.empty((3, 301), np.float32), np.empty(301, np.intc)),
        (np.empty((3, 301)), np.empty(301, np.int64)),
        (np.empty((3, 300)), np.empty(301, np.intc)),
        (np.empty((3, 301)), np.empty(602, np.intc)[::2]),
    ]:
        with pytest.raises(ValueError, match="out:"):
            entry.evaluate({"crank.angle": angle}, wanted, 301, out=out)


def test_outputs_that_share_memory_with_an_input_or_each_other_are_refused():
    """The binary reads a chunk's inputs while it writes earlier samples' outputs: an
    output over an input would be read back as one; two outputs in one place lose one."""
    entry = entries.columns_entry(paths.built_fmu("slider_crank", 2))
    angle = np.linspace(-7.0, 7.0, 301)
    wanted = ("crank.torque", "engine.R_mn.x")
    status = np.zeros(301, np.intc)
    for columns, message in [
        ([np.zeros(301), angle], "the output engine.R_mn.x shares memory with an input"),
        ([np.zeros(301), np.zeros(300)], "out: one array of count values"),
        ([np.zeros(301), [0.0] * 301], "out: one array of count values"),
        ([np.zeros(301)] * 2, "the output crank.torque and the output engine.R_mn.x share memory"),
        ([np.zeros(301), np.zeros(602)[::2]], None),
    ]:
        before = angle.copy()
        if message is None:
            assert entry.evaluate({"crank.angle": angle}, wanted, 301, (columns, status))
            continue
        with pytest.raises(ValueError, match=re.escape(message)):
            entry.evaluate({"crank.angle": angle}, wanted, 301, (columns, status))
        assert np.array_equal(angle, before) and not status.any()

"""FMU state through fmpy, over the harness's inputs, on every FMU the build makes (FMI 2
and 3): a state saved after some steps and restored continues bit for bit as the first
run did (for the drive: its motion rolled back and run again), the same after the state
went through serialized bytes, and bytes that are not a state of the FMU are refused, so
is a state with any one of its 8-byte fields NaN and its checksum made good again (every
field is checked as a setter checks it), with a message naming the field. The C misuse
matrix (tests/fmu_api_tests.c) and the state fuzz (tests/fmu_state_fuzz.c) call the same
entry points directly."""

from __future__ import annotations

import numpy as np
import pytest
from dyadfmu.cosim import importers
from dyadfmu.fmi.slave import Slave
from fmpy import read_model_description

ALL = [(name, version) for name in importers.fmu_names() for version in importers.VERSIONS]
IDS = [f"{name}_fmi{version}" for name, version in ALL]


def _run(s: Slave, setup, names: list, outputs: list, first: int, last: int) -> np.ndarray:
    rows = []
    for k in range(first, last):
        s.set(tuple(names), [setup.inputs[n][k] for n in names])
        s.do_step(float(setup.time[k]), setup.step)
        rows.append(s.get(tuple(outputs)))
    return np.array(rows)


@pytest.mark.parametrize("name,version", ALL, ids=IDS)
def test_a_restored_state_continues_bit_for_bit(name, version):
    setup = importers.setup_of(name, version)
    md = read_model_description(str(setup.path))
    inputs = {v.name for v in md.modelVariables if v.causality == "input"}
    names = [n for n in setup.inputs if n in inputs]
    outputs = [
        v.name
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    s = Slave(setup.path, instance_name="state")
    try:
        s.initialize()
        get, set_, free, serialize, deserialize = s.state_calls()
        _run(s, setup, names, outputs, 0, 20)
        saved = get()
        first = _run(s, setup, names, outputs, 20, 40)
        set_(saved)
        again = _run(s, setup, names, outputs, 20, 40)
        assert np.array_equal(first.view(np.uint64), again.view(np.uint64))
        data = serialize(saved)
        free(saved)
        set_(deserialize(data))
        from_bytes = _run(s, setup, names, outputs, 20, 40)
        assert np.array_equal(first.view(np.uint64), from_bytes.view(np.uint64))
        damaged = bytearray(data)
        damaged[-1] ^= 1
        with pytest.raises(Exception, match="status 3|Error|error"):
            deserialize(bytes(damaged))
        assert any("checksum" in m for m in s.messages), s.messages[-3:]
    finally:
        s.close()


def _seal(data: bytearray) -> bytes:
    """The state's checksum made good again (FNV-1a over the payload, as fmu_state.c)."""
    h = 0xCBF29CE484222325
    for byte in data[32:]:
        h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    data[24:32] = h.to_bytes(8, "little")
    return bytes(data)


@pytest.mark.parametrize("name,version", ALL, ids=IDS)
def test_a_crafted_state_is_refused_naming_its_field(name, version):
    setup = importers.setup_of(name, version)
    s = Slave(setup.path, instance_name="crafted")
    try:
        s.initialize()
        get, set_, free, serialize, deserialize = s.state_calls()
        data = serialize(get())
        fields = (len(data) - 32) // 8
        assert fields >= 5
        for k in range(fields):
            crafted = bytearray(data)
            crafted[32 + 8 * k : 40 + 8 * k] = np.array([np.nan]).tobytes()
            with pytest.raises(Exception, match="status 3|Error|error"):
                deserialize(_seal(crafted))
            assert "refused: " in s.messages[-1] and "checksum" not in s.messages[-1], (
                k,
                s.messages[-1],
            )
        set_(deserialize(data))
    finally:
        s.close()


@pytest.mark.parametrize("count", ("solver.steps", "solver.evaluations"))
@pytest.mark.parametrize("value", (-0.0, 2.5, 2.0**53, 1e300))
def test_a_plants_counts_are_what_steps_could_leave(count, value):
    """A plant's counts of internal steps and evaluations are sums of whole numbers from 0:
    a state holding -0, a fraction, or a count a double no longer counts on from (2^53,
    1e300) is refused naming the count. Found by an attack on the plant, which restored
    -0 and 1e300 and read them back."""
    path = importers.setup_of("slider_crank_motor", 2).path
    s = Slave(path, instance_name="counts")
    try:
        s.set("crank.motor.voltage", 290.0)
        s.initialize()
        for k in range(3):
            s.do_step(k * 1e-3, 1e-3)
        get, set_, free, serialize, deserialize = s.state_calls()
        data = bytearray(serialize(get()))
        kept = np.array([s.get(count)]).tobytes()
        fields = [k for k in range(32, len(data), 8) if data[k : k + 8] == kept]
        assert len(fields) == 1, (count, fields)
        data[fields[0] : fields[0] + 8] = np.array([value]).tobytes()
        with pytest.raises(Exception, match="status 3|Error|error"):
            deserialize(_seal(data))
        assert f"{count} = " in s.messages[-1] and "could leave" in s.messages[-1], s.messages[-1]
    finally:
        s.close()


def test_a_plant_takes_back_the_state_of_a_start_step_of_minus_zero():
    """solver.step_start = -0 is a start value the bound allows (>= 0): the state right
    after initialisation holds it, and the plant takes that state back (a review found it
    refused once -0 counts were)."""
    path = importers.setup_of("slider_crank_motor", 2).path
    s = Slave(path, instance_name="minus_zero")
    try:
        s.initialize({"solver.step_start": -0.0})
        get, set_, free, serialize, deserialize = s.state_calls()
        set_(deserialize(serialize(get())))
        s.do_step(0.0, 1e-3)
        assert s.get("status") == 0
    finally:
        s.close()

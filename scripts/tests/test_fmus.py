"""The ten FMUs through fmpy: validation, co-simulation against the C core,
misuse through fmpy's low-level classes, and a rebuild from sources/."""

import math
import os
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.core import Core
from dyadfmu.cosim.harness import OUTPUTS, links_from_values
from dyadfmu.fmi.slave import Slave
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("DYADFMU_BUILD", ROOT / "build"))
TYPES = ("rrr", "rrt", "rtr", "trt", "rtt")
VERSIONS = (2, 3)
ALL = [(t, v) for t in TYPES for v in VERSIONS]


def fmu_path(dyad, version):
    path = BUILD / "fmus" / f"dyad_{dyad}_fmi{version}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (scripts/run-tests does)")
    return path


@pytest.fixture(scope="module")
def core():
    return Core()


# ---- validation ------------------------------------------------------------------


@pytest.mark.parametrize("dyad,version", ALL)
def test_fmu_validates(dyad, version):
    path = fmu_path(dyad, version)
    assert validate_fmu(str(path)) == []
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
    platform = "linux64" if version == 2 else "x86_64-linux"
    assert "modelDescription.xml" in names
    assert f"binaries/{platform}/dyad_{dyad}.so" in names
    assert "documentation/index.html" in names
    assert f"sources/dyad_{dyad}.c" in names and "sources/dyadfmu/dyad.h" in names
    if version == 3:
        assert "sources/buildDescription.xml" in names
        with zipfile.ZipFile(path) as archive:
            assert (
                archive.read("modelDescription.xml")
                == (
                    ROOT / "modelDescription" / "interface" / "golden" / f"dyad_{dyad}_fmi3.xml"
                ).read_bytes()
            )
    else:
        with zipfile.ZipFile(path) as archive:
            assert (
                archive.read("modelDescription.xml")
                == (
                    ROOT / "modelDescription" / "interface" / "golden" / f"dyad_{dyad}_fmi2.xml"
                ).read_bytes()
            )


# ---- co-simulation against the core ----------------------------------------------


def input_signals(md, revolutions=1.0, samples=200):
    """Smooth time-varying values for every input over one crank revolution
    (t from 0 to 1 s): each input swings around its start value."""
    t = np.linspace(0.0, 1.0, samples + 1)
    phase = 2 * math.pi * revolutions * t
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    rows = np.zeros(len(t), dtype=[("time", np.float64)] + [(v.name, np.float64) for v in inputs])
    rows["time"] = t
    for k, v in enumerate(inputs):
        start = float(v.start)
        if v.name.endswith("angle"):
            value = start + 0.35 * np.sin(phase + 0.7 * k)  # rad
        elif v.name.endswith("length"):
            value = start * (1 + 0.3 * np.sin(phase))  # m, stays positive
        else:
            value = start + (1 + k) * 10 * np.cos(phase + 0.3 * k)
        rows[v.name] = value
    return rows


FIGURES = {"conditioning": ("conditioning", None), "amplification": ("amplification", None)}


@pytest.mark.parametrize("dyad,version", ALL)
def test_cosimulation_reproduces_core(core, dyad, version):
    path = fmu_path(dyad, version)
    md = read_model_description(str(path))
    signals = input_signals(md)
    inputs = [n for n in signals.dtype.names if n != "time"]
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    params = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter"}
    result = simulate_fmu(
        str(path),
        start_time=0,
        stop_time=1,
        output_interval=0.005,  # fmpy's co-simulation step (step_size is its solver's)
        input=signals,
        output=inputs + outputs,
    )
    assert len(result) >= 200
    assert np.all(result["status"] == 0)
    worst = 0.0
    for row in result:
        values = dict(params)
        values.update({name: row[name] for name in inputs})
        m, n, guide_k, guide_p, gravity = links_from_values(values, dyad.upper())
        # the directions as the FMU converts its angles (dyadfmu/angle.h)
        m["dir"] = core.direction(values["link_m.angle"])
        n["dir"] = core.direction(values["link_n.angle"])
        guide_k = None if guide_k is None else core.direction(values["guide_k.angle"])
        guide_p = None if guide_p is None else core.direction(values["guide_p.angle"])
        want = core.solve(
            dyad.upper(),
            m,
            n,
            guide_k,
            guide_p,
            gravity,
            singular_threshold=params["singular_threshold"],
        )
        assert want["status"] == "ok"
        for name in outputs:
            if name == "status":
                continue
            key, index = {**OUTPUTS, **FIGURES}[name]
            expected = want[key] if index is None else want[key][index]
            got = float(row[name])
            scale = max(abs(expected), 1e-300)
            worst = max(worst, abs(got - expected) / scale)
    print(
        f"dyad_{dyad}_fmi{version}: {len(result)} steps, worst relative difference to the "
        f"core {worst:.1e}"
    )
    assert worst == 0.0  # the same code on the same inputs: bit for bit


# ---- misuse through the low-level classes ------------------------------------------


def slave(dyad, version, name="instance"):
    """An instantiated generic dyad FMU of either version (dyadfmu's fmpy wrapper)."""
    return Slave(fmu_path(dyad, version), instance_name=name)


@pytest.mark.parametrize("version", VERSIONS)
def test_wrong_call_order_is_an_error(tmp_path, version):
    s = slave("rrt", version)
    with pytest.raises(FMICallException):
        s.do_step(0, 0.01)  # before initialization
    with pytest.raises(FMICallException):
        s.get("R_np.x")  # outputs need initialization
    s.initialize()
    with pytest.raises(FMICallException):
        s.fmu.enterInitializationMode()
    with pytest.raises(FMICallException):
        s.set("link_m.mass", 3.0)  # fixed parameter after initialization
    s.do_step(0, 0.01)
    s.fmu.terminate()
    with pytest.raises(FMICallException):
        s.do_step(0.01, 0.01)
    s.close()


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("t, h", ((1.7976931348623157e308, 1e300), (1e300, 1e-300), (1e9, 1e-9)))
def test_step_must_end_at_a_later_finite_time(tmp_path, version, t, h):
    """t + h that overflows (or rounds back to t) is an Error, and the instance steps on."""
    s = slave("rrt", version)
    s.initialize()
    with pytest.raises(FMICallException) as error:
        s.do_step(t, h)
    assert error.value.status == 3
    s.do_step(0, 0.01)
    assert s.get("status") == 0 and math.isfinite(s.get("R_np.x"))
    s.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_bad_inputs_and_parameters_are_rejected(tmp_path, version):
    s = slave("rrr", version)
    for name, value in (
        ("link_m.force.x", math.nan),
        ("link_n.omega", math.inf),
        ("link_m.mass", -1.0),
        ("link_n.length", 0.0),
        ("singular_threshold", 1.5),
    ):
        with pytest.raises(FMICallException):
            s.set(name, value)
    s.initialize()
    s.do_step(0, 0.01)  # still usable, with the start values
    assert s.get("status") == 0
    assert math.isfinite(s.get("R_mk.x"))
    assert s.get("link_m.force.x") == 0.0
    s.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_singular_configuration(tmp_path, version):
    s = slave("rrr", version)
    s.initialize()
    s.do_step(0, 0.01)
    s.set("link_n.angle", s.get("link_m.angle") + math.pi)  # links aligned
    with pytest.raises(FMICallException) as error:
        s.do_step(0.01, 0.01)
    assert error.value.status == 2  # discard
    assert s.get("status") == 1
    assert math.isnan(s.get("R_mn.x")) and math.isnan(s.get("R_np.y"))
    assert s.get("conditioning") < 1e-12
    s.set("link_n.angle", 2.0)  # leave the singular position
    s.do_step(0.01, 0.01)
    assert s.get("status") == 0 and math.isfinite(s.get("R_mn.x"))
    s.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_two_instances_do_not_interfere(tmp_path, version):
    a = slave("rtt", version, "a")
    b = slave("rtt", version, "b")
    a.initialize()
    b.initialize()
    a.set("link_m.force.x", -500.0)
    b.set("link_m.force.x", 800.0)
    a.do_step(0, 0.01)
    b.do_step(0, 0.01)
    ra, rb = a.get("R_np.x"), b.get("R_np.x")
    assert ra != rb
    a.do_step(0.01, 0.01)
    assert a.get("R_np.x") == ra and b.get("R_np.x") == rb
    a.close()
    b.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_reset_restores_start_values(tmp_path, version):
    s = slave("rtr", version)
    s.initialize()
    s.do_step(0, 0.01)
    first = s.get("R_mk.y")
    s.set("link_m.moment", 123.0)
    s.do_step(0.01, 0.01)
    assert s.get("R_mk.y") != first
    s.fmu.reset()
    s.set("link_m.mass", 2.5)  # parameters settable again
    s.set("link_m.mass", 2.0)
    s.initialize()
    s.do_step(0, 0.01)
    assert s.get("link_m.moment") == 0.0
    assert s.get("R_mk.y") == first
    s.close()


# ---- rebuild from sources ----------------------------------------------------------


@pytest.mark.parametrize("version", VERSIONS)
def test_source_fmu_rebuilds(tmp_path, version):
    from fmpy.build import build_platform_binary

    path = fmu_path("rrt", version)
    unzipdir = tmp_path / "unzipped"
    with zipfile.ZipFile(path) as archive:
        archive.extractall(unzipdir)
    shutil.rmtree(unzipdir / "binaries")
    build_platform_binary(unzipdir)
    platform = "linux64" if version == 2 else "x86_64-linux"
    assert (unzipdir / "binaries" / platform / "dyad_rrt.so").is_file()
    rebuilt = tmp_path / "rebuilt.fmu"
    shutil.make_archive(str(rebuilt.with_suffix("")), "zip", unzipdir)
    shutil.move(str(rebuilt.with_suffix(".zip")), rebuilt)
    md = read_model_description(str(path))
    signals = input_signals(md, samples=20)
    outputs = ["R_mk.y", "R_np.x", "R_np.y", "R_mn.x", "N_mk", "M_mk", "status"]
    original = simulate_fmu(
        str(path), stop_time=1, output_interval=0.05, input=signals, output=outputs
    )
    again = simulate_fmu(
        str(rebuilt), stop_time=1, output_interval=0.05, input=signals, output=outputs
    )
    for name in outputs:
        np.testing.assert_allclose(again[name], original[name], rtol=1e-13, atol=0)


# ---- directional derivatives ---------------------------------------------------------


@pytest.mark.parametrize("dyad,version", ALL)
def test_directional_derivatives_match_finite_differences(tmp_path, dyad, version):
    """d(every Real output)/d(each input) from the FMU's directional derivative
    against central differences of the FMU's own outputs, at a moving state."""
    s = slave(dyad, version)
    s.initialize()
    inputs = [v for v in s.md.modelVariables if v.causality == "input"]
    outputs = [
        v.name
        for v in s.md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    rng = np.random.default_rng(11)
    state = {}
    for v in inputs:
        value = float(v.start) + (0.1 * rng.normal() if v.unit != "m" else 0.05 * float(v.start))
        if v.unit not in ("rad", "m"):
            value = float(v.start) + 50 * rng.normal()
        state[v.name] = value
        s.set(v.name, value)
    s.do_step(0, 0.01)
    out_vrs = [s.vr[n] for n in outputs]

    def outputs_now():
        return np.array([s.get(n) for n in outputs])

    base = outputs_now()
    scale = np.maximum(np.abs(base), 1.0)
    worst = 0.0
    for v in inputs:
        known = [s.vr[v.name]]
        exact = np.array(s.fmu.getDirectionalDerivative(out_vrs, known, [1.0]))
        h = 1e-6 * max(1.0, abs(state[v.name]))
        s.set(v.name, state[v.name] + h)
        plus = outputs_now()
        s.set(v.name, state[v.name] - h)
        minus = outputs_now()
        s.set(v.name, state[v.name])
        central = (plus - minus) / (2 * h)
        error = np.max(np.abs(exact - central) / (scale / max(1.0, abs(state[v.name]))))
        worst = max(worst, error)
        assert error < 1e-5, (v.name, exact, central)
    print(f"dyad_{dyad}_fmi{version}: directional derivatives vs central differences {worst:.1e}")
    with pytest.raises(FMICallException):  # a parameter is no known
        s.fmu.getDirectionalDerivative(out_vrs, [s.vr["link_m.mass"]], [1.0])
    s.close()

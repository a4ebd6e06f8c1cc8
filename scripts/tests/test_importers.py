"""A second FMI importer beside fmpy, over every FMU the build makes (generic dyads,
tailored scenes, the tailored test dyads, the drive; FMI 2 and FMI 3):

* fmi-sim (Rust, its own FMI import layer) runs each FMU over the harness's
  co-simulation and gives fmpy's outputs bit for bit when both apply the same input
  values, and within 1e-13 of each output's peak over the harness's own signals (its
  FMI 2 interpolation rounds an input by an ulp where fmpy's does not);
* fmutool -check (fmu-manipulation-toolbox) accepts every model description;
* every model description validates against the official FMI 2 / FMI 3 XSD schemas that
  fmpy ships, and every FMI 3 buildDescription.xml against its schema.

Where a tool is missing the tests skip, except under CI (CI=true), where a missing tool
is a failure: scripts/run-tests installs both.
"""

from __future__ import annotations

import os
import re
import zipfile
from dataclasses import replace
from pathlib import Path

import fmpy
import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import importers
from dyadfmu.fmi.simulate import simulate
from fmpy.fmi1 import FMICallException
from lxml import etree

CI = os.environ.get("CI", "").lower() == "true"
ALL = [(name, version) for name in importers.fmu_names() for version in importers.VERSIONS]
IDS = [f"{name}_fmi{version}" for name, version in ALL]
SCHEMAS = Path(fmpy.__file__).parent / "schema"

#: fmi-sim against fmpy over the harness's signals, relative to each output's peak. The
#: only difference is fmi-sim's FMI 2 input interpolation, which can round an input by an
#: ulp of the larger neighbouring sample (2.2e-16 relative); the outputs carry it times
#: the dyads' amplification. Measured at most 1.3e-16; the bound leaves a factor of ~1000
#: for amplification and stays far below the 1e-12 to which the harness holds the FMUs
#: against the reference.
RAW_BOUND = 1e-13
#: The amplification outputs against their own round-off, |fmi-sim - fmpy| / (eps a^2):
#: the same input ulp moves an amplification a by about eps a relative where a group's
#: outputs pass through zero (the RTR's slot moment). Measured at most 2 (tailored_rtt, FMI 2).
AMPLIFICATION_BOUND = 16.0


def fmu_file(name, version) -> Path:
    path = paths.build_dir() / "fmus" / f"{name}_fmi{version}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (scripts/run-tests does)")
    return path


def required(tool: str | None, what: str) -> str:
    if tool is None:
        message = f"{what} is not installed (scripts/run-tests installs it)"
        if CI:
            pytest.fail(message + "; under CI it must run")
        pytest.skip(message)
    return tool


@pytest.fixture(scope="module")
def fmi_sim() -> str:
    exe = required(importers.fmi_sim_executable(), "fmi-sim")
    version = importers.fmi_sim_version(exe)
    assert version == importers.FMI_SIM_VERSION, (
        f"{exe} is fmi-sim {version}; the comparison is made with "
        f"{importers.FMI_SIM_VERSION} (scripts/run-tests installs it, DYADFMU_FMI_SIM names it)"
    )
    return exe


@pytest.fixture(scope="module")
def fmutool() -> str:
    return required(importers.fmutool_executable(), "fmutool (fmu-manipulation-toolbox)")


#: Built with the tests for the design studies' tests only (tests/scenes/balance.toml: a
#: crank whose bearing force is known in closed form); no harness signals to compare on.
#: FMUs of tests/scenes/ that other tests run: the study's balance, the toggles of the
#: mechanism FMUs' status at their assembly limits (test_toggles.py)
STUDY_TEST_FMUS = {"balance_fmi2", "balance_fmi3", "toggles_fmi2", "toggles_fmi3"}
#: and the plants of tests/scenes/ that test_forward_scenes.py runs against the reference
STUDY_TEST_FMUS |= {
    f"{name}_fmi{version}"
    for name in (
        "shaper_forward",
        "lift_forward",
        "leg_forward",
        "leg_motor",
        "four_bar_forward",
        "slider_crank_rotor",
        "four_bar_motor",
        "shaper_motor",
        "slider_crank_linear_motor",
        "leg_mixed_motor",
        "leg_two_circuit_motor",
    )
    for version in (2, 3)
}


def test_the_comparison_covers_every_fmu_the_build_makes():
    built = {p.stem for p in (paths.build_dir() / "fmus").glob("*.fmu")} - STUDY_TEST_FMUS
    assert built == {f"{name}_fmi{version}" for name, version in ALL}


# ---------------------------------------------------------------------------
# fmi-sim against fmpy
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name,version", ALL, ids=IDS)
def test_fmi_sim_gives_fmpys_outputs(name, version, fmi_sim, tmp_path):
    fmu_file(name, version)
    setup = importers.setup_of(name, version)
    other = importers.run_fmi_sim(setup, tmp_path, fmi_sim)
    same_inputs = importers.as_applied_by_fmi_sim(setup)
    exact = importers.compare(same_inputs, simulate(same_inputs), other)
    raw = importers.compare(setup, simulate(setup), other)
    print(
        f"fmi-sim vs fmpy, harness inputs: {raw.line()}, amplification "
        f"{raw.amplification_in_own_roundoff:.2g} x eps a^2; same inputs: "
        f"{exact.max_ulps:.0f} ulps"
    )
    assert exact.max_ulps == 0, f"same inputs, different outputs: {exact.line()}"
    assert raw.max_relative <= RAW_BOUND, raw.line()
    assert raw.amplification_in_own_roundoff <= AMPLIFICATION_BOUND, raw.line()


@pytest.mark.parametrize(
    "name,version,column",
    [("dyad_rrt", 3, "link_m.force.x"), ("shaper", 2, "crank.angle"), ("drive", 2, "load.torque")],
)
def test_the_comparison_fails_on_a_perturbed_input(name, version, column, fmi_sim, tmp_path):
    """One input column scaled by 1 + 1e-9 for fmi-sim only: both checks above fail."""
    setup = importers.setup_of(name, version)
    assert np.ptp(setup.inputs[column]) > 0  # a column that moves
    other = importers.run_fmi_sim(setup, tmp_path, fmi_sim, perturb=column)
    same_inputs = importers.as_applied_by_fmi_sim(setup)
    assert importers.compare(same_inputs, simulate(same_inputs), other).max_ulps > 0
    assert importers.compare(setup, simulate(setup), other).max_relative > RAW_BOUND


@pytest.mark.parametrize("version", importers.VERSIONS)
def test_a_singular_position_ends_both_runs_alike(version, fmi_sim, tmp_path):
    """The RRR's links aligned from row 60 on: the FMU discards the step. FMI 2: both
    importers stop at the last successful time with the status-1 row (NaN reactions),
    bit for bit. FMI 3: both treat the discard as an error."""
    setup = importers.setup_of("dyad_rrr", version)
    inputs = dict(setup.inputs)
    inputs["link_n.angle"] = inputs["link_n.angle"].copy()
    inputs["link_n.angle"][60:] = inputs["link_m.angle"][60:] + np.pi
    setup = replace(setup, inputs=inputs)
    if version == 3:
        with pytest.raises(FMICallException):
            simulate(setup)
        with pytest.raises(importers.ImporterError, match="do_step"):
            importers.run_fmi_sim(setup, tmp_path, fmi_sim)
        return
    other = importers.run_fmi_sim(setup, tmp_path, fmi_sim)
    same_inputs = importers.as_applied_by_fmi_sim(setup)
    ours = simulate(same_inputs)
    assert len(ours["time"]) == 62 and ours["status"][-1] == 1 and np.isnan(ours["R_mn.x"][-1])
    assert importers.compare(same_inputs, ours, other).max_ulps == 0


def test_fmi_sim_refuses_the_fmi3_units_it_is_given_a_copy_without(fmi_sim, tmp_path):
    """fmi-sim 0.7.0 rejects `unit` and `displayUnit` on an FMI 3 <Float64> (the schema
    allows them): it runs a copy whose model description differs in exactly those
    attributes."""
    original = fmu_file("dyad_rrt", 3)
    refused = importers.fmi_sim(fmi_sim, original, tmp_path / "refused.csv", 0.01, 0.005)
    assert refused.returncode != 0
    assert 'unknown field "unit" in element "FmiFloat64"' in refused.stderr
    copy = importers.readable_copy(original, tmp_path / "copy.fmu")
    with zipfile.ZipFile(original) as a, zipfile.ZipFile(copy) as b:
        assert a.namelist() == b.namelist()
        for item in a.namelist():
            if item != "modelDescription.xml":
                assert a.read(item) == b.read(item), item
        before = etree.fromstring(a.read("modelDescription.xml"))
        after = etree.fromstring(b.read("modelDescription.xml"))
    for attribute in ("unit", "displayUnit"):
        assert sum(1 for v in before.iter("Float64") if v.get(attribute)) > 0, attribute
    for v in before.iter("Float64"):
        v.attrib.pop("unit", None)
        v.attrib.pop("displayUnit", None)
    assert etree.tostring(before, method="c14n") == etree.tostring(after, method="c14n")
    assert importers.fmi_sim(fmi_sim, copy, tmp_path / "accepted.csv", 0.01, 0.005).returncode == 0


# ---------------------------------------------------------------------------
# fmutool -check and the XSD schemas
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name,version", ALL, ids=IDS)
def test_fmutool_check_accepts(name, version, fmutool):
    done = importers.fmutool_check(fmu_file(name, version), fmutool)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"compliant with FMI-{version}.0" in done.stdout + done.stderr


def schema(version: int, kind: str = "ModelDescription") -> etree.XMLSchema:
    return etree.XMLSchema(file=str(SCHEMAS / f"fmi{version}" / f"fmi{version}{kind}.xsd"))


def schema_errors(xml: bytes, xsd: etree.XMLSchema) -> list[str]:
    document = etree.fromstring(xml)
    if xsd.validate(document):
        return []
    return [f"line {e.line}: {e.message}" for e in xsd.error_log]


@pytest.mark.parametrize("name,version", ALL, ids=IDS)
def test_model_description_validates_against_the_fmi_schema(name, version):
    with zipfile.ZipFile(fmu_file(name, version)) as archive:
        xml = archive.read("modelDescription.xml")
        build = archive.read("sources/buildDescription.xml") if version == 3 else None
    assert etree.fromstring(xml).get("fmiVersion") == f"{version}.0"
    assert schema_errors(xml, schema(version)) == []
    if build is not None:
        assert schema_errors(build, schema(3, "BuildDescription")) == []


@pytest.mark.parametrize("version", importers.VERSIONS)
def test_a_broken_model_description_fails_both_checks(version, fmutool, tmp_path):
    """A variable whose causality the standard does not know: the schema and fmutool
    both refuse it."""
    original = fmu_file("press", version)
    broken = tmp_path / f"broken_fmi{version}.fmu"
    with zipfile.ZipFile(original) as src, zipfile.ZipFile(broken, "w") as out:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data, count = re.subn(rb'causality="input"', b'causality="inlet"', data, count=1)
                assert count == 1
                xml = data
            out.writestr(item, data)
    assert schema_errors(xml, schema(version)) != []
    done = importers.fmutool_check(broken, fmutool)
    assert done.returncode != 0, done.stdout + done.stderr

"""The variable tables of the dyad FMUs and what modelDescription/generate.py makes of them.

(a) The `depends` lists of every table are the true output dependencies, derived
    here afresh with the independent NumPy reference by perturbing each input (the
    amplification, which the reference does not compute, with the C core).
(b) The generated model descriptions equal the golden files byte for byte.
(c) fmpy validates every generated description, and units, causalities, counts
    and the model structure are what the dyad type calls for.
(d) Malformed tables are refused with a message that names the variable.
Also: the generated C tables compile, the start values give a well-conditioned
solve, and the instantiation token follows the table.

(e) The crank drive (drive.toml, a model with states; fmu/models/fmu_drive.h): golden
    files, fmpy validation, its variables, units, causalities and dependencies
    (including empty ones), its C table, its documentation, and malformed drive
    tables. The dyad-only tests above stay parametrized over the five dyad types.
"""

from __future__ import annotations

import atexit
import math
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
MD_DIR = ROOT / "modelDescription"
GENERATOR = MD_DIR / "generate.py"

from dyadfmu.reference import newton_euler as ref  # noqa: E402
from dyadgen import golden as golden_module  # noqa: E402
from dyadgen import kinds, pipeline  # noqa: E402
from dyadgen.cli import generate as generate_cli  # noqa: E402
from dyadgen.structs import (  # noqa: E402
    DRIVE_INPUT_MEMBERS,
    DRIVE_OUTPUT_MEMBERS,
    MOTOR_INPUT_MEMBERS,
    MOTOR_OUTPUT_MEMBERS,
)
from dyadgen.table import instantiation_token  # noqa: E402

TYPES = ("RRR", "RRT", "RTR", "TRT", "RTT")
PAIRS = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}  # D_m, E, D_n
SCENES_DIR = ROOT / "modelDescription" / "scenes"
#: The generic dyad FMUs' variable tables, as the scene generator makes them from
#: modelDescription/scenes/dyad_<type>.toml, written to files (filled at the end of this module).
TABLE_OF: dict = {}


def load_raw(dyad_type):
    with open(TABLE_OF[dyad_type], "rb") as f:
        return tomllib.load(f)


def names_of(raw, causality):
    return [v["name"] for v in raw["variable"] if v["causality"] == causality]


# ---------------------------------------------------------------------------
# The FMU's view of the reference: values by variable name -> outputs by name
# ---------------------------------------------------------------------------
def _dir(angle):
    return (math.cos(angle), math.sin(angle))


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def _rot90(v):
    return (-v[1], v[0])


def conditioning(dyad_type, m, n, gk, gp):
    """The conditioning figure of the solver (README), from the reference's inputs."""
    i_m, i_n = m["dir"], n["dir"]
    if dyad_type == "RRR":
        return abs(_dot(i_m, _rot90(i_n)))
    if dyad_type == "RRT":
        return abs(_dot(i_n, gk))
    if dyad_type == "TRT":
        return abs(_dot(_rot90(gk), gp))
    if dyad_type == "RTT":
        return abs(_dot(_rot90(gk), i_m))
    d = (m["length"] * i_m[0] - n["length"] * i_n[0], m["length"] * i_m[1] - n["length"] * i_n[1])
    dist = math.hypot(*d)
    if dist == 0:
        return 0.0
    return min(abs(_dot(d, i_m)) / dist, dist / (m["length"] + n["length"]))


def reference_args(values):
    """Reference solve arguments from FMU variable values keyed by name."""
    links = {}
    for g in "mn":
        p = f"link_{g}."
        links[g] = dict(
            dir=_dir(values[p + "angle"]),
            length=values[p + "length"],
            omega=values[p + "omega"],
            epsilon=values[p + "epsilon"],
            accel_d=(values[p + "accel_d.x"], values[p + "accel_d.y"]),
            com=(values[p + "com.x"], values[p + "com.y"]),
            mass=values[p + "mass"],
            inertia=values[p + "inertia"],
            force=(values[p + "force.x"], values[p + "force.y"]),
            moment=values[p + "moment"],
        )
    gk = _dir(values["guide_k.angle"]) if "guide_k.angle" in values else (1.0, 0.0)
    gp = _dir(values["guide_p.angle"]) if "guide_p.angle" in values else (1.0, 0.0)
    return links["m"], links["n"], gk, gp, (values["gravity.x"], values["gravity.y"])


_CORE = []


def core_amplification(dyad_type, m, n, gk, gp, gravity, threshold):
    """The C core's amplification output, NaN where the core is not built."""
    from dyadfmu.core import Core, library_path

    if not _CORE:
        _CORE.append(Core() if library_path().is_file() else None)
    if _CORE[0] is None:
        return math.nan
    return _CORE[0].solve(dyad_type, m, n, gk, gp, gravity, singular_threshold=threshold)[
        "amplification"
    ]


def evaluate(dyad_type, values):
    """Every FMU output (by name) for the given inputs and parameters, by the reference;
    the amplification (data factor / conditioning, src/dyad_amplification.h) by the core."""
    m, n, gk, gp, gravity = reference_args(values)
    out = ref.solve(dyad_type, m, n, gk, gp, gravity)
    result = {}
    for pair in ("mk", "np", "mn"):
        result[f"R_{pair}.x"] = float(out[f"r_{pair}"][0, 0])
        result[f"R_{pair}.y"] = float(out[f"r_{pair}"][0, 1])
        result[f"N_{pair}"] = float(out[f"n_{pair}"][0])
        result[f"M_{pair}"] = float(out[f"m_{pair}"][0])
    cond = conditioning(dyad_type, m, n, gk, gp)
    result["conditioning"] = cond
    result["amplification"] = core_amplification(
        dyad_type, m, n, gk, gp, gravity, values["singular_threshold"]
    )
    result["status"] = 0 if cond >= values["singular_threshold"] else 1
    return result


def random_value(name, rng):
    """A random value of a variable, by its name: generic, nonzero, well inside its domain."""
    leaf = name.split(".", 1)[1] if name.startswith("link_") else name
    ranges = {
        "angle": (0.0, 2 * math.pi),
        "guide_k.angle": (0.0, 2 * math.pi),
        "guide_p.angle": (0.0, 2 * math.pi),
        "length": (0.3, 2.0),
        "omega": (-10.0, 10.0),
        "epsilon": (-100.0, 100.0),
        "accel_d.x": (-50.0, 50.0),
        "accel_d.y": (-50.0, 50.0),
        "force.x": (-200.0, 200.0),
        "force.y": (-200.0, 200.0),
        "moment": (-50.0, 50.0),
        "com.x": (-0.5, 1.0),
        "com.y": (-0.5, 0.5),
        "mass": (0.5, 5.0),
        "inertia": (0.01, 0.5),
        "gravity.x": (-10.0, 10.0),
        "gravity.y": (-10.0, 10.0),
    }
    if leaf == "singular_threshold":
        return 1.4901161193847656e-08
    if leaf == "on_singular":
        return 1  # the FMU layer's setting: the solve never reads it
    lo, hi = ranges[leaf]
    return float(rng.uniform(lo, hi))


def random_configuration(dyad_type, names, rng, min_conditioning=0.2):
    while True:
        values = {name: random_value(name, rng) for name in names}
        if evaluate(dyad_type, values)["conditioning"] >= min_conditioning:
            return values


def changed_outputs(base, other, output_names):
    """Outputs that differ by more than round-off between two evaluations."""
    loads = [
        abs(r[k])
        for r in (base, other)
        for k in output_names
        if k[0] in "RNM" and math.isfinite(r[k])
    ]
    scale = max(loads) if loads else 1.0
    changed = set()
    for k in output_names:
        if k == "status":
            continue
        a, b = base[k], other[k]
        if k == "conditioning":
            tol = 1e-12
        elif k == "amplification":
            tol = 1e-12 * max(abs(a), abs(b))
        else:
            tol = 1e-9 * scale
        if abs(a - b) > tol:
            changed.add(k)
    return changed


def derive_dependencies(dyad_type, raw, configurations=6, seed=0):
    """Output name -> set of input names it depends on, by perturbation with the reference.

    At several random valid configurations (nonzero masses, inertias, offsets, loads and
    lengths), each input in turn is given a fresh random value; an output depends on the
    input if it changes by more than round-off at any configuration. `status` depends on
    what `conditioning` depends on (it is the comparison of the conditioning with the
    threshold)."""
    rng = np.random.default_rng(seed + TYPES.index(dyad_type))
    inputs = names_of(raw, "input")
    known = inputs + names_of(raw, "parameter")
    outputs = names_of(raw, "output")
    deps = {name: set() for name in outputs}
    for _ in range(configurations):
        values = random_configuration(dyad_type, known, rng)
        base = evaluate(dyad_type, values)
        for name in inputs:
            while True:
                trial = dict(values, **{name: random_value(name, rng)})
                result = evaluate(dyad_type, trial)
                if result["conditioning"] >= 0.1:
                    break
            for out in changed_outputs(base, result, outputs):
                deps[out].add(name)
    if "status" in deps:
        deps["status"] = set(deps["conditioning"])
    return deps


# ---------------------------------------------------------------------------
# (a) declared dependencies are the true ones
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("dyad_type", TYPES)
def test_declared_dependencies_are_the_true_ones(dyad_type):
    raw = load_raw(dyad_type)
    derived = derive_dependencies(dyad_type, raw)
    problems = []
    for v in raw["variable"]:
        if v["causality"] != "output":
            continue
        if v["name"] == "amplification" and math.isnan(
            evaluate(dyad_type, start_values(raw))["amplification"]
        ):
            continue  # the C core is not built: nothing to derive it with
        declared = set(v["depends"])
        want = derived[v["name"]]
        if declared != want:
            problems.append(
                f"{v['name']}: missing {sorted(want - declared)}, extra {sorted(declared - want)}"
            )
    assert not problems, f"{TABLE_OF[dyad_type].name}:\n" + "\n".join(problems)


@pytest.mark.parametrize("dyad_type", TYPES)
def test_dependencies_do_not_depend_on_the_sample(dyad_type):
    """Another seed gives the same dependencies: the derivation is not luck. Not for
    the amplification: the larger of two units' data factors, it moves with an input
    only where that input's unit has the larger one, which six configurations show
    (test (a)) and three may not."""
    raw = load_raw(dyad_type)
    first = derive_dependencies(dyad_type, raw, configurations=3, seed=1000)
    second = derive_dependencies(dyad_type, raw, configurations=3, seed=2000)
    first.pop("amplification")
    second.pop("amplification")
    assert first == second


# ---------------------------------------------------------------------------
# generating
# ---------------------------------------------------------------------------
def run_generator(*args):
    return subprocess.run(
        [sys.executable, str(GENERATOR), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """Dyad type -> directory the generator wrote that type's files into."""
    out = {}
    base = tmp_path_factory.mktemp("generated")
    for t in TYPES:
        proc = run_generator(TABLE_OF[t], "--out", base / t)
        assert proc.returncode == 0, proc.stderr
        out[t] = base / t
    return out


def identifier(dyad_type):
    return f"dyad_{dyad_type.lower()}"


def test_generator_writes_every_file(generated):
    for t, d in generated.items():
        for rel in (
            "fmi2/modelDescription.xml",
            "fmi3/modelDescription.xml",
            "fmi3/buildDescription.xml",
            f"{identifier(t)}_model.c",
            "documentation/index.html",
        ):
            assert (d / rel).is_file(), f"{t}: {rel} missing"


# ---------------------------------------------------------------------------
# (b) golden files
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("dyad_type", TYPES)
def test_generated_xml_equals_golden(generated, dyad_type):
    for version in ("fmi2", "fmi3"):
        golden = MD_DIR / "interface" / "golden" / f"{identifier(dyad_type)}_{version}.xml"
        produced = generated[dyad_type] / version / "modelDescription.xml"
        assert golden.is_file(), f"{golden} missing: run generate.py --update-golden"
        assert produced.read_bytes() == golden.read_bytes(), (
            f"{produced.name} ({version}) differs from {golden.name}; review the change and run "
            "modelDescription/generate.py --update-golden"
        )


def test_check_golden_passes():
    proc = run_generator("--check-golden")
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_check_golden_reports_a_difference(tmp_path, monkeypatch):
    monkeypatch.setattr(golden_module, "GOLDEN_DIR", tmp_path)
    assert generate_cli.main(["--update-golden"]) == 0
    target = tmp_path / "dyad_rrt_fmi3.xml"
    target.write_text(target.read_text().replace('stopTime="1.0"', 'stopTime="2.0"'))
    assert generate_cli.main(["--check-golden"]) == 1


def test_output_is_deterministic(generated, tmp_path):
    for t in TYPES:
        again = tmp_path / t
        assert run_generator(TABLE_OF[t], "--out", again).returncode == 0
        for path in generated[t].rglob("*"):
            if path.is_file():
                rel = path.relative_to(generated[t])
                assert (again / rel).read_bytes() == path.read_bytes(), rel
                assert b"\r" not in path.read_bytes()


# ---------------------------------------------------------------------------
# (c) fmpy validation, units, causalities, counts, structure
# ---------------------------------------------------------------------------
EXPECTED_UNIT = [  # by name pattern, independent of the generator's catalogue
    (r"link_[mn]\.angle|guide_[kp]\.angle", "rad"),
    (r"link_[mn]\.omega", "rad/s"),
    (r"link_[mn]\.epsilon", "rad/s2"),
    (r"link_[mn]\.accel_d\.[xy]|gravity\.[xy]", "m/s2"),
    (r"link_[mn]\.force\.[xy]|R_\w\w\.[xy]|N_\w\w", "N"),
    (r"link_[mn]\.moment|M_\w\w", "N.m"),
    (r"link_[mn]\.(length|com\.[xy])", "m"),
    (r"link_[mn]\.mass", "kg"),
    (r"link_[mn]\.inertia", "kg.m2"),
    (r"singular_threshold|on_singular|conditioning|amplification|status", None),
]
BASE_UNITS = {
    "rad": {"rad": 1},
    "rad/s": {"rad": 1, "s": -1},
    "rad/s2": {"rad": 1, "s": -2},
    "m": {"m": 1},
    "m/s2": {"m": 1, "s": -2},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "kg": {"kg": 1},
    "kg.m2": {"kg": 1, "m": 2},
}


def expected_unit(name):
    for pattern, unit in EXPECTED_UNIT:
        if re.fullmatch(pattern, name):
            return unit
    raise AssertionError(f"unexpected variable {name}")


def expected_names(dyad_type):
    """The variables a type must have, by causality, written out from the README's table."""
    d_m, e, d_n = PAIRS[dyad_type]
    inputs, params = [], []
    for g in "mn":
        inputs += [
            f"link_{g}.{x}"
            for x in (
                "angle",
                "omega",
                "epsilon",
                "accel_d.x",
                "accel_d.y",
                "force.x",
                "force.y",
                "moment",
            )
        ]
        if g == "m" and e == "T":
            inputs.append("link_m.length")
        if not (g == "m" and e == "T"):
            params.append(f"link_{g}.length")
        params += [f"link_{g}.{x}" for x in ("com.x", "com.y", "mass", "inertia")]
    if d_m == "T":
        inputs.append("guide_k.angle")
    if d_n == "T":
        inputs.append("guide_p.angle")
    params += ["gravity.x", "gravity.y", "singular_threshold", "on_singular"]
    outputs = [f"R_{p}.{c}" for p in ("mk", "np", "mn") for c in "xy"]
    for p, kind in (("mk", d_m), ("np", d_n), ("mn", e)):
        if kind == "T":
            outputs += [f"N_{p}", f"M_{p}"]
    outputs += ["conditioning", "amplification", "status"]
    return inputs, params, outputs


def read_fmi2(path):
    from fmpy import read_model_description

    return read_model_description(
        str(path), validate=True, validate_variable_names=True, validate_model_structure=True
    )


def read_fmi3(generated_dir, tmp_path):
    """FMI 3 description read from an extracted-FMU layout, so that fmpy also validates
    sources/buildDescription.xml against its schema."""
    from fmpy import read_model_description

    fmu = tmp_path / "fmu3"
    (fmu / "sources").mkdir(parents=True, exist_ok=True)
    shutil.copy(generated_dir / "fmi3" / "modelDescription.xml", fmu / "modelDescription.xml")
    shutil.copy(
        generated_dir / "fmi3" / "buildDescription.xml", fmu / "sources" / "buildDescription.xml"
    )
    return read_model_description(
        str(fmu), validate=True, validate_variable_names=True, validate_model_structure=True
    )


@pytest.mark.parametrize("dyad_type", TYPES)
def test_fmpy_validates_and_interface_is_right(generated, dyad_type, tmp_path):
    raw = load_raw(dyad_type)
    ident = identifier(dyad_type)
    inputs, params, outputs = expected_names(dyad_type)
    md2 = read_fmi2(generated[dyad_type] / "fmi2" / "modelDescription.xml")
    md3 = read_fmi3(generated[dyad_type], tmp_path)

    # the same token everywhere, UUID-shaped
    token = md2.guid
    assert re.fullmatch(r"\{[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}\}", token)
    assert md3.instantiationToken == token
    c_text = (generated[dyad_type] / f"{ident}_model.c").read_text()
    assert f'"{token}"' in c_text
    assert f'"{ident}"' in c_text and f"dyad_solve_{dyad_type.lower()}" in c_text

    # co-simulation interface and sources
    for md, shim in (
        (md2, ["fmi2_functions.c"]),
        (md3, ["fmi3_functions.c", "fmi3_unsupported.c"]),
    ):
        assert md.coSimulation is not None and md.modelExchange is None
        assert md.coSimulation.modelIdentifier == ident
        assert md.variableNamingConvention == "structured"
        assert md.defaultExperiment.stopTime == "1" or float(md.defaultExperiment.stopTime) == 1
        assert [c.name for c in md.logCategories] == [
            "logStatusError",
            "logStatusWarning",
            "logStatusDiscard",
            "logCalls",
        ]
        (config,) = md.buildConfigurations
        assert config.modelIdentifier == ident
        assert config.sourceFileSets[0].sourceFiles == [
            "dyad_common.c",
            f"dyad_{dyad_type.lower()}.c",
            "dyad_tangent.c",
            f"dyad_{dyad_type.lower()}_tangent.c",
            "fmu_dyad.c",
            "fmu_instance.c",
            "fmu_state.c",
            *shim,
            f"{ident}_model.c",
        ]
        units = {u.name: u.baseUnit for u in md.unitDefinitions}
        assert set(units) == set(BASE_UNITS)
        for name, exps in BASE_UNITS.items():
            got = {
                k: getattr(units[name], k)
                for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
                if getattr(units[name], k)
            }
            assert got == exps, name

    # variables: names, causalities, units, counts, value references
    variables2 = md2.modelVariables
    variables3 = [v for v in md3.modelVariables if v.causality != "independent"]
    (time,) = [v for v in md3.modelVariables if v.causality == "independent"]
    assert time.name == "time" and time.valueReference == 0
    for variables in (variables2, variables3):
        by_causality = {
            c: [v.name for v in variables if v.causality == c]
            for c in ("input", "parameter", "output")
        }
        assert by_causality == {"input": inputs, "parameter": params, "output": outputs}
        assert len(variables) == len(inputs) + len(params) + len(outputs)
        assert [v.valueReference for v in variables] == list(range(1, len(variables) + 1))
        for v in variables:
            assert v.unit == expected_unit(v.name), v.name
            if v.causality == "input":
                assert v.variability == "continuous" and v.start is not None
            elif v.causality == "parameter":
                assert (v.variability, v.initial) == ("fixed", "exact") and v.start is not None
            else:
                assert v.initial == "calculated" and v.start is None
                assert v.variability == ("discrete" if v.name == "status" else "continuous")
            want_type = {"status": ("Integer", "Int32"), "on_singular": ("Enumeration",)}
            assert v.type in want_type.get(v.name, ("Real", "Float64")), v.name

    # type-specific presence
    names = set(inputs + params + outputs)
    assert ("guide_p.angle" in names) == (dyad_type == "TRT")
    assert ("guide_k.angle" in names) == (dyad_type in ("RRT", "TRT", "RTT"))
    sliding = {v.name for v in variables2 if v.causality == "input" and v.name.endswith("length")}
    assert sliding == ({"link_m.length"} if dyad_type in ("RTR", "RTT") else set())
    if dyad_type == "RRR":
        assert not [n for n in names if re.match(r"[NM]_", n)]

    # bounds where the solver has a domain
    by_name = {v.name: v for v in variables3}
    assert float(by_name["singular_threshold"].min) == 0
    assert float(by_name["singular_threshold"].max) == 1
    for g in "mn":
        assert float(by_name[f"link_{g}.mass"].min) == 0
        assert float(by_name[f"link_{g}.inertia"].min) == 0
        assert float(by_name[f"link_{g}.length"].min) == 0

    # model structure: outputs, their dependencies as declared, initial unknowns
    declared = {v["name"]: set(v["depends"]) for v in raw["variable"] if v["causality"] == "output"}
    for md in (md2, md3):
        assert [u.variable.name for u in md.outputs] == outputs
        for unknown in md.outputs:
            deps = {d.name for d in unknown.dependencies}
            assert deps == declared[unknown.variable.name], unknown.variable.name
            assert all(d.causality == "input" for d in unknown.dependencies)
        assert [u.variable.name for u in md.initialUnknowns] == outputs


def test_fmi2_dependencies_are_one_based_indices(generated):
    text = (generated["RRT"] / "fmi2" / "modelDescription.xml").read_text()
    raw = load_raw("RRT")
    index = {v["name"]: k + 1 for k, v in enumerate(raw["variable"])}
    r_np_x = next(v for v in raw["variable"] if v["name"] == "R_np.x")
    deps = " ".join(str(i) for i in sorted(index[d] for d in r_np_x["depends"]))
    assert f'<Unknown index="{index["R_np.x"]}" dependencies="{deps}"/>' in text


def test_documentation_is_complete(generated):
    for t in TYPES:
        page = (generated[t] / "documentation" / "index.html").read_text()
        raw = load_raw(t)
        assert page.startswith("<!DOCTYPE html>") and "</html>" in page
        assert "http" not in page  # self-contained: no external resources
        for v in raw["variable"]:
            assert f"<code>{v['name']}</code>" in page
        for word in (
            "singular",
            "invalid input",
            "out of range",
            "Discard",
            "Error",
            "NaN",
            "counter-clockwise",
        ):
            assert word in page, (t, word)


# ---------------------------------------------------------------------------
# the C table compiles; the start values solve
# ---------------------------------------------------------------------------
@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available")
@pytest.mark.parametrize("dyad_type", TYPES)
def test_c_table_compiles(generated, dyad_type, tmp_path):
    source = generated[dyad_type] / f"{identifier(dyad_type)}_model.c"
    proc = subprocess.run(
        [
            "gcc",
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            f"-I{ROOT / 'src' / 'include'}",
            f"-I{ROOT / 'src'}",  # its lanes: the core's solve lane (fmu_dyad_lanes.h)
            f"-I{ROOT / 'fmu'}",
            f"-I{ROOT / 'fmu' / 'models'}",
            "-c",
            str(source),
            "-o",
            str(tmp_path / "model.o"),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize("dyad_type", TYPES)
def test_c_table_matches_the_table(generated, dyad_type):
    raw = load_raw(dyad_type)
    c_text = (generated[dyad_type] / f"{identifier(dyad_type)}_model.c").read_text()
    rows = re.findall(
        r'\{(\d+)u, "([^"]*)", "([^"]*)", (FMU_\w+), (FMU_\w+), (FMU_\w+), '
        r"(offsetof\(\w+, [\w.]+\)|0|FMU_SETTING_\w+),\s+(\S+), (\S+), (\S+), ([\w |]+)\}",
        c_text,
    )
    feeds = {
        int(index): field for field, index in re.findall(r"\{(DYAD_FIELD_\w+), (\d+)\}", c_text)
    }
    assert len(rows) == len(raw["variable"])
    for index, (row, v) in enumerate(zip(rows, raw["variable"], strict=True)):
        vr, name, unit, causality, _, target, offset, start = row[:8]
        assert (int(vr), name, unit) == (v["vr"], v["name"], v.get("unit", ""))
        assert causality == "FMU_" + v["causality"].upper()
        assert float(start) == float(v.get("start", 0.0))  # repr round-trips
        if v["name"].endswith("angle"):
            assert target == "FMU_TARGET_INPUT_ANGLE"
        if v["name"] == "link_m.accel_d.x":
            assert offset == "offsetof(dyad_input, m.accel_d.x)"
            assert feeds[index] == "DYAD_FIELD_M_ACCEL_D"
        if v["causality"] == "output":
            assert index not in feeds
        if v["name"] == "status":
            assert (target, offset) == ("FMU_TARGET_RESULT_STATUS", "0")
        if v["name"] == "on_singular":
            assert (target, offset) == ("FMU_TARGET_SETTING", "FMU_SETTING_ON_SINGULAR")
    vr_limit = len(raw["variable"]) + 1
    assert re.search(
        rf"index_of_vr, {vr_limit}, &fmu_dyad_lane_behaviour, &dyad, &copies\}};", c_text
    )
    assert re.search(r"index_of_vr\[\d+\] = \{\s*-1, 0, 1, 2,", c_text)
    # the straight copies of every step: each input from its place in the call to where
    # the layer keeps it (an angle as set, per variable), each output from its result
    inputs = [(i, v) for i, v in enumerate(raw["variable"]) if v["causality"] == "input"]
    outputs = [v for v in raw["variable"] if v["causality"] == "output" and v["type"] == "Real"]
    stores = re.findall(r"^    (.*) = from\[(\d+)\];", c_text, re.MULTILINE)
    loads = re.findall(
        r"^    to\[(\d+)\] = \*\(const double\*\)\(const void\*\)\(out \+ (.*)\);",
        c_text,
        re.MULTILINE,
    )
    assert [int(k) for _, k in stores] == list(range(len(inputs)))
    for (place, _), (index, v) in zip(stores, inputs, strict=True):
        field = v["lives"].removeprefix("input.")
        if field.endswith("@angle"):
            assert place == f"values[{index}]", v["name"]
        else:
            assert place == f"*(double*)(void*)(in + offsetof(dyad_input, {field}))", v["name"]
    assert [int(k) for k, _ in loads] == list(range(len(outputs)))
    for (_, offset), v in zip(loads, outputs, strict=True):
        assert offset == f"offsetof(dyad_result, {v['lives'].removeprefix('result.')})", v["name"]
    assert f"input_vrs, {len(inputs)}, store_inputs, output_vrs, {len(outputs)}" in c_text


def start_values(raw):
    return {v["name"]: float(v["start"]) for v in raw["variable"] if "start" in v}


@pytest.mark.parametrize("dyad_type", TYPES)
def test_start_values_are_valid_and_far_from_singular(dyad_type):
    raw = load_raw(dyad_type)
    values = start_values(raw)
    result = evaluate(dyad_type, values)
    assert result["conditioning"] > 0.9
    assert result["status"] == 0
    assert all(math.isfinite(result[k]) for k in names_of(raw, "output"))
    assert values["gravity.y"] == -9.81 and values["gravity.x"] == 0


@pytest.mark.parametrize("dyad_type", TYPES)
def test_start_values_solve_ok_in_the_c_core(dyad_type):
    from dyadfmu.core import Core, library_path

    if not library_path().is_file():
        pytest.skip(f"C core not built at {library_path()}")
    values = start_values(load_raw(dyad_type))
    m, n, gk, gp, gravity = reference_args(values)
    got = Core().solve(
        dyad_type, m, n, gk, gp, gravity, singular_threshold=values["singular_threshold"]
    )
    assert got["status"] == "ok", got
    assert got["conditioning"] > 0.9


# ---------------------------------------------------------------------------
# the token
# ---------------------------------------------------------------------------
def test_token_follows_the_table():
    raw = load_raw("RRT")
    token = instantiation_token(raw["model"], raw["variable"])
    assert token == pipeline.load_table(TABLE_OF["RRT"]).token
    changed = [dict(v) for v in raw["variable"]]
    changed[0]["description"] += "."
    assert instantiation_token(raw["model"], changed) != token
    as_int = [
        dict(v, start=int(v["start"])) if v.get("start") == int(v.get("start", 0.5)) else v
        for v in raw["variable"]
    ]
    assert instantiation_token(raw["model"], as_int) == token  # 0 and 0.0 agree
    tokens = {pipeline.load_table(TABLE_OF[t]).token for t in TYPES}
    assert len(tokens) == len(TYPES)


# ---------------------------------------------------------------------------
# (d) malformed tables
# ---------------------------------------------------------------------------
def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(x) for x in value) + "]"
    raise TypeError(value)


def write_toml(raw, path):
    lines = ["[model]"] + [f"{k} = {_toml_value(v)}" for k, v in raw["model"].items()]
    for v in raw["variable"]:
        lines += ["", "[[variable]]"] + [f"{k} = {_toml_value(x)}" for k, x in v.items()]
    path.write_text("\n".join(lines) + "\n")


def _var(raw, name):
    return next(v for v in raw["variable"] if v["name"] == name)


def _rename_omega(raw):
    _var(raw, "link_m.omega")["name"] = "link_m.angle"


def _vr_twice(raw):
    _var(raw, "link_n.mass")["vr"] = _var(raw, "link_m.mass")["vr"]


def _vr_gap(raw):
    _var(raw, "link_n.moment")["vr"] += 100


def _no_start(raw):
    del _var(raw, "link_n.inertia")["start"]


def _append_guide_p(raw):
    guide_k = dict(
        _var(raw, "guide_k.angle"),
        name="guide_p.angle",
        lives="input.guide_p@angle",
        description="Guide at D_n",
    )
    raw["variable"].insert(raw["variable"].index(_var(raw, "guide_k.angle")) + 1, guide_k)
    for k, v in enumerate(raw["variable"]):
        v["vr"] = k + 1


MALFORMED = [
    # (id, mutation, the variable the message must name, a fragment of the problem)
    ("duplicate name", _rename_omega, "link_m.angle", "duplicate name"),
    ("duplicate vr", _vr_twice, "link_n.mass", "duplicate vr"),
    ("vr not consecutive", _vr_gap, "link_n.moment", "not consecutive"),
    (
        "unknown causality",
        lambda r: _var(r, "link_m.mass").update(causality="local"),
        "link_m.mass",
        "unknown causality",
    ),
    (
        "unknown type",
        lambda r: _var(r, "link_m.mass").update(type="Boolean"),
        "link_m.mass",
        "unknown type",
    ),
    (
        "unknown unit",
        lambda r: _var(r, "link_m.omega").update(unit="rpm"),
        "link_m.omega",
        "unknown unit",
    ),
    ("wrong unit", lambda r: _var(r, "link_m.omega").update(unit="rad/s2"), "link_m.omega", "unit"),
    ("start missing", _no_start, "link_n.inertia", "start is missing"),
    (
        "start on an output",
        lambda r: _var(r, "R_mk.x").update(start=0.0),
        "R_mk.x",
        "must not have one",
    ),
    (
        "start below min",
        lambda r: _var(r, "link_n.mass").update(start=-1.0),
        "link_n.mass",
        "below min",
    ),
    (
        "start on an exclusive min",
        lambda r: _var(r, "link_n.length").update(start=0.0),
        "link_n.length",
        "below min",
    ),
    (
        "start above max",
        lambda r: _var(r, "singular_threshold").update(start=1.0),
        "singular_threshold",
        "above max",
    ),
    ("bounds off the domain", lambda r: _var(r, "link_m.mass").pop("min"), "link_m.mass", "domain"),
    (
        "depends on a parameter",
        lambda r: _var(r, "R_mk.x")["depends"].append("link_m.mass"),
        "R_mk.x",
        "not an input",
    ),
    (
        "depends on an unknown name",
        lambda r: _var(r, "N_mk")["depends"].append("link_q.angle"),
        "N_mk",
        "unknown variable 'link_q.angle'",
    ),
    (
        "depends missing",
        lambda r: _var(r, "conditioning").pop("depends"),
        "conditioning",
        "depends is missing",
    ),
    (
        "bad lives member",
        lambda r: _var(r, "link_m.omega").update(lives="input.m.omgea"),
        "link_m.omega",
        "no member",
    ),
    (
        "bad lives grammar",
        lambda r: _var(r, "link_m.omega").update(lives="m.omega"),
        "link_m.omega",
        "bad lives",
    ),
    (
        "angle without @angle",
        lambda r: _var(r, "link_m.angle").update(lives="input.m.dir"),
        "link_m.angle",
        "@angle",
    ),
    (
        "lives of another variable",
        lambda r: _var(r, "link_m.omega").update(lives="input.m.epsilon"),
        "link_m.omega",
        "also the home of",
    ),
    ("field the type lacks", _append_guide_p, "guide_p.angle", "no guide i_p"),
    (
        "output the type lacks",
        lambda r: _var(r, "M_mk").update(name="M_np", lives="result.m_np"),
        "M_np",
        "revolute",
    ),
    (
        "fixed length as an input",
        lambda r: _var(r, "link_m.length").update(causality="input"),
        "link_m.length",
        "is a parameter",
    ),
    (
        "unknown key",
        lambda r: _var(r, "link_m.mass").update(colour="red"),
        "link_m.mass",
        "unknown key 'colour'",
    ),
    ("missing variable", lambda r: r["variable"].pop(), "status", "missing variable"),
    (
        "a default run's step beyond its stop",
        lambda r: r["model"].update(stop_time=0.01, step_size=0.1),
        "step_size",
        "must not exceed 'stop_time'",
    ),
    (
        "a default run that is no time",
        lambda r: r["model"].update(stop_time=-1.0),
        "stop_time",
        "must be a positive number of seconds",
    ),
]


@pytest.mark.parametrize(
    "mutation,name,fragment", [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED]
)
def test_malformed_table_is_refused(tmp_path, mutation, name, fragment):
    raw = load_raw("RRT")
    mutation(raw)
    table = tmp_path / "broken_rrt.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode != 0
    assert not (tmp_path / "out").exists(), "nothing may be written from a bad table"
    lines = [ln for ln in proc.stderr.splitlines() if fragment in ln]
    assert lines, proc.stderr
    assert any("broken_rrt.toml" in ln and f"'{name}'" in ln for ln in lines), proc.stderr


def test_unmodified_copy_is_accepted(tmp_path):
    """The TOML writer of the malformed-table test reproduces a valid table."""
    raw = load_raw("RRT")
    table = tmp_path / "dyad_rrt.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr


# ---------------------------------------------------------------------------
# (e) the crank drive
# ---------------------------------------------------------------------------
DRIVE_TABLE = MD_DIR / "interface" / "drive.toml"
DRIVE_HEADER = ROOT / "fmu" / "models" / "fmu_drive.h"

#: name -> (causality, unit, lives), in table order, written out from the specification.
DRIVE_VARIABLES = {
    "load.torque": ("input", "N.m", "input.load_torque"),
    "load.inertia": ("input", "kg.m2", "input.load_inertia"),
    "load.demand": ("input", "N.m", "input.load_demand"),
    "motor.stall_torque": ("parameter", "N.m", "input.stall_torque"),
    "motor.no_load_speed": ("parameter", "rad/s", "input.no_load_speed"),
    "inertia": ("parameter", "kg.m2", "input.inertia"),
    "crank.mass": ("parameter", "kg", "input.crank_mass"),
    "crank.com.x": ("parameter", "m", "input.crank_com_x"),
    "crank.com.y": ("parameter", "m", "input.crank_com_y"),
    "gravity.x": ("parameter", "m/s2", "input.gravity_x"),
    "gravity.y": ("parameter", "m/s2", "input.gravity_y"),
    "start.angle": ("parameter", "rad", "input.start_angle"),
    "start.speed": ("parameter", "rad/s", "input.start_speed"),
    "crank.angle": ("output", "rad", "result.angle"),
    "crank.omega": ("output", "rad/s", "result.speed"),
    "crank.epsilon": ("output", "rad/s2", "result.acceleration"),
    "motor.torque": ("output", "N.m", "result.motor_torque"),
    "status": ("output", None, "result.status"),
}
DRIVE_STARTS = {
    "load.torque": 0.0,
    "load.inertia": 0.0,
    "load.demand": 0.0,
    "motor.stall_torque": 12.0,
    "motor.no_load_speed": 36.0,
    "inertia": 2e-3,
    "crank.mass": 0.25,
    "crank.com.x": 0.02,
    "crank.com.y": 0.003,
    "gravity.x": 0.0,
    "gravity.y": -9.81,
    "start.angle": 0.0,
    "start.speed": 30.0,
}
DRIVE_DEPENDS = {
    "crank.angle": set(),
    "crank.omega": set(),
    "crank.epsilon": {"load.torque", "load.inertia", "load.demand"},
    "motor.torque": set(),
    "status": {"load.torque", "load.inertia", "load.demand"},
}
DRIVE_UNITS = {"rad", "rad/s", "rad/s2", "m", "m/s2", "N.m", "kg", "kg.m2"}  # no N


def load_drive_raw():
    with open(DRIVE_TABLE, "rb") as f:
        return tomllib.load(f)


@pytest.fixture(scope="module")
def generated_drive(tmp_path_factory):
    out = tmp_path_factory.mktemp("generated_drive")
    proc = run_generator(DRIVE_TABLE, "--out", out)
    assert proc.returncode == 0, proc.stderr
    return out


def test_tables_are_the_drive_the_motor_and_the_scenes_of_the_five_dyads():
    """The drive's and the motor's tables are the ones written by hand; the dyads' tables
    come from their scenes, and all are golden-checked. Only the dyad tables go through
    the dyad-only tests (dependency derivation, reference solve)."""
    on_disk = {p.name for p in (MD_DIR / "interface").glob("*.toml")}
    # (c_names_probe.toml is a scene the scene generator learns its C names from)
    assert on_disk == {
        "drive.toml",
        "motor.toml",
        "dyad_interface.toml",
        "c_names_probe.toml",
        "c_names_probe_internal.toml",
        "c_names_probe_ram.toml",
        "c_names_probe_cylinder.toml",
        "c_names_probe_drivers.toml",
        "c_names_probe_bare.toml",
    }
    assert golden_module.TABLES == ("drive.toml", "motor.toml")
    assert {p.name for p in TABLE_OF.values()} == set(golden_module.GOLDEN_SCENES)
    assert all((SCENES_DIR / name).is_file() for name in golden_module.GOLDEN_SCENES)
    assert pipeline.load_table(DRIVE_TABLE).kind is kinds.DRIVE
    assert pipeline.load_table(MOTOR_TABLE).kind is kinds.MOTOR
    assert all(pipeline.load_table(p).kind is kinds.DYAD for p in TABLE_OF.values())
    for t in TYPES:
        built = pipeline.build_table(pipeline.load_scene(SCENES_DIR / f"dyad_{t.lower()}.toml"))
        assert built.kind is kinds.DYAD and built.type == t
        assert built.token == pipeline.load_table(TABLE_OF[t]).token


def test_drive_generator_writes_every_file(generated_drive):
    for rel in (
        "fmi2/modelDescription.xml",
        "fmi3/modelDescription.xml",
        "fmi3/buildDescription.xml",
        "drive_model.c",
        "documentation/index.html",
    ):
        assert (generated_drive / rel).is_file(), rel


def test_drive_xml_equals_golden(generated_drive):
    for version in ("fmi2", "fmi3"):
        golden = MD_DIR / "interface" / "golden" / f"drive_{version}.xml"
        produced = generated_drive / version / "modelDescription.xml"
        assert golden.is_file(), f"{golden} missing: run generate.py --update-golden"
        assert produced.read_bytes() == golden.read_bytes(), (
            f"drive {version} description differs from {golden.name}; review the change and "
            "run modelDescription/generate.py --update-golden"
        )


def test_drive_output_is_deterministic(generated_drive, tmp_path):
    assert run_generator(DRIVE_TABLE, "--out", tmp_path).returncode == 0
    for path in generated_drive.rglob("*"):
        if path.is_file():
            rel = path.relative_to(generated_drive)
            assert (tmp_path / rel).read_bytes() == path.read_bytes(), rel
            assert b"\r" not in path.read_bytes()


def test_drive_table_is_as_specified():
    raw = load_drive_raw()
    assert raw["model"] == {
        "kind": "drive",
        "identifier": "drive",
        "description": raw["model"]["description"],
    }
    assert [v["name"] for v in raw["variable"]] == list(DRIVE_VARIABLES)
    for k, v in enumerate(raw["variable"]):
        causality, unit, lives = DRIVE_VARIABLES[v["name"]]
        assert v["vr"] == k + 1
        assert (v["causality"], v.get("unit"), v["lives"]) == (causality, unit, lives), v["name"]
        assert "@angle" not in v["lives"]
        if causality != "output":
            assert float(v["start"]) == DRIVE_STARTS[v["name"]], v["name"]
        else:
            assert set(v["depends"]) == DRIVE_DEPENDS[v["name"]], v["name"]
    bounds = {
        v["name"]: (v.get("min"), v.get("min_exclusive", False), v.get("max"))
        for v in raw["variable"]
        if "min" in v or "max" in v
    }
    assert bounds == {
        "motor.stall_torque": (0.0, True, None),
        "motor.no_load_speed": (0.0, True, None),
        "inertia": (0.0, True, None),
        "crank.mass": (0.0, False, None),
    }


def test_drive_fmpy_validates_and_interface_is_right(generated_drive, tmp_path):
    md2 = read_fmi2(generated_drive / "fmi2" / "modelDescription.xml")
    md3 = read_fmi3(generated_drive, tmp_path)
    token = md2.guid
    assert re.fullmatch(r"\{[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}\}", token)
    assert md3.instantiationToken == token
    assert token not in {pipeline.load_table(TABLE_OF[t]).token for t in TYPES}

    for md, shim in (
        (md2, ["fmi2_functions.c"]),
        (md3, ["fmi3_functions.c", "fmi3_unsupported.c"]),
    ):
        assert md.coSimulation is not None and md.modelExchange is None
        assert md.coSimulation.modelIdentifier == "drive"
        assert md.variableNamingConvention == "structured"
        description = md.description
        assert "\n" not in description
        assert "states" in description and "doStep" in description
        assert "Runge-Kutta" in description and "RK4" in description
        assert "substeps" in description
        assert float(md.defaultExperiment.stopTime) == 1
        assert float(md.defaultExperiment.stepSize) == 0.001
        assert [c.name for c in md.logCategories] == [
            "logStatusError",
            "logStatusWarning",
            "logStatusDiscard",
            "logCalls",
        ]
        (config,) = md.buildConfigurations
        assert config.modelIdentifier == "drive"
        assert config.sourceFileSets[0].sourceFiles == [
            "fmu_drive.c",
            "fmu_instance.c",
            "fmu_state.c",
            *shim,
            "drive_model.c",
        ]
        units = {u.name: u.baseUnit for u in md.unitDefinitions}
        assert set(units) == DRIVE_UNITS
        for name in DRIVE_UNITS:
            got = {
                k: getattr(units[name], k)
                for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
                if getattr(units[name], k)
            }
            assert got == BASE_UNITS[name], name
    assert md2.coSimulation.providesDirectionalDerivative is False

    variables2 = md2.modelVariables
    variables3 = [v for v in md3.modelVariables if v.causality != "independent"]
    (time,) = [v for v in md3.modelVariables if v.causality == "independent"]
    assert time.name == "time" and time.valueReference == 0
    for variables in (variables2, variables3):
        assert [v.name for v in variables] == list(DRIVE_VARIABLES)
        assert [v.valueReference for v in variables] == list(range(1, len(DRIVE_VARIABLES) + 1))
        for v in variables:
            causality, unit, _ = DRIVE_VARIABLES[v.name]
            assert (v.causality, v.unit) == (causality, unit), v.name
            if causality == "input":
                assert v.variability == "continuous" and float(v.start) == DRIVE_STARTS[v.name]
            elif causality == "parameter":
                assert (v.variability, v.initial) == ("fixed", "exact")
                assert float(v.start) == DRIVE_STARTS[v.name]
            else:
                assert v.initial == "calculated" and v.start is None
                assert v.variability == ("discrete" if v.name == "status" else "continuous")
            want_type = {"status": ("Integer", "Int32"), "on_singular": ("Enumeration",)}
            assert v.type in want_type.get(v.name, ("Real", "Float64")), v.name
    by_name = {v.name: v for v in variables3}
    for name in ("motor.stall_torque", "motor.no_load_speed", "inertia", "crank.mass"):
        assert float(by_name[name].min) == 0 and by_name[name].max is None, name
    for name in ("load.torque", "load.inertia"):
        assert by_name[name].min is None and by_name[name].max is None, name

    # dependencies: an empty list (not "all"), read back as [] rather than None
    for md in (md2, md3):
        assert [u.variable.name for u in md.outputs] == list(DRIVE_DEPENDS)
        for unknown in md.outputs:
            assert unknown.dependencies is not None, unknown.variable.name
            deps = {d.name for d in unknown.dependencies}
            assert deps == DRIVE_DEPENDS[unknown.variable.name], unknown.variable.name
        assert [u.variable.name for u in md.initialUnknowns] == list(DRIVE_DEPENDS)


def test_drive_empty_dependencies_and_no_derivatives_in_the_xml(generated_drive):
    text2 = (generated_drive / "fmi2" / "modelDescription.xml").read_text()
    text3 = (generated_drive / "fmi3" / "modelDescription.xml").read_text()
    for vr in (14, 15, 17):  # crank.angle, crank.omega, motor.torque: index = vr in FMI 2
        assert f'<Unknown index="{vr}" dependencies=""/>' in text2
        assert f'<Output valueReference="{vr}" dependencies=""/>' in text3
    assert '<Unknown index="16" dependencies="1 2 3"/>' in text2
    assert '<Output valueReference="16" dependencies="1 2 3"/>' in text3
    assert '<Unknown index="18" dependencies="1 2 3"/>' in text2
    assert '<Output valueReference="18" dependencies="1 2 3"/>' in text3
    assert 'providesDirectionalDerivative="false"' in text2
    assert 'providesDirectionalDerivatives="false"' in text3
    assert '<Unit name="N">' not in text2 and '<Unit name="N">' not in text3


def _struct_members(header_text, struct):
    body = re.search(rf"typedef struct {struct} \{{(.*?)\}} {struct};", header_text, re.S)
    assert body, f"{struct} not found in {DRIVE_HEADER.name}"
    return re.findall(r"^\s*(?:double|int)\s+(\w+);", body.group(1), re.M)


def test_drive_members_match_the_header():
    """The generator's view of fmu_drive_input / fmu_drive_output is the header's."""
    text = DRIVE_HEADER.read_text()
    assert _struct_members(text, "fmu_drive_input") == list(DRIVE_INPUT_MEMBERS)
    assert _struct_members(text, "fmu_drive_output") == list(DRIVE_OUTPUT_MEMBERS)
    assert re.search(r"^\s*int status;", text, re.M)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available")
def test_drive_c_table_compiles(generated_drive, tmp_path):
    proc = subprocess.run(
        [
            "gcc",
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            f"-I{ROOT / 'fmu'}",
            f"-I{ROOT / 'fmu' / 'models'}",
            f"-I{ROOT / 'src' / 'include'}",  # fmu_model.h: dyadfmu/evaluation.h
            "-c",
            str(generated_drive / "drive_model.c"),
            "-o",
            str(tmp_path / "drive_model.o"),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr


def test_drive_c_table_matches_the_table(generated_drive):
    raw = load_drive_raw()
    token = pipeline.load_table(DRIVE_TABLE).token
    c_text = (generated_drive / "drive_model.c").read_text()
    assert '#include "fmu_drive.h"' in c_text and "fmu_dyad" not in c_text
    assert "dyad_solve" not in c_text and "DYAD_FIELD" not in c_text
    rows = re.findall(
        r'\{(\d+)u, "([^"]*)", "([^"]*)", (FMU_\w+), (FMU_\w+), (FMU_\w+), '
        r"(offsetof\((\w+), ([\w.]+)\)|0),\s+(\S+), (\S+), (\S+), ([\w |]+)\}",
        c_text,
    )
    assert len(rows) == len(raw["variable"])
    for row, v in zip(rows, raw["variable"], strict=True):
        vr, name, unit, causality, value_type, target, _, struct, member, start = row[:10]
        assert (int(vr), name, unit) == (v["vr"], v["name"], v.get("unit", ""))
        assert causality == "FMU_" + v["causality"].upper()
        assert float(start) == float(v.get("start", 0.0))
        block, path = v["lives"].split(".")
        assert struct == ("fmu_drive_input" if block == "input" else "fmu_drive_output")
        assert member == path
        if v["name"] == "status":
            assert (value_type, target) == ("FMU_INTEGER", "FMU_TARGET_RESULT_STATUS")
            assert (struct, member) == ("fmu_drive_output", "status")
        elif block == "input":
            assert target == "FMU_TARGET_INPUT_REAL"
        else:
            assert target == "FMU_TARGET_RESULT_REAL"
    assert "offsetof(fmu_drive_output, status)" in c_text
    assert "FMU_TARGET_INPUT_ANGLE" not in c_text
    assert re.search(r"FMU_HAS_MIN \| FMU_MIN_EXCLUSIVE\}", c_text)
    vr_limit = len(raw["variable"]) + 1
    assert (
        f'const fmu_model fmu_this_model = {{"drive", "{token}",\n'
        f"                                  variables, {len(raw['variable'])}, "
        f"index_of_vr, {vr_limit}, &fmu_drive_behaviour, NULL, &copies}};"
    ) in c_text


def test_drive_documentation_is_complete(generated_drive):
    page = (generated_drive / "documentation" / "index.html").read_text()
    raw = load_drive_raw()
    assert page.startswith("<!DOCTYPE html>") and "</html>" in page
    assert "http" not in page
    for v in raw["variable"]:
        assert f"<code>{v['name']}</code>" in page
    for phrase in (
        "(inertia + load.inertia) eps = T_stall (1 - omega / omega_0) + load.torque + r_c x m_c g",
        "Runge-Kutta",
        "RK4",
        "substeps",
        "time constant",
        "0.005 rad",
        "Explicit",
        "Stabilised",
        "directional derivatives",
        "J_eff",
        "invalid input",
        "Discard",
        "Error",
        "NaN",
        "counter-clockwise",
        "providesDirectionalDerivative",
        pipeline.load_table(DRIVE_TABLE).token,
    ):
        assert phrase in page, phrase
    assert "dyad_solve" not in page


# The drive's equations (fmu/models/fmu_drive.c), to check the declared dependencies by
# perturbation as the dyad tables are checked against the reference solver.
def drive_outputs(values, angle, speed):
    total = values["inertia"] + values["load.inertia"]
    motor = values["motor.stall_torque"] * (1 - speed / values["motor.no_load_speed"])
    if not total > 0:
        return {
            "crank.angle": angle,
            "crank.omega": speed,
            "crank.epsilon": math.nan,
            "motor.torque": math.nan,
            "status": 2,
        }
    c, s = math.cos(angle), math.sin(angle)
    rx = c * values["crank.com.x"] - s * values["crank.com.y"]
    ry = s * values["crank.com.x"] + c * values["crank.com.y"]
    gravity = values["crank.mass"] * (rx * values["gravity.y"] - ry * values["gravity.x"])
    epsilon = (motor + values["load.torque"] - values["load.demand"] + gravity) / total
    if not (math.isfinite(epsilon) and math.isfinite(motor)):
        return {
            "crank.angle": angle,
            "crank.omega": speed,
            "crank.epsilon": math.nan,
            "motor.torque": motor if math.isfinite(motor) else math.nan,
            "status": 3,
        }
    return {
        "crank.angle": angle,
        "crank.omega": speed,
        "crank.epsilon": epsilon,
        "motor.torque": motor,
        "status": 0,
    }


def test_drive_declared_dependencies_are_the_true_ones():
    """As for the dyads: among valid inputs, an output depends on an input if it changes
    with it; `status` depends on what decides validity (inertia + load.inertia > 0) and
    on what can overflow the acceleration (load.torque, load.demand)."""
    rng = np.random.default_rng(7)
    raw = load_drive_raw()
    inputs = names_of(raw, "input")
    derived = {name: set() for name in names_of(raw, "output")}
    for _ in range(6):
        values = {name: float(rng.uniform(0.5, 2.0)) for name in DRIVE_STARTS}
        values["load.torque"] = float(rng.uniform(-5, 5))
        values["load.inertia"] = float(rng.uniform(0, 0.1))
        angle, speed = float(rng.uniform(0, 2 * math.pi)), float(rng.uniform(-40, 40))
        base = drive_outputs(values, angle, speed)
        for name in inputs:
            trial = dict(values, **{name: values[name] + float(rng.uniform(0.01, 0.1))})
            other = drive_outputs(trial, angle, speed)
            assert other["status"] == 0
            for out in derived:
                if out != "status" and abs(other[out] - base[out]) > 1e-12 * (1 + abs(base[out])):
                    derived[out].add(name)
    # validity: inertia (a parameter) + load.inertia > 0, and a finite acceleration
    derived["status"] = {"load.inertia", "load.torque", "load.demand"}
    assert drive_outputs(dict(DRIVE_STARTS, **{"load.inertia": -1.0}), 0.0, 0.0)["status"] == 2
    assert (
        drive_outputs(dict(DRIVE_STARTS, **{"load.torque": -1.7976931348623157e308}), 0.0, 0.0)[
            "status"
        ]
        == 3
    )
    demand = dict(DRIVE_STARTS, **{"load.demand": 1.7976931348623157e308})
    assert drive_outputs(demand, 0.0, 0.0)["status"] == 3
    declared = {v["name"]: set(v["depends"]) for v in raw["variable"] if v["causality"] == "output"}
    assert declared == derived == DRIVE_DEPENDS


def test_drive_start_values_are_valid():
    values = start_values(load_drive_raw())
    out = drive_outputs(values, values["start.angle"], values["start.speed"])
    assert out["status"] == 0 and all(math.isfinite(x) for x in out.values())
    assert values["gravity.y"] == -9.81 and values["gravity.x"] == 0


def test_drive_and_dyad_tokens_differ_and_follow_the_table():
    raw = load_drive_raw()
    token = pipeline.load_table(DRIVE_TABLE).token
    assert token == instantiation_token(raw["model"], raw["variable"])
    changed = dict(raw["model"], description=raw["model"]["description"] + ".")
    assert instantiation_token(changed, raw["variable"]) != token


def _drive_var(raw, name):
    return next(v for v in raw["variable"] if v["name"] == name)


def _drop_drive_variable(raw, name):
    raw["variable"].remove(_drive_var(raw, name))
    for k, v in enumerate(raw["variable"]):
        v["vr"] = k + 1
    for v in raw["variable"]:
        if "depends" in v:
            v["depends"] = [d for d in v["depends"] if d != name]


MALFORMED_DRIVE = [
    (
        "lives to no member",
        lambda r: _drive_var(r, "load.torque").update(lives="input.load_torq"),
        "load.torque",
        "fmu_drive_input has no member 'load_torq'",
    ),
    (
        "lives to no output member",
        lambda r: _drive_var(r, "crank.omega").update(lives="result.omega"),
        "crank.omega",
        "fmu_drive_output has no member 'omega'",
    ),
    (
        "lives to a dyad member",
        lambda r: _drive_var(r, "gravity.x").update(lives="input.gravity.x"),
        "gravity.x",
        "bad lives",
    ),
    (
        "lives to a state",
        lambda r: _drive_var(r, "start.angle").update(lives="input.angle"),
        "start.angle",
        "is a state of the drive",
    ),
    (
        "lives with @angle",
        lambda r: _drive_var(r, "start.angle").update(lives="input.start_angle@angle"),
        "start.angle",
        "@angle",
    ),
    (
        "lives of another variable",
        lambda r: _drive_var(r, "motor.torque").update(lives="result.acceleration"),
        "motor.torque",
        "also the home of",
    ),
    (
        "missing stall torque",
        lambda r: _drop_drive_variable(r, "motor.stall_torque"),
        "motor.stall_torque",
        "missing variable",
    ),
    (
        "missing load inertia",
        lambda r: _drop_drive_variable(r, "load.inertia"),
        "load.inertia",
        "missing variable",
    ),
    (
        "wrong name for lives",
        lambda r: _drive_var(r, "crank.omega").update(name="crank.speed"),
        "crank.speed",
        "expected 'crank.omega'",
    ),
    ("wrong unit", lambda r: _drive_var(r, "load.torque").update(unit="N"), "load.torque", "unit"),
    (
        "unknown unit",
        lambda r: _drive_var(r, "start.speed").update(unit="rpm"),
        "start.speed",
        "unknown unit",
    ),
    (
        "input as a parameter",
        lambda r: _drive_var(r, "load.inertia").update(causality="parameter"),
        "load.inertia",
        "is an input of the drive",
    ),
    (
        "start on the exclusive min",
        lambda r: _drive_var(r, "inertia").update(start=0.0),
        "inertia",
        "below min",
    ),
    (
        "bounds off the domain",
        lambda r: _drive_var(r, "crank.mass").pop("min"),
        "crank.mass",
        "domain",
    ),
    (
        "bounds on an unbounded input",
        lambda r: _drive_var(r, "load.inertia").update(min=0.0),
        "load.inertia",
        "domain",
    ),
    (
        "start missing",
        lambda r: _drive_var(r, "start.speed").pop("start"),
        "start.speed",
        "start is missing",
    ),
    (
        "vr out of order",
        lambda r: _drive_var(r, "inertia").update(vr=9),
        "inertia",
        "not consecutive",
    ),
    (
        "parameter after an output",
        lambda r: (
            r["variable"].append(
                r["variable"].pop(r["variable"].index(_drive_var(r, "start.speed")))
            )
            or [v.update(vr=k + 1) for k, v in enumerate(r["variable"])]
        ),
        "start.speed",
        "parameter after outputs",
    ),
    (
        "a dependency too few",
        lambda r: _drive_var(r, "crank.epsilon")["depends"].pop(),
        "crank.epsilon",
        "true dependencies",
    ),
    (
        "a dependency too many",
        lambda r: _drive_var(r, "crank.angle")["depends"].append("load.torque"),
        "crank.angle",
        "true dependencies",
    ),
    (
        "depends missing",
        lambda r: _drive_var(r, "motor.torque").pop("depends"),
        "motor.torque",
        "depends is missing",
    ),
    (
        "unknown key",
        lambda r: _drive_var(r, "inertia").update(colour="red"),
        "inertia",
        "unknown key 'colour'",
    ),
]


@pytest.mark.parametrize(
    "mutation,name,fragment", [m[1:] for m in MALFORMED_DRIVE], ids=[m[0] for m in MALFORMED_DRIVE]
)
def test_malformed_drive_table_is_refused(tmp_path, mutation, name, fragment):
    raw = load_drive_raw()
    mutation(raw)
    table = tmp_path / "broken_drive.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode != 0
    assert not (tmp_path / "out").exists(), "nothing may be written from a bad table"
    lines = [ln for ln in proc.stderr.splitlines() if fragment in ln]
    assert lines, proc.stderr
    assert any("broken_drive.toml" in ln and f"'{name}'" in ln for ln in lines), proc.stderr


@pytest.mark.parametrize(
    "model,fragment",
    [
        ({"kind": "drive", "type": "RRT"}, "only a dyad has a type"),
        ({"kind": "pump"}, "kind 'pump' is not one of dyad, drive, motor"),
        ({"kind": "dyad"}, "type None is not one of"),
        ({"kind": "drive", "colour": "red"}, "[model]: unknown key 'colour'"),
    ],
    ids=["drive with a type", "unknown kind", "dyad kind without a type", "unknown model key"],
)
def test_malformed_drive_model_is_refused(tmp_path, model, fragment):
    raw = load_drive_raw()
    raw["model"] = dict({k: v for k, v in raw["model"].items() if k != "kind"}, **model)
    table = tmp_path / "broken_drive.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode != 0
    assert not (tmp_path / "out").exists()
    assert any("broken_drive.toml" in ln and fragment in ln for ln in proc.stderr.splitlines()), (
        proc.stderr
    )


def test_dyad_table_may_name_its_kind(tmp_path):
    """kind = "dyad" is the default: saying it is accepted (with another token)."""
    raw = load_raw("RRT")
    raw["model"] = {"kind": "dyad", **raw["model"]}
    table = tmp_path / "dyad_rrt.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr


def test_drive_lives_must_not_name_dyad_structs():
    with pytest.raises(ValueError, match="no member"):
        kinds.DRIVE.parse_lives("input.m.omega")
    with pytest.raises(ValueError, match="no member"):
        kinds.DYAD.parse_lives("input.load_torque")  # a dyad's lives
    lives = kinds.DRIVE.parse_lives("result.status")
    assert (lives.target, lives.offset, lives.field) == (
        "FMU_TARGET_RESULT_STATUS",
        "offsetof(fmu_drive_output, status)",
        "DYAD_FIELD_NONE",
    )
    assert kinds.DYAD.parse_lives("result.status").offset == "0"  # dyads: as they always were


def test_unmodified_drive_copy_is_accepted(tmp_path):
    raw = load_drive_raw()
    table = tmp_path / "drive.toml"
    write_toml(raw, table)
    proc = run_generator(table, "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr
    assert pipeline.load_table(table).token == pipeline.load_table(DRIVE_TABLE).token


# ---------------------------------------------------------------------------
# (e') the DC motor: a model with a state that interpolates its inputs
# ---------------------------------------------------------------------------
MOTOR_TABLE = MD_DIR / "interface" / "motor.toml"
MOTOR_HEADER = ROOT / "fmu" / "models" / "fmu_motor.h"
#: name -> (causality, unit, lives), in table order, written out from the specification.
MOTOR_VARIABLES = {
    "motor.voltage": ("input", "V", "input.voltage"),
    "shaft.omega": ("input", "rad/s", "input.omega"),
    "motor.resistance": ("parameter", "Ohm", "input.resistance"),
    "motor.inductance": ("parameter", "H", "input.inductance"),
    "motor.torque_constant": ("parameter", "N.m/A", "input.torque_constant"),
    "motor.friction": ("parameter", "N.m.s/rad", "input.friction"),
    "motor.ratio": ("parameter", None, "input.ratio"),
    "motor.current_start": ("parameter", "A", "input.current_start"),
    "shaft.torque": ("output", "N.m", "result.torque"),
    "motor.current": ("output", "A", "result.current"),
    "status": ("output", None, "result.status"),
}
#: (min, exclusive): R, k and r positive, L and c not negative.
MOTOR_BOUNDS = {
    "motor.resistance": (0.0, True),
    "motor.inductance": (0.0, False),
    "motor.torque_constant": (0.0, True),
    "motor.friction": (0.0, False),
    "motor.ratio": (0.0, True),
}


@pytest.fixture(scope="module")
def generated_motor(tmp_path_factory):
    out = tmp_path_factory.mktemp("generated_motor")
    proc = run_generator(MOTOR_TABLE, "--out", out)
    assert proc.returncode == 0, proc.stderr
    return out


def test_motor_xml_equals_golden_and_is_deterministic(generated_motor, tmp_path):
    for version in ("fmi2", "fmi3"):
        golden = MD_DIR / "interface" / "golden" / f"motor_{version}.xml"
        produced = generated_motor / version / "modelDescription.xml"
        assert produced.read_bytes() == golden.read_bytes(), (
            f"motor {version} description differs from {golden.name}; review the change and "
            "run modelDescription/generate.py --update-golden"
        )
    assert run_generator(MOTOR_TABLE, "--out", tmp_path).returncode == 0
    for path in generated_motor.rglob("*"):
        if path.is_file():
            assert (tmp_path / path.relative_to(generated_motor)).read_bytes() == path.read_bytes()


def test_motor_fmpy_validates_and_interface_is_right(generated_motor, tmp_path):
    md2 = read_fmi2(generated_motor / "fmi2" / "modelDescription.xml")
    md3 = read_fmi3(generated_motor, tmp_path)
    assert md3.instantiationToken == md2.guid == pipeline.load_table(MOTOR_TABLE).token
    assert md2.coSimulation.canInterpolateInputs is True
    for md, shim in (
        (md2, ["fmi2_functions.c"]),
        (md3, ["fmi3_functions.c", "fmi3_unsupported.c"]),
    ):
        assert md.coSimulation.modelIdentifier == "motor"
        assert md.coSimulation.maxOutputDerivativeOrder == 1
        assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
        (config,) = md.buildConfigurations
        assert config.sourceFileSets[0].sourceFiles == [
            "fmu_motor.c",
            "fmu_instance.c",
            "fmu_state.c",
            *shim,
            "motor_model.c",
        ]
        variables = [v for v in md.modelVariables if v.causality != "independent"]
        assert [v.name for v in variables] == list(MOTOR_VARIABLES)
        assert [v.valueReference for v in variables] == list(range(1, len(MOTOR_VARIABLES) + 1))
        for v in variables:
            causality, unit, _ = MOTOR_VARIABLES[v.name]
            assert (v.causality, v.unit) == (causality, unit), v.name
            if v.name in MOTOR_BOUNDS:
                assert float(v.min) == MOTOR_BOUNDS[v.name][0] and v.max is None, v.name
        # every output depends on both inputs: without inductance the current follows them
        for unknown in md.outputs:
            assert {d.name for d in unknown.dependencies} == {"motor.voltage", "shaft.omega"}
    assert md2.coSimulation.providesDirectionalDerivative is False


def test_motor_table_bounds_are_exclusive_where_positive():
    with open(MOTOR_TABLE, "rb") as f:
        raw = tomllib.load(f)
    bounds = {
        v["name"]: (v["min"], v.get("min_exclusive", False)) for v in raw["variable"] if "min" in v
    }
    assert bounds == MOTOR_BOUNDS
    assert [v["lives"] for v in raw["variable"]] == [x[2] for x in MOTOR_VARIABLES.values()]


def test_motor_members_match_the_header():
    text = MOTOR_HEADER.read_text()
    assert _struct_members(text, "fmu_motor_input") == list(MOTOR_INPUT_MEMBERS)
    assert _struct_members(text, "fmu_motor_output") == list(MOTOR_OUTPUT_MEMBERS)


def test_motor_state_and_rates_are_no_variables():
    for lives, why in (
        ("input.current", "is a state of the motor"),
        ("input.voltage_rate", "first derivative of an input"),
        ("input.torque", "has no member"),
    ):
        with pytest.raises(ValueError, match=why):
            kinds.MOTOR.parse_lives(lives)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available")
def test_motor_c_table_compiles(generated_motor, tmp_path):
    proc = subprocess.run(
        ["gcc", "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror"]
        + [f"-I{ROOT / 'fmu'}", f"-I{ROOT / 'fmu' / 'models'}", f"-I{ROOT / 'src' / 'include'}"]
        + ["-c", str(generated_motor / "motor_model.c"), "-o", str(tmp_path / "motor_model.o")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr


def test_motor_documentation_is_complete(generated_motor):
    page = (generated_motor / "documentation" / "index.html").read_text()
    for name in MOTOR_VARIABLES:
        assert f"<code>{name}</code>" in page, name
    for phrase in ("L di/dt = V - R i - k r omega", "expm1", "no rotor inertia", "phi2"):
        assert phrase in page, phrase


def _write_generic_tables():
    out = Path(tempfile.mkdtemp(prefix="dyadfmu_tables_"))
    atexit.register(shutil.rmtree, out, ignore_errors=True)  # written at import, read by tests
    for t in TYPES:
        path = out / f"dyad_{t.lower()}.toml"
        write_toml(kinds.generic_data(pipeline.load_scene(SCENES_DIR / path.name)), path)
        TABLE_OF[t] = path


_write_generic_tables()


@pytest.mark.parametrize("dyad_type", TYPES)
def test_bounds_are_the_core_domains(dyad_type):
    """A dyad FMU checks each value against its variable's bounds where it is set and
    then solves without the core's check of its input (dyad_solve_valid_<type>). That
    holds only if the bounds are the domains the core checks: a length may be 0 exactly
    where the C core's dyad_length_may_be_zero says so, a mass and an inertia not
    below 0, the singular threshold strictly between 0 and 1, every other field any
    finite number, and a direction set only as an angle (a unit vector)."""
    import ctypes

    from dyadfmu.core import library_path

    lib = ctypes.CDLL(str(library_path()))
    lib.dyad_length_may_be_zero.argtypes = [ctypes.c_int, ctypes.c_int]
    checked = 0
    for v in load_raw(dyad_type)["variable"]:
        lives = v.get("lives", "")
        if v["causality"] == "output" or not lives.startswith("input."):
            continue
        field = lives.removeprefix("input.")
        bounds = (
            v.get("min"),
            v.get("max"),
            v.get("min_exclusive", False),
            v.get("max_exclusive", False),
        )
        leaf = field.split(".")[-1].split("@")[0]
        if leaf == "length":
            may_be_zero = lib.dyad_length_may_be_zero(TYPES.index(dyad_type), "mn".index(field[0]))
            expected = (0.0, None, not may_be_zero, False)
        elif leaf in ("mass", "inertia"):
            expected = (0.0, None, False, False)
        elif field == "singular_threshold":
            expected = (0.0, 1.0, True, True)
        else:
            expected = (None, None, False, False)
        if leaf in ("dir", "guide_k", "guide_p"):
            assert field.endswith("@angle"), f"{v['name']}: a direction is set as an angle"
        assert bounds == expected, f"{dyad_type} {v['name']}: bounds {bounds}, core {expected}"
        checked += 1
    assert checked >= 25


def test_angles_display_in_degrees_and_speeds_in_rpm():
    """Every built FMU, FMI 2 and 3: a variable in rad shows in deg, one in rad/s in rpm,
    by the unit definitions' factors (shown = factor * value)."""
    from dyadfmu import paths
    from fmpy import read_model_description

    fmus = sorted((paths.build_dir() / "fmus").glob("*.fmu"))
    if not fmus:
        pytest.skip("no FMU built")
    want = {"rad": ("deg", 180 / math.pi), "rad/s": ("rpm", 60 / (2 * math.pi))}
    for fmu in fmus:
        md = read_model_description(str(fmu))
        declared = {
            u.name: [(d.name, d.factor, d.offset) for d in u.displayUnits]
            for u in md.unitDefinitions
        }
        for unit, (name, factor) in want.items():
            if unit in declared:
                ((shown, got, offset),) = declared[unit]
                assert shown == name and got == pytest.approx(factor, rel=1e-15), fmu.name
                assert offset in (None, 0, 0.0), fmu.name
        for v in md.modelVariables:
            expected = want.get(v.unit, (None,))[0]
            assert v.displayUnit == expected, (fmu.name, v.name)

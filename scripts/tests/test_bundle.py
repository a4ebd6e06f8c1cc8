"""A scene's bundle for firmware (scripts/build-scene --bundle, modelDescription/scene.py
--bundle): the folder holds exactly the C a firmware compiles to call <id>_evaluate.

For two mechanisms (the shaper and the lift, whose FMUs the build makes) and a tailored
scene of all five dyad types (the C names probe, whose FMU is built here from the list
its build description gives) the bundle, copied to a folder of its own, is compiled
alone (nothing of the checkout on the include path) with -std=c99 -Wall -Wextra
-Wpedantic -Werror, in double and in float, with a main that fills the input block,
evaluates and prints every output; those agree with the FMU's at the same inputs, and
with --with-derivatives so do the rates with the FMU's directional derivative. nm shows
that an evaluate-only link holds no tangent or dual code and that each core file of the
bundle is needed. The bundle's own CMakeLists.txt builds, on its core/ and on the core
that `cmake --install` installs (as tests/consumer uses it), and build-scene measures
the size into the README.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave
from dyadgen import pipeline
from dyadgen.locations import C_NAMES_PROBE, SCENES_DIR
from tool_checks import required_tool

ROOT = paths.ROOT
BUILD_SCENE = ROOT / "scripts" / "build-scene"
SCENE_TOOL = ROOT / "modelDescription" / "scene.py"
WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O1"]
FLOAT = "-DDYAD_REAL_FLOAT"
#: the scenes bundled: two mechanisms, and a tailored scene of every dyad type
SCENES = {
    "shaper": SCENES_DIR / "shaper.toml",
    "lift": SCENES_DIR / "lift.toml",
    "zqid": C_NAMES_PROBE,
}
#: the names of the derivative's code (dyad_react_tangent_of, dyad_point_on_link_dual,
#: dyad_force_size_rate, ...): nothing of it in an evaluate-only link
DERIVATIVE_SYMBOL = re.compile(r"tangent|dual|_rate$", re.IGNORECASE)


def _run(*command: object, cwd: Path | None = None) -> str:
    done = subprocess.run(
        [str(c) for c in command], capture_output=True, text=True, cwd=cwd, check=False
    )
    assert done.returncode == 0, (
        f"{' '.join(map(str, command))} exited with {done.returncode}:\n"
        f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    )
    return done.stdout


def _table(name: str):
    return pipeline.build_table(pipeline.load_scene(SCENES[name], check_c_names=False))


# ---------------------------------------------------------------------------
# The inputs, the test's main and the FMU
# ---------------------------------------------------------------------------
def _block_inputs(table) -> list:
    targets = ("FMU_TARGET_INPUT_REAL", "FMU_TARGET_INPUT_ANGLE")
    return [v for v in table.variables if v.lives.target in targets]


def _outputs(table) -> list:
    return [v for v in table.variables if v.lives.target == "FMU_TARGET_RESULT_REAL"]


def _inputs_at(table) -> dict[str, float]:
    """Values of the inputs away from their starts (parameters stay at theirs): an angle
    turned, a position moved a little, a rate or a load made non-zero."""
    values = {}
    inputs = [v for v in _block_inputs(table) if v.causality == "input"]
    for k, v in enumerate(inputs):
        start = float(v.start)
        if v.lives.target == "FMU_TARGET_INPUT_ANGLE":
            values[v.name] = start + 0.7 + 0.37 * k
        elif v.unit == "m":
            values[v.name] = start + 0.01 * (k + 1)
        else:
            values[v.name] = start + (1.0 + 0.5 * k) * {"N": 100.0, "N.m": 10.0}.get(v.unit, 1.0)
    return values


def _main_c(table, values: dict[str, float], derivative: bool) -> str:
    """A program that fills the input block (the parameters at their starts), evaluates,
    prints every Real output and, with `derivative`, the rates along the first input."""
    ident = table.identifier
    lines = ["#include <stdio.h>", "#include <string.h>", f'#include "{ident}_scene.h"', ""]
    lines += ["int main(void)", "{", f"    {ident}_input in;", f"    {ident}_output out;"]
    lines.append("    fmu_evaluation evaluation;")
    if derivative:
        lines += [f"    {ident}_input seed;", f"    {ident}_output rate;"]
        lines.append("    memset(&seed, 0, sizeof seed);")
    for v in _block_inputs(table):
        value = repr(values.get(v.name, float(v.start)))
        if v.lives.target == "FMU_TARGET_INPUT_ANGLE":
            value = f"dyad_dir_from_angle({value})"
        lines.append(f"    in.{v.lives.path} = {value};")
    call = f"{ident}_evaluate(&in, &out, &evaluation);"
    if derivative:
        first = next(v for v in _block_inputs(table) if v.name == next(iter(values)))
        m = first.lives.path
        if first.lives.target == "FMU_TARGET_INPUT_ANGLE":
            lines.append(f"    seed.{m} = dyad_vec2_make(-in.{m}.y, in.{m}.x);")
        else:
            lines.append(f"    seed.{m} = 1.0;")
        call = f"{ident}_derivative(&in, &seed, &out, &rate, &evaluation);"
    lines += [f"    {call}", '    printf("status %d %d\\n", (int)evaluation.status, out.status);']
    for v in _outputs(table):
        lines.append(f'    printf("out {v.name} %.17g\\n", out.{v.lives.path});')
        if derivative:
            lines.append(f'    printf("rate {v.name} %.17g\\n", rate.{v.lives.path});')
    return "\n".join(lines + ["    return 0;", "}", ""])


def _printed(text: str) -> dict[str, float]:
    found = {}
    for line in text.splitlines():
        kind, name, value = line.split(" ", 2)
        found[f"{kind} {name}"] = float(value) if kind != "status" else value
    return found


def _fmu_of_probe(table, tmp: Path) -> Path:
    """The probe's FMI 2 FMU, compiled as CMake compiles an FMU from the C files its build
    description lists (an undefined symbol fails the link)."""
    from fmpy import __file__ as fmpy_init

    gen = tmp / "generated"
    pipeline.write_files(gen, pipeline.outputs_of(table))
    places = (ROOT / "src", ROOT / "fmu", gen)
    sources = [
        next(p / f for p in places if (p / f).is_file()) for f in table.kind.source_files(table, 2)
    ]
    binary = tmp / "binaries" / "linux64" / f"{table.identifier}.so"
    binary.parent.mkdir(parents=True)
    includes = [ROOT / "src" / "include", ROOT / "src", ROOT / "fmu", gen]
    includes.append(Path(fmpy_init).parent / "c-code")
    _run(
        "cc", *WARNINGS, "-fPIC", "-shared", "-fvisibility=hidden", "-Wl,--no-undefined",
        f"-Wl,--version-script={ROOT / 'fmu' / 'exports.map'}", *[f"-I{i}" for i in includes],
        *sources, "-o", binary, "-lm",
    )  # fmt: skip
    fmu = tmp / f"{table.identifier}_fmi2.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.write(gen / "fmi2" / "modelDescription.xml", "modelDescription.xml")
        archive.write(binary, f"binaries/linux64/{table.identifier}.so")
    return fmu


@pytest.fixture(scope="module")
def fmu_results(tmp_path_factory):
    """Per scene: the FMU's outputs and their rates along the first input, at the inputs
    of _inputs_at, keyed as the test's main prints them."""
    cache: dict[str, dict] = {}

    def results(name: str) -> dict[str, float]:
        if name not in cache:
            table = _table(name)
            if name == "zqid":
                path = _fmu_of_probe(table, tmp_path_factory.mktemp("probe_fmu"))
            else:
                path = paths.built_fmu(name, 2, None, how="scripts/run-tests")
            cache[name] = _fmu_at(path, table)
        return cache[name]

    return results


def _fmu_at(path: Path, table) -> dict[str, float]:
    values = _inputs_at(table)
    outputs = tuple(v.name for v in _outputs(table))
    slave = Slave(path, instance_name=table.identifier)
    try:
        slave.initialize()
        slave.set(tuple(values), list(values.values()))
        slave.do_step(0.0, 1e-3)
        assert slave.get_status() == 0, "the FMU has no answer at the test's inputs"
        found = dict(zip((f"out {n}" for n in outputs), slave.get(outputs), strict=True))
        rates = slave.directional_derivative(outputs, (next(iter(values)),), [1.0])
        found.update(zip((f"rate {n}" for n in outputs), rates, strict=True))
    finally:
        slave.close()
    return found


# ---------------------------------------------------------------------------
# The bundles
# ---------------------------------------------------------------------------
def _scene_tool(*args: object) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(SCENE_TOOL), *map(str, args)], capture_output=True, text=True
    )


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    """The bundle of a scene, with or without derivatives, written by scene.py --bundle and
    then copied to a folder of its own (so that no path leads back to the checkout)."""
    cache: dict[tuple, Path] = {}

    def make(name: str, derivatives: bool) -> Path:
        if (name, derivatives) not in cache:
            out = tmp_path_factory.mktemp("written")
            extra = ["--with-derivatives"] if derivatives else []
            done = _scene_tool(SCENES[name], "--bundle", out, *extra)
            assert done.returncode == 0, done.stderr
            ident = _table(name).identifier
            assert done.stdout.strip() == str(out / ident)
            alone = tmp_path_factory.mktemp("alone") / ident
            shutil.copytree(out / ident, alone)
            cache[name, derivatives] = alone
        return cache[name, derivatives]

    return make


def _compile(folder: Path, table, flags: list[str], work: Path, derivative: bool) -> Path:
    """The test's main on the bundle's scene/ and core/src/, compiled alone and linked."""
    work.mkdir(parents=True, exist_ok=True)
    (work / "main.c").write_text(_main_c(table, _inputs_at(table), derivative))
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    objects = []
    for source in [work / "main.c", *sources]:
        objects.append(work / f"{source.stem}.o")
        _run(
            "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
            "-c", source, "-o", objects[-1],
        )  # fmt: skip
    _run("cc", "-o", work / "main", *objects, "-lm")
    return work / "main"


def _symbols(program: Path) -> list[str]:
    return [line.split()[-1] for line in _run("nm", program).splitlines() if line.split()]


def _derivative_symbols(program: Path) -> list[str]:
    return [n for n in _symbols(program) if DERIVATIVE_SYMBOL.search(n)]


def _agree(found: dict, expected: dict, kinds: tuple, table, tolerance: float) -> None:
    """Every printed value of `kinds` within `tolerance` of the largest of its unit."""
    unit = {v.name: v.unit for v in _outputs(table)}
    for kind in kinds:
        keys = [k for k in expected if k.startswith(kind + " ")]
        scale: dict[str, float] = {}
        for k in keys:
            u = unit[k.split(" ", 1)[1]]
            scale[u] = max(scale.get(u, 0.0), abs(expected[k]))
        for k in keys:
            limit = tolerance * max(scale[unit[k.split(" ", 1)[1]]], 1e-30)
            assert math.isfinite(found[k]) and abs(found[k] - expected[k]) <= limit, (
                k, found[k], expected[k],
            )  # fmt: skip


# ---------------------------------------------------------------------------
# The tests
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("derivatives", [False, True], ids=["evaluate", "derivatives"])
@pytest.mark.parametrize("real", ["double", "float"])
@pytest.mark.parametrize("name", list(SCENES))
def test_the_bundle_compiles_alone_and_agrees_with_the_fmu(
    name, real, derivatives, bundle, fmu_results, tmp_path
):
    required_tool("cc")
    required_tool("nm")
    table = _table(name)
    folder = bundle(name, derivatives)
    flags = [FLOAT] if real == "float" else []
    program = _compile(folder, table, flags, tmp_path / "build", derivatives)
    found = _printed(_run(program))
    assert found["status 0"] == "0", found["status 0"]  # FMU_OK, out.status 0
    tolerance = 1e-9 if real == "double" else 1e-3
    kinds = ("out", "rate") if derivatives else ("out",)
    _agree(found, fmu_results(name), kinds, table, tolerance)
    symbols = _symbols(program)
    derivative = [n for n in symbols if DERIVATIVE_SYMBOL.search(n)]
    if derivatives:
        assert f"{table.identifier}_derivative" in symbols
        assert "dyad_react_tangent_of" in derivative and "dyad_force_size_rate" in derivative
    else:
        assert f"{table.identifier}_evaluate" in symbols and derivative == [], derivative


@pytest.mark.parametrize("name", list(SCENES))
def test_the_bundle_holds_exactly_the_files_evaluate_needs(name, bundle, tmp_path):
    """Each core source of an evaluate-only bundle is needed (the link fails without it),
    each header is included by a file of the bundle, nothing is a derivative's, and
    --with-derivatives adds the scene's and the core's tangents and nothing else."""
    required_tool("cc")
    table = _table(name)
    folder = bundle(name, False)
    files = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    assert not [f for f in files if "tangent" in f], sorted(files)
    ident = table.identifier
    top = {"README.md", "CMakeLists.txt", "LICENSE", f"example/{ident}_example.c"}
    scene = {f"scene/{ident}_scene.h", f"scene/{ident}_scene.c"}
    assert top | scene <= files
    texts = [(folder / f).read_text() for f in files if f.endswith((".c", ".h"))]
    included = {Path(n).name for t in texts for n in re.findall(r'#include "([^"]+)"', t)}
    headers = {Path(f).name for f in files if f.startswith("core/") and f.endswith(".h")}
    assert headers <= included, sorted(headers - included)
    program = _compile(folder, table, [], tmp_path / "all", derivative=False)
    objects = sorted(program.parent.glob("dyad_*.o"))
    assert objects and len(objects) == len(
        [f for f in files if f.startswith("core/src/") and f.endswith(".c")]
    )
    for left_out in objects:
        rest = [o for o in program.parent.glob("*.o") if o != left_out]
        done = subprocess.run(
            ["cc", "-o", tmp_path / "x", *rest, "-lm"], capture_output=True, text=True
        )
        assert done.returncode != 0 and "undefined reference" in done.stderr, left_out.name
    with_derivatives = bundle(name, True)
    more = {
        p.relative_to(with_derivatives).as_posix()
        for p in with_derivatives.rglob("*")
        if p.is_file()
    }
    added = more - files
    assert f"scene/{ident}_scene_tangent.c" in added and "core/src/dyad_tangent.c" in added
    assert all("tangent" in f for f in added), sorted(added)
    assert files - more == set()


def test_the_bundle_builds_with_its_own_cmakelists(bundle, fmu_results, tmp_path):
    """cmake on the bundle alone, in float: its example runs and prints the shaper's
    outputs at the scene's start values, as the FMU gives them there."""
    required_tool("cmake")
    folder = bundle("shaper", True)
    build = tmp_path / "build"
    _run("cmake", "-S", folder, "-B", build, "-DDYADFMU_FLOAT=ON", "-DCMAKE_BUILD_TYPE=Release")
    _run("cmake", "--build", build)
    printed = _run(build / "shaper_example")
    torque = float(re.search(r"^crank\.torque +(\S+) N\.m$", printed, re.M).group(1))
    slave = Slave(paths.built_fmu("shaper", 2, None, how="scripts/run-tests"))
    try:
        slave.initialize()
        slave.do_step(0.0, 1e-3)
        expected = slave.get("crank.torque")
    finally:
        slave.close()
    assert expected != 0 and abs(torque - expected) <= 1e-4 * abs(expected), (torque, expected)
    assert re.search(r"^d/d crank\.angle$", printed, re.M)
    assert _derivative_symbols(build / "shaper_example")


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    """The core configured, built and installed alone into <tmp>/prefix (as
    scripts/tests/test_install.py installs it)."""
    required_tool("cmake")
    tmp = tmp_path_factory.mktemp("install")
    options = ["-DDYADFMU_BUILD_FMUS=OFF", "-DDYADFMU_BUILD_TESTS=OFF", "-DDYADFMU_BUILD_BENCH=OFF"]
    _run("cmake", "-S", ROOT, "-B", tmp / "build", "-DCMAKE_BUILD_TYPE=Release", *options)
    _run("cmake", "--build", tmp / "build", "-j", str(os.cpu_count() or 2))
    _run("cmake", "--install", tmp / "build", "--prefix", tmp / "prefix")
    return tmp / "prefix"


@pytest.mark.parametrize("real", ["double", "float"])
@pytest.mark.parametrize("name", ["shaper", "zqid"])
def test_the_scene_builds_on_the_installed_core(name, real, prefix, bundle, fmu_results, tmp_path):
    """scene/ of the bundle with the installed headers and static library instead of core/:
    the same outputs as the FMU, and nothing of the derivative linked."""
    required_tool("nm")
    table = _table(name)
    folder = bundle(name, False)
    lib = next(p for p in prefix.iterdir() if p.name.startswith("lib"))
    flags, library = ([FLOAT], "libdyadfmu_float.a") if real == "float" else ([], "libdyadfmu.a")
    (tmp_path / "main.c").write_text(_main_c(table, _inputs_at(table), derivative=False))
    program = tmp_path / "main"
    _run(
        "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{prefix / 'include'}", "-o", program,
        tmp_path / "main.c", *sorted(folder.glob("scene/*.c")), lib / library, "-lm",
    )  # fmt: skip
    found = _printed(_run(program))
    assert found["status 0"] == "0"
    _agree(found, fmu_results(name), ("out",), table, 1e-9 if real == "double" else 1e-3)
    assert _derivative_symbols(program) == []


def test_the_bundles_cmakelists_builds_on_the_installed_core(prefix, bundle, tmp_path):
    required_tool("cmake")
    folder = bundle("shaper", True)
    build = tmp_path / "build"
    _run(
        "cmake", "-S", folder, "-B", build, "-DDYADFMU_INSTALLED_CORE=ON",
        f"-DCMAKE_PREFIX_PATH={prefix}",
    )  # fmt: skip
    _run("cmake", "--build", build)
    assert f"dyadfmu_DIR:PATH={prefix}" in (build / "CMakeCache.txt").read_text()
    assert not list(build.rglob("*shaper_core*")), "the bundled core was built too"
    assert "crank.torque" in _run(build / "shaper_example")


# ---------------------------------------------------------------------------
# A plant (a forward scene) in firmware
# ---------------------------------------------------------------------------
#: the plant bundled, its run: a supply, steps, and the outputs compared
PLANT = SCENES_DIR / "slider_crank_motor.toml"
PLANT_RUN = {"crank.motor.voltage": 290.0}
PLANT_STEPS, PLANT_STEP = 200, 1e-3
PLANT_SEEN = ("crank.angle", "crank.omega", "crank.motor.current", "engine.R_np.x")


def _plant_main(table, values: dict[str, float], tolerance: float | None) -> str:
    """A program that starts the plant at its start values (the tolerances set where
    given), sets the inputs of `values`, advances PLANT_STEPS steps and prints the
    outputs of PLANT_SEEN after each."""
    ident = table.identifier
    members = {v.name: v.lives.path for v in table.variables}
    lines = ["#include <stdio.h>", "#include <string.h>", f'#include "{ident}_plant.h"', ""]
    lines += ["int main(void)", "{", f"    {ident}_input in;", f"    {ident}_output out;"]
    lines += ["    fmu_evaluation evaluation;", "    int k;", "    memset(&in, 0, sizeof in);"]
    given = dict(values)
    if tolerance is not None:
        given.update({"solver.rtol": tolerance, "solver.atol": tolerance})
    for v in _block_inputs(table):
        lines.append(f"    in.{v.lives.path} = {given.get(v.name, float(v.start))!r};")
    lines += [
        f"    {ident}_plant_start(&in, &evaluation);",
        f"    for (k = 0; k < {PLANT_STEPS}; ++k) {{",
    ]
    lines += [
        f"        (void){ident}_plant_advance(&in, {PLANT_STEP!r}, &evaluation);",
        "        if (evaluation.status == FMU_OK) {",
        f"            {ident}_plant_evaluate(&in, &out, &evaluation);",
        "        }",
        "        if (evaluation.status != FMU_OK) {",
        '            printf("failed %s\\n", evaluation.reason);',
        "            return 1;",
        "        }",
    ]
    for name in PLANT_SEEN:
        lines.append(f'        printf("%d {name} %.17g\\n", k, out.{members[name]});')
    return "\n".join(lines + ["    }", "    return 0;", "}", ""])


def _plant_fmu_run(tolerance: float | None) -> np.ndarray:
    """The plant's FMU over the same run: PLANT_SEEN after each step, a row per step."""
    parameters = {} if tolerance is None else {"solver.rtol": tolerance, "solver.atol": tolerance}
    slave = Slave(paths.built_fmu("slider_crank_motor", 2, None, how="scripts/run-tests"), "p")
    rows = []
    try:
        slave.initialize(parameters)
        slave.set(tuple(PLANT_RUN), list(PLANT_RUN.values()))
        for k in range(PLANT_STEPS):
            slave.do_step(k * PLANT_STEP, PLANT_STEP)
            rows.append(slave.get(PLANT_SEEN))
    finally:
        slave.close()
    return np.array(rows)


def _plant_bundle_run(folder: Path, table, flags: list, tolerance, work: Path) -> np.ndarray:
    work.mkdir(parents=True, exist_ok=True)
    (work / "main.c").write_text(_plant_main(table, PLANT_RUN, tolerance))
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    _run(
        "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
        "-o", work / "main", work / "main.c", *sources, "-lm",
    )  # fmt: skip
    printed = [line.split() for line in _run(work / "main").splitlines()]
    rows = np.array([float(value) for _, _, value in printed]).reshape(PLANT_STEPS, -1)
    return rows


@pytest.mark.parametrize("real", ["double", "float"])
def test_a_plants_bundle_integrates_as_its_fmu_does(real, tmp_path):
    """The slider-crank's plant (a forward scene) in firmware: its bundle, compiled alone
    (-Wall -Wextra -Wpedantic -Werror), started, stepped 200 ms of a run-up from rest at 1
    ms steps. In double at the default tolerances, the crank's angle, speed, the current
    and a joint reaction after every step are its FMU's, bit for bit (the same C, the same
    compiler); in float, with both tolerances 1e-6, within FLOAT_PLANT_BOUND of the
    double FMU's travel and peaks at the same tolerances."""
    from dyadgen import bundle as bundles

    required_tool("cc")
    table = pipeline.build_table(pipeline.load_scene(PLANT, check_c_names=False))
    out = tmp_path / "written"
    done = _scene_tool(PLANT, "--bundle", out)
    assert done.returncode == 0, done.stderr
    folder = out / table.identifier
    assert (folder / "scene" / f"{table.identifier}_plant.h").is_file()
    tolerance = None if real == "double" else 1e-6
    flags = [] if real == "double" else [FLOAT]
    found = _plant_bundle_run(folder, table, flags, tolerance, tmp_path / "build")
    expected = _plant_fmu_run(tolerance)
    if real == "double":
        np.testing.assert_array_equal(found, expected)
        return
    scale = np.max(np.abs(expected), axis=0)
    start = next(float(v.start) for v in table.variables if v.name == "crank.angle_start")
    scale[0] = abs(expected[-1, 0] - start)  # the angle travelled
    off = np.max(np.abs(found - expected), axis=0) / scale
    print(f"float plant against double: {dict(zip(PLANT_SEEN, off, strict=True))}")
    assert np.all(off < bundles.FLOAT_PLANT_BOUND), off


#: (member set, value, what the start or the first step says), for the plant's bundle
PLANT_HOSTILE = (
    ("plant_crank_motor_resistance", "-1.0", "crank.motor.resistance = -1"),
    ("plant_rtol", "NAN", "solver.rtol = nan"),
    ("plant_crank_motor_ratio", "0.0", "crank.motor.ratio = 0"),
    ("plant_crank_position_start", "1e20", "crank.angle_start = 1e+20"),
    ("plant_step_start", "1e-18", "ok"),
)


def _hostile_main(table) -> str:
    """A program that, for each case of PLANT_HOSTILE, fills the block at its start
    values with that one member changed, starts the plant, takes a 1 ms step and prints
    the reason, or ok and the time the step returned."""
    ident = table.identifier
    lines = ["#include <math.h>", "#include <stdio.h>", "#include <string.h>"]
    lines += [f'#include "{ident}_plant.h"', "", "int main(void)", "{"]
    lines += [f"    {ident}_input in;", "    fmu_evaluation evaluation;", "    double reached;"]
    for member, value, _ in PLANT_HOSTILE:
        lines.append("    memset(&in, 0, sizeof in);")
        lines += [f"    in.{v.lives.path} = {float(v.start)!r};" for v in _block_inputs(table)]
        lines.append(f"    in.{member} = {value};")
        lines.append(f"    {ident}_plant_start(&in, &evaluation);")
        lines.append("    reached = evaluation.status == FMU_OK ?")
        lines.append(f"        {ident}_plant_advance(&in, 1e-3, &evaluation) : 0;")
        lines.append('    if (evaluation.status == FMU_OK) printf("ok %.17g\\n", reached);')
        lines.append('    else printf("%d %s\\n", (int)evaluation.status, evaluation.reason);')
    return "\n".join(lines + ["    return 0;", "}", ""])


@pytest.mark.parametrize("real", ["double", "float"])
def test_a_plants_bundle_refuses_what_its_fmu_refuses(real, tmp_path):
    """The bundle has no setters: its start and its steps refuse, by name, what the FMU's
    setters refuse (a resistance below 0, a tolerance not finite, a gear ratio of 0, a
    start angle of 1e20 rad, which no step moved); those ran on with status ok before.
    A first step below the step's resolution (solver.step_start = 1e-18 s) lets the
    integrator choose instead of failing every step; a step that ends returns h itself,
    in float too."""
    required_tool("cc")
    table = pipeline.build_table(pipeline.load_scene(PLANT, check_c_names=False))
    done = _scene_tool(PLANT, "--bundle", tmp_path / "written")
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "written" / table.identifier
    (tmp_path / "main.c").write_text(_hostile_main(table))
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    flags = [] if real == "double" else [FLOAT]
    _run(
        "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
        "-o", tmp_path / "main", tmp_path / "main.c", *sources, "-lm",
    )  # fmt: skip
    said = _run(tmp_path / "main").splitlines()
    assert len(said) == len(PLANT_HOSTILE), said
    for line, (_, _, expected) in zip(said, PLANT_HOSTILE, strict=True):
        if expected == "ok":
            assert line == "ok 0.001", line
        else:
            assert line.startswith(f"3 {expected}:"), (line, expected)  # FMU_ERROR


#: the four-bar with a crank of the rocker's length: no longer Grashof, so that the crank
#: meets an assembly limit, where the rocker and the coupler stand in line
TOGGLE_CRANK = ("length = 0.05 ", "length = 0.12 ")
TOGGLE_MAIN = r"""#include <math.h>
#include <stdio.h>
#include "toggle_bar_scene.h"

static int at(double c, double s, toggle_bar_output* out)
{
    toggle_bar_input in;
    fmu_evaluation evaluation;
    in.crank_dir = dyad_vec2_make((dyad_real)c, (dyad_real)s);
    in.crank_omega = 10;
    in.crank_epsilon = 0;
    in.rocker_moment = 5;
    in.linkage_branch = -1;
    in.gravity_x = 0;
    in.gravity_y = -9.81;
    toggle_bar_evaluate(&in, out, &evaluation);
    return out->status;
}

/* With an argument: the crank's direction (rounded to float) 1e-2 .. 1e-14 rad before the
 * assembly limit, found by bisection. Without: the status and the forces at each line of
 * directions read. */
int main(int argc, char** argv)
{
    toggle_bar_output out;
    float c, s;
    (void)argv;
    if (argc > 1) {
        double lo = 2.3, hi = 2.36;
        for (int i = 0; i < 100; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (at(cos(mid), sin(mid), &out) != 4) lo = mid; else hi = mid;
        }
        for (int k = 2; k <= 14; ++k) {
            const double t = lo - pow(10, -k);
            printf("%.9g %.9g\n", (double)(float)cos(t), (double)(float)sin(t));
        }
        return 0;
    }
    while (scanf("%f %f", &c, &s) == 2) {
        const int status = at(c, s, &out);
        printf("%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", status,
               (double)out.crank_torque, (double)out.linkage_r_mk_x, (double)out.linkage_r_mk_y,
               (double)out.linkage_r_np_x, (double)out.linkage_r_np_y,
               (double)out.linkage_r_mn_x, (double)out.linkage_r_mn_y,
               (double)out.crank_r_o_x, (double)out.crank_r_o_y,
               (double)out.linkage_conditioning);
    }
    return 0;
}
"""


def test_a_float_build_flags_the_toggle_float_cannot_resolve(tmp_path):
    """A scene that does not set singular_threshold takes the scalar's own default:
    sqrt(eps) of float (3.45e-4) in a float build, not double's 1.49e-8 baked in. Near a
    four-bar's assembly limit every force the float build gives with status 0 is within
    sqrt(FLT_EPSILON) of the largest force there, against the double build at the same
    (float) inputs; before, float said status 0 with forces 0.09 % to 36 % off while double
    still resolved them. Double flags nothing more than it did."""
    required_tool("cc")
    four_bar = (SCENES_DIR / "four_bar.toml").read_text()
    assert TOGGLE_CRANK[0] in four_bar
    scene = tmp_path / "toggle_bar.toml"
    scene.write_text(four_bar.replace(*TOGGLE_CRANK).replace('"four_bar"', '"toggle_bar"'))
    done = _scene_tool(scene, "--bundle", tmp_path / "written")
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "written" / "toggle_bar"
    evaluation = (folder / "scene" / "toggle_bar_scene.c").read_text()
    assert "DYAD_DEFAULT_SINGULAR_THRESHOLD" in evaluation and "1.49" not in evaluation
    (tmp_path / "main.c").write_text(TOGGLE_MAIN)
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    programs = {}
    for real, flags in (("double", []), ("float", [FLOAT])):
        programs[real] = tmp_path / f"main_{real}"
        _run(
            "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
            "-o", programs[real], tmp_path / "main.c", *sources, "-lm",
        )  # fmt: skip
    points = _run(programs["double"], "limit")

    def forces(real: str) -> list[tuple[int, np.ndarray]]:
        done = subprocess.run(
            [programs[real]], input=points, capture_output=True, text=True, check=True
        )
        rows = [line.split() for line in done.stdout.splitlines()]
        return [(int(r[0]), np.array([float(x) for x in r[1:]])) for r in rows]

    double, single = forces("double"), forces("float")
    assert len(double) == len(single) == 13
    resolved = [k for k, (status, _) in enumerate(double) if status == 0]
    assert len(resolved) >= 5, double  # down to a conditioning of about 1e-3
    held = 0
    for k, (status, found) in enumerate(single):
        if status != 0:
            assert status == 1, (k, status)  # singular, not a failure of some other kind
            continue
        assert k in resolved, k
        truth = double[k][1]
        largest = np.abs(truth[:-1]).max()
        worst = np.abs(found[:-1] - truth[:-1]).max() / largest
        assert worst <= 2.0**-11.5, (k, worst, found, truth)  # sqrt(FLT_EPSILON)
        held += 1
    assert held >= 1, single


def _text_sizes(readme: str) -> dict[str, tuple[int, int]]:
    rows = re.findall(r"^\| (double|float) \| (\d+) \| (\d+) \|$", readme, re.M)
    return {real: (int(objects), int(linked)) for real, objects, linked in rows}


def test_build_scene_writes_the_bundle_and_measures_its_size(tmp_path):
    """scripts/build-scene --bundle: the folder DIR/<id>/, the README with the example's
    size in double and float, the derivative's code adding to it; written again, an
    earlier bundle is replaced (no tangent file left from the one before)."""
    required_tool("cc")
    required_tool("size")
    out = tmp_path / "bundles"
    sizes = {}
    for extra in (["--with-derivatives"], []):
        done = subprocess.run(
            [str(BUILD_SCENE), "--bundle", str(out), *extra, str(SCENES["shaper"])],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr[-3000:]
        assert done.stdout.splitlines()[-1] == str(out / "shaper")
        readme = (out / "shaper" / "README.md").read_text()
        sizes[bool(extra)] = _text_sizes(readme)
        assert set(sizes[bool(extra)]) == {"double", "float"}, readme[-1500:]
        assert ("shaper_derivative`: the" in readme) == bool(extra)
    assert not list(out.rglob("*tangent*"))
    for real in ("double", "float"):
        evaluate, derivatives = sizes[False][real], sizes[True][real]
        assert 0 < evaluate[0] < evaluate[1] and derivatives[1] > evaluate[1] + 20000, sizes


def test_bundle_options_are_checked(tmp_path):
    generic = SCENES_DIR / "dyad_rrt.toml"
    done = _scene_tool(generic, "--bundle", tmp_path)
    assert done.returncode == 1
    assert "realisation generic" in done.stderr and "dyad_solve_rrt" in done.stderr
    done = _scene_tool(SCENES["shaper"], "--check", "--with-derivatives")
    assert done.returncode == 2 and "--with-derivatives is an option of --bundle" in done.stderr
    (tmp_path / "shaper").mkdir()
    (tmp_path / "shaper" / "notes.txt").write_text("mine\n")
    done = _scene_tool(SCENES["shaper"], "--bundle", tmp_path)
    assert done.returncode == 2 and "holds no bundle" in done.stderr
    assert (tmp_path / "shaper" / "notes.txt").read_text() == "mine\n"
    (tmp_path / "shaper" / "notes.txt").unlink()
    (tmp_path / "shaper" / "scene").mkdir()
    (tmp_path / "shaper" / "core" / "src").mkdir(parents=True)
    (tmp_path / "shaper" / "core" / "src" / "link").symlink_to(tmp_path)
    done = _scene_tool(SCENES["shaper"], "--bundle", tmp_path)
    assert done.returncode == 2 and "holds no bundle" in done.stderr, "a link is something"
    (tmp_path / "shaper" / "core" / "src" / "link").unlink()
    # empty folders, as Ninja makes them for the outputs it expects, are nothing
    done = _scene_tool(SCENES["shaper"], "--bundle", tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "shaper" / "scene" / "shaper_scene.c").is_file()
    assert "--bundle DIR" in _scene_tool("--help").stdout
    help_text = _run(BUILD_SCENE, "--help")
    assert "--bundle DIR" in help_text and "--with-derivatives" in help_text
    done = subprocess.run(
        [str(BUILD_SCENE), "--with-derivatives", str(SCENES["shaper"])],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert done.returncode == 2 and "--with-derivatives is an option of --bundle" in done.stderr


def test_build_scene_refuses_an_identifier_twice(tmp_path):
    """A scene with a built-in scene's identifier, or two given scenes with one, is refused
    in one line before CMake would define their targets twice."""
    press = SCENES_DIR / "press.toml"
    mine = tmp_path / "my_press.toml"
    mine.write_text(press.read_text())
    done = subprocess.run(
        [str(BUILD_SCENE), str(mine)], capture_output=True, text=True, check=False
    )
    assert done.returncode == 1, done.stderr[-2000:]
    assert "identifier 'press' names a built-in FMU" in done.stderr
    other = tmp_path / "other.toml"
    text = press.read_text().replace('identifier = "press"', 'identifier = "my_press"')
    assert 'identifier = "my_press"' in text
    mine.write_text(text)
    other.write_text(text)
    done = subprocess.run(
        [str(BUILD_SCENE), str(mine), str(other)], capture_output=True, text=True, check=False
    )
    assert done.returncode == 2, done.stderr[-2000:]
    assert f"{other}: identifier 'my_press' is also that of {mine}" in done.stderr


def test_build_scene_builds_a_built_in_scene():
    """A built-in scene given to build-scene is built like any other (CMake has its targets
    already: given again, they were defined twice)."""
    required_tool("cmake")
    done = subprocess.run(
        [str(BUILD_SCENE), str(SCENES_DIR / "press.toml")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    for version in (2, 3):
        assert f"press_fmi{version}.fmu: 4 inputs, 1 parameter, 5 outputs; valid" in done.stdout


def test_dyadfmu_build_scene_builds_a_users_scene_where_asked(tmp_path):
    """`dyadfmu build-scene FILE --out DIR`, run outside the checkout: the scene's FMUs in
    DIR/fmus/, a line per FMU packaged, the build's output in DIR/build.log, each FMU
    validated; the scene's [experiment] is the FMU's default run."""
    required_tool("cmake")
    text = (SCENES_DIR / "slider_crank.toml").read_text()
    text = text.replace('identifier = "slider_crank"', 'identifier = "users_crank"')
    scene = tmp_path / "users_crank.toml"
    scene.write_text(text + "\n[experiment]\nstop = 0.05\nstep = 0.01\n")
    out = tmp_path / "my build"
    done = subprocess.run(
        [sys.executable, "-m", "dyadfmu", "build-scene", scene.name, "--out", out,
         "--windows", "off"],
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    for version in (2, 3):
        fmu = out / "fmus" / f"users_crank_fmi{version}.fmu"
        assert f"{fmu}: 5 inputs, 4 parameters, 28 outputs; valid" in done.stdout
        assert f"packaged users_crank_fmi{version}.fmu" in done.stderr
    assert "Packaging users_crank_fmi2.fmu" in (out / "build.log").read_text()
    from dyadfmu import run_table

    rows = run_table(out / "fmus" / "users_crank_fmi2.fmu")
    assert list(rows["time"]) == pytest.approx([0.0, 0.01, 0.02, 0.03, 0.04, 0.05])


def test_dyadfmu_build_scene_says_what_it_lacks_in_one_line(monkeypatch, tmp_path, capsys):
    from dyadfmu import build_scene

    scene = str(SCENES_DIR / "press.toml")
    found = shutil.which
    monkeypatch.setattr(build_scene.shutil, "which", lambda name: None)
    assert build_scene.main([scene, "--out", str(tmp_path)]) == 2
    said = capsys.readouterr().err
    assert said.startswith("dyadfmu build-scene: building a scene's FMUs needs CMake (cmake)")
    assert said.count("\n") == 1 and "study" not in said
    monkeypatch.setattr(
        build_scene.shutil, "which", lambda name: None if "mingw" in name else found(name)
    )
    assert build_scene.main([scene, "--out", str(tmp_path), "--windows", "on"]) == 2
    said = capsys.readouterr().err
    assert "--windows on needs the MinGW-w64 cross compiler" in said and said.count("\n") == 1
    assert not (tmp_path / "fmus").exists()


OVERFLOW_MAIN = r"""#include <stdio.h>
#include "over_bar_scene.h"

/* The crank at 1 rad, the rocker's moment from the command line: the status and reason. */
int main(int argc, char** argv)
{
    over_bar_input in;
    over_bar_output out;
    fmu_evaluation evaluation;
    float moment = 0;
    if (argc < 2 || sscanf(argv[1], "%f", &moment) != 1) return 2;
    in.crank_dir = dyad_vec2_make((dyad_real)0.5403023058681398, (dyad_real)0.8414709848078965);
    in.crank_omega = 10;
    in.crank_epsilon = 0;
    in.rocker_moment = moment;
    in.linkage_branch = -1;
    in.gravity_x = 0;
    in.gravity_y = -9.81;
    over_bar_evaluate(&in, &out, &evaluation);
    printf("%d %s\n", out.status, evaluation.reason);
    return 0;
}
"""


def test_a_float_build_says_its_reactions_overflow_float(tmp_path):
    """A rocker moment of 3e38 N m is a float, and the reactions it drives are not: the
    float build gives status 3 and says they overflow float, not double. Double resolves
    them."""
    required_tool("cc")
    scene = tmp_path / "over_bar.toml"
    scene.write_text((SCENES_DIR / "four_bar.toml").read_text().replace('"four_bar"', '"over_bar"'))
    done = _scene_tool(scene, "--bundle", tmp_path / "written")
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "written" / "over_bar"
    (tmp_path / "main.c").write_text(OVERFLOW_MAIN)
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    said = {}
    for real, flags in (("double", []), ("float", [FLOAT])):
        program = tmp_path / f"main_{real}"
        _run(
            "cc", *WARNINGS, *flags, f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
            "-o", program, tmp_path / "main.c", *sources, "-lm",
        )  # fmt: skip
        said[real] = _run(program, "3e38").strip()
    assert said["double"] == "0", said
    assert said["float"].startswith("3 ") and "overflow float" in said["float"], said
    assert "double" not in said["float"], said

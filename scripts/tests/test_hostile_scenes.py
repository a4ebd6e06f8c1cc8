"""Scenes as untrusted input: the scene generator (modelDescription/scene.py) on hostile
and careless scenes.

* Each malformed hostile scene (modelDescription/scenes/malformed/hostile_*.toml) is refused
  with exactly the message its first line names: descriptions that would end a C comment or carry
  control or bidi characters, numbers beyond a double, names with a trailing newline,
  names too long, names that clash with C, the core or the generated code.
* Every name the generated code, the core or C uses is refused as a dyad's name; the
  refused set covers every identifier of the generated code of every example scene.
* Accepted scenes with awkward descriptions and file names put no scene text into the
  generated C outside comments and string literals, compile with -std=c99 -Werror, and
  give model descriptions that the FMI 2 and FMI 3 schemas accept.
* A description that tries to plant a constructor, with the description check bypassed,
  still compiles to an FMU with the same symbols and constructors as a plain one.
* A tunable pair point (tunable = ["DYAD.D_m"], or ["all"]) works as documented.
* Mutated scenes give file:line messages, never a traceback.
* Checking a long chain grows linearly: counted in function calls, not timed.
"""

from __future__ import annotations

import collections
import json
import math
import random
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
MD_DIR = ROOT / "modelDescription"

from dyadfmu.cosim import scenes  # noqa: E402
from dyadfmu.study import long_chain  # noqa: E402
from dyadgen import cnames, pipeline, textsafe  # noqa: E402
from dyadgen.emit import fmi2, fmi3  # noqa: E402
from dyadgen.emit import scene_c as scene_emit  # noqa: E402
from dyadgen.kinds import SceneTable  # noqa: E402
from dyadgen.scenefile import mechanism  # noqa: E402
from dyadgen.scenefile import names as scene_names  # noqa: E402
from dyadgen.scenefile.c_names import c_names  # noqa: E402
from dyadgen.scenefile.problems import SceneError  # noqa: E402

SCENE_TOOL = MD_DIR / "scene.py"
SCENES_DIR = ROOT / "modelDescription" / "scenes"
HOSTILE = sorted((SCENES_DIR / "malformed").glob("hostile_*.toml"))
SIXBAR = SCENES_DIR / "sixbar.toml"
GCC = shutil.which("gcc")
needs_gcc = pytest.mark.skipif(GCC is None, reason="gcc not available")
#: As the FMUs are compiled (CMakeLists.txt), in strict ISO mode so that trigraphs count.
C_FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror"]


def run_tool(*args):
    return subprocess.run(
        [sys.executable, str(SCENE_TOOL), *map(str, args)], capture_output=True, text=True
    )


#: The identifier of a copy of the six-bar: a built-in scene's own identifier is refused
#: in any other file.
COPY_ID = "my_sixbar"


def sixbar_with(tmp_path, name="sixbar.toml", **scene_keys) -> Path:
    """The six-bar scene with keys of its [scene] table replaced (its identifier
    COPY_ID unless given), written to tmp_path."""
    scene_keys.setdefault("identifier", f'"{COPY_ID}"')
    text = SIXBAR.read_text(encoding="utf-8")
    for key, value in scene_keys.items():
        line = f"{key} = {value}"
        text, count = re.subn(rf"(?m)^{key} = .*$", lambda _, line=line: line, text)
        assert count == 1, key
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def toml_string(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(text, ensure_ascii=False)


def include_flags(generated: Path) -> list[str]:
    from fmpy import __file__ as fmpy_init

    return [
        f"-I{ROOT / 'src' / 'include'}",
        f"-I{ROOT / 'src'}",
        f"-I{ROOT / 'fmu'}",
        f"-I{generated}",
        f"-I{Path(fmpy_init).parent / 'c-code'}",
    ]


# ---------------------------------------------------------------------------
# the hostile malformed scenes, each with its exact message
# ---------------------------------------------------------------------------
def test_the_hostile_examples_cover_the_findings():
    kinds = {p.stem for p in HOSTILE}
    assert {
        "hostile_description_comment_end",
        "hostile_description_control",
        "hostile_description_bidi",
        "hostile_number_beyond_double",
        "hostile_name_trailing_newline",
        "hostile_identifier_too_long",
        "hostile_dyad_in",
        "hostile_dyad_keyword",
        "hostile_dyad_crank_torque",
        "hostile_dyad_core_name",
    } <= kinds


@pytest.mark.parametrize("path", HOSTILE, ids=lambda p: p.stem)
def test_hostile_scene_is_refused_with_its_exact_message(path, tmp_path):
    expect = re.fullmatch(r"# expect: line (\d+): (.*)", path.read_text().splitlines()[0])
    assert expect, f"{path.name}: first line must be '# expect: line N: message'"
    done = run_tool(path, "--out", tmp_path / "out")
    assert done.returncode == 1, done.stdout
    assert "Traceback" not in done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("error:")]
    assert f"error: {path.name}:{expect.group(1)}: {expect.group(2)}" in errors, done.stderr
    assert not (tmp_path / "out").exists()


def test_a_file_that_is_not_utf8_is_refused_with_its_line(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(b'[scene]\nidentifier = "x"\ndescription = "Pr\xe9sse"\n')
    with pytest.raises(SceneError) as error:
        pipeline.load_scene(path)
    assert error.value.args[0] == ["latin1.toml:3: not UTF-8 text (byte 43)"]


# ---------------------------------------------------------------------------
# names: C keywords, the names of C's headers, the core and the generated code
# ---------------------------------------------------------------------------
def _refusal(tmp_path, text: str) -> list[str]:
    path = tmp_path / "named.toml"
    path.write_text(text, encoding="utf-8")
    try:
        pipeline.load_scene(path)
    except SceneError as error:
        return error.args[0]
    return []


def test_every_name_the_generated_code_uses_is_refused_as_a_dyad_name(tmp_path):
    """A dyad's name is a local variable of the generated code; every identifier that C,
    the headers the code includes, the core and the generated code use is refused, with
    the dyad's line."""
    names = c_names()
    base = SIXBAR.read_text()
    line = base.splitlines().index('name = "second"') + 1
    candidates = sorted(n for n in names.reserved if scene_names.NAME.fullmatch(n))
    # the examples of the issue, and the macros a C program must leave alone
    assert {
        "in",
        "out",
        "load",
        "check",
        "model",
        "evaluation",
        "cos",
        "snprintf",
        "memset",
        "errno",
        "int",
        "double",
    } <= set(candidates)
    assert {"NULL", "EOF", "INFINITY", "NAN", "errno"} <= names.reserved
    assert len(candidates) > 300  # C, math.h, stdio.h, string.h, ...
    for name in candidates + ["crank_torque", "dyad_cross", "fmu_instance", "dyad"]:
        problems = _refusal(tmp_path, base.replace('name = "second"', f'name = "{name}"'))
        assert any(
            p.startswith(f"named.toml:{line}: dyad ") and f"'{name}'" in p for p in problems
        ), (name, problems)


@pytest.mark.parametrize("name", ("NULL", "EOF", "INFINITY", "NAN", "errno", "main", "int", "dyad"))
def test_an_identifier_named_after_c_or_the_core_is_refused(name, tmp_path):
    problems = _refusal(
        tmp_path, SIXBAR.read_text().replace('identifier = "sixbar"', f'identifier = "{name}"')
    )
    assert any(
        p.startswith("named.toml:") and "identifier" in p and f"'{name}" in p for p in problems
    ), problems


@pytest.mark.parametrize(
    "keyword", sorted(k for k in cnames.C_KEYWORDS if scene_names.NAME.fullmatch(k))
)
def test_a_c_keyword_is_refused_as_a_link_name(keyword, tmp_path):
    text = SIXBAR.read_text().replace('"connector"', f'"{keyword}"')
    line = text.splitlines().index(f'name = "{keyword}"') + 1
    assert f"named.toml:{line}: link #3: name '{keyword}' is a C keyword" in _refusal(
        tmp_path, text
    )


def _scene_objects(sc) -> list[tuple[str, str]]:
    objects = [("identifier", sc.identifier)]
    for driver in sc.drivers:
        objects.append(("crank", driver.name))
        if driver.actuator:  # a cylinder's name is the driver's too
            objects.append(("crank", driver.actuator))
    # an unnamed dyad is "dyad" in the generated C (its result, and d_dyad its rate)
    objects += [("dyad", d.name or "dyad") for d in sc.dyads]
    objects += [("link", g) for g in sc.links]
    return objects


SCENE_FILES = sorted(SCENES_DIR.glob("*.toml")) + sorted((ROOT / "tests" / "scenes").glob("*.toml"))


def _generates_code(path: Path) -> bool:
    """A tailored scene (its own C); a generic dyad's scene has none."""
    return isinstance(pipeline.build_table(pipeline.load_scene(path)), SceneTable)


TAILORED_SCENE_FILES = [p for p in SCENE_FILES if _generates_code(p)]


@pytest.mark.parametrize("path", TAILORED_SCENE_FILES, ids=lambda p: p.stem)
def test_the_refused_names_cover_the_generated_code(path):
    """Every identifier of a scene's generated C is a name the generator refuses (C's, the
    headers', the core's, the generated code's own), or one it derives from a name of
    the scene, or a member: the probe the refused names are learnt from has every
    feature of the examples."""
    names = c_names()
    sc = pipeline.load_scene(path)
    table = pipeline.build_table(sc)
    derived = {c for kind, name in _scene_objects(sc) for _, c in names.derived(kind, name)}
    generated = scene_emit.scene_c(table.scene) + scene_emit.scene_tangent_c(table.scene)
    code = [t.text for t in cnames.identifiers(generated) if not t.member]
    declared = sorted(cnames.declared_names(scene_emit.scene_header(table)))
    for name in code + declared:
        assert name in names.reserved or name in derived, (path.name, name)


def test_generated_names_stay_within_c99_significance():
    """MAX_NAME keeps every derived C name within the 63 characters C99 guarantees."""
    names = c_names()
    longest = max(
        len(c)
        for kind in names.patterns
        for _, c in names.derived(kind, "x" * scene_names.MAX_NAME)
    )
    assert longest <= 63


# ---------------------------------------------------------------------------
# scene text in the generated files
# ---------------------------------------------------------------------------
AWKWARD_DESCRIPTIONS = (
    "leakmark opens a comment /* here",
    'leakmark has a " quote',
    "leakmark ends in a backslash \\",
    "leakmark ends in a trigraph ??/",
    "leakmark %s %n %d",
    "Presse à vilebrequin — ünïcode ✓ leakmark",
    '<b>leakmark</b> & "x" -- y -->',
    "leakmark // a line comment, / * apart, ??= and ??( trigraphs",
)
AWKWARD_FILE_NAMES = (
    "my--press.toml",
    "leak-->mark.toml",
    "leak*mark.toml",
    "leak\\mark.toml",
    "leak??=mark.toml",
    "-leakmark-.toml",
    "leak--.toml",
    "leak\u202emark.toml",
    "leak\x07mark.toml",
)


def _generate(tmp_path, description="A six-bar", file_name="sixbar.toml") -> Path:
    path = sixbar_with(tmp_path, file_name, description=toml_string(description))
    out = tmp_path / "generated"
    done = run_tool(path, "--out", out)
    assert done.returncode == 0, done.stderr
    return out


def _no_scene_text_in_code(out: Path, marker: str):
    for source in sorted(out.glob("*.[ch]")):
        for t in cnames.tokens(source.read_text(encoding="utf-8")):
            if t.kind not in ("comment", "string", "header"):
                assert marker not in t.text.lower(), (source.name, t)


def _compiles(out: Path, tmp_path):
    for source in sorted(out.glob("*.c")):
        done = subprocess.run(
            [GCC, *C_FLAGS, "-fsyntax-only", *include_flags(out), str(source)],
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, (source.name, done.stderr)


def _valid_model_descriptions(out: Path, tmp_path, description: str):
    from fmpy import read_model_description

    layout = tmp_path / "fmu3"
    (layout / "sources").mkdir(parents=True)
    shutil.copy(out / "fmi3" / "modelDescription.xml", layout / "modelDescription.xml")
    shutil.copy(out / "fmi3" / "buildDescription.xml", layout / "sources" / "buildDescription.xml")
    for where in (out / "fmi2" / "modelDescription.xml", layout):
        md = read_model_description(
            str(where), validate=True, validate_variable_names=True, validate_model_structure=True
        )
        assert md.description == description
        assert len(md.modelVariables) > 30


@needs_gcc
@pytest.mark.parametrize("description", AWKWARD_DESCRIPTIONS)
def test_an_awkward_description_stays_in_comments_and_strings(description, tmp_path):
    assert textsafe.description_problem(description) is None
    out = _generate(tmp_path, description)
    _no_scene_text_in_code(out, "leakmark")
    assert textsafe.c_comment(description) in (out / f"{COPY_ID}_scene.c").read_text()
    _compiles(out, tmp_path)
    _valid_model_descriptions(out, tmp_path, description)
    page = (out / "documentation" / "index.html").read_text()
    assert f"<p>{textsafe.html(description)}</p>" in page


@needs_gcc
@pytest.mark.parametrize("file_name", AWKWARD_FILE_NAMES)
def test_an_awkward_file_name_stays_in_comments(file_name, tmp_path):
    out = _generate(tmp_path, file_name=file_name)
    _no_scene_text_in_code(out, "leak")
    _compiles(out, tmp_path)
    _valid_model_descriptions(out, tmp_path, "A six-bar")
    for xml in out.glob("fmi*/*.xml"):
        comment = re.search(r"<!--(.*?)-->", xml.read_text(), re.S).group(1)
        assert "--" not in comment and textsafe.xml_comment(file_name) in comment


def test_escaping_functions_close_every_way_out():
    """Random text through each escaping function: nothing that ends or nests a C comment
    or joins its line, no '--' in an XML comment, a C string that reads back."""
    rng = random.Random(12)
    alphabet = "*/\\?=-<>&\"' \n\ta\u202e\u0000\u00e9\U0001f600"
    for _ in range(3000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 12)))
        comment = textsafe.c_comment(text)
        assert "*/" not in comment and "/*" not in comment and "\\" not in comment
        assert "??/" not in comment and "\n" not in comment and "\u202e" not in comment
        xml = textsafe.xml_comment(text)
        assert "--" not in xml and not xml.endswith("-") and not xml.startswith("-")
        literal = textsafe.c_string(text)
        assert literal.isascii() and "??" not in literal
        assert _read_c_string(literal) == text.encode("utf-8")
        assert "<" not in textsafe.html(text) and "\u202e" not in textsafe.plain(text)


def _read_c_string(literal: str) -> bytes:
    tokens = cnames.tokens(literal)
    assert [t.kind for t in tokens] == ["string"]
    body, out, k = literal[1:-1], bytearray(), 0
    while k < len(body):
        if body[k] == "\\":
            if body[k + 1] in "01234567":
                out.append(int(body[k + 1 : k + 4], 8))
                k += 4
            else:
                out += body[k + 1].encode()
                k += 2
        else:
            out += body[k].encode()
            k += 1
    return bytes(out)


# ---------------------------------------------------------------------------
# a constructor planted in the description
# ---------------------------------------------------------------------------
#: A constructor with a side effect (gcc drops an empty one), and a global it sets.
PLANT = (
    "x */ volatile int dyadfmu_planted_flag; __attribute__((constructor)) static void "
    "dyadfmu_planted(void) { dyadfmu_planted_flag = 1; } /* y"
)


def test_a_planted_constructor_is_refused(tmp_path):
    path = sixbar_with(tmp_path, description=toml_string(PLANT))
    line = path.read_text().splitlines().index(f"description = {toml_string(PLANT)}") + 1
    done = run_tool(path, "--check")
    assert done.returncode == 1
    assert (
        f"error: sixbar.toml:{line}: [scene]: description must not contain '*/' (it is "
        "copied into a C comment, which '*/' would end)"
    ) in done.stderr.splitlines()


def _build_fmu(table, tmp_path, name) -> Path:
    """The FMI 2 FMU of a tailored table, compiled as CMake compiles it (hidden
    visibility, the FMI functions exported and nothing else, unused sections dropped)."""
    gen = tmp_path / name
    for rel, text in pipeline.outputs_of(table).items():
        (gen / rel).parent.mkdir(parents=True, exist_ok=True)
        (gen / rel).write_text(text, encoding="utf-8")
    ident = table.identifier
    library = gen / "binaries" / "linux64" / f"{ident}.so"
    library.parent.mkdir(parents=True)
    types = sorted({d.type.lower() for d in table.scene.dyads})
    kinematics = []
    if table.scene.internal():  # a mechanism FMU: the types' kinematics too
        kinematics = [
            ROOT / "src" / "dyad_kinematics.c",
            ROOT / "src" / "dyad_kinematics_tangent.c",
        ]
        kinematics += [ROOT / "src" / f"dyad_kin_{t}{s}.c" for t in types for s in ("", "_tangent")]
    sources = (
        [ROOT / "src" / "dyad_common.c"]
        + [ROOT / "src" / f"dyad_{t}.c" for t in types]
        + kinematics
        + [ROOT / "src" / "dyad_tangent.c"]  # the closed forms' tangents (the derivative)
        + [ROOT / "src" / f"dyad_{t}_tangent.c" for t in types]
        + [
            gen / f"{ident}_scene.c",
            gen / f"{ident}_scene_tangent.c",
            ROOT / "fmu" / "fmu_instance.c",
            ROOT / "fmu" / "fmu_state.c",
            ROOT / "fmu" / "fmi2_functions.c",
            gen / f"{ident}_model.c",
        ]
    )
    done = subprocess.run(
        [
            GCC,
            *C_FLAGS,
            "-O1",
            "-fPIC",
            "-shared",
            "-fvisibility=hidden",
            "-ffunction-sections",
            "-fdata-sections",
            "-Wl,--gc-sections",
            f"-Wl,--version-script={ROOT / 'fmu' / 'exports.map'}",
            *include_flags(gen),
            *map(str, sources),
            "-o",
            str(library),
            "-lm",
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    fmu = tmp_path / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.write(gen / "fmi2" / "modelDescription.xml", "modelDescription.xml")
        archive.write(library, f"binaries/linux64/{ident}.so")
    return fmu


def _symbols_and_constructors(fmu: Path, tmp_path) -> tuple[list, int]:
    with zipfile.ZipFile(fmu) as archive:
        name = next(n for n in archive.namelist() if n.endswith(".so"))
        library = tmp_path / "inspect" / fmu.stem / Path(name).name
        library.parent.mkdir(parents=True)
        library.write_bytes(archive.read(name))
    nm = subprocess.run(["nm", "--defined-only", str(library)], capture_output=True, text=True)
    symbols = sorted(line.split()[-1] for line in nm.stdout.splitlines())
    sections = subprocess.run(
        ["objdump", "-h", str(library)], capture_output=True, text=True
    ).stdout
    init = re.search(r"\.init_array\s+([0-9a-f]+)", sections)
    return symbols, int(init.group(1), 16) if init else 0


@needs_gcc
@pytest.mark.skipif(
    shutil.which("nm") is None or shutil.which("objdump") is None, reason="binutils not available"
)
def test_a_planted_constructor_stays_a_comment_even_past_the_check(tmp_path):
    """With the description check bypassed, the escaping of the C comment alone keeps the
    planted code out: the FMU has the same symbols and constructors as with a plain
    description, and fmpy validates and runs it."""
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    plain = pipeline.build_table(pipeline.load_scene(SIXBAR))
    planted_scene = pipeline.load_scene(SIXBAR)
    planted_scene.description = PLANT
    planted = pipeline.build_table(planted_scene)
    assert textsafe.html(PLANT) in pipeline.outputs_of(planted)["documentation/index.html"]
    plain_fmu = _build_fmu(plain, tmp_path, "plain")
    planted_fmu = _build_fmu(planted, tmp_path, "planted")
    want = _symbols_and_constructors(plain_fmu, tmp_path)
    got = _symbols_and_constructors(planted_fmu, tmp_path)
    assert not any("planted" in s for s in got[0])
    assert got == want
    assert validate_fmu(str(planted_fmu)) == []
    result = simulate_fmu(str(planted_fmu), stop_time=0.01, step_size=0.005, output=["status"])
    assert len(result) >= 2


# ---------------------------------------------------------------------------
# a tunable pair point
# ---------------------------------------------------------------------------
class _Slave:
    """A pair-point FMU whose parameters are set before initialisation (dyadfmu's fmpy
    wrapper)."""

    def __init__(self, fmu: Path, tmp_path, tag):
        from dyadfmu.fmi.slave import Slave

        self.slave = Slave(fmu, instance_name=tag)
        self.md, self.vr = self.slave.md, self.slave.vr

    def start(self, parameters: dict):
        self.slave.initialize(parameters)

    def outputs(self, inputs: dict, names):
        self.slave.set(tuple(inputs), list(inputs.values()))
        self.slave.do_step(0.0, 1e-3)
        return np.array(self.slave.get(tuple(names)))


@needs_gcc
@pytest.mark.parametrize("tunable", ('["second.D_m"]', '["all"]'))
def test_a_tunable_pair_point_is_a_parameter_that_works(tunable, tmp_path):
    """modelDescription/scenes/README.md lists DYAD.D_m.x (a pair point `at`) among the tunable
    parameters: with it tunable, the FMU gives the outputs of the baked scene at the same value, and
    other outputs at another value."""
    path = sixbar_with(tmp_path, "tunable.toml", tunable=tunable)
    assert run_tool(path, "--check").returncode == 0
    tuned = pipeline.build_table(pipeline.load_scene(path))
    params = [v.name for v in tuned.variables if v.causality == "parameter"]
    assert {"second.D_m.x", "second.D_m.y"} <= set(params)
    baked = pipeline.build_table(pipeline.load_scene(SIXBAR))
    source = scenes.Source("sixbar")
    motion = source.motion("varying", 1.0)
    kin = source.kinematics(np.array([0.37 * motion.duration]), motion)
    inputs = {
        v.name: float(np.asarray(kin[v.name])[0]) for v in baked.variables if v.causality == "input"
    }
    names = [v.name for v in baked.variables if v.causality == "output" and v.type == "Real"]
    want = _Slave(_build_fmu(baked, tmp_path, "baked"), tmp_path, "baked")
    want.start({})
    expected = want.outputs(inputs, names)
    same = _Slave(_build_fmu(tuned, tmp_path, "tuned"), tmp_path, "same")
    same.start({})
    assert np.array_equal(same.outputs(inputs, names), expected)
    moved = _Slave(tmp_path / "tuned.fmu", tmp_path, "moved")
    start = {v.name: v.start for v in tuned.variables if v.name == "second.D_m.x"}
    moved.start({"second.D_m.x": start["second.D_m.x"] + 0.01})
    assert not np.array_equal(moved.outputs(inputs, names), expected)


# ---------------------------------------------------------------------------
# every failure a message
# ---------------------------------------------------------------------------
_NASTY = [
    10**400,
    -(10**400),
    math.nan,
    math.inf,
    0,
    -1,
    1e308,
    True,
    "",
    "x",
    "\u202e",
    "a*/b",
    "in",
    "load",
    "dyad_x",
    "crank",
    "frame",
    "external",
    "all",
    [],
    [1, 2],
    [10**400, 0],
    ["all"],
    {},
    {"link": "frame"},
    {"link": {"name": "crank"}},
    {"link": "crank", "at": [0.0, 0.0]},
    {"link": "crank", "guide": 0.1},
    "RRR",
    "RTT",
    "TRT",
    "a" * 41,
    "rocker",
    "coupler",
    "first",
    "link_m",
    [[1]],
    0.5,
    {"x": 1},
    "status",
    "first.D_m",
    "crank.torque",
    "int",
    "rod_f",
    "crank_torque",
    "x\n",
]


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and not math.isfinite(v):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, list):
        return "[" + ", ".join(map(_toml_value, v)) + "]"
    return "{ " + ", ".join(f"{toml_string(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"


def _toml(data: dict) -> str:
    lines = []
    for key, value in data.items():
        rows = (
            value
            if isinstance(value, list) and value and all(isinstance(r, dict) for r in value)
            else None
        )
        if isinstance(value, dict):
            rows = [value]
        if rows is None:
            lines.insert(0, f"{toml_string(key)} = {_toml_value(value)}")
            continue
        for row in rows:
            lines.append(
                f"[{toml_string(key)}]" if isinstance(value, dict) else f"[[{toml_string(key)}]]"
            )
            lines += [f"{toml_string(k)} = {_toml_value(v)}" for k, v in row.items()]
    return "\n".join(lines) + "\n"


def _mutate(rng, node, depth=0):
    if isinstance(node, dict) and node:
        key = rng.choice(list(node))
        r = rng.random()
        if r < 0.4 or depth > 3:
            node[key] = rng.choice(_NASTY)
        elif r < 0.5:
            del node[key]
        elif r < 0.6:
            node[rng.choice(["name", "at", "guide", "link", "k", "p", "type", "x"])] = rng.choice(
                _NASTY
            )
        else:
            _mutate(rng, node[key], depth + 1)
    elif isinstance(node, list) and node:
        k = rng.randrange(len(node))
        r = rng.random()
        if r < 0.3 and not isinstance(node[k], dict):
            node[k] = rng.choice(_NASTY)
        elif r < 0.4:
            node.append(json.loads(json.dumps(node[k])))
        elif r < 0.5:
            del node[k]
        else:
            _mutate(rng, node[k], depth + 1)


def test_mutated_scenes_give_messages_never_tracebacks(tmp_path):
    """Values of the example scenes replaced by numbers beyond a double, NaN, wrong types,
    names that clash, tables where strings belong: the generator accepts the scene and
    generates it, or refuses it with file:line messages; nothing else escapes."""
    sources = [(p, tomllib.loads(p.read_text())) for p in sorted(SCENES_DIR.glob("*.toml"))]
    for _, data in sources:  # a copy may not keep a built-in scene's identifier
        data["scene"]["identifier"] = "my_" + data["scene"]["identifier"]
    rng = random.Random(2024)
    outcomes = collections.Counter()
    for trial in range(600):
        path, data = rng.choice(sources)
        data = json.loads(json.dumps(data))
        for _ in range(rng.randint(1, 3)):
            _mutate(rng, data)
        target = tmp_path / path.name
        try:
            target.write_text(_toml(data), encoding="utf-8")
            tomllib.loads(target.read_text())
        except (ValueError, TypeError, tomllib.TOMLDecodeError):
            continue
        try:
            pipeline.outputs_of(pipeline.build_table(pipeline.load_scene(target)))
            outcomes["accepted"] += 1
        except SceneError as error:
            outcomes["refused"] += 1
            for message in error.args[0]:
                assert re.match(rf"{re.escape(path.name)}:\d+: \S", message), (trial, message)
    assert outcomes["refused"] > 300 and outcomes["accepted"] > 20, outcomes


# ---------------------------------------------------------------------------
# long chains
# ---------------------------------------------------------------------------
def _calls_to_check(path: Path) -> int:
    """Python and C function calls made while checking a scene (as --check does)."""
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event in ("call", "c_call"):
            count += 1

    sys.setprofile(profile)
    try:
        pipeline.build_table(pipeline.load_scene(path))
    finally:
        sys.setprofile(None)
    return count


def test_checking_a_chain_grows_linearly_with_its_dyads(tmp_path):
    """Function calls, not time: twice the dyads may cost a little more than twice the
    calls (the dependency lists are longer), not four or eight times."""
    c_names()  # learnt once per process
    small = _calls_to_check(long_chain.write_chain(50, tmp_path))
    large = _calls_to_check(long_chain.write_chain(100, tmp_path))
    print(f"calls to check 50 dyads: {small}, 100 dyads: {large} ({large / small:.2f} x)")
    assert large < 2.3 * small


def _dyad_lines(path: Path) -> list[int]:
    return [n for n, line in enumerate(path.read_text().splitlines(), 1) if line == "[[dyad]]"]


def _problems(path: Path) -> list[str]:
    try:
        pipeline.load_scene(path)
    except SceneError as error:
        return error.args[0]
    return []


_CHAIN_RULE = (
    "a chain has at most 200 (the model descriptions list every output's dependency on "
    "every input of the dyads hanging on it, which grows as dyads x chain length)"
)


@pytest.mark.parametrize("dyads", [201, 260])
def test_a_chain_past_its_limit_is_refused_once_at_its_first_dyad_past_it(dyads, tmp_path):
    assert long_chain.MAX_CHAIN == mechanism.MAX_CHAIN == 200
    path = long_chain.write_chain(dyads, tmp_path, chain=dyads)
    line = _dyad_lines(path)[200]
    assert _problems(path) == [
        f"{path.name}:{line}: dyad 'd201' hangs, directly or through other dyads, on 200 "
        f"dyads: a chain of 201, and {_CHAIN_RULE}"
    ]


def _two_chains_joined(tmp_path, p: str) -> Path:
    """Two chains of 100 dyads on the crank, and a 201st dyad whose k hangs on the first
    chain's last rocker and whose p is `p`."""
    text = long_chain.chain_scene(200, "joined", chain=100)
    text += f"""
[[dyad]]
name = "d201"
type = "RRR"
m = "coupler201"
n = "rocker201"
k = {{ link = "rocker100", at = [0.12, 0.02] }}
p = {p}

[[link]]
name = "coupler201"
length = 0.2
com = [0.07, 0.01]
mass = 1.0
inertia = 3.0e-3

[[link]]
name = "rocker201"
length = 0.15
com = [0.07, 0.01]
mass = 1.0
inertia = 3.0e-3
"""
    path = tmp_path / "joined.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_dyad_on_two_chains_has_both_in_its_chain(tmp_path):
    joined = _two_chains_joined(tmp_path, '{ link = "rocker200", at = [0.12, 0.02] }')
    line = _dyad_lines(joined)[200]
    assert _problems(joined) == [
        f"joined.toml:{line}: dyad 'd201' hangs, directly or through other dyads, on 200 "
        f"dyads: a chain of 201, and {_CHAIN_RULE}"
    ]
    assert _problems(_two_chains_joined(tmp_path, '"frame"')) == []


def test_model_descriptions_grow_linearly_with_dyads_in_chains_of_a_given_length(tmp_path):
    """The dependency lists grow as dyads x chain length: at a fixed chain length, twice
    the dyads give about twice the model description (a little more: the value
    references have more digits), not four times as one chain twice as long would."""
    sizes = {}
    for dyads in (100, 200):
        table = pipeline.build_table(
            pipeline.load_scene(long_chain.write_chain(dyads, tmp_path, chain=50))
        )
        sizes[dyads] = len(fmi2.model_description(table)) + len(fmi3.model_description(table))
    assert 1.9 < sizes[200] / sizes[100] < 2.3, sizes


@needs_gcc
def test_a_chain_of_200_dyads_is_checked_generated_and_compiles(tmp_path):
    path = long_chain.write_chain(200, tmp_path)
    done = run_tool(path, "--check")
    assert done.returncode == 0, done.stderr
    assert "chain200 (tailored): 1803 inputs, 4 parameters, 1604 outputs" in done.stdout
    out = tmp_path / "generated"
    assert run_tool(path, "--out", out).returncode == 0
    source = out / "chain200_scene.c"
    assert source.read_text().count("dyad_react_rrr(&load, &d") == 200
    _compiles(out, tmp_path)


# ---------------------------------------------------------------------------
# CMake
# ---------------------------------------------------------------------------
def test_cmake_stops_on_a_planted_description(tmp_path):
    bad = SCENES_DIR / "malformed" / "hostile_description_comment_end.toml"
    done = subprocess.run(
        [
            "cmake",
            "-S",
            str(ROOT),
            "-B",
            str(tmp_path / "build"),
            "-DDYADFMU_BUILD_TESTS=OFF",
            "-DDYADFMU_BUILD_BENCH=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DDYADFMU_SCENES={bad}",
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode != 0
    message = " ".join(done.stderr.split())  # CMake wraps long lines
    assert (
        "hostile_description_comment_end.toml:5: [scene]: description must not contain" in message
    ), done.stderr


# ---------------------------------------------------------------------------
# identifiers that would break the build: the core's prefixes, a built-in FMU's name
# ---------------------------------------------------------------------------
def _identifier_refusal(tmp_path, identifier: str) -> tuple[int, list[str]]:
    """(line of the identifier, the problems) of the six-bar copied under `identifier`."""
    path = sixbar_with(tmp_path, "named.toml", identifier=toml_string(identifier))
    line = path.read_text().splitlines().index(f"identifier = {toml_string(identifier)}") + 1
    try:
        pipeline.load_scene(path)
    except SceneError as error:
        return line, error.args[0]
    return line, []


@pytest.mark.parametrize(
    "identifier, prefix",
    [
        ("dyad_check", "dyad_"),  # its dyad_check_input is the core's function
        ("fmu_x", "fmu_"),
        ("fmi2Foo", "fmi2"),
        ("fmi3_x", "fmi3"),
        ("dyadfmu_x", "dyadfmu_"),
        ("Dyad_Check", "dyad_"),
        ("fmu", "fmu_"),
    ],
)
def test_an_identifier_with_a_reserved_prefix_is_refused_at_its_line(tmp_path, identifier, prefix):
    line, problems = _identifier_refusal(tmp_path, identifier)
    assert (
        f"named.toml:{line}: [scene]: identifier '{identifier}' starts with '{prefix}', which "
        "is reserved for the C names of the core, the FMU layer and FMI"
    ) in "\n".join(problems), problems


#: Every name Windows reserves for a device, in the cases a scene might write it.
_DEVICES = ["con", "prn", "aux", "nul"] + [f"{p}{n}" for p in ("com", "lpt") for n in range(10)]


@pytest.mark.parametrize(
    "identifier", [f(d) for d in _DEVICES for f in (str.lower, str.upper, str.capitalize)]
)
def test_a_windows_device_name_is_refused_as_identifier_at_its_line(tmp_path, identifier):
    """nul.dll, com1.dll and the like are devices on Windows: no FMU binary can be so named."""
    line, problems = _identifier_refusal(tmp_path, identifier)
    assert problems == [
        f"named.toml:{line}: [scene]: identifier '{identifier}' is a reserved device name on "
        "Windows (in any case: CON, PRN, AUX, NUL, COM0 to COM9, LPT0 to LPT9): its library "
        f"{identifier}.dll could not be created or loaded there; choose another identifier"
    ], problems


@pytest.mark.parametrize("identifier", ["con1", "nul_x", "com10", "lpt", "auxiliary", "Com_1"])
def test_a_name_that_only_starts_like_a_device_is_accepted(tmp_path, identifier):
    assert _identifier_refusal(tmp_path, identifier)[1] == []


def test_a_superscript_port_number_is_no_identifier(tmp_path):
    """Windows also reserves COM¹ to COM³; they are no C identifiers, refused as such."""
    line, problems = _identifier_refusal(tmp_path, "COM\u00b9")
    assert len(problems) == 1 and "must be a C identifier" in problems[0], problems


def _builtin_files() -> list[tuple[Path, str]]:
    """(file, identifier) of every FMU the build always makes, read as CMake finds them."""
    files = sorted(SCENES_DIR.glob("*.toml")) + sorted((ROOT / "tests" / "scenes").glob("*.toml"))
    found = [(p, tomllib.loads(p.read_text())["scene"]["identifier"]) for p in files]
    tables = [MD_DIR / "interface" / name for name in ("drive.toml", "motor.toml")]
    return found + [(p, tomllib.loads(p.read_text())["model"]["identifier"]) for p in tables]


@pytest.mark.parametrize("path, identifier", _builtin_files(), ids=lambda v: str(v)[-20:])
def test_a_built_in_fmu_s_identifier_is_refused_in_another_file(tmp_path, path, identifier):
    """A second scene named like a built-in FMU makes CMake define its targets twice."""
    line, problems = _identifier_refusal(tmp_path, identifier)
    where = path.relative_to(ROOT)
    assert any(
        p.startswith(f"named.toml:{line}: [scene]: identifier '{identifier}' names a built-in FMU")
        and f"(from {where})" in p
        for p in problems
    ), problems


def test_each_built_in_scene_keeps_its_own_identifier():
    for path, _ in _builtin_files()[:-2]:
        pipeline.load_scene(path)  # no SceneError, dyad_rrr's 'dyad_' prefix included


# ---------------------------------------------------------------------------
# untrusted TOML: size, nesting, byte order mark
# ---------------------------------------------------------------------------
def test_a_deeply_nested_value_is_refused_at_its_line_without_a_traceback(tmp_path):
    path = tmp_path / "deep.toml"
    path.write_text(SIXBAR.read_text() + "\n[start]\ncom = " + "[" * 5000 + "]" * 5000 + "\n")
    line = len(path.read_text().splitlines())
    done = run_tool(path, "--check")
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert f"error: deep.toml:{line}: arrays or tables nested more than 32 deep" in done.stderr


def test_a_file_without_end_is_not_read_to_its_end():
    done = subprocess.run(
        [sys.executable, str(SCENE_TOOL), "/dev/zero", "--check"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert "error: zero: larger than 1000000 bytes: not read" in done.stderr


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + sixbar_with(tmp_path).read_bytes())
    assert pipeline.load_scene(path).identifier == COPY_ID


# ---------------------------------------------------------------------------
# a refused value is told once, not again by the checks that depend on it
# ---------------------------------------------------------------------------
def _engine_problems(tmp_path, old: str, new: str) -> list[str]:
    text = (SCENES_DIR / "engine.toml").read_text()
    text = text.replace('identifier = "engine"', 'identifier = "my_engine"')
    assert old in text
    return _refusal(tmp_path, text.replace(old, new, 1))


def test_a_refused_link_name_is_told_once(tmp_path):
    """The probe's case: a [[link]] refused for its name left the dyad without links, and
    the load on the other link, 'piston', was told as a load on an unknown link."""
    problems = _engine_problems(tmp_path, 'name = "rod"', 'name = "ro\\"d"')
    assert any("link #2: name 'ro\"d' must be a lower-case identifier" in p for p in problems)
    assert not any("[loads]" in p for p in problems), problems


def test_a_refused_gravity_is_not_told_again_as_an_unknown_tunable(tmp_path):
    problems = _engine_problems(tmp_path, "y = -9.81", "y = nan")
    assert len(problems) == 1 and "[gravity]: 'y' must be a finite number" in problems[0]

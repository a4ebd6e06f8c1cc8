"""A scene's batch evaluation in lanes (<id>_lanes: emit/batch_c.py on
src/dyad_lanes.h), compiled as the FMU compiles its scene C: the build's object of that C
where it is current (_built_scene), else compiled here.

For every built-in scene that has one, over random samples of its inputs with failing
ones mixed in (an input NaN, an input far out of range; the toggles scene's dead centres
and lost assemblies), a sample's count of failed checks is 0 exactly where the scalar
<id>_evaluate says status 0, and there its outputs are evaluate's bit for bit: in the
baseline build, the AVX2 one and the AVX-512 one (where the CPU has them), each called by
name, and through the dispatching <id>_lanes; also _first against <id>_evaluate_first,
and _bare (the bounds left out: NaN) against the same, but for the bounds and for a
sample with a reaction beyond DBL_MAX eps, which _bare sends to be evaluated alone.
GCC reports every loop over samples vectorised in each build: a scene's, dyad_solve_batch's
and a generic dyad FMU's (fmu/models/fmu_dyad_lanes.h). The FMU's columns entry
runs the lanes (scripts/tests/test_columns_entry.py holds it to the rows entry).
"""

from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadgen import pipeline
from dyadgen.corefiles import scene_core_sources
from dyadgen.emit.batch_c import batch_supported, block_reals, scheduled_lanes
from dyadgen.emit.scene_c import bare_lanes, bound_members, later_members
from dyadgen.locations import SCENES_DIR, TEST_SCENES_DIR
from tool_checks import CI, required_tool

ROOT = paths.ROOT
SCENE_TOOL = ROOT / "modelDescription" / "scene.py"
#: the flags fmu/CMakeLists.txt gives a scene's C, with the warnings of every build
FLAGS = [
    "-std=c99", "-O3", "-fno-trapping-math", "-fno-math-errno",
    "--param=large-function-growth=10000", "--param=inline-unit-growth=1000",
    "--param=max-combine-insns=2", "-fno-tree-pre",
    "-Wall", "-Wextra", "-Wpedantic", "-Werror",
]  # fmt: skip
#: ... and adds to a scene's C where its lanes are scheduled (batch_c.scheduled_lanes)
SCHEDULE = ["-fschedule-insns", "-fsched-pressure"]
#: a rebuild of an FMU's sources by an importer's compiler in its default mode, without the
#: build's -std=c99: GCC's GNU mode, which fuses a * b + c where the target has FMA (the
#: AVX-512 lanes'), and Clang, which fuses within an expression by default
REBUILDS = {
    "gnu": ["cc", *(f for f in FLAGS if f != "-std=c99")],
    "clang": ["clang", "-std=c99", "-O3", "-fno-trapping-math", "-fno-math-errno",
              "-Wall", "-Wextra", "-Wpedantic", "-Werror"],
}  # fmt: skip
SAMPLES = 600
SCENES = sorted(
    path
    for path in [*SCENES_DIR.glob("*.toml"), *TEST_SCENES_DIR.glob("*.toml")]
    if batch_supported(pipeline.load_scene(path, check_c_names=False))
)


def _table(path: Path):
    return pipeline.build_table(pipeline.load_scene(path, check_c_names=False))


DRIVER = r"""#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "@ID_scene.h"

typedef void (*lanes_fn)(size_t, dyad_real (*)[@UP_LANES], const unsigned char*);
typedef void (*scalar_fn)(const @ID_input*, @ID_output*, fmu_evaluation*);

/* Every sample of `in` through the lanes of `lanes`, @UP_LANES at a time: per sample its
 * count of failed checks and its outputs, after the scalar evaluation's status and
 * outputs. */
static void run(const double* in, size_t count, lanes_fn lanes, scalar_fn scalar, FILE* out)
{
    static dyad_real grid[@UP_LANE_COLUMNS][@UP_LANES];
    size_t first, i, j;
    for (first = 0; first < count; first += @UP_LANES) {
        const size_t n = count - first < @UP_LANES ? count - first : @UP_LANES;
        for (i = 0; i < n; ++i) {
            for (j = 0; j < @UP_LANE_INPUTS; ++j) {
                grid[j][i] = in[(first + i) * @UP_LANE_INPUTS + j];
            }
        }
        lanes(n, grid, NULL);
        for (i = 0; i < n; ++i) {
            @ID_input block;
            @ID_output result;
            fmu_evaluation evaluation;
            memcpy(&block, &in[(first + i) * @UP_LANE_INPUTS], sizeof block);
            scalar(&block, &result, &evaluation);
            fprintf(out, "%d", result.status);
            for (j = 0; j < @UP_LANE_OUTPUTS; ++j) {
                fprintf(out, " %a", ((const dyad_real*)(const void*)&result)[j]);
            }
            fprintf(out, " | %a", grid[@UP_LANE_INPUTS + @UP_LANE_OUTPUTS][i]);
            for (j = 0; j < @UP_LANE_OUTPUTS; ++j) {
                fprintf(out, " %a", grid[@UP_LANE_INPUTS + j][i]);
            }
            fprintf(out, "\n");
        }
    }
}

int main(int argc, char** argv)
{
    static double in[@SAMPLES * @UP_LANE_INPUTS];
    FILE* file = fopen(argv[1], "rb");
    const char* how = argc > 2 ? argv[2] : "";
    scalar_fn scalar = @ID_evaluate;
    lanes_fn lanes = @ID_lanes;
    if (file == NULL || fread(in, sizeof in, 1, file) != 1) {
        return 2;
    }
    fclose(file);
    const int bare = strstr(how, "bare") != NULL, first = strstr(how, "first") != NULL;
    if (first) {
        @FIRST
    }
    if (bare) {
        @BARE
    }
    if (strstr(how, "baseline") != NULL) {
        lanes = bare ? @BARE_BASELINE : first ? @FIRST_BASELINE : @ID_lanes_baseline;
    }
#if defined(__x86_64__)
    if (strstr(how, "avx2") != NULL) {
        if (!__builtin_cpu_supports("avx2")) {
            return 3;
        }
        lanes = bare ? @BARE_AVX2 : first ? @FIRST_AVX2 : @ID_lanes_avx2;
    }
    if (strstr(how, "avx512") != NULL) {
        if (!__builtin_cpu_supports("avx512f")) {
            return 3;
        }
        lanes = bare ? @BARE_AVX512 : first ? @FIRST_AVX512 : @ID_lanes_avx512;
    }
#endif
    run(in, @SAMPLES, lanes, scalar, stdout);
    return 0;
}
"""


def _driver(ident: str, has_first: bool, has_bare: bool) -> str:
    """The test program of scene `ident`; `has_first`: whether it has halves; `has_bare`:
    lanes without the bounds, held to the first half (or the whole) bit for bit."""
    text = DRIVER.replace("@UP_", f"{ident.upper()}_").replace("@SAMPLES", str(SAMPLES))
    scalar = "@ID_evaluate_first" if has_first else "@ID_evaluate"
    for isa in ("_BASELINE", "_AVX2", "_AVX512"):
        text = text.replace(f"@BARE{isa}", f"@ID_lanes_bare{isa.lower()}" if has_bare else "lanes")
    text = text.replace(
        "@BARE", f"scalar = {scalar}; lanes = @ID_lanes_bare;" if has_bare else "return 4;"
    )
    if has_first:
        text = text.replace("@FIRST_BASELINE", "@ID_lanes_first_baseline")
        text = text.replace("@FIRST_AVX2", "@ID_lanes_first_avx2")
        text = text.replace("@FIRST_AVX512", "@ID_lanes_first_avx512")
        text = text.replace("@FIRST", "scalar = @ID_evaluate_first; lanes = @ID_lanes_first;")
    else:
        text = text.replace("@FIRST_BASELINE", "@ID_lanes_baseline")
        text = text.replace("@FIRST_AVX2", "@ID_lanes_avx2")
        text = text.replace("@FIRST_AVX512", "@ID_lanes_avx512")
        text = text.replace("@FIRST", "return 4;")
    return text.replace("@ID_", f"{ident}_")


#: the input _inputs spoils one sample in twenty with: the only samples whose reactions can
#: reach DBL_MAX eps (4e292), above which the lanes without the bounds send a sample to be
#: evaluated alone (src/dyad_lanes.h), as its bounds could overflow (a reaction need not be
#: an output, so the test asks for the input)
HUGE = 1e300


def _inputs(table, rng: np.random.Generator) -> np.ndarray:
    """SAMPLES input blocks: angles turned at random, other inputs scattered about their
    starts by their units' sizes, a tunable branch kept (the other assembly of a chain
    may not close anywhere near); one sample in twenty with an input NaN, one with an
    input of HUGE."""
    members, _ = block_reals(table.scene)
    start = {v.lives.path: float(v.start) for v in table.variables if v.start is not None}
    unit = {v.lives.path: v.unit for v in table.variables}
    scale = {"m": 0.02, "rad/s": 20.0, "rad/s2": 200.0, "m/s": 0.5, "m/s2": 20.0, "N": 300.0}
    columns = []
    for member, angle in members:
        if angle:
            turn = rng.uniform(-np.pi, np.pi, SAMPLES)
            columns += [np.cos(turn), np.sin(turn)]
        elif member.endswith("branch"):
            columns.append(np.full(SAMPLES, start.get(member, 1.0)))
        else:
            size = scale.get(unit.get(member) or "", 10.0)
            columns.append(start.get(member, 0.0) + size * rng.standard_normal(SAMPLES))
    block = np.column_stack(columns)
    for k in range(SAMPLES):
        if k % 20 == 7:
            block[k, rng.integers(block.shape[1])] = np.nan
        elif k % 20 == 13:
            block[k, rng.integers(block.shape[1])] = HUGE
    return block


def _dependencies(depfile: Path) -> list[Path] | None:
    """The files a Make-style dependency file lists after its target, resolved; None where
    it or one of them is not there, or it is not one rule of absolute paths."""
    try:
        text = depfile.read_text().replace("\\\n", " ")
        named = re.split(r"(?<!\\)\s+", text.split(": ", 1)[1].strip())
    except (OSError, IndexError):
        return None
    found = [Path(name.replace("\\ ", " ")) for name in named if name]
    if not found or not all(path.is_absolute() and path.is_file() for path in found):
        return None
    return [path.resolve() for path in found]


def _built_object(build: Path, source: Path, report: Path, schedule: list[str]) -> Path | None:
    """The object the build's compile command of `source` (compile_commands.json) writes,
    where that command is the compiler these tests call (cc) with FLAGS and `schedule`, -O3
    last, no sanitizer, and GCC's report to `report`."""
    commands = build / "compile_commands.json"
    if not commands.is_file():
        return None
    entries = [e for e in json.loads(commands.read_text()) if Path(e["file"]).resolve() == source]
    if len(entries) != 1:
        return None
    args = shlex.split(entries[0]["command"])
    levels = [a for a in args if a.startswith("-O")]
    dumps = [a.split("=", 1)[1] for a in args if a.startswith("-fdump-tree-vect-optimized=")]
    cc = shutil.which("cc")
    compiled_as_here = (
        cc is not None
        and Path(args[0]).resolve() == Path(cc).resolve()
        and set(FLAGS) <= set(args)
        and (set(SCHEDULE) <= set(args)) == bool(schedule)
        and levels[-1:] == ["-O3"]
        and not any(a.startswith("-fsanitize") for a in args)
        and [Path(d).resolve() for d in dumps] == [report]
        and "-o" in args[:-1]
    )
    if not compiled_as_here:
        return None
    return (Path(entries[0]["directory"]) / args[args.index("-o") + 1]).resolve()


def _current(built: Path, source: Path, report: Path, gen: Path) -> bool:
    """Whether the object `built` and GCC's `report` of its compile are what the build
    would make now of the C that `gen` holds: every file the compile read that the
    generator wrote is byte for byte that in `gen`; the others are this checkout's or the
    system's (/usr); none is newer than the object, nor the target's makefiles (its flags),
    and the report is not older than any."""
    read = _dependencies(built.with_name(built.name + ".d")) if built.is_file() else None
    if read is None or source not in read:
        return False
    for path in read:
        if path.parent == source.parent:
            if path.read_bytes() != (gen / path.name).read_bytes():
                return False
        elif not path.is_relative_to(ROOT.resolve()) and not path.is_relative_to("/usr"):
            return False
    target = next((d for d in built.parents if d.suffix == ".dir"), None)
    rules = [target / name for name in ("flags.make", "build.make")] if target else []
    made = built.stat().st_mtime_ns
    if any(path.stat().st_mtime_ns > made for path in [*read, *rules] if path.is_file()):
        return False
    return report.stat().st_mtime_ns >= max(path.stat().st_mtime_ns for path in read)


def _built_scene(ident: str, gen: Path, schedule: list[str]) -> tuple[Path, str] | None:
    """(object, GCC's report of the loops it vectorised) of the scene's C as the build
    compiled it (fmu/CMakeLists.txt), where the build compiled this very C (what the
    generator writes today, in `gen`) as these tests would (_built_object) and the object
    is current (_current). Else None: the scene's C is compiled here."""
    build = paths.build_dir().resolve()
    source = build / "generated" / ident / f"{ident}_scene.c"
    report = source.with_suffix(".vect")
    if not (source.is_file() and report.is_file()):
        return None
    built = _built_object(build, source, report, schedule)
    if built is None or not _current(built, source, report, gen):
        return None
    with open(report) as lines:
        vectorised = "".join(line for line in lines if ": optimized: " in line)
    return built, vectorised


#: per scene, whether its lanes' test program linked the build's object of its C
LINKED_FROM_BUILD: dict[str, bool] = {}


@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    """Per scene: its lanes' test program, from the scene's FMU C and the core files it
    calls. The scene's C is the build's object where the build compiled it as this would
    (_built_scene; the excavator's takes 75 s), else compiled here."""
    required_tool("cc")
    made: dict[tuple[str, str], Path] = {}

    def make(path: Path, rebuild: str = "") -> tuple[Path, object]:
        table = _table(path)
        compile_with = REBUILDS[rebuild] if rebuild else ["cc", *FLAGS]
        if (path.name, rebuild) not in made:
            required_tool(compile_with[0])
            work = tmp_path_factory.mktemp(table.identifier)
            done = subprocess.run(
                [sys.executable, str(SCENE_TOOL), str(path), "--out", str(work / "gen")],
                capture_output=True,
                text=True,
            )
            assert done.returncode == 0, done.stderr
            gen = work / "gen"
            ident = table.identifier
            scene_c = (gen / f"{ident}_scene.c").read_text()
            has_first = f"{ident}_lanes_first(" in scene_c
            has_bare = f"{ident}_lanes_bare(" in scene_c
            (work / "main.c").write_text(_driver(ident, has_first, has_bare))
            core = [ROOT / "src" / f for f in scene_core_sources(table.scene, derivatives=False)]
            includes = [f"-I{d}" for d in (gen, ROOT / "src", ROOT / "src" / "include")]
            schedule = SCHEDULE if scheduled_lanes(table.scene) and not rebuild else []
            built = None if rebuild else _built_scene(ident, gen, schedule)
            if not rebuild:
                LINKED_FROM_BUILD[ident] = built is not None
            if built is None:
                report = subprocess.run(
                    [*compile_with, *schedule, *includes, "-c", str(gen / f"{ident}_scene.c"),
                     "-o", str(work / "scene.o"),
                     *([] if rebuild else ["-fopt-info-vec-optimized"])],
                    capture_output=True, text=True,
                )  # fmt: skip
                assert report.returncode == 0, report.stderr
                built = work / "scene.o", report.stderr
            (work / "vectorised.txt").write_text(built[1])
            link = subprocess.run(
                [*compile_with, *includes, str(work / "main.c"), str(built[0]),
                 *map(str, core), "-lm", "-o", str(work / "lanes")],
                capture_output=True, text=True,
            )  # fmt: skip
            assert link.returncode == 0, link.stderr
            rng = np.random.default_rng(sum(map(ord, ident)))
            _inputs(table, rng).astype("<f8").tofile(work / "inputs.bin")
            made[path.name, rebuild] = work
        return made[path.name, rebuild], table

    return make


def _rows(text: str) -> list[tuple[int, list[str], float, list[str]]]:
    rows = []
    for line in text.splitlines():
        scalar, lanes = line.split(" | ")
        status, *outputs = scalar.split()
        failed, *found = lanes.split()
        rows.append((int(status), outputs, float.fromhex(failed), found))
    return rows


#: each instruction set's lanes, called by name
ISAS = ("baseline", "avx2", "avx512")


def _halves(path: Path) -> tuple[str, ...]:
    """The scene's lanes: the whole, its first half where it has halves, and those without
    the bounds where it has them."""
    scene = pipeline.load_scene(path, check_c_names=False)
    return (
        "",
        *(["first "] if later_members(scene) else []),
        *(["bare "] if bare_lanes(scene) else []),
    )


#: (scene, how): the whole evaluation dispatched and each instruction set's, and where the
#: scene has halves its first, and its lanes without the bounds, the same ways
CASES = [
    (path, f"{half}{isa}".strip())
    for path in SCENES
    for half in _halves(path)
    for isa in ("", *ISAS)
]


@pytest.mark.parametrize(("path", "how"), CASES, ids=[f"{p.stem}-{h}" for p, h in CASES])
def test_a_sample_the_lanes_pass_is_what_evaluate_gives(path, how, programs):
    _check_lanes(*programs(path), how)


@pytest.mark.parametrize("how", ["avx512", "avx2", ""])
@pytest.mark.parametrize("rebuild", sorted(REBUILDS))
def test_a_rebuild_in_a_compilers_default_mode_keeps_the_bits(rebuild, how, programs):
    """The four-bar's scene C and the core files compiled as an importer may rebuild an
    FMU's sources (REBUILDS): each instruction set's lanes still give evaluate's bits (no
    fused multiply-add: dyad_lanes.h)."""
    _check_lanes(*programs(SCENES_DIR / "four_bar.toml", rebuild), how)


def _check_lanes(work: Path, table, how: str) -> None:
    """The lanes `how` of the program in `work` against the scalar evaluation, sample by
    sample."""
    done = subprocess.run(
        [str(work / "lanes"), str(work / "inputs.bin"), how], capture_output=True, text=True
    )
    if done.returncode == 3:
        pytest.skip(f"this CPU has no {how.split()[-1].upper()}")
    assert done.returncode == 0, done.stderr
    rows = _rows(done.stdout)
    assert len(rows) == SAMPLES
    _, members = block_reals(table.scene)
    bounds = [members.index(m) for m in bound_members(table.scene)] if "bare" in how else []
    assert bounds or "bare" not in how, "lanes without bounds for a scene that reports none"
    inputs = np.fromfile(work / "inputs.bin", dtype="<f8").reshape(SAMPLES, -1)
    passed = 0
    for k, (status, outputs, failed, found) in enumerate(rows):
        if bounds and failed != 0 and status == 0:  # a reaction beyond DBL_MAX eps ...
            assert np.nanmax(np.abs(inputs[k])) >= HUGE, (k, failed)  # ... from a huge input
            continue
        assert (failed == 0) == (status == 0), (k, status, failed)
        if status == 0:
            assert all("nan" in found[i] for i in bounds), (k, [found[i] for i in bounds])
            outputs = [o for i, o in enumerate(outputs) if i not in bounds]
            found = [o for i, o in enumerate(found) if i not in bounds]
            assert outputs == found, (
                k,
                [i for i, (a, b) in enumerate(zip(outputs, found, strict=True)) if a != b],
            )
            passed += 1
    # both sides reached: most samples pass, and some of the spoiled ones do not
    assert SAMPLES // 2 < passed <= SAMPLES - SAMPLES // 40, passed


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_the_loop_over_samples_vectorises(path, programs):
    """GCC's report: every lane's loop over samples vectorised (the whole evaluation's, and
    _first's where the scene has halves: the efforts and the reactions), for each
    instruction set (_widths)."""
    work, table = programs(path)
    scene_c = (work / "gen" / f"{table.identifier}_scene.c").read_text().splitlines()
    loops = [  # each lane's loop, the whole's first: a sample's input block is its first line
        n + 1
        for n, line in enumerate(scene_c[:-1])
        if line == "    for (i = 0; i < count; ++i) {"
        and scene_c[n + 1].endswith(f"{table.identifier}_input in;")
    ]
    report = (work / "vectorised.txt").read_text()
    vectorised = set(
        (int(line), width)
        for line, width in re.findall(
            r"_scene\.c:(\d+):\d+: optimized: loop vectorized using (\d+) byte vectors", report
        )
    )
    wanted = {(line, width) for line in loops for width in _widths()}
    assert loops and wanted <= vectorised, sorted(wanted - vectorised)


#: scenes whose lanes choose an assembly branch per sample (a tunable branch input): a
#: dyad's (RRT, RRR) and a cylinder's
BRANCHED = [p for p in SCENES if p.stem in ("slider_crank", "four_bar", "cylinder_arm")]


@pytest.mark.parametrize("path", BRANCHED, ids=[p.stem for p in BRANCHED])
def test_a_loop_over_samples_holds_each_double_in_one_register(path, programs):
    """GCC's vectoriser takes as many samples a vector as a vector holds doubles (SSE2 2,
    AVX2 4, AVX-512 8) in each lane's loop over samples, with a branch input among them: a
    32-bit value in the loop (an int branch, say) would make it take twice as many, each
    double then in two registers (the slider-crank's AVX2 lanes: 290 -> 266 instructions a
    sample through the columns entry without it)."""
    work, table = programs(path)
    ident = table.identifier
    scene_c = work / "gen" / f"{ident}_scene.c"
    assert "< 0 ? DYAD_R(-1.0) : DYAD_R(1.0)" in scene_c.read_text()  # a branch per sample
    lines = scene_c.read_text().splitlines()
    loops = {
        n + 1
        for n, line in enumerate(lines[:-1])
        if line == "    for (i = 0; i < count; ++i) {"
        and lines[n + 1].endswith(f"{ident}_input in;")
    }
    dump = work / "vect"
    dump.mkdir(exist_ok=True)
    includes = [f"-I{d}" for d in (work / "gen", ROOT / "src", ROOT / "src" / "include")]
    done = subprocess.run(
        ["cc", *FLAGS, *includes, "-c", str(scene_c), "-o", str(dump / "scene.o"),
         f"-fdump-tree-vect-details={dump / 'scene.vect'}"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    doubles = {"baseline": 2, "avx2": 4, "avx512": 8}
    wanted = {isa: n for isa, n in doubles.items() if str(8 * n) in _widths()}
    first: dict[tuple[str, int], int] = {}  # (function, loop line): its first factor
    function = ""
    with open(dump / "scene.vect") as report:
        for line in report:
            if line.startswith(";; Function "):
                function = line.split()[2]
                continue
            found = re.search(r"_scene\.c:(\d+):\d+: note: +vectorization factor = (\d+)", line)
            if found and int(found[1]) in loops:
                first.setdefault((function, int(found[1])), int(found[2]))
    lanes = {(f, n): factor for (f, n), factor in first.items() if f.startswith(f"{ident}_lanes")}
    checked = [(f, n, factor, wanted[f.rsplit("_", 1)[1]]) for (f, n), factor in lanes.items()
               if f.rsplit("_", 1)[1] in wanted]  # fmt: skip
    assert len(checked) >= len(wanted), sorted(first)
    assert all(factor == n for _, _, factor, n in checked), checked


def test_dyad_solve_batch_loops_vectorise(tmp_path):
    """src/dyad_batch.c compiled as CMakeLists.txt compiles it: GCC's report has each
    type's loop over a block's rows vectorised, two rows a vector for the baseline and,
    on x86-64, four for AVX2 and eight for AVX-512 (src/dyad_lanes.h's solve lanes)."""
    required_tool("cc")
    source = ROOT / "src" / "dyad_batch.c"
    report = subprocess.run(
        ["cc", *FLAGS, f"-I{ROOT / 'src'}", f"-I{ROOT / 'src' / 'include'}", "-c", str(source),
         "-o", str(tmp_path / "batch.o"), "-fopt-info-vec-optimized"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert report.returncode == 0, report.stderr
    lines = source.read_text().splitlines()
    for kind in ("rrr", "rrt", "rtr", "trt", "rtt"):
        line = lines.index(f"BATCH_LOOPS({kind})") + 1
        for width in _widths():
            wanted = f"dyad_batch.c:{line}:1: optimized: loop vectorized using {width} byte vectors"
            assert wanted in report.stderr, (kind, width, report.stderr[-2000:])


@pytest.mark.parametrize("kind", ["rrr", "rrt", "rtr", "trt", "rtt"])
def test_a_generic_dyad_fmus_lanes_vectorise(kind, tmp_path):
    """A generic dyad FMU's variable table (dyad_<type>_model.c, which holds its lanes:
    fmu/models/fmu_dyad_lanes.h) compiled as fmu/CMakeLists.txt compiles it: GCC's report
    has its loop over samples vectorised in each instruction set's lanes (_widths)."""
    required_tool("cc")
    scene = SCENES_DIR / f"dyad_{kind}.toml"
    gen = tmp_path / "gen"
    done = subprocess.run(
        [sys.executable, str(SCENE_TOOL), str(scene), "--out", str(gen)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    model = gen / f"dyad_{kind}_model.c"
    includes = [ROOT / "src", ROOT / "src" / "include", ROOT / "fmu", ROOT / "fmu" / "models"]
    report = subprocess.run(
        ["cc", *FLAGS, *SCHEDULE, *(f"-I{d}" for d in includes), "-c", str(model),
         "-o", str(tmp_path / "model.o"), "-fopt-info-vec-optimized"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert report.returncode == 0, report.stderr
    line = model.read_text().splitlines().index(f"FMU_DYAD_LANES({kind})") + 1
    for width in _widths():
        wanted = f"_model.c:{line}:1: optimized: loop vectorized using {width} byte vectors"
        assert wanted in report.stderr, (kind, width, report.stderr[-2000:])


def _widths() -> list[str]:
    """The bytes of a vector of each instruction set's lanes the compiler builds: 16
    (SSE2, NEON), and on x86-64 32 (AVX2) and 64 (AVX-512)."""
    done = subprocess.run(["cc", "-dumpmachine"], capture_output=True, text=True)
    return ["16", "32", "64"] if "x86_64" in done.stdout else ["16"]


def _cmake_flags(text: str, after: str) -> set[str]:
    """The compiler flags CMake text gives just after ``after`` (a generator expression's
    list separated by ';', or a set() of words)."""
    start = text.index(after) + len(after)
    chunk = text[start : text.index(")", text.index("\n", start) + 1) + 1]
    return set(re.findall(r"(?:-O3|-f[a-z-]+|--param=[a-z-]+=\d+)", chunk))


def test_the_build_compiles_the_lanes_with_the_flags_these_tests_use():
    """What these tests compile with is what the build gives the lanes: a scene's C and a
    generic dyad's variable table (fmu/CMakeLists.txt), the cross-compiled binaries' model
    C, and src/dyad_batch.c
    (CMakeLists.txt); a flag dropped there, and the loops would not vectorise in the
    binaries while these tests still did."""
    vectorising = {f for f in FLAGS if f.startswith(("-O", "-f", "--param"))}
    fmu = (ROOT / "fmu" / "CMakeLists.txt").read_text()
    core = (ROOT / "CMakeLists.txt").read_text()
    assert _cmake_flags(fmu, "set(lane_options") == vectorising
    for source, after in (
        ("${gen}/${id}_scene.c", ";${lane_report}"),
        ("${gen}/${id}_model.c", ""),
    ):
        given = re.escape(f"set_source_files_properties({source} PROPERTIES COMPILE_OPTIONS")
        options = re.escape(f'"${{lane_options}};${{scene_lane_schedule}}{after}")')
        assert re.search(given + r"\s+" + options, fmu), source
    assert _cmake_flags(fmu, "set(cross_lane_flags") == vectorising
    # ... and where the generator says "scheduled" (a scene's C, a generic dyad's table and
    # a cross build's model C) the flags for register pressure
    schedule = "-fschedule-insns;-fsched-pressure"
    assert f'set(lane_schedule "$<$<C_COMPILER_ID:GNU>:{schedule}>")\n' in fmu
    assert f"set(cross_lane_schedule {schedule.replace(';', ' ')})\n" in fmu
    assert schedule.split(";") == SCHEDULE
    assert (
        'if(lanes STREQUAL "scheduled")\n    set(scene_lane_schedule "${lane_schedule}")\n'
        "    set(scene_cross_schedule ${cross_lane_schedule})\n"
    ) in fmu
    assert "${cross_lane_flags} ${scene_cross_schedule}" in fmu
    wanted = {"-O3", "-fno-trapping-math", "-fno-math-errno"}
    assert _cmake_flags(core, "set_source_files_properties(src/dyad_batch.c") == wanted


@pytest.mark.parametrize(("threshold", "bare"), [(None, True), (1e-12, True), (1e-300, False)])
def test_lanes_leave_the_bounds_out_only_where_no_status_can_need_them(threshold, bare, tmp_path):
    """Every built-in scene without a cylinder has lanes without the bounds; a scene
    with a cylinder (whose bound divides by its forces) has none, nor one whose threshold
    lets a bound overflow where the scalar evaluation would then say status 3: the
    slider-crank at 1e-300 (a dyad's amplification up to (1 / eps) / 1e-300)."""
    from dyadgen.emit import kinematics_c

    for path in SCENES:
        scene = pipeline.load_scene(path, check_c_names=False)
        assert bare_lanes(scene) == (not kinematics_c.cylinders(scene)), path.name
    text = (SCENES_DIR / "slider_crank.toml").read_text()
    text = text.replace('identifier = "slider_crank"', 'identifier = "thresholded"', 1)
    if threshold is not None:
        text = text.replace("[scene]\n", f"[scene]\nsingular_threshold = {threshold!r}\n", 1)
    (tmp_path / "slider_crank.toml").write_text(text)
    scene = pipeline.load_scene(tmp_path / "slider_crank.toml", check_c_names=False)
    assert scene.threshold.value == (threshold or scene.threshold.value)
    assert bare_lanes(scene) == bare


def _chain_scene(stages: int, threshold: float) -> str:
    """A crank and `stages` RRR stages in series, each on the last one's rocker: every
    stage loads the one before it."""
    lines = [
        "[scene]",
        'identifier = "stages"',
        f"singular_threshold = {threshold!r}",
        'description = "RRR stages in series"',
        'outputs = ["all"]',
        "[crank]",
        'name = "crank"',
        "length = 0.3",
    ]
    for k in range(1, stages + 1):
        carrier = '"crank"' if k == 1 else f'{{ link = "r{k - 1}", at = [0.3, 0.0] }}'
        lines += [
            "[[dyad]]",
            f'name = "s{k}"',
            'type = "RRR"',
            f'm = "c{k}"',
            f'n = "r{k}"',
            f"k = {carrier}",
            f'p = {{ link = "frame", at = [{k}.0, 0.0] }}',
            "branch = 1",
        ]
    for k in range(1, stages + 1):
        for name, length in ((f"c{k}", 1.0), (f"r{k}", 0.3)):
            lines += ["[[link]]", f'name = "{name}"', f"length = {length}", "com = [0.1, 0.0]"]
            lines += ["mass = 1.0", "inertia = 0.01"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(("stages", "bare"), [(2, True), (6, False)])
def test_a_chain_whose_bounds_float_could_overflow_has_no_lanes_without_them(
    stages, bare, tmp_path
):
    """Six stages loading each other at a threshold of 1e-16: in double every bound stays
    finite, but the scene's C also compiles in float (DYAD_REAL_FLOAT), where each data
    factor reaches 2^23 and six of them overflow FLT_MAX: no lanes without the bounds.
    Two stages keep them."""
    (tmp_path / "stages.toml").write_text(_chain_scene(stages, 1e-16))
    scene = pipeline.load_scene(tmp_path / "stages.toml", check_c_names=False)
    assert batch_supported(scene) and len(scene.dyads) == stages
    assert bare_lanes(scene) == bare


def test_each_scenes_program_links_the_builds_object(programs):
    """Under CI, where build/ is built before the tests run, every scene's lanes program
    links the build's object of the scene's C (_built_scene) rather than compiling the C
    again: this file then takes minutes rather than ten. Elsewhere a build that is older
    than the sources, or configured otherwise, is compiled around, and this says which."""
    for path in SCENES:
        programs(path)
    compiled = sorted(ident for ident, linked in LINKED_FROM_BUILD.items() if not linked)
    if compiled and not CI:
        pytest.skip(f"compiled here, as {paths.build_dir()} has none current: {compiled}")
    assert not compiled, f"{paths.build_dir()} holds no current object of {compiled}"

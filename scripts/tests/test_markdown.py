"""Every Markdown the project writes, read back with a Markdown parser (markdown-it-py, see
markdown_check.py): each report writer is called on small data holding hostile text (a
'|', a backslash, a backtick, HTML, a newline, emphasis, a link, mathematics, an entity)
where a user's or an FMU's text goes (a name, a unit, a study's description, an FMU's
message), and every table must have as many cells in each row as in its header and its
delimiter row, with the hostile text one cell shown literally; the escaping itself
(dyadfmu.report.markdown) in a paragraph, a heading and a cell. The reports that other
tests write by running the commands are read the same way there (test_harness.py,
test_cosim.py, test_sweep.py), and the quick study's report that scripts/run-tests writes
before pytest (build/study-quick/report.md) here."""

from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import markdown_check as mc
import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import importers, scenes, windows
from dyadfmu.cosim.compare import OutputError
from dyadfmu.report import cosim as cosim_report
from dyadfmu.report import markdown, mechanisms, tables
from dyadfmu.report import scenes as scenes_report
from dyadfmu.report import speed as speed_report
from dyadfmu.report import study as study_report
from dyadfmu.report import sweep as sweep_report
from dyadfmu.study import long_chain
from dyadfmu.study.accuracy import METHODS, SETS, Sizes
from dyadfmu.study.configurations import TYPES
from dyadfmu.study.footprint import Footprint
from dyadfmu.study.speed import SceneSpeed, Step, TypeSpeed
from dyadfmu.sweep import results
from dyadfmu.sweep.studyfile import read_study
from tool_checks import required

#: Text that would break a table or mark itself up if it were pasted raw.
HOSTILE = "a|b \\ c `d` <script>alert(1)</script>\nnext *e* _f_ [g](h) $i$ ~~j~~ &amp; # k\\"
#: How it must show: the newline visible, everything else as it is.
SHOWN = HOSTILE.replace("\n", "<U+000A>")


def _cell(table: mc.Table, row: int, column: int) -> str | None:
    return table.texts(row)[column]


def _only_text(inline, allowed: tuple[str, ...] = ()) -> str:
    """The text an inline token shows, where its only markup is of the kinds `allowed`
    (the project's own emphasis around literal text)."""
    kinds = {c.type for c in inline.children}
    assert kinds <= {"text", *allowed}, (inline.content, kinds)
    return "".join(c.content for c in inline.children if c.type == "text")


# ---- the checker -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        # the errors table as it was written: nine header cells over five delimiters
        (
            "| output | unit | peak |reference| | max |FMU - reference| | relative to peak |\n"
            "|---|---|---|---|---|\n| R.x | N | 1 | 0 | 0 |\n",
            "in no table",
        ),
        ("| a | b |\n|---|---|\n| 1 | 2 | 3 |\n", "3 cells under a header of 2"),
        ("| a | b |\n|---|---|\n| 1 \\| 2 |\n", "1 cells under a header of 2"),
        ("| a | b |\n|---|---|\n| 1 | 2 |\n|x\n", "3 cells|in no table|1 cells"),
    ],
)
def test_the_checker_finds_a_ragged_or_broken_table(text, problem):
    with pytest.raises(AssertionError, match=problem):
        mc.tables(text)


# ---- the escaping ------------------------------------------------------------------------

LITERALS = [
    HOSTILE,
    "- item",
    "+ item",
    "1. first",
    "2) second",
    "---",
    "= =",
    "***",
    "> quoted",
    "#heading #",
    "    four spaces",
    "<!-- comment -->",
    "<http://example.com>",
    "&lt;img&gt; &#65; &copy",
    "a\\",
    "\\|",
    "``` fence",
    "~~~",
    "[a]: /url",
    "![i](u)",
    "line\u2028sep\u202eback\x1b[31m\ttab",
    "-1.5e+03 and 1.5 and a - b",
]


def _expected(text: str) -> str:
    return "".join(f"<U+{ord(ch):04X}>" if markdown.hidden(ch) else ch for ch in text.strip(" "))


@pytest.mark.parametrize("raw", LITERALS)
def test_text_shows_literally_in_a_heading_a_paragraph_and_a_cell(raw):
    safe = markdown.text(raw)
    document = "\n".join(
        [f"# {safe}", "", "intro", safe, "", safe, "", *markdown.table([safe, "b"], [[safe, raw]])]
    )
    heading, continued, paragraph = mc.paragraphs(document)[:3]
    want = _expected(raw)
    assert mc.literal(heading) == want
    assert mc.literal(paragraph) == want
    # after a line of a paragraph: no setext underline, no list or quote interrupting it
    assert _only_text(continued, ("softbreak",)) == "intro" + want
    (table,) = mc.tables(document)
    assert table.texts(0) == [want, "b"] and table.texts(1) == [want, want]


def test_text_is_one_line_and_markup_passes_unchanged():
    safe = markdown.text("a\nb\r\nc")
    assert "\n" not in safe and "\r" not in safe
    assert markdown.text(safe) == safe
    assert markdown.text(markdown.Markup("**bold**")) == "**bold**"
    assert markdown.text(1.5) == "1.5"
    assert markdown.text("-1.5") == "-1.5" and markdown.text("1.5") == "1.5"


def test_a_table_refuses_a_ragged_row_and_a_cell_of_two_lines():
    with pytest.raises(ValueError, match="row 2 has 3 cells, its header 2"):
        markdown.table(["a", "b"], [["1", "2"], ["1", "2", "3"]])
    with pytest.raises(ValueError, match="one line"):
        markdown.table(["a"], [[markdown.Markup("x\ny")]])
    with pytest.raises(ValueError, match="align"):
        markdown.table(["a", "b"], [], "r")
    with pytest.raises(ValueError, match="one column"):
        markdown.table([], [])


def test_a_table_aligns_its_columns():
    lines = markdown.table(["a", "b", "c", "d"], [["1", "2", "3", "4"]], "-lrc")
    assert lines[1] == "|---|:---|---:|:---:|"
    tokens = mc.parser().parse("\n".join(lines))
    styles = [t.attrs.get("style") for t in tokens if t.type == "th_open"]
    assert styles == [None, "text-align:left", "text-align:right", "text-align:center"]


@pytest.mark.parametrize(
    ("raw", "span"),
    [("dyad_rrr*x[1]", True), ("a|b", False), ("a`b", False), ("a\nb", False), (" a", False)],
)
def test_a_code_span_where_one_holds_the_text_else_text(raw, span):
    document = f"{markdown.code(raw)}\n\n" + "\n".join(
        markdown.table(["x"], [[markdown.code(raw)]])
    )
    paragraph = mc.paragraphs(document)[0]
    (table,) = mc.tables(document)
    for inline in (paragraph, table.rows[1][0]):
        kinds = [c.type for c in inline.children]
        if span:
            assert kinds == ["code_inline"] and inline.children[0].content == raw
        else:
            assert mc.literal(inline) == _expected(raw)


def test_an_image_names_its_file_as_it_is():
    tokens = mc.paragraphs(markdown.image("a [b]", "my plot (1).png"))[0].children
    assert tokens[0].type == "image" and tokens[0].attrs["src"] == "my%20plot%20%281%29.png"
    assert "".join(c.content for c in tokens[0].children) == "a [b]"


# ---- the reports -------------------------------------------------------------------------


def test_a_run_errors_table_has_five_columns_and_its_names_literal(tmp_path):
    """dyadfmu run, dyadfmu scene: <name>_errors.md, its title the run's summary."""
    errors = [OutputError(HOSTILE, "N m", 2.0, 1e-15, 5e-16), OutputError("R.x", "N", 1, 0, 0)]
    md, _ = tables.write_error_tables(tmp_path / "x", HOSTILE, tables.error_rows(errors))
    text = md.read_text(encoding="utf-8")
    (table,) = mc.check_file(md)
    assert table.texts(0) == tables.ERROR_HEADER  # "peak |reference|" one cell
    assert len(table.rows) == 3 and _cell(table, 1, 0) == SHOWN
    assert mc.literal(mc.paragraphs(text)[0]) == SHOWN


def _scene_run(name: str) -> SimpleNamespace:
    """What scenes.accuracy_rows reads of a scene's run."""
    valid = np.array([True, True, False])
    return SimpleNamespace(
        name=name,
        fmi_version=2,
        steps=3,
        errors=[OutputError(HOSTILE, "N", 2.0, 1e-15, 5e-16)],
        worst_relative=5e-16,
        valid=valid,
        fmu={"crank.torque": np.array([-1.0, 2.0, 9.0])},
        source=SimpleNamespace(crank_name="crank"),
        energy_residual=math.nan,
        seconds_fmu=0.01,
    )


def test_the_scenes_report_reads_as_three_tables(tmp_path):
    """dyadfmu scenes: the accuracy, footprint and mechanism FMUs' tables, the drawings."""
    acc = scenes_report.accuracy_rows([_scene_run(HOSTILE), _scene_run("engine")])
    name = next(iter(scenes.FULL_OF))
    one = Footprint(3, 4, 5, 1000, 500, 800.0, 1e-7)
    foot = scenes_report.footprint_rows([(name, one, [one] * len(scenes.FULL_OF[name]))])
    moving = [list(mechanisms.HEADER)]
    moving.append(mechanisms.row(HOSTILE, -1, (9, 2), (HOSTILE, 1e-15), ("-", 0.0), (900, 300)))
    drawings = (tmp_path / "engine_reactions.png", tmp_path / "a|b`c.png")
    text = scenes_report.report_text(acc, foot, True, moving, drawings)
    found = mc.tables(text)
    assert [len(t.rows[0]) for t in found] == [len(acc[0]), len(foot[0]), len(mechanisms.HEADER)]
    assert [t.texts(0) for t in found] == [acc[0], foot[0], list(mechanisms.HEADER)]
    assert _cell(found[0], 1, 0) == SHOWN and _cell(found[2], 1, 0) == SHOWN
    assert _cell(found[2], 1, 4) == f"1.0e-15 ({SHOWN})" and _cell(found[2], 1, 5) == "0.0e+00 (-)"
    last = mc.paragraphs(text)[-1]
    assert _only_text(last, ("code_inline",)).endswith("a|b`c.png")


def _summary() -> list[dict]:
    """A study summary: every method and type, the FMUs in both versions."""
    methods = [*METHODS, "fmu_c2", "fmu_c3", "fmu_fmpy2", "fmu_fmpy3"]
    return [
        {"method": m, "type": t, "median": 1e-16, "worst": 1e-15, "componentwise": 1e-14}
        | {"seconds": 1e-7 * (k + 1), "instructions": 300.0 if m == "core" else math.nan}
        for k, m in enumerate(methods)
        for t in TYPES
    ]


def _speeds() -> tuple[list[TypeSpeed], list[SceneSpeed]]:
    step = {2: Step(400.0, 250.0, 30.0, 200.0), 3: Step(410.0, 250.0, 30.0, 200.0)}
    types = [
        TypeSpeed(t, 60, 70.0, 200.0, dict(step), 150.0, {False: 2e-7, True: 1e-7}) for t in TYPES
    ]
    batch = {(73, False): 1e-6, (73, True): 2e-6, (10_000, False): 3e-7, (10_000, True): 5e-7}
    batch[10_000, "numpy"] = batch[73, "rows"] = 2e-6
    batch[73, "baseline"], batch[10_000, "baseline"] = 2e-6, 2.4e-6
    batch[73, "avx2"], batch[10_000, "avx2"] = 1.5e-6, 1.2e-6
    batch[10_000, "into"], batch[10_000, "baseline into"] = 2.5e-7, 1.8e-6
    batch[10_000, "avx2 into"] = 1.1e-6
    plant = {v: Step(4000.0, 250.0, 0.0, 200.0) for v in (2, 3)}  # 20x: not the rule's
    flops = {False: 900.0, True: 1500.0}
    shaper = SceneSpeed("shaper", dict(step), batch, flops, lanes="avx512")
    scenes = [SceneSpeed(HOSTILE, dict(step)), shaper]
    return types, [*scenes, SceneSpeed("plant", plant, plant=True)]


def test_the_study_report_and_its_speed_section_read_as_tables(tmp_path):
    """dyadfmu study (report.md) and dyadfmu speed (its section, printed)."""
    contract = {(m, t, s): 0.5 for m in METHODS for t in TYPES for s in SETS}
    silent = {(m, t, s): 0 for m in METHODS for t in TYPES for s in SETS}
    figures = {"work_precision": Path("wp.png"), "error_vs_amplification": Path("e a.png")}
    sizes = Sizes(10, 5, 2, 1, 3, 10, 10, 10, 1)
    path = study_report.markdown(
        tmp_path, _summary(), contract, silent, sizes, True, 1.0, figures, _speeds()
    )
    found = mc.check_file(path)
    headers = [
        study_report.SUMMARY_HEADER,
        study_report.CONTRACT_HEADER,
        speed_report.TYPE_HEADER,
        speed_report.SCENE_HEADER,
        speed_report.BATCH_HEADER,
    ]
    assert [tuple(t.texts(0)) for t in found] == headers
    assert len(found[0].rows) == 1 + len(_summary()) and len(found[2].rows) == 1 + len(TYPES)
    assert _cell(found[3], 1, 0) == SHOWN
    printed = "\n".join(speed_report.markdown(*_speeds()))
    assert [tuple(t.texts(0)) for t in mc.tables(printed)] == headers[2:]
    # a plant's step (20x its evaluation: it integrates) is not held to the step rule
    assert "`dyadfmu plants` measures it): worst 2.05x" in printed
    # the shaper's batch against the stacked NumPy solve at 10,000 samples: 2e-6 / 3e-7
    assert "stacked NumPy solve: worst 6.7x (shaper, 10,000 samples), **not met**." in printed
    # against the flops' time (900 at RRR's 70 flops in 1e-7 s: 1.29e-6 s), at 10,000
    assert "within 1.5x, worst 1.87x (shaper, 10,000 samples), **not met**" in printed
    assert "AVX2's under 1x, worst 0.93x (shaper, 10,000 samples), met." in printed
    assert "AVX-512's, under 1x: worst 0.23x (shaper, 10,000 samples), met." in printed
    assert (
        "(`out=`), worst: AVX-512's 0.19x (shaper, 10,000 samples), AVX2's 0.86x (shaper, "
        "10,000 samples), the baseline's 1.40x (shaper, 10,000 samples)." in printed
    )
    assert _cell(found[4], 2, 3) == "300 ns (0.2x)"
    assert _cell(found[4], 2, 4) == "1200 ns (0.9x) / 2400 ns (1.9x)"
    assert _cell(found[4], 2, 5) == "250 ns (0.2x) / 1100 ns (0.9x) / 1800 ns (1.4x)"


def _cosim_row(name: str, scheme: str, step: float, diverged: bool) -> dict:
    """A row of the co-simulation study (cosim_report.FIELDS)."""
    row = dict.fromkeys(cosim_report.FIELDS, 0.5)
    row |= {"mechanism": name, "ratio": 1.0, "scheme": scheme, "step": step, "steps": 200}
    row |= {"diverged": diverged, "diverged_at": 0.25 if diverged else None, "fmi_version": 2}
    row |= {"reason": HOSTILE if diverged else "", "drive": HOSTILE, "wall_time": 0.1}
    row |= {"speed_error_at": 0.1, "reaction_error_at": 0.0, "dyad": "RRT"}
    return row


def test_the_cosim_report_shows_an_fmus_message_in_one_cell(tmp_path):
    """dyadfmu cosim: the machines, the runs (a diverged one with its FMU's message) and the
    mechanism FMUs' table."""
    rows = [
        _cosim_row("slider-crank", scheme, step, scheme == "explicit" and step == 1e-3)
        for scheme in ("explicit", "stabilised")
        for step in (1e-2, 1e-3)
    ]
    refs = {
        ("slider-crank", 1.0): SimpleNamespace(wall_time=1.0, mean_speed=314.0, peak_reaction=9e3)
    }
    drive = SimpleNamespace(
        t=np.zeros(11), inertia_mismatch=1e-15, affine_residual=1e-14, wall_time=0.2
    )
    runs = [(HOSTILE, 1e-3, drive, {"phi": 1e-9, "omega": 1e-8})]
    lines = tuple(cosim_report.mechanism_lines(runs))
    path = cosim_report.markdown(
        tmp_path / "report.md", rows, refs, True, 1.0, Path("plot.png"), 2, lines
    )
    text = path.read_text(encoding="utf-8")
    found = mc.check_file(path)
    headers = [
        cosim_report.MACHINE_HEADER,
        cosim_report.RESULTS_HEADER,
        cosim_report.MECHANISM_HEADER,
    ]
    assert [tuple(t.texts(0)) for t in found] == headers
    statuses = [found[1].rows[k][-1] for k in range(1, 5)]
    assert [mc.literal(s) for s in statuses] == ["ok", None, "ok", "ok"]
    assert (
        _only_text(statuses[1], ("strong_open", "strong_close")) == f"diverged at 0.25 s: {SHOWN}"
    )
    assert _cell(found[2], 1, 0) == SHOWN
    stamp, intro = mc.paragraphs(text)[1:3]
    assert _only_text(stamp, ("code_inline",)).startswith("Measured 20")  # when, on what
    assert f"drive: {SHOWN};" in _only_text(intro, ("code_inline",))


def test_the_sweep_report_shows_the_study_files_names_literally(tmp_path):
    """dyadfmu sweep: report.md, its title the study file's name, its description, the
    units of the FMU in the table's header."""
    (tmp_path / "m.fmu").write_bytes(b"")
    name = "st|u\\dy`<script>\n*x*"
    path = tmp_path / f"{name}.toml"
    description = HOSTILE
    path.write_text(
        f"[study]\ndescription = '''{description}'''\nfmu = \"m.fmu\"\n"
        '[run]\nkind = "kinetostatic"\nspeed = 10.0\npoints = 12\n'
        '[sampling]\nmethod = "grid"\ncount = 2\n'
        '[[parameter]]\nname = "crank.mass"\nlow = 1.0\nhigh = 2.0\n'
        '[[figure]]\nname = "peak"\nof = "crank.torque"\nstat = "peak"\n'
        '[objective]\nminimize = "peak"\nconstraints = [{ figure = "peak", max = 5 }]\n',
        encoding="utf-8",
    )
    study = read_study(path)
    table = results.Table(
        ["crank.mass"], ["peak"], np.array([[1.0], [2.0]]), np.array([[3.0], [-4.0]]),
        ["ok", "failed"], ["", HOSTILE],
    )  # fmt: skip
    units = {"crank.mass": "kg|`<b>`", "peak": "N m"}
    text = sweep_report.report_text(table, study, 2.0, HOSTILE, units)
    (found,) = mc.tables(text)
    assert found.texts(0) == ["design", "crank.mass [kg|`<b>`]", "peak [N m]", "digits"]
    assert found.texts(1) == ["0", "1", "3", "-"]
    title, stamp, said, ran = mc.paragraphs(text)[:4]
    assert mc.literal(title) == "Study " + name.replace("\n", "<U+000A>")
    assert mc.literal(stamp).endswith(f"by dyadfmu sweep {name.replace(chr(10), '<U+000A>')}.toml.")
    assert mc.literal(said) == " ".join(description.split())
    assert f"on {SHOWN} (not counting" in mc.literal(ran)


def test_the_importers_windows_and_scene_bench_tables_read_as_tables():
    """python -m dyadfmu.cosim.importers, python -m dyadfmu.cosim.windows, dyadfmu
    scene-bench: the tables they print."""
    raw = importers.Difference(HOSTILE, 100, 7, 1e-16, 2e-16, 1.0, "x", 0.5)
    exact = importers.Difference(HOSTILE, 100, 7, 0.0, 0.0, 0.0, "x")
    printed = importers.table_lines([(HOSTILE, 2, raw, exact), ("engine", 3, raw, raw)])
    (found,) = mc.tables("\n".join(printed))
    assert tuple(found.texts(0)) == importers.TABLE_HEADER
    assert found.texts(1)[0] == SHOWN and found.texts(1)[-1] == "bit-identical"
    assert found.texts(2)[-1] == "1 ulps"
    replay = windows.Difference(HOSTILE, 10, 4, 3, 1e-16, HOSTILE, False)
    (found,) = mc.tables("\n".join(windows.table_lines([replay])))
    assert tuple(found.texts(0)) == windows.TABLE_HEADER
    assert found.texts(1) == [SHOWN, "10", "0", "4", "3", f"1e-16 ({SHOWN})", "DIFFER"]
    bench = long_chain.table_lines([(25, (0.1, 0.05), (0.3, 0.2), 2.5e6)])
    (found,) = mc.tables("\n".join(bench))
    assert tuple(found.texts(0)) == long_chain.TABLE_HEADER
    assert found.texts(1) == ["25", "0.10", "0.05", "0.30", "0.20", "2.5"]


def test_the_quick_study_report_of_the_test_run_reads_as_tables():
    """The report scripts/run-tests writes with 'dyadfmu study --quick' before pytest."""
    report = paths.build_dir() / "study-quick" / "report.md"
    required(report.is_file(), f"{report} is not written (scripts/run-tests writes it)")
    found = mc.check_file(report)
    assert [tuple(t.texts(0)) for t in found][:2] == [
        study_report.SUMMARY_HEADER,
        study_report.CONTRACT_HEADER,
    ]


def test_a_report_says_when_on_what_and_by_which_command():
    """Every report's first paragraph: the time (UTC), this machine's processor and cores,
    and the command that regenerates it."""
    line = str(markdown.provenance("scripts/run-study --quick"))
    assert re.fullmatch(
        r"Measured 20\d\d-\d\d-\d\d \d\d:\d\d UTC on .+, \d+ cores, .+ by "
        r"`scripts/run-study --quick`\.",
        line,
    ), line
    assert markdown.machine() in line.replace("\\", "")


def test_the_speed_section_on_a_cpu_without_avx512_says_what_its_widest_lanes_did():
    """Where the widest lanes are AVX2's, they are the AVX2 figures, and no AVX-512 line."""
    types, scenes = _speeds()
    shaper = scenes[1]
    shaper.lanes = "avx2"
    shaper.samples = {k: v for k, v in shaper.samples.items() if k[1] not in ("avx2", "avx2 into")}
    printed = "\n".join(speed_report.markdown(types, scenes))
    assert "AVX2's under 1x, worst 0.23x (shaper, 10,000 samples), met." in printed
    assert "AVX-512" not in printed
    assert "worst: AVX2's 0.19x (shaper, 10,000 samples), the baseline's 1.40x" in printed
    batch = mc.tables(printed)[-1]
    assert _cell(batch, 2, 4) == "300 ns (0.2x) / 2400 ns (1.9x)"
    assert _cell(batch, 2, 5) == "250 ns (0.2x) / 1800 ns (1.4x)"

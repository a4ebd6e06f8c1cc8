"""Design studies (dyadfmu sweep): the study file refused with its line where it is wrong,
the designs, the counterweight's mass properties, the figures, the Pareto front, the
scene copy, and whole studies: on a local Dask cluster of two workers the table equals
the same runs in a loop, a failed run is a row with its status, and the best
counterweight is the one that balances the crank (known in closed form)."""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import markdown_check
import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.sweep import designs, execute, figures, results, runs, sources, stroke, study
from dyadfmu.sweep.studyfile import (
    Counterweight,
    Figure,
    LoadTable,
    Sampling,
    StudyError,
    read_study,
)

ROOT = Path(__file__).resolve().parents[2]
BALANCE = paths.build_dir() / "fmus" / "balance_fmi2.fmu"

#: The crank of tests/scenes/balance.toml: mass, centre of mass (m), inertia (kg m2).
M0, C0, I0 = 2.0, (0.012, 0.003), 3.0e-3
#: Where the study's counterweight goes, and its mass that brings the centre of mass to O.
AT = (-0.036, -0.009)
BALANCING = M0 * math.hypot(*C0) / math.hypot(*AT)  # = 2/3 kg: m0 c0 + m a = 0

BALANCE_STUDY = f"""
[study]
description = "counterweight on a crank with its own unbalance"
fmu = "{BALANCE}"

[run]
kind = "kinetostatic"
speed = 100.0
points = 36

[sampling]
method = "grid"
count = 13                    # 0 to 2 kg in steps of 1/6 kg: 2/3 kg is the 5th

[[parameter]]
name = "counterweight"
counterweight = "crank"
at = [{AT[0]}, {AT[1]}]
low = 0.0
high = 2.0

[[figure]]
name = "bearing_peak"
of = ["crank.R_O.x", "crank.R_O.y"]
stat = "peak"

[[figure]]
name = "torque_rms"
of = "crank.torque"
stat = "rms"

[objective]
minimize = "bearing_peak"
best = 3
"""


def _write(tmp_path: Path, text: str, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _refused(tmp_path: Path, text: str) -> str:
    with pytest.raises(StudyError) as info:
        read_study(_write(tmp_path, text))
    return str(info.value)


# ---- the study file --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ('stat = "peak"', 'stat = "highest"', "highest", "stat must be one of"),
        ("speed = 100.0", "speed = -1.0", "speed =", "speed must be a positive"),
        ("low = 0.0", "low = -1.0", "low =", "cannot be negative"),
        ("at = [", "at = [1.0, ", "at =", "at must be [x, y]"),
        ("high = 2.0", "high = nan", "high =", "high must be a finite number"),
        ('minimize = "bearing_peak"', 'minimize = "bearing"', "minimize", "must name a figure"),
        ("[[parameter]]", "[[parameter]]\nstep = 1", "step = 1", "unknown key 'step'"),
        ('name = "counterweight"', 'name = "drive.inertia"', "drive.inertia", "kind = 'driven'"),
        ('kind = "kinetostatic"', 'kind = "static"', "static", "kind must be"),
        ('method = "grid"', 'method = "sobol"', "sobol", "method must be one of"),
    ],
)
def test_a_bad_study_is_refused_at_its_line(tmp_path, old, new, marker, words):
    text = BALANCE_STUDY.replace(old, new, 1)
    assert text != BALANCE_STUDY
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if marker in t)
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: "), message
    assert words in message


def test_a_grid_over_a_million_designs_is_refused(tmp_path):
    text = BALANCE_STUDY.replace("count = 13 ", "count = 1001 ")
    text += '\n[[parameter]]\nname = "crank.length"\nlow = 0.04\nhigh = 0.06\n'
    assert "over a million" in _refused(tmp_path, text)


def test_a_name_the_fmu_does_not_have_is_refused_with_its_line(tmp_path):
    if not BALANCE.is_file():
        pytest.skip(f"{BALANCE} is not built")
    for old, new, words in [
        (
            'of = "crank.torque"',
            'of = "crank.torque_peak"',
            "crank.torque_peak is not a Real output",
        ),
        ('counterweight = "crank"', 'counterweight = "rod"', "rod.mass is not a Real parameter"),
    ]:
        text = BALANCE_STUDY.replace(old, new)
        line = next(k for k, t in enumerate(text.splitlines(), start=1) if new in t)
        with pytest.raises(StudyError) as info:
            study.prepare(_write(tmp_path, text), tmp_path)
        assert str(info.value).startswith(f"{tmp_path / 'study.toml'}:{line}: ")
        assert words in str(info.value)


def test_a_missing_source_file_is_refused(tmp_path):
    text = BALANCE_STUDY.replace(str(BALANCE), "no_such.fmu")
    assert "no such .fmu file" in _refused(tmp_path, text)


# ---- designs ---------------------------------------------------------------------------------


def test_a_grid_varies_the_first_parameter_slowest():
    d = designs.designs(Sampling("grid", 3), [0.0, 10.0], [2.0, 30.0])
    assert d.tolist() == [[a, b] for a in (0.0, 1.0, 2.0) for b in (10.0, 20.0, 30.0)]


@pytest.mark.parametrize("method", ["random", "lhs"])
def test_drawn_designs_are_within_bounds_and_repeat_by_seed(method):
    lows, highs = [-1.0, 100.0, 0.0], [1.0, 300.0, 1e-3]
    a = designs.designs(Sampling(method, 50, seed=7), lows, highs)
    b = designs.designs(Sampling(method, 50, seed=7), lows, highs)
    c = designs.designs(Sampling(method, 50, seed=8), lows, highs)
    assert a.shape == (50, 3) and np.array_equal(a, b) and not np.array_equal(a, c)
    assert np.all(a >= lows) and np.all(a <= highs)


def test_a_latin_hypercube_has_one_design_in_each_stratum():
    d = designs.designs(Sampling("lhs", 40, seed=3), [0.0, -5.0], [1.0, 5.0])
    for j, (lo, hi) in enumerate([(0.0, 1.0), (-5.0, 5.0)]):
        strata = np.floor((d[:, j] - lo) / (hi - lo) * 40).astype(int)
        assert sorted(strata) == list(range(40))


# ---- the counterweight, the loads, the figures -----------------------------------------------


def test_a_counterweight_moves_the_centre_of_mass_and_adds_its_inertia():
    cw = Counterweight("cw", 0.0, 1.0, "crank", (-0.05, 0.02))
    base = {"crank.mass": 2.0, "crank.com.x": 0.01, "crank.com.y": 0.0, "crank.inertia": 4e-3}
    out = cw.assign(0.5, base)
    # two bodies about the origin: the mass moment and the inertia about O are sums
    assert out["crank.mass"] == 2.5
    assert out["crank.com.x"] * 2.5 == pytest.approx(2.0 * 0.01 + 0.5 * -0.05, rel=1e-15)
    assert out["crank.com.y"] * 2.5 == pytest.approx(0.5 * 0.02, rel=1e-15)
    about_o = 4e-3 + 2.0 * 0.01**2 + 0.5 * (0.05**2 + 0.02**2)
    g2 = out["crank.com.x"] ** 2 + out["crank.com.y"] ** 2
    assert out["crank.inertia"] + 2.5 * g2 == pytest.approx(about_o, rel=1e-14)
    assert cw.assign(0.0, base) == pytest.approx(base)


def test_a_load_table_is_periodic_and_linear_between_points():
    table = LoadTable("f", (1.0, 2.0, 4.0), (10.0, 20.0, 0.0))
    assert table.at(1.5) == pytest.approx(15.0)
    assert table.at(3.0) == pytest.approx(10.0)
    assert table.at(1.5 + 2 * math.pi) == pytest.approx(15.0)
    # from 4 rad back to 1 + 2 pi: 0 -> 10
    assert table.at(4.0 + (2 * math.pi - 3.0) / 2) == pytest.approx(5.0)
    assert table.at(0.5) == pytest.approx(table.at(0.5 + 2 * math.pi))


def test_the_figures_of_known_series():
    phi = np.linspace(0.0, 4 * math.pi, 401)
    series = {"t": 2.0 + np.sin(phi), "x": 3.0 * np.ones(401), "y": 4.0 * np.ones(401)}

    def value(of, stat, phis=phi):
        return figures.figure_value(Figure("f", of, stat), series, phis)

    assert value(("x", "y"), "peak") == 5.0
    assert value(("t",), "fluctuation") == pytest.approx(2.0 / 2.0, rel=1e-3)
    assert value(("t",), "drop") == pytest.approx(2.0 / 3.0, rel=1e-3)
    # the work of a torque 2 + sin over two revolutions, per revolution: 2 * 2 pi
    assert value(("t",), "work_per_revolution") == pytest.approx(4 * math.pi, rel=1e-5)
    equal = np.linspace(0.0, 2 * math.pi, 36, endpoint=False)
    series["t"] = 2.0 + np.sin(equal)
    assert value(("t",), "work_per_revolution", None) == pytest.approx(4 * math.pi, rel=1e-14)
    assert value(("t",), "rms", None) == pytest.approx(math.sqrt(4.5), rel=1e-14)


def test_the_pareto_front_keeps_the_designs_none_beats_in_both():
    a = np.array([1.0, 2.0, 3.0, 2.5, 0.5, 4.0])
    b = np.array([5.0, 3.0, 1.0, 4.0, 9.0, 0.5])
    mask = np.array([True, True, True, True, True, False])
    assert results.pareto_front(a, b, mask) == [4, 0, 1, 2]


# ---- the scene copy --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "data",
    [
        {
            "a": 'quote " backslash \\ newline \n tab \t unicode \u00e9 \u2028',
            "b": [1, 2.5e-8, True],
        },
        {
            "scene": {"identifier": "x", "tunable": []},
            "dyad": [{"k": {"link": "frame", "at": [0.0, 0.01]}}, {"n": 1}],
        },
        {"loads": {'weird "key"': {"angle": [0.0], "value": [1.0]}}},
    ],
)
def test_toml_text_reads_back_as_the_same_data(data):
    assert tomllib.loads(sources.toml_text(data)) == data


def test_every_builtin_scene_reads_back_through_toml_text():
    for path in sorted((ROOT / "modelDescription" / "scenes").glob("*.toml")):
        data = tomllib.loads(path.read_text())
        assert tomllib.loads(sources.toml_text(data)) == data, path


def test_the_scene_copy_makes_the_study_parameters_tunable_and_passes_the_checks(tmp_path):
    s = read_study(ROOT / "modelDescription" / "scenes" / "studies" / "engine_counterweight.toml")
    path = sources.sweep_scene(s, tmp_path)
    scene = tomllib.loads(path.read_text())["scene"]
    assert scene["identifier"].startswith("engine_sweep_")
    assert set(scene["tunable"]) >= {"crank.mass", "crank.com.x", "crank.com.y", "crank.inertia"}
    assert sources.sweep_scene(s, tmp_path) == path  # the same study, the same copy
    done = subprocess.run(
        [sys.executable, str(ROOT / "modelDescription" / "scene.py"), str(path), "--check"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


# ---- whole studies -----------------------------------------------------------------------------


def _needs_balance():
    if not BALANCE.is_file():
        pytest.skip(f"{BALANCE} is not built")


def test_the_best_counterweight_is_the_one_that_balances_the_crank(tmp_path):
    _needs_balance()
    result = study.run_study(_write(tmp_path, BALANCE_STUDY), tmp_path / "out", workers=0)
    best = result.best[0]
    assert result.table.values[best, 0] == pytest.approx(BALANCING, rel=1e-12)
    peak = result.table.column("bearing_peak")
    # balanced, the bearing carries nothing; otherwise (m0 + m) omega^2 |com|
    assert peak[best] < 1e-9 * peak.max()
    for k in (0, 12):
        m = result.table.values[k, 0]
        com = np.hypot(M0 * C0[0] + m * AT[0], M0 * C0[1] + m * AT[1])
        assert peak[k] == pytest.approx(100.0**2 * com, rel=1e-12)
    assert (tmp_path / "out" / "study" / "results.csv").is_file()
    # the report read back by a Markdown parser: the best designs, one row each
    (best_table,) = markdown_check.check_file(tmp_path / "out" / "study" / "report.md")
    assert [row[0] for row in map(best_table.texts, range(1, 4))] == list(map(str, result.best))


FAILING_STUDY = BALANCE_STUDY.replace(
    "[[figure]]",
    '[[parameter]]\nname = "rod.length"\nlow = 0.02\nhigh = 0.2\n\n[[figure]]',
    1,
).replace("count = 13 ", "count = 3 ")


def test_a_local_cluster_of_two_gives_the_loop_s_table_and_failures_are_rows(tmp_path):
    _needs_balance()
    path = _write(tmp_path, FAILING_STUDY)
    s, run, values, _ = study.prepare(path, tmp_path)
    loop = results.table_of(s, values, [(k, run(tuple(v))) for k, v in enumerate(values)])
    on_dask = results.table_of(s, values, execute.run_dask(run, values, workers=2))
    assert on_dask.status == loop.status and on_dask.message == loop.message
    assert np.array_equal(on_dask.values, loop.values)
    assert np.array_equal(on_dask.figures, loop.figures, equal_nan=True)
    # a rod of 2 cm cannot reach the piston's line from a crank of 5 cm
    short = [k for k in range(len(values)) if values[k, 1] == 0.02]
    assert short and all(loop.status[k] == "cannot_assemble" for k in short)
    assert all("cannot assemble" in loop.message[k] for k in short)
    assert all(np.isnan(loop.figures[k]).all() for k in short)
    assert all(loop.status[k] == "ok" for k in range(len(values)) if k not in short)


def test_a_driven_study_on_two_workers_equals_its_loop(tmp_path):
    text = (ROOT / "modelDescription" / "scenes" / "studies" / "shaper_motor.toml").read_text()
    shaper = paths.build_dir() / "fmus" / "shaper_fmi2.fmu"
    if not shaper.is_file():
        pytest.skip(f"{shaper} is not built")
    text = text.replace('scene = "../shaper.toml"', f'fmu = "{shaper}"')
    text = text.replace("count = 8", "count = 2").replace("duration = 4.0", "duration = 0.3")
    text = text.replace("settle = 2.0", "settle = 0.1").replace(
        'name = "drive.inertia"', 'name = "drive.motor.no_load_speed"'
    )
    text = text.replace("low = 5.0\nhigh = 50.0", "low = 7.0\nhigh = 8.0").replace(
        '[drive]\n"motor.no_load_speed" = 7.5', "[drive]\ninertia = 5.0"
    )
    s, run, values, _ = study.prepare(_write(tmp_path, text), tmp_path)
    assert isinstance(run, runs.DrivenRun)
    loop = [(k, run(tuple(v))) for k, v in enumerate(values)]
    assert loop == execute.run_dask(run, values, workers=2)
    assert all(o.status == "ok" for _, o in loop)
    # a stiffer motor (higher stall torque) holds the speed closer to its mean
    fluct = {tuple(values[k]): o.figures[1] for k, o in loop}
    assert fluct[(400.0, 8.0)] < fluct[(100.0, 8.0)]


def test_a_study_runs_on_an_existing_cluster_by_its_address(tmp_path):
    _needs_balance()
    from dask.distributed import LocalCluster

    s, run, values, _ = study.prepare(_write(tmp_path, BALANCE_STUDY), tmp_path)
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster:
        remote = execute.run_dask(run, values, workers=0, scheduler=cluster.scheduler_address)
    assert remote == [(k, run(tuple(v))) for k, v in enumerate(values)]


def test_the_rows_entry_gives_the_fmi_calls_figures_bit_for_bit(tmp_path):
    _needs_balance()
    s, run, values, _ = study.prepare(_write(tmp_path, FAILING_STUDY), tmp_path)
    assert isinstance(run, runs.KinetostaticRun) and run.use_rows
    from dataclasses import replace

    through_fmi = replace(run, use_rows=False)
    rows = [(k, tuple(v)) for k, v in enumerate(values)]
    assert run.chunk(rows) == through_fmi.chunk(rows)


def test_the_rows_entry_refuses_a_value_reference_of_the_wrong_kind():
    _needs_balance()
    from dyadfmu.sweep.rows import rows_entry

    entry = rows_entry(BALANCE)
    x = np.zeros((2, 3))
    inputs = ("crank.angle", "crank.omega", "crank.epsilon")
    with pytest.raises(RuntimeError, match="refused"):  # an output set
        entry.evaluate((), np.zeros((2, 0)), ("crank.torque",) * 3, x, ("crank.torque",))
    with pytest.raises(RuntimeError, match="refused"):  # a parameter as an input
        entry.evaluate((), np.zeros((2, 0)), ("crank.mass",) * 3, x, ("crank.torque",))
    y, status = entry.evaluate(
        ("crank.mass",), np.array([[2.0], [-1.0]]), inputs, x, ("crank.torque", "crank.R_O.x")
    )
    assert status[0] == 0 and np.all(np.isfinite(y[0]))
    assert status[1] == 3 and np.all(np.isnan(y[1]))  # a negative mass: refused, NaN


def test_a_scene_identifier_or_study_name_cannot_leave_the_output_folder(tmp_path):
    scene = (ROOT / "tests" / "scenes" / "balance.toml").read_text()
    (tmp_path / "evil.toml").write_text(
        scene.replace('identifier = "balance"', 'identifier = "../../x"')
    )
    text = BALANCE_STUDY.replace(f'fmu = "{BALANCE}"', 'scene = "evil.toml"')
    s = read_study(_write(tmp_path, text))
    with pytest.raises(sources.SourceError, match="C identifier"):
        sources.sweep_scene(s, tmp_path / "out")
    assert not (tmp_path / "x_sweep").exists() and not list(tmp_path.parent.glob("x_sweep*"))
    with pytest.raises(StudyError, match="name"):
        study.run_study(_write(tmp_path, BALANCE_STUDY, "...toml"), tmp_path / "o", workers=0)
    assert not (tmp_path / "results.csv").exists()


# ---- untrusted study files: refused with their line, never a traceback -----------------------

HUGE = "1" + "0" * 400  # a TOML integer no float holds

DRIVEN_RUN = """[run]
kind = "driven"
step = 0.1
duration = 1.0
settle = 0.0
start_speed = 1.0
"""


@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ("high = 2.0", f"high = {HUGE}", "high =", "high must be a finite number"),
        ("at = [", f"at = [{HUGE}, ", "at = [", "at must be [x, y]"),
        ("at = [", "at = [2000.0, ", "at = [", "within +-1000"),
        ("high = 2.0", "high = 2e6", "high =", "above 1e+06 kg"),
        (
            "[[figure]]",
            '[[parameter]]\nname = "crank.length"\nlow = -1.7e308\nhigh = 1.7e308\n\n[[figure]]',
            "high = 1.7e308",
            "high - low is not a finite",
        ),
        ("speed = 100.0", "speed = 1979-05-27", "speed =", "speed must be a number"),
        ('minimize = "bearing_peak"', 'minimize = ["bearing_peak"]', "minimize", "must name"),
        ("best = 3", 'constraints = [{ figure = ["x"], max = 1 }]', "constraints", "constraint"),
        ("best = 3", "constraints = 5", "constraints", "constraints must be a list"),
        (
            "best = 3",
            f'constraints = [{{ figure = "torque_rms", max = {HUGE} }}]',
            "constraints",
            "max must be a finite number",
        ),
        ('name = "torque_rms"', 'name = "counterweight"', 'name = "counterweight"', "is taken"),
        ("[sampling]", "[drive]\ninertia = 1.0\n\n[sampling]", "[drive]", "kind = 'driven'"),
        ("[study]", "[study]\nfmi = 3", "fmi = 3", "an .fmu has its own"),
        ("[study]", "loads = 5\n\n[study]", "loads = 5", "loads must be a table"),
        (
            "[sampling]",
            '[loads."crank.torque"]\nangle = [0.0]\nvalue = [1e13]\n\n[sampling]',
            "[loads.",
            "a load beyond",
        ),
        ("[sampling]", "[fixed]\ncrank.mass = 1.0\n\n[sampling]", "crank.mass", "in quotes"),
        ("[sampling]", "[fixed.crank]\nmass = 1.0\n\n[sampling]", "[fixed.crank]", "in quotes"),
        (
            "[sampling]",
            '[fixed]\n"crank.mass" = 1.0\n\n[sampling]',
            '"crank.mass"',
            "crank.mass is set twice: by counterweight counterweight and by [fixed]",
        ),
        (
            "[[figure]]",
            '[[parameter]]\nname = "second"\ncounterweight = "crank"\nat = [0.0, 0.0]\n'
            "low = 0.0\nhigh = 1.0\n\n[[figure]]",
            'counterweight = "crank"',
            "crank.mass is set twice: by counterweight counterweight and by counterweight second",
        ),
        (
            "[[figure]]",
            '[[parameter]]\nname = "crank.com.x"\nlow = 0.0\nhigh = 1.0\n\n[[figure]]',
            'name = "crank.com.x"',
            "crank.com.x is set twice",
        ),
        (
            'method = "grid"\ncount = 13 ',
            'method = "random"\ncount = 1000000 ',
            "count = 1000000",
            "split the study",
        ),
    ],
)
def test_an_untrusted_study_is_refused_at_its_line_without_a_traceback(
    tmp_path, old, new, marker, words
):
    text = BALANCE_STUDY.replace(old, new, 1)
    if "split the study" in words:
        text = text.replace("points = 36", "points = 100000")
    assert text != BALANCE_STUDY
    line = max(k for k, t in enumerate(text.splitlines(), start=1) if marker in t)
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: "), message
    assert words in message


@pytest.mark.parametrize(
    "run, words",
    [
        ("settle = 0.0", None),
        ("settle = 0.2", "fewer than 10 communication points"),
        ("step = 1e-7", "1e+08"),
    ],
)
def test_a_driven_run_keeps_enough_points_and_bounded_work(tmp_path, run, words):
    key = run.split(" =")[0]
    driven = DRIVEN_RUN.replace(f"{key} = ", f"{run}\n#", 1)
    text = BALANCE_STUDY.replace(
        '[run]\nkind = "kinetostatic"\nspeed = 100.0\npoints = 36\n', driven
    )
    text = text.replace("count = 13 ", "count = 1001 ")
    if words is None:
        assert read_study(_write(tmp_path, text)).run.settle == 0.0
        return
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if t.startswith(key))
    line = (
        line
        if key == "settle"
        else next(k for k, t in enumerate(text.splitlines(), start=1) if t.startswith("count"))
    )
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: "), message
    assert words in message


def test_line_of_finds_dotted_keys_and_sub_tables():
    from dyadfmu.sweep.studyfile import line_of

    text = (
        "[study]\n"  # 1
        'scene = "x"\n'  # 2
        "[fixed]\n"  # 3
        "rocker.mass = 1\n"  # 4
        '"crank.mass" = 2\n'  # 5
        "[fixed.gravity]\n"  # 6
        "x = 1\n"  # 7
        '[loads."slider.force.x"]\n'  # 8
        "angle = [0.0]\n"  # 9
        "[[figure]]\n"  # 10
        'name = "a"\n'  # 11
        "[[figure]]   # the second\n"  # 12
        'name = "b"\n'  # 13
    )
    assert line_of(text, "fixed", key="rocker") == 4
    assert line_of(text, "fixed", key="crank.mass") == 5
    assert line_of(text, "fixed", key="gravity") == 6
    assert line_of(text, "loads", key="slider.force.x") == 8
    assert line_of(text, "loads") == 8
    assert line_of(text, "figure", 1, "name") == 13
    assert line_of(text, "", key="study") == 1
    assert line_of(text, "objective") == 1


def test_a_report_without_a_feasible_design_says_so(tmp_path):
    text = BALANCE_STUDY.replace("best = 3", 'constraints = [{ figure = "torque_rms", max = -1 }]')
    s = read_study(_write(tmp_path, text))
    table = results.Table(
        ["counterweight"], ["bearing_peak", "torque_rms"], np.zeros((1, 1)),
        np.ones((1, 2)), ["ok"], [""],
    )  # fmt: skip
    from dyadfmu.report.sweep import report_text

    assert "No design ran and met every constraint" in report_text(table, s, 1.0, "x")


def test_a_fluctuation_about_a_mean_that_is_not_positive_is_a_status_not_a_number():
    fluct = Figure("f", ("w",), "fluctuation")
    drop = Figure("d", ("w",), "drop")
    peak = Figure("p", ("w",), "peak")
    with pytest.raises(figures.UndefinedFigure, match="positive mean"):
        figures.figure_value(fluct, {"w": np.array([-1.0, 1.0, -0.5])}, None)
    with pytest.raises(figures.UndefinedFigure, match="maximum is positive"):
        figures.figure_value(drop, {"w": np.array([-1.0, -2.0])}, None)
    run = runs.KinetostaticRun("x.fmu", "crank", (), (), (), (), (fluct, peak))
    outcome = run.outcome({"w": np.array([-1.0, 1.0, -0.5])}, None)
    assert outcome.status == "undefined_figure" and "f: fluctuation" in outcome.message
    assert math.isnan(outcome.figures[0]) and outcome.figures[1] == 1.0


def test_a_broken_fmu_is_refused_naming_the_file(tmp_path):
    import zipfile

    junk = tmp_path / "junk.fmu"
    junk.write_bytes(b"not a zip")
    with pytest.raises(sources.SourceError, match="junk.fmu: not an FMU that can be read"):
        sources.model_description(junk)
    empty = tmp_path / "empty.fmu"
    with zipfile.ZipFile(empty, "w") as z:
        z.writestr("readme.txt", "no model description")
    with pytest.raises(sources.SourceError, match="empty.fmu: not an FMU that can be read"):
        sources.model_description(empty)
    _needs_balance()
    stripped = tmp_path / "stripped.fmu"
    with zipfile.ZipFile(BALANCE) as src, zipfile.ZipFile(stripped, "w") as dst:
        for item in src.infolist():
            if not item.filename.startswith("binaries/"):
                dst.writestr(item, src.read(item))
    with pytest.raises(sources.SourceError, match="no binary for this platform"):
        sources.model_description(stripped)
    assert sources.model_description(BALANCE).coSimulation is not None


def test_a_counterweight_on_a_link_whose_mass_is_not_a_real_start_value_is_refused(tmp_path):
    from dyadfmu.sweep.checks import base_values
    from fmpy.model_description import ModelDescription, ScalarVariable

    md = ModelDescription()
    for name, start in (("crank.mass", "true"), ("crank.com.x", "0"), ("crank.com.y", "0")):
        v = ScalarVariable(name=name, valueReference=len(md.modelVariables))
        v.causality, v.type, v.start = "parameter", "Real", start
        md.modelVariables.append(v)
    s = read_study(_write(tmp_path, BALANCE_STUDY))
    with pytest.raises(StudyError, match="no finite start value"):
        base_values(s, md)


def test_a_malformed_scene_is_refused_with_the_scene_checker_s_line(tmp_path):
    scene = (ROOT / "tests" / "scenes" / "balance.toml").read_text()
    text = BALANCE_STUDY.replace(f'fmu = "{BALANCE}"', 'scene = "bad.toml"')
    for bad, words in (
        (scene.replace("[effects]", "when = 1979-05-27\n\n[effects]"), "bad.toml:"),
        (scene.replace("[scene]", "scene = 5\n[scene]"), "bad.toml"),
        (scene.replace('tunable = ["crank", "rod.length"]', 'tunable = "crank"'), "bad.toml"),
        (scene + "\n[[[oops\n", "bad.toml"),
    ):
        (tmp_path / "bad.toml").write_text(bad)
        s = read_study(_write(tmp_path, text))
        with pytest.raises(sources.SourceError) as info:
            sources.sweep_scene(s, tmp_path / "out")
        assert str(info.value).startswith(str(tmp_path / "bad.toml")) and words in str(info.value)


def test_a_chunk_the_columns_or_rows_entry_refuses_runs_through_the_next(tmp_path, monkeypatch):
    """The columns entry first; where it refuses, the rows entry; where that refuses too,
    FMI: the same outcomes each way, to the last bit."""
    _needs_balance()
    s, run, values, _ = study.prepare(_write(tmp_path, BALANCE_STUDY), tmp_path)
    rows = list(enumerate(values[:3]))
    through_columns = run.chunk(rows)

    from dyadfmu.sweep import rows as rows_module

    used = []
    monkeypatch.setattr(rows_module.ColumnsEntry, "evaluate", lambda *a: used.append(1))
    assert run.chunk(rows) == through_columns and used  # refused: None

    def refuse(*args, **kwargs):
        raise RuntimeError("dyadfmu_evaluate_rows refused the call (status 3)")

    monkeypatch.setattr(rows_module.RowsEntry, "evaluate", refuse)
    assert run.chunk(rows) == through_columns


@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ('name = "counterweight"', 'name = "status"', 'name = "status"', "a column of the table"),
        ("count = 13 ", "count = 13\nseed = 4 ", "seed = 4", "seed belongs to random and lhs"),
        (
            '[run]\nkind = "kinetostatic"\nspeed = 100.0\npoints = 36\n',
            'run = { kind = "kinetostatic", speed = -1.0, points = 36 }\n',
            "run = {",
            "speed must be a positive",
        ),
        (
            '[run]\nkind = "kinetostatic"\nspeed = 100.0\npoints = 36\n',
            'run.kind = "kinetostatic"\nrun.speed = 100.0\nrun.points = 7\n',
            "run.points",
            "points must be an integer",
        ),
        (
            'description = "counterweight on a crank with its own unbalance"',
            'description = """\n[run]\nspeed = 1\n"""',
            "speed = 100.0",
            "speed must be a positive",
        ),
        ("speed = 100.0", "speed = 100.0 100", "speed = 100.0 100", "not valid TOML"),
    ],
)
def test_more_untrusted_studies_are_refused_at_their_line(tmp_path, old, new, marker, words):
    text = BALANCE_STUDY.replace(old, new, 1)
    if new.startswith("run"):  # a top-level key: before the first table
        text = new + BALANCE_STUDY.replace(old, "", 1)
    if '"""' in new:
        text = text.replace("speed = 100.0", "speed = -100.0")
    assert text != BALANCE_STUDY
    mark = marker.replace("speed = 100.0", "speed = -100.0") if '"""' in new else marker
    line = max(k for k, t in enumerate(text.splitlines(), start=1) if mark in t)
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: "), message
    assert words in message


def test_a_driven_duration_must_be_whole_steps_and_a_study_file_a_regular_file(tmp_path):
    driven = DRIVEN_RUN.replace("duration = 1.0", "duration = 1.05")
    text = BALANCE_STUDY.replace(
        '[run]\nkind = "kinetostatic"\nspeed = 100.0\npoints = 36\n', driven
    )
    assert "duration must be a whole number of steps" in _refused(tmp_path, text)
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    with pytest.raises(StudyError, match="not a study file"):
        read_study(fifo)


def _edited_fmu(tmp_path: Path, name: str, edit) -> Path:
    """A copy of the balance FMU with ``edit(member name, bytes) -> bytes`` applied."""
    import zipfile

    out = tmp_path / name
    with zipfile.ZipFile(BALANCE) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            dst.writestr(item, edit(item.filename, src.read(item)))
    return out


def test_a_binary_that_crashes_or_will_not_instantiate_is_refused(tmp_path, monkeypatch):
    _needs_balance()
    truncated = _edited_fmu(
        tmp_path, "trunc.fmu", lambda n, b: b[:5000] if n.endswith(".so") else b
    )
    scratch = tmp_path / "scratch"  # where the trial's process unpacks the FMU
    scratch.mkdir()
    monkeypatch.setenv("TMPDIR", str(scratch))
    monkeypatch.setattr(tempfile, "tempdir", None)
    with pytest.raises(sources.SourceError, match="does not load or instantiate"):
        sources.model_description(truncated)
    assert list(scratch.iterdir()) == []  # the crashed process's folder removed too
    other_guid = _edited_fmu(
        tmp_path,
        "guid.fmu",
        lambda n, b: (
            re.sub(rb'guid="\{[^}]*\}"', b'guid="{00000000-0000-0000-0000-000000000000}"', b)
            if n == "modelDescription.xml"
            else b
        ),
    )
    with pytest.raises(sources.SourceError, match="Failed to instantiate"):
        sources.model_description(other_guid)


def test_a_column_named_like_an_fmu_variable_or_an_alias_set_twice_is_refused(tmp_path):
    _needs_balance()
    text = BALANCE_STUDY.replace('name = "counterweight"', 'name = "rod.length"')
    with pytest.raises(StudyError, match="a counterweight's name cannot be a variable"):
        study.prepare(_write(tmp_path, text), tmp_path)

    def alias(name: str, data: bytes) -> bytes:
        if name != "modelDescription.xml":
            return data
        xml = data.decode()
        m = re.search(r'<ScalarVariable name="crank.mass".*?</ScalarVariable>', xml, re.S)
        return xml.replace(
            m.group(0), m.group(0) + m.group(0).replace("crank.mass", "ghost.mass"), 1
        ).encode()

    aliased = _edited_fmu(tmp_path, "alias.fmu", alias)
    text = BALANCE_STUDY.replace(str(BALANCE), str(aliased)) + '\n[fixed]\n"ghost.mass" = 50.0\n'
    with pytest.raises(StudyError, match="ghost.mass and crank.mass are one variable"):
        study.prepare(_write(tmp_path, text), tmp_path)


def test_a_long_scene_identifier_stays_within_forty_characters_in_the_copy(tmp_path):
    scene = (ROOT / "tests" / "scenes" / "balance.toml").read_text()
    long_id = "balance_with_a_long_identifier_x12345678"
    assert len(long_id) == 40
    (tmp_path / "long.toml").write_text(
        scene.replace('identifier = "balance"', f'identifier = "{long_id}"')
    )
    s = read_study(
        _write(tmp_path, BALANCE_STUDY.replace(f'fmu = "{BALANCE}"', 'scene = "long.toml"'))
    )
    copy = sources.sweep_scene(s, tmp_path / "out")
    identifier = tomllib.loads(copy.read_text())["scene"]["identifier"]
    assert len(identifier) == 40 and identifier.startswith(long_id[:23] + "_sweep_")


def test_a_name_the_scene_has_no_parameter_of_is_refused_at_the_study_s_line(tmp_path):
    scene = ROOT / "tests" / "scenes" / "balance.toml"
    text = BALANCE_STUDY.replace(f'fmu = "{BALANCE}"', f'scene = "{scene}"')
    text += '\n[fixed]\n"foo.bar" = 1.0\n'
    line = len(text.splitlines())
    with pytest.raises(StudyError) as info:
        study.prepare(_write(tmp_path, text), tmp_path)
    assert str(info.value).startswith(
        f"{tmp_path / 'study.toml'}:{line}: foo.bar is not a parameter"
    )


# ---- untrusted study files: nesting, byte order mark; names before the build ------------------


def test_a_deeply_nested_study_is_refused_at_its_line_not_with_a_recursion_error(tmp_path):
    text = BALANCE_STUDY + '\n[fixed]\n"crank.mass" = ' + "[" * 5000 + "]" * 5000 + "\n"
    line = len(text.splitlines())
    message = _refused(tmp_path, text)
    assert message == f"{tmp_path / 'study.toml'}:{line}: arrays or tables nested more than 32 deep"


def test_the_sweep_command_refuses_a_deeply_nested_study_without_a_traceback(tmp_path):
    path = _write(tmp_path, "[study]\nx = " + "[" * 5000 + "]" * 5000 + "\n")
    done = subprocess.run(
        [sys.executable, "-m", "dyadfmu", "sweep", str(path), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        cwd=ROOT / "scripts",
    )
    assert done.returncode != 0 and "Traceback" not in done.stderr, done.stderr
    assert f"{path}:2: arrays or tables nested more than 32 deep" in done.stderr


def test_a_study_with_a_byte_order_mark_is_read(tmp_path):
    path = tmp_path / "study.toml"
    path.write_bytes(b"\xef\xbb\xbf" + BALANCE_STUDY.encode())
    assert read_study(path).description == "counterweight on a crank with its own unbalance"


def test_a_misspelt_name_is_refused_before_the_scene_s_fmu_is_built(tmp_path, monkeypatch):
    """modelDescription/scenes/studies/README.md: every problem is refused before anything runs; the
    mechanism FMU's build (tens of seconds) is not started for a misspelt figure."""

    def no_build(*args, **kwargs):
        raise AssertionError("the mechanism FMU was built before the names were checked")

    monkeypatch.setattr(sources, "mechanism_fmu", no_build)
    scene = ROOT / "tests" / "scenes" / "balance.toml"
    text = BALANCE_STUDY.replace(f'fmu = "{BALANCE}"', f'scene = "{scene}"')
    text = text.replace('of = "crank.torque"', 'of = "crank.torqe"')
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if "crank.torqe" in t)
    with pytest.raises(StudyError) as info:
        study.prepare(_write(tmp_path, text), tmp_path)
    assert str(info.value).startswith(f"{tmp_path / 'study.toml'}:{line}: torque_rms: ")
    assert "crank.torqe is not a Real output or input of balance_sweep_" in str(info.value)


# ---- designs that are not ok: a failed sample, too few digits; min constraints; log axes ------

#: A study whose figure reads an input only: the crank's angle, which every sample has
#: whether or not the mechanism closes there. A rod of 2 cm cannot reach the piston's line
#: from a crank of 5 cm at most crank angles (status 4, cannot assemble).
INPUT_ONLY_STUDY = (
    BALANCE_STUDY.replace(
        '[[parameter]]\nname = "counterweight"\ncounterweight = "crank"\n'
        f"at = [{AT[0]}, {AT[1]}]\nlow = 0.0\nhigh = 2.0\n",
        '[[parameter]]\nname = "rod.length"\nlow = 0.02\nhigh = 0.2\n',
    )
    .replace("count = 13 ", "count = 3 ")
    .split("[[figure]]")[0]
    + '[[figure]]\nname = "angle_max"\nof = "crank.angle"\nstat = "max"\n\n'
    + '[objective]\nminimize = "angle_max"\n'
)


@pytest.mark.parametrize("use_rows", [True, False], ids=["rows", "fmi"])
def test_a_design_with_a_failed_sample_is_not_ok_even_where_its_figures_read_inputs(
    tmp_path, use_rows
):
    _needs_balance()
    from dataclasses import replace

    s, run, values, _ = study.prepare(_write(tmp_path, INPUT_ONLY_STUDY), tmp_path)
    assert values[:, 0].tolist() == pytest.approx([0.02, 0.11, 0.2])
    run = replace(run, use_rows=use_rows)
    table = results.table_of(s, values, run.chunk(list(enumerate(values))))
    assert table.status == ["cannot_assemble", "ok", "ok"], table.message
    assert "cannot assemble" in table.message[0]
    assert results.feasible(table, s).tolist() == [False, True, True]
    assert results.best_designs(table, s) in ([1, 2], [2, 1])


def test_a_sample_whose_status_is_not_0_fails_its_design_whatever_its_outputs(
    tmp_path, monkeypatch
):
    """The FMU may report a sample singular (status 1) with finite outputs, as it does near
    a toggle position: the design is not ok, and the message says where."""
    _needs_balance()
    from dataclasses import replace

    from dyadfmu.fmi.slave import Slave

    reported = Slave.get_status

    def singular_at_a_quarter_turn(self):
        angle = self.get("crank.angle") if "crank.angle" in self.names else 0.0
        return 1 if abs(angle - math.pi / 2) < 1e-12 else reported(self)

    s, run, values, _ = study.prepare(_write(tmp_path, BALANCE_STUDY), tmp_path)
    run = replace(run, use_rows=False)
    assert run(tuple(values[4])).status == "ok"
    monkeypatch.setattr(Slave, "get_status", singular_at_a_quarter_turn)
    outcome = run(tuple(values[4]))
    assert outcome.status == "singular" and all(map(math.isfinite, outcome.figures[:0]))
    assert "status 1 at crank angle 1.5708 rad" in outcome.message
    table = results.table_of(s, values, [(k, run(tuple(v))) for k, v in enumerate(values)])
    assert set(table.status) == {"singular"} and results.best_designs(table, s) == []


def test_the_digits_of_a_design_come_from_its_worst_amplification():
    from dyadfmu.sweep.runs import EPS, digits_of

    assert digits_of(1.0) == pytest.approx(-math.log10(EPS))  # 15.65: a double's digits
    assert digits_of(1e8) == pytest.approx(-math.log10(EPS) - 8)
    assert math.isnan(digits_of(math.nan)) and digits_of(math.inf) == -math.inf
    run = runs.KinetostaticRun(
        "x.fmu", "crank", (), (), (), (), (Figure("p", ("w",), "peak"),),
        amplifications=("a.amplification", "b.amplification"), min_digits=8.0,
    )  # fmt: skip
    calm = {
        "w": np.ones(3),
        "a.amplification": np.array([1.0, 2.0, 3.0]),
        "b.amplification": np.ones(3),
    }
    assert run.outcome(calm, None) == runs.Outcome((1.0,), "ok", "", digits_of(3.0))
    steep = dict(calm, **{"b.amplification": np.array([1.0, 1e9, 4.0])})
    outcome = run.outcome(steep, None)
    assert outcome.status == "inaccurate" and outcome.figures == (1.0,)
    assert outcome.digits == pytest.approx(digits_of(1e9))
    assert outcome.message.startswith("b.amplification 1e+09 at sample 1: eps x amplification")
    assert "6.7 digits, fewer than min_digits 8" in outcome.message
    unbounded = dict(calm, **{"a.amplification": np.array([1.0, np.nan, 1.0])})
    assert run.outcome(unbounded, None).status == "inaccurate"
    from dyadfmu.sweep.runs import amplification_outputs
    from fmpy.model_description import ModelDescription, ScalarVariable

    md = ModelDescription()
    for name in ("a.amplification", "b.amplification", "amplification", "a.conditioning"):
        v = ScalarVariable(name=name, valueReference=len(md.modelVariables))
        v.causality, v.type = "output", "Real"
        md.modelVariables.append(v)
    assert amplification_outputs(md) == ("amplification",)  # the mechanism's, where it has one
    md.modelVariables = md.modelVariables[:2] + md.modelVariables[3:]
    assert amplification_outputs(md) == ("a.amplification", "b.amplification")


#: The balance scene's rod close to upright at three quarters of a turn (the crank's pin 5 cm
#: below O, the guide 1 cm above it: a rod of 6 cm stands normal to the guide there, the
#: RRT's singular position, and a shorter one cannot reach), given mass so that the dyad
#: carries loads, against a rod of 18 cm.
NEAR_SINGULAR_STUDY = f"""
[study]
scene = "{ROOT / "tests" / "scenes" / "balance.toml"}"
min_digits = 13

[run]
kind = "kinetostatic"
speed = 100.0
points = 36

[sampling]
method = "grid"
count = 2

[[parameter]]
name = "rod.length"
low = 0.0601
high = 0.18

[fixed]
"rod.mass" = 0.5
"rod.com.x" = 0.02
"rod.inertia" = 1e-4

[[figure]]
name = "torque_peak"
of = "crank.torque"
stat = "peak"

[[figure]]
name = "amplification_max"
of = "amplification"          # the mechanism FMU's own: the bound of every output
stat = "max"

[objective]
minimize = "torque_peak"
"""


@pytest.mark.skipif(shutil.which("cmake") is None, reason="building a study's scene needs CMake")
def test_a_design_whose_amplification_leaves_too_few_digits_is_flagged(tmp_path):
    result = study.run_study(_write(tmp_path, NEAR_SINGULAR_STUDY), tmp_path / "out", workers=0)
    table, s = result.table, result.study
    assert s.min_digits == 13
    near, far = 0, 1
    amplification = table.column("amplification_max")
    assert table.digits.tolist() == [runs.digits_of(a) for a in amplification]
    # the worst sample is at three quarters of a turn, the rod close to upright: its
    # conditioning is the cosine of the rod's angle to the guide, and its amplification at
    # least data factor / conditioning with the data factor at least 1
    length = table.values[near, 0]
    conditioning = math.sqrt(length**2 - 0.06**2) / length
    assert conditioning < 0.1
    assert amplification[near] >= 0.999 / conditioning
    assert table.digits[near] < 13 <= table.digits[far]
    assert table.status == ["inaccurate", "ok"], table.message
    assert "fewer than min_digits 13" in table.message[near]
    assert math.isfinite(table.figures[near][0])  # its figures kept, shown as such
    assert result.best == [far]
    csv = (tmp_path / "out" / "study" / "results.csv").read_text().splitlines()
    assert csv[0].endswith(",digits,status,message") and ",inaccurate," in csv[1]
    report = (tmp_path / "out" / "study" / "report.md").read_text()
    assert "1 design with fewer than `min_digits` 13 is `inaccurate`, not ok." in report


@pytest.mark.skipif(shutil.which("cmake") is None, reason="building a study's scene needs CMake")
def test_a_design_at_its_toggle_is_singular_not_ok(tmp_path):
    """A rod 0.6 nm longer than upright at three quarters of a turn: its conditioning
    there, 1.4e-4, is far above the singular threshold, but the closure of its position,
    the gap under a square root, is 3.5e-9 of its terms: the mechanism FMU reports
    singular, so the design fails; the 18 cm rod is the best."""
    text = NEAR_SINGULAR_STUDY.replace("low = 0.0601", "low = 0.0600000006")
    result = study.run_study(_write(tmp_path, text), tmp_path / "out", workers=0)
    table = result.table
    assert table.status == ["singular", "ok"], table.message
    assert "near a dead centre or branch point" in table.message[0]
    assert not math.isfinite(table.figures[0][0])
    assert result.best == [1]


def _constraint_study(constraint: str) -> str:
    return BALANCE_STUDY.replace("best = 3", f"constraints = [{constraint}]\nbest = 13")


def test_a_min_constraint_excludes_the_designs_below_it(tmp_path):
    _needs_balance()
    text = _constraint_study('{ figure = "bearing_peak", min = 20.0 }')
    result = study.run_study(_write(tmp_path, text), tmp_path / "out", workers=0, plots=False)
    table, s = result.table, result.study
    peak = table.column("bearing_peak")
    assert set(table.status) == {"ok"} and peak.min() < 20.0 < peak.max()
    assert results.feasible(table, s).tolist() == (peak >= 20.0).tolist()
    assert result.best and all(peak[k] >= 20.0 for k in result.best)
    assert peak[result.best[0]] == min(peak[peak >= 20.0])
    report = (tmp_path / "out" / "study" / "report.md").read_text()
    assert "subject to bearing\\_peak >= 20:" in report
    both = _constraint_study('{ figure = "bearing_peak", min = 20.0, max = 60.0 }')
    s = read_study(_write(tmp_path, both))
    assert results.feasible(table, s).tolist() == ((peak >= 20) & (peak <= 60)).tolist()
    from dyadfmu.report.sweep import report_text

    assert "subject to 20 <= bearing\\_peak <= 60:" in report_text(table, s, 1.0, "x")


@pytest.mark.parametrize(
    "constraint, words",
    [
        ('{ figure = "torque_rms", min = nan }', "torque_rms: a constraint's min must be a finite"),
        ('{ figure = "torque_rms", min = 2.0, max = 1.0 }', "min 2 is above its max 1"),
        ('{ figure = "torque_rms" }', "a constraint is { figure = NAME, max = NUMBER }, {"),
        ('{ figure = "torque_rms", mn = 1.0 }', "or both bounds, with NAME one of"),
        ('{ figure = "torque", min = 1.0 }', "with NAME one of bearing_peak, torque_rms"),
    ],
)
def test_a_bad_min_constraint_is_refused_at_its_line(tmp_path, constraint, words):
    text = _constraint_study(constraint)
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if "constraints" in t)
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: ") and words in message


@pytest.mark.parametrize(
    "value, words", [("16", "min_digits must be from 0 to 15.65"), ("-1", "from 0")]
)
def test_a_bad_min_digits_is_refused_at_its_line(tmp_path, value, words):
    text = BALANCE_STUDY.replace("[study]", f"[study]\nmin_digits = {value}")
    assert words in _refused(tmp_path, text)
    assert read_study(_write(tmp_path, BALANCE_STUDY)).min_digits == 8.0


def _figure_of(monkeypatch, table, s) -> object:
    """The matplotlib figure plot_study draws (caught as it is saved)."""
    from dyadfmu.report import sweep as report
    from matplotlib.figure import Figure as MplFigure

    drawn = []
    monkeypatch.setattr(MplFigure, "savefig", lambda fig, *a, **k: drawn.append(fig))
    report.plot_study(table, s, Path("unused.png"))
    (fig,) = drawn
    return fig


def _table(values: np.ndarray, *figures: np.ndarray) -> results.Table:
    """Designs that all ran: one parameter (cw) or two (cw, rod.length), and the figures
    bearing_peak and torque_rms."""
    names = ["cw", "rod.length"][: values.shape[1]]
    n = len(values)
    return results.Table(names, ["bearing_peak", "torque_rms"], values,
                         np.column_stack(figures), ["ok"] * n, [""] * n)  # fmt: skip


def test_a_plotted_quantity_over_many_decades_gets_a_log_axis(tmp_path, monkeypatch):
    from matplotlib.colors import LogNorm, SymLogNorm

    s = read_study(_write(tmp_path, _constraint_study('{ figure = "torque_rms", max = 600.0 }')))
    x = np.linspace(0.0, 2.0, 10)[:, None]
    wide = np.logspace(-3, 6, 10)  # the objective over 1e-3 .. 1e6
    narrow = np.linspace(1.0, 500.0, 10)
    designs, pareto = _figure_of(monkeypatch, _table(x, wide, narrow), s).axes[:2]
    assert designs.get_yscale() == "log" and designs.get_xscale() == "linear"
    assert pareto.get_xscale() == "log" and pareto.get_yscale() == "linear"
    # signs mixed: symmetric log; a narrow range stays linear
    mixed = wide * np.where(np.arange(10) % 2, -1, 1)
    assert _figure_of(monkeypatch, _table(x, mixed, narrow), s).axes[0].get_yscale() == "symlog"
    assert _figure_of(monkeypatch, _table(x, narrow, narrow), s).axes[0].get_yscale() == "linear"
    # two parameters: the parameters' own axes, the objective's colour scale
    two = BALANCE_STUDY.replace(
        "[[figure]]",
        '[[parameter]]\nname = "rod.length"\nlow = 0.001\nhigh = 10.0\n\n[[figure]]',
        1,
    )
    s2 = read_study(_write(tmp_path, two, "two.toml"))
    grid = np.array([[a, b] for a in (0.0, 1.0, 2.0) for b in (0.001, 0.1, 10.0)])
    z = np.logspace(-3, 6, 9)
    heat = _figure_of(monkeypatch, _table(grid, z, z), s2).axes[0]
    assert heat.get_yscale() == "log" and heat.get_xscale() == "linear"
    (mesh,) = heat.collections
    assert isinstance(mesh.norm, LogNorm)
    scattered = grid + np.array([[0.01 * k, 0.0] for k in range(9)])  # not a grid: a scatter
    points = _figure_of(monkeypatch, _table(scattered, -z, z), s2).axes[0].collections[0]
    assert isinstance(points.norm, SymLogNorm)


def test_the_pareto_front_of_a_figure_bounded_from_below_keeps_the_highest():
    a = np.array([1.0, 2.0, 3.0, 2.5])
    b = np.array([5.0, 3.0, 9.0, 4.0])  # a transmission angle, say: the larger the better
    mask = np.ones(4, dtype=bool)
    assert results.pareto_front(a, b, mask) == [0, 1]
    assert results.pareto_front(a, b, mask, b_higher_is_better=True) == [0, 2]


# ---- an installed package runs nothing from beside its install location ---------------------


def test_an_installed_copy_never_takes_the_folders_around_it_for_a_checkout(tmp_path):
    """The package copied as pip installs it (site-packages/dyadfmu with its bundled core
    and sources), with a checkout's markers, a generator, a core and a build planted at the
    paths derived from that place (<prefix>/lib/python3.X/...): every place the package
    would run or load lies inside it."""
    prefix = tmp_path / "lib" / "python3.11"
    package = prefix / "site-packages" / "dyadfmu"
    shutil.copytree(
        ROOT / "scripts" / "dyadfmu", package, ignore=shutil.ignore_patterns("__pycache__")
    )
    (package / "_lib").mkdir()
    (package / "_lib" / "libdyadfmu.so").write_bytes(b"")
    (package / "_project" / "modelDescription").mkdir(parents=True)
    (prefix / "scripts").mkdir()
    (prefix / "scripts" / "pyproject.toml").write_text("")
    (prefix / "CMakeLists.txt").write_text("")
    (prefix / "modelDescription").mkdir()
    (prefix / "modelDescription" / "scene.py").write_text("raise SystemExit(3)\n")
    (prefix / "build").mkdir()
    (prefix / "build" / "libdyadfmu.so").write_bytes(b"")
    probe = (
        "import dyadfmu.paths as p, dyadfmu.core as c\n"
        f"assert p.__file__.startswith({str(package)!r})\n"
        "from dyadfmu.sweep import scenebuild as b\n"
        "print(p.in_checkout())\n"
        "print(*[p.GENERATOR, p.SCENES_DIR, p.project_dir(), b.generator(), "
        "b.build_folder(p.Path('out')).resolve(), p.build_dir().resolve(), "
        "*c.library_candidates()], sep='\\n')\n"
    )
    import sysconfig

    env = {k: v for k, v in os.environ.items() if not k.startswith("DYADFMU_")}
    # -S: no site hooks, so not the checkout's editable install; the copy first, then the
    # venv's packages (NumPy, fmpy)
    env["PYTHONPATH"] = os.pathsep.join([str(package.parent), sysconfig.get_paths()["purelib"]])
    done = subprocess.run(
        [sys.executable, "-S", "-c", probe], capture_output=True, text=True, cwd=tmp_path, env=env
    )
    assert done.returncode == 0, done.stderr
    installed, *places = done.stdout.split("\n")[:-1]
    assert installed == "False"
    beside = [p for p in places if prefix in Path(p).parents and package not in Path(p).parents]
    assert beside == [], places
    assert Path(places[3]) == package / "_project" / "modelDescription" / "scene.py"


def test_a_scene_study_without_cmake_or_a_compiler_is_refused_in_one_line(monkeypatch, tmp_path):
    from dyadfmu import build_scene
    from dyadfmu.sweep import scenebuild

    monkeypatch.setattr(build_scene.shutil, "which", lambda name: None)
    problem = scenebuild.tools_problem()
    assert problem.startswith(
        "building the study's mechanism FMU from its scene needs CMake (cmake), a C compiler "
        "(cc), not found here: install them"
    )
    assert "\n" not in problem and 'fmu = "....fmu"' in problem
    with pytest.raises(scenebuild.BuildError) as info:
        scenebuild.scene_fmu(tmp_path / "x.toml", "x_sweep_0123456789", 2, tmp_path)
    assert str(info.value) == problem


# ---- runs over a linear driver's stroke -----------------------------------------------------

CYLINDER_ARM = paths.build_dir() / "fmus" / "cylinder_arm_fmi2.fmu"
LIFT = paths.build_dir() / "fmus" / "lift_fmi2.fmu"

#: The arm of tests/scenes/cylinder_arm.toml (O = (0, 1), B at |OB| = 1.2166 m) with its
#: cylinder's frame pin A = (x, 0.2) moved out: the triangle closes for lengths from
#: ||OA| - |OB|| to |OA| + |OB|, 0.2166 m at x = 0.6, 0.3096 m at x = 1.3 and 0.9375 m at
#: x = 2.0, where the stroke's first lengths cannot reach. 25 instants put samples at a
#: quarter and at half of the run: the cycloid's largest acceleration and speed.
STROKE_STUDY = f"""
[study]
description = "the arm's cylinder pinned farther out on the frame"
fmu = "{CYLINDER_ARM}"

[run]
kind = "kinetostatic"
stroke = [0.6, 1.9]
duration = 2.0
points = 25

[sampling]
method = "grid"
count = 3

[[parameter]]
name = "hoist.base.x"
low = 0.6
high = 2.0

[loads]
"payload.force.y" = -4000.0

[[figure]]
name = "force_peak"
of = "hoist.force"
stat = "peak"

[[figure]]
name = "speed_max"
of = "hoist.velocity"
stat = "max"

[[figure]]
name = "acceleration_max"
of = "hoist.acceleration"
stat = "max"

[[figure]]
name = "length_min"
of = "hoist.length"
stat = "min"

[[figure]]
name = "length_max"
of = "hoist.length"
stat = "max"

[objective]
minimize = "force_peak"
"""


def _needs(fmu: Path) -> None:
    if not fmu.is_file():
        pytest.skip(f"{fmu} is not built")


@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ("stroke = [0.6, 1.9]", "stroke = [1.9, 0.6]", "stroke =", "stroke must rise"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6, nan]", "stroke =", "two finite numbers"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6, inf]", "stroke =", "two finite numbers"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6]", "stroke =", "stroke must be [low, high]"),
        ("stroke = [0.6, 1.9]", 'stroke = [0.6, "1.9"]', "stroke =", "must be [low, high]"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6, 2e4]", "stroke =", "within +-10000"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6, 0.6]", "stroke =", "stroke must rise"),
        ("stroke = [0.6, 1.9]", "angle = [0.0, 3.2]", "angle =", "less than pi"),
        ("stroke = [0.6, 1.9]", "angle = [0.5, 0.1]", "angle =", "angle must rise"),
        ("stroke = [0.6, 1.9]", "stroke = [0.6, 1.9]\nspeed = 3.0", "speed = 3.0", "one of speed"),
        ("stroke = [0.6, 1.9]", "", 'kind = "kinetostatic"', "one of speed"),
        ("duration = 2.0", "duration = 0.0", "duration =", "duration must be a positive"),
        ("duration = 2.0", "", "[run]", "duration must be a number"),
        ("points = 25", "points = 3", "points =", "points must be an integer"),
        (
            '"payload.force.y" = -4000.0',
            '"payload.force.y" = { angle = [0.0, 1.0], value = [1.0, 2.0] }',
            '"payload.force.y"',
            "a run over a stroke takes constant loads",
        ),
        ('stat = "peak"', 'stat = "work_per_revolution"', "work_per", "has no revolution"),
    ],
)
def test_a_bad_stroke_run_is_refused_at_its_line(tmp_path, old, new, marker, words):
    _needs(CYLINDER_ARM)
    text = STROKE_STUDY.replace(old, new, 1)
    assert text != STROKE_STUDY
    line = max(k for k, t in enumerate(text.splitlines(), start=1) if marker in t)
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: "), message
    assert words in message


def test_a_crank_s_run_takes_no_duration(tmp_path):
    text = BALANCE_STUDY.replace("speed = 100.0", "speed = 100.0\nduration = 1.0")
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if t.startswith("duration"))
    message = _refused(tmp_path, text)
    assert message.startswith(f"{tmp_path / 'study.toml'}:{line}: duration belongs to a run")


@pytest.mark.parametrize(
    "fmu, old, new, marker, words",
    [
        (
            CYLINDER_ARM,
            "stroke = [0.6, 1.9]\nduration = 2.0\n",
            "speed = 10.0\n",
            "speed =",
            "speed turns a crank (a revolution); cylinder_arm_fmi2.fmu is driven by the "
            "cylinder hoist: give kind = 'kinetostatic', stroke = [low, high] (m, its length",
        ),
        (
            CYLINDER_ARM,
            "stroke = [0.6, 1.9]",
            "angle = [0.0, 1.0]",
            "angle =",
            "angle needs the geometry of cylinder hoist among the parameters",
        ),
        (
            CYLINDER_ARM,
            "stroke = [0.6, 1.9]",
            "stroke = [0.0, 1.9]",
            "stroke =",
            "a cylinder's length is positive: stroke from 0 m",
        ),
        (
            CYLINDER_ARM,
            '[run]\nkind = "kinetostatic"\nstroke = [0.6, 1.9]\nduration = 2.0\npoints = 25\n',
            DRIVEN_RUN,
            'kind = "driven"',
            "kind turns a crank (by the drive FMU); cylinder_arm_fmi2.fmu is driven by the "
            "cylinder hoist",
        ),
        (
            LIFT,
            "stroke = [0.6, 1.9]",
            "angle = [0.0, 1.0]",
            "angle =",
            "angle turns a cylinder's link; lift_fmi2.fmu is driven by the ram ram: give "
            "stroke = [low, high] (m, its position)",
        ),
        (
            BALANCE,
            "stroke = [0.6, 1.9]",
            "stroke = [0.0, 0.1]",
            "stroke =",
            "stroke moves a ram or a cylinder over its stroke; balance_fmi2.fmu is driven by "
            "the crank crank: give speed (rad/s, one revolution)",
        ),
        (
            CYLINDER_ARM,
            '"payload.force.y" = -4000.0',
            '"hoist.velocity" = 1.0',
            '"hoist.velocity" = 1.0',
            "hoist.velocity is not a load input of cylinder_arm_fmi2.fmu",
        ),
    ],
    ids=["speed-on-cylinder", "angle-without-geometry", "stroke-from-0", "driven-on-cylinder",
         "angle-on-ram", "stroke-on-crank", "driver-input-as-load"],
)  # fmt: skip
def test_a_run_its_driver_cannot_do_is_refused_at_its_line(tmp_path, fmu, old, new, marker, words):
    _needs(fmu)
    # the driver is checked first: the names of the cylinder study do not matter here
    text = STROKE_STUDY.replace(old, new, 1).replace(str(CYLINDER_ARM), str(fmu))
    assert text != STROKE_STUDY
    line = max(k for k, t in enumerate(text.splitlines(), start=1) if marker in t)
    with pytest.raises(StudyError) as info:
        study.prepare(_write(tmp_path, text), tmp_path)
    assert str(info.value).startswith(f"{tmp_path / 'study.toml'}:{line}: "), str(info.value)
    assert words in str(info.value)


@pytest.mark.parametrize("use_rows", [True, False], ids=["rows", "fmi"])
def test_a_stroke_that_the_triangle_cannot_close_over_fails_its_design(tmp_path, use_rows):
    """The cylinder's pin at x = 2 m cannot reach the stroke's first lengths: that design is
    cannot_assemble with the FMU's gap and the length where it failed; the others run the
    cycloid: rest at both ends, 1.3 m/s at half way, 2 pi 1.3 / 2^2 m/s2 at a quarter."""
    _needs(CYLINDER_ARM)
    from dataclasses import replace

    s, run, values, _ = study.prepare(_write(tmp_path, STROKE_STUDY), tmp_path)
    assert isinstance(run, runs.StrokeRun) and run.inputs()[:3] == (
        "hoist.length", "hoist.velocity", "hoist.acceleration",
    )  # fmt: skip
    run = replace(run, use_rows=use_rows)
    table = results.table_of(s, values, run.chunk(list(enumerate(values))))
    assert table.status == ["ok", "ok", "cannot_assemble"], table.message
    assert "cylinder hoist cannot assemble" in table.message[2]
    assert "|O A| > |O B| + s by 0.3375" in table.message[2]  # 2.1541 - 1.2166 - 0.6
    assert "at sample 0: hoist.length 0.6" in table.message[2]
    for k in (0, 1):
        assert table.column("length_min")[k] == 0.6 and table.column("length_max")[k] == 1.9
        assert table.column("speed_max")[k] == pytest.approx(1.3, rel=1e-15)
        assert table.column("acceleration_max")[k] == pytest.approx(
            2 * math.pi * 1.3 / 4, rel=1e-15
        )
    assert results.best_designs(table, s)[0] in (0, 1)
    other = results.table_of(
        s, values, replace(run, use_rows=not use_rows).chunk(list(enumerate(values)))
    )
    assert np.array_equal(other.figures, table.figures, equal_nan=True)
    assert other.message == table.message


def test_a_ram_s_stroke_run_gives_the_force_the_fmu_gives_at_each_position(tmp_path):
    """The lift's ram over 0.1 to 0.4 m in 1.5 s: the sweep's peak force against the FMU
    stepped through the same motion, computed here from the cycloid's definition."""
    _needs(LIFT)
    text = (
        STROKE_STUDY.replace(str(CYLINDER_ARM), str(LIFT))
        .replace("stroke = [0.6, 1.9]", "stroke = [0.1, 0.4]")
        .replace("duration = 2.0", "duration = 1.5")
        .replace('name = "hoist.base.x"', 'name = "gravity.y"')
        .replace("low = 0.6\nhigh = 2.0", "low = -9.81\nhigh = 0.0")
        .replace('"payload.force.y" = -4000.0', '"platform.force.y" = -2000.0')
        .replace("hoist.", "ram.")
        .replace('"ram.length"', '"ram.position"')
    )  # fmt: skip
    s, run, values, _ = study.prepare(_write(tmp_path, text), tmp_path)
    table = results.table_of(s, values, run.chunk(list(enumerate(values))))
    assert table.status == ["ok"] * 3, table.message
    from dyadfmu.fmi.slave import Slave

    lift = Slave(LIFT)
    tau = np.arange(25) / 24
    q = 0.1 + 0.3 * (tau - np.sin(2 * math.pi * tau) / (2 * math.pi))
    v = 0.3 / 1.5 * (1 - np.cos(2 * math.pi * tau))
    a = 2 * math.pi * 0.3 / 1.5**2 * np.sin(2 * math.pi * tau)
    for k, (g,) in enumerate(values):
        lift.reset()
        lift.initialize({"gravity.y": g})
        force = []
        for j in range(25):
            lift.set(("ram.position", "ram.velocity", "ram.acceleration", "platform.force.y"),
                     (q[j], v[j], a[j], -2000.0))  # fmt: skip
            lift.do_step(j * 1.5 / 24, 1.5 / 24)
            force.append(lift.get("ram.force"))
        assert table.column("force_peak")[k] == pytest.approx(np.max(np.abs(force)), rel=1e-12)
    lift.close()


def test_the_cycloid_rises_rest_to_rest_and_its_rates_are_its_derivatives():
    q, v, a = stroke.cycloid(0.5, 2.0, 3.0, 3001)
    assert (q[0], q[-1], v[0], a[0]) == (0.5, 2.0, 0.0, 0.0)
    assert abs(v[-1]) < 1e-15 and abs(a[-1]) < 1e-14
    assert np.all(np.diff(q) > 0)
    # central differences over dt = 1 ms: second order, within 1e-5 of the rates here
    assert np.max(np.abs((q[2:] - q[:-2]) / 2e-3 - v[1:-1])) < 1e-5
    assert np.max(np.abs((v[2:] - v[:-2]) / 2e-3 - a[1:-1])) < 1e-5
    assert np.max(v) == pytest.approx(2 * 1.5 / 3.0, rel=1e-12)


def test_a_cylinder_s_length_and_rates_follow_its_pins():
    """s, s' and s'' against the pins themselves: B from the link's angle, s = |B - A|,
    s' = u . v_B and s'' = u . a_B + (|v_B|^2 - s'^2) / s with u = (B - A) / s, v_B and a_B
    the velocity and acceleration of B turning about O."""
    o, a, pin = (0.3, -0.2), (2.0, 0.5), (1.1, -0.4)
    cylinder = stroke.Cylinder("c", "l", o, a, pin, 1.0)
    theta = np.linspace(-0.3, 1.2, 7)
    omega, epsilon = np.linspace(0.5, -0.7, 7), np.linspace(-2.0, 3.0, 7)
    s, rate, acceleration = cylinder.lengths(theta, omega, epsilon)
    r = np.stack([np.cos(theta) * pin[0] - np.sin(theta) * pin[1],
                  np.sin(theta) * pin[0] + np.cos(theta) * pin[1]], axis=1)  # fmt: skip
    d = np.array(o) + r - np.array(a)
    length = np.hypot(d[:, 0], d[:, 1])
    u = d / length[:, None]
    across = np.stack([-r[:, 1], r[:, 0]], axis=1)  # k x r
    v_b = omega[:, None] * across
    a_b = epsilon[:, None] * across - (omega**2)[:, None] * r
    s_rate = np.sum(u * v_b, axis=1)
    s_acc = np.sum(u * a_b, axis=1) + (np.sum(v_b * v_b, axis=1) - s_rate**2) / length
    np.testing.assert_allclose(s, length, rtol=1e-14)
    np.testing.assert_allclose(rate, s_rate, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(acceleration, s_acc, rtol=1e-12, atol=1e-14)


def test_a_cylinder_run_through_its_toggle_or_on_its_other_branch_cannot_be_run():
    # O at the origin, A on +x, B on the link's i: in line with O and A at angle 0 and pi,
    # to the left of O -> A (branch +1) between them
    left = stroke.Cylinder("c", "l", (0.0, 0.0), (2.0, 0.0), (1.0, 0.0), 1.0)
    left.check(0.1, 3.0)
    for low, high, at in [(-0.1, 0.5, "l.angle 0 rad"), (0.5, math.pi, "l.angle 3.14159 rad")]:
        with pytest.raises(stroke.Unreachable) as info:
            left.check(low, high)  # the end of the range at the toggle counts
        assert info.value.status == "singular"
        assert f"passes its toggle (O, A and B in line) at {at}" in str(info.value)
    with pytest.raises(stroke.Unreachable) as info:
        left.check(-1.0, -0.1)
    assert info.value.status == "cannot_assemble"
    assert "B is to the right of the line O -> A, the branch -1, not the cylinder's +1" in str(
        info.value
    )
    # the FMU's reading of a branch: below 0 is -1, anything else +1
    stroke.Cylinder("c", "l", (0.0, 0.0), (2.0, 0.0), (1.0, 0.0), -1e-300).check(-1.0, -0.1)
    stroke.Cylinder("c", "l", (0.0, 0.0), (2.0, 0.0), (1.0, 0.0), 0.0).check(0.1, 1.0)
    # any geometry: at the angle reported, O, A and B are in line
    tilted = stroke.Cylinder("c", "l", (0.3, 1.7), (5.3, 0.9), (4.3, -0.7), 1.0)
    with pytest.raises(stroke.Unreachable) as info:
        tilted.check(0.0, 0.8)
    at = float(re.search(r"at l.angle ([-0-9.e]+) rad", str(info.value)).group(1))
    b = (
        0.3 + math.cos(at) * 4.3 + math.sin(at) * 0.7,
        1.7 + math.sin(at) * 4.3 - math.cos(at) * 0.7,
    )
    cross = (5.3 - 0.3) * (b[1] - 1.7) - (0.9 - 1.7) * (b[0] - 0.3)
    assert abs(cross) < 1e-5 * 5.1 * 4.36  # |OA| |OB| sin(angle), to the 6 digits shown
    with pytest.raises(stroke.Unreachable) as info:
        stroke.Cylinder("c", "l", (1.0, 1.0), (1.0, 1.0), (1.0, 0.0), 1.0).check(0.0, 1.0)
    assert info.value.status == "invalid_input"


#: The arm's cylinder turning the arm from -0.25 to 1.8 rad, its bracket B at 1.2 m along
#: the arm and y below or above it: O, A and B fall in line at arm.angle 2.379 rad for
#: y = -0.2, 2.049 for y = 0.2 and 1.750 for y = 0.6, within the run.
ARM_ANGLE_STUDY = f"""
[study]
scene = "{ROOT / "tests" / "scenes" / "cylinder_arm.toml"}"

[run]
kind = "kinetostatic"
angle = [-0.25, 1.8]
duration = 3.0
points = 41

[sampling]
method = "grid"
count = 3

[[parameter]]
name = "hoist.pin.y"
low = -0.2
high = 0.6

[loads]
"payload.force.y" = -4000.0

[[figure]]
name = "force_peak"
of = "hoist.force"
stat = "peak"

[[figure]]
name = "arm_omega_max"
of = "arm.omega"
stat = "max"

[[figure]]
name = "arm_epsilon_max"
of = "arm.epsilon"
stat = "max"

[objective]
minimize = "force_peak"
"""


@pytest.mark.skipif(shutil.which("cmake") is None, reason="building a study's scene needs CMake")
def test_an_angle_run_turns_the_link_as_asked_and_refuses_a_design_through_its_toggle(
    tmp_path, monkeypatch
):
    """Over the arm's angle, each design's cylinder lengths from its own pins: the FMU's arm
    turns at the cycloid's rates (2 x 2.05 / 3 rad/s at half way, 2 pi 2.05 / 3^2 rad/s2 at
    a quarter); the design whose triangle passes its toggle within the run is singular,
    before any sample; with the checks of the branch taken away, a design on the other
    branch is caught by the angle the FMU reports."""
    from dataclasses import replace

    s, run, values, _ = study.prepare(_write(tmp_path, ARM_ANGLE_STUDY), tmp_path)
    assert run.link == "arm" and run.inputs()[0] == "hoist.length"
    for use_rows in (True, False):
        table = results.table_of(
            s, values, replace(run, use_rows=use_rows).chunk(list(enumerate(values)))
        )
        assert table.status == ["ok", "ok", "singular"], table.message
        assert "passes its toggle (O, A and B in line) at arm.angle 1.75" in table.message[2]
        omega, epsilon = table.column("arm_omega_max"), table.column("arm_epsilon_max")
        assert omega[:2] == pytest.approx([2 * 2.05 / 3] * 2, rel=1e-12)
        assert epsilon[:2] == pytest.approx([2 * math.pi * 2.05 / 9] * 2, rel=1e-9)
    unchecked = replace(run, fixed=(("hoist.branch", -1.0),))
    assert unchecked(tuple(values[0])).status == "cannot_assemble"
    monkeypatch.setattr(stroke.Cylinder, "check", lambda self, low, high: None)
    outcome = unchecked(tuple(values[0]))
    assert outcome.status == "wrong_angle" and "the FMU puts arm at" in outcome.message
    assert "not the run's -0.25 rad (sample 0)" in outcome.message


def _model(inputs: tuple, outputs: tuple, parameters: tuple = ()):
    from fmpy.model_description import ModelDescription, ScalarVariable

    md = ModelDescription()
    for causality, names in (("input", inputs), ("output", outputs), ("parameter", parameters)):
        for name in names:
            v = ScalarVariable(name=name, valueReference=len(md.modelVariables))
            v.causality, v.type = causality, "Real"
            md.modelVariables.append(v)
    return md


def test_the_driver_of_a_mechanism_fmu_is_found_by_its_inputs_and_effort():
    """A crank needs its rates; a ram or a cylinder without inertia takes its coordinate
    alone, and a stroke run sets that alone; a cylinder's geometry is known where the FMU
    has all of it as parameters."""
    from dyadfmu.sweep.checks import driver_of

    assert driver_of(_model(("crank.angle",), ("crank.torque",))) is None
    crank = driver_of(_model(("c.angle", "c.omega", "c.epsilon", "f.force.x"), ("c.torque",)))
    assert (crank.kind, crank.motion, crank.effort) == (
        "crank", ("c.angle", "c.omega", "c.epsilon"), "c.torque",
    )  # fmt: skip
    ram = driver_of(_model(("r.position", "r.velocity", "r.acceleration"), ("r.force",)))
    assert (ram.kind, ram.motion) == ("ram", ("r.position", "r.velocity", "r.acceleration"))
    geometry = ("arm.at.x", "arm.at.y", "h.base.x", "h.base.y", "h.pin.x", "h.pin.y", "h.branch")
    still = driver_of(_model(("h.length", "p.force.y"), ("h.force", "arm.angle"), geometry))
    assert (still.kind, still.motion, still.link, still.geometry) == (
        "cylinder", ("h.length",), "arm", geometry,
    )  # fmt: skip
    assert driver_of(_model(("h.length",), ("h.force", "arm.angle"), geometry[:-1])).geometry == ()
    assert driver_of(_model(("h.length",), ("h.angle",))) is None  # no force: no driver
    run = runs.StrokeRun(
        "x.fmu", "h", (), (), (), (LoadTable("p.force.y", (0.0,), (-5.0,)),), (),
        motion=still.motion, effort=still.effort, points=9, low=1.0, high=2.0, duration=4.0,
    )  # fmt: skip
    x = run.samples({})
    assert run.inputs() == ("h.length", "p.force.y") and x.shape == (9, 2)
    assert x[:, 0].tolist() == pytest.approx(stroke.cycloid(1.0, 2.0, 4.0, 9)[0].tolist())
    assert set(x[:, 1]) == {-5.0}


def test_every_driver_of_a_mechanism_fmu_is_found():
    """A scene with several drivers: each, cranks, rams, cylinders, by its own inputs
    and effort."""
    from dyadfmu.sweep.checks import drivers_of

    inputs = ("w.angle", "w.omega", "w.epsilon", "s.position", "s.velocity", "s.acceleration")
    inputs += ("j.length", "j.velocity", "j.acceleration", "t.moment")
    found = drivers_of(_model(inputs, ("w.torque", "j.force", "s.force", "arm.angle")))
    assert [(d.kind, d.name, d.effort) for d in found] == [
        ("crank", "w", "w.torque"), ("ram", "s", "s.force"), ("cylinder", "j", "j.force"),
    ]  # fmt: skip


LEG = paths.build_dir() / "fmus" / "leg_fmi2.fmu"


def test_a_one_driver_run_of_a_mechanism_fmu_with_several_drivers_is_refused_naming_them(
    tmp_path,
):
    """A [run] over one driver would leave the others at their start values: the leg's FMU
    (two hip cranks) is refused at the run's speed, naming both drivers and the way out."""
    _needs(LEG)
    text = BALANCE_STUDY.replace(str(BALANCE), str(LEG))
    line = next(k for k, t in enumerate(text.splitlines(), start=1) if t.startswith("speed ="))
    with pytest.raises(StudyError) as info:
        study.prepare(_write(tmp_path, text), tmp_path)
    assert str(info.value) == (
        f"{tmp_path / 'study.toml'}:{line}: leg_fmi2.fmu has 2 drivers (the crank front, the "
        "crank rear): a run over one driver would leave the others at their start values; "
        "give each driver its range in a [[run.driver]] table (name, and angle or stroke)"
    )


def test_a_small_crank_study_runs_in_this_process_without_a_worker_count(tmp_path, monkeypatch):
    """No cluster for a study whose runs evaluate in calls of the binary and take less
    than a cluster takes to start; the same table as with --workers 0."""
    _needs_balance()

    def no_cluster(*args, **kwargs):
        raise AssertionError("a local cluster was started for a small study")

    monkeypatch.setattr(execute, "run_dask", no_cluster)
    chosen = study.run_study(_write(tmp_path, BALANCE_STUDY), tmp_path / "a", plots=False)
    serial = study.run_study(_write(tmp_path, BALANCE_STUDY), tmp_path / "b", workers=0)
    assert np.array_equal(chosen.table.figures, serial.table.figures)
    assert "this process" in (tmp_path / "a" / "study" / "report.md").read_text(encoding="utf-8")


def test_the_worker_count_is_the_user_s_or_chosen_by_the_study_s_size():
    crank = runs.KinetostaticRun.__new__(runs.KinetostaticRun)
    object.__setattr__(crank, "points", 360)
    object.__setattr__(crank, "use_rows", True)
    assert study.workers_for(crank, 61, None) == 0
    assert study.workers_for(crank, study.IN_PROCESS_SAMPLES // 360 + 1, None) == 2
    assert study.workers_for(crank, 61, 3) == 3 and study.workers_for(crank, 10**6, 0) == 0
    object.__setattr__(crank, "use_rows", False)  # through FMI, design by design
    assert study.workers_for(crank, 61, None) == 2
    assert study.workers_for(object(), 1, None) == 2  # a driven run co-simulates


def test_a_study_s_scene_fmu_is_built_again_where_it_is_older_than_the_sources(
    tmp_path, monkeypatch
):
    """Named by its scene's content, the FMU is still built by the project's sources: one
    older than any of them (an update of the core or the FMU layer) is built again."""
    from dyadfmu.sweep import scenebuild

    project, out = tmp_path / "project", tmp_path / "out"
    for folder in scenebuild.BUILT_FROM:
        (project / folder).mkdir(parents=True)
        (project / folder / "source.c").write_text("/* */\n")
    scene = tmp_path / "scene.toml"
    scene.write_text("# a scene\n")
    monkeypatch.setattr(scenebuild.paths, "project_dir", lambda: project)
    monkeypatch.setattr(scenebuild.paths, "in_checkout", lambda: False)  # built under out
    fmu = scenebuild.build_folder(out) / "fmus" / "s_fmi2.fmu"
    assert fmu.is_relative_to(out)
    fmu.parent.mkdir(parents=True)
    fmu.write_bytes(b"built")
    built = []
    monkeypatch.setattr(scenebuild, "tools_problem", lambda: None)
    monkeypatch.setattr(scenebuild, "configure", lambda *a, **k: None)
    monkeypatch.setattr(
        scenebuild, "build_logged", lambda build, targets, **k: built.append(targets)
    )
    os.utime(fmu, (2e9, 2e9))  # newer than every source: taken as it is
    assert scenebuild.scene_fmu(scene, "s", 2, out) == fmu and built == []
    os.utime(fmu, (1e9, 1e9))  # older than the sources: built again
    assert scenebuild.scene_fmu(scene, "s", 2, out) == fmu and built == [["s_fmi2_package"]]

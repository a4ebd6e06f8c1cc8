"""Design studies over mechanisms with several drivers ([[run.driver]]): the study file
refused at its line where a driver's range is wrong, the run refused where it does not fit
the FMU's drivers, and the excavator's three cylinders moved at once: each design's
cylinder lengths and rates, set into the FMU, put the boom, the stick (relative to the
boom) and the rocker (relative to the stick) at the commanded angles, rates and
accelerations, read back from the FMU's own outputs; a design whose carried cylinder
passes its toggle, or sits on its other branch, is a row with its status."""

from __future__ import annotations

import math
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave
from dyadfmu.sweep import results, runs, stroke, study
from dyadfmu.sweep.studyfile import MultiStroke, StudyError, read_study

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "modelDescription" / "scenes"
FMUS = paths.build_dir() / "fmus"

needs_cmake = pytest.mark.skipif(
    shutil.which("cmake") is None, reason="building a study's scene needs CMake"
)

#: The excavator's three cylinders over a digging pass (the example study's motion and
#: its varied parameters, so that both share one build of the scene's copy).
EXCAVATOR_STUDY = f"""
[study]
scene = "{SCENES / "excavator.toml"}"
min_digits = 7.0

[run]
kind = "kinetostatic"
duration = 6.0
points = 25

[[run.driver]]
name = "boom_cyl"
angle = [-0.2, 0.45]

[[run.driver]]
name = "stick_cyl"
angle = [-1.0, -2.0]

[[run.driver]]
name = "bucket_cyl"
angle = [2.2, 0.8]

[sampling]
method = "grid"
count = 2

[[parameter]]
name = "boom_cyl.base.x"
low = 1.2
high = 1.5

[[parameter]]
name = "boom_cyl.base.y"
low = 0.6
high = 0.7

[[parameter]]
name = "boom_cyl.pin.x"
low = 2.35
high = 2.55

[[parameter]]
name = "boom_cyl.pin.y"
low = 0.65
high = 0.75

[loads]
"dig.force.x" = 98480.0
"dig.force.y" = -17360.0

[[figure]]
name = "boom_force_peak"
of = "boom_cyl.force"
stat = "peak"

[[figure]]
name = "bucket_force_peak"
of = "bucket_cyl.force"
stat = "peak"

[objective]
minimize = "boom_force_peak"
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(text)
    return path


def _line(text: str, marker: str) -> int:
    return max(k for k, t in enumerate(text.splitlines(), start=1) if marker in t)


def _refused_at(tmp_path: Path, text: str, marker: str, words: str, prepare: bool) -> None:
    """The study ``text`` is refused at the last line holding ``marker``, saying ``words``
    (read only, or checked against its FMU where ``prepare``)."""
    path = _write(tmp_path, text)
    with pytest.raises(StudyError) as info:
        study.prepare(path, tmp_path) if prepare else read_study(path)
    message = str(info.value)
    assert message.startswith(f"{path}:{_line(text, marker)}: "), message
    assert words in message, message


def test_a_run_over_several_drivers_is_read_driver_by_driver():
    """Each [[run.driver]] its own range, in the file's order, either way."""
    s = read_study(SCENES / "studies" / "excavator_pins.toml")
    assert isinstance(s.run, MultiStroke) and (s.run.duration, s.run.points) == (6.0, 61)
    assert [(d.name, d.over, d.start, d.end) for d in s.run.drivers] == [
        ("boom_cyl", "angle", -0.2, 0.45),
        ("stick_cyl", "angle", -1.0, -2.0),
        ("bucket_cyl", "angle", 2.2, 0.8),
    ]


@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ("angle = [2.2, 0.8]", "angle = [2.2, 0.8]\nstroke = [2.0, 2.5]", "stroke =",
         "driver bucket_cyl: give one of angle = [low, high]"),
        ("angle = [2.2, 0.8]", "", 'name = "bucket_cyl"', "driver bucket_cyl: give one of"),
        ('name = "bucket_cyl"', 'name = "stick_cyl"', 'name = "stick_cyl"',
         "driver stick_cyl is given twice"),
        ("angle = [2.2, 0.8]", "angle = [2.2, 0.8]\nspeed = 1.0", "speed =",
         "unknown key 'speed'; expected name, angle, stroke"),
        ("angle = [2.2, 0.8]", "angle = [2.2, nan]", "angle = [2.2", "two finite numbers"),
        ("angle = [2.2, 0.8]", "angle = [2.2, 200.0]", "angle = [2.2", "within +-100"),
        ("angle = [2.2, 0.8]", "angle = [2.2]", "angle = [2.2", "angle must be [low, high]"),
        ("points = 25", "points = 25\nangle = [0.0, 1.0]", "angle = [0.0",
         "angle moves a mechanism's only driver; with [[run.driver]] tables"),
        ('kind = "kinetostatic"', 'kind = "driven"', 'kind = "driven"',
         "[[run.driver]] moves drivers over given ranges: it needs kind = 'kinetostatic'"),
        ('"dig.force.y" = -17360.0', '"dig.force.y" = { angle = [0.0], value = [1.0] }',
         '"dig.force.y"', "a run over a stroke takes constant loads"),
        ('stat = "peak"', 'stat = "work_per_revolution"', "work_per", "has no revolution"),
        ('method = "grid"\ncount = 2', 'method = "random"\ncount = 1000000', "count =",
         "1000000 designs make 1e+11 driver positions in all, over the limit"),
    ],
    ids=["angle-and-stroke", "neither", "twice", "unknown-key", "nan", "beyond-100",
         "one-number", "run-angle-too", "driven", "load-table", "work-per-revolution", "work"],
)  # fmt: skip
def test_a_bad_driver_range_is_refused_at_its_line(tmp_path, old, new, marker, words):
    text = EXCAVATOR_STUDY.replace(old, new, 1)
    assert text != EXCAVATOR_STUDY
    if "1000000" in new:  # and 1e5 instants each: 1e11 driver positions
        text = text.replace("points = 25", "points = 100000")
    _refused_at(tmp_path, text, marker, words, prepare=False)


LIFT = FMUS / "lift_fmi2.fmu"
LEG = FMUS / "leg_fmi2.fmu"
EXCAVATOR = FMUS / "excavator_fmi2.fmu"


def _needs(fmu: Path) -> None:
    if not fmu.is_file():
        pytest.skip(f"{fmu} is not built")


@needs_cmake
@pytest.mark.parametrize(
    "old, new, marker, words",
    [
        ('name = "bucket_cyl"', 'name = "bucket"', 'name = "bucket"',
         "bucket is no driver of excavator_sweep_"),
        ('[[run.driver]]\nname = "bucket_cyl"\nangle = [2.2, 0.8]\n', "", "[run]",
         "the run moves no range of the cylinder bucket_cyl of excavator_sweep_"),
        ("angle = [2.2, 0.8]", "stroke = [0.0, 2.5]", "stroke =",
         "a cylinder's length is positive: stroke = [0, 2.5] m; bucket_cyl is a cylinder"),
        ("angle = [2.2, 0.8]", "angle = [3.2, 0.0]", "angle = [3.2",
         "cylinder bucket_cyl: angle spans 3.2 rad: a cylinder turns its link relative to "
         "stick by less than pi"),
    ],
    ids=["no-such-driver", "driver-left-out", "stroke-from-0", "angle-over-pi"],
)  # fmt: skip
def test_a_run_that_does_not_fit_the_fmu_s_drivers_is_refused_at_its_line(
    tmp_path, old, new, marker, words
):
    """Checked against the model description generated from the scene: before the
    scene's copy is built."""
    text = EXCAVATOR_STUDY.replace(old, new, 1)
    assert text != EXCAVATOR_STUDY
    _refused_at(tmp_path, text, marker, words, prepare=True)


@needs_cmake
def test_a_cylinder_whose_pins_sit_on_two_bodies_cannot_run_over_an_angle(tmp_path):
    """The loader's tilt cylinder: its barrel on the frame, its bellcrank's pivot on the
    lift arm; its length depends on two angles."""
    text = (
        EXCAVATOR_STUDY.replace(str(SCENES / "excavator.toml"), str(SCENES / "loader.toml"))
        .replace('[[run.driver]]\nname = "bucket_cyl"\nangle = [2.2, 0.8]\n', "")
        .replace("boom_cyl", "lift_cyl")
        .replace("stick_cyl", "tilt_cyl")
        .replace("bucket_cyl", "tilt_cyl")
        .replace('"dig.force.x" = 98480.0\n"dig.force.y"', '"payload.force.y"')
    )
    marker = "angle = [-1.0, -2.0]"
    _refused_at(
        tmp_path,
        text,
        marker,
        "cylinder tilt_cyl: its pivot O is on lift_arm and its barrel's pin A on the frame: "
        "its length depends on the angles of bellcrank and of lift_arm, not on one angle; "
        "give stroke = [low, high] (m, its length)",
        prepare=True,
    )


@pytest.mark.parametrize(
    "fmu, entries, marker, words",
    [
        (LIFT, 'name = "ram"\nangle = [0.0, 0.5]', "angle =",
         "angle turns a crank or a cylinder's link; ram is a ram: give stroke"),
        (LEG, 'name = "front"\nstroke = [0.1, 0.2]\n\n[[run.driver]]\nname = "rear"\n'
         "angle = [-2.5, -1.7]", "stroke =",
         "stroke moves a ram or a cylinder; front is a crank: give angle"),
        (EXCAVATOR, 'name = "boom_cyl"\nangle = [-0.2, 0.45]\n\n[[run.driver]]\nname = '
         '"stick_cyl"\nstroke = [2.8, 3.5]\n\n[[run.driver]]\nname = "bucket_cyl"\n'
         "stroke = [2.0, 2.7]", "angle =",
         "cylinder boom_cyl: angle needs its geometry among the FMU's parameters"),
    ],
    ids=["angle-on-ram", "stroke-on-crank", "angle-without-geometry"],
)  # fmt: skip
def test_a_range_its_driver_cannot_take_is_refused_at_its_line(
    tmp_path, fmu, entries, marker, words
):
    _needs(fmu)
    text = (
        f'[study]\nfmu = "{fmu}"\n\n[run]\nkind = "kinetostatic"\nduration = 1.0\n\n'
        f'[[run.driver]]\n{entries}\n\n[sampling]\nmethod = "grid"\ncount = 1\n\n'
        '[[parameter]]\nname = "gravity.y"\nlow = -9.81\nhigh = -9.81\n\n'
        '[[figure]]\nname = "g"\nof = "gravity.y"\nstat = "max"\n\n[objective]\nminimize = "g"\n'
    )
    _refused_at(tmp_path, text, marker, words, prepare=True)


def _cycloid(start: float, end: float, duration: float, points: int) -> tuple:
    """The rest-to-rest rise from its definition (README: q = start + (end - start)
    (tau - sin(2 pi tau) / (2 pi))) and its derivatives by hand."""
    tau = np.linspace(0.0, 1.0, points)
    span = end - start
    q = start + span * (tau - np.sin(2 * math.pi * tau) / (2 * math.pi))
    rate = span / duration * (1 - np.cos(2 * math.pi * tau))
    return q, rate, 2 * math.pi * span / duration**2 * np.sin(2 * math.pi * tau)


def _stepped(fmu: Path, design: dict, inputs: tuple, x: np.ndarray, names: tuple) -> dict:
    """The FMU set to ``design`` and stepped through the samples ``x`` of ``inputs``:
    each output's series."""
    fmu_ = Slave(fmu)
    fmu_.initialize(design)
    rows, status = [], []
    for row in x:
        fmu_.set(inputs, tuple(row))
        rows.append(fmu_.get(names))
        status.append(fmu_.get_status())
    fmu_.close()
    return dict(zip(names, np.array(rows).T, strict=True)) | {"status": np.array(status)}


@needs_cmake
def test_every_driver_moves_its_link_through_the_commanded_angles(tmp_path):
    """Each design's cylinder lengths, rates and accelerations, set into the FMU, put the
    boom at its angle, the stick at its angle from the boom and the rocker at its angle
    from the stick, with the cycloid's rates and accelerations, as the FMU's own outputs
    give them; the run's figures are the FMU's efforts over that motion."""
    s, run, values, _ = study.prepare(_write(tmp_path, EXCAVATOR_STUDY), tmp_path)
    assert isinstance(run, runs.MultiStrokeRun)
    assert [(a.link, a.carrier) for a in run.axes] == [
        ("boom", ""), ("stick", "boom"), ("rocker", "stick"),
    ]  # fmt: skip
    fmu = next((tmp_path).glob("excavator_sweep_*.toml"))
    fmu = paths.ROOT / "build-scene" / "fmus" / f"{fmu.stem}_fmi2.fmu"
    table = results.table_of(s, values, run.chunk(list(enumerate(values))))
    assert set(table.status) == {"ok"}, table.message
    links = ("boom", "stick", "rocker")
    names = tuple(f"{n}.{q}" for n in links for q in ("angle", "omega", "epsilon"))
    names += ("boom_cyl.force", "bucket_cyl.force")
    for k in (0, len(values) - 1):
        params = run.mechanism_parameters(tuple(values[k]))
        got = _stepped(fmu, params, run.inputs(), run.samples(params), names)
        assert set(got["status"]) == {0}
        relative = {"boom": None, "stick": "boom", "rocker": "stick"}
        for link, d in zip(links, s.run.drivers, strict=True):
            wanted = _cycloid(d.start, d.end, s.run.duration, s.run.points)
            for q, want in zip(("angle", "omega", "epsilon"), wanted, strict=True):
                carrier = relative[link]
                series = got[f"{link}.{q}"] - (got[f"{carrier}.{q}"] if carrier else 0.0)
                # to round-off: 1e-15 to 2.3e-15 of each series' largest here
                scale = np.max(np.abs(want))
                assert np.max(np.abs(series - want)) <= 1e-13 * scale, (k, link, q)
        peak = np.max(np.abs(got["boom_cyl.force"]))
        assert table.column("boom_force_peak")[k] == pytest.approx(peak, rel=1e-12)
        peak = np.max(np.abs(got["bucket_cyl.force"]))
        assert table.column("bucket_force_peak")[k] == pytest.approx(peak, rel=1e-12)


@needs_cmake
def test_a_carried_cylinder_through_its_toggle_or_on_its_other_branch_is_a_row(
    tmp_path, monkeypatch
):
    """The stick cylinder's eye moved to where O, A and B fall in line within the pass is
    singular, naming the angle from the boom, before any sample; its branch flipped, it
    cannot assemble; both rows without figures. With the geometry's check taken away, the
    FMU's angle outputs catch the other branch."""
    s, run, values, _ = study.prepare(_write(tmp_path, EXCAVATOR_STUDY), tmp_path)
    # B = (-0.75, y) in the stick's frame, O = (5.7, 0) and A = (2.6, 0.8) in the boom's:
    # at stick.angle - boom.angle = -1.5, B - O points along A - O where y is
    alpha = math.atan2(0.8, 2.6 - 5.7)
    beta = alpha + 1.5 - 2 * math.pi  # the direction of B in the stick's frame, in (-pi, pi]
    y = -0.75 * math.tan(beta)
    assert math.isclose(math.atan2(y, -0.75), beta, abs_tol=1e-12)
    toggling = replace(run, fixed=(("stick_cyl.pin.y", y),))
    flipped = replace(run, fixed=(("stick_cyl.branch", 1.0),))
    outcomes = [(0, toggling(tuple(values[0]))), (1, flipped(tuple(values[0])))]
    table = results.table_of(s, values[:2], outcomes)
    assert table.status == ["singular", "cannot_assemble"], table.message
    assert (
        "cylinder stick_cyl passes its toggle (O, A and B in line) at stick.angle - boom.angle "
        "-1.5 rad" in table.message[0]
    )
    assert "from stick.angle - boom.angle -2 to -1 rad B is to the right" in table.message[1]
    assert np.all(np.isnan(table.figures))
    monkeypatch.setattr(stroke.Cylinder, "check", lambda self, low, high: None)
    outcome = flipped(tuple(values[0]))
    assert outcome.status == "wrong_angle", outcome
    assert "the FMU puts stick at 0.889682568 rad from boom, not the run's -1 rad (sample 0)" in (
        outcome.message
    )

"""The drawing of a cylinder-driven mechanism (scripts/dyadfmu/report/cylinder_drawing.py)
against its FMU read on its own: every point the drawing computes before plotting is the
FMU's output (bit for bit; a load's point its link's angle output turned onto the load's
`at`), every arrow is |F| over the scale its legend states, every curve of the force
figure is the FMU's force at those lengths, loads and rates, and both PNG files are
written. The boom of tests/scenes/cylinder_boom.toml runs with its tunable pins moved off
the scene's numbers, so that a point taken from the scene instead of the FMU is found."""

import math
import re
import shutil

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from dyadfmu import paths  # noqa: E402
from dyadfmu.fmi.slave import Slave  # noqa: E402
from dyadfmu.report import cylinder_drawing as cd  # noqa: E402
from matplotlib.patches import FancyArrow  # noqa: E402

BOOM = paths.ROOT / "tests" / "scenes" / "cylinder_boom.toml"
#: tunable pins and the load's point moved off the scene's numbers (m)
PARAMETERS = {"hoist.base.x": 0.65, "hoist.pin.y": -0.25, "payload.at.x": 2.7}
LOADS = {"payload.force.x": 1500.0, "payload.force.y": -6000.0}  # N
LENGTHS = (0.95, 1.2, 1.45)  # m, within the stroke with these pins


def fmu_path():
    return paths.built_fmu("cylinder_boom", 2, how="scripts/run-tests")


@pytest.fixture(scope="module")
def scene():
    return cd.read_scene(BOOM)


@pytest.fixture
def machine(scene):
    m = cd.Machine(scene, fmu_path(), PARAMETERS)
    yield m
    m.close()


class Reference:
    """The FMU on its own: an instance with the same parameters, read by name."""

    def __init__(self):
        self.slave = Slave(fmu_path(), instance_name="reference")
        self.slave.initialize(PARAMETERS)
        self.t = 0.0

    def at(self, length, loads, rate=0.0):
        values = {"payload.force.x": 0.0, "payload.force.y": 0.0, **loads}
        values.update({"hoist.length": length, "hoist.velocity": rate, "hoist.acceleration": 0.0})
        self.slave.set(tuple(values), list(values.values()))
        self.slave.do_step(self.t, 1e-3)
        self.t += 1e-3
        assert self.slave.get_status() == 0
        return self

    def point(self, name):
        return np.array(self.slave.get((f"{name}.x", f"{name}.y")))

    def value(self, name):
        return self.slave.get(name)


@pytest.fixture
def reference():
    r = Reference()
    yield r
    r.slave.close()


def _poses(machine):
    barrel = cd.BARREL_SHARE * min(LENGTHS)
    return [cd.pose(machine, machine.at(s, LOADS), barrel) for s in LENGTHS]


def _same(a, b):
    return np.array_equal(np.asarray(a, float), np.asarray(b, float))


def test_every_point_drawn_is_the_fmus_output(machine, reference):
    """B, the dyad's pairs, the rod's end, the polygon of the boom and the dyad's links
    are the FMU's position outputs bit for bit; A and O its parameters (or the scene's
    baked numbers); the barrel starts at A along hoist.angle, BARREL_SHARE of the
    shortest length long; the load's point is the boom's angle output turned onto the
    FMU's payload.at."""
    for p in _poses(machine):
        ref = reference.at(p.length, LOADS)
        b = ref.point("hoist.B.position")
        d_m, e, d_n = (ref.point(f"hang.{k}.position") for k in ("D_m", "E", "D_n"))
        a = np.array([ref.value("hoist.base.x"), 0.2])
        o = np.array([0.0, 1.0])
        angle = ref.value("boom.angle")
        load = o + 2.7 * np.array([math.cos(angle), math.sin(angle)])
        assert _same(p.points["B"], b) and _same(p.points["A"], a) and _same(p.points["O"], o)
        assert np.allclose(p.points["payload"], load, rtol=0, atol=1e-15)
        for key, want in (("hang.D_m", d_m), ("hang.E", e), ("hang.D_n", d_n)):
            assert _same(p.points[key], want), key
        segments = p.segments()
        assert _same(segments["rod"][1], b)
        start, mouth = segments["barrel"]
        assert _same(start, a)
        axis = ref.value("hoist.angle")
        assert np.allclose(
            mouth - start,
            cd.BARREL_SHARE * min(LENGTHS) * np.array([math.cos(axis), math.sin(axis)]),
            rtol=0,
            atol=1e-15,
        )
        assert _same(segments["rod"][0], mouth)
        ends = {}
        for name, (p0, p1) in segments.items():
            body = name.split(": ")[0]
            ends.setdefault(body, []).extend([tuple(p0), tuple(p1)])
        assert set(ends["boom"]) == {tuple(o), tuple(b), tuple(d_m), tuple(p.points["payload"])}
        assert len(ends["boom"]) == 8  # a closed polygon of four edges
        assert sorted(ends["platform"]) == sorted([tuple(d_m), tuple(e)])  # one bar
        assert sorted(ends["tie"]) == sorted([tuple(d_n), tuple(e)])
        assert set(p.pivots) == {"O", "A", "hang.D_n"}


def _legend_scale(ax):
    said = re.search(
        r"scale ([0-9.eE+-]+) kN per m of arrow", ax.get_legend().get_title().get_text()
    )
    assert said, ax.get_legend().get_title().get_text()
    return float(said.group(1))


def _check_arrows(ax, drawn, p, reference):
    """Each arrow from its point, |F| / (the legend's scale) long along F."""
    scale = _legend_scale(ax)
    ref = reference.at(p.length, LOADS)
    forces = {
        "boom.R_O": ("O", ref.point("boom.R_O")),
        "hoist.R_A": ("A", ref.point("hoist.R_A")),
        "hoist.R_B": ("B", ref.point("hoist.R_B")),
        "hang.R_mk": ("hang.D_m", ref.point("hang.R_mk")),
        "hang.R_mn": ("hang.E", ref.point("hang.R_mn")),
        "hang.R_np": ("hang.D_n", ref.point("hang.R_np")),
        "payload": ("payload", np.array([LOADS["payload.force.x"], LOADS["payload.force.y"]])),
    }
    assert set(drawn["arrows"]) == set(forces)
    arrows = [a for a in ax.patches if isinstance(a, FancyArrow)]
    assert len(arrows) == len(forces)
    for name, (key, force) in forces.items():
        start, vec = p.points[key], force / 1e3 / scale
        xy = drawn["arrows"][name].get_xy() - start
        along = xy @ (vec / np.hypot(*vec))
        assert along.max() == pytest.approx(np.hypot(*vec), rel=1e-9), name
        assert along.min() == pytest.approx(0.0, abs=1e-9 * np.hypot(*vec)), name
        tip = xy[np.argmax(along)]
        assert np.allclose(tip, vec, rtol=0, atol=1e-9 * np.hypot(*vec)), name
    return scale


def test_arrows_are_the_forces_over_the_legends_scale(machine, reference):
    """At the last length (the default) and at the first, with the round scale chosen and
    with one given: every reaction output and the payload as an arrow from its point,
    |F| / scale long; the largest within ARROW_SHARE of the drawing's size and above
    half of that."""
    poses = _poses(machine)
    for at in (-1, 0):
        fig, ax = plt.subplots()
        drawn = cd.draw(ax, machine, poses, at)
        scale = _check_arrows(ax, drawn, poses[at], reference)
        assert scale == drawn["scale"]
        longest = max(np.hypot(*f) for *_, f, _ in poses[at].forces) / 1e3 / scale
        assert 0.5 * cd.ARROW_SHARE * drawn["size"] <= longest <= cd.ARROW_SHARE * drawn["size"]
        plt.close(fig)
    fig, ax = plt.subplots()
    drawn = cd.draw(ax, machine, poses, -1, scale=7.0)
    assert _check_arrows(ax, drawn, poses[-1], reference) == 7.0
    plt.close(fig)


def test_force_curves_are_the_fmus_force(machine, reference, tmp_path):
    """The four curves of the force figure: with and without the loads, at rest and
    extending at 0.1 m/s, each the FMU's hoist.force (kN) over boom.angle (deg)."""
    lengths = cd.stroke_lengths((0.95, 1.45), 11)
    curves = cd.force_curves(machine, lengths, LOADS, 0.1)
    lines = cd.force_figure(machine, curves, LOADS, tmp_path / "force.png")
    cases = {(True, 0.0), (False, 0.0), (True, 0.1), (False, 0.1)}
    assert set(curves) == cases and cases <= set(lines)
    forces = {}
    for loaded, rate in cases:
        want_x, want_y = [], []
        for s in lengths:
            ref = reference.at(s, LOADS if loaded else {}, rate)
            want_x.append(math.degrees(ref.value("boom.angle")))
            want_y.append(ref.value("hoist.force") / 1e3)
        line = lines[(loaded, rate)]
        assert _same(line.get_xdata(), want_x), (loaded, rate)
        assert _same(line.get_ydata(), want_y), (loaded, rate)
        forces[(loaded, rate)] = np.array(want_y)
    # the cases differ, so that a curve of the wrong case is found
    assert np.all(np.abs(forces[(True, 0.0)] - forces[(False, 0.0)]) > 1.0)
    assert np.all(forces[(True, 0.1)] != forces[(True, 0.0)])


def _png(path):
    assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = mpimg.imread(path)
    assert image.shape[0] > 300 and image.shape[1] > 300
    assert float(image[..., :3].std()) > 0.05  # not blank


def test_the_command_writes_both_pngs(tmp_path, capsys):
    """The command writes <identifier>.png and <identifier>_force.png and says so."""
    argv = [str(BOOM), "--stroke", "0.95", "1.45", "--samples", "9", "--out", str(tmp_path)]
    argv += ["--load", "payload.force.y=-6000", "--set", "hoist.pin.y=-0.25"]
    assert cd.main(argv) == 0
    _png(tmp_path / "cylinder_boom.png")
    _png(tmp_path / "cylinder_boom_force.png")
    said = capsys.readouterr().out
    assert "wrote" in said and "cylinder_boom_force.png" in said


@pytest.mark.parametrize(
    "extra,said",
    [
        (["--load", "payload.force.z=1"], "--load payload.force.z: not a load input"),
        (["--set", "boom.at.x=1"], "--set boom.at.x: not a tunable parameter"),
        (["--stroke", "0.1", "1.2"], "hoist.length = 0.1 m:"),
        (["--positions", "2", "--reactions-at", "3"], "--reactions-at 3: only 2 positions"),
        (["--stroke", "1.2", "1.2"], "--stroke 1.2 1.2: the ends must differ"),
    ],
)
def test_the_command_refuses_bad_arguments_in_one_line(tmp_path, capsys, extra, said):
    argv = [str(BOOM), "--stroke", "0.95", "1.45", "--out", str(tmp_path)] + extra
    with pytest.raises(SystemExit) as done:
        cd.main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert said in err and len(err.strip().splitlines()) == 1, err


def test_a_scene_without_a_cylinder_is_refused():
    with pytest.raises(cd.DrawingError, match=r"lift.toml: no \[cylinder\] table"):
        cd.read_scene(paths.SCENES_DIR / "lift.toml")


def test_an_fmu_of_another_version_of_the_scene_is_refused(tmp_path):
    """O moved in a copy of the scene (baked, so the FMU keeps the old one): the outputs'
    |O B| disagrees with the scene's pin."""
    text = BOOM.read_text().replace('identifier = "cylinder_boom"', 'identifier = "boom_moved"')
    moved = tmp_path / "boom_moved.toml"
    moved.write_text(text.replace("at = [0.0, 1.0]", "at = [0.0, 1.02]"))
    m = cd.Machine(cd.read_scene(moved), fmu_path())
    try:
        with pytest.raises(cd.DrawingError, match=r"\|O B\| = .* build the FMU from this scene"):
            cd.pose(m, m.at(1.2, {}), 1.0)
    finally:
        m.close()
    shutil.rmtree(tmp_path)

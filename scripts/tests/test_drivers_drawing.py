"""The drawing of a mechanism with several drivers (scripts/dyadfmu/report/drivers_drawing.py)
against its FMU read on its own, on modelDescription/scenes/excavator.toml (three cylinders,
the stick's and the bucket's pinned to the boom and the stick, a digging force at the
bucket's tip) and leg.toml (two cranks): every point drawn is the FMU's output (B, the
dyads' pairs, bit for bit) or placed here from its outputs independently (a carried pivot
from its carrier's angle, a crank's pin from its angle, a load's point), every arrow is
|F| over the scale its legend states, every curve of the effort figure is the FMU's effort
along the motion; the command refuses a range on an unknown input, naming it."""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from dyadfmu import paths  # noqa: E402
from dyadfmu.fmi.slave import Slave  # noqa: E402
from dyadfmu.report import drivers_drawing as dd  # noqa: E402

EXCAVATOR = paths.SCENES_DIR / "excavator.toml"
LEG = paths.SCENES_DIR / "leg.toml"
#: the digging force's point moved off the scene's tip (a tunable parameter, m)
PARAMETERS = {"dig.at.x": -0.2, "dig.at.y": -1.4}
LOADS = {"dig.force.x": 98480.0, "dig.force.y": -17360.0}  # N, along the bucket's frame
RANGES = {
    "boom_cyl.length": (1.95, 3.35),
    "stick_cyl.length": (2.5, 3.8),
    "bucket_cyl.length": (1.85, 2.85),
}
SHARES = (0.0, 0.5, 1.0)
CYLINDERS = ("boom_cyl", "stick_cyl", "bucket_cyl")


def fmu_path(name):
    return paths.built_fmu(name, 2, how="scripts/run-tests")


@pytest.fixture
def mechanism():
    m = dd.Mechanism(dd.read_scene(EXCAVATOR), fmu_path("excavator"), PARAMETERS)
    yield m
    m.close()


class Reference:
    """The FMU on its own: an instance with the same parameters, read by name."""

    def __init__(self, name, parameters):
        self.slave = Slave(fmu_path(name), instance_name="reference")
        self.slave.initialize(parameters)
        self.t = 0.0

    def at(self, values):
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
    r = Reference("excavator", PARAMETERS)
    yield r
    r.slave.close()


def excavator_inputs(share, loads, rates=None):
    """The excavator's inputs at a share of the motion: every load, rate, acceleration."""
    values = {"dig.force.x": 0.0, "dig.force.y": 0.0, **loads}
    for name, (lo, hi) in RANGES.items():
        cyl = name.split(".")[0]
        values[name] = lo + share * (hi - lo)
        values[f"{cyl}.velocity"] = (rates or {}).get(name, 0.0)
        values[f"{cyl}.acceleration"] = 0.0
    return values


def _turn(angle, local):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * local[0] - s * local[1], s * local[0] + c * local[1]])


def _same(a, b):
    return np.array_equal(np.asarray(a, float), np.asarray(b, float))


def _poses(mechanism):
    coordinates = dd.motion(RANGES, SHARES)
    lengths = dd.barrels(mechanism, coordinates)
    return [
        dd.pose(mechanism, mechanism.at(c, LOADS), lengths, t)
        for c, t in zip(coordinates, SHARES, strict=True)
    ]


def _excavator_points(ref):
    """The pins placed here from the reference's outputs and the scene's numbers: the
    boom's, stick's and rocker's pivots, the barrels' pins, the digging force's point."""
    boom, stick, bucket = (ref.value(f"{k}.angle") for k in ("boom", "stick", "bucket"))
    o_boom = np.array([0.2, 2.0])
    o_stick = o_boom + _turn(boom, (5.7, 0.0))
    d_n = ref.point("linkage.D_n.position")
    return {
        "boom.O": o_boom,
        "boom_cyl.A": np.array([1.2, 0.7]),
        "stick.O": o_stick,
        "stick_cyl.A": o_boom + _turn(boom, (2.6, 0.8)),
        "rocker.O": o_stick + _turn(stick, (2.45, 0.15)),
        "bucket_cyl.A": o_stick + _turn(stick, (0.1, 0.45)),
        "dig": d_n + _turn(bucket, (-0.2, -1.4)),
    }


def test_every_point_drawn_is_the_fmus_output(mechanism, reference):
    """Each cylinder's B and the four-bar's pairs are the FMU's outputs bit for bit; the
    carried pivots and barrel pins, placed with the carriers' angle outputs here, agree
    to 1e-14 m; each barrel starts at A along the cylinder's angle output, BARREL_SHARE
    of its shortest length long, and its rod ends at B; the bodies are the polygons of
    their points."""
    poses = _poses(mechanism)
    for p, share in zip(poses, SHARES, strict=True):
        ref = reference.at(excavator_inputs(share, LOADS))
        for cyl in CYLINDERS:
            assert _same(p.points[f"{cyl}.B"], ref.point(f"{cyl}.B.position")), cyl
        for pair in ("D_m", "E", "D_n"):
            want = ref.point(f"linkage.{pair}.position")
            assert _same(p.points[f"linkage.{pair}"], want), pair
        for key, want in _excavator_points(ref).items():
            assert np.allclose(p.points[key], want, rtol=0, atol=1e-14), key
        segments = p.segments()
        for cyl in CYLINDERS:
            start, mouth = segments[f"{cyl}.barrel"]
            axis = ref.value(f"{cyl}.angle")
            barrel = 0.8 * min(RANGES[f"{cyl}.length"])
            assert _same(start, p.points[f"{cyl}.A"])
            assert np.allclose(mouth - start, barrel * _turn(axis, (1.0, 0.0)), atol=1e-14)
            assert _same(segments[f"{cyl}.rod"][1], ref.point(f"{cyl}.B.position"))
        assert set(p.bodies["boom"]) == {"boom.O", "boom_cyl.B", "stick.O", "stick_cyl.A"}
        assert set(p.bodies["stick"]) == {
            "stick.O",
            "stick_cyl.B",
            "rocker.O",
            "bucket_cyl.A",
            "linkage.D_n",
        }
        assert set(p.bodies["bucket"]) == {"linkage.D_n", "linkage.E", "dig"}
        assert set(p.pivots) == {"boom.O", "boom_cyl.A"}


def test_crank_pins_are_the_dyads_pairs():
    """leg.toml: each crank's pin, placed from its angle input and length, is where the
    FMU puts the knee (the dyad's D_m, D_n) to 1e-15 m; the pivots are the frame's."""
    m = dd.Mechanism(dd.read_scene(LEG), fmu_path("leg"))
    try:
        ranges = {"front.angle": (-0.8, -1.3), "rear.angle": (-2.3, -1.8)}
        for c in dd.motion(ranges, SHARES):
            p = dd.pose(m, m.at(c, {"foot.force.y": 30.0}), {})
            assert np.allclose(p.points["front.A"], p.points["knees.D_m"], rtol=0, atol=1e-15)
            assert np.allclose(p.points["rear.A"], p.points["knees.D_n"], rtol=0, atol=1e-15)
            assert _same(p.points["front.O"], (0.04, 0.0))
            assert _same(p.points["rear.O"], (-0.04, 0.0))
            assert np.allclose(p.points["foot"], p.points["knees.E"], rtol=0, atol=1e-15)
    finally:
        m.close()


def test_arrows_are_the_forces_over_the_legends_scale(mechanism, reference):
    """At the last pose: every reaction output (each cylinder's R_A, R_B and its link's
    R_O, the four-bar's three) and the digging force turned onto the bucket's frame as
    an arrow from its point, |F| / scale long."""
    poses = _poses(mechanism)
    fig, ax = plt.subplots()
    drawn = dd.draw(ax, mechanism, poses, -1)
    scale, unit = drawn["scale"], drawn["unit"]
    assert unit == ("kN", 1e3)
    title = ax.get_legend().get_title().get_text()
    assert f"scale {scale:g} kN per m of arrow" in title
    ref = reference.at(excavator_inputs(1.0, LOADS))
    want = {}
    for cyl, link in zip(CYLINDERS, ("boom", "stick", "rocker"), strict=True):
        want[f"{link}.R_O"] = ref.point(f"{link}.R_O")
        want[f"{cyl}.R_A"] = ref.point(f"{cyl}.R_A")
        want[f"{cyl}.R_B"] = ref.point(f"{cyl}.R_B")
    for r in ("R_mk", "R_mn", "R_np"):
        want[f"linkage.{r}"] = ref.point(f"linkage.{r}")
    want["dig"] = _turn(ref.value("bucket.angle"), (LOADS["dig.force.x"], LOADS["dig.force.y"]))
    assert set(drawn["arrows"]) == set(want)
    points = {name: key for name, _, key, _, _ in poses[-1].forces}
    for name, force in want.items():
        vec = force / 1e3 / scale
        xy = drawn["arrows"][name].get_xy() - poses[-1].points[points[name]]
        along = xy @ (vec / np.hypot(*vec))
        assert along.max() == pytest.approx(np.hypot(*vec), rel=1e-9), name
        assert along.min() == pytest.approx(0.0, abs=1e-9 * np.hypot(*vec)), name
        assert np.allclose(xy[np.argmax(along)], vec, rtol=0, atol=1e-9 * np.hypot(*vec)), name
    plt.close(fig)


def test_effort_curves_are_the_fmus_efforts(mechanism, reference, tmp_path):
    """The effort figure's curves: each cylinder's force (kN) along the motion with and
    without the digging force, at rest and over the motion in 5 s, the FMU's."""
    shares = np.linspace(0.0, 1.0, 7)
    curves = dd.effort_curves(mechanism, RANGES, shares, LOADS, 5.0)
    lines = dd.effort_figure(mechanism, curves, LOADS, RANGES, tmp_path / "f.png", 5.0, SHARES)
    cases = {(True, False), (False, False), (True, True), (False, True)}
    assert set(curves) == cases
    rates = {n: (hi - lo) / 5.0 for n, (lo, hi) in RANGES.items()}
    found = {}
    for loaded, moving in cases:
        want = {cyl: [] for cyl in CYLINDERS}
        for t in shares:
            ref = reference.at(
                excavator_inputs(t, LOADS if loaded else {}, rates if moving else None)
            )
            for cyl in CYLINDERS:
                want[cyl].append(ref.value(f"{cyl}.force") / 1e3)
        for cyl in CYLINDERS:
            line = lines[(f"{cyl}.force", loaded, moving)]
            assert _same(line.get_xdata(), 100.0 * shares)
            assert _same(line.get_ydata(), want[cyl]), (cyl, loaded, moving)
            found[(cyl, loaded, moving)] = np.array(want[cyl])
    for cyl in CYLINDERS:  # the cases differ, so that a curve of the wrong case is found
        assert np.all(found[(cyl, True, False)] != found[(cyl, False, False)])
        assert np.all(found[(cyl, True, True)] != found[(cyl, True, False)])


def _png(path):
    assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = mpimg.imread(path)
    assert image.shape[0] > 300 and image.shape[1] > 300
    assert float(image[..., :3].std()) > 0.05  # not blank


def test_the_command_writes_both_pngs(tmp_path, capsys):
    """leg.toml: <identifier>.png and <identifier>_forces.png, the torques in N m."""
    argv = [str(LEG), "--range", "front.angle", "-0.8", "-1.3", "--range", "rear.angle"]
    argv += ["-2.3", "-1.8", "--samples", "9", "--out", str(tmp_path)]
    assert dd.main(argv) == 0
    _png(tmp_path / "leg.png")
    _png(tmp_path / "leg_forces.png")
    said = capsys.readouterr().out
    assert "wrote" in said and "leg_forces.png" in said


@pytest.mark.parametrize(
    "extra,said",
    [
        (
            ["--range", "wheel.angle", "0", "1"],
            "--range wheel.angle: not a driver's coordinate of leg_fmi2.fmu (its drivers: "
            "front.angle, rear.angle)",
        ),
        (["--range", "front.omega", "0", "1"], "--range front.omega: not a driver's coordinate"),
        (["--range", "front.angle", "0", "1"], "--range front.angle: given twice"),
        (["--range", "rear.angle", "a", "1"], "--range rear.angle: not numbers"),
        (["--load", "foot.force.z=1"], "--load foot.force.z: not a load input"),
        (["--positions", "2", "--reactions-at", "3"], "--reactions-at 3: only 2 poses"),
    ],
)
def test_the_command_refuses_bad_arguments_in_one_line(tmp_path, capsys, extra, said):
    argv = [str(LEG), "--range", "front.angle", "-0.8", "-1.3", "--out", str(tmp_path)] + extra
    with pytest.raises(SystemExit) as done:
        dd.main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert said in err and len(err.strip().splitlines()) == 1, err


def test_help_names_the_options(capsys):
    with pytest.raises(SystemExit) as done:
        dd.main(["--help"])
    assert done.value.code == 0
    said = " ".join(capsys.readouterr().out.split())
    for text in ("--range INPUT MIN MAX", "--duration", "--load", "_forces.png", "N m"):
        assert text in said, text


def test_a_scene_without_a_driver_is_refused(tmp_path):
    text = LEG.read_text()
    head = text[: text.index("[[crank]]")]
    bare = tmp_path / "bare.toml"
    bare.write_text(head.replace('identifier = "leg"', 'identifier = "bare"'))
    with pytest.raises(dd.DrawingError):
        dd.read_scene(bare)

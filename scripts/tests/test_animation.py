"""`dyadfmu animate`: the mechanism in motion as an HTML page with a time slider and a GIF.
The page is loaded in a real browser (Debian's chromium, headless, through Selenium and
chromium-driver): what it draws at each instant is read back from the document and
compared with the FMU's own outputs at that instant, run here on its own."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu.animation import page
from dyadfmu.fmi.slave import Slave
from tool_checks import required, required_tool

ROOT = Path(__file__).resolve().parents[2]
SLIDER_CRANK = ROOT / "modelDescription" / "scenes" / "slider_crank.toml"
SHAPER_PAIRS = [f"{d}.{p}" for d in ("slot", "ram") for p in ("D_m", "E", "D_n")]
#: Plotting precision: the page's numbers have page.DIGITS significant digits.
PLOTTED = 10.0 ** (1 - page.DIGITS)


def _animate(*args: object) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "dyadfmu", "animate", *map(str, args)],
        capture_output=True,
        text=True,
    )


def _csv(path: Path) -> dict:
    names = [n.strip('"') for n in path.read_text().splitlines()[0].split(",")]
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: values[:, k] for k, n in enumerate(names)}


@pytest.fixture(scope="module")
def browser():
    """Headless chromium driven by chromium-driver through Selenium."""
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        required(False, "selenium is not installed")
    chromium, driver = required_tool("chromium"), required_tool("chromedriver")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    session = webdriver.Chrome(service=Service(driver), options=options)
    yield session
    session.quit()


def _open(browser, path: Path) -> None:
    browser.get(path.resolve().as_uri())
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors


def _show(browser, k: int) -> None:
    """Move the time slider to frame k the way a user's drag does (its input event)."""
    browser.execute_script(
        "const s = document.getElementById('time'); s.value = arguments[0];"
        "s.dispatchEvent(new Event('input'));",
        k,
    )


def _drawn(browser) -> dict:
    """Every point the page draws now: name -> (x, y) m (the SVG's y is -y)."""
    found = browser.execute_script(
        "return Array.from(document.querySelectorAll('#drawing [data-point]')).map("
        "c => [c.dataset.point, Number(c.getAttribute('cx')), Number(c.getAttribute('cy'))]);"
    )
    return {name: (x, -y) for name, x, y in found}


def _fmu_pairs(fmu: Path, angles: np.ndarray) -> list[dict]:
    """The FMU's own pair positions at each crank angle, run here."""
    slave = Slave(fmu)
    slave.initialize()
    found = []
    for angle in angles:
        slave.set(("crank.angle",), (float(angle),))
        slave.do_step(0.0, 1e-3)
        names = tuple(f"{p}.position.{a}" for p in SHAPER_PAIRS for a in "xy")
        values = slave.get(names)
        found.append({p: (values[2 * i], values[2 * i + 1]) for i, p in enumerate(SHAPER_PAIRS)})
    slave.close()
    return found


def test_the_shaper_page_draws_the_fmus_pair_positions_and_its_slider_moves_it(tmp_path, browser):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    done = _animate("shaper", "--instants", 121, "--no-gif", "--out", tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    html = tmp_path / "shaper_animation.html"
    rows = _csv(tmp_path / "shaper_animation.csv")
    assert len(rows["time"]) == 121
    _open(browser, html)
    slider = browser.find_element(By.ID, "time")
    assert slider.get_attribute("max") == "120"
    first = _drawn(browser)
    slider.send_keys(Keys.ARROW_RIGHT, Keys.ARROW_RIGHT)  # a user's keys move the mechanism
    assert browser.find_element(By.TAG_NAME, "body").get_attribute("data-shown") == "2"
    moved = _drawn(browser)
    assert math.dist(first["slot.E"], moved["slot.E"]) > 1e-3
    frames = [0, 2, 17, 45, 60, 93, 120]
    fmu = ROOT / "build" / "fmus" / "shaper_fmi2.fmu"
    truth = _fmu_pairs(fmu, rows["crank.angle"][frames])
    size = 0.6  # m, the shaper's extent
    for k, want in zip(frames, truth, strict=True):
        _show(browser, k)
        drawn = _drawn(browser)
        for pair in SHAPER_PAIRS:
            assert math.dist(drawn[pair], want[pair]) <= PLOTTED * size, (k, pair)
        crank = math.dist(drawn["crank.A"], drawn["crank.O"])
        assert abs(crank - 0.1) <= PLOTTED, k  # the crank's length, |O A|
    cursor = browser.execute_script(
        "return Number(document.querySelector('[data-cursor]').getAttribute('x1'));"
    )
    _show(browser, 0)
    assert cursor > browser.execute_script(
        "return Number(document.querySelector('[data-cursor]').getAttribute('x1'));"
    )
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]


def _short_rod_scene(tmp_path: Path) -> Path:
    text = SLIDER_CRANK.read_text().replace(
        'identifier = "slider_crank"', 'identifier = "anim_rod"'
    )
    path = tmp_path / "anim_rod.toml"
    path.write_text(text.replace("length = 0.18", "length = 0.05"))
    return path


def test_a_scene_that_does_not_assemble_everywhere_is_marked_not_fatal(tmp_path, browser):
    from PIL import Image

    required_tool("cmake")
    done = _animate(_short_rod_scene(tmp_path), "--instants", 37, "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr[-3000:]
    assert "no answer at" in done.stderr and "cannot assemble" in done.stderr
    out = tmp_path / "out"
    rows = _csv(out / "anim_rod_animation.csv")
    failed = np.flatnonzero(np.isnan(rows["engine.E.position.x"]))
    assert 0 < len(failed) < 37
    with Image.open(out / "anim_rod_animation.gif") as gif:
        assert gif.n_frames == 37
    _open(browser, out / "anim_rod_animation.html")
    k = int(failed[len(failed) // 2])
    _show(browser, k)
    reason = browser.execute_script("return document.getElementById('reason').textContent;")
    assert "no answer" in reason and "cannot assemble" in reason
    layer = browser.execute_script(
        "const g = document.getElementById('drawing');"
        "return [g.getAttribute('opacity'), g.getAttribute('data-frame')];"
    )
    assert float(layer[0]) < 1 and int(layer[1]) not in set(failed.tolist())
    marks = browser.execute_script("return document.querySelectorAll('[data-failed]').length;")
    assert marks >= len(failed)
    _show(browser, 0)
    assert browser.execute_script("return document.getElementById('reason').textContent;") == ""


def _recording(tmp_path: Path) -> Path:
    """A recorded run of the shaper FMU: dyadfmu rows over a crank turn."""
    angles = np.linspace(0.0, 2.0 * math.pi, 25)
    table = tmp_path / "turn.csv"
    columns = np.column_stack([angles / (2 * math.pi), angles, np.full(25, 2 * math.pi)])
    np.savetxt(table, columns, delimiter=",", header="time,crank.angle,crank.omega", comments="")
    fmu = ROOT / "build" / "fmus" / "shaper_fmi2.fmu"
    run = subprocess.run(
        [sys.executable, "-m", "dyadfmu", "rows", fmu, "--input", table, "--out", tmp_path],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    return tmp_path / "shaper_fmi2.csv"


def _rewritten(path: Path, out: Path, change) -> Path:
    lines = path.read_text().splitlines()
    header = [n.strip('"') for n in lines[0].split(",")]
    body = [line.split(",") for line in lines[1:]]
    header, body = change(header, body)
    out.write_text("\n".join([",".join(header), *(",".join(r) for r in body)]) + "\n")
    return out


def test_a_recorded_run_is_animated_and_a_bad_one_refused_in_one_line(tmp_path):
    recorded = _recording(tmp_path)
    done = _animate(recorded, "--scene", "shaper", "--no-gif", "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr[-3000:]
    drawn = _csv(tmp_path / "out" / "shaper_animation.csv")
    source = _csv(recorded)
    for name in ("crank.angle", "slot.E.position.x", "ram.D_m.position.y", "crank.torque"):
        assert np.array_equal(drawn[name], source[name]), name

    def without_positions(header, body):
        keep = [i for i, n in enumerate(header) if not n.startswith("ram.E.position")]
        return [header[i] for i in keep], [[r[i] for i in keep] for r in body]

    def nan_row(header, body):
        body[6][header.index("slot.E.position.y")] = "nan"
        return header, body

    def no_angle(header, body):
        keep = [i for i, n in enumerate(header) if n != "crank.angle"]
        return [header[i] for i in keep], [[r[i] for i in keep] for r in body]

    def another(header, body):
        return ["time", "motor.speed", "tank.level"], [[r[0], "1", "2"] for r in body]

    cases = {
        without_positions: "has no pair positions of shaper (ram.E.position.x, ram.E.position.y)",
        nan_row: "1 rows with NaN and status 0 (the first on line 8, t = 0.25 s, in "
        "slot.E.position.y)",
        no_angle: "has no crank.angle (the FMU's input)",
        another: "is not a recording of shaper_fmi2.fmu: none of its columns (motor.speed, "
        "tank.level) is a variable of it",
    }

    def no_reactions(header, body):
        keep = [i for i, n in enumerate(header) if ".R_" not in n]
        return [header[i] for i in keep], [[r[i] for i in keep] for r in body]

    # what the drawing needs is there: drawn, with the efforts alone beside it
    bare = _rewritten(recorded, tmp_path / "no_reactions.csv", no_reactions)
    shown = _animate(bare, "--scene", "shaper", "--no-gif", "--out", tmp_path / "bare")
    assert shown.returncode == 0, shown.stderr[-2000:]
    assert _csv(tmp_path / "bare" / "shaper_animation.csv").keys() >= {"crank.torque"}
    named = _animate(
        bare, "--scene", "shaper", "--curve", "slot.R_mk", "--no-gif", "--out", tmp_path
    )
    assert named.returncode == 1 and "--curve slot.R_mk: not in no_reactions.csv" in named.stderr
    for change, message in cases.items():
        bad = _rewritten(recorded, tmp_path / f"{change.__name__}.csv", change)
        refused = _animate(bad, "--scene", "shaper", "--no-gif", "--out", tmp_path / "bad")
        assert refused.returncode == 1, change.__name__
        lines = refused.stderr.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], (change.__name__, refused.stderr)


def test_rows_the_recording_marks_with_a_status_are_instants_without_an_answer(tmp_path):
    recorded = _recording(tmp_path)

    def flagged(header, body):
        k = header.index("status")
        for row in body[3:5]:
            row[k] = "4"
            row[header.index("slot.E.position.x")] = "nan"
        return header, body

    bad = _rewritten(recorded, tmp_path / "flagged.csv", flagged)
    done = _animate(bad, "--scene", "shaper", "--no-gif", "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert "no answer at 2 of 25 instants" in done.stderr and "status 4" in done.stderr
    drawn = _csv(tmp_path / "out" / "shaper_animation.csv")
    assert np.flatnonzero(np.isnan(drawn["slot.E.position.x"])).tolist() == [3, 4]


def test_the_page_data_cannot_close_its_script_element():
    hostile = {"source": "run</script><script>alert(1)</script>&.csv"}
    text = page.script_json(hostile)
    assert "<" not in text and ">" not in text and "&" not in text
    import json

    assert json.loads(text) == hostile


def test_the_gif_has_a_frame_per_instant_each_its_own(tmp_path):
    from PIL import Image, ImageChops

    done = _animate("slider_crank", "--instants", 9, "--out", tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    with Image.open(tmp_path / "slider_crank_animation.gif") as gif:
        assert gif.n_frames == 9
        frames = []
        for k in range(gif.n_frames):
            gif.seek(k)
            frames.append(gif.convert("RGB"))
    for a, b in zip(frames, frames[1:], strict=False):
        assert ImageChops.difference(a, b).getbbox() is not None


def test_the_options_are_checked_by_name(tmp_path):
    cases = {
        ("nonesuch",): "nonesuch: not a shipped mechanism",
        ("x.csv",): "x.csv: a recorded run needs --scene",
        ("shaper", "--curve", "slot.R_zz"): "--curve slot.R_zz: not an output of shaper_fmi2.fmu",
        ("shaper", "--instants", "1"): "--instants",
    }
    for args, message in cases.items():
        done = _animate(*args, "--no-gif", "--out", tmp_path)
        assert done.returncode != 0 and message in done.stderr, (args, done.stderr)

"""A mechanism FMU computes its effective inertia (J and dJ/dq, or M(q), and the efforts at
zero acceleration: a kinematic pass of their own) only where the importer reads them: a
step whose gets read torques and reactions alone leaves them to their first read. What an
importer reads must not depend on that: every value, whatever it reads when, equals bit
for bit what an instance reading every output at every step reads; a saved state, a
restored one and the directional derivative too. The halves of the scene's C
(<id>_evaluate_first, <id>_evaluate_later; an FMU's, not a controller's bundle) are
checked against <id>_evaluate in C."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.fmi.slave import Slave
from dyadfmu.study.speed import step_rows
from dyadgen import pipeline
from dyadgen.emit.scene_c import later_members
from fmpy import read_model_description
from tool_checks import required_tool

ROOT = paths.ROOT
#: one driver (crank; a chain of two dyads; a ram), several drivers, cylinders
SCENES = ("slider_crank", "shaper", "lift", "leg", "excavator")
STEPS = 40


def _names(fmu: Path) -> tuple[list[str], list[str], list[str]]:
    """(inputs, every Real output, the outputs a step may leave to their first read)."""
    md = read_model_description(str(fmu))
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    reals = [
        v.name
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    later = [n for n in reals if n.endswith((".J", ".dJdq", "torque0", "force0"))]
    later += [n for n in reals if n.startswith("M.")]
    return inputs, reals, later


def _rows(fmu: Path) -> np.ndarray:
    return step_rows(read_model_description(str(fmu)), STEPS, seed=7)[2]


def _same(a: list, b: list) -> bool:
    return np.array_equal(np.asarray(a, float), np.asarray(b, float), equal_nan=True)


@pytest.mark.parametrize("version", (2, 3))
@pytest.mark.parametrize("name", SCENES)
def test_every_read_equals_an_instance_reading_every_output(name, version):
    fmu = paths.built_fmu(name, version)
    inputs, reals, later = _names(fmu)
    assert later, f"{name}: no effective inertia among its outputs"
    others = [n for n in reals if n not in later]
    whole, partial = Slave(fmu, "whole"), Slave(fmu, "partial")
    for slave in (whole, partial):
        slave.initialize()
    t, h = 0.0, 1e-3
    for k, row in enumerate(_rows(fmu)):
        for slave in (whole, partial):
            slave.set(tuple(inputs), row)
            slave.do_step(t, h)
        want = dict(zip(reals, whole.get(tuple(reals)), strict=True))
        got = dict(zip(others, partial.get(tuple(others)), strict=True))
        if k % 3 == 2:  # now and then the inertia too, in a get of its own
            got.update(zip(later, partial.get(tuple(later)), strict=True))
        if k % 7 == 6:  # or one output of it alone, after every output in one get
            got.update(zip(reals, partial.get(tuple(reals)), strict=True))
            got[later[-1]] = partial.get(later[-1])
        assert _same([got[n] for n in got], [want[n] for n in got]), (name, k)
        assert partial.get_status() == whole.get_status() == 0
        t += h
    whole.close()
    partial.close()


def test_a_state_saved_before_the_inertia_is_read_gives_it_after_restore():
    fmu = paths.built_fmu("shaper", 2)
    inputs, reals, later = _names(fmu)
    rows = _rows(fmu)
    slave = Slave(fmu, "saved")
    slave.initialize()
    get_state, set_state, free_state, *_ = slave.state_calls()
    slave.set(tuple(inputs), rows[5])
    slave.do_step(0.0, 1e-3)
    slave.get(tuple(n for n in reals if n not in later))  # the inertia left for later
    state = get_state()
    want = slave.get(tuple(later))
    slave.set(tuple(inputs), rows[20])
    slave.do_step(1e-3, 1e-3)
    moved = slave.get(tuple(later))
    set_state(state)
    assert _same(slave.get(tuple(later)), want) and not _same(moved, want)
    free_state(state)
    slave.close()


def test_the_derivative_of_the_inertia_is_the_same_whatever_was_read():
    fmu = paths.built_fmu("slider_crank", 2)
    inputs, reals, later = _names(fmu)
    row = _rows(fmu)[9]
    found = []
    for read in (reals, [n for n in reals if n not in later]):
        slave = Slave(fmu, "derivative")
        slave.initialize()
        slave.set(tuple(inputs), row)
        slave.do_step(0.0, 1e-3)
        slave.get(tuple(read))
        found.append(slave.directional_derivative(tuple(later), ("crank.angle",), [1.0]))
        found.append(slave.get(tuple(later)))
        slave.close()
    assert _same(found[0], found[2]) and _same(found[1], found[3])
    assert np.all(np.isfinite(found[0]))


def test_only_mechanisms_of_inverse_dynamics_leave_outputs_for_later():
    for name in SCENES:
        assert later_members(pipeline.load_scene(paths.SCENES_DIR / f"{name}.toml")), name
    forward = pipeline.load_scene(paths.SCENES_DIR / "slider_crank_forward.toml")
    dyad = pipeline.load_scene(paths.SCENES_DIR / "dyad_rrt.toml")
    assert later_members(forward) == () and later_members(dyad) == ()


def _scene_tool(*args: object) -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "modelDescription" / "scene.py"), *map(str, args)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


def _sources(name: str, out: Path) -> Path:
    """The scene's C as its FMU compiles it (the halves of evaluate in it; a bundle for a
    controller leaves them out), beside the core files of its bundle."""
    scene = paths.SCENES_DIR / f"{name}.toml"
    _scene_tool(scene, "--bundle", out / "bundle")
    _scene_tool(scene, "--out", out / "fmu")
    folder = out / "bundle" / name
    assert "evaluate_first" not in (folder / "scene" / f"{name}_scene.c").read_text()
    for suffix in ("_scene.c", "_scene.h"):
        (folder / "scene" / f"{name}{suffix}").write_text(
            (out / "fmu" / f"{name}{suffix}").read_text()
        )
    # the FMU's C also evaluates many samples at once, on the core's lanes
    shutil.copy(paths.ROOT / "src" / "dyad_lanes.h", folder / "core" / "src")
    return folder


#: A program on a bundle's scene: the halves against the whole at the example's inputs
#: moved a little each time; 0 where they agree bit for bit and the first half left the
#: later outputs NaN, at 40 or more of the 50 (the others have no answer).
HALVES_MAIN = r"""
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "IDENT_scene.h"

int main(void)
{
    int k, bad = 0, answered = 0;
    for (k = 0; k < 50; ++k) {
        IDENT_input in;
        IDENT_output whole, halves;
        fmu_evaluation a, b;
        memset(&whole, 0, sizeof whole); /* the padding compared too */
        memset(&halves, 0, sizeof halves);
        START
        IDENT_evaluate(&in, &whole, &a);
        IDENT_evaluate_first(&in, &halves, &b);
        if (a.status != b.status) { printf("status %d %d\n", a.status, b.status); return 1; }
        if (b.status != FMU_OK) continue;
        ++answered;
        NAN_CHECKS
        IDENT_evaluate_later(&in, &halves, &b);
        if (b.status != a.status || memcmp(&whole, &halves, sizeof whole) != 0) {
            printf("halves differ at %d\n", k);
            bad = 1;
        }
        /* an effort the second half reads, not finite: its outputs are not either, so
         * every output NaN and status 3, as the whole evaluation reports an overflow */
        IDENT_evaluate_first(&in, &halves, &b);
        halves.EFFORT = INFINITY;
        IDENT_evaluate_later(&in, &halves, &b);
        if (b.status != FMU_DISCARD || halves.status != 3 || !isnan(halves.EFFORT)) {
            printf("an overflow in the second half not reported at %d\n", k);
            bad = 1;
        }
    }
    printf("answered %d of 50\n", answered);
    return bad || answered < 40;
}
"""


@pytest.mark.parametrize("name", ("slider_crank", "leg"))
def test_the_halves_of_the_scene_s_c_give_what_evaluate_gives(name, tmp_path):
    required_tool("cc")
    folder = _sources(name, tmp_path)
    table = pipeline.build_table(pipeline.load_scene(paths.SCENES_DIR / f"{name}.toml"))
    members = later_members(table.scene)
    start = _start_lines(table)
    checks = "\n".join(
        f'        if (!isnan(halves.{m})) {{ printf("{m} not NaN\\n"); return 1; }}'
        for m in members
    )
    effort = next(m[:-1] for m in members if m.endswith(("torque0", "force0")))
    main = HALVES_MAIN.replace("IDENT", name).replace("START", start)
    main = main.replace("NAN_CHECKS", checks).replace("EFFORT", effort)
    (tmp_path / "main.c").write_text(main)
    sources = sorted(folder.glob("scene/*.c")) + sorted(folder.glob("core/src/*.c"))
    subprocess.run(
        ["cc", "-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2",
         f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
         f"-I{folder / 'core' / 'src'}", "-o", str(tmp_path / "halves"),
         str(tmp_path / "main.c"), *map(str, sources), "-lm"],
        check=True,
    )  # fmt: skip
    done = subprocess.run([str(tmp_path / "halves")], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout


def _start_lines(table: object) -> str:
    """C that sets every input member from its start value, an angle (its unit vector)
    and the rest moved with k, so that the 50 evaluations differ."""
    lines = ["        memset(&in, 0, sizeof in);"]
    for v in table.variables:
        if v.lives.struct != "input":
            continue
        start = float(v.start or 0.0)
        if v.lives.angle:
            value = f"({start!r} + 0.1 * k)"
            lines.append(f"        in.{v.lives.path}.x = cos{value};")
            lines.append(f"        in.{v.lives.path}.y = sin{value};")
        else:
            lines.append(f"        in.{v.lives.path} = {start!r} * (1.0 + 0.01 * k) + 0.01 * k;")
    return "\n".join(lines)


#: A program on a scene's C: the check the whole evaluation ends with, on outputs where one
#: the second half gives (MEMBER) is not finite: status 3, every output NaN, Discard.
CHECK_MAIN = r"""
#include "IDENT_scene.c"

int main(void)
{
    IDENT_output out;
    fmu_evaluation evaluation;
    memset(&out, 0, sizeof out);
    out.MEMBER = INFINITY;
    check(&out, &evaluation);
    return !(evaluation.status == FMU_DISCARD && out.status == 3 && isnan(out.MEMBER));
}
"""


@pytest.mark.parametrize("name", ("slider_crank", "leg"))
def test_the_whole_evaluation_checks_the_outputs_the_second_half_gives(name, tmp_path):
    """<id>_evaluate, which an FMU runs where its get reads the effective inertia, checks
    every output it gives, those of the second half among them (an overflow there is
    status 3, not a status 0 beside an infinite J)."""
    required_tool("cc")
    folder = _sources(name, tmp_path)
    table = pipeline.build_table(pipeline.load_scene(paths.SCENES_DIR / f"{name}.toml"))
    core = sorted(folder.glob("core/src/*.c"))
    for member in later_members(table.scene):
        main = tmp_path / f"check_{member}.c"
        main.write_text(CHECK_MAIN.replace("IDENT", name).replace("MEMBER", member))
        subprocess.run(
            ["cc", "-std=c99", "-O1", f"-I{folder / 'scene'}", f"-I{folder / 'core' / 'include'}",
             f"-I{folder / 'core' / 'src'}", "-o", str(tmp_path / "check"), str(main),
             *map(str, core), "-lm"],
            check=True,
        )  # fmt: skip
        done = subprocess.run([str(tmp_path / "check")], capture_output=True, text=True)
        assert done.returncode == 0, f"{name}: {member} not finite passes the check"

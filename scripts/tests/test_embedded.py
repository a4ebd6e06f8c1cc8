"""Scenes on the Cortex-M4F (dyadfmu.embedded): the bundle built as float firmware and run
under QEMU against the same tick program built for this machine in float, its cost per
tick from QEMU's instruction trace, its flash, RAM and stack.

Without the ARM toolchain or QEMU the tests that run firmware skip, except under CI
(CI=true), where they fail: scripts/run-tests installs both.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.embedded import firmware, sizes, stack, study, ticks, trace
from tool_checks import required

FLT_EPSILON = float(np.finfo(np.float32).eps)


# ---------------------------------------------------------------------------
# The cycle table, the map reader and the tick program's source, alone
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "mnemonic, operands, expected",
    [
        ("vdiv.f32", "s0, s1, s2", (14, False)),
        ("vsqrt.f32", "s0, s1", (14, False)),
        ("vfma.f32", "s0, s1, s2", (3, False)),
        ("vmul.f32", "s0, s1, s2", (1, False)),
        ("vldr", "s15, [r3, #4]", (2, False)),
        ("vpush", "{d8-d9}", (5, False)),
        ("ldr.w", "r3, [r2, #4]", (2, False)),
        ("ldrd", "r2, r3, [r0]", (3, False)),
        ("push", "{r4, r5, r6, r7, lr}", (6, False)),
        ("pop", "{r4, r5, pc}", (4, True)),
        ("bne.n", "1a4 <dyad_kin_run+0x20>", (1, True)),
        ("bx", "lr", (1, True)),
        ("bic.w", "r1, r2, #3", (1, False)),  # not a branch, though it starts with b
        ("bls", "2c0 <x>", (1, True)),
        ("sdiv", "r0, r1, r2", (12, False)),
        ("mla", "r0, r1, r2, r3", (2, False)),
        ("adds", "r0, #1", (1, False)),
    ],
)
def test_each_instruction_costs_its_documented_cycles(mnemonic, operands, expected):
    assert trace.cycles_of(mnemonic, operands) == expected


MAP = textwrap.dedent(
    """\
    Archive member included to satisfy reference by file (symbol)

    Discarded input sections

     .text          0x00000000      0x400 /w/shaper_scene.o

    Linker script and memory map

    .text           0x00000000     0x1000
     *(.vectors)
     .vectors       0x00000000       0x1c /w/m4f_start.o
     .text.shaper_evaluate
                    0x00000020      0x300 /w/shaper_scene.o
                    0x00000020                shaper_evaluate
     .text.dyad_kin_run
                    0x00000320       0x80 /w/dyad_kinematics.o
     .text          0x000003a0       0x40 /usr/lib/libm.a(lib_a-s_atan.o)
     .rodata.names  0x000003e0       0x10 /w/shaper_scene.o
    .data           0x20000000        0x8 load address 0x00001000
     .data          0x20000000        0x8 /usr/lib/libc_nano.a(lib_a-impure.o)
    .bss            0x20000008       0x14
     .bss.ticks     0x20000008        0x4 /w/ticks_common.o
     COMMON         0x2000000c       0x10 /w/dyad_kinematics.o
    """
)


def test_the_map_reader_gives_each_owner_its_bytes(tmp_path):
    """Flash counts .text (code and read-only data) and .data's initial values; RAM .data
    and .bss; a discarded section counts nowhere."""
    path = tmp_path / "firmware.map"
    path.write_text(MAP, encoding="utf-8")
    found = sizes.read_map(path, ("shaper_scene", "dyad_kinematics"))
    assert found.flash == {"scene": 0x300 + 0x80 + 0x10, "libraries": 0x40 + 0x8, "port": 0x1C}
    assert found.ram == {"scene": 0x10, "libraries": 0x8, "port": 0x4}
    assert found.members == {"libm.a(lib_a-s_atan.o)", "libc_nano.a(lib_a-impure.o)"}


CALL_GRAPH = textwrap.dedent(
    """\
    graph: { title: "scene.c"
    node: { title: "scene_evaluate" label: "scene_evaluate\\nscene.c:9:6\\n48 bytes (static)" }
    node: { title: "scene.c:kinematics" label: "kinematics\\nscene.c:3:1\\n300 bytes (static)" }
    node: { title: "scene.c:fail" label: "fail\\nscene.c:5:1\\n24 bytes (static)" }
    node: { title: "snprintf" label: "snprintf\\nstdio.h:266:5" shape : ellipse }
    node: { title: "dyad_solve" label: "dyad_solve\\ndyad.h:10:5" shape : ellipse }
    edge: { sourcename: "scene_evaluate" targetname: "scene.c:kinematics" }
    edge: { sourcename: "scene_evaluate" targetname: "scene.c:fail" }
    edge: { sourcename: "scene.c:fail" targetname: "snprintf" }
    edge: { sourcename: "scene.c:kinematics" targetname: "dyad_solve" }
    }
    """
)
CORE_GRAPH = textwrap.dedent(
    """\
    graph: { title: "core.c"
    node: { title: "dyad_solve" label: "dyad_solve\\ncore.c:1:5\\nFRAME bytes (KIND)" }
    }
    """
)


def _core(frame: int, kind: str) -> str:
    return CORE_GRAPH.replace("FRAME", str(frame)).replace("KIND", kind)


def test_the_stack_bound_is_the_costliest_chain_of_frames(tmp_path):
    """Frames add along a chain of calls across objects; a function no object defines is
    named, not counted; a frame GCC cannot bound leaves no bound."""
    scene, core = tmp_path / "scene.ci", tmp_path / "core.ci"
    scene.write_text(CALL_GRAPH, encoding="utf-8")
    core.write_text(_core(400, "static"), encoding="utf-8")
    bound = stack.deepest([scene, core], "scene_evaluate")
    assert bound == stack.StackBound(48 + 300 + 400, ("scene_evaluate", "kinematics", "dyad_solve"),
                                     ("snprintf",))  # fmt: skip
    core.write_text(_core(16, "static"), encoding="utf-8")
    assert stack.deepest([scene, core], "scene_evaluate").bytes == 48 + 300 + 16
    core.write_text(_core(16, "dynamic"), encoding="utf-8")
    assert stack.deepest([scene, core], "scene_evaluate").bytes is None


def _blocks(member: str = "crank_omega") -> ticks.Blocks:
    inputs = (
        ticks.Member("crank.angle", "crank_dir", "rad", 0.5, True, True),
        ticks.Member("crank.omega", member, "rad/s", 3.0, False, True),
        ticks.Member("slider.mass", "slider_mass", "kg", 12.0, False, False),
    )
    outputs = (ticks.Member("crank.torque", "crank_torque", "N.m", None, False, False),)
    return ticks.Blocks("shaper", inputs, outputs)


def test_the_tick_table_holds_the_inputs_exactly():
    """Every input as a hexadecimal literal that reads back to the same double; an angle
    as its cosine and sine; an input not given at its start value."""
    angle = np.array([0.1, 2.0])
    text = ticks.source(_blocks(), {"crank.angle": angle, "crank.omega": 7.25}, 2)
    row = [np.cos(0.1), np.sin(0.1), 7.25]
    assert "{" + ", ".join(float(v).hex() for v in row) + "}" in text
    assert f"in->slider_mass = {(12.0).hex()};" in text
    assert "shaper_evaluate(&in, &out, &evaluation);" in text


def test_a_scene_file_turns_its_first_crank_or_moves_what_is_asked():
    """Without ranges the first angle input turns once from its start; a range moves its
    input from MIN to MAX; an input the scene does not have is refused with the list."""
    turned = ticks.swept_inputs(_blocks(), {}, 5)
    assert list(turned) == ["crank.angle"]
    np.testing.assert_allclose(turned["crank.angle"], np.linspace(0.5, 0.5 + 2 * np.pi, 5))
    moved = ticks.swept_inputs(_blocks(), {"crank.omega": (1.0, 3.0)}, 3)
    np.testing.assert_array_equal(moved["crank.omega"], [1.0, 2.0, 3.0])
    with pytest.raises(ticks.EmbeddedError, match="not an input of shaper; its inputs are: "):
        ticks.swept_inputs(_blocks(), {"slider.mass": (1.0, 2.0)}, 3)  # a parameter
    no_angle = ticks.Blocks("lift", _blocks().inputs[1:], _blocks().outputs)
    with pytest.raises(ticks.EmbeddedError, match="no angle input to turn: give the motion"):
        ticks.swept_inputs(no_angle, {}, 3)


def test_a_plant_is_refused_by_name():
    """A plant's bundle integrates its motion: a tick program of given motion has nothing
    to evaluate there, and says so before building anything."""
    scene = paths.SCENES_DIR / "slider_crank_motor.toml"
    with pytest.raises(ticks.EmbeddedError, match=r"slider_crank_motor.toml: a plant"):
        ticks.read_blocks(scene)


def test_the_tick_program_refuses_what_it_cannot_write():
    with pytest.raises(ticks.EmbeddedError, match="finite"):
        ticks.source(_blocks(), {"crank.omega": np.array([1.0, np.nan])}, 2)
    with pytest.raises(ticks.EmbeddedError, match="block member"):
        ticks._member(
            {
                "name": "x",
                "member": "a; } int main(",
                "unit": "-",
                "start": 0.0,
                "angle": False,
                "input": True,
            }
        )


# ---------------------------------------------------------------------------
# Firmware under QEMU
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def shaper(tmp_path_factory):
    missing = firmware.missing_tools()
    required(not missing, f"missing {', '.join(missing)}")
    return study.run_scene("shaper", tmp_path_factory.mktemp("shaper"), count=120, traced=6)


def _angles(result: study.SceneResult) -> int:
    return sum(name.endswith(".angle") for name in result.outputs)


def test_the_m4f_gives_the_hosts_float_outputs(shaper):
    """Every tick's torque and bearing loads bit for bit as this machine's float build
    gives them (the same operations, no contraction on either side); the angles, which
    come from each C library's own atan2f, within one FLT_EPSILON of their peak."""
    c = shaper.against_host
    assert c.same_status
    assert c.identical >= c.outputs - _angles(shaper), c
    assert c.worst <= 1.0, c
    assert c.worst == 0.0 or c.worst_output.endswith(".angle"), c


def test_gccs_default_contraction_moves_the_outputs(shaper):
    """With -ffp-contract=fast (GCC's default for the M4F) the loads differ from the host's:
    the reason the firmware's build turns it off. They stay close: within 64 FLT_EPSILON."""
    c = shaper.contracted
    assert c.same_status
    assert c.identical < c.outputs - _angles(shaper)
    assert 0 < c.worst <= 64, c


def test_the_shaper_tick_fits_a_fifth_of_a_millisecond_in_float(shaper):
    """The float build computes in float alone: no instruction of a tick in libgcc's
    software double (only the reasons of a refusal, which format doubles, link it); its
    estimated cycles are at most 20 % of a 1 ms tick at 168 MHz."""
    assert all(c.soft_float == 0 for c in shaper.costs)
    assert all(2_000 < c.instructions < c.cycles for c in shaper.costs)
    assert shaper.cycles_share() <= 0.20


def test_the_shaper_fits_a_small_part(shaper):
    """Flash, RAM and stack of the scene and the core, and of what they pull in."""
    assert 4_000 < shaper.sizes.flash["scene"] < 64 * 1024
    assert shaper.sizes.flash["libraries"] < 16 * 1024
    assert shaper.sizes.ram["scene"] == 0  # no static state
    assert 256 < shaper.stack < 8 * 1024
    d = shaper.derivative_sizes
    assert d is not None and d.flash["scene"] > shaper.sizes.flash["scene"]
    assert shaper.derivative_stack > shaper.stack


def test_the_call_graphs_bound_holds_the_painted_stack(shaper):
    """The call graph's chain from shaper_evaluate holds its frames, those of the core's
    kinematics among them; the painted stack adds the tick program's frame and the C
    library's (atan2f's, named outside the bound) and is no smaller."""
    bound = shaper.stack_bound
    assert bound.chain[0] == "shaper_evaluate" and len(bound.chain) >= 2
    assert "atan2f" in bound.outside
    assert 1_000 < bound.bytes <= shaper.stack
    assert shaper.derivative_stack_bound.bytes > bound.bytes


def test_a_refusal_says_why_without_stdio(tmp_path):
    """A firmware built with DYAD_SCENE_TERSE links no printf, yet a refused tick still
    says why: the reason's words and names, each number as '?'. The lift's ram pushed far
    beyond its reach cannot assemble; the ticks before it answer."""
    missing = firmware.missing_tools()
    required(not missing, f"missing {', '.join(missing)}")
    scene = paths.SCENES_DIR / "lift.toml"
    blocks = ticks.read_blocks(scene)
    bundle = ticks.write_bundle(scene, tmp_path / "bundle")
    source = tmp_path / "lift_ticks.c"
    source.write_text(ticks.source(blocks, {"ram.position": np.array([0.55, 50.0])}, 2))
    for built in (
        firmware.build_host(bundle, source, tmp_path / "host"),
        firmware.build_m4f(bundle, source, tmp_path / "m4f"),
    ):
        run = firmware.parse(firmware.run(built), len(blocks.outputs))
        assert list(run.status) == [0, 4]
        assert np.isnan(run.values[1]).all() and np.isfinite(run.values[0]).all()
        (reason,) = run.reasons
        assert "cannot assemble at this driver position" in reason and "?" in reason, reason
        assert "%" not in reason
    linked = sizes.read_map(built.map_file, built.scene_objects).members
    assert not {m for m in linked if "printf" in m}, linked

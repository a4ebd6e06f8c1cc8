"""A scene's batch evaluation, <identifier>_evaluate_many (an FMU's: a controller's
bundle leaves it out, as it does the halves of evaluate).

Many samples in columns: the scene's evaluation written once more as one sample of a
loop that the compiler vectorises (src/dyad_lanes.h): the same
terms (emit/scene_c.py writes them with its Plan's `lane`), the core's calls replaced by
their twins that count their failed checks instead of returning early, so that a sample
none of whose checks failed has exactly the outputs evaluate gives it. A sample with a
failed check is flagged, and its caller asks evaluate for its status and reason. An
angle's atan2, a call, is taken after the loop from the direction the loop leaves.

A mechanism whose drivers are cranks, rams or cylinders (dyad_cylinder_lane).
"""

from __future__ import annotations

from dyadgen.emit import kinematics_c
from dyadgen.model import Scene

#: samples per pass of the vector loop: the directions of their angles wait on the stack
CHUNK = 32


def batch_supported(scene: Scene) -> bool:
    """Whether the scene has a batch evaluation: a mechanism without states."""
    return scene.internal() and not scene.forward()


#: The most closed-form stages (dyads and cylinders) of a scene whose lanes the build
#: schedules for register pressure (scheduled_lanes).
SCHEDULED_STAGES = 2


def scheduled_lanes(scene: Scene) -> bool:
    """Whether the build has GCC schedule the scene's C before register allocation
    (-fschedule-insns -fsched-pressure; scene.py --cmake-info says "scheduled", as it does
    for a generic dyad, whose variable table holds its type's lanes): a scene with a batch
    evaluation of at most SCHEDULED_STAGES. A lane's loop body holds the whole mechanism,
    and so scheduled it spills far fewer registers (the shaper's lanes without the bounds
    alone, 512 samples: baseline 104 -> 83 ns a sample, AVX2 53 -> 42), but GCC's time for
    it grows faster than the body: the scene C of the built-in shaper and the studies'
    copies of the engine, the shaper and the tipper (its dyad and cylinder) took 1.06 to
    1.45 times as long, the excavator's study copy (a dyad and three cylinders, its
    parameters variables) 2.4 times (79 -> 189 s), which a study's user would wait for."""
    stages = len(scene.dyads) + len(kinematics_c.cylinders(scene))
    return batch_supported(scene) and stages <= SCHEDULED_STAGES


def batch_include(scene: Scene) -> str:
    """The lanes of the scene's dyad types and of its cylinders (src/dyad_lanes.h), for
    the top of its C."""
    types = sorted({d.type for d in scene.dyads})
    types += ["CYLINDER"] if kinematics_c.cylinders(scene) else []
    return "".join(f"#define DYAD_LANES_{t}\n" for t in types) + '#include "dyad_lanes.h"\n'


def lane_function(ident: str, name: str, declarations: list[str], body: list[str]) -> list[str]:
    """One sample's evaluation: the count of its failed checks, its outputs in `out`
    but for its angles, whose directions it leaves in `turn`."""
    head = f"DYAD_CLOSED_FORM dyad_real {name}("
    return [
        f"{head}const {ident}_input* in, {ident}_output* out,",
        f"{' ' * len(head)}dyad_vec2* turn)",
        "{",
        "    dyad_real bad = 0;",
        *declarations,
        "    (void)in;",
        "    (void)turn;",
        *body,
        "}",
    ]


def block_reals(scene: Scene) -> tuple[list[tuple[str, bool]], list[str]]:
    """The members of the input block (with whether each is an angle's unit vector, two
    reals) and the real members of the output block: the lanes' columns, where each
    real's column is its place in its block."""
    inputs = [(i.member, i.angle) for i in scene.inputs]
    inputs += [(p.member, False) for p in scene.parameters() if p.tunable]
    return inputs, [o.member for o in scene.outputs if not o.integer]


def many_function(scene: Scene, name: str, lane: str, angles: list[str]) -> list[str]:
    """<identifier>_<name>: the lane over the samples of the lanes' columns, then the
    angles of `angles` (output members, in the order of the lane's `turn`)."""
    ident, upper = scene.identifier, scene.identifier.upper()
    inputs, outputs = block_reals(scene)

    def place(block: str, m: str) -> str:
        return f"offsetof({ident}_{block}, {m}) / sizeof(dyad_real)"

    out = f"{upper}_LANE_INPUTS + "
    bad = f"{upper}_LANE_INPUTS + {upper}_LANE_OUTPUTS"
    head = f"DYAD_CLOSED_FORM void {name}_in("
    lines = [
        f"{head}size_t count, dyad_real (*restrict lanes)[{upper}_LANES],",
        f"{' ' * len(head)}const unsigned char* wanted)",
        "{",
        "    size_t i;",
        "    for (i = 0; i < count; ++i) {",
        f"        {ident}_input in;",
        f"        {ident}_output out;",
        f"        dyad_vec2 turn[{max(len(angles), 1)}];",
    ]
    for m, angle in inputs:
        if angle:
            lines.append(f"        in.{m}.x = lanes[{place('input', m)}][i];")
            lines.append(f"        in.{m}.y = lanes[{place('input', m)} + 1][i];")
        else:
            lines.append(f"        in.{m} = lanes[{place('input', m)}][i];")
    lines.append(f"        lanes[{bad}][i] = {lane}(&in, &out, turn);")
    for m in outputs:
        if m in angles:  # its direction, for the loop below: x in its column, y after bad's
            k = angles.index(m)
            lines.append(f"        lanes[{out}{place('output', m)}][i] = turn[{k}].x;")
            lines.append(f"        lanes[{bad} + {1 + k}][i] = turn[{k}].y;")
        else:
            lines.append(f"        lanes[{out}{place('output', m)}][i] = out.{m};")
    lines.append("    }")
    for k, m in enumerate(angles):
        column = f"lanes[{out}{place('output', m)}]"
        lines += [
            f"    if (wanted == NULL || wanted[{place('output', m)}]) {{",
            "        for (i = 0; i < count; ++i) {",
            f"            {column}[i] = dyad_atan2(lanes[{bad} + {1 + k}][i], {column}[i]);",
            "        }",
            "    }",
        ]
    if not angles:
        lines.append("    (void)wanted;")
    return [*lines, "}", "", *_dispatch(scene, name)]


def _dispatch(scene: Scene, name: str) -> list[str]:
    """<identifier>_<name>_baseline and, where the compiler can target them and ask the
    CPU for them (src/dyad_lanes.h), <identifier>_<name>_avx2 and _avx512, each <name>_in;
    <identifier>_<name>_at_most, which takes the widest the CPU runs up to a cap, and
    <identifier>_<name>, the widest."""
    ident, upper = scene.identifier, scene.identifier.upper()
    columns = f"dyad_real (*restrict lanes)[{upper}_LANES]"

    def function(variant: str, body: list[str], prefix: str = "", cap: bool = False) -> list[str]:
        head = f"{prefix}void {ident}_{name}{variant}("
        indent = " " * len(head)
        params = [f"size_t count, {columns},", "const unsigned char* wanted)"]
        if cap:
            params = ["dyad_lanes_isa cap, size_t count,", f"{columns},", params[1]]
        return [head + params[0], *(indent + p for p in params[1:]), "{", *body, "}"]

    call = f"{name}_in(count, lanes, wanted);"
    lines = [*function("_baseline", [f"    {call}"]), ""]
    cases = []
    for isa, target in (("avx512", "AVX512"), ("avx2", "AVX2")):
        lines += [
            f"#if DYAD_LANES_HAVE_{target}",
            *function(f"_{isa}", [f"    {call}"], f"DYAD_LANES_{target}_TARGET "),
            "#endif",
            "",
        ]
        cases += [
            f"#if DYAD_LANES_HAVE_{target}",
            f"    case DYAD_LANES_{target}:",
            f"        {ident}_{name}_{isa}(count, lanes, wanted);",
            "        return;",
            "#endif",
        ]
    at_most = [
        "    switch (dyad_lanes_widest(cap)) {",
        *cases,
        "    default:",
        f"        {ident}_{name}_baseline(count, lanes, wanted);",
        "    }",
    ]
    widest = [f"    {ident}_{name}_at_most(DYAD_LANES_AVX512, count, lanes, wanted);"]
    return [
        *lines,
        *function("_at_most", at_most, cap=True),
        "",
        *function("", widest),
    ]


def layout_check(scene: Scene) -> list[str]:
    """That the blocks are reals alone, the output's status last: each real has a column."""
    ident, upper = scene.identifier, scene.identifier.upper()
    real = "sizeof(dyad_real)"
    return [
        "/* the lanes' columns are the blocks' reals: the blocks hold nothing else, but for",
        " * the output's status, last */",
        f"typedef char {ident}_lanes_are_the_blocks",
        f"    [sizeof({ident}_input) == {upper}_LANE_INPUTS * {real} &&",
        f"             offsetof({ident}_output, status) == {upper}_LANE_OUTPUTS * {real}",
        "         ? 1",
        "         : -1];",
    ]


def prototypes(scene: Scene, first: bool, bare: bool, angles: int) -> list[str]:
    """The header's declarations of <identifier>_lanes (and, with `first`, of
    <identifier>_lanes_first; with `bare`, of <identifier>_lanes_bare), with the numbers
    of their columns; `angles`: the angle outputs, whose directions take a column more
    each while a call runs."""
    ident = scene.identifier
    inputs, outputs = block_reals(scene)
    reals = sum(2 if angle else 1 for _, angle in inputs)
    upper = ident.upper()
    names = ["lanes", *(["lanes_first"] if first else []), *(["lanes_bare"] if bare else [])]
    lines = [
        f"/* {ident}_evaluate at `count` samples (at most {upper}_LANES), in columns:",
        " * lanes[j][i] is real j of sample i. The input block's reals come first, in its order",
        " * (an angle as the .x and .y of its unit vector), then the output block's (not its",
        f" * status), then the count of sample i's failed checks; {upper}_LANE_COLUMNS columns",
        " * in all, the last ones scratch. Where that count is 0, sample i's outputs are what",
        f" * {ident}_evaluate gives, bit for bit (status 0); elsewhere they mean nothing, and",
        f" * {ident}_evaluate says why. Every check is made without a branch, so that the loop",
        " * over samples vectorises. `wanted`, NULL or a flag per output in its block's order:",
        " * an output not wanted may be left out (an angle's atan2). _first: as",
        f" * {ident}_evaluate_first. _bare: as _first (or as the whole where there are no",
        " * halves) with the reactions' bounds (each dyad's amplification and the",
        " * mechanism's) NaN, the statuses the same. _baseline: compiled for the platform's",
        " * baseline; _avx2 and _avx512 (x86-64 with GCC or Clang only): for a CPU with AVX2,",
        " * with AVX-512",
        " * (no fused multiply-add: the same results bit for bit); _at_most:",
        " * the widest this CPU runs up to `cap` (dyad_lanes_isa, dyadfmu/types.h);",
        " * without a suffix, the widest this CPU runs. */",
        f"#define {upper}_LANES {CHUNK}",
        f"#define {upper}_LANE_INPUTS {reals}",
        f"#define {upper}_LANE_OUTPUTS {len(outputs)}",
        f"#define {upper}_LANE_COLUMNS {reals + len(outputs) + 1 + angles}",
    ]
    for name in names:
        for variant in ("", "_baseline", "_avx2", "_avx512", "_at_most"):
            head = f"void {ident}_{name}{variant}("
            cap = "dyad_lanes_isa cap, " if variant == "_at_most" else ""
            lines += [
                f"{head}{cap}size_t count, dyad_real (*lanes)[{upper}_LANES],",
                f"{' ' * len(head)}const unsigned char* wanted);",
            ]
    return lines

"""The tick program of a scene: its bundle's ``<id>_evaluate`` called once a tick over a
table of inputs compiled into the program, every output written as its bit pattern.

The same C source runs on the host (``src/examples/firmware/host_port.c``) and on the
Cortex-M4F under QEMU (``m4f_start.c``), so that the two agree or differ by what their
compilers and C libraries do, nothing else. An angle input goes in as its unit vector,
computed here in double and rounded by the C cast of each port alike.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import paths

__all__ = [
    "Member",
    "Blocks",
    "EmbeddedError",
    "read_blocks",
    "swept_inputs",
    "write_bundle",
    "source",
]

#: A member path of a block as the generator names it (C identifiers joined by dots).
_MEMBER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class EmbeddedError(Exception):
    """A scene, a tool or a run that the embedded build cannot use, in one line."""


@dataclass(frozen=True)
class Member:
    """A member of the input or output block of a scene's C."""

    name: str  # the FMU variable's name
    member: str  # its path in the block
    unit: str
    start: float | None
    angle: bool  # an angle input, kept as its unit vector
    input: bool  # an input (not a tunable parameter)


@dataclass(frozen=True)
class Blocks:
    """The input and output blocks of a scene's bundle."""

    identifier: str
    inputs: tuple[Member, ...]
    outputs: tuple[Member, ...]


def _generator(scene: Path, *options: str) -> str:
    command = [sys.executable, str(paths.GENERATOR), str(scene), *options]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise EmbeddedError(f"{scene}: {(done.stderr or done.stdout).strip()}")
    return done.stdout


def _member(entry: dict) -> Member:
    if not _MEMBER.fullmatch(entry["member"]):
        raise EmbeddedError(f"the generator named a block member {entry['member']!r}")
    return Member(
        entry["name"],
        entry["member"],
        entry["unit"],
        entry["start"],
        entry["angle"],
        entry["input"],
    )


def read_blocks(scene: Path) -> Blocks:
    """The blocks of the scene's C (modelDescription/scene.py --blocks); a plant, whose
    bundle integrates its motion, refused."""
    data = json.loads(_generator(scene, "--blocks"))
    identifier = data["identifier"]
    if not _IDENTIFIER.fullmatch(identifier):
        raise EmbeddedError(f"{identifier!r} is not a scene identifier")
    if data["plant"]:
        raise EmbeddedError(
            f'{scene}: a plant (dynamics = "forward"): its bundle integrates its motion '
            "over a step, and a tick program evaluates a mechanism at given motion"
        )
    return Blocks(
        identifier,
        tuple(_member(e) for e in data["inputs"]),
        tuple(_member(e) for e in data["outputs"]),
    )


def write_bundle(scene: Path, out: Path, derivatives: bool = False) -> Path:
    """The scene's bundle for firmware written into out/<identifier>/ (that folder)."""
    _generator(scene, "--bundle", str(out), *(["--with-derivatives"] if derivatives else []))
    folders = [p for p in Path(out).iterdir() if (p / "scene").is_dir()]
    if len(folders) != 1:
        raise EmbeddedError(f"{out}: expected one bundle, found {len(folders)}")
    return folders[0]


def swept_inputs(
    blocks: Blocks, ranges: dict[str, tuple[float, float]], count: int
) -> dict[str, np.ndarray]:
    """Each input of `ranges` (name -> (min, max)) from its min to its max over `count`
    ticks; without ranges, the scene's first angle input one turn from its start. The
    other inputs keep their start values."""
    inputs = {m.name: m for m in blocks.inputs if m.input}
    if not ranges:
        angle = next((m for m in inputs.values() if m.angle), None)
        if angle is None:
            raise EmbeddedError(
                f"{blocks.identifier} has no angle input to turn: give the motion with --range "
                f"INPUT MIN MAX (its inputs: {', '.join(inputs) or 'none'})"
            )
        ranges = {angle.name: (angle.start, angle.start + 2.0 * np.pi)}
    for name, (low, high) in ranges.items():
        if name not in inputs:
            raise EmbeddedError(
                f"--range {name}: not an input of {blocks.identifier}; its inputs are: "
                f"{', '.join(inputs) or 'none'}"
            )
        if not (np.isfinite(low) and np.isfinite(high)):
            raise EmbeddedError(f"--range {name} {low} {high}: the range must be finite")
    return {name: np.linspace(low, high, count) for name, (low, high) in ranges.items()}


def _literal(value: float) -> str:
    """A C99 hexadecimal floating literal: the double exactly."""
    value = float(value)
    if not np.isfinite(value):
        raise EmbeddedError(f"a tick's input is {value}: the tick table takes finite inputs")
    return value.hex()


def _columns(blocks: Blocks, inputs: dict[str, np.ndarray], ticks: int) -> list[np.ndarray]:
    """The table's columns: each input the table gives (an angle as its cosine and sine)."""
    columns = []
    for m in blocks.inputs:
        if m.name not in inputs:
            continue
        values = np.broadcast_to(np.asarray(inputs[m.name], dtype=float), (ticks,))
        columns += [np.cos(values), np.sin(values)] if m.angle else [values]
    return columns


def _fill_lines(blocks: Blocks, inputs: dict[str, np.ndarray]) -> tuple[list[str], list[str]]:
    """(the statements setting the start values, those setting tick k's from the table)."""
    start, per_tick, column = [], [], 0
    for m in blocks.inputs:
        if m.name in inputs:
            if m.angle:
                per_tick.append(
                    f"    in->{m.member} = dyad_vec2_make((dyad_real)ticks_inputs[k][{column}], "
                    f"(dyad_real)ticks_inputs[k][{column + 1}]);"
                )
                column += 2
            else:
                per_tick.append(f"    in->{m.member} = ticks_inputs[k][{column}];")
                column += 1
        elif m.angle:
            c, s = np.cos(m.start), np.sin(m.start)
            start.append(
                f"    in->{m.member} = dyad_vec2_make((dyad_real){_literal(c)}, "
                f"(dyad_real){_literal(s)});"
            )
        else:
            start.append(f"    in->{m.member} = {_literal(m.start)};")
    return start, per_tick


def _seed(blocks: Blocks) -> str:
    """The statement seeding the derivative along the block's first input."""
    first = next((m for m in blocks.inputs if m.input), None)
    if first is None:
        raise EmbeddedError(f"{blocks.identifier} has no input to take a derivative along")
    if first.angle:  # d(cos, sin)/d angle = (-sin, cos)
        m = first.member
        return f"seed.{m} = dyad_vec2_make(-in.{m}.y, in.{m}.x);"
    return f"seed.{first.member} = 1.0;"


def _evaluation(blocks: Blocks, derivative: bool) -> tuple[str, str]:
    """(the declarations, the call) of a tick's evaluation."""
    ident = blocks.identifier
    if not derivative:
        return "", f"{ident}_evaluate(&in, &out, &evaluation);"
    declarations = f"    {ident}_input seed;\n    {ident}_output rate;\n"
    call = (
        f"memset(&seed, 0, sizeof seed);\n        {_seed(blocks)}\n        "
        f"{ident}_derivative(&in, &seed, &out, &rate, &evaluation);"
    )
    return declarations, call


def source(
    blocks: Blocks, inputs: dict[str, np.ndarray], ticks: int, derivative: bool = False
) -> str:
    """<identifier>_ticks.c: `ticks` ticks over `inputs` (an input's name -> its values per
    tick, or one value for all); the inputs not given keep their start values. With
    `derivative`, each tick calls <identifier>_derivative along the first input (the
    bundle must have it) and writes the outputs it gives."""
    ident = blocks.identifier
    declarations, call = _evaluation(blocks, derivative)
    columns = _columns(blocks, inputs, ticks)
    start, per_tick = _fill_lines(blocks, inputs)
    rows = ",\n".join(
        "    {" + ", ".join(_literal(c[k]) for c in columns) + "}" for k in range(ticks)
    )
    table = (
        f"static const double ticks_inputs[{ticks}][{len(columns)}] = {{\n{rows}\n}};\n"
        if columns
        else ""
    )
    writes = "\n".join(f"    ticks_write_bits(out->{m.member});" for m in blocks.outputs)
    return _TEMPLATE.format(
        ident=ident,
        ticks=ticks,
        table=table,
        start="\n".join(start) or "    (void)in;",
        per_tick="\n".join(per_tick) or "    (void)in;\n    (void)k;",
        writes=writes,
        declarations=declarations,
        call=call,
    )


_TEMPLATE = """\
/* {ident}_ticks.c: {ident}_evaluate once a tick over a table of inputs, every output
 * written as its bit pattern. Generated by dyadfmu.embedded; do not edit. */
#include <string.h>

#include "{ident}_scene.h"
#include "ticks_port.h"

#define TICKS {ticks}L

{table}
static void start_values({ident}_input* in)
{{
{start}
}}

static void fill(long k, {ident}_input* in)
{{
{per_tick}
}}

static void emit(long k, const {ident}_output* out, const fmu_evaluation* evaluation)
{{
    ticks_write_tick(k, out->status);
{writes}
    ticks_write_end_of_line();
    if (evaluation->status != FMU_OK) {{
        ticks_write("reason ");
        ticks_write(evaluation->reason);
        ticks_write_end_of_line();
    }}
}}

int ticks_main(void)
{{
    {ident}_input in;
    {ident}_output out;
    fmu_evaluation evaluation;
{declarations}    long k;
    start_values(&in);
    for (k = 0; k < TICKS; ++k) {{
        fill(k, &in);
        ticks_begin(k);
        {call}
        ticks_end(k);
        emit(k, &out, &evaluation);
    }}
    ticks_write_count("stack", ticks_stack_used());
    return 0;
}}
"""

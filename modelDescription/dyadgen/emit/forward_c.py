"""The C of a forward scene's behaviour (dyadgen/forward.py): the parts generated for
the scene's drivers around templates/forward_behaviour.c.in."""

from __future__ import annotations

import functools
from pathlib import Path
from string import Template

from dyadgen.forward import MAX_STEPS, RTOL_MIN, STEP_SHARE, behaviour_parts
from dyadgen.model import Scene

TEMPLATE = Path(__file__).parent / "templates" / "forward_behaviour.c.in"


@functools.cache
def _template() -> Template:
    return Template(TEMPLATE.read_text(encoding="utf-8"))


def forward_behaviour(scene: Scene) -> list[str]:
    """The behaviour's C lines: its constants, the parts of the scene's drivers, the
    template."""
    drivers, size, states, parts = behaviour_parts(scene)
    ident = scene.identifier
    head = [
        f"enum {{ PLANT_DRIVERS = {drivers}, PLANT_SIZE = {size}, PLANT_STATES = {states}, "
        f"PLANT_MAX_STEPS = {MAX_STEPS} }};",
        "/* How closely a step that fails is located, in parts of the communication step. */",
        "#define PLANT_LOCATE_TOLERANCE 1e-10",
        "/* The share of solver.rtol and solver.atol each internal step's error is held to,",
        " * so that the errors of thousands of steps stay within them (the free four-bar's",
        " * energy over 100 s within 4.2e-10 of its exchange at rtol 1e-10). */",
        f"#define PLANT_STEP_SHARE {STEP_SHARE!r}",
        "/* ... but no tighter than a few units of round-off. */",
        f"#define PLANT_RTOL_MIN {RTOL_MIN!r}",
        "",
    ]
    return head + parts + _template().substitute(ident=ident).splitlines() + [""]

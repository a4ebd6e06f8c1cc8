"""The documentation page of an FMU (documentation/index.html), one template per kind of
model (templates/*.html, string.Template). Every text of the table or the scene is
escaped for HTML (textsafe.html) before it is substituted; the templates hold the
prose."""

from __future__ import annotations

import functools
from pathlib import Path
from string import Template

from dyadgen import textsafe
from dyadgen.dyadtypes import MAY_BE_ZERO, PAIRS, TYPE_NOTES
from dyadgen.emit.xmltext import num, settings_of
from dyadgen.model import Attachment, Crank, Param, Scene
from dyadgen.table import Table, Variable

TEMPLATES = Path(__file__).resolve().parent / "templates"
h = textsafe.html


@functools.cache
def template(name: str) -> Template:
    """A template file of templates/."""
    return Template((TEMPLATES / name).read_text(encoding="utf-8"))


@functools.cache
def stylesheet() -> str:
    """The style every page embeds (templates/style.css)."""
    return (TEMPLATES / "style.css").read_text(encoding="utf-8")


def _fmt_bounds(v: Variable) -> str:
    if v.min is None and v.max is None:
        return ""
    lo = ("(" if v.min_exclusive else "[") if v.min is not None else "("
    hi = (")" if v.max_exclusive else "]") if v.max is not None else ")"
    lo_v = num(v.min) if v.min is not None else "-inf"
    hi_v = num(v.max) if v.max is not None else "inf"
    return f"{lo}{lo_v}, {hi_v}{hi}"


def _start_text(v: Variable) -> str:
    """The start value as the model descriptions write it; none for an output."""
    if v.start is None:
        return ""
    return str(int(v.start)) if v.type == "Enumeration" else num(v.start)


def variable_rows(table: Table) -> str:
    """The table of every variable."""
    o = [
        "<table>",
        "<tr><th>vr</th><th>name</th><th>causality</th><th>type</th><th>unit</th>"
        "<th>start</th><th>range</th><th>description</th></tr>",
    ]
    for v in table.variables:
        start = _start_text(v)
        o.append(
            f'<tr><td class="num">{v.vr}</td><td><code>{h(v.name)}</code></td>'
            f"<td>{v.causality}</td><td>{v.type}</td><td>{h(v.unit or '-')}</td>"
            f'<td class="num">{start}</td><td class="num">{h(_fmt_bounds(v))}</td>'
            f"<td>{h(v.description)}</td></tr>"
        )
    o.append("</table>")
    return "\n".join(o)


def settings_section(table: Table) -> str:
    """A section per setting of the FMU layer: its items and what each does."""
    parts = []
    for s in settings_of(table):
        rows = "".join(
            f'<tr><td class="num">{i.value}</td><td><code>{h(i.name)}</code></td>'
            f"<td>{h(i.description)}</td></tr>"
            for i in s.items
        )
        parts.append(
            f"<h2><code>{h(s.name)}</code></h2>\n<p>{h(s.description)}. A fixed parameter of "
            f"declared type <code>{h(s.type_name)}</code>, set through <code>fmi2SetInteger</code>"
            f" or <code>fmi3SetInt64</code>; any other value is refused with Error.</p>\n"
            f"<table><tr><th>value</th><th>item</th><th>doStep</th></tr>{rows}</table>"
        )
    return "\n".join(parts)


def page(name: str, table: Table, **values: object) -> str:
    """Template `name` filled with the table's identity, its variables (the table alone, or
    the whole section) and `values` (already HTML)."""
    identity = template("identity.html").substitute(
        identifier=h(table.identifier), token=h(table.token), table_file=h(table.path.name)
    )
    variables = variable_rows(table)
    # the Variables section the drive's and the dyads' pages share (templates/variables.html)
    section = template("variables.html").substitute(variables=variables).removesuffix("\n")
    return template(name).substitute(
        css=stylesheet(),
        identity=identity,
        identifier=h(table.identifier),
        description=h(table.description),
        variables=variables,
        variable_section=section,
        settings=settings_section(table),
        **values,
    )


def dyad_page(table: Table) -> str:
    """The page of a generic dyad FMU."""
    t = table.type
    d_m, e, d_n = PAIRS[t]
    conditioning, singular, typical = TYPE_NOTES[t]
    guides = []
    if d_m == "T":
        guides.append("<code>i_k</code> (input <code>guide_k.angle</code>) at D_m")
    if e == "T":
        guides.append("<code>i_m</code> (link m itself) at E")
    if d_n == "T":
        guides.append("<code>i_p</code> (input <code>guide_p.angle</code>) at D_n")
    zero = [f"l_{g}" for g, ok in zip("mn", MAY_BE_ZERO[t], strict=True) if ok]
    sliders = [v.name for v in table.of("input") if v.name.endswith(".length")]
    sliding = ""
    if sliders:
        sliding = (
            "\n<p>Because the pair E slides along link m, the length l_m = |D_m E| "
            f"changes with the motion and is an input (<code>{h(sliders[0])}</code>); "
            "every other length is a fixed parameter.</p>"
        )
    return page(
        "dyad.html",
        table,
        type=t,
        d_m=d_m,
        e=e,
        d_n=d_n,
        guides=", ".join(guides) or "none",
        zero=", ".join(zero) or "none",
        sliders=sliding,
        typical=h(typical),
        singular=h(singular),
        conditioning=h(conditioning),
    )


def drive_page(table: Table) -> str:
    """The page of the crank drive (fmu/models/fmu_drive.c)."""
    return page("drive.html", table)


def motor_page(table: Table) -> str:
    """The page of the DC motor (fmu/models/fmu_motor.c)."""
    return page("motor.html", table)


def _param_text(prm: Param) -> str:
    return f"<code>{prm.name}</code>" if prm.tunable else repr(prm.value)


def _attachment_text(att: Attachment, kinds: dict | None = None) -> str:
    """Where a dyad's outer pair sits, in words (`kinds`: each driver's kind by its link)."""
    if att.kind == "frame":
        return "the frame" + (f" (guide at {h(_param_text(att.guide))} rad)" if att.guide else "")
    if att.guide is not None:
        return (
            f"a guide on <code>{h(att.link)}</code> at {h(_param_text(att.guide))} rad from its "
            f"i, through ({h(_param_text(att.at[0]))}, {h(_param_text(att.at[1]))}) m in its frame"
        )
    if att.kind == "external":
        return "an external link whose motion is an input"
    if att.at is None:
        kind = (kinds or {}).get(att.link, "crank")
        return f"the {_DRIVER_POINT[kind]} <code>{h(att.link)}</code>"
    return (
        f"<code>{h(att.link)}</code> at ({h(_param_text(att.at[0]))}, "
        f"{h(_param_text(att.at[1]))}) m in its frame"
    )


#: where a dyad sits on the driver when its table gives no point
_DRIVER_POINT = {"crank": "pin of the crank", "ram": "origin R of the ram", "cylinder": "pin B of"}


def _driver_text(driver: Crank) -> str:
    """A driver's paragraph: what it is and what balances it."""
    name = f"<code>{h(driver.name)}</code>"
    if driver.is_cylinder():
        return (
            f"Cylinder <code>{h(driver.actuator)}</code> between the frame pin A and the pin B "
            f"of {name}, which turns about the frame pivot O; its length is the driver's "
            "coordinate. Its axial force and the reactions at A, B and O follow from the "
            "equilibrium of the link, the barrel and the rod once every dyad is solved."
        )
    if driver.is_ram():
        return (
            f"Ram {name} sliding on a frame guide; its origin R is at its displacement along "
            "the guide. Its actuator force and the guide's normal force and moment follow "
            "from its equilibrium once every dyad is solved."
        )
    return (
        f"Crank {name} about the fixed pivot O; its pin A lies at (length, 0) in its frame. "
        "Its driving torque and the force of the frame at O follow from its equilibrium "
        "once every dyad is solved."
    )


def _scene_sections(scene: Scene) -> dict[str, str]:
    """The parts of a scene's page that depend on its mechanism."""
    loaded = [f"{g} (force)" for g, link in scene.links.items() if link.force]
    loaded += [f"{g} (moment)" for g, link in scene.links.items() if link.moment]
    crank = "".join(f"\n<p>{_driver_text(driver)}</p>" for driver in scene.drivers)
    if len(scene.drivers) > 1:
        crank += (
            "\n<p>With several drivers, the efforts (torques and forces) are M(q) q'' + h: "
            "<code>M.a.b</code> is the inertia matrix (the effort of a per acceleration of b), "
            "each driver's <code>torque0</code> or <code>force0</code> its effort h at zero "
            "acceleration of every driver.</p>"
        )
    kinds = {driver.name: driver.kind for driver in scene.drivers}
    dyads = "".join(
        f"\n<tr><td><code>{h(d.name or '-')}</code></td><td>{d.type}</td>"
        f"<td><code>{h(d.m)}</code></td><td><code>{h(d.n)}</code></td>"
        f"<td>{_attachment_text(d.k, kinds)}</td><td>{_attachment_text(d.p, kinds)}</td></tr>"
        for d in scene.dyads
    )
    baked = [prm for prm in scene.parameters() if not prm.tunable]
    constants = ""
    if baked:
        constants = (
            "\n<h2>Constants</h2>\n<p>Fixed by the scene and compiled in:</p>"
            "\n<table><tr><th>name</th><th>value</th><th>unit</th></tr>"
        )
        constants += "".join(
            f'\n<tr><td><code>{h(prm.name)}</code></td><td class="num">'
            f"{prm.value!r}</td><td>{h(prm.unit or '-')}</td></tr>"
            for prm in baked
        )
        constants += "\n</table>"
    return {
        "loads": h(", ".join(loaded) or "none"),
        "crank": crank,
        "dyads": dyads,
        "constants": constants,
    }


def _driving_inputs(table: Table) -> tuple[str, str]:
    """The inputs that belong to the drivers, named in HTML, and the loads counted."""
    prefixes = tuple(f"{d.driver_name()}." for d in table.scene.drivers)
    driving = [v.name for v in table.of("input") if v.name.startswith(prefixes)]
    loads = len(table.of("input")) - len(driving)
    named = ", ".join(f"<code>{h(name)}</code>" for name in driving)
    rest = {0: "no load", 1: "the active load (1 input)"}.get(
        loads, f"the active loads ({loads} inputs)"
    )
    return named, rest


def _plant_takes(table: Table) -> str:
    """What a plant (dynamics = "forward") takes: its drivers' efforts or motors'
    voltages and its loads; it integrates the motion itself."""
    named, rest = _driving_inputs(table)
    return (
        f"only what drives it ({named}) and {rest}, integrates its drivers' motion inside "
        "each step to the tolerances solver.rtol and solver.atol (a plant: no motion is an "
        "input; through FMI 2 each input may also be given its first derivative, which the "
        "plant follows it along within the steps), and gives that motion"
    )


def _takes(table: Table) -> str:
    """What the FMU takes at every communication point: a mechanism FMU (internal
    kinematics) its driver's motion and its loads alone, solving the links' motion itself;
    another every link's current kinematics and the loads."""
    scene = table.scene
    if not scene.internal():
        return "the links' current kinematics and active loads"
    if scene.forward():
        return _plant_takes(table)
    named, rest = _driving_inputs(table)
    if not scene.crank:
        return (
            f"only its {len(scene.drivers)} drivers' motion ({named}) and {rest}, solves the "
            "links' motion from the drivers' itself (the kinematics are inside: no link's "
            "motion is an input),"
        )
    driver = scene.crank.kind
    return (
        f"only the {driver}'s motion ({named}) and {rest}, solves the links' motion from the "
        f"{driver}'s itself (the kinematics are inside: no link's motion is an input),"
    )


def scene_page(table: Table) -> str:
    """The page of a tailored scene's FMU."""
    scene = table.scene
    n = table.counts()
    return page(
        "scene.html",
        table,
        takes=_takes(table),
        scene_file=h(scene.path.name),
        inputs=n["input"],
        parameters=n["parameter"],
        outputs=n["output"],
        inertia="yes" if scene.inertia else "no",
        gravity="yes" if scene.gravity else "no",
        stop=h(f"{scene.experiment.stop:.6g}"),
        step=h(f"{scene.experiment.step:.6g}"),
        **_scene_sections(scene),
    )

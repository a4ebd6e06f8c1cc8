"""Internal kinematics in a scene's C: the chain's positions, velocities and accelerations
from the driver's motion outwards, one dyad at a time with the core's closed forms
(dyadfmu/kinematics.h), before the kinetostatics run backwards.

The generated function `kinematics` fills one dyad_kin_result per dyad. It takes the
driver's rate and acceleration as arguments, so that the same code also runs at unit
rate and zero acceleration: the velocities it then gives are the velocity ratios
V = dv/dq' of every centre of mass and its accelerations their derivatives dV/dq, from
which the effective inertia at the driver J(q) and dJ/dq follow.
"""

from __future__ import annotations

import math

from dyadgen import textsafe
from dyadgen.model import Attachment, Dyad, Param, Scene, c_num, member
from dyadgen.needs import kin_name, kin_name_of_cylinder

#: the core's failure statuses and the scene status each one reports
FAILURE_TEXT = "0 ok, 1 singular, 3 out of range, 4 cannot assemble"


def _vec(x: str, y: str) -> str:
    return f"dyad_vec2_make({x}, {y})"


def _point(at: tuple[Param, Param]) -> str:
    return _vec(at[0].c(), at[1].c())


def needed_dyads(scene: Scene, solved: list, everything: bool) -> list[Dyad]:
    """The dyads whose kinematics the code needs: those it solves and those whose
    kinematic outputs are wanted (every dyad for the effective inertia), with every dyad
    they hang on."""
    if everything:
        return list(scene.dyads)
    wanted = {d.index for d in solved}
    wanted |= {int(o.source[3:]) for o in scene.outputs if o.source.startswith("kin")}
    owner = {g: d for d in scene.dyads for g in (d.m, d.n)}
    for d in reversed(scene.dyads):
        if d.index in wanted:
            for att in (d.k, d.p):
                if att.kind == "link":
                    wanted.add(owner[att.link].index)
    return [d for d in scene.dyads if d.index in wanted]


class _Mounts:
    """The C expressions of the motion of the external links where a dyad meets them."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.owner = {g: (d, side) for d in scene.dyads for side, g in (("m", d.m), ("n", d.n))}
        self.driver = scene.crank.name

    def carrier(self, link: str) -> tuple[str, str, str, str]:
        """(origin motion, direction, omega, epsilon) of a moving link, in C."""
        if link == self.driver and self.scene.crank.is_cylinder():
            res = f"kin->{kin_name_of_cylinder(self.scene)}"
            return (
                f"&{member(link)}_o",
                f"{res}.link_dir",
                f"{res}.link_omega",
                f"{res}.link_epsilon",
            )
        if link == self.driver:
            c = member(link)
            rate = "0.0" if self.scene.crank.is_ram() else "rate"
            accel = "0.0" if self.scene.crank.is_ram() else "accel"
            return f"&{c}_o", f"{c}_i", rate, accel
        d, side = self.owner[link]
        res = f"kin->{kin_name(d)}.{side}"
        return f"&{res}.d", f"{res}.dir", f"{res}.omega", f"{res}.epsilon"

    def lines(self, att: Attachment, slot: str) -> list[str]:
        """Assignments of k.<slot> (k or p) for one attachment."""
        if att.kind == "frame":
            out = [f"k.{slot}.point = fixed_point({_point(att.at)});"]
            if att.guide is not None:
                out.append(f"k.{slot}.guide = {_unit(att.guide)};")
            return out
        origin, direction, omega, epsilon = self.carrier(att.link)
        at = self.offset(att)
        out = [
            f"k.{slot}.point = dyad_point_on_link({origin}, {direction}, {omega}, {epsilon}, {at});"
        ]
        if att.guide is not None:
            out.append(f"k.{slot}.guide = {_turned(att.guide, direction)};")
            out.append(f"k.{slot}.omega = {omega};")
            out.append(f"k.{slot}.epsilon = {epsilon};")
        return out

    def carried_amplification(self, d: Dyad) -> str | None:
        """The C sum of the amplifications of the earlier dyads whose links carry this
        dyad's mounts (their round-off is its inputs'), or None where the frame and the
        driver carry both: known to the last bit."""
        owners = []
        for att in (d.k, d.p):
            if att.kind == "link" and att.link in self.owner:
                owner = self.owner[att.link][0]
                if owner not in owners:
                    owners.append(owner)
        terms = [f"kin->{kin_name(o)}.amplification" for o in owners]
        if self.scene.crank.is_cylinder() and any(att.kind == "crank" for att in (d.k, d.p)):
            # the link the cylinder turns carries the triangle's round-off
            terms.append(f"kin->{kin_name_of_cylinder(self.scene)}.kin_amplification")
        return " + ".join(terms) if terms else None

    def offset(self, att: Attachment) -> str:
        """The pair's point (a guide's point) in its carrier's frame."""
        if att.at is not None:
            return _point(att.at)
        if att.kind == "crank" and self.scene.crank.is_cylinder():
            params = self.scene.crank.params  # the rod's pin B
            return _vec(params["pin.x"].c(), params["pin.y"].c())
        if att.kind == "crank" and not self.scene.crank.is_ram():
            return _vec(self.scene.crank.params["length"].c(), "0.0")
        return _vec("0.0", "0.0")


def _unit(angle: Param) -> str:
    if angle.tunable:
        return f"dyad_dir_from_angle({angle.c()})"
    return _vec(c_num(math.cos(angle.value)), c_num(math.sin(angle.value)))


def _turned(angle: Param, direction: str) -> str:
    """The direction `direction` turned by `angle`."""
    if angle.is_zero():
        return direction
    if angle.tunable:
        return f"dyad_turn({direction}, dyad_dir_from_angle({angle.c()}))"
    return f"dyad_turn({direction}, {_unit(angle)})"


def _turn(scene: Scene, d: Dyad, side: str) -> str | None:
    """turn_m or turn_n of a locked link: its direction from its guide's (or link m's)."""
    link = scene.links[d.m if side == "m" else d.n]
    if link.translating:
        angle, guide = link.params["angle"], link.attachment().guide
        if angle.tunable or guide.tunable:
            return f"dyad_dir_from_angle({angle.c()} - {guide.c()})"
        return _unit(Param("", angle.value - guide.value, "rad", ""))
    turn = link.params.get("turn")
    return None if turn is None or turn.is_zero() else _unit(turn)


def _dyad_lines(scene: Scene, mounts: _Mounts, d: Dyad) -> list[str]:
    """The kinematics of one dyad: its inputs, the call, the early return."""
    out = [f"/* dyad {d.name or ''} ({d.type}) */"]
    out.append("k = dyad_kin_input_default();")
    out += mounts.lines(d.k, "k") + mounts.lines(d.p, "p")
    for side, g in (("m", d.m), ("n", d.n)):
        params = scene.links[g].params
        if "length" in params:
            out.append(f"k.length_{side} = {params['length'].c()};")
        turn = _turn(scene, d, side)
        if turn is not None:
            out.append(f"k.turn_{side} = {turn};")
        if "com.x" in params:
            out.append(f"k.com_{side} = {_vec(params['com.x'].c(), params['com.y'].c())};")
    if d.branch is not None:
        branch = d.branch
        out.append(
            f"k.branch = {branch.c()} < 0 ? -1 : 1;"
            if branch.tunable
            else f"k.branch = {int(branch.value)};"
        )
    out.append(f"k.singular_threshold = {scene.threshold.c()};")
    carried = mounts.carried_amplification(d)
    if carried is not None:
        out.append(f"k.mount_amplification = {carried};")
    result = f"&kin->{kin_name(d)}"
    out.append(f"if (dyad_kinematics_{d.type.lower()}(&k, {result}) != DYAD_STATUS_OK) {{")
    out.append(f"    *failed = {d.index};")
    out.append(f"    return {result};")
    out.append("}")
    return out


def _cylinder_part_lines(params: dict, target: str) -> list[str]:
    """The barrel's and the rod's centres of mass (and with `target` "cin", where the
    kinematics alone are wanted, nothing more; else their masses and inertias too)."""
    out = []
    for part in ("barrel", "rod"):
        keys = ("com",) if target == "cin" else ("mass", "com", "inertia")
        for key in keys:
            value = params.get(f"{part}.{key}")
            if value is not None and not value.is_zero():
                out.append(f"{target}.{part}.{key} = {value.c()};")
    return out


def cylinder_input_lines(
    scene: Scene, target: str, rates: tuple[str, str], pivot: str
) -> list[str]:
    """The assignments of a dyad_cylinder_input `target`: the frame pins (O's motion
    `pivot`), the pin B, the length and its `rates`, the branch and, for the kinematics
    alone (`target` "cin"), the centres of mass, or for the forces every mass of the
    barrel and the rod (the link's resultant is the scene's, at O)."""
    driver = scene.crank
    params = driver.params
    branch = params["branch"]
    rate, accel = rates
    out = [
        f"{target} = dyad_cylinder_input_default();",
        f"{target}.a = fixed_point({_vec(params['base.x'].c(), params['base.y'].c())});",
        f"{target}.o = {pivot};",
        f"{target}.pin_b = {_vec(params['pin.x'].c(), params['pin.y'].c())};",
        f"{target}.length = in->{member(driver.actuator)}_length;",
        f"{target}.rate = {rate};",
        f"{target}.accel = {accel};",
        f"{target}.branch = {branch.c()} < 0 ? -1 : 1;"
        if branch.tunable
        else f"{target}.branch = {int(branch.value)};",
        f"{target}.singular_threshold = {scene.threshold.c()};",
    ]
    if "com.x" in params and target == "cin":
        out.append(f"{target}.link.com = {_vec(params['com.x'].c(), params['com.y'].c())};")
    return out + _cylinder_part_lines(params, target)


def _cylinder_lines(scene: Scene) -> list[str]:
    """The cylinder's motion and that of the link it turns, first."""
    c = member(scene.crank.name)
    at = _vec(scene.crank.params["at.x"].c(), scene.crank.params["at.y"].c())
    result = f"kin->{kin_name_of_cylinder(scene)}"
    out = [f"const dyad_point_motion {c}_o = fixed_point({at});", "dyad_cylinder_input cin;"]
    out += cylinder_input_lines(scene, "cin", ("rate", "accel"), f"{c}_o")
    out += [
        f"if (dyad_cylinder(&cin, &{result}) != DYAD_STATUS_OK) {{",
        f"    *failed = {len(scene.dyads)};",
        f"    return cylinder_failure(&{result}, &kin->cylinder_failure);",
        "}",
    ]
    return out


def _driver_lines(scene: Scene) -> list[str]:
    """The driver's frame and the motion of its origin (O or R)."""
    driver = scene.crank
    if driver.is_cylinder():
        return _cylinder_lines(scene)
    c = member(driver.name)
    at = _vec(driver.params["at.x"].c(), driver.params["at.y"].c())
    if driver.is_ram():
        return [
            f"const dyad_vec2 {c}_i = {_unit(driver.params['guide'])};",
            f"dyad_point_motion {c}_o;",
            f"{c}_o.position = dyad_add({at}, dyad_scale(in->{c}_position, {c}_i));",
            f"{c}_o.velocity = dyad_scale(rate, {c}_i);",
            f"{c}_o.acceleration = dyad_scale(accel, {c}_i);",
        ]
    return [
        f"const dyad_vec2 {c}_i = in->{c}_dir;",
        f"const dyad_point_motion {c}_o = fixed_point({at});",
    ]


def kinematics_body(scene: Scene, dyads: list[Dyad]) -> list[str]:
    """The statements of the function `kinematics`."""
    mounts = _Mounts(scene)
    body = _driver_lines(scene) + (["dyad_kin_input k;"] if dyads else [])
    for d in dyads:
        body += _dyad_lines(scene, mounts, d)
    body.append("return NULL;")
    return body


def kinematics_type(scene: Scene) -> str:
    """The kinematics block type: one dyad_kin_result per dyad."""
    ident = scene.identifier
    members = [f"    dyad_kin_result {kin_name(d)};" for d in scene.dyads]
    if scene.crank and scene.crank.is_cylinder():
        members.append(f"    dyad_cylinder_result {kin_name_of_cylinder(scene)};")
        members.append("    dyad_kin_result cylinder_failure; /* its failure, as a dyad's */")
    return "\n".join([f"typedef struct {ident}_kinematics {{", *members, f"}} {ident}_kinematics;"])


def kinematics_function(scene: Scene, dyads: list[Dyad]) -> str:
    """The kinematics block type and the function that fills it."""
    ident = scene.identifier
    body = kinematics_body(scene, dyads)
    lines = [kinematics_type(scene), ""]
    lines += [
        "/* The chain's kinematics from the driver outwards, the driver at its position in",
        " * `in` moving at `rate` with `accel` (rad/s and rad/s2, or m/s and m/s2 for a ram).",
        " * Returns NULL, or the result of the first dyad that does not solve (its index",
        " * in `failed`). */",
        f"static const dyad_kin_result* kinematics(const {ident}_input* in, double rate,",
        f"                                         double accel, {ident}_kinematics* kin,",
        "                                         int* failed)",
        "{",
    ]
    lines += [f"    {line}" for line in body]
    lines.append("}")
    return "\n".join(lines)


def failure_names(scene: Scene) -> str:
    """The dyads' names by index (the cylinder's last), for the log, as a C array
    initialiser."""
    names = [f"dyad {d.name or d.type}" for d in scene.dyads]
    if scene.crank and scene.crank.is_cylinder():
        names.append(f"cylinder {scene.crank.actuator}")
    return ", ".join(textsafe.c_string(n) for n in names)


def driver_rates(scene: Scene) -> tuple[str, str]:
    """The C expressions of the driver's rate and acceleration (0 without inertia)."""
    c = member(scene.crank.driver_name())
    if not scene.inertia:
        return "0.0", "0.0"
    if scene.crank.balances_with_force():
        return f"in->{c}_velocity", f"in->{c}_acceleration"
    return f"in->{c}_omega", f"in->{c}_epsilon"


def _body_terms(
    mass: Param | None, inertia: Param | None, com: str, turn: tuple[str, str]
) -> tuple[list, list]:
    """m V.V + I W^2 and m V.V' + I W W' of one body, from its centre of mass's motion
    `com` and its angular velocity and acceleration `turn` at unit rate (C)."""
    j_terms, dj_terms = [], []
    if mass is not None and not mass.is_zero():
        v, a = f"{com}.velocity", f"{com}.acceleration"
        j_terms.append(f"{mass.c()} * dyad_dot({v}, {v})")
        dj_terms.append(f"{mass.c()} * dyad_dot({v}, {a})")
    if inertia is not None and not inertia.is_zero():
        omega, epsilon = turn
        j_terms.append(f"{inertia.c()} * {omega} * {omega}")
        dj_terms.append(f"{inertia.c()} * {omega} * {epsilon}")
    return j_terms, dj_terms


def _cylinder_inertia_terms(scene: Scene) -> tuple[list[str], list[str]]:
    """The link's, the barrel's and the rod's terms of J and of dJ/dq."""
    params = scene.crank.params
    res = f"unit.{kin_name_of_cylinder(scene)}"
    link = (f"{res}.link_omega", f"{res}.link_epsilon")
    j_terms, dj_terms = _body_terms(
        params.get("mass"), params.get("inertia"), f"{res}.link_com", link
    )
    axis = (f"{res}.cylinder_omega", f"{res}.cylinder_epsilon")
    for part in ("barrel", "rod"):
        j, dj = _body_terms(
            params.get(f"{part}.mass"), params.get(f"{part}.inertia"), f"{res}.{part}_com", axis
        )
        j_terms += j
        dj_terms += dj
    return j_terms, dj_terms


def inertia_terms(scene: Scene, dyads: list[Dyad]) -> tuple[list[str], list[str]]:
    """The terms of J and of dJ/dq in C, from the kinematics at unit rate `unit`: each
    moving body's m V.V + I W^2 and 2 (m V.V' + I W W')."""
    driver = scene.crank
    mass = driver.params.get("mass")
    j_terms, dj_terms = [], []
    if driver.is_cylinder():
        j_terms, dj_terms = _cylinder_inertia_terms(scene)
    elif driver.is_ram():
        if mass is not None and not mass.is_zero():
            j_terms.append(mass.c())
    else:
        com = _vec(driver.params["com.x"].c(), driver.params["com.y"].c())
        if mass is not None and not mass.is_zero():
            j_terms.append(f"{mass.c()} * dyad_dot({com}, {com})")
        inertia = driver.params.get("inertia")
        if inertia is not None and not inertia.is_zero():
            j_terms.append(inertia.c())
    for d in dyads:
        for side, g in (("m", d.m), ("n", d.n)):
            res = f"unit.{kin_name(d)}.{side}"
            params = scene.links[g].params
            j, dj = _body_terms(
                params.get("mass"),
                params.get("inertia"),
                f"{res}.com",
                (f"{res}.omega", f"{res}.epsilon"),
            )
            j_terms += j
            dj_terms += dj
    return j_terms, dj_terms

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
from dyadgen.model import Attachment, Crank, Dyad, Param, Scene, c_real, member
from dyadgen.needs import kin_name, kin_name_of_cylinder

#: the core's failure statuses and the scene status each one reports
FAILURE_TEXT = "0 ok, 1 singular, 3 out of range, 4 cannot assemble"


def rate_names(scene: Scene, driver: Crank) -> tuple[str, str]:
    """The names of a driver's rate and acceleration among the arguments of the generated
    `kinematics`: `rate` and `accel` where the scene has one driver."""
    if len(scene.drivers) == 1:
        return "rate", "accel"
    c = member(driver.driver_name())
    return f"rate_{c}", f"accel_{c}"


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

    def carrier(self, link: str) -> tuple[str, str, str, str]:
        """(origin motion, direction, omega, epsilon) of a moving link, in C."""
        driver = self.scene.driver_of(link)
        if driver is not None and driver.is_cylinder():
            res = f"kin->{kin_name_of_cylinder(driver)}"
            return (
                f"&{member(link)}_o",
                f"{res}.link_dir",
                f"{res}.link_omega",
                f"{res}.link_epsilon",
            )
        if driver is not None:
            c = member(link)
            rate, accel = ("0.0", "0.0") if driver.is_ram() else rate_names(self.scene, driver)
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
        cylinders = []
        for att in (d.k, d.p):
            driver = self.scene.driver_of(att.link) if att.kind == "crank" else None
            if driver is not None and driver.is_cylinder() and driver not in cylinders:
                cylinders.append(driver)
        # the link a cylinder turns carries the triangle's round-off
        terms += [f"kin->{kin_name_of_cylinder(c)}.kin_amplification" for c in cylinders]
        return " + ".join(terms) if terms else None

    def offset(self, att: Attachment) -> str:
        """The pair's point (a guide's point) in its carrier's frame."""
        if att.at is not None:
            return _point(att.at)
        driver = self.scene.driver_of(att.link) if att.kind == "crank" else None
        if driver is not None and driver.is_cylinder():
            params = driver.params  # the rod's pin B
            return _vec(params["pin.x"].c(), params["pin.y"].c())
        if driver is not None and not driver.is_ram():
            return _vec(driver.params["length"].c(), "0.0")
        return _vec("0.0", "0.0")


def _unit(angle: Param) -> str:
    if angle.tunable:
        return f"dyad_dir_from_angle({angle.c()})"
    return _vec(c_real(math.cos(angle.value)), c_real(math.sin(angle.value)))


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


def branch_real(branch: Param | None) -> str:
    """A branch as the real that a batch's lane takes in place of the input's int
    (src/dyad_lanes.h): the same value as the int the scalar path converts (+1 where a
    type has none)."""
    if branch is None:
        return "DYAD_R(1.0)"
    if branch.tunable:
        return f"({branch.c()} < 0 ? DYAD_R(-1.0) : DYAD_R(1.0))"
    return f"DYAD_R({int(branch.value)}.0)"


def _dyad_lines(scene: Scene, mounts: _Mounts, d: Dyad, lane: bool = False) -> list[str]:
    """The kinematics of one dyad: its inputs, the call, the early return; in a batch's
    `lane`, the call's twin of src/dyad_lanes.h, whose failed checks it counts."""
    out = [f"/* dyad {d.name or ''} ({d.type}) */"]
    out.append(f"k = {'dyad_lane_kin_input_default' if lane else 'dyad_kin_input_default'}();")
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
    if d.branch is not None and not lane:
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
    if lane:
        branch = branch_real(d.branch)
        return [*out, f"bad += dyad_kin_lane_{d.type.lower()}(&k, {branch}, {result});"]
    out.append(f"if (dyad_kinematics_{d.type.lower()}(&k, {result}) != DYAD_STATUS_OK) {{")
    out.append(f"    *failed = {d.index};")
    out.append(f"    return {result};")
    out.append("}")
    return out


def _cylinder_part_lines(params: dict, target: str, motion_only: bool) -> list[str]:
    """The barrel's and the rod's centres of mass (and where the kinematics alone are
    wanted, `motion_only`, nothing more; else their masses and inertias too)."""
    out = []
    for part in ("barrel", "rod"):
        keys = ("com",) if motion_only else ("mass", "com", "inertia")
        for key in keys:
            value = params.get(f"{part}.{key}")
            if value is not None and not value.is_zero():
                out.append(f"{target}.{part}.{key} = {value.c()};")
    return out


def cylinder_input_lines(
    scene: Scene,
    driver: Crank,
    target: str,
    rates: tuple[str, str],
    pins: tuple[str, str],
    motion_only: bool = False,
    lane: bool = False,
) -> list[str]:
    """The assignments of a dyad_cylinder_input `target`: the frame pins (O's motion
    `pivot`), the pin B, the length and its `rates`, the branch (but in a batch's `lane`,
    whose call takes it as a real: branch_real) and, for the kinematics alone
    (`motion_only`), the centres of mass, or for the forces every mass of the barrel and
    the rod (the link's resultant is the scene's, at O). `pins`: the motion of A and of
    O, in C."""
    params = driver.params
    branch = params["branch"]
    rate, accel = rates
    out = [
        f"{target} = dyad_cylinder_input_default();",
        f"{target}.a = {pins[0]};",
        f"{target}.o = {pins[1]};",
        f"{target}.pin_b = {_vec(params['pin.x'].c(), params['pin.y'].c())};",
        f"{target}.length = in->{member(driver.actuator)}_length;",
        f"{target}.rate = {rate};",
        f"{target}.accel = {accel};",
    ]
    if not lane:
        out.append(
            f"{target}.branch = {branch.c()} < 0 ? -1 : 1;"
            if branch.tunable
            else f"{target}.branch = {int(branch.value)};"
        )
    out.append(f"{target}.singular_threshold = {scene.threshold.c()};")
    if "com.x" in params and motion_only:
        out.append(f"{target}.link.com = {_vec(params['com.x'].c(), params['com.y'].c())};")
    return out + _cylinder_part_lines(params, target, motion_only)


def fixed_pin(driver: Crank, key: str) -> str:
    """A cylinder's pin on the frame, `at` (O) or `base` (A), as a point's motion in C."""
    params = driver.params
    return f"fixed_point({_vec(params[f'{key}.x'].c(), params[f'{key}.y'].c())})"


def is_carried(driver: Crank) -> bool:
    """Whether a cylinder's pin O or A sits on a moving link."""
    return bool(driver.carriers())


def mount_names(driver: Crank) -> tuple[str, str]:
    """The kinematics block's members holding a carried cylinder's pins A and O."""
    c = member(driver.actuator)
    return f"{c}_mount_a", f"{c}_mount_o"


def _pin_motion(mounts: _Mounts, driver: Crank, key: str) -> str:
    """The motion of a cylinder's pin O (`at`) or A (`base`) in C: on the frame, or a
    point of the driver's link carrying it."""
    carrier = driver.pivot_on if key == "at" else driver.base_on
    if carrier is None:
        return fixed_pin(driver, key)
    origin, direction, omega, epsilon = mounts.carrier(carrier)
    point = _vec(driver.params[f"{key}.x"].c(), driver.params[f"{key}.y"].c())
    return f"dyad_point_on_link({origin}, {direction}, {omega}, {epsilon}, {point})"


def _cylinder_lines(scene: Scene, mounts: _Mounts, driver: Crank, lane: bool) -> list[str]:
    """A cylinder's motion and that of the link it turns (with `lane`, by its twin of
    src/dyad_lanes.h, whose failed checks it counts)."""
    c = member(driver.name)
    result = f"kin->{kin_name_of_cylinder(driver)}"
    cin = "cin" if len(scene.drivers) == 1 else f"cin_{member(driver.actuator)}"
    out = [f"const dyad_point_motion {c}_o = {_pin_motion(mounts, driver, 'at')};"]
    base = _pin_motion(mounts, driver, "base")
    if is_carried(driver):
        mount_a, mount_o = mount_names(driver)
        out += [f"kin->{mount_a} = {base};", f"kin->{mount_o} = {c}_o;"]
        base = f"kin->{mount_a}"
    out.append(f"dyad_cylinder_input {cin};")
    rates = rate_names(scene, driver)
    out += cylinder_input_lines(scene, driver, cin, rates, (base, f"{c}_o"), True, lane)
    carried = [
        f"kin->{kin_name_of_cylinder(d)}.kin_amplification"
        for d in scene.drivers
        if d.is_cylinder() and d.name in driver.carriers()
    ]
    if carried:
        out.append(f"{cin}.mount_amplification = {' + '.join(carried)};")
    if lane:
        branch = branch_real(driver.params["branch"])
        return [*out, f"bad += dyad_cylinder_lane(&{cin}, {branch}, &{result});"]
    failed = len(scene.dyads) + cylinders(scene).index(driver)
    out += [
        f"if (dyad_cylinder(&{cin}, &{result}) != DYAD_STATUS_OK) {{",
        f"    *failed = {failed};",
        f"    return cylinder_failure(&{result}, &kin->cylinder_failure);",
        "}",
    ]
    return out


def cylinders(scene: Scene) -> list[Crank]:
    """The scene's cylinders, in the order of their failures' indices after the dyads'."""
    return [d for d in scene.drivers if d.is_cylinder()]


def _driver_lines(scene: Scene, mounts: _Mounts, driver: Crank, lane: bool) -> list[str]:
    """A driver's frame and the motion of its origin (O or R)."""
    if driver.is_cylinder():
        return _cylinder_lines(scene, mounts, driver, lane)
    c = member(driver.name)
    at = _vec(driver.params["at.x"].c(), driver.params["at.y"].c())
    if driver.is_ram():
        rate, accel = rate_names(scene, driver)
        return [
            f"const dyad_vec2 {c}_i = {_unit(driver.params['guide'])};",
            f"dyad_point_motion {c}_o;",
            f"{c}_o.position = dyad_add({at}, dyad_scale(in->{c}_position, {c}_i));",
            f"{c}_o.velocity = dyad_scale({rate}, {c}_i);",
            f"{c}_o.acceleration = dyad_scale({accel}, {c}_i);",
        ]
    return [
        f"const dyad_vec2 {c}_i = in->{c}_dir;",
        f"const dyad_point_motion {c}_o = fixed_point({at});",
    ]


def kinematics_body(scene: Scene, dyads: list[Dyad], lane: bool = False) -> list[str]:
    """The statements of the function `kinematics` (with `lane`, of `kinematics_lane`,
    which counts the failed checks of a batch's sample)."""
    mounts = _Mounts(scene)
    body = [line for driver in scene.drivers for line in _driver_lines(scene, mounts, driver, lane)]
    body += ["dyad_kin_input k;"] if dyads else []
    for d in dyads:
        body += _dyad_lines(scene, mounts, d, lane)
    if not lane:
        return [*body, "return NULL;"]
    body = [lane_twins(line) for line in body]
    return ["dyad_real bad = 0;", *body, "return bad;"]


def lane_twins(line: str) -> str:
    """A line of C with the core's calls that have an inline twin for a batch's loop
    (src/dyad_lanes.h) calling the twin."""
    for call in ("dyad_point_on_link(", "dyad_cylinder_input_default("):
        line = line.replace(call, call.replace("dyad_", "dyad_lane_", 1))
    return line


def kinematics_lane_function(scene: Scene, dyads: list[Dyad]) -> str:
    """`kinematics_lane`: the chain's kinematics as `kinematics` solves them, without a
    branch, for one sample of a batch (src/dyad_lanes.h); returns the count of failed
    checks, 0 where `kinematics` returns NULL with the same results."""
    rates = ", ".join(
        f"dyad_real {rate}, dyad_real {accel}"
        for rate, accel in (rate_names(scene, d) for d in scene.drivers)
    )
    head = "DYAD_CLOSED_FORM dyad_real kinematics_lane("
    return "\n".join(
        [
            f"{head}const {scene.identifier}_input* in, {rates},",
            f"{' ' * len(head)}{scene.identifier}_kinematics* kin)",
            "{",
            *(f"    {line}" for line in kinematics_body(scene, dyads, lane=True)),
            "}",
        ]
    )


def kinematics_type(scene: Scene) -> str:
    """The kinematics block type: one dyad_kin_result per dyad."""
    ident = scene.identifier
    members = [f"    dyad_kin_result {kin_name(d)};" for d in scene.dyads]
    for driver in cylinders(scene):
        members.append(f"    dyad_cylinder_result {kin_name_of_cylinder(driver)};")
        if is_carried(driver):
            mount_a, mount_o = mount_names(driver)
            members.append(f"    dyad_point_motion {mount_a}, {mount_o}; /* its pins A and O */")
    if cylinders(scene):
        members.append("    dyad_kin_result cylinder_failure; /* its failure, as a dyad's */")
    return "\n".join([f"typedef struct {ident}_kinematics {{", *members, f"}} {ident}_kinematics;"])


def kinematics_function(scene: Scene, dyads: list[Dyad]) -> str:
    """The kinematics block type and the function that fills it."""
    ident = scene.identifier
    body = kinematics_body(scene, dyads)
    lines = [kinematics_type(scene), ""]
    if len(scene.drivers) == 1:
        lines += [
            "/* The chain's kinematics from the driver outwards, the driver at its position in",
            " * `in` moving at `rate` with `accel` (rad/s and rad/s2, or m/s and m/s2 for a ram).",
            " * Returns NULL, or the result of the first dyad that does not solve (its index",
            " * in `failed`). */",
            f"static const dyad_kin_result* kinematics(const {ident}_input* in, dyad_real rate,",
            f"                                         dyad_real accel, {ident}_kinematics* kin,",
            "                                         int* failed)",
            "{",
        ]
    else:
        rates = ", ".join(
            f"dyad_real {rate}, dyad_real {accel}"
            for rate, accel in (rate_names(scene, d) for d in scene.drivers)
        )
        lines += [
            "/* The chain's kinematics from the drivers outwards, each driver at its position",
            " * in `in` moving at its rate with its acceleration (rad/s and rad/s2, or m/s and",
            " * m/s2 for a ram or a cylinder). Returns NULL, or the result of the first dyad",
            " * or cylinder that does not solve (its index in `failed`). */",
            f"static const dyad_kin_result* kinematics(const {ident}_input* in, {rates},",
            f"                                         {ident}_kinematics* kin, int* failed)",
            "{",
        ]
    lines += [f"    {line}" for line in body]
    lines.append("}")
    return "\n".join(lines)


def failure_names(scene: Scene) -> str:
    """The dyads' names by index (the cylinder's last), for the log, as a C array
    initialiser."""
    names = [f"dyad {d.name or d.type}" for d in scene.dyads]
    names += [f"cylinder {c.actuator}" for c in cylinders(scene)]
    return ", ".join(textsafe.c_string(n) for n in names)


def driver_rates(scene: Scene, driver: Crank) -> tuple[str, str]:
    """The C expressions of a driver's rate and acceleration (0 without inertia)."""
    c = member(driver.driver_name())
    if not scene.inertia:
        return "0.0", "0.0"
    if driver.balances_with_force():
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


def _cylinder_inertia_terms(driver: Crank, unit: str) -> tuple[list[str], list[str]]:
    """The link's, the barrel's and the rod's terms of J and of dJ/dq."""
    params = driver.params
    res = f"{unit}.{kin_name_of_cylinder(driver)}"
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


def _driver_inertia_terms(driver: Crank, unit: str) -> tuple[list[str], list[str]]:
    """A driver's own body's terms of J and dJ/dq at unit rate `unit`."""
    if driver.is_cylinder():
        return _cylinder_inertia_terms(driver, unit)
    mass = driver.params.get("mass")
    j_terms: list[str] = []
    if driver.is_ram():
        if mass is not None and not mass.is_zero():
            j_terms.append(mass.c())
        return j_terms, []
    com = _vec(driver.params["com.x"].c(), driver.params["com.y"].c())
    if mass is not None and not mass.is_zero():
        j_terms.append(f"{mass.c()} * dyad_dot({com}, {com})")
    inertia = driver.params.get("inertia")
    if inertia is not None and not inertia.is_zero():
        j_terms.append(inertia.c())
    return j_terms, []


def inertia_terms(scene: Scene, dyads: list[Dyad]) -> tuple[list[str], list[str]]:
    """The terms of J and of dJ/dq in C, from the kinematics at unit rate `unit`: each
    moving body's m V.V + I W^2 and 2 (m V.V' + I W W')."""
    j_terms, dj_terms = _driver_inertia_terms(scene.crank, "unit")
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


def _cross_terms(mass: Param | None, inertia: Param | None, com: tuple, turn: tuple) -> list:
    """m V_a.V_b + I W_a W_b of one body from its centre of mass's velocity and its
    angular velocity per unit rate of drivers a and b (C: `com` and `turn` pairs)."""
    terms = []
    if mass is not None and not mass.is_zero():
        terms.append(f"{mass.c()} * dyad_dot({com[0]}.velocity, {com[1]}.velocity)")
    if inertia is not None and not inertia.is_zero():
        terms.append(f"{inertia.c()} * {turn[0]} * {turn[1]}")
    return terms


def _own_body_cross(driver: Crank, units: tuple[str, str], same: bool) -> list[str]:
    """A driver's own bodies' terms of M(q)'s entry (a, b): a crank or a ram (turning or
    sliding on the frame) moves with its own driver alone, where a = b = the driver; a
    cylinder's link, barrel and rod with whatever moves its pins too."""
    if not driver.is_cylinder():
        return _driver_inertia_terms(driver, units[0])[0] if same else []
    params = driver.params
    res = tuple(f"{u}.{kin_name_of_cylinder(driver)}" for u in units)
    terms = _cross_terms(
        params.get("mass"),
        params.get("inertia"),
        (f"{res[0]}.link_com", f"{res[1]}.link_com"),
        (f"{res[0]}.link_omega", f"{res[1]}.link_omega"),
    )
    for part in ("barrel", "rod"):
        terms += _cross_terms(
            params.get(f"{part}.mass"),
            params.get(f"{part}.inertia"),
            (f"{res[0]}.{part}_com", f"{res[1]}.{part}_com"),
            (f"{res[0]}.cylinder_omega", f"{res[1]}.cylinder_omega"),
        )
    return terms


def inertia_matrix_terms(scene: Scene, dyads: list[Dyad], a: Crank, b: Crank) -> list[str]:
    """The terms of M(q)'s entry (a, b) in C, from the kinematics at unit rate of driver a
    alone, `unit_<a>`, and of b alone: sum over the moving bodies of m V_a.V_b + I W_a W_b.
    A driver's own body moves with its driver only."""
    units = (f"unit_{member(a.driver_name())}", f"unit_{member(b.driver_name())}")
    terms = []
    for driver in scene.drivers:
        if driver.is_cylinder() and (driver is a or is_carried(driver)):
            terms += _own_body_cross(driver, units, a is b)
        elif driver is a:
            terms += _own_body_cross(driver, units, a is b)
    for d in dyads:
        for side, g in (("m", d.m), ("n", d.n)):
            res = tuple(f"{u}.{kin_name(d)}.{side}" for u in units)
            params = scene.links[g].params
            terms += _cross_terms(
                params.get("mass"),
                params.get("inertia"),
                (f"{res[0]}.com", f"{res[1]}.com"),
                (f"{res[0]}.omega", f"{res[1]}.omega"),
            )
    return terms

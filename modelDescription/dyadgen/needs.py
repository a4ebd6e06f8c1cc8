"""What a scene needs: its inputs (the motion and active loads of the links the wanted
outputs involve) and its outputs with their dependencies.

Inputs are derived as candidates first; once it is known what the generated code
computes (scenefile.read prunes the candidates the code never reads), the outputs'
dependencies follow from the inputs that are left."""

from __future__ import annotations

import re

from dyadgen.dyadtypes import PAIR_NAMES, PAIRS, pair_label
from dyadgen.model import (
    Crank,
    Dyad,
    Input,
    Link,
    Output,
    Scene,
    ancestors,
    carriers,
    loaders,
    member,
    own_accel,
    unit_vector_c,
)

#: What a dyad's amplification output means (README, "Status, conditioning, amplification").
AMPLIFICATION_TEXT = (
    "Data factor / conditioning: eps x amplification bounds the error of each "
    "reaction relative to the largest reaction of its unit (N or N.m)"
)
#: The same in a mechanism FMU, whose dyads' motion is its own round-off too.
KINEMATIC_AMPLIFICATION_TEXT = (
    "eps x amplification bounds the error of each reaction of the dyad relative to its "
    "largest reaction of the unit (N or N.m), the round-off of the dyad's motion included"
)
#: A mechanism FMU's own amplification output.
MECHANISM_AMPLIFICATION_TEXT = (
    "eps x amplification bounds the error of every output with status 0 relative to the "
    "peak of its unit over the motion: the kinematics' round-off (which grows like "
    "1 / conditioning^2 at a dead centre) and the reactions' together"
)
CONDITIONING_TEXT = "Conditioning of {} in [0, 1]; below singular_threshold the dyad is singular"
#: In a mechanism FMU the motion's amplification decides (kinematics.h).
KINEMATIC_CONDITIONING_TEXT = (
    "Conditioning of {} in [0, 1] (|sin| of the angle its velocity equations divide by); "
    "the dyad is singular where its motion's amplification exceeds 1 / singular_threshold"
)


# ---------------------------------------------------------------------------
# Inputs
# ---------------------------------------------------------------------------
def _motion_inputs(scene: Scene, link: Link) -> list[Input]:
    g = link.name
    out = []
    if not link.translating:
        out.append(
            Input(
                f"{g}.angle",
                "rad",
                f"Direction of {g}: angle of i from D towards E, counter-clockwise from x",
                member(g) + "_dir",
                True,
                owner=g,
            )
        )
        if scene.inertia:
            out.append(
                Input(
                    f"{g}.omega", "rad/s", f"Angular velocity of {g}", member(g) + "_omega", owner=g
                )
            )
            out.append(
                Input(
                    f"{g}.epsilon",
                    "rad/s2",
                    f"Angular acceleration of {g}",
                    member(g) + "_epsilon",
                    owner=g,
                )
            )
    if scene.inertia and own_accel(link):
        for c in "xy":
            out.append(
                Input(
                    f"{g}.accel_d.{c}",
                    "m/s2",
                    f"Acceleration of {g} at its outer pair D, global {c}",
                    f"{member(g)}_accel_d_{c}",
                    owner=g,
                )
            )
    return out


def _load_inputs(link: Link) -> list[Input]:
    """A link's active force and moment inputs, where [loads] lists them."""
    g = link.name
    out = []
    if link.force:
        for c in "xy":
            out.append(
                Input(
                    f"{g}.force.{c}",
                    "N",
                    f"Active force on {g} at its centre of mass, global {c}",
                    f"{member(g)}_force_{c}",
                    owner=g,
                )
            )
    if link.moment:
        out.append(
            Input(
                f"{g}.moment",
                "N.m",
                f"Active moment on {g}, counter-clockwise",
                member(g) + "_moment",
                owner=g,
            )
        )
    return out


def point_load_inputs(scene: Scene) -> list[Input]:
    """The force and moment inputs of the scene's [[load]] tables, in file order."""
    out = []
    for load in scene.point_loads:
        n, g = load.name, load.link
        frame = "global" if load.components == "global" else f"along {g}'s"
        if load.force:
            for c, axis in (("x", "i"), ("y", "j")):
                text = f"{c}" if load.components == "global" else f"{axis} ({c} in its frame)"
                out.append(
                    Input(
                        f"{n}.force.{c}",
                        "N",
                        f"Force of load {n} on {g} at its point {n}.at, {frame} {text}",
                        f"{member(n)}_force_{c}",
                        owner=g,
                    )
                )
        if load.moment:
            out.append(
                Input(
                    f"{n}.moment",
                    "N.m",
                    f"Moment of load {n} on {g}, counter-clockwise",
                    f"{member(n)}_moment",
                    owner=g,
                )
            )
    return out


def _link_inputs(scene: Scene, link: Link) -> list[Input]:
    g = link.name
    out = _motion_inputs(scene, link) + _load_inputs(link)
    if link.sliding:
        out.append(
            Input(
                f"{g}.length",
                "m",
                f"Current length |D E| of {g} (pair E slides along it)",
                member(g) + "_length",
                start=1.0,
                domain={"min": 0.0, "min_exclusive": True},
                owner=g,
            )
        )
    return out


def _crank_inputs(scene: Scene, driver: Crank) -> list[Input]:
    c = driver.name
    inputs = [
        Input(
            f"{c}.angle",
            "rad",
            "Crank angle phi (i_c from O towards A)",
            member(c) + "_dir",
            True,
            owner=c,
        )
    ]
    if scene.inertia:
        inputs.append(
            Input(f"{c}.omega", "rad/s", "Crank angular velocity", member(c) + "_omega", owner=c)
        )
        inputs.append(
            Input(
                f"{c}.epsilon",
                "rad/s2",
                "Crank angular acceleration",
                member(c) + "_epsilon",
                owner=c,
            )
        )
    return inputs


def _guide_inputs(d: Dyad) -> list[Input]:
    inputs = []
    for side, pair in (("k", "D_m"), ("p", "D_n")):
        att = getattr(d, side)
        if att.kind in ("crank", "link") and att.guide is not None:
            slider = d.m if side == "k" else d.n
            inputs.append(
                Input(
                    f"{d.prefix()}slide_{side}",
                    "m",
                    f"Position of {pair} along the guide on {att.link}, "
                    "from the guide's point 'at'",
                    f"{member(d.prefix())}slide_{side}",
                    owner=slider,
                )
            )
        if att.kind == "external" and d.pair_kind("mk" if side == "k" else "np") == "T":
            inputs.append(
                Input(
                    f"{d.prefix()}guide_{side}.angle",
                    "rad",
                    f"Direction of the guide of the external link at {pair}",
                    f"{member(d.prefix())}guide_{side}",
                    True,
                )
            )
    return inputs


def _ram_inputs(scene: Scene, driver: Crank) -> list[Input]:
    r = driver.name
    inputs = [
        Input(
            f"{r}.position",
            "m",
            "Ram displacement x along its guide: its origin R is at + x i_r",
            member(r) + "_position",
            owner=r,
        )
    ]
    if scene.inertia:
        for key, unit, text in (
            ("velocity", "m/s", "Ram velocity along its guide"),
            ("acceleration", "m/s2", "Ram acceleration along its guide"),
        ):
            inputs.append(Input(f"{r}.{key}", unit, text, f"{member(r)}_{key}", owner=r))
    return inputs


def _cylinder_inputs(scene: Scene, driver: Crank) -> list[Input]:
    """A cylinder's length and, with inertia, its rate and acceleration: the inputs of
    the driver's motion, owned by the link it turns."""
    c, link = driver.actuator, driver.name
    motion = [("length", "m", "Cylinder length s = |A B| between its pins")]
    if scene.inertia:
        motion += [
            ("velocity", "m/s", "Cylinder extension rate ds/dt"),
            ("acceleration", "m/s2", "Cylinder extension acceleration d2s/dt2"),
        ]
    inputs = [
        Input(f"{c}.{key}", unit, text, f"{member(c)}_{key}", owner=link)
        for key, unit, text in motion
    ]
    inputs[0].domain = {"min": 0.0, "min_exclusive": True}
    return inputs


def _driver_motion_inputs(scene: Scene) -> list[Input]:
    """The inputs of the drivers' motion, driver by driver."""
    inputs = []
    for driver in scene.drivers:
        if driver.is_cylinder():
            inputs += _cylinder_inputs(scene, driver)
        else:
            inputs += (_ram_inputs if driver.is_ram() else _crank_inputs)(scene, driver)
    return inputs


def derive_inputs(scene: Scene) -> None:
    """Every candidate input of the scene, in table order. With internal kinematics they
    are the driver's motion and the loads; every link's motion is computed (its C
    expressions are in scene.computed)."""
    if scene.internal():
        inputs = _driver_motion_inputs(scene)
        for d in scene.dyads:
            for g in (d.m, d.n):
                inputs += _load_inputs(scene.links[g])
        scene.inputs = inputs + point_load_inputs(scene)
        scene.computed = computed_motion(scene)
        return
    inputs = _driver_motion_inputs(scene)
    for d in scene.dyads:
        for g in (d.m, d.n):
            inputs += _link_inputs(scene, scene.links[g])
        inputs += _guide_inputs(d)
    scene.inputs = inputs + point_load_inputs(scene)


def kin_name(d: Dyad) -> str:
    """The member of the generated kinematics block that holds a dyad's result."""
    return member(d.name or "dyad")


def computed_motion(scene: Scene) -> dict[str, str]:
    """Internal kinematics: every link motion the kinetostatics read, by the name its
    input would have, as a C expression on the kinematics block `kin`."""
    out = {}
    for d in scene.dyads:
        dn = kin_name(d)
        for side, g in (("m", d.m), ("n", d.n)):
            res = f"kin.{dn}.{side}"
            out[f"{g}.angle"] = f"{res}.dir"
            out[f"{g}.omega"] = f"{res}.omega"
            out[f"{g}.epsilon"] = f"{res}.epsilon"
            out[f"{g}.accel_d.x"] = f"{res}.d.acceleration.x"
            out[f"{g}.accel_d.y"] = f"{res}.d.acceleration.y"
            if scene.links[g].sliding:
                out[f"{g}.length"] = f"{res}.length"
        for side in "kp":
            out[f"{d.prefix()}slide_{side}"] = f"kin.{dn}.slide_{side}.s"
    for driver in scene.drivers:
        if driver.is_ram():
            out[f"{driver.name}.angle"] = unit_vector_c(driver.params["guide"])
        if driver.is_cylinder():
            g, cyl = driver.name, f"kin.{kin_name_of_cylinder(driver)}"
            out[f"{g}.angle"] = f"{cyl}.link_dir"
            out[f"{g}.omega"] = f"{cyl}.link_omega"
            out[f"{g}.epsilon"] = f"{cyl}.link_epsilon"
    return out


def kin_name_of_cylinder(driver: Crank) -> str:
    """The member of the generated kinematics block that holds a cylinder's result."""
    return member(driver.actuator) + "_cylinder"


# ---------------------------------------------------------------------------
# Outputs
# ---------------------------------------------------------------------------
class _Offer:
    """The outputs a scene offers, in order, and by the names a scene may ask for."""

    def __init__(self) -> None:
        self.offered: list[Output] = []
        self.by_name: dict[str, list[Output]] = {}

    def add(self, name: str, group: list[Output]) -> None:
        self.by_name[name] = group
        self.offered += group


class _Index:
    """What the dependencies of every dyad's outputs are picked from, found once."""

    def __init__(self, scene: Scene) -> None:
        self.carrier_of = carriers(scene)
        self.geometry = {
            i.name
            for i in scene.inputs
            if i.unit in ("rad", "m") and not i.name.endswith(".moment")
        }
        self.owner_of = {i.name: i.owner for i in scene.inputs}
        # the inputs of no link: the guides of external links, DYAD.guide_k.angle
        self.unowned = [i.name for i in scene.inputs if i.owner == ""]


def _driver_inputs(scene: Scene, upto: int) -> list[str]:
    """The first `upto` inputs of each driver's motion: its position, velocity,
    acceleration."""
    names = []
    for driver in scene.drivers:
        motion = [i for i in scene.inputs if i.owner == driver.name]
        names += [i.name for i in motion if i.unit not in ("N", "N.m")][:upto]
    return names


def _dependencies(scene: Scene, d: Dyad, index: _Index) -> tuple[list, list]:
    """The inputs of a dyad's reactions, and of its conditioning: the dyad's own
    directions and lengths, and the direction of a guide it slides on (an input, or a
    moving carrier's angle). With internal kinematics: the driver's motion and the loads
    of the links involved; the conditioning follows the driver's position."""
    if scene.internal():
        involved = {d.m, d.n} | {g for o in loaders(scene, d) for g in (o.m, o.n)}
        loads = [i.name for i in scene.inputs if i.owner in involved]
        return _driver_inputs(scene, 3) + loads, _driver_inputs(scene, 1)
    involved = {d.m, d.n}
    for other in loaders(scene, d):
        involved |= {other.m, other.n}
    involved |= ancestors(index.carrier_of, involved)
    guides = [n for n in index.unowned if n.startswith(d.prefix())]
    deps = [i.name for i in scene.inputs if i.owner in involved] + guides
    own = {d.m, d.n} | {a.link for a in (d.k, d.p) if a.guide is not None and a.link}
    own_geometry = [
        n for n in deps if n in index.geometry and (index.owner_of[n] in own or n in guides)
    ]
    return deps, own_geometry


def reaction_text(d: Dyad, pair: str) -> str:
    """The description of a reaction output."""
    other = {"mk": "k", "np": "p"}.get(pair)
    if pair == "mn":
        return f"Force on {d.m} from {d.n} at E"
    link = d.m if pair == "mk" else d.n
    att = d.k if pair == "mk" else d.p
    source = att.link if att.kind in ("crank", "link") else att.kind
    return f"Force on {link} from {source} ({other}) at {pair_label(pair)}"


def _dyad_outputs(
    offer: _Offer, d: Dyad, deps: list, own_geometry: list, internal: bool = False
) -> None:
    pre = d.prefix()
    source = str(d.index)
    named = d.name or "the dyad"
    for pair, idx in PAIR_NAMES:
        group = [
            Output(
                f"{pre}R_{pair}.{c}",
                "N",
                reaction_text(d, pair) + f", global {c}",
                f"{member(pre)}r_{pair}_{c}",
                depends=deps,
                source=source,
            )
            for c in "xy"
        ]
        offer.add(f"{pre}R_{pair}", group)
        if PAIRS[d.type][idx] == "T":
            label = f"the sliding pair {pair_label(pair)} of {named}"
            n_out = Output(
                f"{pre}N_{pair}",
                "N",
                f"Normal force of {label}",
                f"{member(pre)}n_{pair}",
                depends=deps,
                source=source,
            )
            m_out = Output(
                f"{pre}M_{pair}",
                "N.m",
                f"Reactive moment of {label}",
                f"{member(pre)}m_{pair}",
                depends=deps,
                source=source,
            )
            offer.add(n_out.name, [n_out])
            offer.add(m_out.name, [m_out])
    cond = Output(
        f"{pre}conditioning",
        None,
        (KINEMATIC_CONDITIONING_TEXT if internal else CONDITIONING_TEXT).format(named),
        f"{member(pre)}conditioning",
        depends=own_geometry,
        source=source,
    )
    offer.add(cond.name, [cond])
    if internal and not pre:
        return  # the mechanism's own amplification, which bounds this dyad's too
    amp = Output(
        f"{pre}amplification",
        None,
        KINEMATIC_AMPLIFICATION_TEXT if internal else AMPLIFICATION_TEXT,
        f"{member(pre)}amplification",
        depends=deps,
        source=source,
    )
    offer.add(amp.name, [amp])


def _motion_output(
    offer: _Offer, name: str, unit: str, text: str, c_member: str, depends: list, source: str
) -> Output:
    out = Output(name, unit, text, c_member, depends=depends, source=source)
    offer.add(name, [out])
    return out


def _link_motion_outputs(offer: _Offer, scene: Scene, g: str, source: str) -> None:
    """A link's angle and, with inertia, its rates; a sliding length."""
    link = scene.links[g]
    c = member(g)
    if not link.translating:
        text = f"Direction of {g}: angle of i from D towards E, in (-pi, pi]"
        _motion_output(
            offer, f"{g}.angle", "rad", text, f"{c}_angle", _driver_inputs(scene, 1), source
        )
        if scene.inertia:
            for key, unit, text, upto in (
                ("omega", "rad/s", f"Angular velocity of {g}", 2),
                ("epsilon", "rad/s2", f"Angular acceleration of {g}", 3),
            ):
                depends = _driver_inputs(scene, upto)
                _motion_output(offer, f"{g}.{key}", unit, text, f"{c}_{key}", depends, source)
    if link.sliding:
        text = f"Current length |D E| of {g} (pair E slides along it)"
        _motion_output(
            offer, f"{g}.length", "m", text, f"{c}_length", _driver_inputs(scene, 1), source
        )


def _kinematic_outputs(offer: _Offer, scene: Scene, d: Dyad) -> None:
    """Internal kinematics: where a dyad's links and pair points are."""
    source = f"kin{d.index}"
    pre = d.prefix()
    position = _driver_inputs(scene, 1)
    for g in (d.m, d.n):
        _link_motion_outputs(offer, scene, g, source)
    for pair in ("D_m", "E", "D_n"):
        group = [
            Output(
                f"{pre}{pair}.position.{c}",
                "m",
                f"Position of pair {pair} of {d.name or 'the dyad'}, global {c}",
                f"{member(pre)}{pair.lower()}_position_{c}",
                depends=position,
                source=source,
            )
            for c in "xy"
        ]
        offer.add(f"{pre}{pair}.position", group)
    for side, pair in (("k", "D_m"), ("p", "D_n")):
        if d.pair_kind("mk" if side == "k" else "np") == "T":
            text = f"Position of {pair} along its guide, from the guide's point 'at'"
            name = f"{pre}slide_{side}"
            _motion_output(offer, name, "m", text, member(name), position, source)


def _driver_inertia_outputs(offer: _Offer, scene: Scene) -> None:
    """Internal kinematics with inertia: the effective inertia at the driver and the
    balancing torque (force) at zero driver acceleration; with several drivers the inertia
    matrix M(q) instead of J and dJ/dq."""
    if len(scene.drivers) > 1:
        _inertia_matrix_outputs(offer, scene)
        return
    c = scene.crank.driver_name()
    ram = scene.crank.balances_with_force()
    unit, rate = ("kg", "m") if ram else ("kg.m2", "rad")
    balance, bunit = ("force", "N") if ram else ("torque", "N.m")
    every = [i.name for i in scene.inputs]
    position = _driver_inputs(scene, 1)
    texts = (
        ("J", unit, f"Effective inertia at the driver: {balance} = J q'' + {balance}0", position),
        ("dJdq", f"{unit}/{rate}", "Derivative of J along the driver's position q", position),
        (f"{balance}0", bunit, f"Driving {balance} at zero driver acceleration", every),
    )
    for key, u, text, depends in texts:
        source = "crank" if key.endswith("0") else "driver"
        c_member = f"{member(c)}_{key.lower()}"
        if not key.endswith("0"):
            c_member = f"{member(c)}_reduced_{key.lower()}"  # not the frame's local c_j
        _motion_output(offer, f"{c}.{key}", u, text, c_member, depends, source)


def effort_of(driver: Crank) -> tuple[str, str]:
    """(name, unit) of a driver's effort: a crank's torque, a ram's or a cylinder's force."""
    return ("force", "N") if driver.balances_with_force() else ("torque", "N.m")


def inertia_entry_unit(row: Crank, column: Crank) -> str:
    """The unit of M(q)'s entry: effort of `row` per acceleration of `column`."""
    linear = row.balances_with_force() + column.balances_with_force()
    return ("kg.m2", "kg.m", "kg")[linear]


def inertia_entry_member(scene: Scene, row: Crank, column: Crank) -> str:
    """The C member of M(q)'s entry (row, column), by the drivers' places in the scene (two
    names joined could read as two other names joined)."""
    return f"inertia_m_{scene.drivers.index(row)}_{scene.drivers.index(column)}"


def _inertia_matrix_outputs(offer: _Offer, scene: Scene) -> None:
    """Several drivers: every entry of M(q), efforts = M(q) q'' + h, and each driver's
    effort at zero acceleration of every driver, h."""
    position = _driver_inputs(scene, 1)
    every = [i.name for i in scene.inputs]
    for row in scene.drivers:
        a = row.driver_name()
        for column in scene.drivers:
            b = column.driver_name()
            effort = effort_of(row)[0]
            rate = "acceleration" if column.balances_with_force() else "epsilon"
            text = f"Inertia matrix M(q), row {a}, column {b}: d {a}.{effort} / d {b}.{rate}"
            unit = inertia_entry_unit(row, column)
            c_member = inertia_entry_member(scene, row, column)
            _motion_output(offer, f"M.{a}.{b}", unit, text, c_member, position, "driver")
    for driver in scene.drivers:
        c = driver.driver_name()
        effort, unit = effort_of(driver)
        text = (
            f"{effort.capitalize()} of {c} with every driver's acceleration zero: h in "
            "efforts = M(q) q'' + h"
        )
        c_member = f"{member(c)}_{effort}0"
        _motion_output(offer, f"{c}.{effort}0", unit, text, c_member, every, "crank")


def _cylinder_motion_outputs(offer: _Offer, scene: Scene, driver: Crank) -> None:
    """The motion of the link a cylinder turns and of the cylinder itself, pin B, and the
    triangle's conditioning."""
    link, c = driver.name, driver.actuator
    # every driver's motion, as a dyad's links list it: with several drivers the cylinder
    # is not the first one (nor, carried, moved by its own alone)
    position = _driver_inputs(scene, 1)
    bodies = (
        (link, member(link), f"Direction of {link}: angle of its i, in (-pi, pi]", f"{link}"),
        (
            c,
            member(c),
            f"Direction of cylinder {c}: angle of its axis from A towards B, in (-pi, pi]",
            f"cylinder {c}",
        ),
    )
    for name, cm, text, label in bodies:
        _motion_output(offer, f"{name}.angle", "rad", text, f"{cm}_angle", position, "crank")
        if scene.inertia:
            for key, unit, what, upto in (
                ("omega", "rad/s", "Angular velocity", 2),
                ("epsilon", "rad/s2", "Angular acceleration", 3),
            ):
                _motion_output(
                    offer,
                    f"{name}.{key}",
                    unit,
                    f"{what} of {label}",
                    f"{cm}_{key}",
                    _driver_inputs(scene, upto),
                    "crank",
                )
    group = [
        Output(
            f"{c}.B.position.{x}",
            "m",
            f"Position of the rod's pin B of cylinder {c}, global {x}",
            f"{member(c)}_b_position_{x}",
            depends=position,
            source="crank",
        )
        for x in "xy"
    ]
    offer.add(f"{c}.B.position", group)
    _motion_output(
        offer,
        f"{c}.conditioning",
        None,
        f"Conditioning of cylinder {c} in [0, 1]: |sin| of the angle between O B and A B, 0 "
        "where O, A and B fall in line (the toggle, where the cylinder cannot turn the link)",
        f"{member(c)}_conditioning",
        position,
        "crank",
    )


def _cylinder_outputs(offer: _Offer, scene: Scene, driver: Crank) -> None:
    """A cylinder's axial force, its pins' reactions and the barrel's action on the rod,
    and the frame's force on the link it turns."""
    link, c = driver.name, driver.actuator
    every = [i.name for i in scene.inputs]
    _motion_output(
        offer,
        f"{c}.force",
        "N",
        f"Axial force of cylinder {c}: positive pushes its pins apart (the rod in compression)",
        f"{member(c)}_force",
        every,
        "crank",
    )
    pins = (
        (f"{c}.R_A", f"{member(c)}_r_a", f"Force on the barrel of {c} from the frame at A"),
        (f"{c}.R_B", f"{member(c)}_r_b", f"Force on {link} from the rod of {c} at B"),
        (f"{link}.R_O", f"{member(link)}_r_o", f"Force on {link} from the frame at O"),
    )
    for name, cm, text in pins:
        group = [
            Output(
                f"{name}.{x}",
                "N",
                f"{text}, global {x}",
                f"{cm}_{x}",
                depends=every,
                source="crank",
            )
            for x in "xy"
        ]
        offer.add(name, group)
    for key, unit, text in (
        ("N", "N", f"Force of the barrel of {c} on its rod across the axis at B, along k0 x u"),
        ("M", "N.m", f"Moment of the barrel of {c} on its rod, counter-clockwise"),
    ):
        _motion_output(
            offer, f"{c}.{key}", unit, text, f"{member(c)}_{key.lower()}_rod", every, "crank"
        )


def _ram_outputs(offer: _Offer, scene: Scene, driver: Crank) -> None:
    c = driver.name
    every = [i.name for i in scene.inputs]
    for key, unit, text in (
        ("force", "N", "Actuator force on the ram along its guide i_r"),
        ("N", "N", "Normal force on the ram from its guide, along j_r"),
        ("M", "N.m", "Reactive moment on the ram from its guide, counter-clockwise"),
    ):
        c_member = f"{member(c)}_{'force' if key == 'force' else 'guide_' + key.lower()}"
        _motion_output(offer, f"{c}.{key}", unit, text, c_member, every, "crank")


def _crank_outputs(offer: _Offer, scene: Scene, driver: Crank) -> None:
    c = driver.name
    every = [i.name for i in scene.inputs]
    torque = Output(
        f"{c}.torque",
        "N.m",
        "Driving torque on the crank about O, counter-clockwise",
        f"{member(c)}_torque",
        depends=every,
        source="crank",
    )
    r_o = [
        Output(
            f"{c}.R_O.{x}",
            "N",
            f"Force on the crank from the frame at O, global {x}",
            f"{member(c)}_r_o_{x}",
            depends=every,
            source="crank",
        )
        for x in "xy"
    ]
    offer.add(torque.name, [torque])
    offer.add(f"{c}.R_O", r_o)


def why_not(scene: Scene, wanted: str) -> str:
    """Why a scene has no output of the name `wanted`."""
    head, _, tail = wanted.rpartition(".")
    for d in scene.dyads:
        if head == d.name or (not d.name and not head):
            m = re.fullmatch(r"(N|M)_(mk|np|mn)", tail)
            if m and d.pair_kind(m.group(2)) == "R":
                return (
                    f"no pair provides it: {pair_label(m.group(2))} of the {d.type} "
                    f"dyad '{d.name}' is revolute (no normal force or reactive moment)"
                )
            return (
                f"dyad '{d.name}' has no output '{tail}' (it has R_mk, R_np, R_mn, "
                "conditioning, amplification and N_/M_ of its sliding pairs)"
            )
    for driver in scene.drivers:
        if driver.is_cylinder() and head in (driver.name, driver.actuator):
            return (
                f"the cylinder has 'force', 'R_A', 'R_B', 'N', 'M', its motion and "
                f"'B.position'; its link '{driver.name}' its motion and 'R_O'"
            )
        if head == driver.name and driver.is_ram():
            return "the ram has only 'force', 'N' and 'M'"
        if head == driver.name:
            return "the crank has only 'torque' and 'R_O'"
    names = [d.name for d in scene.dyads] + [d.driver_name() for d in scene.drivers]
    return f"no dyad or crank is named '{head}' (known: {', '.join(names)})"


def _choose(offer: _Offer, scene: Scene, wanted: list[str]) -> tuple[list[Output], list[str]]:
    chosen: list[Output] = []
    problems = []
    picked: set[int] = set()
    for w in wanted:
        if w == "all":
            group = offer.offered
        elif w in offer.by_name:
            group = offer.by_name[w]
        else:
            group = [o for o in offer.offered if o.name == w][-1:] or None
            if group is None:
                problems.append(f"output '{w}': {why_not(scene, w)}")
                continue
        for o in group:
            if id(o) not in picked:
                picked.add(id(o))
                chosen.append(o)
    position = {id(o): k for k, o in enumerate(offer.offered)}
    chosen.sort(key=lambda o: position[id(o)])
    return chosen, problems


def derive_outputs(scene: Scene, wanted: list[str]) -> list[str]:
    """The scene's outputs: those `wanted` (names, groups such as R_mk, or "all") and
    the status; returns why a wanted name is no output, one message each."""
    offer = _Offer()
    index = _Index(scene)
    for d in scene.dyads:
        if scene.internal():
            _kinematic_outputs(offer, scene, d)
        deps, own_geometry = _dependencies(scene, d, index)
        _dyad_outputs(offer, d, deps, own_geometry, scene.internal())
    for driver in scene.drivers:
        if driver.is_cylinder():
            _cylinder_motion_outputs(offer, scene, driver)
            _cylinder_outputs(offer, scene, driver)
        elif driver.is_ram():
            _ram_outputs(offer, scene, driver)
        else:
            _crank_outputs(offer, scene, driver)
    if scene.internal() and scene.inertia:
        _driver_inertia_outputs(offer, scene)
    chosen, problems = _choose(offer, scene, wanted)
    if scene.internal():
        # a mechanism FMU always says how far its outputs can be trusted
        chosen.append(
            Output(
                "amplification",
                None,
                MECHANISM_AMPLIFICATION_TEXT,
                "amplification",
                depends=[i.name for i in scene.inputs],
                source="mechanism",
            )
        )
    status_text = "0 ok, 1 a dyad is singular, 3 a reaction overflows"
    if scene.internal():
        status_text += ", 4 a dyad cannot assemble"
    if any(d.is_cylinder() for d in scene.drivers):
        status_text = (
            "0 ok, 1 a dyad or the cylinder is singular, 3 a reaction overflows, 4 a dyad or "
            "the cylinder cannot assemble"
        )
    status = Output(
        "status",
        None,
        status_text,
        "status",
        integer=True,
        depends=[i.name for i in scene.inputs],
    )
    scene.outputs = chosen + [status]
    return problems

"""A tailored scene's C: its header (the flat input and output blocks) and the code that
computes only what the scene needs.

Each link's resultant load is written out term by term, and a term that the scene
leaves out (no inertia, no gravity, a centre of mass baked at the pair, a mass baked
at 0) is not generated at all. The chain is solved from the last dyad back to the
first: the reaction of a later dyad on a link of an earlier one enters that link's
resultant as a force at the pair point, and the crank's driving torque and pivot
reaction come last. The closed forms are the core's dyad_react_<type>
(src/include/dyadfmu/loaded.h).

The emitter first makes a plan (which dyads the wanted outputs need, which links move)
and then writes the function body in passes: frames, accelerations of the pairs D,
resultants, the chain, the crank, the outputs. A last pass drops the constants nothing
reads; the body goes into templates/scene.c.in.
"""

from __future__ import annotations

import functools
import math
import re
import sys
from pathlib import Path
from string import Template

from dyadgen import textsafe
from dyadgen.emit import batch_c, kinematics_c, tangent_c
from dyadgen.model import Attachment, Crank, Dyad, Param, Scene, c_real, loaders, member
from dyadgen.needs import effort_of, inertia_entry_member, kin_name_of_cylinder
from dyadgen.table import Table

TEMPLATE = Path(__file__).resolve().parent / "templates" / "scene.c.in"
#: the output member of a mechanism FMU's own amplification
MECHANISM_AMPLIFICATION = "amplification"
KINEMATICS_TEMPLATE = TEMPLATE.with_name("scene_kinematics.c.in")
#: what both files of a scene (<identifier>_scene.c and _scene_tangent.c) report a failure with
HELPERS_TEMPLATE = TEMPLATE.with_name("scene_helpers.c.in")
TANGENT_TEMPLATE = TEMPLATE.with_name("scene_tangent.c.in")
FIXED_POINT_TEMPLATE = TEMPLATE.with_name("scene_fixed_point.c.in")
CHECK_TEMPLATE = TEMPLATE.with_name("scene_check.c.in")
#: the failure of a dyad whose values solve while their rates overflow: the derivative's alone
DERIVATIVE_CASE = """    } else if (dyad->status == DYAD_STATUS_OK) {
        /* the values solve, their rates overflow */
        out->status = 0;
        SCENE_REASON(evaluation->reason, sizeof evaluation->reason,
                     "the directional derivative of dyad %s is not finite at these inputs", name);
"""
KINEMATICS_INCLUDE = '#include "dyadfmu/dyad.h"\n#include "dyadfmu/kinematics.h"\n'
FAIL_TEMPLATE = TEMPLATE.with_name("scene_fail.c.in")
CYLINDER_INCLUDE = '#include "dyadfmu/cylinder.h"\n'
CYLINDER_FAILURE_TEMPLATE = TEMPLATE.with_name("cylinder_failure.c.in")
FAIL_CYLINDER_TEMPLATE = TEMPLATE.with_name("fail_cylinder.c.in")


def _vec(x: str, y: str) -> str:
    return f"dyad_vec2_make({x}, {y})"


def _sum(terms: list) -> str:
    """The C sum of vector terms (0 if none)."""
    if not terms:
        return "dyad_vec2_make(0.0, 0.0)"
    expr = terms[0]
    for t in terms[1:]:
        expr = f"dyad_add({expr}, {t})"
    return expr


def _unit_vector(angle: float) -> str:
    return _vec(c_real(math.cos(angle)), c_real(math.sin(angle)))


class _Code:
    """The lines of the function body, indented one level."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def __call__(self, text: str = "") -> None:
        self.lines.append(("    " + text) if text else "")


class Plan:
    """What the code of a scene computes: the dyads the wanted outputs need (their own,
    the dyads loading those, and for the crank's outputs every dyad on the crank), the
    links whose resultants it forms, and the C names of their pairs' accelerations."""

    def __init__(self, scene: Scene, lane: bool = False, bounds: bool = True) -> None:
        self.scene = scene
        #: the code of one sample of a batch (src/dyad_lanes.h): no branch, no early
        #: return; each check's failure counted in `bad`
        self.lane = lane
        #: the reactions' bounds computed (a batch may leave them out: :func:`bare_lanes`)
        self.bounds = bounds
        self.drivers = scene.drivers
        self.names = {i.name: i for i in scene.inputs}
        #: every driver's balance is wanted (one output of one of them asks for them all)
        self.crank_needed = any(o.source == "crank" for o in scene.outputs)
        needed = {int(o.source) for o in scene.outputs if o.source.isdigit()}
        if self.crank_needed:
            needed |= {d.index for d in scene.dyads if any(a.kind == "crank" for a in (d.k, d.p))}
        for d in list(scene.dyads):
            if d.index in needed:
                needed |= {other.index for other in loaders(scene, d)}
        self.solved = [d for d in scene.dyads if d.index in needed]
        crank = [driver.name for driver in self.drivers]
        self.everything = crank + [g for d in scene.dyads for g in (d.m, d.n)]
        self.moving = (crank if self.crank_needed else []) + [
            g for d in self.solved for g in (d.m, d.n)
        ]
        #: internal kinematics: the effective inertia's outputs, the dyads whose kinematics
        #: the code solves
        self.inertia_needed = any(o.source == "driver" for o in scene.outputs) or any(
            o.name.endswith(("torque0", "force0")) and o.source == "crank" for o in scene.outputs
        )
        self.kinematic = (
            kinematics_c.needed_dyads(scene, self.solved, self.inertia_needed)
            if scene.internal()
            else []
        )
        #: the kinematics function runs: for the dyads' motion, or a cylinder's
        self.runs_kinematics = bool(self.kinematic) or bool(kinematics_c.cylinders(scene))
        self.accel: dict[str, str | None] = {}  # link -> C name of a_D or None for zero
        self.accel_size: dict[str, str] = {}  # link -> C expression of the size of a_D's terms

    def direct_loaders(self, d: Dyad) -> list:
        """The dyads whose outer pairs sit on this dyad's links."""
        return [x for x in self.scene.dyads if any(a.link in (d.m, d.n) for a in (x.k, x.p))]

    def inp(self, name: str) -> str:
        """The input block's member of an input, or the C expression that computes it
        (internal kinematics)."""
        if name in self.names:
            return f"in->{self.names[name].member}"
        return self.scene.computed[name]

    def has(self, name: str) -> bool:
        """Whether the scene has the input, or computes it."""
        return name in self.names or name in self.scene.computed

    def omega(self, g: str) -> str | None:
        """A link's angular velocity, where it is an input."""
        return self.inp(g + ".omega") if self.has(g + ".omega") else None

    def epsilon(self, g: str) -> str | None:
        """A link's angular acceleration, where it is an input."""
        return self.inp(g + ".epsilon") if self.has(g + ".epsilon") else None

    def point(self, g: str, at: tuple[Param, Param]) -> str | None:
        """C expression of a point's offset from D_g (O for the crank) given (Param, Param)."""
        c = member(g)
        x, y = at
        if x.is_zero() and y.is_zero():
            return None
        if y.is_zero():
            return f"dyad_scale({x.c()}, {c}_i)"
        if x.is_zero():
            return f"dyad_scale({y.c()}, {c}_j)"
        return f"dyad_combine({x.c()}, {c}_i, {y.c()}, {c}_j)"

    def attachment_point(self, att: Attachment) -> str | None:
        """The pair's point (for a sliding pair: the guide's point) from the carrier's D."""
        driver = self.scene.driver_of(att.link) if att.kind == "crank" else None
        if driver is not None and att.at is None and driver.is_ram():
            return None  # the ram's origin R
        if driver is not None and att.at is None and driver.is_cylinder():
            params = driver.params  # the rod's pin B
            return self.point(att.link, (params["pin.x"], params["pin.y"]))
        if driver is not None and att.at is None:
            length = driver.params["length"]
            return self.point(att.link, (length, Param("", 0.0, "m", "")))
        return self.point(att.link, att.at)

    def has_com(self, g: str) -> bool:
        """Whether a link's centre of mass lies off its pair D (O for the crank)."""
        params = self.scene.params_of(g)
        com_x = params.get("com.x")
        return com_x is not None and not (com_x.is_zero() and params["com.y"].is_zero())


# ---------------------------------------------------------------------------
# Passes
# ---------------------------------------------------------------------------
def _kinematics(plan: Plan, code: _Code) -> None:
    """Internal kinematics: the chain's motion from the driver's, first."""
    if not plan.runs_kinematics:
        return
    scene = plan.scene
    rates = ", ".join(
        f"{rate}, {accel}"
        for rate, accel in (kinematics_c.driver_rates(scene, d) for d in scene.drivers)
    )
    if plan.lane:
        code(f"{scene.identifier}_kinematics kin;")
        code(f"bad += kinematics_lane(in, {rates}, &kin);")
        return
    code("/* The kinematics from the driver outwards; a dyad that cannot close (or is at a")
    code(" * dead centre) stops here with every output NaN. */")
    code(f"{scene.identifier}_kinematics kin;")
    code("{")
    code("    int failed = 0;")
    code(f"    const dyad_kin_result* bad = kinematics(in, {rates}, &kin, &failed);")
    code("    if (bad != NULL) {")
    code(f"        fail_kinematics(out, bad, failed, {scene.threshold.c()}, evaluation);")
    code("        return;")
    code("    }")
    code("}")
    code()


def _frames(plan: Plan, code: _Code) -> None:
    code("/* Link frames: i from D towards E, j = k0 x i. */")
    for g in plan.everything:
        c = member(g)
        link = plan.scene.links.get(g)
        if link is not None and link.translating:
            a = link.params["angle"]
            value = f"dyad_dir_from_angle({a.c()})" if a.tunable else _unit_vector(a.value)
            code(f"const dyad_vec2 {c}_i = {value};")
        elif plan.has(g + ".angle"):
            code(f"const dyad_vec2 {c}_i = {plan.inp(g + '.angle')};")
        else:
            continue  # a link the requested outputs do not involve
        code(f"const dyad_vec2 {c}_j = dyad_perp({c}_i);")


def _carried_accel(plan: Plan, code: _Code, g: str, att: Attachment) -> None:
    """a_D of a link whose pair D sits on a moving link: from that link's motion."""
    c = member(g)
    carrier = att.link
    r = plan.attachment_point(att)
    terms = []
    sizes = []
    if plan.accel.get(carrier):
        terms.append(plan.accel[carrier])
        sizes.append(plan.accel_size[carrier])
    if r is not None:
        code(f"const dyad_vec2 {c}_r_d = {r};")
        w, e = plan.omega(carrier), plan.epsilon(carrier)
        if e:
            terms.append(f"dyad_scale({e}, dyad_perp({c}_r_d))")
            sizes.append(f"dyad_fabs({e}) * dyad_norm1({c}_r_d)")
        if w:
            terms.append(f"dyad_scale(-{w} * {w}, {c}_r_d)")
            sizes.append(f"{w} * {w} * dyad_norm1({c}_r_d)")
    if not terms:
        plan.accel[g] = None
        return
    code(f"const dyad_vec2 {c}_a_d = {_sum(terms)};")
    plan.accel[g] = f"{c}_a_d"
    code(f"const dyad_real {c}_a_d_size = {' + '.join(sizes)};")
    plan.accel_size[g] = f"{c}_a_d_size"


def _accelerations(plan: Plan, code: _Code) -> None:
    if not plan.scene.inertia:
        return
    code()
    code("/* Accelerations of the pairs D: 0 on a fixed pivot, an input on a guide or an")
    code(" * external link, and from the carrying link's motion on a moving link. */")
    for driver in plan.drivers:
        plan.accel[driver.name] = None
        if driver.pivot_on is not None and driver.name in plan.moving:
            # the pivot O moves with the link carrying it
            at = (driver.params["at.x"], driver.params["at.y"])
            _carried_accel(plan, code, driver.name, Attachment("crank", driver.pivot_on, at))
        if driver.is_ram() and plan.crank_needed:
            c = member(driver.name)
            code(f"const dyad_vec2 {c}_a_d = dyad_scale(in->{c}_acceleration, {c}_i);")
            plan.accel[driver.name] = f"{c}_a_d"
            plan.accel_size[driver.name] = f"dyad_fabs(in->{c}_acceleration)"
    for d in plan.solved:
        for g, att in ((d.m, d.k), (d.n, d.p)):
            c = member(g)
            if plan.has(g + ".accel_d.x"):
                given = _vec(plan.inp(g + ".accel_d.x"), plan.inp(g + ".accel_d.y"))
                code(f"const dyad_vec2 {c}_a_d = {given};")
                plan.accel[g] = f"{c}_a_d"
                plan.accel_size[g] = f"dyad_norm1({c}_a_d)"
            elif att.kind in ("crank", "link"):
                _carried_accel(plan, code, g, att)
            else:
                plan.accel[g] = None


def _mass_terms(plan: Plan, g: str, r: str | None) -> tuple[list, list]:
    """The terms the mass multiplies: gravity, minus the acceleration of the centre of
    mass (without the centripetal term), and their sizes."""
    scene = plan.scene
    c = member(g)
    inner = []
    inner_sizes = []
    if scene.gravity:
        gx, gy = scene.gravity_params
        inner.append(_vec(gx.c(), gy.c()))
        inner_sizes.append(f"dyad_norm1({inner[-1]})")
    if scene.inertia:
        tang = []
        if plan.accel.get(g):
            tang.append(plan.accel[g])
            inner_sizes.append(plan.accel_size[g])
        e = plan.epsilon(g)
        if e and r is not None:
            tang.append(f"dyad_scale({e}, dyad_perp({c}_r))")
            inner_sizes.append(f"dyad_fabs({e}) * dyad_norm1({c}_r)")
        inner += [f"dyad_neg({t})" for t in tang]
    return inner, inner_sizes


def _force_terms(plan: Plan, g: str, r: str | None) -> tuple[list, list]:
    """The terms of a link's resultant force and their sizes (dyadfmu/loaded.h), as the
    core forms them."""
    link = plan.scene.links.get(g)
    mass = plan.scene.params_of(g).get("mass")
    terms = []
    sizes = []
    if link is not None and link.force:
        terms.append(_vec(plan.inp(g + ".force.x"), plan.inp(g + ".force.y")))
        sizes.append(f"dyad_norm1({terms[-1]})")
    if mass is not None and not mass.is_zero():
        inner, inner_sizes = _mass_terms(plan, g, r)
        if inner:
            terms.append(f"dyad_scale({mass.c()}, {_sum(inner)})")
            sizes.append(f"{mass.c()} * ({' + '.join(inner_sizes)})")
    return terms, sizes


def _moment_terms(plan: Plan, g: str) -> tuple[list, list]:
    link = plan.scene.links.get(g)
    inert = plan.scene.params_of(g).get("inertia")
    e = plan.epsilon(g)
    terms = []
    sizes = []
    if link is not None and link.moment:
        terms.append(plan.inp(g + ".moment"))
        sizes.append(f"dyad_fabs({terms[-1]})")
    if plan.scene.inertia and inert is not None and not inert.is_zero() and e:
        terms.append(f"-{inert.c()} * {e}")
        sizes.append(f"{inert.c()} * dyad_fabs({e})")
    return terms, sizes


def _point_loads(plan: Plan, g: str, r: str | None) -> tuple[list, list, list, list]:
    """The terms of the [[load]] tables on link g: each force F (global, or R(theta) F
    for a follower force) joins the resultant, and its moment about the centre of mass
    C, (P - C) x F with P - C = R(theta) at - r, joins the moment; a pure moment joins
    as it is. Returns (force terms, their sizes, moment terms, their sizes)."""
    c = member(g)
    forces, force_sizes, moments, moment_sizes = [], [], [], []
    for load in plan.scene.point_loads:
        if load.link != g:
            continue
        n = load.name
        if load.force:
            fx, fy = plan.inp(f"{n}.force.x"), plan.inp(f"{n}.force.y")
            f = _vec(fx, fy)
            size = f"dyad_norm1({f})"
            if load.components == "link":  # a follower force turns with its link
                f = f"dyad_combine({fx}, {c}_i, {fy}, {c}_j)"
                # its components' sizes: the turn's products may cancel
                size = f"dyad_fabs({fx}) * dyad_norm1({c}_i) + dyad_fabs({fy}) * dyad_norm1({c}_j)"
            forces.append(f)
            force_sizes.append(size)
            p = plan.point(g, load.at)
            arm = p if r is None else f"dyad_neg({c}_r)" if p is None else f"dyad_sub({p}, {c}_r)"
            if arm is not None:
                moments.append(f"dyad_cross({arm}, {f})")
                moment_sizes.append(f"dyad_norm1({arm}) * ({size})")
        if load.moment:
            moments.append(plan.inp(f"{n}.moment"))
            moment_sizes.append(f"dyad_fabs({moments[-1]})")
    return forces, force_sizes, moments, moment_sizes


def _resultant(plan: Plan, code: _Code, g: str) -> None:
    c = member(g)
    r = None
    if plan.has_com(g):
        params = plan.scene.params_of(g)
        r = plan.point(g, (params["com.x"], params["com.y"]))
        code(f"const dyad_vec2 {c}_r = {r};")
    force_terms, force_sizes = _force_terms(plan, g, r)
    placed, placed_sizes, placed_moments, placed_moment_sizes = _point_loads(plan, g, r)
    force_terms += placed
    force_sizes += placed_sizes
    code(f"dyad_vec2 {c}_f = {_sum(force_terms)};")
    moment_terms, moment_sizes = _moment_terms(plan, g)
    moment_terms += placed_moments
    moment_sizes += placed_moment_sizes
    code(f"dyad_real {c}_m = {' + '.join(moment_terms) if moment_terms else '0.0'};")
    if r is not None and force_terms:
        code(f"dyad_real {c}_m_d = {c}_m + dyad_cross({c}_r, {c}_f);")
        moment_sizes.append(f"dyad_norm1({c}_r) * {c}_f_size")
    else:
        code(f"dyad_real {c}_m_d = {c}_m;")
    code(f"dyad_real {c}_f_size = {' + '.join(force_sizes) or '0.0'};")
    code(f"dyad_real {c}_m_d_size = {' + '.join(moment_sizes) or '0.0'};")
    mass = plan.scene.params_of(g).get("mass")
    w = plan.omega(g)
    if plan.scene.inertia and mass is not None and not mass.is_zero() and r is not None and w:
        code(f"{c}_f = dyad_add({c}_f, dyad_scale({mass.c()} * {w} * {w}, {c}_r));")
        code(f"{c}_f_size += {mass.c()} * {w} * {w} * dyad_norm1({c}_r);")
    code(f"(void){c}_m;")
    code(f"(void){c}_f_size;")
    code(f"(void){c}_m_d_size;")


def _resultants(plan: Plan, code: _Code) -> None:
    code()
    code("/* Resultant of each link's active load, weight and inertia at its centre of mass:")
    code(" * force f, moment m about the centre of mass, moment m_d about D (without the")
    code(" * centripetal force, which points at D). Only the scene's terms are written. */")
    for g in plan.moving:
        _resultant(plan, code, g)


def _guide(plan: Plan, d: Dyad, side: str, att: Attachment) -> str:
    """The direction i_k or i_p of the guide a translational outer pair slides on."""
    if att.kind == "external":
        return plan.inp(f"{d.prefix()}guide_{side}.angle")
    guide = att.guide
    if att.kind == "frame":
        return f"dyad_dir_from_angle({guide.c()})" if guide.tunable else _unit_vector(guide.value)
    carrier = member(att.link)
    if guide.is_zero():
        return f"{carrier}_i"
    if guide.tunable:
        return f"dyad_combine(cos({guide.c()}), {carrier}_i, sin({guide.c()}), {carrier}_j)"
    cos, sin = c_real(math.cos(guide.value)), c_real(math.sin(guide.value))
    return f"dyad_combine({cos}, {carrier}_i, {sin}, {carrier}_j)"


def _load(plan: Plan, code: _Code, d: Dyad) -> None:
    """dyad_loaded of one dyad: its links' frames, lengths and resultants, its guides."""
    code("    dyad_loaded load;")
    for side, g in (("m", d.m), ("n", d.n)):
        c = member(g)
        link = plan.scene.links[g]
        length = plan.inp(g + ".length") if link.sliding else link.params["length"].c()
        code(f"    load.{side}.i = {c}_i;")
        code(f"    load.{side}.j = {c}_j;")
        code(f"    load.{side}.l = {length};")
        for part in ("f", "m", "m_d", "f_size", "m_d_size"):
            code(f"    load.{side}.{part} = {c}_{part};")
    for side, att in (("k", d.k), ("p", d.p)):
        if d.pair_kind("mk" if side == "k" else "np") == "T":
            code(f"    load.i_{side} = {_guide(plan, d, side, att)};")
        else:
            code(f"    load.i_{side} = dyad_vec2_make(1.0, 0.0);")
        code(f"    load.j_{side} = dyad_perp(load.i_{side});")


def _feedback(plan: Plan, code: _Code, d: Dyad, side: str, att: Attachment) -> None:
    """The dyad's reaction on the moving link its outer pair sits on."""
    if att.kind not in ("crank", "link") or att.link not in plan.moving:
        return
    dn = member(d.name or "dyad")
    pair_force = "r_mk" if side == "k" else "r_np"
    carrier = member(att.link)
    r = plan.attachment_point(att)
    reactive = ""
    if att.guide is not None:
        # the pair point slides along the guide; the pair also carries a moment
        slide = f"dyad_scale({plan.inp(d.prefix() + 'slide_' + side)}, load.i_{side})"
        r = slide if r is None else f"dyad_add({r}, {slide})"
        reactive = f" - {dn}.m_{pair_force[2:]}"
    also = " and the reactive moment" if reactive else ""
    force_size, moment_size = (
        ("dyad_lane_force_size", "dyad_lane_moment_size")
        if plan.lane
        else ("dyad_force_size", "dyad_moment_size")
    )
    code(f"    /* on {att.link}: -{pair_force.upper()} at the pair{also} */")
    code(f"    {carrier}_f = dyad_sub({carrier}_f, {dn}.{pair_force});")
    code(f"    {carrier}_f_size += {force_size}(&{dn});")
    if r is None:
        return
    moment = f" + {moment_size}(&{dn})" if reactive else ""
    code(f"    {{ const dyad_real moment = -dyad_cross({r}, {dn}.{pair_force}){reactive};")
    code(f"      {carrier}_m_d += moment;")
    code(f"      {carrier}_m_d_size += dyad_norm1({r}) * {force_size}(&{dn}){moment};")
    if plan.has_com(att.link):
        code(f"      {carrier}_m += moment + dyad_cross({carrier}_r, {dn}.{pair_force}); }}")
    else:
        code(f"      {carrier}_m += moment; }}")


def _bound(plan: Plan, code: _Code, d: Dyad) -> None:
    """The bound of a dyad's reactions, once they are solved: the core's amplification
    (its own round-off, and that of the reactions of the dyads loading it, which reach
    it through its loads' sizes) and, where the kinematics are internal, its motion's
    round-off, and what its loaders' motion added to theirs. A relative error e of the
    motion moves the loads by e of their sizes and the conditioning by e of itself:
    e (1 + data factor) of the largest reaction, the data factor being amplification x
    conditioning (dyad_amplification.h); so does an extra error e of a loader's
    reactions, relative to its largest."""
    dn = member(d.name or "dyad")
    if not plan.bounds:
        return
    extra = []
    if d in plan.kinematic:
        extra.append(f"DYAD_R(2.0) * kin.{kinematics_c.kin_name(d)}.amplification")
    solved = {x.index for x in plan.solved}
    for loader in plan.direct_loaders(d):
        if loader.index in solved:
            ln = member(loader.name or "dyad")
            extra.append(f"({ln}_bound - {ln}.amplification)")
    if not extra:
        code(f"const dyad_real {dn}_bound = {dn}.amplification;")
        return
    code(
        f"const dyad_real {dn}_bound = {dn}.amplification + {dn}.amplification * "
        f"{dn}.conditioning * ({' + '.join(extra)});"
    )


def mechanism_amplification(plan: Plan) -> str:
    """The C expression of a mechanism FMU's amplification: the bound of every output it
    reports. A dyad whose reactions are solved contributes its bound, which holds its
    motion's amplification twice over; one whose motion alone is reported, three times
    its motion's (the accelerations and the effective inertia square the rates)."""
    solved = {d.index for d in plan.solved}
    terms = ["DYAD_R(1.0)"] + [f"{member(d.name or 'dyad')}_bound" for d in plan.solved]
    for driver in kinematics_c.cylinders(plan.scene):
        kin = f"kin.{kin_name_of_cylinder(driver)}"
        terms.append(f"DYAD_R(3.0) * {kin}.kin_amplification")
        if plan.crank_needed:
            terms.append(f"{member(driver.actuator)}_bound")
    terms += [
        f"DYAD_R(3.0) * kin.{kinematics_c.kin_name(d)}.amplification"
        for d in plan.kinematic
        if d.index not in solved
    ]
    return " + ".join(terms)


def _chain(plan: Plan, code: _Code) -> None:
    threshold = plan.scene.threshold.c()
    code()
    code("/* The dyads from the last to the first: each one's reactions load the links")
    code(" * it is attached to, as forces at its pair points. */")
    for d in reversed(plan.solved):
        dn = member(d.name or "dyad")
        code(f"{{ /* dyad {d.name or ''} ({d.type}) */")
        _load(plan, code, d)
        code(f"    load.singular_threshold = {threshold};")
        if plan.lane:
            bare = "" if plan.bounds else "bare_"
            code(f"    bad += dyad_react_lane_{bare}{d.type.lower()}(&load, &{dn});")
        else:
            code(f"    if (dyad_react_{d.type.lower()}(&load, &{dn}) != DYAD_STATUS_OK) {{")
            code(
                f"        fail(out, &{dn}, {textsafe.c_string(d.name or d.type)}, "
                f"{threshold}, evaluation);"
            )
            code("        return;")
            code("    }")
        _feedback(plan, code, d, "k", d.k)
        _feedback(plan, code, d, "p", d.p)
        code("}")
        _bound(plan, code, d)


def _crank_outputs(plan: Plan, driver: Crank) -> tuple[bool, bool]:
    """Whether the crank's torque and its R_O are wanted."""
    c = member(driver.name)
    outputs = plan.scene.outputs
    return (
        any(o.member == f"{c}_torque" for o in outputs),
        any(o.member.startswith(f"{c}_r_o_") for o in outputs),
    )


def _wanted(plan: Plan, driver: Crank, key: str) -> bool:
    """Whether the driver's output `key` (its member's suffix) is wanted."""
    c = member(driver.driver_name())
    return any(o.member == f"{c}_{key}" for o in plan.scene.outputs)


def _ram(code: _Code, driver: Crank) -> None:
    """The ram: the actuator force balances the forces along the guide, the guide's
    normal force those across it and its reactive moment the moments about R."""
    c = member(driver.name)
    code()
    code("/* The ram: the actuator force balances the forces along its guide, the guide's")
    code(" * normal force those across it, its reactive moment the moments about R. */")
    code(f"{c}_force = -dyad_dot({c}_f, {c}_i);")
    code(f"{c}_guide_n = -dyad_dot({c}_f, dyad_perp({c}_i));")
    code(f"{c}_guide_m = -{c}_m_d;")


def _cylinder_bound(driver: Crank) -> str:
    """The bound of the cylinder's forces: the core's (its own terms) and the round-off
    of the loads on the link, which reach it summed (their sizes over the largest force,
    the sum of the forces' norms standing for the largest within a factor 4), both
    carrying the triangle's."""
    c, link = member(driver.actuator), member(driver.name)
    params = driver.params
    pin = f"dyad_norm1({kinematics_c._vec(params['pin.x'].c(), params['pin.y'].c())})"
    forces = " + ".join(
        [f"dyad_fabs({c}_cyl.axial_force)"] + [f"dyad_norm1({c}_cyl.r_{p})" for p in "abo"]
    )
    sizes = f"{link}_f_size + {link}_m_d_size / {pin}"
    return (
        f"{c}_cyl.amplification + {c}_cyl.kin_amplification * "
        f"(DYAD_R(1.0) + DYAD_R(4.0) * ({sizes}) / ({forces} + DYAD_REAL_MIN))"
    )


def _cylinder(plan: Plan, code: _Code, driver: Crank) -> None:
    """The cylinder: the loads on its link (its resultant about O, every dyad's reaction
    on it included) and the barrel's and the rod's own, balanced by the axial force and
    the pins' reactions (dyadfmu/cylinder.h)."""
    scene = plan.scene
    c, link = member(driver.actuator), member(driver.name)
    rate, accel = kinematics_c.driver_rates(scene, driver)
    code()
    code("/* The cylinder: its link's resultant (at O, with its moment about O) and the")
    code(" * barrel's and the rod's weight and inertia balanced by the axial force and the")
    code(" * pins' reactions. */")
    code("{")
    code("    dyad_cylinder_input cyl_in;")
    if kinematics_c.is_carried(driver):
        pins = tuple(f"kin.{name}" for name in kinematics_c.mount_names(driver))
    else:
        pins = (kinematics_c.fixed_pin(driver, "base"), kinematics_c.fixed_pin(driver, "at"))
    lines = kinematics_c.cylinder_input_lines(
        scene, driver, "cyl_in", (rate, accel), pins, lane=plan.lane
    )
    for line in lines:
        code("    " + (kinematics_c.lane_twins(line) if plan.lane else line))
    code(f"    cyl_in.link.force = {link}_f;")
    code(f"    cyl_in.link.moment = {link}_m_d;")
    if scene.gravity:
        gx, gy = scene.gravity_params
        code(f"    cyl_in.gravity = {_vec(gx.c(), gy.c())};")
    if plan.lane:
        branch = kinematics_c.branch_real(driver.params["branch"])
        code(f"    bad += dyad_cylinder_lane(&cyl_in, {branch}, &{c}_cyl);")
    else:
        code(f"    if (dyad_cylinder(&cyl_in, &{c}_cyl) != DYAD_STATUS_OK) {{")
        name = textsafe.c_string(driver.actuator)
        code(f"        fail_cylinder(out, &{c}_cyl, {name}, evaluation);")
        code("        return;")
        code("    }")
    code("}")
    code(f"{c}_force = {c}_cyl.axial_force;")
    code(f"const dyad_real {c}_bound = {_cylinder_bound(driver)};")


def _crank(plan: Plan, code: _Code) -> None:
    if not plan.crank_needed:
        return
    # from the last driver back: a cylinder's reactions load the earlier driver's link
    # that carries its pins before that driver's balance
    for driver in reversed(plan.drivers):
        if driver.is_cylinder():
            _cylinder(plan, code, driver)
            _cylinder_feedback(plan, code, driver)
        elif driver.is_ram():
            _ram(code, driver)
        else:
            _crank_balance(plan, code, driver)


def _cylinder_feedback(plan: Plan, code: _Code, driver: Crank) -> None:
    """A carried cylinder's reactions on the links carrying its pins: -R_A at A, -R_O at
    O, with their sizes."""
    c = member(driver.actuator)
    for key, carrier, force in (
        ("base", driver.base_on, f"{c}_cyl.r_a"),
        ("at", driver.pivot_on, f"{c}_cyl.r_o"),
    ):
        if carrier is None:
            continue
        g = member(carrier)
        pin = "A" if key == "base" else "O"
        r = plan.point(carrier, (driver.params[f"{key}.x"], driver.params[f"{key}.y"]))
        code(f"/* on {carrier}: the reaction of cylinder {driver.actuator} at {pin} */")
        code(f"{g}_f = dyad_sub({g}_f, {force});")
        code(f"{g}_f_size += dyad_norm1({force});")
        if r is None:
            continue
        code(f"{{ const dyad_real moment = -dyad_cross({r}, {force});")
        code(f"  {g}_m_d += moment;")
        code(f"  {g}_m_d_size += dyad_norm1({r}) * dyad_norm1({force});")
        if plan.has_com(carrier):
            code(f"  {g}_m += moment + dyad_cross({g}_r, {force}); }}")
        else:
            code(f"  {g}_m += moment; }}")


def _crank_balance(plan: Plan, code: _Code, driver: Crank) -> None:
    c = member(driver.name)
    torque, r_o = _crank_outputs(plan, driver)
    code()
    code("/* The crank: the driving torque balances the moments about O, R_O the forces. */")
    if torque or _wanted(plan, driver, "torque0"):
        code(f"{c}_torque = -{c}_m_d;")
    if r_o:
        code(f"{c}_r_o = dyad_neg({c}_f);")
    code(f"(void){c}_m_d;")


def _driver_inertia(plan: Plan, code: _Code) -> None:
    """J(q), dJ/dq and the balance at zero driver acceleration (internal kinematics);
    with several drivers M(q) and the balances at zero acceleration of every driver."""
    if not plan.inertia_needed:
        return
    if len(plan.drivers) > 1:
        _inertia_matrix(plan, code)
        return
    scene = plan.scene
    c = member(scene.crank.driver_name())
    j_terms, dj_terms = kinematics_c.inertia_terms(scene, plan.kinematic)
    code()
    code("/* The effective inertia at the driver: at unit rate and zero acceleration the")
    code(" * kinematics give each centre of mass's velocity per unit driver rate V and its")
    code(" * derivative along the driver V', each link's W and W': J = sum m V.V + I W^2,")
    code(" * dJ/dq = 2 sum (m V.V' + I W W'). */")
    code(f"{scene.identifier}_kinematics unit;")
    _unit_kinematics(plan, code, "unit", "1.0, 0.0")
    code(f"const dyad_real {c}_reduced_j = {' + '.join(j_terms) or '0.0'};")
    code(f"const dyad_real {c}_reduced_djdq = DYAD_R(2.0) * ({' + '.join(dj_terms) or '0.0'});")
    _, accel = kinematics_c.driver_rates(scene, scene.crank)
    balance = "force" if scene.crank.balances_with_force() else "torque"
    if _wanted(plan, scene.crank, f"{balance}0"):
        code(f"const dyad_real {c}_{balance}0 = {c}_{balance} - {c}_reduced_j * {accel};")


def _unit_kinematics(plan: Plan, code: _Code, target: str, rates: str) -> None:
    """The kinematics at the rates `rates` (C arguments) and zero accelerations."""
    scene = plan.scene
    if plan.lane:
        code(f"bad += kinematics_lane(in, {rates}, &{target});")
        return
    code("{")
    code("    int failed = 0;")
    code(f"    const dyad_kin_result* bad = kinematics(in, {rates}, &{target}, &failed);")
    code("    if (bad != NULL) {")
    code(f"        fail_kinematics(out, bad, failed, {scene.threshold.c()}, evaluation);")
    code("        return;")
    code("    }")
    code("}")


def _inertia_matrix(plan: Plan, code: _Code) -> None:
    """M(q) from the kinematics at unit rate of each driver alone, and each driver's
    effort at zero acceleration of every driver, h = effort - M q''."""
    scene = plan.scene
    drivers = plan.drivers
    code()
    code("/* The inertia matrix: at unit rate of driver a alone (the others at rest, no")
    code(" * acceleration) the kinematics give each centre of mass's velocity V_a and each")
    code(" * link's angular velocity W_a per unit rate of a: M_ab = sum m V_a.V_b + I W_a W_b,")
    code(" * symmetric; efforts = M(q) q'' + h. */")
    for driver in drivers:
        unit = f"unit_{member(driver.driver_name())}"
        rates = ", ".join("1.0, 0.0" if other is driver else "0.0, 0.0" for other in drivers)
        code(f"{scene.identifier}_kinematics {unit};")
        _unit_kinematics(plan, code, unit, rates)
    entry = functools.partial(inertia_entry_member, scene)
    for i, a in enumerate(drivers):
        for b in drivers[i:]:
            terms = kinematics_c.inertia_matrix_terms(scene, plan.kinematic, a, b)
            code(f"const dyad_real {entry(a, b)} = {' + '.join(terms) or '0.0'};")
        for b in drivers[:i]:
            code(f"const dyad_real {entry(a, b)} = {entry(b, a)};")
    for a in drivers:
        effort = effort_of(a)[0]
        if not _wanted(plan, a, f"{effort}0"):
            continue
        c = member(a.driver_name())
        terms = [f"{entry(a, b)} * {kinematics_c.driver_rates(scene, b)[1]}" for b in drivers]
        code(f"const dyad_real {c}_{effort}0 = {c}_{effort} - ({' + '.join(terms)});")


def _kinematic_exprs(scene: Scene) -> dict[str, str]:
    """The C expressions of the kinematic outputs (internal kinematics)."""
    exprs = {}
    for d in scene.dyads:
        kin = f"kin.{member(d.name or 'dyad')}"
        pre = member(d.prefix())
        for side, g in (("m", d.m), ("n", d.n)):
            c = member(g)
            exprs[f"{c}_angle"] = f"dyad_atan2({kin}.{side}.dir.y, {kin}.{side}.dir.x)"
            exprs[f"{c}_omega"] = f"{kin}.{side}.omega"
            exprs[f"{c}_epsilon"] = f"{kin}.{side}.epsilon"
            exprs[f"{c}_length"] = f"{kin}.{side}.length"
        for pair, point in (("d_m", "m.d"), ("e", "e"), ("d_n", "n.d")):
            for x in "xy":
                exprs[f"{pre}{pair}_position_{x}"] = f"{kin}.{point}.position.{x}"
        for side in "kp":
            exprs[f"{pre}slide_{side}"] = f"{kin}.slide_{side}.s"
    for driver in scene.drivers:
        c = member(driver.driver_name())
        for key in ("torque0", "force0", "reduced_j", "reduced_djdq"):
            exprs[f"{c}_{key}"] = f"{c}_{key}"
        for other in scene.drivers:
            entry = inertia_entry_member(scene, driver, other)
            exprs[entry] = entry
        if driver.is_cylinder():
            exprs.update(_cylinder_exprs(driver))
    return exprs


def _cylinder_exprs(driver: Crank) -> dict[str, str]:
    """The C expressions of a cylinder's outputs and of its link's."""
    c, link = member(driver.actuator), member(driver.name)
    kin = f"kin.{kin_name_of_cylinder(driver)}"
    exprs = {}
    for key in ("angle", "omega", "epsilon"):
        exprs[f"{link}_{key}"] = f"{kin}.link_{key}"
        exprs[f"{c}_{key}"] = f"{kin}.cylinder_{key}"
    for x in "xy":
        exprs[f"{c}_b_position_{x}"] = f"{kin}.b.position.{x}"
        exprs[f"{c}_r_a_{x}"] = f"{c}_cyl.r_a.{x}"
        exprs[f"{c}_r_b_{x}"] = f"{c}_cyl.r_b.{x}"
        exprs[f"{link}_r_o_{x}"] = f"{c}_cyl.r_o.{x}"
    exprs[f"{c}_conditioning"] = f"{kin}.conditioning"
    exprs[f"{c}_force"] = f"{c}_force"
    exprs[f"{c}_n_rod"] = f"{c}_cyl.n_rod"
    exprs[f"{c}_m_rod"] = f"{c}_cyl.m_rod"
    return exprs


def _output_exprs(scene: Scene) -> dict[str, str]:
    """The C expression of every output's value, by output member."""
    exprs = {}
    for driver in scene.drivers:
        c = member(driver.name)
        exprs[f"{c}_torque"] = f"{c}_torque"
        exprs[f"{c}_r_o_x"] = f"{c}_r_o.x"
        exprs[f"{c}_r_o_y"] = f"{c}_r_o.y"
        for key in ("force", "guide_n", "guide_m"):  # a ram's balance
            exprs[f"{c}_{key}"] = f"{c}_{key}"
    for d in scene.dyads:
        pre = member(d.prefix())
        dn = member(d.name or "dyad")
        for pair in ("mk", "np", "mn"):
            for c in "xy":
                exprs[f"{pre}r_{pair}_{c}"] = f"{dn}.r_{pair}.{c}"
            for kind in "nm":
                exprs[f"{pre}{kind}_{pair}"] = f"{dn}.{kind}_{pair}"
        exprs[f"{pre}conditioning"] = f"{dn}.conditioning"
        exprs[f"{pre}amplification"] = f"{dn}_bound"
    if scene.internal():
        exprs.update(_kinematic_exprs(scene))
    return exprs


def _outputs(plan: Plan, code: _Code, later: tuple[str, ...] = ()) -> None:
    """Every output written, those given later (see :func:`later_members`) NaN. In a
    batch's lane, an angle's direction goes to `turn` (its atan2 would keep the loop
    from vectorising: :func:`lane_angles`) and the outputs' finiteness is counted."""
    code()
    code("/* Outputs */")
    exprs = _output_exprs(plan.scene)
    if plan.scene.internal():
        exprs[MECHANISM_AMPLIFICATION] = mechanism_amplification(plan)
    turns = lane_angles(plan.scene, later) if plan.lane else {}
    for k, (y, x) in enumerate(turns.values()):
        code(f"turn[{k}] = dyad_vec2_make({x}, {y});")
    for o in plan.scene.outputs:
        if not o.integer and o.member not in turns:
            code(f"out->{o.member} = {'NAN' if o.member in later else exprs[o.member]};")
    if plan.lane:
        written = [
            o.member
            for o in plan.scene.outputs
            if not o.integer and o.member not in later and o.member not in turns
        ]
        residues = [f"(out->{m} - out->{m})" for m in written]
        residues += [f"dyad_kin_residue(turn[{k}])" for k in range(len(turns))]
        code(f"return bad + DYAD_FAILED({' + '.join(residues) or '0.0'} == 0);")
        return
    code("out->status = 0;")
    code("check_first(out, evaluation);" if later else "check(out, evaluation);")


#: A cylinder's angles (dyad_cylinder_result) by the direction each is the atan2 of.
CYLINDER_ANGLES = {"link_angle": "link_dir", "cylinder_angle": "axis"}


def lane_angles(scene: Scene, later: tuple[str, ...] = ()) -> dict[str, tuple[str, str]]:
    """The angle outputs a batch's lane leaves to after its loop: member -> the C of the
    (y, x) of its direction, whose atan2 the scalar evaluation writes (or reads from a
    cylinder's result, which holds that atan2)."""
    exprs = _output_exprs(scene)
    found = {}
    for o in scene.outputs:
        expr = exprs.get(o.member, "")
        if o.integer or o.member in later:
            continue
        result, _, field = expr.rpartition(".")
        if field in CYLINDER_ANGLES and result.startswith("kin."):
            direction = f"{result}.{CYLINDER_ANGLES[field]}"
            found[o.member] = (f"{direction}.y", f"{direction}.x")
            continue
        if not expr.startswith("dyad_atan2("):
            continue
        arguments = expr[len("dyad_atan2(") : -1].split(", ")
        if len(arguments) != 2 or not expr.endswith(")"):
            raise ValueError(f"an angle's expression the batch cannot split: {expr}")
        found[o.member] = (arguments[0], arguments[1])
    return found


def _inertia_members(plan: Plan) -> tuple[set[str], list[str]]:
    """The effective inertia's pass (:func:`_driver_inertia`): (the output members it
    gives, the drivers' efforts it reads)."""
    scene = plan.scene
    if len(plan.drivers) > 1:
        drivers = plan.drivers
        gives = {inertia_entry_member(scene, a, b) for a in drivers for b in drivers}
        efforts = [(member(a.driver_name()), effort_of(a)[0]) for a in drivers]
        efforts = [
            (c, e) for (c, e), a in zip(efforts, drivers, strict=True) if _wanted(plan, a, f"{e}0")
        ]
    else:
        c = member(scene.crank.driver_name())
        balance = "force" if scene.crank.balances_with_force() else "torque"
        gives = {f"{c}_reduced_j", f"{c}_reduced_djdq"}
        efforts = [(c, balance)] if _wanted(plan, scene.crank, f"{balance}0") else []
    gives |= {f"{c}_{e}0" for c, e in efforts}
    return gives, [f"{c}_{e}" for c, e in efforts]


def later_members(scene: Scene) -> tuple[str, ...]:
    """The outputs of the effective inertia's own kinematic pass (J and dJ/dq, or M(q),
    and each driver's effort at zero acceleration) where that pass can run after the
    rest, as <identifier>_evaluate_later: a mechanism of inverse dynamics whose every
    effort the pass reads is an output. An FMU step leaves them to their first read.
    Empty where there is no such pass, or where a plant's step needs it."""
    plan = Plan(scene)
    if not (scene.internal() and plan.inertia_needed) or scene.forward():
        return ()
    gives, reads = _inertia_members(plan)
    exprs = _output_exprs(scene)
    outputs = {o.member for o in scene.outputs if not o.integer}
    if any(r not in outputs or exprs.get(r) != r for r in reads):
        return ()
    return tuple(o.member for o in scene.outputs if o.member in gives)


def bound_members(scene: Scene) -> tuple[str, ...]:
    """The outputs that are the reactions' bounds: each dyad's amplification and the
    mechanism's."""
    exprs = _output_exprs(scene)
    return tuple(
        o.member
        for o in scene.outputs
        if o.member == MECHANISM_AMPLIFICATION or exprs.get(o.member, "").endswith("_bound")
    )


#: Each scalar the scene's C compiles with (DYAD_REAL_FLOAT: float): its eps, its largest
#: finite value and DYAD_DEFAULT_SINGULAR_THRESHOLD (dyadfmu/types.h), sqrt(eps).
SCALARS = (
    (2.0**-52, sys.float_info.max, 1.4901161193847656e-8),
    (2.0**-23, 3.4028234663852886e38, 3.4526698e-4),
)


def bare_lanes(scene: Scene) -> bool:
    """Whether the scene's batch has lanes without the bounds (<identifier>_lanes_bare),
    for a call that reads none of them: where leaving them out cannot change a status.
    The scalar evaluation says 3 where a bound overflows; with the threshold t a constant
    and no cylinder (whose bound divides by its forces), none can. A dyad accepted has
    conditioning c >= t and its motion's amplification at most 1 / t (else its status is
    not 0); its amplification a is its data factor, at most 1 / eps while its reactions
    stay below DYAD_REAL_MAX eps (the lanes count a sample beyond as failed: it is
    evaluated alone), over c (dyad_amplification.h). So its bound a + a c (2 / t + its
    loaders' bounds) is at most (1 / eps) (1 / t + 2 / t + those bounds), and the
    mechanism's 1 + their sum + 3 / t per dyad whose motion alone is reported: checked
    finite here, with a margin, in double and in float (SCALARS), where a chain of dyads
    loading each other multiplies the data factors (2^23 each) sooner."""
    if kinematics_c.cylinders(scene) or scene.threshold.tunable:
        return False
    plan = Plan(scene)
    for eps, largest, default in SCALARS:
        threshold = default if scene.threshold.macro else scene.threshold.value
        bound: dict[int, float] = {}
        for d in reversed(plan.solved):
            loaders = sum(bound.get(x.index, 0.0) for x in plan.direct_loaders(d))
            motion = 2 / threshold if d in plan.kinematic else 0.0
            bound[d.index] = (1 / eps) * (1 / threshold + motion + loaders)
        solved = {d.index for d in plan.solved}
        motions = sum(3 / threshold for d in plan.kinematic if d.index not in solved)
        if not 1 + sum(bound.values()) + motions < largest / 4:
            return False
    return True


def _later_body(plan: Plan, later: tuple[str, ...]) -> list[str]:
    """<identifier>_evaluate_later's body: the efforts from the outputs, the effective
    inertia's pass, its outputs and their check."""
    code = _Code()
    for effort in _inertia_members(plan)[1]:
        code(f"const dyad_real {effort} = out->{effort};")
    _driver_inertia(plan, code)
    exprs = _output_exprs(plan.scene)
    code()
    for m in later:
        code(f"out->{m} = {exprs[m]};")
    code("check_later(out, evaluation);")
    return drop_unused_constants(code.lines)


def drop_unused_constants(lines: list) -> list:
    """Remove `const ... name = ...;` lines whose name nothing else reads (a frame vector j
    that no term of the scene needs, say), until none is left. Each identifier's uses are
    counted once; removing a line takes its uses off the counts, which may free the
    constants it read in turn."""
    declaration = re.compile(r"^\s*const [A-Za-z0-9_]+ ([A-Za-z0-9_]+) = .*;$")
    word = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
    uses: dict[str, int] = {}
    declared: dict[str, int] = {}  # constant -> its line
    for k, line in enumerate(lines):
        for w in word.findall(line):
            uses[w] = uses.get(w, 0) + 1
        m = declaration.match(line)
        if m:
            declared[m.group(1)] = k
    removed: set[int] = set()
    pending = [name for name in declared if uses[name] == 1]
    while pending:
        name = pending.pop()
        k = declared[name]
        if k in removed or uses[name] != 1:
            continue
        removed.add(k)
        for w in word.findall(lines[k]):
            uses[w] -= 1
            if w != name and w in declared and uses[w] == 1:
                pending.append(w)
    return [line for k, line in enumerate(lines) if k not in removed]


PASSES = (
    _kinematics,
    _frames,
    _accelerations,
    _resultants,
    _chain,
    _crank,
    _driver_inertia,
    _outputs,
)


def _declarations(plan: Plan) -> tuple[list[str], list[str]]:
    dyads = [f"    dyad_result {member(d.name or 'dyad')};" for d in plan.solved]
    crank = []
    for driver in plan.drivers if plan.crank_needed else []:
        if driver.is_cylinder():
            c = member(driver.actuator)
            crank += [f"    dyad_cylinder_result {c}_cyl;", f"    dyad_real {c}_force;"]
        elif driver.is_ram():
            c = member(driver.name)
            crank += [f"    dyad_real {c}_{key};" for key in ("force", "guide_n", "guide_m")]
        else:
            c = member(driver.name)
            torque, r_o = _crank_outputs(plan, driver)
            if torque or _wanted(plan, driver, "torque0"):
                crank.append(f"    dyad_real {c}_torque;")
            if r_o:
                crank.append(f"    dyad_vec2 {c}_r_o;")
    return dyads, crank


@functools.cache
def _template(path: Path = TEMPLATE) -> Template:
    return Template(path.read_text(encoding="utf-8"))


def _kinematics_code(plan: Plan, tangent: bool = False, later: str = "") -> str:
    """The kinematics function (for the tangent's file, the block type alone) and its
    failure report, for internal kinematics; `fixed_point` where it or `later` (the
    code that follows) calls it."""
    if not plan.runs_kinematics:
        return ""
    scene = plan.scene
    if tangent:
        function = kinematics_c.kinematics_type(scene)
    else:
        function = kinematics_c.kinematics_function(scene, plan.kinematic)
    fixed = "fixed_point(" in function + later
    return _template(KINEMATICS_TEMPLATE).substitute(
        ident=scene.identifier,
        fixed_point=_template(FIXED_POINT_TEMPLATE).template + "\n" if fixed else "",
        kinematics_function=function,
        names=kinematics_c.failure_names(scene),
        cylinder_failure=_template(CYLINDER_FAILURE_TEMPLATE).template
        if kinematics_c.cylinders(scene)
        else "",
        failure_text=_failure_text(scene),
    )


def _failure_text(scene: Scene) -> str:
    """failure_text: how a dyad's (or the cylinder's) triangle fails to close, in words."""
    lines = [
        "/* How the failing dyad's (or cylinder's) closure fails, in words. */",
        "static const char* failure_text(const dyad_kin_result* dyad, int index)",
        "{",
    ]
    if kinematics_c.cylinders(scene):
        lines += [
            f"    if (index >= {len(scene.dyads)}) {{",
            "        return dyad->failure == DYAD_KIN_TOO_FAR",
            '                   ? "the cylinder is too short to reach, |O A| > |O B| + s"',
            '                   : "the triangle of its pins does not close, |O A| < ||O B| - s|";',
            "    }",
        ]
    else:
        lines.append("    (void)index;")
    lines += ["    return dyad_kin_failure_name(dyad->failure);", "}", ""]
    return "\n".join(lines)


def _helpers(
    plan: Plan, tangent: bool = False, later_code: str = "", later: tuple[str, ...] = ()
) -> str:
    """What a file of the scene reports a failure with: set_nan, fail, the kinematics
    (see _kinematics_code) and check (with check_later for the outputs ``later``)."""
    reals = [o.member for o in plan.scene.outputs if not o.integer]
    return _template(HELPERS_TEMPLATE).substitute(
        ident=plan.scene.identifier,
        nan_lines="\n".join(f"    out->{m} = NAN;" for m in reals),
        fail_dyad=_template(FAIL_TEMPLATE).substitute(
            ident=plan.scene.identifier, derivative_case=DERIVATIVE_CASE if tangent else ""
        )
        if plan.solved
        else "",
        kinematics_code=_kinematics_code(plan, tangent, later_code),
        fail_cylinder=_template(FAIL_CYLINDER_TEMPLATE).substitute(ident=plan.scene.identifier)
        if plan.crank_needed and kinematics_c.cylinders(plan.scene)
        else "",
        check_functions=_checks(plan.scene.identifier, reals, later),
    )


def _checks(ident: str, reals: list[str], later: list[str]) -> str:
    """check: every Real output finite, else each one NaN and status 3; with outputs given
    later (see :func:`later_members`) also check_first over the others, for the first half,
    and check_later over those, for the second (the whole evaluation checks them all)."""

    def one(name: str, members: list[str]) -> str:
        terms = " + ".join(f"(out->{m} - out->{m})" for m in members) or "0.0"
        return _template(CHECK_TEMPLATE).substitute(ident=ident, name=name, check_terms=terms)

    if not later:
        return one("check", reals)
    first = [m for m in reals if m not in later]
    halves = one("check_first", first) + "\n" + one("check_later", [m for m in reals if m in later])
    return one("check", reals) + "\n" + halves


def _evaluation(
    scene: Scene, later: tuple[str, ...] = (), lane: bool = False, bounds: bool = True
) -> tuple[Plan, list[str], list[str], list[str]]:
    """(plan, dyad declarations, crank declarations, body) of the scene's evaluate; with
    outputs given later (:func:`later_members`), of <identifier>_evaluate_first; with
    `lane`, of one sample of its batch (see :class:`Plan`), and without `bounds`, of one
    that leaves them NaN (:func:`bare_lanes`)."""
    plan = Plan(scene, lane, bounds)
    code = _Code()
    left = later + (() if bounds else bound_members(scene))
    for write in PASSES:
        if write is _outputs:
            _outputs(plan, code, left)
        elif not (later and write is _driver_inertia):
            write(plan, code)
    dyad_decls, crank_decls = _declarations(plan)
    return plan, dyad_decls, crank_decls, drop_unused_constants(code.lines)


def inputs_read(scene: Scene) -> set[str]:
    """The members of the input block that the scene's evaluation (its kinematics
    included) reads; its tangent reads no other."""
    plan, dyad_decls, crank_decls, body = _evaluation(scene)
    text = "\n".join(dyad_decls + crank_decls + body) + _kinematics_code(plan)
    return set(re.findall(r"\bin->([A-Za-z0-9_]+)", text))


def _file_fields(plan: Plan) -> dict[str, str]:
    """The template fields both files of a scene fill alike."""
    scene = plan.scene
    return {
        "ident": scene.identifier,
        "scene_file": textsafe.c_comment(scene.path.name),
        "kinematics_include": (KINEMATICS_INCLUDE if plan.runs_kinematics else "")
        + (CYLINDER_INCLUDE if kinematics_c.cylinders(scene) else ""),
    }


def _function(ident: str, name: str, body: list[str]) -> list[str]:
    """A function of the scene on (in, out, evaluation) with this body."""
    head = f"void {ident}_{name}("
    return [
        f"{head}const {ident}_input* in, {ident}_output* out,",
        f"{' ' * len(head)}fmu_evaluation* evaluation)",
        "{",
        *body,
        "}",
    ]


def _batch_code(scene: Scene, later: tuple[str, ...]) -> str:
    """The scene's batch evaluation (emit/batch_c.py): its kinematics and its evaluation
    (with outputs ``later``, also its first half) as one sample of a loop, and
    <identifier>_lanes (and _lanes_first, and _lanes_bare: :func:`bare_lanes`) over many."""
    ident = scene.identifier
    lines = [
        "/* ---- many samples at once: the evaluation as one sample of a loop that vectorises",
        " * (src/dyad_lanes.h) ---------------------------------------------------------- */",
        "",
        *batch_c.layout_check(scene),
        "",
        kinematics_c.kinematics_lane_function(scene, Plan(scene).kinematic),
    ]
    variants = [("", (), True)] + ([("_first", later, True)] if later else [])
    variants += [("_bare", later, False)] if bare_lanes(scene) else []
    for suffix, half, bounds in variants:
        _, dyad_decls, crank_decls, body = _evaluation(scene, half, lane=True, bounds=bounds)
        lane = f"lane_evaluate{suffix}"
        angles = list(lane_angles(scene, half))
        lines += ["", *batch_c.lane_function(ident, lane, dyad_decls + crank_decls, body)]
        lines += ["", *batch_c.many_function(scene, f"lanes{suffix}", lane, angles)]
    return "\n".join(lines) + "\n"


def _functions(scene: Scene, later: tuple[str, ...], batch: bool) -> tuple[Plan, str]:
    """<identifier>_evaluate; with outputs ``later`` (:func:`later_members`), its two halves
    too, <identifier>_evaluate_first and <identifier>_evaluate_later (the same terms, so
    the same values bit for bit), for a caller that reads those only now and then; with
    `batch`, its batch evaluation (:func:`_batch_code`)."""
    plan, dyad_decls, crank_decls, body = _evaluation(scene)
    ident = scene.identifier
    lines = _function(ident, "evaluate", [*dyad_decls, *crank_decls, "    (void)in;", *body])
    if later:
        plan, dyad_decls, crank_decls, body = _evaluation(scene, later)
        first = [*dyad_decls, *crank_decls, "    (void)in;", *body]
        lines += ["", *_function(ident, "evaluate_first", first), ""]
        lines += _function(ident, "evaluate_later", _later_body(plan, later))
    text = "\n".join(lines) + "\n"
    return plan, text + ("\n" + _batch_code(scene, later) if batch else "")


def scene_c(scene: Scene, halves: bool = True) -> str:
    """<identifier>_scene.c: the computation of the scene (of its current outputs),
    <identifier>_evaluate; with ``halves``, where some of its outputs can come after the
    others (:func:`later_members`), <identifier>_evaluate_first and _later too, and where
    the scene has one, its batch evaluation (an FMU's; a bundle for a controller leaves
    them out)."""
    later = later_members(scene) if halves else ()
    batch = halves and batch_c.batch_supported(scene)
    plan, functions = _functions(scene, later, batch)
    return _template().substitute(
        _file_fields(plan),
        batch_include=batch_c.batch_include(scene) if batch else "",
        description=textsafe.c_comment(scene.description),
        inertia="on" if scene.inertia else "off",
        gravity="on" if scene.gravity else "off",
        helpers=_helpers(plan, later=later),
        functions=functions,
    )


def scene_tangent_c(scene: Scene) -> str:
    """<identifier>_scene_tangent.c: the directional derivative of the scene's
    computation, <identifier>_derivative."""
    plan, dyad_decls, crank_decls, body = _evaluation(scene)
    kinematics, derivative = tangent_c.scene_tangent(
        scene, plan.kinematic, dyad_decls + crank_decls + body, plan.runs_kinematics
    )
    reals = [o.member for o in scene.outputs if not o.integer]
    return _template(TANGENT_TEMPLATE).substitute(
        _file_fields(plan),
        helpers=_helpers(plan, tangent=True, later_code=kinematics + derivative),
        kinematics_tangent=kinematics,
        rate_check_terms=" + ".join(f"(rate->{m} - rate->{m})" for m in reals) or "0.0",
        derivative_indent=" " * len(f"void {scene.identifier}_derivative("),
        body=derivative,
    )


def scene_header(table: Table, halves: bool = True) -> str:
    """<identifier>_scene.h: the input and output blocks of the scene and its functions
    (``halves``: as :func:`scene_c`)."""
    scene = table.scene
    ident = scene.identifier
    guard = f"DYADFMU_SCENE_{ident.upper()}_H"
    # the blocks' numbers in the scalar's precision; a plant's stay double, its integrator's
    real = "double" if scene.forward() else "dyad_real"
    lines = [
        f"/* {ident}_scene.h: the scene {ident} in C: its input and output blocks, the",
        f" * function that computes it ({ident}_scene.c) and the one that also gives its",
        f" * directional derivative ({ident}_scene_tangent.c). Plain C99 on the dyadfmu core,",
        " * nothing of FMI. Generated by modelDescription/scene.py from",
        f" * {textsafe.c_comment(scene.path.name)}; do not edit. */",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        *(["#include <stddef.h>", ""] if halves and batch_c.batch_supported(scene) else []),
        '#include "dyadfmu/evaluation.h"',
        '#include "dyadfmu/vec2.h"',
        "",
        "/* Inputs and tunable parameters; an angle is kept as its unit vector. The numbers are",
        " * dyad_real (float with DYAD_REAL_FLOAT, else double)"
        + (", but for a plant's, which stay double. */" if scene.forward() else ". */"),
        f"typedef struct {ident}_input {{",
    ]
    units = {v.lives.path: v.unit for v in table.variables}
    for name, leaf in table.kind.input_members.items():
        ctype = "dyad_vec2" if leaf == "dir" else real
        lines.append(f"    {ctype} {name}; /* {units.get(name) or '-'} */")
    if not table.kind.input_members:
        lines.append(f"    {real} unused; /* the scene has no inputs */")
    lines += [f"}} {ident}_input;", "", f"typedef struct {ident}_output {{"]
    for name, leaf in table.kind.output_members.items():
        if leaf == "status":
            cannot = ", 4 cannot assemble" if scene.internal() else ""
            lines.append(f"    int {name}; /* 0 ok, 1 singular, 3 out of range{cannot} */")
        else:
            lines.append(f"    {real} {name}; /* {units.get(name) or '-'} */")
    lines += [f"}} {ident}_output;", "", *_prototypes(ident)]
    if halves and later_members(scene):
        lines += ["", *_later_prototypes(ident, later_members(scene))]
    if halves and batch_c.batch_supported(scene):
        angles = len(lane_angles(scene))
        first, bare = bool(later_members(scene)), bare_lanes(scene)
        lines += ["", *batch_c.prototypes(scene, first, bare, angles)]
    lines += ["", f"#endif /* {guard} */"]
    return "\n".join(lines) + "\n"


def _later_prototypes(ident: str, later: tuple[str, ...]) -> list[str]:
    """The two halves of <identifier>_evaluate, where some outputs can come later."""
    first, second = f"void {ident}_evaluate_first(", f"void {ident}_evaluate_later("
    return [
        f"/* {ident}_evaluate in two halves, for a caller that does not always read every",
        f" * output: {ident}_evaluate_first gives every output but {', '.join(later)},",
        " * which it leaves NaN (they need a kinematic pass of their own); after it returned",
        f" * FMU_OK, {ident}_evaluate_later, with the same `in` and `out`, gives those too.",
        f" * Together they give what {ident}_evaluate gives, bit for bit. */",
        f"{first}const {ident}_input* in, {ident}_output* out,",
        f"{' ' * len(first)}fmu_evaluation* evaluation);",
        f"{second}const {ident}_input* in, {ident}_output* out,",
        f"{' ' * len(second)}fmu_evaluation* evaluation);",
    ]


def _prototypes(ident: str) -> list[str]:
    """The header's functions, each with what it promises."""
    evaluate = f"void {ident}_evaluate("
    derivative = f"void {ident}_derivative("
    return [
        "/* The outputs at the inputs `in`, every one of `out`; `evaluation` says how it went:",
        " * status FMU_OK, or FMU_DISCARD where the scene has no answer at these inputs (every",
        " * Real output NaN, out->status saying why, evaluation->reason in one line). Nothing",
        " * allocates and nothing is kept between calls. */",
        f"{evaluate}const {ident}_input* in, {ident}_output* out,",
        f"{' ' * len(evaluate)}fmu_evaluation* evaluation);",
        "",
        f"/* {ident}_evaluate, and in `rate` the exact directional derivative of every Real",
        " * output along `seed`: the rates of the inputs (an angle's as the rate of its unit",
        " * vector; a tunable parameter's is not read). FMU_DISCARD too where the rates are not",
        f" * finite. Defined in {ident}_scene_tangent.c, which a program that only evaluates",
        " * leaves out, with the core's *_tangent.c files. */",
        f"{derivative}const {ident}_input* in, const {ident}_input* seed,",
        f"{' ' * len(derivative)}{ident}_output* out, {ident}_output* rate,",
        f"{' ' * len(derivative)}fmu_evaluation* evaluation);",
    ]

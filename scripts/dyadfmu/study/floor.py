"""The per-sample floor of a whole mechanism's job, counted: from the driver's motion
(a crank's angle, rate and acceleration, or a ram's position, rate and acceleration),
gravity and the scene's load inputs, the driving torque or force and every pair reaction.

Each mechanism's job is written once, in closed form, on :class:`Counted`, a scalar that
counts its adds, subtracts, multiplies, divides and square roots (the convention of
:mod:`.flops`: comparisons, negations, abs, min and max are free). The scene's constants
(lengths, centres of mass, masses, inertias, guide directions, fixed points) are plain
floats, folded as a C compiler folds them: an operation between two constants is free,
and so is one that a constant 0 or 1 removes (``x * 0``, ``x + 0``, ``x * 1``), since the
closed form written for that scene has no such term. Multiplying by any other constant
counts one, as in C. The crank's cosine and sine are taken as given (libm's operations
are not counted here; callgrind's count of a step has them). Gravity is an input, so each
link's weight costs its multiply.

The parts (:class:`Floor`):

* kinematics: every link's position (its direction), rate and acceleration, and those of
  the pair points the job needs, from the driver's motion;
* loads: each dyad link's resultant (its centre of mass's acceleration, the inertia force
  and weight with the active load, the inertia moment, the moment about the link's pair
  D), and the transfer of an outer dyad's reaction onto the inner link that carries it
  (``transfer``, part of ``loads``);
* reactions: each dyad's reactions from its links' resultants, eliminated in closed form
  (two projections of the inner reaction R_mn from the links' moments, the rest from the
  links' forces), sharing the kinematics' divisor (1 / cross(i_m, i_n), 1 / (i_n . i_k),
  1 / l_m);
* balance: the driver's own resultant and its balance (torque and pivot reaction, or the
  ram's force, guide normal force and moment).

Against the count stated atop ``src/dyad_<type>.c`` ("Closed forms: N flops": RRR 122,
RRT 137, RTR 134): that covers the dyad's two links' resultants (2 x 28 = 56), its
reactions (RRR 21, RRT 33, RTR 27) and the error bound's amplification (45 to 51), for
any lengths, centres and guides and with the reactions rearranged to keep their digits.
Here, with the scene's constants folded, a dyad's reactions take RRR 12, RRT 8 and RTR 8
flops (the divisor comes from the kinematics) and its two links' resultants 23 to 45
(the square of each rate shared with the kinematics); the amplification the job does not
need. ``Floor.stated_total`` counts the job with the stated closed forms (the kinematics, the dyads'
stated counts, the transfers and the balance), ``Floor.total`` the minimal evaluation
counted here; the one is the other with each dyad's own loads and reactions replaced by
its stated count. The kinematics keep every link's position, rate and acceleration (a
slider's rate too, which the reactions do not need).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from .. import paths

PARTS = ("kinematics", "loads", "reactions", "balance")


@dataclass
class Tally:
    """Operations counted, by part; ``part`` is the one now counting."""

    part: str = "kinematics"
    counts: dict[str, int] = field(default_factory=dict)

    def add(self) -> None:
        """One operation more, in the current part."""
        self.counts[self.part] = self.counts.get(self.part, 0) + 1

    @contextmanager
    def counting(self, part: str) -> Iterator[None]:
        """Counts into ``part`` inside the block."""
        before, self.part = self.part, part
        try:
            yield
        finally:
            self.part = before


def _is(x: object, k: float) -> bool:
    return isinstance(x, int | float) and x == k


class Counted:
    """A double whose arithmetic is counted in its tally; plain floats are constants."""

    __slots__ = ("tally", "value")

    def __init__(self, value: float, tally: Tally) -> None:
        self.value, self.tally = float(value), tally

    def _make(self, value: float) -> Counted:
        self.tally.add()
        return Counted(value, self.tally)

    @staticmethod
    def _of(x: object) -> float:
        return x.value if isinstance(x, Counted) else float(x)

    def __add__(self, other: object) -> Counted:
        return self if _is(other, 0) else self._make(self.value + self._of(other))

    __radd__ = __add__

    def __sub__(self, other: object) -> Counted:
        return self if _is(other, 0) else self._make(self.value - self._of(other))

    def __rsub__(self, other: object) -> Counted:
        return -self if _is(other, 0) else self._make(self._of(other) - self.value)

    def __mul__(self, other: object) -> Counted | float:
        if _is(other, 0):
            return 0.0
        if _is(other, 1) or _is(other, -1):
            return self if other == 1 else -self
        return self._make(self.value * self._of(other))

    __rmul__ = __mul__

    def __truediv__(self, other: object) -> Counted:
        return self if _is(other, 1) else self._make(self.value / self._of(other))

    def __rtruediv__(self, other: object) -> Counted:
        return self._make(self._of(other) / self.value)

    def __neg__(self) -> Counted:
        return Counted(-self.value, self.tally)

    def __float__(self) -> float:
        return self.value


Number = Counted | float
Vec = tuple[Number, Number]


def sqrt(x: Number) -> Number:
    """A counted square root."""
    return x._make(math.sqrt(x.value)) if isinstance(x, Counted) else math.sqrt(x)


def cos_sin(angle: Counted) -> tuple[Counted, Counted]:
    """The cosine and sine of an angle, not counted (libm's)."""
    return Counted(math.cos(angle.value), angle.tally), Counted(math.sin(angle.value), angle.tally)


def add(a: Vec, b: Vec) -> Vec:
    """a + b."""
    return (a[0] + b[0], a[1] + b[1])


def sub(a: Vec, b: Vec) -> Vec:
    """a - b."""
    return (a[0] - b[0], a[1] - b[1])


def scale(k: Number, v: Vec) -> Vec:
    """k v."""
    return (k * v[0], k * v[1])


def dot(a: Vec, b: Vec) -> Number:
    """a . b."""
    return a[0] * b[0] + a[1] * b[1]


def cross(a: Vec, b: Vec) -> Number:
    """a x b (its z component)."""
    return a[0] * b[1] - a[1] * b[0]


def perp(v: Vec) -> Vec:
    """v turned by +90 deg."""
    return (-v[1], v[0])


ZERO: Vec = (0.0, 0.0)


@dataclass(frozen=True)
class Point:
    """A point's position, velocity and acceleration (constants where it is fixed)."""

    pos: Vec
    vel: Vec = ZERO
    acc: Vec = ZERO


@dataclass(frozen=True)
class Frame:
    """A link's motion: its pair point D, its direction i, rate w, its square w2 and
    acceleration e."""

    d: Point
    i: Vec
    w: Number = 0.0
    w2: Number = 0.0
    e: Number = 0.0

    def offset(self, local: tuple[float, float]) -> Vec:
        """S - D of the point at ``local`` in the link's frame {D; i, j}."""
        return add(scale(local[0], self.i), scale(local[1], perp(self.i)))

    def acceleration(self, r: Vec) -> Vec:
        """The acceleration of the point D + r."""
        return sub(add(self.d.acc, scale(self.e, perp(r))), scale(self.w2, r))

    def at(self, r: Vec) -> Point:
        """The position, velocity and acceleration of the point D + r."""
        return Point(
            add(self.d.pos, r), add(self.d.vel, scale(self.w, perp(r))), self.acceleration(r)
        )

    def point(self, local: tuple[float, float]) -> Point:
        """The position, velocity and acceleration of the point at ``local``."""
        return self.at(self.offset(local))


@dataclass(frozen=True)
class Load:
    """A link's load resultant: force F and its moment about the link's pair D."""

    f: Vec
    m_d: Number


def resultant(
    frame: Frame, link: Mapping, gravity: Vec, force: Vec = ZERO, moment: Number = 0.0
) -> Load:
    """Inertia force and weight at the centre of mass with the active load, the inertia
    moment, and their moment about D."""
    r = frame.offset(tuple(link.get("com", (0.0, 0.0))))
    f = add(force, scale(float(link["mass"]), sub(gravity, frame.acceleration(r))))
    m = moment - float(link["inertia"]) * frame.e
    return Load(f, m + cross(r, f))


def carried(load: Load, r: Vec, force: Vec) -> Load:
    """The load with a force at D + r added (an outer dyad's reaction on this link)."""
    return Load(add(load.f, force), load.m_d + cross(r, force))


# --- the dyads' kinematics -------------------------------------------------------------


@dataclass(frozen=True)
class DyadMotion:
    """Both links' motion and the divisor the reactions share with the kinematics."""

    m: Frame
    n: Frame
    inverse: Number
    #: inverse / l_m and inverse / l_n, where the kinematics formed them
    inverse_m: Number = 1.0
    inverse_n: Number = 1.0


def rrr_motion(dm: Point, dn: Point, lm: float, ln: float, branch: float) -> DyadMotion:
    """RRR: E from the two circles about D_m and D_n; the rates and accelerations from
    v_E (a_E) written along both links, projected on i_n and i_m."""
    d = sub(dn.pos, dm.pos)
    inv = 1.0 / dot(d, d)
    a = 0.5 + 0.5 * (lm * lm - ln * ln) * inv
    h = branch * sqrt(lm * lm * inv - a * a)
    em = add(scale(a, d), scale(h, perp(d)))
    i_m, i_n = scale(1.0 / lm, em), scale(1.0 / ln, sub(em, d))
    inverse = 1.0 / cross(i_m, i_n)
    inv_m, inv_n = inverse * (1.0 / lm), inverse * (1.0 / ln)
    dv = sub(dn.vel, dm.vel)
    w_m, w_n = dot(dv, i_n) * inv_m, dot(dv, i_m) * inv_n
    w2_m, w2_n = w_m * w_m, w_n * w_n
    b = sub(sub(dn.acc, scale(w2_n * ln, i_n)), sub(dm.acc, scale(w2_m * lm, i_m)))
    e_m, e_n = dot(b, i_n) * inv_m, dot(b, i_m) * inv_n
    m, n = Frame(dm, i_m, w_m, w2_m, e_m), Frame(dn, i_n, w_n, w2_n, e_n)
    return DyadMotion(m, n, inverse, inv_m, inv_n)


def rrt_motion(dn: Point, at: Vec, g: Vec, ln: float, branch: float) -> DyadMotion:
    """RRT on a frame guide through ``at`` along ``g``: E = at + s g at the distance l_n
    from D_n; s' and w_n from v_E = s' g = v_Dn + w_n l_n j_n dotted with i_n and crossed
    with g, s'' and e_n likewise. Link m keeps the guide's direction."""
    w = sub(dn.pos, at)
    c = cross(g, w)
    s = dot(w, g) + branch * sqrt(ln * ln - c * c)
    i_n = scale(1.0 / ln, sub(scale(s, g), w))
    inverse = 1.0 / dot(g, i_n)
    inv_n = inverse * (1.0 / ln)
    s_rate, w_n = dot(dn.vel, i_n) * inverse, -cross(g, dn.vel) * inv_n
    w2_n = w_n * w_n
    b = sub(dn.acc, scale(w2_n * ln, i_n))
    s_acc, e_n = dot(b, i_n) * inverse, -cross(g, b) * inv_n
    e = Point(add(at, scale(s, g)), scale(s_rate, g), scale(s_acc, g))
    return DyadMotion(Frame(e, g), Frame(dn, i_n, w_n, w2_n, e_n), inverse, 1.0, inv_n)


def rtr_motion(dm: Point, dn: Point) -> tuple[DyadMotion, Number]:
    """RTR with D_m on the frame and l_n = 0 (E = D_n, link n keeps link m's direction):
    i_m along D_n - D_m; w_m and e_m from v_Dn and a_Dn crossed with i_m. Also 1 / l_m."""
    d = sub(dn.pos, dm.pos)
    inv = 1.0 / sqrt(dot(d, d))
    i = scale(inv, d)
    w = cross(i, dn.vel) * inv
    length_rate = dot(dn.vel, i)
    e = (cross(i, dn.acc) - 2.0 * w * length_rate) * inv
    w2 = w * w
    return DyadMotion(Frame(dm, i, w, w2, e), Frame(dn, i, w, w2, e), inv), inv


# --- the dyads' reactions --------------------------------------------------------------

Reactions = dict[str, Number]


def _named(r_mk: Vec, r_np: Vec, r_mn: Vec) -> Reactions:
    return {
        "R_mk.x": r_mk[0],
        "R_mk.y": r_mk[1],
        "R_np.x": r_np[0],
        "R_np.y": r_np[1],
        "R_mn.x": r_mn[0],
        "R_mn.y": r_mn[1],
    }


def rrr_reactions(dyad: DyadMotion, m: Load, n: Load) -> Reactions:
    """cross(i_m, R_mn) = -M_Dm / l_m, cross(i_n, R_mn) = M_Dn / l_n (the links' moments
    about D_m and D_n), solved by Cramer's rule; R_mk and R_np from the links' forces."""
    i_m, i_n = dyad.m.i, dyad.n.i
    b_m, b_n = -m.m_d * dyad.inverse_m, n.m_d * dyad.inverse_n
    r_mn = (b_m * i_n[0] - i_m[0] * b_n, i_n[1] * b_m - i_m[1] * b_n)
    return _named(scale(-1.0, add(r_mn, m.f)), sub(r_mn, n.f), r_mn)


def rrt_reactions(dyad: DyadMotion, m: Load, n: Load) -> Reactions:
    """R_mn . i_k = -F_m . i_k (the slider's forces along the guide) and cross(i_n, R_mn) =
    M_Dn / l_n (the rod's moment about D_n); N_mk across the guide, M_mk = -M_Dm."""
    g, i_n = dyad.m.i, dyad.n.i
    b_g, b_n = -dot(m.f, g) * dyad.inverse, n.m_d * dyad.inverse_n
    r_mn = (b_g * i_n[0] - g[1] * b_n, g[0] * b_n + i_n[1] * b_g)
    j = perp(g)  # along an axis, each force's component across it costs nothing
    normal = -dot(add(m.f, r_mn), j) if all(j) else -(dot(m.f, j) + dot(r_mn, j))
    out = _named(scale(normal, j), sub(r_mn, n.f), r_mn)
    return out | {"N_mk": normal, "M_mk": -m.m_d}


def rtr_reactions(dyad: DyadMotion, inv_length: Number, m: Load, n: Load) -> Reactions:
    """l_n = 0: the block's moment about E = D_n gives M_mn = M_Dn, the lever's about D_m
    N_mn = -(M_Dm + M_mn) / l_m; R_mn = N_mn j_m, the rest from the links' forces."""
    normal = -(m.m_d + n.m_d) * inv_length
    r_mn = scale(normal, perp(dyad.m.i))
    out = _named(scale(-1.0, add(r_mn, m.f)), sub(r_mn, n.f), r_mn)
    return out | {"N_mn": normal, "M_mn": n.m_d}


# --- the drivers ------------------------------------------------------------------------


def crank_frame(crank: Mapping, angle: Counted, omega: Counted, epsilon: Counted) -> Frame:
    """The crank turning about its pivot 'at'."""
    return Frame(Point(tuple(crank.get("at", ZERO))), cos_sin(angle), omega, omega * omega, epsilon)


def crank_balance(crank: Frame, link: Mapping, gravity: Vec, pin: Vec, r_np: Vec) -> Reactions:
    """The crank's own resultant, its pivot reaction R_O and driving torque, with -R_np at
    its pin D + ``pin``."""
    own = resultant(crank, link, gravity)
    r_o = sub(r_np, own.f)
    return {"torque": cross(pin, r_np) - own.m_d, "R_O.x": r_o[0], "R_O.y": r_o[1]}


# --- the mechanisms ---------------------------------------------------------------------


def _gravity(scene: Mapping, values: Mapping[str, Counted]) -> Vec:
    return (values["gravity.x"], values["gravity.y"])


def _links(scene: Mapping) -> dict[str, Mapping]:
    return {link["name"]: link for link in scene["link"]}


def _dyad(scene: Mapping, name: str) -> Mapping:
    return next(d for d in scene["dyad"] if d["name"] == name)


def _prefixed(name: str, reactions: Reactions) -> Reactions:
    return {f"{name}.{k}": v for k, v in reactions.items()}


def _crank_inputs(scene: Mapping, v: Mapping[str, Counted]) -> Frame:
    name = scene["crank"].get("name", "crank")
    return crank_frame(scene["crank"], v[f"{name}.angle"], v[f"{name}.omega"], v[f"{name}.epsilon"])


def _guide(spec: Mapping) -> tuple[Vec, Vec]:
    """A frame guide's point and direction."""
    angle = float(spec["guide"])  # a right angle's cosine 6e-17 is the scene's 0
    return tuple(spec["at"]), (round(math.cos(angle), 15), round(math.sin(angle), 15))


def _force(v: Mapping[str, Counted], link: str) -> Vec:
    return (v[f"{link}.force.x"], v[f"{link}.force.y"])


def _crank_pin(scene: Mapping, v: Mapping[str, Counted]) -> tuple[Frame, Point]:
    """The crank's frame and the motion of its pin, where the first dyad rides."""
    crank = _crank_inputs(scene, v)
    return crank, crank.point((float(scene["crank"]["length"]), 0.0))


def _with_balance(
    scene: Mapping, crank: Frame, pin: Point, g: Vec, named: Reactions, r_np: Vec, tally: Tally
) -> Reactions:
    """The dyads' reactions `named` and the crank's balance against R_np at its pin."""
    with tally.counting("balance"):
        balance = crank_balance(crank, scene["crank"], g, sub(pin.pos, crank.d.pos), r_np)
    return named | _prefixed(scene["crank"]["name"], balance)


def slider_crank(scene: Mapping, v: Mapping[str, Counted], tally: Tally) -> Reactions:
    """Crank and RRT (piston m on the frame guide, rod n from the crank pin)."""
    dyad, links, g = scene["dyad"][0], _links(scene), _gravity(scene, v)
    rod = links[dyad["n"]]
    crank, pin = _crank_pin(scene, v)
    at, direction = _guide(dyad["k"])
    motion = rrt_motion(pin, at, direction, float(rod["length"]), float(dyad.get("branch", 1)))
    with tally.counting("loads"):
        m = resultant(motion.m, links[dyad["m"]], g, _force(v, dyad["m"]))
        n = resultant(motion.n, rod, g)
    with tally.counting("reactions"):
        out = rrt_reactions(motion, m, n)
    r_np = (out["R_np.x"], out["R_np.y"])
    return _with_balance(scene, crank, pin, g, _prefixed(dyad["name"], out), r_np, tally)


def four_bar(scene: Mapping, v: Mapping[str, Counted], tally: Tally) -> Reactions:
    """Crank and RRR (rocker m from a frame pivot, coupler n from the crank pin); the
    scene's moment on the rocker."""
    dyad, links, g = scene["dyad"][0], _links(scene), _gravity(scene, v)
    rocker, coupler = links[dyad["m"]], links[dyad["n"]]
    lm, ln = float(rocker["length"]), float(coupler["length"])
    crank, pin = _crank_pin(scene, v)
    motion = rrr_motion(Point(tuple(dyad["k"]["at"])), pin, lm, ln, float(dyad["branch"]))
    with tally.counting("loads"):
        m = resultant(motion.m, rocker, g, moment=v[f"{dyad['m']}.moment"])
        n = resultant(motion.n, coupler, g)
    with tally.counting("reactions"):
        out = rrr_reactions(motion, m, n)
    r_np = (out["R_np.x"], out["R_np.y"])
    return _with_balance(scene, crank, pin, g, _prefixed(dyad["name"], out), r_np, tally)


def shaper(scene: Mapping, v: Mapping[str, Counted], tally: Tally) -> Reactions:
    """Crank, RTR "slot" (lever m on a frame pivot, block n on the crank pin) and RRT
    "ram" (slider m on the frame guide, rod n from the lever's tip); the cutting force on
    the slider. The ram's reaction R_np rides on the lever at its tip."""
    slot, ram, links, g = (
        _dyad(scene, "slot"),
        _dyad(scene, "ram"),
        _links(scene),
        _gravity(scene, v),
    )
    rod = links[ram["n"]]
    crank, pin = _crank_pin(scene, v)
    slot_motion, inv_length = rtr_motion(Point(tuple(slot["k"]["at"])), pin)
    r_tip = slot_motion.m.offset(tuple(ram["p"]["at"]))
    tip = slot_motion.m.at(r_tip)
    at, direction = _guide(ram["k"])
    ram_motion = rrt_motion(tip, at, direction, float(rod["length"]), float(ram.get("branch", 1)))
    with tally.counting("loads"):
        slider = resultant(ram_motion.m, links[ram["m"]], g, _force(v, ram["m"]))
        rod_load = resultant(ram_motion.n, rod, g)
    with tally.counting("reactions"):
        outer = rrt_reactions(ram_motion, slider, rod_load)
    with tally.counting("loads"):
        lever = resultant(slot_motion.m, links[slot["m"]], g)
        block = resultant(slot_motion.n, links[slot["n"]], g)
    with tally.counting("transfer"):
        lever = carried(lever, r_tip, (-outer["R_np.x"], -outer["R_np.y"]))
    with tally.counting("reactions"):
        inner = rtr_reactions(slot_motion, inv_length, lever, block)
    named = _prefixed("slot", inner) | _prefixed("ram", outer)
    return _with_balance(scene, crank, pin, g, named, (inner["R_np.x"], inner["R_np.y"]), tally)


def ram_balance(scene: Mapping, ram: Frame, gravity: Vec, r_np: Vec) -> Reactions:
    """The ram's own resultant and its balance with -R_np at its pin R: the force along
    the guide, the guide's normal force and its moment about R."""
    own = resultant(ram, {"inertia": 0.0, **scene["ram"]}, gravity)
    rest = sub(r_np, own.f)
    return {"force": dot(rest, ram.i), "N": dot(rest, perp(ram.i)), "M": -own.m_d}


def lift(scene: Mapping, v: Mapping[str, Counted], tally: Tally) -> Reactions:
    """Ram on a frame guide, RRR "lever" (arm m on a frame pivot, strut n from the ram's
    pin) and RRT "hoist" (platform m on a frame guide, rod n from the arm's tip); the
    payload on the platform. The hoist's reaction R_np rides on the arm at its tip."""
    lever, hoist, links, g = (
        _dyad(scene, "lever"),
        _dyad(scene, "hoist"),
        _links(scene),
        _gravity(scene, v),
    )
    arm, strut, rod = links[lever["m"]], links[lever["n"]], links[hoist["n"]]
    at, direction = _guide(scene["ram"])
    x, rate, acc = (v[f"ram.{k}"] for k in ("position", "velocity", "acceleration"))
    pin = Point(add(at, scale(x, direction)), scale(rate, direction), scale(acc, direction))
    ram = Frame(pin, direction)
    arm_l, strut_l, rod_l = (float(k["length"]) for k in (arm, strut, rod))
    motion = rrr_motion(Point(tuple(lever["k"]["at"])), pin, arm_l, strut_l, float(lever["branch"]))
    r_tip = motion.m.offset(tuple(hoist["p"]["at"]))
    tip = motion.m.at(r_tip)
    h_at, h_dir = _guide(hoist["k"])
    outer_motion = rrt_motion(tip, h_at, h_dir, rod_l, float(hoist.get("branch", 1)))
    with tally.counting("loads"):
        platform = resultant(outer_motion.m, links[hoist["m"]], g, _force(v, hoist["m"]))
        rod_load = resultant(outer_motion.n, rod, g)
    with tally.counting("reactions"):
        outer = rrt_reactions(outer_motion, platform, rod_load)
    with tally.counting("loads"):
        arm_load, strut_load = resultant(motion.m, arm, g), resultant(motion.n, strut, g)
    with tally.counting("transfer"):
        arm_load = carried(arm_load, r_tip, (-outer["R_np.x"], -outer["R_np.y"]))
    with tally.counting("reactions"):
        inner = rrr_reactions(motion, arm_load, strut_load)
    with tally.counting("balance"):
        balance = ram_balance(scene, ram, g, (inner["R_np.x"], inner["R_np.y"]))
    return _prefixed("lever", inner) | _prefixed("hoist", outer) | _prefixed("ram", balance)


Evaluation = Callable[[Mapping, Mapping[str, Counted], Tally], Reactions]

#: Each mechanism's evaluation of the job.
MECHANISMS: dict[str, Evaluation] = {
    "slider_crank": slider_crank,
    "four_bar": four_bar,
    "shaper": shaper,
    "lift": lift,
}


@dataclass(frozen=True)
class Floor:
    """One mechanism's floor per sample: the flops of each part of the minimal closed-form
    evaluation (``transfer``: of ``loads``, the outer dyads' reactions moved onto the
    links that carry them) and the dyads' closed-form counts stated atop src/."""

    mechanism: str
    kinematics: int
    loads: int
    reactions: int
    balance: int
    transfer: int
    stated: int

    @property
    def total(self) -> int:
        """The minimal evaluation's flops."""
        return self.kinematics + self.loads + self.reactions + self.balance

    @property
    def stated_total(self) -> int:
        """The stated count: the kinematics, the dyads' stated closed forms (their links'
        resultants, reactions and amplification), the transfers and the balance."""
        return self.kinematics + self.stated + self.transfer + self.balance


def scene(name: str, root: Path | None = None) -> dict:
    """The scene file modelDescription/scenes/<name>.toml, parsed."""
    folder = (root or paths.ROOT) / "modelDescription" / "scenes"
    return tomllib.loads((folder / f"{name}.toml").read_text(encoding="utf-8"))


def evaluate(
    name: str, values: Mapping[str, float], table: Mapping | None = None
) -> tuple[Reactions, Tally]:
    """The job of mechanism ``name`` at one sample: ``values`` holds the driver's motion
    and the load inputs by FMU name, and ``gravity.x``, ``gravity.y`` (default the
    scene's). Returns the efforts and reactions by FMU name (Counted) and the tally."""
    table = table if table is not None else scene(name)
    tally = Tally()
    given = {"gravity.x": table["gravity"]["x"], "gravity.y": table["gravity"]["y"], **values}
    counted = {k: Counted(x, tally) for k, x in given.items()}
    return MECHANISMS[name](table, counted, tally), tally


def floor(name: str, values: Mapping[str, float] | None = None, root: Path | None = None) -> Floor:
    """The floor of mechanism ``name`` (its scene's start values where ``values`` is
    None: the count is the same at every sample)."""
    from .speed import closed_form_flops

    table = scene(name, root)
    values = values if values is not None else sample_values(name, table)
    _, tally = evaluate(name, values, table)
    stated = sum(closed_form_flops(d["type"], root) for d in table["dyad"])
    counts = {part: tally.counts.get(part, 0) for part in PARTS}
    transfer = tally.counts.get("transfer", 0)
    counts["loads"] += transfer
    return Floor(name, **counts, transfer=transfer, stated=stated)


def sample_values(name: str, table: Mapping) -> dict[str, float]:
    """A sample of the driver's motion and loads where no term vanishes by accident."""
    if "ram" in table:
        values = {"ram.position": 0.2, "ram.velocity": 0.1, "ram.acceleration": 0.3}
    else:
        crank = table["crank"].get("name", "crank")
        values = {f"{crank}.angle": 0.7, f"{crank}.omega": 10.0, f"{crank}.epsilon": 3.0}
    for link in table.get("loads", {}).get("force", []):
        values |= {f"{link}.force.x": 100.0, f"{link}.force.y": 50.0}
    for link in table.get("loads", {}).get("moment", []):
        values[f"{link}.moment"] = 2.0
    return values


def floors(
    names: tuple[str, ...] = tuple(MECHANISMS), root: Path | None = None
) -> dict[str, Floor]:
    """Each mechanism's floor."""
    return {name: floor(name, root=root) for name in names}

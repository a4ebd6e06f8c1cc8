"""The model of a scene: an optional crank and a chain of Assur dyads, each dyad's links
m and n and how its outer pairs meet their external links k and p (the frame, the
crank, a link of an earlier dyad, or an external link whose motion is an input), the
scene's numbers (baked into the code, or tunable parameters), and its derived inputs
and outputs (needs.py fills them in)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from dyadgen.dyadtypes import PAIR_NAMES, PAIRS


def c_num(x: float) -> str:
    """A double as a C constant that reads back to the same double."""
    text = repr(float(x))
    return text if ("." in text or "e" in text or "inf" in text or "nan" in text) else text + ".0"


def c_real(x: float) -> str:
    """A number of the scene's arithmetic in C: in the scalar's precision (DYAD_R,
    dyadfmu/types.h), so that a float build computes in float; exact in double."""
    return f"DYAD_R({c_num(x)})"


def unit_vector_c(angle: Param) -> str:
    """The unit vector at an angle (rad) in C: a constant, or computed where it is tunable."""
    if angle.tunable:
        return f"dyad_dir_from_angle({angle.c()})"
    return f"dyad_vec2_make({c_real(math.cos(angle.value))}, {c_real(math.sin(angle.value))})"


def member(name: str) -> str:
    """The C member of a structured name: dots as underscores."""
    return name.replace(".", "_")


@dataclass
class Param:
    """A number of the scene: baked into the code, or an FMU parameter."""

    name: str  # FMU name, e.g. "lever.mass"
    value: float
    unit: str | None
    description: str
    domain: dict = field(default_factory=dict)
    tunable: bool = False
    member: str = ""  # C member of the input block when tunable
    #: a macro of the core that stands for the value in C: the scalar's own default,
    #: which differs between the double and the float build
    macro: str = ""

    def c(self) -> str:
        """The value in C: the input block's member, the macro, or the constant."""
        if self.tunable:
            return f"in->{self.member}"
        return self.macro or c_real(self.value)

    def is_zero(self) -> bool:
        """Baked at 0: a term it multiplies is not written."""
        return not self.tunable and self.value == 0.0


@dataclass
class Attachment:
    """Where a dyad's outer pair meets its external link."""

    kind: str  # "frame", "external", "crank", "link"
    link: str | None = None  # the moving link (crank or dyad link) it is on
    #: the point in that link's frame; on the frame (internal kinematics) the fixed pivot
    #: or a point of the guide's line, global
    at: tuple[Param, Param] | None = None
    guide: Param | None = None  # guide angle on the frame, for a translational pair


@dataclass(eq=False)
class Link:
    """A link of a dyad (m or n), its numbers and its active loads."""

    name: str
    dyad: Dyad
    side: str  # "m" or "n"
    line: int | None
    sliding: bool  # its length varies (link m of RTR, RTT)
    translating: bool  # it cannot turn: its outer pair slides on the frame
    params: dict = field(default_factory=dict)  # key -> Param (length, angle, com.x, ...)
    force: bool = False
    moment: bool = False

    def attachment(self) -> Attachment:
        """The attachment of its outer pair D: k for link m, p for link n."""
        return self.dyad.k if self.side == "m" else self.dyad.p


@dataclass(eq=False)
class PointLoad:
    """A load where it acts ([[load]]): a force at a point of a link, its components
    global or the link's own (a follower force), and/or a pure moment."""

    name: str  # the prefix of its inputs and parameters
    link: str  # the loaded link: a dyad's link or the driver
    at: tuple  # (Param, Param): the point in the link's frame (m)
    components: str  # "global" or "link"
    force: bool
    moment: bool
    line: int | None = None


@dataclass(eq=False)
class Dyad:
    """A dyad of the chain: its type, links and outer attachments."""

    name: str
    type: str
    index: int
    line: int | None
    m: str = ""
    n: str = ""
    k: Attachment | None = None
    p: Attachment | None = None
    branch: Param | None = None  # the assembly branch (+1 or -1), internal kinematics
    internal: bool = False  # its kinematics are solved in the generated code

    def prefix(self) -> str:
        """The prefix of its variables' names: 'name.', or none for an unnamed dyad."""
        return f"{self.name}." if self.name else ""

    def pair_kind(self, pair: str) -> str:
        """R or T of the pair a reaction suffix (mk, np, mn) names."""
        return PAIRS[self.type][dict(PAIR_NAMES)[pair]]


@dataclass
class Crank:
    """The driver: a crank turning about the frame pivot O, a ram (a linear actuator)
    sliding on a frame guide (kind "ram"), or a hydraulic cylinder between a frame pin A
    and a pin B of a link it turns about the frame pivot O (kind "cylinder": `name` is
    the driven link, which dyads and loads name as they name a crank, and `actuator`
    the cylinder, which names the driver's inputs and its balance)."""

    name: str
    line: int | None
    params: dict = field(default_factory=dict)
    kind: str = "crank"
    actuator: str = ""
    index: int = 0  # of its table among the scene's tables of its kind
    #: a cylinder's carriers: the driver link its pivot O (its pin A) is a point of, in
    #: that link's frame; None for the frame (a global point)
    pivot_on: str | None = None
    base_on: str | None = None

    def carriers(self) -> list[str]:
        """The moving links a cylinder's pins O and A sit on (none for the frame)."""
        return [c for c in (self.pivot_on, self.base_on) if c is not None]

    def is_ram(self) -> bool:
        """Whether the driver is a ram: it translates, and balances with a force."""
        return self.kind == "ram"

    def is_cylinder(self) -> bool:
        """Whether the driver is a cylinder between two pins: its length is the driver's
        coordinate, and it balances with its axial force."""
        return self.kind == "cylinder"

    def balances_with_force(self) -> bool:
        """Whether the driver's effort is a force (N), not a torque."""
        return self.kind in ("ram", "cylinder")

    def driver_name(self) -> str:
        """The name of the driver's inputs and effort: the cylinder's for a cylinder."""
        return self.actuator or self.name


@dataclass
class Motor:
    """A DC motor geared to a crank of a forward scene ([[motor]]): with the rotor at
    ratio q' and the armature current i, inductance i' = V - resistance i -
    torque_constant ratio q', and the crank's torque ratio (torque_constant i - friction
    ratio q') - ratio^2 rotor_inertia q''. Its numbers are the FMU's parameters (but a
    zero inductance, and then the start current: see :attr:`circuit`)."""

    driver: str  # the crank's name
    line: int | None
    numbers: dict  # key -> value, every key of MOTOR_NUMBERS

    @property
    def circuit(self) -> bool:
        """Whether its armature current is a state (inductance > 0); with none, the current
        is (V - torque_constant ratio q') / resistance at every instant: the drive FMU's
        linear torque-speed characteristic."""
        return self.numbers["inductance"] > 0


#: A motor's numbers: key -> (unit, what, default or None where required, least, strict)
MOTOR_NUMBERS = {
    "resistance": ("Ohm", "Armature resistance", None, 0.0, True),
    "inductance": ("H", "Armature inductance (0: no current state)", None, 0.0, False),
    "torque_constant": (
        "N.m/A",
        "Torque constant, in SI also the back-EMF constant (V.s/rad)",
        None,
        0.0,
        True,
    ),
    "rotor_inertia": ("kg.m2", "Rotor inertia about its axis", 0.0, 0.0, False),
    "friction": ("N.m.s/rad", "Viscous friction at the rotor", 0.0, 0.0, False),
    "ratio": ("", "Gear ratio: rotor turns per crank turn", 1.0, 0.0, True),
    "current": ("A", "Armature current at the start", 0.0, None, False),
}


@dataclass(eq=False)
class Output:
    """An output the scene offers: its name, C member and dependencies."""

    name: str
    unit: str | None
    description: str
    member: str
    integer: bool = False
    depends: list = field(default_factory=list)
    source: str = ""  # the dyad (by index, as text) or "crank" it comes from


@dataclass
class Input:
    """An input of the scene: a link's motion or active load, or a guide's direction."""

    name: str
    unit: str | None
    description: str
    member: str
    angle: bool = False
    start: float = 0.0
    domain: dict = field(default_factory=dict)
    owner: str = ""  # link the input belongs to ("" for a dyad's guide)


@dataclass(frozen=True)
class Experiment:
    """A model description's DefaultExperiment: from 0 to stop (s), a row every step (s)."""

    stop: float
    step: float


#: The run of a model that states none (the hand-written tables').
DEFAULT_EXPERIMENT = Experiment(1.0, 1.0e-3)


@dataclass
class Scene:
    """A checked scene: the mechanism, its effects and numbers, and (once derived) its
    inputs and outputs."""

    path: Path
    identifier: str
    description: str
    inertia: bool
    gravity: bool
    #: the driver where the scene has exactly one (else None: see drivers)
    crank: Crank | None
    dyads: list
    links: dict  # name -> Link
    gravity_params: tuple | None  # (Param, Param)
    threshold: Param
    #: "internal": the kinematics are solved in the generated code from the driver's
    #: motion; "external": every link's motion is an input
    kinematics: str = "external"
    #: "inverse": the drivers' motion in, their efforts out; "forward": the efforts in,
    #: the motion integrated inside (dyadgen/forward.py)
    dynamics: str = "inverse"
    #: internal kinematics: the name of a link's motion (as an input would be named,
    #: "rod.angle") -> the C expression that computes it
    computed: dict = field(default_factory=dict)
    outputs: list = field(default_factory=list)  # Output
    inputs: list = field(default_factory=list)  # Input, in table order
    #: dyad index -> the dyads that load it (see loaders), computed once
    loaders: dict = field(default_factory=dict, repr=False)
    point_loads: list = field(default_factory=list)  # PointLoad, in file order
    #: every driver: cranks, rams, cylinders, each kind in file order
    drivers: list = field(default_factory=list)
    #: a forward scene's DC motors, one per crank at most, in file order
    motors: list = field(default_factory=list)
    #: the DefaultExperiment ([experiment], or derived: scenefile/experiment.py)
    experiment: Experiment = DEFAULT_EXPERIMENT

    def driver_of(self, name: str) -> Crank | None:
        """The driver whose moving link is `name` (a crank, a ram, a cylinder's link)."""
        return next((d for d in self.drivers if d.name == name), None)

    def parameters(self) -> list:
        """Every Param of the scene in table order."""
        out = []
        for driver in self.drivers:
            out += driver.params.values()
        for d in self.dyads:
            for g in (d.m, d.n):
                out += self.links[g].params.values()
            for a in (d.k, d.p):
                if a.at:
                    out += a.at
                if a.guide:
                    out.append(a.guide)
            if d.branch:
                out.append(d.branch)
        for load in self.point_loads:
            out += load.at
        if self.gravity_params:
            out += self.gravity_params
        out.append(self.threshold)
        return out

    def internal(self) -> bool:
        """Whether the generated code solves the kinematics from the driver's motion."""
        return self.kinematics == "internal"

    def forward(self) -> bool:
        """Whether the scene is a plant: its drivers' efforts in, its motion integrated."""
        return self.dynamics == "forward"

    def params_of(self, g: str) -> dict:
        """The numbers of a moving link: a driver's or a dyad link's."""
        driver = self.driver_of(g)
        return driver.params if driver else self.links[g].params


def carriers(scene: Scene) -> dict:
    """Link name -> the moving link (crank or dyad link) its pair D sits on, or None."""
    out = {}
    for name, link in scene.links.items():
        att = link.attachment()
        out[name] = att.link if att.kind in ("crank", "link") else None
    for driver in scene.drivers:
        out[driver.name] = None
    return out


def ancestors(carrier_of: dict, names: set) -> set:
    """The moving links whose motion the accelerations of the links `names`' pairs D
    derive from: their carriers, the carriers' carriers, and so on (`carrier_of` from
    carriers). Each link is visited once."""
    found: set = set()
    for name in names:
        carrier = carrier_of[name]
        while carrier is not None and carrier not in found:
            found.add(carrier)
            carrier = carrier_of[carrier]
    return found


def loaders(scene: Scene, dyad: Dyad) -> list:
    """Dyads whose reactions load this dyad's links, directly or through others."""
    if not scene.loaders:
        # a dyad hangs only on links of earlier dyads: from the last dyad back, each one's
        # loaders are the dyads on its links and their loaders
        on_link: dict[str, list] = {}
        for d in scene.dyads:
            for a in (d.k, d.p):
                if a.kind == "link":
                    on_link.setdefault(a.link, []).append(d)
        for d in reversed(scene.dyads):
            found: dict[int, Dyad] = {}
            for g in (d.m, d.n):
                for child in on_link.get(g, []):
                    found[child.index] = child
                    found.update((o.index, o) for o in scene.loaders[child.index])
            found.pop(d.index, None)
            scene.loaders[d.index] = list(found.values())
    return scene.loaders[dyad.index]


def own_accel(link: Link) -> bool:
    """Whether the acceleration of D_g is an input: where D_g slides on a guide (of the frame
    or of a moving link) or sits on an external link. On a fixed pivot it is 0; on a point
    of the crank or of an earlier link the generated code derives it from that link's
    motion."""
    att = link.attachment()
    return att.kind == "external" or att.guide is not None

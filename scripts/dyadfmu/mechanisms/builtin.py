"""Five class II planar mechanisms, each a crank plus one Assur dyad, with closed-form
kinematics and active loads, ready for the dyad FMUs and for :mod:`dyadfmu.reference.newton_euler`.

============  =====  ========================================================
name          dyad   mechanism
============  =====  ========================================================
slider-crank  RRT    offset slider-crank, gas force on the piston
four-bar      RRR    Grashof crank-rocker, resisting torque on the rocker
quick-return  RTR    crank and slotted lever, resisting moment on the working stroke
scotch-yoke   RTT    Scotch yoke, pump resistance on the yoke
trt-slot      TRT    oscillating slotted crank driving a slider
============  =====  ========================================================

In every mechanism the crank is the external link p (it carries pair D_n) and the
frame is the external link k (it carries pair D_m). The crank turns about O = (0, 0);
its angle phi is measured from +x, counter-clockwise, and its pin is
A = O + r (cos phi, sin phi).

Dyad conventions (those of the FMUs, see the README): ``i_g`` is the unit vector of
link g from D_g towards E (``<g>.angle`` is its angle), E = D_m + l_m i_m = D_n + l_n i_n,
``<g>.omega`` and ``<g>.epsilon`` are absolute, ``<g>.accel_d`` is the acceleration of
the material point of link g at D_g, the centre of mass is S_g = D_g + x_S i_g + y_S j_g
and the active load (``<g>.force`` at S_g, ``<g>.moment``) excludes the weight, which
the solvers add from ``gravity``. In all five mechanisms the link frame {D_g; i_g, j_g}
is fixed in its link, so ``accel_d`` is the second time derivative of D_g.

Every position, velocity and acceleration is in closed form; nothing is
differentiated numerically here. Default data (dimensions, masses, loads, speeds) are
in ``mechanisms.toml`` next to this module.

Active loads (on link m; link n is unloaded apart from its weight):

* slider-crank: gas force on the piston along -x, once per revolution,
  F = area (p_base + (p_peak - p_base) exp(kappa (cos(phi - phi_TDC - psi_peak) - 1))),
  phi_TDC = asin(e / (l + r)) the crank angle of top dead centre;
* four-bar: torque on the rocker M = -T0 tanh(omega_m / w_ref) - c omega_m;
* quick-return: moment on the lever M = -M0 tanh(u) (1 + tanh(u)) / 2, u = omega_m / w_ref:
  about -M0 on the slow working stroke (omega_m > 0 for a counter-clockwise crank), about
  0 on the quick return, always opposing the lever's motion;
* scotch-yoke, trt-slot: force along the guide F_x = -F0 tanh(v / v_ref) - c v, v the
  velocity of link m.

The trt-slot crank oscillates (phi = pi/2 + 0.9 sin(omega t)) instead of turning round:
at phi = 0 and pi its slot is parallel to the guide (E at infinity, conditioning
sin phi = 0), and for phi in (pi, 2 pi) the slot's line meets the guide behind O.

Example::

    mech = load("slider-crank")
    motion = mech.motion("constant", revolutions=1)
    t = np.linspace(0, motion.duration, 361)
    kin = mech.kinematics(t, motion)
    inputs, params = mech.fmu_inputs(kin), mech.fmu_parameters()
    out = reference.solve(mech.dyad, *mech.reference_inputs(kin))
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources

import numpy as np

from . import geometry as geo
from . import motion as motion_
from .motion import CrankMotion

__all__ = ["NAMES", "CrankMotion", "CrankSample", "Mechanism", "load", "default_data"]

#: The mechanisms, in the order of the documentation.
NAMES = ("slider-crank", "four-bar", "quick-return", "scotch-yoke", "trt-slot")

#: Dyad type of each mechanism.
DYADS = {
    "slider-crank": "RRT",
    "four-bar": "RRR",
    "quick-return": "RTR",
    "scotch-yoke": "RTT",
    "trt-slot": "TRT",
}

#: Types whose link m has a sliding length (an FMU input rather than a parameter).
_SLIDING_M = ("RTR", "RTT")
#: Types with a translational pair at D_m (guide_k) and at D_n (guide_p).
_GUIDE_K = ("RRT", "TRT", "RTT")
_GUIDE_P = ("TRT",)
#: What the conditioning is computed from.
_CONDITIONING_KEYS = ("m.angle", "n.angle", "guide_k.angle", "guide_p.angle", "m.length")
_CONDITIONING_KEYS += ("n.length", "D_m", "D_n")


def _branch(table: Mapping, where: str) -> float:
    """The assembly branch table["branch"]: +1 (the default) or -1."""
    value = geo.number(table, "branch", where, default=1.0)
    if value not in (1.0, -1.0):
        raise ValueError(f"{where}.branch: expected +1 or -1, got {value!r}")
    return value


@dataclass(frozen=True)
class CrankSample:
    """The crank's motion at the sample times: angle, speed and acceleration (N,) and
    its pin A's position, velocity and acceleration (N, 2)."""

    phi: np.ndarray
    w: np.ndarray
    eps: np.ndarray
    A: np.ndarray
    vA: np.ndarray
    aA: np.ndarray

    def pin_origin(self, link: str) -> dict:
        """Kinematics entries of a link whose origin D is the crank pin A: copies of A,
        v_A and a_A as ``D_<link>``, ``v_D_<link>`` and ``<link>.accel_d``."""
        return {
            f"D_{link}": self.A.copy(),
            f"v_D_{link}": self.vA.copy(),
            f"{link}.accel_d": self.aA.copy(),
        }


# ---------------------------------------------------------------------------
# data
# ---------------------------------------------------------------------------
def default_data() -> dict:
    """The packaged ``mechanisms.toml`` as a dict (a fresh copy)."""
    text = resources.files(__package__ or "dyadfmu").joinpath("mechanisms.toml").read_text("utf-8")
    return tomllib.loads(text)


# ---------------------------------------------------------------------------
# the mechanisms
# ---------------------------------------------------------------------------
class Mechanism:
    """A crank (external link p, pivot O) plus one dyad (links m, n) on the frame k.

    Attributes: ``name``, ``dyad`` ("RRT", ...), ``description``, ``gravity`` (gx, gy)
    [m/s2], ``crank`` {mass [kg], inertia [kg m2] about its centre of mass, com (x, y)
    [m] in the crank frame {O; crank direction, +90 deg}, radius r [m]}, ``links``
    {"m": {...}, "n": {...}} with mass, inertia, com and (where constant) length,
    ``geometry`` (the mechanism's own dimensions), ``load_data`` (its load model's
    constants), ``data`` (the whole table it was made from).
    """

    dyad = ""
    _constant_length = {"m": True, "n": True}
    #: the assembly branches of the mechanism; :attr:`branch` is the one it is built on
    branches: tuple[float, ...] = (1.0,)
    branch = 1.0

    def __init__(self, name: str, table: Mapping):
        where = name
        self.name = name
        self.data = copy.deepcopy(dict(table))
        dyad = str(table.get("dyad", self.dyad)).upper()
        if dyad != self.dyad:
            raise ValueError(f"{where}.dyad: the mechanism is an {self.dyad} dyad, got {dyad!r}")
        self.description = str(table.get("description", name))
        self.gravity = geo.pair(table, "gravity", where) if "gravity" in table else (0.0, -9.81)
        crank = table.get("crank", {})
        self.crank = {
            "radius": geo.number(crank, "radius", f"{where}.crank", positive=True),
            "mass": geo.number(crank, "mass", f"{where}.crank", nonnegative=True),
            "inertia": geo.number(crank, "inertia", f"{where}.crank", nonnegative=True),
            "com": geo.pair(crank, "com", f"{where}.crank"),
        }
        self.links = {}
        for g in ("m", "n"):
            lt = table.get(f"link_{g}", {})
            w = f"{where}.link_{g}"
            link = {
                "mass": geo.number(lt, "mass", w, nonnegative=True),
                "inertia": geo.number(lt, "inertia", w, nonnegative=True),
                "com": geo.pair(lt, "com", w),
            }
            fixed = self._fixed_lengths().get(g)
            if fixed is not None:
                link["length"] = fixed
            elif self._constant_length[g]:
                link["length"] = geo.number(lt, "length", w, positive=True)
            self.links[g] = link
        self.geometry = dict(table.get("geometry", {}))
        self.load_data = dict(table.get("load", {}))
        self._motion_data = dict(table.get("motion", {}))
        self._setup(where)
        self._check_motion(where)

    # ---- per type ---------------------------------------------------------
    def _fixed_lengths(self) -> dict:
        """Lengths fixed at 0 by the mechanism's construction."""
        return {}

    def _setup(self, where: str):  # pragma: no cover - overridden
        raise NotImplementedError

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:  # pragma: no cover
        raise NotImplementedError

    def _loads(self, kin: dict) -> dict:  # pragma: no cover
        raise NotImplementedError

    # ---- motion -----------------------------------------------------------
    def motion(self, kind: str = "constant", revolutions: float = 2.0) -> CrankMotion:
        """The crank's motion over ``revolutions`` revolutions (kind "constant": constant
        speed; "varying": omega = w0 (1 + a sin(w0 t)), phi integrated exactly)."""
        revolutions = motion_.checked_request(kind, revolutions)
        md, w = self._motion_data, f"{self.name}.motion"
        return motion_.rotating(
            kind,
            geo.number(md, "omega", w, positive=True),
            geo.number(md, "variation", w) if "variation" in md else 0.3,
            geo.number(md, "phi0", w) if "phi0" in md else 0.0,
            revolutions,
        )

    def _check_motion(self, where: str):
        variation = self._motion_data.get("variation", 0.3)
        if not (isinstance(variation, (int, float)) and 0 <= variation < 1):
            raise ValueError(f"{where}.motion.variation: must be in [0, 1), got {variation!r}")
        self.motion("constant", 1.0)

    # ---- kinematics -------------------------------------------------------
    def kinematics(self, t: np.ndarray, motion: CrankMotion, branch: float | None = None) -> dict:
        """Positions, velocities, accelerations and active loads at the times ``t`` (N,),
        on the assembly ``branch`` (default: the mechanism's, :attr:`branch`; the
        slider-crank and the four-bar have two, +1 and -1, the others one, +1). A
        complex ``t`` gives complex kinematics, analytic in t (for complex-step
        derivatives); the conditioning is then that of the real parts.

        Keys (arrays over the N samples; points and vectors (N, 2), scalars (N,)):
        ``t``; ``crank.angle``, ``crank.omega``, ``crank.epsilon``; points ``O``, ``A``,
        ``D_m``, ``E``, ``D_n``, ``S_m``, ``S_n``, ``S_c``; velocities ``v_A``, ``v_E``,
        ``v_D_m``, ``v_D_n``, ``v_S_m``, ``v_S_n``, ``v_S_c``; accelerations ``a_A``,
        ``a_E`` (of the geometric point E), ``a_S_m``, ``a_S_n``, ``a_S_c``; per link g in
        m, n: ``g.angle``, ``g.omega``, ``g.epsilon``, ``g.accel_d`` (N, 2), ``g.length``,
        ``g.length_rate``, ``g.length_accel``; ``guide_k.angle`` / ``guide_p.angle`` where
        the type has them; loads ``m.force``, ``m.moment``, ``n.force``, ``n.moment``;
        ``conditioning`` (the dyad's, as the FMU computes it). Non-array entries:
        ``frame`` (fixed pivots and fixed guides for drawing), ``mechanism`` (the name),
        ``branch`` (the assembly branch).
        """
        branch = self._checked_branch(branch)
        t, phi, w, eps = motion.sampled(t)
        r = self.crank["radius"]
        i_c = geo.unit(phi)
        j_c = geo.rot90(i_c)
        A = r * i_c
        vA = r * geo.col(w) * j_c
        aA = r * geo.col(eps) * j_c - r * geo.col(w * w) * i_c

        kin = {
            "t": t,
            "crank.angle": phi,
            "crank.omega": w,
            "crank.epsilon": eps,
            "O": np.zeros_like(A),
            "A": A,
            "v_A": vA,
            "a_A": aA,
            "branch": branch,
        }
        kin.update(self._dyad_kinematics(CrankSample(phi, w, eps, A, vA, aA), branch))

        self._point_e(kin)
        self._centres_of_mass(kin, w, eps)
        kin.update(self._loads(kin))
        kin["conditioning"] = self.conditioning(kin)
        kin["frame"] = self.frame() if branch == self.branch else self._frame_of(branch)
        kin["mechanism"] = self.name
        return kin

    @staticmethod
    def _point_e(kin: dict) -> None:
        """The geometric point E from link m, with its velocity and acceleration."""
        # the geometric point E from link m: E = D_m + l_m i_m
        i_m = geo.unit(kin["m.angle"])
        j_m = geo.rot90(i_m)
        lm, dlm, ddlm = kin["m.length"], kin["m.length_rate"], kin["m.length_accel"]
        wm, em = kin["m.omega"], kin["m.epsilon"]
        kin["E"] = kin["D_m"] + geo.col(lm) * i_m
        kin["v_E"] = kin["v_D_m"] + geo.col(dlm) * i_m + geo.col(lm * wm) * j_m
        kin["a_E"] = (
            kin["m.accel_d"]
            + geo.col(ddlm - lm * wm * wm) * i_m
            + geo.col(lm * em + 2.0 * dlm * wm) * j_m
        )

    def _centres_of_mass(self, kin: dict, w: np.ndarray, eps: np.ndarray) -> None:
        """The centres of mass of m, n and the crank, with their velocities and
        accelerations."""
        i_c = geo.unit(kin["crank.angle"])
        j_c = geo.rot90(i_c)
        # centres of mass: rigid-body relations from D_g (fixed in link g)
        for g in ("m", "n"):
            i_g = geo.unit(kin[f"{g}.angle"])
            x_s, y_s = self.links[g]["com"]
            rel = x_s * i_g + y_s * geo.rot90(i_g)
            wg, eg = geo.col(kin[f"{g}.omega"]), geo.col(kin[f"{g}.epsilon"])
            kin[f"S_{g}"] = kin[f"D_{g}"] + rel
            kin[f"v_S_{g}"] = kin[f"v_D_{g}"] + wg * geo.rot90(rel)
            kin[f"a_S_{g}"] = kin[f"{g}.accel_d"] + eg * geo.rot90(rel) - wg * wg * rel
        x_c, y_c = self.crank["com"]
        rel = x_c * i_c + y_c * j_c
        kin["S_c"] = rel
        kin["v_S_c"] = geo.col(w) * geo.rot90(rel)
        kin["a_S_c"] = geo.col(eps) * geo.rot90(rel) - geo.col(w * w) * rel

    def frame(self) -> dict:
        """Fixed pivots {label: (x, y)} and fixed guides {label: ((x0, y0), (x1, y1))}."""
        return {"pivots": {"O": (0.0, 0.0)}, "guides": {}}

    def _frame_of(self, branch: float) -> dict:
        """The frame drawn for another assembly branch than the mechanism's."""
        other = copy.copy(self)
        other.branch = branch
        return other.frame()

    def _checked_branch(self, branch: float | None) -> float:
        """The assembly branch asked for (None: the mechanism's), checked against the
        branches the mechanism has."""
        if branch is None:
            return self.branch
        if branch not in self.branches:
            raise ValueError(
                f"{self.name}: assembly branch {branch!r}; expected one of {self.branches}"
            )
        return float(branch)

    def conditioning(self, kin: dict) -> np.ndarray:
        """The dyad's conditioning per sample, as the C core computes it (README); of the
        real parts where the kinematics are complex."""
        kin = {k: np.real(kin[k]) for k in _CONDITIONING_KEYS if k in kin}
        i_m, i_n = geo.unit(kin["m.angle"]), geo.unit(kin["n.angle"])
        if self.dyad == "RRR":
            return np.abs(geo.dot(i_m, geo.rot90(i_n)))
        if self.dyad == "RRT":
            return np.abs(geo.dot(i_n, geo.unit(kin["guide_k.angle"])))
        if self.dyad == "RTR":
            lm, ln = kin["m.length"], kin["n.length"]
            d = kin["D_n"] - kin["D_m"]
            dist = geo.norm(d)
            i_beta = d / geo.col(np.where(dist > 0, dist, 1.0))
            c = np.abs(geo.dot(i_beta, i_m))
            return np.minimum(c, np.minimum(1.0, dist / (lm + ln)))
        if self.dyad == "TRT":
            return np.abs(
                geo.dot(geo.rot90(geo.unit(kin["guide_k.angle"])), geo.unit(kin["guide_p.angle"]))
            )
        return np.abs(geo.dot(geo.rot90(geo.unit(kin["guide_k.angle"])), i_m))  # RTT

    # ---- FMU and reference ------------------------------------------------
    def fmu_parameters(self) -> dict:
        """The FMU's parameters (all but ``singular_threshold``): name -> value."""
        p = {}
        for g in ("m", "n"):
            link = self.links[g]
            if not (g == "m" and self.dyad in _SLIDING_M):
                p[f"link_{g}.length"] = float(link["length"])
            p[f"link_{g}.com.x"], p[f"link_{g}.com.y"] = (float(c) for c in link["com"])
            p[f"link_{g}.mass"] = float(link["mass"])
            p[f"link_{g}.inertia"] = float(link["inertia"])
        p["gravity.x"], p["gravity.y"] = (float(c) for c in self.gravity)
        return p

    def fmu_inputs(self, kin: dict) -> dict:
        """The FMU's inputs as arrays (N,): name -> values, in the table's order."""
        u = {}
        for g in ("m", "n"):
            u[f"link_{g}.angle"] = np.asarray(kin[f"{g}.angle"], dtype=float)
            u[f"link_{g}.omega"] = np.asarray(kin[f"{g}.omega"], dtype=float)
            u[f"link_{g}.epsilon"] = np.asarray(kin[f"{g}.epsilon"], dtype=float)
            u[f"link_{g}.accel_d.x"] = kin[f"{g}.accel_d"][:, 0].copy()
            u[f"link_{g}.accel_d.y"] = kin[f"{g}.accel_d"][:, 1].copy()
            u[f"link_{g}.force.x"] = kin[f"{g}.force"][:, 0].copy()
            u[f"link_{g}.force.y"] = kin[f"{g}.force"][:, 1].copy()
            u[f"link_{g}.moment"] = np.asarray(kin[f"{g}.moment"], dtype=float)
            if g == "m" and self.dyad in _SLIDING_M:
                u["link_m.length"] = np.asarray(kin["m.length"], dtype=float)
        if self.dyad in _GUIDE_K:
            u["guide_k.angle"] = np.asarray(kin["guide_k.angle"], dtype=float)
        if self.dyad in _GUIDE_P:
            u["guide_p.angle"] = np.asarray(kin["guide_p.angle"], dtype=float)
        return u

    def reference_inputs(self, kin: dict) -> tuple:
        """``(m, n, guide_k, guide_p, gravity)`` for ``reference.solve(dyad, ...)``, batched
        over the samples (a guide is None where the type has none)."""
        links = []
        for g in ("m", "n"):
            link = self.links[g]
            links.append(
                {
                    "dir": geo.unit(kin[f"{g}.angle"]),
                    "length": np.asarray(kin[f"{g}.length"], dtype=float),
                    "omega": np.asarray(kin[f"{g}.omega"], dtype=float),
                    "epsilon": np.asarray(kin[f"{g}.epsilon"], dtype=float),
                    "accel_d": np.asarray(kin[f"{g}.accel_d"], dtype=float),
                    "com": tuple(link["com"]),
                    "mass": link["mass"],
                    "inertia": link["inertia"],
                    "force": np.asarray(kin[f"{g}.force"], dtype=float),
                    "moment": np.asarray(kin[f"{g}.moment"], dtype=float),
                }
            )
        gk = geo.unit(kin["guide_k.angle"]) if self.dyad in _GUIDE_K else None
        gp = geo.unit(kin["guide_p.angle"]) if self.dyad in _GUIDE_P else None
        return links[0], links[1], gk, gp, tuple(self.gravity)

    def __repr__(self):
        return f"<Mechanism {self.name} ({self.dyad})>"


def _link(
    prefix: str,
    angle: np.ndarray,
    omega: np.ndarray,
    epsilon: np.ndarray,
    length: np.ndarray | float,
    rate: np.ndarray | None = None,
    accel: np.ndarray | None = None,
):
    """Per-link entries; rate/accel of the length default to 0 (constant length)."""
    n = np.shape(angle)

    def full(x: object) -> np.ndarray:
        return np.broadcast_to(geo.inexact(0.0 if x is None else x), n).copy()

    return {
        f"{prefix}.angle": full(angle),
        f"{prefix}.omega": full(omega),
        f"{prefix}.epsilon": full(epsilon),
        f"{prefix}.length": full(length),
        f"{prefix}.length_rate": full(rate),
        f"{prefix}.length_accel": full(accel),
    }


class SliderCrank(Mechanism):
    """RRT: rod n from the crank pin A (D_n) to the piston pin B (E = D_m, l_m = 0);
    piston m on the frame guide along +x at height e. Gas force on the piston along -x."""

    dyad = "RRT"
    _constant_length = {"m": False, "n": True}
    branches = (1.0, -1.0)

    def _fixed_lengths(self):
        return {"m": 0.0}

    def _setup(self, where: str):
        self.e = geo.number(self.geometry, "offset", f"{where}.geometry")
        self.branch = _branch(self.geometry, f"{where}.geometry")
        self.l = self.links["n"]["length"]
        r = self.crank["radius"]
        if not self.l > r + abs(self.e):
            raise ValueError(
                f"{where}: the rod ({self.l} m) must be longer than crank radius "
                f"+ |offset| ({r + abs(self.e)} m) for the crank to turn round"
            )
        ld, w = self.load_data, f"{where}.load"
        self.area = math.pi * geo.number(ld, "bore", w, positive=True) ** 2 / 4.0
        self.p_peak = geo.number(ld, "p_peak", w)
        self.p_base = geo.number(ld, "p_base", w)
        self.psi_peak = geo.number(ld, "psi_peak", w)
        self.kappa = geo.number(ld, "kappa", w, nonnegative=True)
        #: crank angle of top dead centre (crank and rod in line, piston farthest out)
        self.phi_tdc = self.top_dead_centre(self.branch)

    def top_dead_centre(self, branch: float) -> float:
        """The crank angle (rad) of top dead centre on the assembly ``branch``: crank and
        rod in line, the piston farthest from O (on branch -1 it runs on the guide's
        other side of O, and the angle is pi minus that of branch +1)."""
        base = math.asin(self.e / (self.l + self.crank["radius"]))
        return base if branch > 0 else math.pi - base

    def gas_force(self, phi: np.ndarray, branch: float | None = None) -> np.ndarray:
        """Magnitude [N] of the gas force on the piston: it acts along -x on branch +1
        and along +x on branch -1 (towards the crank), peaking ``psi_peak`` after top
        dead centre of that branch (default: the mechanism's branch)."""
        tdc = self.phi_tdc if branch is None else self.top_dead_centre(branch)
        psi = geo.inexact(phi) - tdc - self.psi_peak
        pulse = np.exp(self.kappa * (np.cos(psi) - 1.0))
        return self.area * (self.p_base + (self.p_peak - self.p_base) * pulse)

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:
        phi, A, vA, aA = crank.phi, crank.A, crank.vA, crank.aA
        rod, e = self.l, self.e
        sn = (e - A[:, 1]) / rod  # E_y = e = A_y + rod sin(theta_n)
        # branch +1: the piston to the right of the crank pin (ahead of A's foot along +x)
        cn = branch * np.sqrt(1.0 - sn * sn)
        tn = geo.angle(geo.vec(cn, sn))
        wn = -vA[:, 1] / (rod * cn)
        en = (rod * wn * wn * sn - aA[:, 1]) / (rod * cn)
        B = geo.vec(A[:, 0] + rod * cn, np.full_like(cn, e))
        vB = geo.vec(vA[:, 0] - rod * wn * sn, 0.0)
        aB = geo.vec(aA[:, 0] - rod * en * sn - rod * wn * wn * cn, 0.0)
        zero = np.zeros_like(phi)
        out = {
            "D_m": B,
            "v_D_m": vB,
            "m.accel_d": aB,
            **crank.pin_origin("n"),
            "guide_k.angle": zero.copy(),
        }
        out.update(_link("m", zero, zero, zero, zero))
        out.update(_link("n", tn, wn, en, rod))
        return out

    def _loads(self, kin: dict):
        branch = kin.get("branch", self.branch)
        f = self.gas_force(kin["crank.angle"], branch)
        zero = np.zeros_like(f)
        return {
            "m.force": geo.vec(-branch * f, zero),
            "m.moment": zero.copy(),
            "n.force": geo.vec(zero, zero),
            "n.moment": zero.copy(),
        }

    def frame(self) -> dict:
        r, rod, e = self.crank["radius"], self.l, self.e
        x0, x1 = math.sqrt((rod - r) ** 2 - e * e), math.sqrt((rod + r) ** 2 - e * e)
        if self.branch < 0:
            x0, x1 = -x1, -x0
        pad = 0.25 * r
        return {"pivots": {"O": (0.0, 0.0)}, "guides": {"k": ((x0 - pad, e), (x1 + pad, e))}}


class FourBar(Mechanism):
    """RRR: coupler n from the crank pin A (D_n) to E, rocker m from the fixed pivot
    O4 (D_m) to E. Resisting torque on the rocker."""

    dyad = "RRR"
    branches = (1.0, -1.0)

    def _setup(self, where: str):
        g = self.geometry
        self.O4 = geo.pair(g, "O4", f"{where}.geometry")
        self.branch = _branch(g, f"{where}.geometry")
        a = self.crank["radius"]
        b, c = self.links["n"]["length"], self.links["m"]["length"]
        d = math.hypot(*self.O4)
        s, l_ = min(a, b, c, d), max(a, b, c, d)
        if not (a == s and s + l_ < a + b + c + d - s - l_):
            raise ValueError(
                f"{where}: not a Grashof crank-rocker (crank {a}, coupler {b}, "
                f"rocker {c}, ground {d} m): the crank must be the shortest link "
                f"and shortest + longest < the other two"
            )
        ld, w = self.load_data, f"{where}.load"
        self.T0 = geo.number(ld, "T0", w)
        self.w_ref = geo.number(ld, "w_ref", w, positive=True)
        self.c_visc = geo.number(ld, "c", w)

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:
        A, vA, aA = crank.A, crank.vA, crank.aA
        b, c = self.links["n"]["length"], self.links["m"]["length"]
        O4 = np.broadcast_to(np.asarray(self.O4, dtype=float), A.shape)
        dv = A - O4
        dist = geo.norm(dv)
        u = dv / geo.col(dist)
        along = (c * c - b * b + dist * dist) / (2.0 * dist)
        height = np.sqrt(c * c - along * along)
        # branch +1: E on the left of the directed line A -> O4, i.e. on the right of O4 -> A
        E = O4 + geo.col(along) * u - branch * geo.col(height) * geo.rot90(u)
        i_m = (E - O4) / c
        i_n = (E - A) / b
        tm = geo.angle(i_m)
        tn = geo.angle(i_n)
        s_mn = geo.cross(i_n, i_m)  # sin(theta_m - theta_n)
        wn = -geo.dot(vA, i_m) / (b * s_mn)
        wm = -geo.dot(vA, i_n) / (c * s_mn)
        K = aA - geo.col(wn * wn * b) * i_n + geo.col(wm * wm * c) * i_m
        en = -geo.dot(K, i_m) / (b * s_mn)
        em = -geo.dot(K, i_n) / (c * s_mn)
        zero = np.zeros_like(A)
        out = {
            "D_m": O4.copy(),
            "v_D_m": zero.copy(),
            "m.accel_d": zero.copy(),
            **crank.pin_origin("n"),
        }
        out.update(_link("m", tm, wm, em, c))
        out.update(_link("n", tn, wn, en, b))
        return out

    def _loads(self, kin: dict):
        wm = kin["m.omega"]
        zero = np.zeros_like(wm)
        return {
            "m.force": geo.vec(zero, zero),
            "m.moment": -self.T0 * np.tanh(wm / self.w_ref) - self.c_visc * wm,
            "n.force": geo.vec(zero, zero),
            "n.moment": zero.copy(),
        }

    def frame(self) -> dict:
        return {"pivots": {"O": (0.0, 0.0), "O4": tuple(self.O4)}, "guides": {}}


class QuickReturn(Mechanism):
    """RTR: block n on the crank pin A (D_n = E, l_n = 0) sliding in the slot of the
    lever m pivoted at the fixed O2 (D_m); l_m = |O2 A|. Resisting moment on the lever
    during its working stroke."""

    dyad = "RTR"
    _constant_length = {"m": False, "n": False}

    def _fixed_lengths(self):
        return {"n": 0.0}

    def _setup(self, where: str):
        g, w = self.geometry, f"{where}.geometry"
        self.O2 = geo.pair(g, "O2", w)
        r = self.crank["radius"]
        d = math.hypot(*self.O2)
        if not d > 1.05 * r:
            raise ValueError(
                f"{where}: |O O2| = {d} m must exceed the crank radius {r} m "
                f"(by 5 %) for the lever to oscillate"
            )
        self.lever_length = geo.number(g, "lever_length", w, positive=True)
        if self.lever_length < d + r:
            raise ValueError(f"{w}.lever_length: must be at least |O O2| + r = {d + r} m")
        ld, wl = self.load_data, f"{where}.load"
        self.M0 = geo.number(ld, "M0", wl)
        self.w_ref = geo.number(ld, "w_ref", wl, positive=True)

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:
        A, vA, aA = crank.A, crank.vA, crank.aA
        O2 = np.broadcast_to(np.asarray(self.O2, dtype=float), A.shape)
        dv = A - O2
        lm = geo.norm(dv)
        i_m = dv / geo.col(lm)
        j_m = geo.rot90(i_m)
        tm = geo.angle(i_m)
        dlm = geo.dot(vA, i_m)  # A = O2 + l_m i_m
        wm = geo.dot(vA, j_m) / lm
        ddlm = geo.dot(aA, i_m) + lm * wm * wm
        em = (geo.dot(aA, j_m) - 2.0 * dlm * wm) / lm
        zero = np.zeros_like(A)
        out = {
            "D_m": O2.copy(),
            "v_D_m": zero.copy(),
            "m.accel_d": zero.copy(),
            **crank.pin_origin("n"),
        }
        out.update(_link("m", tm, wm, em, lm, dlm, ddlm))
        out.update(_link("n", tm, wm, em, 0.0 * lm))  # the block turns with the lever
        return out

    def _loads(self, kin: dict):
        u = np.tanh(kin["m.omega"] / self.w_ref)
        zero = np.zeros_like(u)
        return {
            "m.force": geo.vec(zero, zero),
            "m.moment": -self.M0 * u * (1.0 + u) / 2.0,
            "n.force": geo.vec(zero, zero),
            "n.moment": zero.copy(),
        }

    def frame(self) -> dict:
        return {"pivots": {"O": (0.0, 0.0), "O2": tuple(self.O2)}, "guides": {}}


def _resistance_along_x(kin: dict, f0: float, v_ref: float, c_visc: float):
    """Loads of a link m that translates along x against a smooth resisting force
    F = -f0 tanh(v / v_ref) - c_visc v (N), v the velocity of D_m (m/s)."""
    v = kin["v_D_m"][:, 0]
    zero = np.zeros_like(v)
    fx = -f0 * np.tanh(v / v_ref) - c_visc * v
    return {
        "m.force": geo.vec(fx, zero),
        "m.moment": zero.copy(),
        "n.force": geo.vec(zero, zero),
        "n.moment": zero.copy(),
    }


class ScotchYoke(Mechanism):
    """RTT: block n on the crank pin A (D_n = E, l_n = 0) sliding in the vertical slot
    of the yoke m, which slides on the frame guide along x at y = -h; D_m = (A_x, -h),
    i_m = (0, 1), l_m = A_y + h. Pump resistance on the yoke along x."""

    dyad = "RTT"
    _constant_length = {"m": False, "n": False}

    def _fixed_lengths(self):
        return {"n": 0.0}

    def _setup(self, where: str):
        self.h = geo.number(self.geometry, "h", f"{where}.geometry", positive=True)
        r = self.crank["radius"]
        if not self.h > 1.05 * r:
            raise ValueError(f"{where}.geometry.h: must exceed the crank radius {r} m by 5 %")
        ld, w = self.load_data, f"{where}.load"
        self.F0 = geo.number(ld, "F0", w)
        self.v_ref = geo.number(ld, "v_ref", w, positive=True)
        self.c_visc = geo.number(ld, "c", w)

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:
        phi, A, vA, aA = crank.phi, crank.A, crank.vA, crank.aA
        h = self.h
        up = np.full_like(phi, math.pi / 2.0)
        zero = np.zeros_like(phi)
        out = {
            "D_m": geo.vec(A[:, 0], -h + zero),
            "v_D_m": geo.vec(vA[:, 0], zero),
            "m.accel_d": geo.vec(aA[:, 0], zero),
            **crank.pin_origin("n"),
            "guide_k.angle": zero.copy(),
        }
        out.update(_link("m", up, zero, zero, A[:, 1] + h, vA[:, 1], aA[:, 1]))
        out.update(_link("n", up, zero, zero, zero))
        return out

    def _loads(self, kin: dict):
        return _resistance_along_x(kin, self.F0, self.v_ref, self.c_visc)

    def frame(self) -> dict:
        r, h = self.crank["radius"], self.h
        return {"pivots": {"O": (0.0, 0.0)}, "guides": {"k": ((-1.6 * r, -h), (1.6 * r, -h))}}


class TRTSlot(Mechanism):
    """TRT: block n slides in the crank's slot (i_n = i_p = crank direction) and is
    pinned at E to the slider m on the fixed guide along x at y = h: E = (h cot phi, h),
    l_m = l_n = 0. The crank oscillates inside (0, pi) (see the module data)."""

    dyad = "TRT"
    _constant_length = {"m": False, "n": False}

    def _fixed_lengths(self):
        return {"m": 0.0, "n": 0.0}

    def _setup(self, where: str):
        self.h = geo.number(self.geometry, "h", f"{where}.geometry", positive=True)
        ld, w = self.load_data, f"{where}.load"
        self.F0 = geo.number(ld, "F0", w)
        self.v_ref = geo.number(ld, "v_ref", w, positive=True)
        self.c_visc = geo.number(ld, "c", w)

    def motion(self, kind: str = "constant", revolutions: float = 2.0) -> CrankMotion:
        """The crank's oscillation over ``revolutions`` cycles: phi = centre + amplitude
        sin(omega t) (kind "varying" adds harmonic2 sin(2 omega t)). A full turn is
        impossible: at phi = 0 and pi the slot is parallel to the guide (E at infinity,
        conditioning sin phi = 0)."""
        revolutions = motion_.checked_request(kind, revolutions)
        md, w = self._motion_data, f"{self.name}.motion"
        return motion_.oscillating(
            kind,
            geo.number(md, "omega", w, positive=True),
            geo.number(md, "centre", w),
            geo.number(md, "amplitude", w),
            geo.number(md, "harmonic2", w) if "harmonic2" in md else 0.0,
            revolutions,
        )

    def _check_motion(self, where: str):
        r, h = self.crank["radius"], self.h
        for kind in ("constant", "varying"):
            m = self.motion(kind, 1.0)
            phi = m.phi(np.linspace(0.0, m.duration, 2001))
            s = float(np.min(np.sin(phi)))
            if s < 0.2:
                raise ValueError(
                    f"{where}.motion: the {kind} oscillation reaches sin(phi) = "
                    f"{s:.3g}; it must stay inside (0, pi) with sin(phi) >= 0.2 "
                    f"(the slot is parallel to the guide at 0 and pi)"
                )
            if h / s > r:
                raise ValueError(
                    f"{where}.crank.radius: the slot ({r} m) must reach the "
                    f"guide at the extreme angle ({h / s:.4g} m)"
                )

    def _dyad_kinematics(self, crank: CrankSample, branch: float) -> dict:
        phi, w, eps = crank.phi, crank.w, crank.eps
        h = self.h
        c, s = np.cos(phi), np.sin(phi)
        x = h * c / s
        dx = -h * w / (s * s)
        ddx = -h * eps / (s * s) + 2.0 * h * w * w * c / (s**3)
        zero = np.zeros_like(phi)
        E = geo.vec(x, h + zero)
        vE = geo.vec(dx, zero)
        aE = geo.vec(ddx, zero)
        out = {
            "D_m": E,
            "v_D_m": vE,
            "m.accel_d": aE,
            "D_n": E.copy(),
            "v_D_n": vE.copy(),
            "n.accel_d": aE.copy(),
            "guide_k.angle": zero.copy(),
            "guide_p.angle": geo.inexact(phi).copy(),
        }
        out.update(_link("m", zero, zero, zero, zero))
        out.update(_link("n", phi, w, eps, zero))
        return out

    def _loads(self, kin: dict):
        return _resistance_along_x(kin, self.F0, self.v_ref, self.c_visc)

    def frame(self) -> dict:
        r, h = self.crank["radius"], self.h
        reach = math.sqrt(max(r * r - h * h, 0.0))
        return {
            "pivots": {"O": (0.0, 0.0)},
            "guides": {"k": ((-reach - 0.1 * r, h), (reach + 0.1 * r, h))},
        }


_CLASSES = {
    "slider-crank": SliderCrank,
    "four-bar": FourBar,
    "quick-return": QuickReturn,
    "scotch-yoke": ScotchYoke,
    "trt-slot": TRTSlot,
}


def load(name: str, data: Mapping | None = None) -> Mechanism:
    """The mechanism ``name`` (one of :data:`NAMES`) with its default data.

    ``data`` overrides the packaged defaults key by key (nested tables merged): a
    mapping, either the whole document (with a table ``name``) or the mechanism's own
    table, or the path of a TOML file of the same form.
    """
    if name not in NAMES:
        raise ValueError(f"unknown mechanism {name!r}; expected one of: {', '.join(NAMES)}")
    table = geo.overridden(default_data()[name], name, data)
    return _CLASSES[name](name, table)

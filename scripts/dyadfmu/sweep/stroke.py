"""A linear driver's run over its stroke: the motion, and for a cylinder run through its
link's angle, the cylinder's length, rate and acceleration from each design's geometry.

The motion is a cycloidal rise, rest to rest: the coordinate q (a ram's position, a
cylinder's length, or the angle of a cylinder's link) goes from ``low`` to ``high`` in
``duration`` T as

    q = low + (high - low) (tau - sin(2 pi tau) / (2 pi)),   tau = t / T,
    q' = (high - low) (1 - cos(2 pi tau)) / T,   q'' = 2 pi (high - low) sin(2 pi tau) / T^2,

sampled at ``points`` equally spaced instants, both ends included. Velocity and
acceleration are zero at both ends and continuous between: the inertia terms are
exercised (the peak acceleration is 2 pi (high - low) / T^2 at a quarter of the run)
without the jumps of a motion that starts at full speed.

The cylinder (modelDescription/scenes/README.md, ``[cylinder]``). The link turns about its
pivot O, the barrel is pinned to the frame at A and the rod to the link at B, at ``pin``
p in the link's frame. With a = |OA|, b = |p|, alpha the direction of A - O and beta that
of p, the link at angle theta has B at O + R(theta) p and, by the law of cosines in the
triangle O, A, B (psi = theta + beta - alpha, the angle at O from OA to OB),

    s^2 = a^2 + b^2 - 2 a b cos(psi),
    ds/dtheta = a b sin(psi) / s,   d2s/dtheta2 = (a b cos(psi) - (ds/dtheta)^2) / s,

ds/dtheta being the cylinder's lever arm about O (computed from r = B - O and e = A - O
as e x r / s and (e . r - (ds/dtheta)^2) / s, s = |r - e|). The cylinder's rates follow from the
link's: s' = ds/dtheta theta', s'' = d2s/dtheta2 theta'^2 + ds/dtheta theta''. B is to the
left of the directed line O -> A where sin(psi) > 0 (branch +1, the cylinder's ``branch``
whose sign counts; the FMU reads a branch below 0 as -1 and any other as +1). Where psi
is a multiple of pi, O, A and B are in line: the toggle, where the lever arm vanishes, the
cylinder cannot turn the link and the link's angle passes from one branch to the other.
A run over [low, high] is possible on the cylinder's branch only where sin(psi) keeps the
branch's sign over the whole interval: psi is linear in theta, so the check is exact, not
sampled.

A cylinder's pins O and A may both sit on a moving link, the carrier C (the stick
cylinder of an excavator, pinned to the boom at both ends; modelDescription/scenes/
README.md, "Several drivers"). The triangle O, A, B is then one of C's frame: O and A are
fixed in it and B turns about O with the link's angle relative to C, theta - theta_C.
The formulas above hold in C's frame with that relative angle and its rates, whatever C
itself does: the length depends on the relative angle only, so a run over it gives each
design's lengths and rates in closed form and its toggle check stays exact. Where O and
A sit on different bodies (one on the frame, one on a link), the length depends on two
angles: such a cylinder is run over its length, not an angle (the study refuses it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["cycloid", "Cylinder", "Unreachable"]


def cycloid(
    low: float, high: float, duration: float, points: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q', q'') of the cycloidal rise from ``low`` to ``high`` in ``duration`` s, at
    ``points`` equally spaced instants from 0 to ``duration``."""
    tau = np.linspace(0.0, 1.0, points)
    span, turn = high - low, 2 * math.pi * tau
    q = low + span * (tau - np.sin(turn) / (2 * math.pi))
    q[-1] = high  # exactly the end of the stroke, not within round-off of it
    return q, span * (1 - np.cos(turn)) / duration, 2 * math.pi * span * np.sin(turn) / duration**2


class Unreachable(ValueError):
    """A cylinder's design cannot turn its link over the run: ``status`` says how
    (``singular``: the run passes the toggle; ``cannot_assemble``: B is on the other
    branch; ``invalid_input``: two of the pins coincide)."""

    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status = status


@dataclass(frozen=True)
class Cylinder:
    """A cylinder's geometry: the link's pivot O and the barrel's pin A (m, global, or in
    the frame of the link ``carrier`` that carries both), the rod's pin B (m, in the
    link's frame), the branch (its sign). Its angles are the link's, relative to the
    carrier's where it has one."""

    name: str
    link: str
    o: tuple
    a: tuple
    pin: tuple
    branch: float
    carrier: str | None = None

    @property
    def angle_name(self) -> str:
        """The angle the triangle sees, as messages name it."""
        own = f"{self.link}.angle"
        return own if self.carrier is None else f"{own} - {self.carrier}.angle"

    def _triangle(self) -> tuple[float, float, float]:
        """(|OA|, |OB|, beta - alpha)."""
        dx, dy = self.a[0] - self.o[0], self.a[1] - self.o[1]
        return (
            math.hypot(dx, dy),
            math.hypot(*self.pin),
            math.atan2(self.pin[1], self.pin[0]) - math.atan2(dy, dx),
        )

    def check(self, low: float, high: float) -> None:
        """Unreachable where the link cannot be turned from ``low`` to ``high`` (rad) on
        the cylinder's branch: the toggle within the interval, or B on the other side."""
        a, b, offset = self._triangle()
        if not (a > 0 and b > 0 and math.isfinite(a * b)):
            raise Unreachable(
                "invalid_input",
                f"cylinder {self.name}: O, A and B must be three points at finite distances "
                f"(|OA| = {a:.6g} m, |OB| = {b:.6g} m)",
            )
        psi0, psi1 = low + offset, high + offset
        n = math.ceil(psi0 / math.pi)
        if n * math.pi <= psi1:  # sin(psi) = 0 on [psi0, psi1]
            at = n * math.pi - offset
            raise Unreachable(
                "singular",
                f"cylinder {self.name} passes its toggle (O, A and B in line) at "
                f"{self.angle_name} {at:.6g} rad ({math.degrees(at):.4g} deg): no length "
                f"of it turns {self.link} from {low:.6g} to {high:.6g} rad",
            )
        side = 1 if math.sin(0.5 * (psi0 + psi1)) > 0 else -1
        if side != (-1 if self.branch < 0 else 1):
            raise Unreachable(
                "cannot_assemble",
                f"cylinder {self.name}: from {self.angle_name} {low:.6g} to {high:.6g} rad "
                f"B is to the {'left' if side > 0 else 'right'} of the line O -> A, the "
                f"branch {side:+d}, not the cylinder's {-side:+d}",
            )

    def lengths(
        self, theta: np.ndarray, omega: np.ndarray, epsilon: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, s', s'') of the cylinder with its link at ``theta`` (rad), turning at
        ``omega`` (rad/s) with ``epsilon`` (rad/s2)."""
        # from the points themselves, r = B - O and e = A - O, not from the law of
        # cosines, whose difference loses digits where s is short against |OA| and |OB|
        c, sn = np.cos(theta), np.sin(theta)
        rx = c * self.pin[0] - sn * self.pin[1]
        ry = sn * self.pin[0] + c * self.pin[1]
        ex, ey = self.a[0] - self.o[0], self.a[1] - self.o[1]
        s = np.hypot(rx - ex, ry - ey)
        arm = (ex * ry - ey * rx) / s  # e x r = a b sin(psi)
        curvature = (ex * rx + ey * ry - arm * arm) / s  # e . r = a b cos(psi)
        return s, arm * omega, curvature * omega * omega + arm * epsilon

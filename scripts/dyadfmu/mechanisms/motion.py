"""Crank motions: closed-form angle, speed and acceleration of a turning or oscillating
crank."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .geometry import inexact


@dataclass(frozen=True)
class CrankMotion:
    """A crank motion: phi(t) [rad], omega(t) [rad/s], epsilon(t) [rad/s2] as vectorised
    callables, consistent with each other in closed form, and ``duration`` [s] covering
    the requested number of revolutions (or oscillation cycles)."""

    kind: str
    phi: Callable[[np.ndarray], np.ndarray]
    omega: Callable[[np.ndarray], np.ndarray]
    epsilon: Callable[[np.ndarray], np.ndarray]
    duration: float
    cycles: float
    description: str = ""

    def sampled(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The times ``t`` as a float array of shape (N,), and the crank's angle, angular
        velocity and angular acceleration at them, each a float array of that shape
        (complex arrays where ``t`` is complex: a complex step in time passes through)."""
        t = np.atleast_1d(inexact(t))
        if t.ndim != 1:
            raise ValueError(f"t: expected shape (N,), got {t.shape}")
        phi = np.broadcast_to(self.phi(t), t.shape).astype(t.dtype)
        w = np.broadcast_to(self.omega(t), t.shape).astype(t.dtype)
        eps = np.broadcast_to(self.epsilon(t), t.shape).astype(t.dtype)
        return t, phi, w, eps


def checked_request(kind: str, revolutions: float) -> float:
    """The number of revolutions (or cycles) asked of a motion of ``kind``, checked:
    kind "constant" or "varying", revolutions a positive finite number."""
    if kind not in ("constant", "varying"):
        raise ValueError(f"unknown motion kind {kind!r}; expected 'constant' or 'varying'")
    revolutions = float(revolutions)
    if not (revolutions > 0 and math.isfinite(revolutions)):
        raise ValueError(f"revolutions must be a positive number, got {revolutions!r}")
    return revolutions


def rotating(
    kind: str, w0: float, variation: float, phi0: float, revolutions: float
) -> CrankMotion:
    """Full rotation. constant: phi = phi0 + w0 t. varying: omega = w0 (1 + a sin(w0 t)),
    phi = phi0 + w0 t + a (1 - cos(w0 t)), epsilon = a w0^2 cos(w0 t)."""
    a = variation if kind == "varying" else 0.0

    def phi(t: np.ndarray):
        t = inexact(t)
        return phi0 + w0 * t + a * (1.0 - np.cos(w0 * t))

    def omega(t: np.ndarray):
        t = inexact(t)
        return w0 * (1.0 + a * np.sin(w0 * t))

    def epsilon(t: np.ndarray):
        t = inexact(t)
        return a * w0 * w0 * np.cos(w0 * t)

    # duration: phi(T) - phi0 = 2 pi N; exact for integer N, Newton otherwise
    # (the left side increases strictly since |a| < 1)
    target = 2.0 * math.pi * revolutions
    x = target  # x = w0 T
    for _ in range(60):
        f = x + a * (1.0 - math.cos(x)) - target
        x_new = x - f / (1.0 + a * math.sin(x))
        if abs(x_new - x) <= 1e-15 * max(1.0, abs(x)):
            x = x_new
            break
        x = x_new
    text = (
        f"constant speed {w0:.6g} rad/s"
        if a == 0.0
        else f"omega = {w0:.6g} (1 + {a:g} sin({w0:.6g} t)) rad/s"
    )
    return CrankMotion(kind, phi, omega, epsilon, x / w0, float(revolutions), text)


def oscillating(
    kind: str, w: np.ndarray, centre: np.ndarray, amplitude: float, harmonic2: float, cycles: float
) -> CrankMotion:
    """Oscillation phi = centre + A1 sin(w t) + A2 sin(2 w t) (A2 = 0 for kind constant)."""
    a2 = harmonic2 if kind == "varying" else 0.0

    def phi(t: np.ndarray):
        t = inexact(t)
        return centre + amplitude * np.sin(w * t) + a2 * np.sin(2.0 * w * t)

    def omega(t: np.ndarray):
        t = inexact(t)
        return amplitude * w * np.cos(w * t) + 2.0 * a2 * w * np.cos(2.0 * w * t)

    def epsilon(t: np.ndarray):
        t = inexact(t)
        return -amplitude * w * w * np.sin(w * t) - 4.0 * a2 * w * w * np.sin(2.0 * w * t)

    text = (
        f"phi = {centre:.4g} + {amplitude:g} sin({w:.6g} t)"
        + (f" + {a2:g} sin({2 * w:.6g} t)" if a2 else "")
        + " rad"
    )
    return CrankMotion(kind, phi, omega, epsilon, cycles * 2.0 * math.pi / w, float(cycles), text)


@dataclass(frozen=True)
class RamMotion:
    """A linear actuator's (ram's) motion along its guide: position x(t) [m], velocity
    [m/s] and acceleration [m/s2] as vectorised callables, consistent with each other in
    closed form, and ``duration`` [s] covering the requested number of strokes out and
    back (``cycles``)."""

    kind: str
    position: Callable[[np.ndarray], np.ndarray]
    velocity: Callable[[np.ndarray], np.ndarray]
    acceleration: Callable[[np.ndarray], np.ndarray]
    duration: float
    cycles: float
    description: str = ""

    def sampled(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The times ``t`` as an array of shape (N,), and the ram's position, velocity and
        acceleration at them (float, or complex where ``t`` is complex)."""
        t = np.atleast_1d(inexact(t))
        if t.ndim != 1:
            raise ValueError(f"t: expected shape (N,), got {t.shape}")
        x = np.broadcast_to(self.position(t), t.shape).astype(t.dtype)
        v = np.broadcast_to(self.velocity(t), t.shape).astype(t.dtype)
        a = np.broadcast_to(self.acceleration(t), t.shape).astype(t.dtype)
        return t, x, v, a


def stroke(
    kind: str, x0: float, length: float, w: float, variation: float, cycles: float
) -> RamMotion:
    """A ram's strokes out and back: x = x0 + length (1 - cos theta) / 2 with the phase
    theta = w t (kind "constant") or theta = w t + a sin(w t) (kind "varying", a =
    ``variation`` in [0, 1), so that theta keeps increasing). x runs from x0 to x0 + length
    and back once per period 2 pi / w, at rest at both ends."""
    a = variation if kind == "varying" else 0.0
    half = 0.5 * length

    def phase(t: np.ndarray) -> tuple:
        wt = w * inexact(t)
        return wt + a * np.sin(wt), w * (1.0 + a * np.cos(wt)), -a * w * w * np.sin(wt)

    def position(t: np.ndarray) -> np.ndarray:
        return x0 + half * (1.0 - np.cos(phase(t)[0]))

    def velocity(t: np.ndarray) -> np.ndarray:
        th, dth, _ = phase(t)
        return half * np.sin(th) * dth

    def acceleration(t: np.ndarray) -> np.ndarray:
        th, dth, ddth = phase(t)
        return half * (np.cos(th) * dth * dth + np.sin(th) * ddth)

    text = f"x = {x0:.4g} + {length:.4g} (1 - cos theta) / 2 m, theta = {w:.6g} t" + (
        f" + {a:g} sin({w:.6g} t)" if a else ""
    )
    return RamMotion(
        kind, position, velocity, acceleration, cycles * 2.0 * math.pi / w, float(cycles), text
    )

"""The independent references: the dyad's Newton-Euler system solved with NumPy and, for
ground truth, with mpmath (:mod:`.newton_euler`); the dyads' kinematics (positions, velocities,
accelerations and their derivatives along a seed of the inputs) with mpmath
(:mod:`.dyad_kinematics`); a whole mechanism FMU's outputs from its scene file, built on
those two (:mod:`.scene_mp`); the motor-driven mechanism as one ODE (:mod:`.machine`); a
mechanism with several drivers moved by given efforts, its motion integrated
(:mod:`.forward`).

``dyadfmu.reference.solve`` is :func:`.newton_euler.solve`, the NumPy reference of a batch
of dyads (``dyadfmu.solve`` is the C core's), and ``solve_mp`` its mpmath ground truth of
one dyad."""

from .newton_euler import solve, solve_mp

__all__ = ["solve", "solve_mp"]

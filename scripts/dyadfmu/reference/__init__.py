"""The independent references: the dyad's Newton-Euler system solved with NumPy and, for
ground truth, with mpmath (:mod:`.newton_euler`); the dyads' kinematics (positions, velocities,
accelerations and their derivatives along a seed of the inputs) with mpmath
(:mod:`.dyad_kinematics`); a whole mechanism FMU's outputs from its scene file, built on
those two (:mod:`.scene_mp`); the motor-driven mechanism as one ODE (:mod:`.machine`)."""

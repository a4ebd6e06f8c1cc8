"""The independent references: the dyad's Newton-Euler system solved with NumPy and, for
ground truth, with mpmath (:mod:`.newton_euler`); the motor-driven mechanism as one ODE
(:mod:`.machine`)."""

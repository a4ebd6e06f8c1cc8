"""Python harness of the planar Assur dyad project: mechanisms, references, FMUs through
fmpy, co-simulations, studies and reports."""

from .batch import Reactions, solve
from .plant import Trajectory, forward

__all__ = ["Reactions", "Trajectory", "forward", "solve"]

"""Python harness of the planar Assur dyad project: mechanisms, references, FMUs through
fmpy, co-simulations, studies and reports."""

from .batch import Reactions, solve
from .fmi.rows import Rows, run_table
from .plant import Trajectory, forward

__all__ = ["Reactions", "Rows", "Trajectory", "forward", "run_table", "solve"]

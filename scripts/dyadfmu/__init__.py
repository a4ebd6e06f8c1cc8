"""Python harness of the planar Assur dyad project: mechanisms, references, FMUs through
fmpy, co-simulations, studies and reports."""

from .batch import Reactions, solve
from .fmi.rows import Rows, run_table
from .mechanism_batch import Evaluation, evaluate
from .plant import Trajectory, forward

__all__ = [
    "Evaluation",
    "Reactions",
    "Rows",
    "Trajectory",
    "evaluate",
    "forward",
    "run_table",
    "solve",
]

"""Python harness of the planar Assur dyad project: mechanisms, references, FMUs through
fmpy, co-simulations, studies and reports."""

from .batch import Reactions, solve

__all__ = ["Reactions", "solve"]

"""Python helpers for the planar Assur dyad project (independent numerical reference in :mod:`dyadfmu.reference`)."""

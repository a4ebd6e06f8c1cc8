"""What the generator knows about the five dyad types: their pairs, which of their
lengths may be 0, and what conditions them."""

from __future__ import annotations

import math

#: Pair kinds at (D_m, E, D_n) of each type.
PAIRS = {"RRR": "RRR", "RRT": "TRR", "RTR": "RTR", "TRT": "TRT", "RTT": "TTR"}
TYPES = tuple(PAIRS)  # RRR, RRT, RTR, TRT, RTT

#: Whether the length of link m / n may be 0 (dyad_length_may_be_zero()).
MAY_BE_ZERO = {
    "RRR": (False, False),
    "RRT": (True, False),
    "RTR": (False, True),
    "TRT": (True, True),
    "RTT": (False, True),
}

#: Per type: the conditioning figure, where it vanishes, and a typical use.
TYPE_NOTES = {
    "RRR": (
        "|i_m . j_n|",
        "links m and n are aligned (E on the line D_m D_n)",
        "the coupler and rocker of a four-bar linkage",
    ),
    "RRT": (
        "|i_n . i_k|",
        "link n stands normal to the guide i_k",
        "the slider (m) and connecting rod (n) of a slider-crank",
    ),
    "RTR": (
        "min(|i_beta . i_m|, |D_m D_n| / (l_m + l_n)), i_beta = (l_m i_m - l_n i_n) / |D_m D_n|",
        "the slot of link m stands normal to the line D_m D_n, or D_m and D_n coincide",
        "the slotted lever (m) and the block (n) of a quick-return mechanism",
    ),
    "TRT": (
        "|j_k . i_p|",
        "the guides i_k and i_p are parallel",
        "two sliders on fixed guides pinned together at E",
    ),
    "RTT": (
        "|j_k . i_m|",
        "the slot i_m of link m is parallel to the guide i_k",
        "the yoke (m) and the block (n) of a Scotch yoke",
    ),
}

#: Per pair, the outputs a dyad offers: reactions always, normal force and
#: reactive moment where the pair is translational. (suffix, index into PAIRS[type])
PAIR_NAMES = (("mk", 0), ("np", 2), ("mn", 1))


def pair_label(pair: str) -> str:
    """The pair a reaction suffix names: mk -> D_m, np -> D_n, mn -> E."""
    return {"mk": "D_m", "np": "D_n", "mn": "E"}[pair]


#: Units: name -> exponents of the SI base units (FMI BaseUnit attributes).
UNITS = {
    "rad": {"rad": 1},
    "rad/s": {"s": -1, "rad": 1},
    "rad/s2": {"s": -2, "rad": 1},
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "kg": {"kg": 1},
    "kg.m": {"kg": 1, "m": 1},
    "kg.m2": {"kg": 1, "m": 2},
    "kg.m2/rad": {"kg": 1, "m": 2, "rad": -1},
    "kg/m": {"kg": 1, "m": -1},
    # a motor's (forward scenes' [motor])
    "s": {"s": 1},
    "A": {"A": 1},
    "V": {"kg": 1, "m": 2, "s": -3, "A": -1},
    "Ohm": {"kg": 1, "m": 2, "s": -3, "A": -2},
    "H": {"kg": 1, "m": 2, "s": -2, "A": -2},
    "N.m/A": {"kg": 1, "m": 2, "s": -2, "A": -1},
    "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1},
}
BASE_UNIT_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
#: The unit a simulator shows a variable in by default, and its factor: shown = factor *
#: value. Angles in degrees, angular speeds in revolutions per minute.
DISPLAY_UNITS = {"rad": ("deg", 180 / math.pi), "rad/s": ("rpm", 30 / math.pi)}

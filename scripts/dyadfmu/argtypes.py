"""argparse types shared by dyadfmu's commands: numbers checked for their range, each
message naming the value (argparse names the option)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

__all__ = ["whole", "real", "assignment"]


def whole(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: a decimal whole number from `low` to `high` (argparse names the
    option; the message names the value)."""

    def check(text: str) -> int:
        try:
            value = int(text, 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be from {low} to {high}, got {text}")
        return value

    return check


def real(low: float, high: float, above: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number from `low` (or `above` it) to `high`."""

    def check(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
        in_range = (low < value if above else low <= value) and value <= high
        if not (math.isfinite(value) and in_range):
            bounds = f"above {low:g} and at most" if above else f"from {low:g} to"
            raise argparse.ArgumentTypeError(f"must be a number {bounds} {high:g}, got {text}")
        return value

    return check


def assignment(text: str) -> tuple[str, float]:
    """An argparse type: NAME=VALUE, VALUE a finite number."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name}: not a number: {value!r}") from None
    if not math.isfinite(number):
        raise argparse.ArgumentTypeError(f"{name}: not a finite number: {value!r}")
    return name.strip(), number

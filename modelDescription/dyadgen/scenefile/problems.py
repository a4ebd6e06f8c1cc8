"""The problems of a scene, each with its file and line, and the checks of single values
every section parser shares."""

from __future__ import annotations

import math
from pathlib import Path

from dyadgen import textsafe
from dyadgen.scenefile.locator import Locator


class SceneError(Exception):
    """The scene is malformed; args[0] lists the problems."""


class Problems:
    """The problems found so far, as 'file:line: message'."""

    def __init__(self, path: Path, locator: Locator) -> None:
        self.path = path
        self.loc = locator
        self.items: list[str] = []
        #: (section, index) of every table with a problem: a later check skips what
        #: only follows from a value refused there (a tunable value that was refused)
        self.troubled: set[tuple[str, int]] = set()

    def where(self, section: str = "", index: int = 0, key: str | None = None) -> str:
        """file:line of a table or key; a table written as a plain key (scene = 1) is
        found as that key, and what has no line of its own (a table that is missing)
        is placed on line 1."""
        line = self.loc.line(section, index, key) if section else self.loc.line("", 0, key)
        if line is None and section:
            line = self.loc.line("", 0, section.split(".")[0])
        return f"{textsafe.plain(self.path.name)}:{line or 1}"

    def add(self, message: str, section: str = "", index: int = 0, key: str | None = None) -> None:
        """Record a problem of a table (the index-th of an array) or of one of its keys."""
        self.items.append(f"{self.where(section, index, key)}: {textsafe.plain(message)}")
        self.troubled.add((section, index))


def real(value: object) -> float | None:
    """A TOML number as a finite double, or None: not a number (a bool is none), not
    finite, or an integer beyond the range of a double."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def shown(value: object) -> str:
    """A value of the scene for a message, shortened (an integer of 400 digits stays
    readable)."""
    text = repr(value)
    return text if len(text) <= 60 else text[:40] + f"... ({len(text)} characters)"


def number(
    p: Problems,
    table: dict,
    key: str,
    where: str,
    sec: str,
    idx: int,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    required: bool = True,
) -> float | None:
    """The number `key` of a table, checked; None (and a problem) where it is not valid."""
    if key not in table:
        if required:
            p.add(f"{where}: missing parameter '{key}'", sec, idx)
        return None
    value = real(table[key])
    if value is None:
        p.add(
            f"{where}: '{key}' must be a finite number (within the range of a double), "
            f"not {shown(table[key])}",
            sec,
            idx,
            key,
        )
        return None
    if positive and not value > 0:
        p.add(f"{where}: '{key}' must be positive, not {shown(table[key])}", sec, idx, key)
        return None
    if nonnegative and not value >= 0:
        p.add(f"{where}: '{key}' must not be negative, not {shown(table[key])}", sec, idx, key)
        return None
    return value


def pair_of_numbers(
    p: Problems, table: dict, key: str, where: str, sec: str, idx: int, required: bool = True
) -> tuple[float, float] | None:
    """The point `key` ([x, y] in m) of a table, checked."""
    if key not in table:
        if required:
            p.add(f"{where}: missing parameter '{key}' ([x, y] in m)", sec, idx)
        return None
    value = table[key]
    if not isinstance(value, list) or len(value) != 2 or any(real(v) is None for v in value):
        p.add(
            f"{where}: '{key}' must be [x, y], two finite numbers (m), not {shown(value)}",
            sec,
            idx,
            key,
        )
        return None
    return real(value[0]), real(value[1])


def unknown_keys(p: Problems, table: dict, allowed: set, where: str, sec: str, idx: int) -> None:
    """A problem for every key of the table that is not `allowed`."""
    for key in table:
        if key not in allowed:
            p.add(
                f"{where}: unknown key '{key}' (expected one of {', '.join(sorted(allowed))})",
                sec,
                idx,
                key,
            )

"""Floating-point operations a program executes, counted from callgrind's per-instruction
counts (``--dump-instr=yes``) and the objects' disassembly (``objdump -d``).

An operation is an add, subtract, multiply, divide or square root of doubles: one per
scalar instruction (``addsd``, ``vmulsd``, ...), two per packed one (``mulpd``) and two
per fused multiply-add. Comparisons, minimum and maximum, negation and absolute value
(sign-bit masks), conversions and moves are not counted: the usual convention, under
which the closed forms' own counts (atop each type's file in ``src/``) are made.
"""

from __future__ import annotations

import re
import subprocess
from collections import Counter
from pathlib import Path

_SCALAR = re.compile(r"^v?(add|sub|mul|div|sqrt)sd$")
_PACKED = re.compile(r"^v?(add|sub|mul|div|sqrt)pd$")
_FUSED = re.compile(r"^vfn?m(add|sub)\d{3}[sp]d$")
_COST = re.compile(r"^(0x[0-9a-f]+|[+-]\d+|\*)\s+(\d+)$")


def operations_of(mnemonic: str) -> int:
    """Floating-point operations of one executed instruction of this mnemonic."""
    if _SCALAR.match(mnemonic):
        return 1
    if _PACKED.match(mnemonic) or _FUSED.match(mnemonic):
        return 2
    return 0


def mnemonics(obj: Path) -> dict[int, str]:
    """Address (as objdump prints it) to mnemonic, for every instruction of an object."""
    done = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", str(obj)], capture_output=True, text=True
    )
    table = {}
    for line in done.stdout.splitlines():
        parts = line.split("\t")
        if len(parts) >= 2 and parts[0].strip().endswith(":"):
            try:
                address = int(parts[0].strip()[:-1], 16)
            except ValueError:
                continue
            table[address] = parts[1].split()[0] if parts[1].split() else ""
    return table


def _next_position(token: str, last: int) -> int:
    if token == "*":
        return last
    if token[0] in "+-":
        return last + int(token)
    return int(token, 16)


def executed(callgrind_out: Path) -> dict[str, Counter]:
    """Executed instructions per object and address (exclusive counts) of a callgrind
    output written with ``--dump-instr=yes --dump-line=no``."""
    objects: dict[str, str] = {}
    counts: dict[str, Counter] = {}
    current, position, skip_next = "", 0, False
    for raw in callgrind_out.read_text().splitlines():
        line = raw.strip()
        named = re.match(r"c?ob=\((\d+)\)\s*(.*)", line)
        if named:
            if named.group(2):  # an object is named where it first appears
                objects[named.group(1)] = named.group(2)
            if line.startswith("ob="):
                current = objects.get(named.group(1), "")
            continue
        if line.startswith("calls="):
            skip_next = True
            continue
        match = _COST.match(line)
        if not match:
            continue
        position = _next_position(match.group(1), position)
        if skip_next:  # the inclusive cost of a call, not this instruction's own
            skip_next = False
            continue
        counts.setdefault(current, Counter())[position] += int(match.group(2))
    return counts


def operations(callgrind_out: Path) -> int:
    """Floating-point operations executed in all objects of a callgrind output."""
    total = 0
    for obj, per_address in executed(callgrind_out).items():
        if not obj or not Path(obj).is_file():
            continue
        table = mnemonics(Path(obj))
        total += sum(n * operations_of(table.get(a, "")) for a, n in per_address.items())
    return total

"""Instructions and estimated cycles per tick of a Cortex-M4F tick program, from QEMU's
trace of every instruction it executed (``-singlestep -d exec,nochain``: a translation
block per instruction, each logged with its address when it runs).

QEMU counts instructions, not cycles: it models no pipeline. The cycles are an estimate
from the instruction mix, each instruction at the count the Cortex-M4 Technical Reference
Manual (ARM DDI 0439, "Processor instruction timings", and the FPU's table) gives for it:
one cycle for the data processing instructions, two for a single load or store, 1 + N for
a load or store of N registers, 14 for ``vdiv.f32`` and ``vsqrt.f32``, 3 for the
multiply-accumulates, 2 to 12 for an integer division (taken as 12), and for a branch
taken (or any instruction that writes the PC) a pipeline refill of 3 more (the table's
1 to 3, taken at its worst). Memory is taken as zero-wait (code and data in SRAM, or
flash behind an accelerator that hits), so the estimate is an upper bound for such a
part's core and says nothing of wait states.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .ticks import EmbeddedError

__all__ = ["TickCost", "Instruction", "disassemble", "symbols", "tick_costs", "cycles_of"]

OBJDUMP = "arm-none-eabi-objdump"
NM = "arm-none-eabi-nm"
#: the refill of a taken branch (the table's P, 1 to 3), taken at its worst
REFILL = 3
_CONDITIONS = {
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le",
}  # fmt: skip
_BRANCHES = {"b", "bl", "bx", "blx", "cbz", "cbnz", "tbb", "tbh"}
_MULTIPLY_ACCUMULATE = {"vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"}
_LINE = re.compile(r"^\s*([0-9a-f]+):\s+((?:[0-9a-f]{4}\s?)+)\s+(\S+)\s*([^;@]*)")
_TRACE_PC = re.compile(rb"\[[0-9a-f]+/([0-9a-f]+)/")


@dataclass(frozen=True)
class Instruction:
    """One instruction of the program's code: its size (bytes) and cycle count when it
    does not change the flow (`branch`: when it does, REFILL more)."""

    size: int
    cycles: int
    branch: bool
    mnemonic: str


def _registers(operands: str) -> int:
    """The registers a register list names ({r4-r7, lr}: 5; d registers count twice)."""
    inside = operands[operands.find("{") + 1 : operands.find("}")]
    count = 0
    for part in filter(None, (p.strip() for p in inside.split(","))):
        width = 2 if part.startswith("d") else 1
        if "-" in part:
            low, high = (int(re.sub(r"\D", "", r)) for r in part.split("-"))
            count += (high - low + 1) * width
        else:
            count += width
    return max(count, 1)


def cycles_of(mnemonic: str, operands: str) -> tuple[int, bool]:
    """(cycles without a refill, whether it can change the flow) of an instruction."""
    m = mnemonic.lower().split(".")[0]
    writes_pc = bool(re.search(r"\bpc\b", operands.split(",")[0])) or "pc}" in operands
    if m.startswith("v"):
        if m in ("vdiv", "vsqrt"):
            return 14, False
        if m in _MULTIPLY_ACCUMULATE:
            return 3, False
        if m in ("vldr", "vstr"):
            return 2, False
        if m.startswith(("vpush", "vpop", "vldm", "vstm")):
            return 1 + _registers(operands), False
        return 1, False
    if m in _BRANCHES or (m[:1] == "b" and m[1:] in _CONDITIONS):
        return 1 + (m in ("tbb", "tbh")), True
    if m in ("sdiv", "udiv"):
        return 12, False
    if m in ("mla", "mls"):
        return 2, False
    if m.startswith(("push", "pop", "ldm", "stm")):
        return 1 + _registers(operands), writes_pc
    if m in ("ldrd", "strd"):
        return 3, False
    if m.startswith(("ldr", "str")):
        return 2, writes_pc and m.startswith("ldr")
    return 1, writes_pc and m.startswith(("mov", "add", "sub"))


def disassemble(elf: Path) -> dict[int, Instruction]:
    """Every instruction of the ELF's code by address."""
    text = _tool([OBJDUMP, "-d", str(elf)])
    code = {}
    for line in text.splitlines():
        match = _LINE.match(line)
        if not match or match.group(3).startswith("."):  # .word: a literal pool's data
            continue
        raw = match.group(2).split()
        cycles, branch = cycles_of(match.group(3), match.group(4))
        code[int(match.group(1), 16)] = Instruction(2 * len(raw), cycles, branch, match.group(3))
    return code


def symbols(elf: Path) -> dict[str, tuple[int, int]]:
    """Each function's (address, size) in the ELF (the Thumb bit cleared)."""
    out = {}
    for line in _tool([NM, "-S", "--defined-only", str(elf)]).splitlines():
        words = line.split()
        if len(words) == 4 and words[2].lower() == "t":
            out[words[3]] = (int(words[0], 16) & ~1, int(words[1], 16))
    return out


def _tool(command: list[str]) -> str:
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise EmbeddedError(f"{' '.join(command)} failed: {done.stderr.strip()}")
    return done.stdout


@dataclass(frozen=True)
class TickCost:
    """One tick's evaluation on the M4F: instructions QEMU executed, cycles estimated,
    and of those instructions the ones in software floating point (libgcc's __aeabi_d*,
    __aeabi_f2d and the like: double arithmetic the M4F's FPU cannot do)."""

    instructions: int
    cycles: int
    soft_float: int


def _pcs(trace: Path) -> np.ndarray:
    data = trace.read_bytes()
    return np.array([int(m, 16) for m in _TRACE_PC.findall(data)], dtype=np.int64)


#: libgcc's software double: what a float build must never run
_SOFT_DOUBLE = ("__aeabi_d", "__aeabi_f2d", "__adddf3", "__muldf3", "__divdf3", "__subdf3")


def _ranges(names: dict[str, tuple[int, int]], prefixes: tuple) -> list[tuple[int, int]]:
    return [(a, a + s) for n, (a, s) in names.items() if n.startswith(prefixes)]


def _inside(pcs: np.ndarray, ranges: list[tuple[int, int]]) -> np.ndarray:
    hit = np.zeros(len(pcs), dtype=bool)
    for low, high in ranges:
        hit |= (pcs >= low) & (pcs < high)
    return hit


def tick_costs(elf: Path, trace: Path) -> list[TickCost]:
    """The cost of each traced tick: from the call of ticks_begin to that of ticks_end,
    less ticks_begin's own instructions (the tick program's few instructions of the
    call of <id>_evaluate stay in)."""
    names = symbols(elf)
    code = disassemble(elf)
    pcs = _pcs(trace)
    begin, end = names["ticks_begin"], names["ticks_end"]
    starts = np.flatnonzero(pcs == begin[0])
    ends = np.flatnonzero(pcs == end[0])
    soft = _ranges(names, _SOFT_DOUBLE)
    costs = []
    for s, e in zip(starts, ends, strict=False):
        keep = ~_inside(pcs[s:e], [(begin[0], begin[0] + begin[1])])
        costs.append(_cost(pcs[s:e][keep], pcs[s + 1 : e + 1][keep], code, soft))
    if not costs:
        raise EmbeddedError(f"{trace}: no tick between ticks_begin and ticks_end")
    return costs


def _cost(tick: np.ndarray, following: np.ndarray, code: dict, soft: list) -> TickCost:
    cycles = 0
    for pc, after in zip(tick.tolist(), following.tolist(), strict=True):
        op = code.get(pc)
        if op is None:
            raise EmbeddedError(f"the trace ran an instruction at {pc:#x} the ELF does not hold")
        cycles += op.cycles + (REFILL if op.branch and after != pc + op.size else 0)
    return TickCost(len(tick), cycles, int(_inside(tick, soft).sum()))

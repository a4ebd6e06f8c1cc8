"""The deepest stack a function can reach, from GCC's call graph with each function's own
frame (``-fcallgraph-info=su``: a ``.ci`` file per object, in the VCG format).

The bound is the costliest chain of calls from the function down through the functions the
objects define, each frame as GCC gives it. A call into a function no object defines (the
C library's: ``atan2f``, ``snprintf``, libgcc's helpers) adds a frame the graph does not
know; those are named beside the bound, which leaves them out. A frame of dynamic size
that GCC cannot bound, or a call chain that comes back to itself, makes the bound
unknown (None).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["StackBound", "read_graph", "deepest"]

_NODE = re.compile(r'^node: \{ title: "([^"]+)" label: "([^"]*)"')
_EDGE = re.compile(r'^edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
_FRAME = re.compile(r"\\n(\d+) bytes \(([a-z,]+)\)")


@dataclass(frozen=True)
class StackBound:
    """The deepest chain from a function: its bytes (None where unbounded), the functions
    on it, and the outside functions called anywhere below it, whose frames are not in."""

    bytes: int | None
    chain: tuple[str, ...]
    outside: tuple[str, ...]


def _name(title: str) -> str:
    """A node's function name: a static function's title is 'file:name'."""
    return title.rsplit(":", 1)[-1].split(".")[0]


def read_graph(ci_files: list[Path]) -> tuple[dict[str, int | None], dict[str, set[str]]]:
    """(each defined function's frame in bytes, None where unbounded; its callees), by title,
    over every .ci file."""
    frames: dict[str, int | None] = {}
    calls: dict[str, set[str]] = {}
    for path in ci_files:
        for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
            node = _NODE.match(line)
            if node:
                frame = _FRAME.search(node.group(2))
                if frame:
                    bounded = frame.group(2) in ("static", "dynamic,bounded")
                    frames[node.group(1)] = int(frame.group(1)) if bounded else None
                continue
            edge = _EDGE.match(line)
            if edge:
                calls.setdefault(edge.group(1), set()).add(edge.group(2))
    return frames, calls


def deepest(ci_files: list[Path], root: str) -> StackBound:
    """The StackBound of the function named `root` (a global function)."""
    frames, calls = read_graph(ci_files)
    memo: dict[str, tuple[int | None, tuple[str, ...]]] = {}
    outside: set[str] = set()

    def walk(title: str, seen: frozenset) -> tuple[int | None, tuple[str, ...]]:
        if title in seen:
            return None, (_name(title),)  # recursion: no bound
        if title in memo:
            return memo[title]
        own = frames[title]
        best: tuple[int | None, tuple[str, ...]] = (0, ())
        for callee in sorted(calls.get(title, ())):
            if callee not in frames:
                outside.add(_name(callee))
                continue
            below = walk(callee, seen | {title})
            if below[0] is None or (best[0] is not None and below[0] > best[0]):
                best = below
        total = None if own is None or best[0] is None else own + best[0]
        memo[title] = (total, (_name(title), *best[1]))
        return memo[title]

    if root not in frames:
        raise KeyError(f"{root} is not in the call graph")
    total, chain = walk(root, frozenset())
    return StackBound(total, chain, tuple(sorted(outside)))

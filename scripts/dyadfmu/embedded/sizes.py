"""Flash and RAM of a Cortex-M4F firmware by whom they are for, from the linker's map:
the scene and the core (the bundle's objects), the C library, libm and libgcc they pull
in, and the tick program with its start-up (the port), which a real firmware replaces.

Flash is what the part stores: code and read-only data (the output section ``.text``),
the unwinding index and the initial values of ``.data``; RAM is ``.data`` and ``.bss``,
the stack apart (measured by painting, m4f_start.c).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Sizes", "read_map"]

_OUTPUT = re.compile(r"^(\.[\w.]+)")
_INPUT = re.compile(r"^ (\.[\w.]+|COMMON)\s*(?:0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*))?$")
_PLACED = re.compile(r"^\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
_FLASH = {".text", ".ARM.exidx", ".data"}
_RAM = {".data", ".bss"}


@dataclass
class Sizes:
    """Bytes of flash and RAM per owner: "scene" (the scene's and the core's objects),
    "libraries" (libc, libm, libgcc), "port" (the tick program and its start-up)."""

    flash: dict = field(default_factory=lambda: {"scene": 0, "libraries": 0, "port": 0})
    ram: dict = field(default_factory=lambda: {"scene": 0, "libraries": 0, "port": 0})
    #: the library members linked in (archive(member)), for the report
    members: set = field(default_factory=set)


def _owner(path: str, scene_objects: tuple[str, ...]) -> str:
    if path.endswith(")") and ".a(" in path:
        return "libraries"
    return "scene" if Path(path).stem in scene_objects else "port"


def _add(sizes: Sizes, output: str, size: int, path: str, scene_objects: tuple) -> None:
    owner = _owner(path, scene_objects)
    if owner == "libraries":
        sizes.members.add(Path(path).name)
    if output in _FLASH:
        sizes.flash[owner] += size
    if output in _RAM:
        sizes.ram[owner] += size


def read_map(map_file: Path, scene_objects: tuple[str, ...]) -> Sizes:
    """The Sizes of a link from its map (GNU ld -Map)."""
    sizes = Sizes()
    lines = map_file.read_text(encoding="utf-8", errors="replace").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Linker script and memory"))
    output, pending = "", False
    for line in lines[start:]:
        match = _OUTPUT.match(line)
        if match:
            output, pending = match.group(1), False
            continue
        match = _INPUT.match(line)
        if match:  # an input section: placed on this line, or on the next one
            pending = not match.group(2)
            if match.group(2):
                _add(sizes, output, int(match.group(3), 16), match.group(4), scene_objects)
            continue
        placed = _PLACED.match(line) if pending else None
        if placed:
            _add(sizes, output, int(placed.group(2), 16), placed.group(3), scene_objects)
        pending = False
    return sizes

"""The identifiers of the FMUs the build always makes (fmu/CMakeLists.txt): every scene in
modelDescription/scenes/, the test scenes in tests/scenes/ and the variable tables written by hand
(the drive and the motor). A scene of another file may not take one: a build with both would define
the CMake targets <identifier>_fmi2 and _fmi3 twice. Read from the files themselves,
once per process."""

from __future__ import annotations

import tomllib
from pathlib import Path

from dyadgen.locations import HAND_TABLES, INTERFACE_DIR, SCENES_DIR, TEST_SCENES_DIR

_FOUND: list = []


def _identifier(path: Path, table: str) -> str | None:
    """The identifier in [table] of a file, None where it has none (or cannot be read)."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return None
    section = data.get(table)
    identifier = section.get("identifier") if isinstance(section, dict) else None
    return identifier if isinstance(identifier, str) else None


def _files() -> list[tuple[Path, str]]:
    """(file, the table holding its identifier) of every FMU the build always makes."""
    scenes = sorted(SCENES_DIR.glob("*.toml")) + sorted(TEST_SCENES_DIR.glob("*.toml"))
    tables = [INTERFACE_DIR / name for name in HAND_TABLES]
    return [(p, "scene") for p in scenes] + [(p, "model") for p in tables]


def builtin_identifiers() -> dict[str, Path]:
    """Identifier -> the file it comes from, of every FMU the build always makes."""
    if not _FOUND:
        found: dict[str, Path] = {}
        for path, table in _files():
            identifier = _identifier(path, table)
            if identifier is not None:
                found.setdefault(identifier, path.resolve())
        _FOUND.append(found)
    return _FOUND[0]


def is_builtin(path: Path, identifier: str) -> bool:
    """Whether `path` is the built-in file that `identifier` names
    (modelDescription/scenes/press.toml for 'press'): the one file that may use a built-in
    identifier."""
    return builtin_identifiers().get(identifier) == Path(path).resolve()

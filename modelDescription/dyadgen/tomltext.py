"""Untrusted TOML files read within bounds: at most MAX_BYTES of them (a device such as
/dev/zero or a huge file is refused, not read to its end), UTF-8 with or without a byte
order mark, and values nested at most MAX_NESTING deep (tomllib would otherwise recurse
until Python gives up). Every refusal says where: the line where known.

dyadfmu's study files (scripts/dyadfmu/sweep/studyfile.py) keep the same limits; that
package does not import the generator, so the two are kept parallel."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

__all__ = ["MAX_BYTES", "MAX_NESTING", "TomlTextError", "read_toml", "too_deep_line"]

#: The largest file read (the limit of a study file too).
MAX_BYTES = 1_000_000
#: The deepest nesting of arrays and tables in a value (a scene needs 5).
MAX_NESTING = 32
_STRING = re.compile(
    r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*|\Z'
)


class TomlTextError(ValueError):
    """The file cannot be read as TOML: args are (line or None, message)."""

    @property
    def line(self) -> int | None:
        """The line of the problem, None where it has none."""
        return self.args[0]

    @property
    def message(self) -> str:
        """What is wrong."""
        return self.args[1]


def _read_bytes(path: Path) -> bytes:
    """At most MAX_BYTES of the file (one byte more tells that it is larger)."""
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise TomlTextError(None, f"cannot read: {exc.strerror}") from None
    if len(raw) > MAX_BYTES:
        raise TomlTextError(None, f"larger than {MAX_BYTES} bytes: not read")
    return raw


def _decode(raw: bytes) -> str:
    """The text, UTF-8 (a leading byte order mark is dropped)."""
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise TomlTextError(line, f"not UTF-8 text (byte {exc.start + 1})") from None


def too_deep_line(text: str, limit: int = MAX_NESTING) -> int | None:
    """The line where arrays and inline tables first nest deeper than `limit`, strings and
    comments skipped (the pattern's last branch, the end, scans the rest); None where
    they never do."""
    depth, line, pos = 0, 1, 0
    for found in _STRING.finditer(text):
        for ch in text[pos : found.start()]:
            line += ch == "\n"
            depth += (ch in "[{") - (ch in "]}")
            if depth > limit:
                return line
        line += found.group().count("\n")
        pos = found.end()
    return None


def _parse(text: str) -> dict:
    deep = too_deep_line(text)
    if deep is not None:
        raise TomlTextError(deep, f"arrays or tables nested more than {MAX_NESTING} deep")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = re.search(r"at line (\d+)", str(exc))
        raise TomlTextError(int(line.group(1)) if line else None, f"invalid TOML: {exc}") from None
    except RecursionError:  # not reached within MAX_NESTING; kept as the last guard
        raise TomlTextError(None, "arrays or tables nested too deeply") from None


def read_toml(path: Path) -> tuple[str, dict]:
    """The text of a TOML file and its data; TomlTextError where it cannot be read."""
    text = _decode(_read_bytes(Path(path)))
    return text, _parse(text)

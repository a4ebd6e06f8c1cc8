"""Where things are in a scene file: the line of every table and key, for messages."""

from __future__ import annotations

import re
import tomllib


class Locator:
    """Line numbers of tables and keys in a TOML text, for messages. The text is read as
    TOML reads it: strings (basic, literal, multi-line) and comments are skipped, so that a
    '[' or '#' inside a string moves nothing, and quoted keys and headers are decoded."""

    BARE = re.compile(r"[A-Za-z0-9_-]+")
    STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')

    def __init__(self, text: str):
        self.tables: dict[tuple[str, int], int] = {}
        self.keys: dict[tuple[str, int, str], int] = {}
        self._counts: dict[str, int] = {}
        self._section, self._index = "", 0
        depth = 0  # inside a multi-line array or inline table
        closing = None  # the closing quotes of an open multi-line string
        # TOML ends lines at LF only (str.splitlines would split at U+2028 and others too)
        for number, line in enumerate(text.split("\n"), start=1):
            line = line.removesuffix("\r")
            pos = 0
            if closing:
                end = line.find(closing)
                if end < 0:
                    continue
                pos, closing = end + 3, None
            if depth == 0 and pos == 0:
                pos = self._statement(line, number)
            depth, closing = self._scan(line, pos, depth)

    def _key(self, line: str, pos: int) -> tuple[list[str], int]:
        """The parts of the (dotted) key at `pos`, and where it ends; no parts if none."""
        parts = []
        while True:
            while pos < len(line) and line[pos] in " \t":
                pos += 1
            bare = self.BARE.match(line, pos)
            quoted = self.STRING.match(line, pos)
            if quoted:
                try:
                    parts.append(next(iter(tomllib.loads(quoted.group(0) + " = 0"))))
                except tomllib.TOMLDecodeError:
                    return [], pos
                pos = quoted.end()
            elif bare:
                parts.append(bare.group(0))
                pos = bare.end()
            else:
                return [], pos
            while pos < len(line) and line[pos] in " \t":
                pos += 1
            if not line.startswith(".", pos):
                return parts, pos
            pos += 1

    def _statement(self, line: str, number: int) -> int:
        """Record a table header or a key that starts `line`; where the value starts."""
        pos = len(line) - len(line.lstrip(" \t"))
        if line.startswith("[", pos):
            array = line.startswith("[[", pos)
            parts, end = self._key(line, pos + (2 if array else 1))
            if parts:
                section = ".".join(parts)
                if array:
                    self._index = self._counts.get(section, -1) + 1
                    self._counts[section] = self._index
                else:
                    self._index = 0
                self._section = section
                self.tables.setdefault((section, self._index), number)
            return len(line)
        parts, end = self._key(line, pos)
        if parts and line.startswith("=", end):
            self.keys.setdefault((self._section, self._index, parts[0]), number)
            return end + 1
        return len(line)

    @staticmethod
    def _scan(line: str, pos: int, depth: int) -> tuple[int, str | None]:
        """The bracket depth after a line's value from `pos`, and the closing quotes of a
        multi-line string the line leaves open."""
        while pos < len(line):
            ch = line[pos]
            if ch == "#":
                break
            if ch in "\"'":
                triple = ch * 3
                if line.startswith(triple, pos):
                    end = line.find(triple, pos + 3)
                    if end < 0:
                        return depth, triple
                    pos = end + 3
                    continue
                pos += 1
                while pos < len(line) and line[pos] != ch:
                    pos += 2 if ch == '"' and line[pos] == "\\" else 1
            elif ch in "[{":
                depth += 1
            elif ch in "]}":
                depth = max(depth - 1, 0)
            pos += 1
        return depth, None

    def line(self, section: str, index: int = 0, key: str | None = None) -> int | None:
        """The line of a key of a table (the index-th of an array of tables), or of the
        table itself; None where neither is written."""
        if key is not None and (section, index, key) in self.keys:
            return self.keys[(section, index, key)]
        return self.tables.get((section, index))

"""Markdown as the reports write it. Every string the project does not write itself (a
study's description, a name from a scene or study file or a file name, a unit or a
variable name from an FMU, an FMU's message, a measured figure) reaches a report through
:func:`text`, which makes it one line of literal text, the same in a paragraph, a heading
and a table cell; :func:`table` writes a table whose cells go through :func:`text` unless
they are :class:`Markup`, Markdown the project wrote itself.

    text(value)           literal text: one line, every markup character escaped
    code(value)           a code span where the value can be one, else text(value)
    image(alt, target)    an image of a file beside the report
    table(header, rows)   a table as lines, the same number of cells in every row
    provenance(command)   the line under a report's title: when, on what, by which command

As in the scene generator's escaping (modelDescription/dyadgen/textsafe.py), a character
that is not shown as itself (a control, format, bidi, private-use, unassigned or
separator character: a newline, a tab, an escape sequence) is written visibly as
<U+XXXX>, so that no text breaks a table row or a paragraph, or hides.

What :func:`text` escapes, for CommonMark with GitHub's extensions (tables,
strikethrough, mathematics between dollars): the characters that mark up text anywhere in
a line (backslash, backtick, ``*``, ``_``, brackets, ``|``, ``~``, ``$``, ``#``) with a
backslash; ``&``, ``<`` and ``>`` (entities, HTML, autolinks, quotes) as entities, which
every Markdown renderer reads; and what starts a block at the start of a line (a list
item, a rule, a setext underline).
"""

from __future__ import annotations

import datetime
import os
import platform
import re
import unicodedata
from collections.abc import Iterable, Sequence
from urllib.parse import quote

__all__ = ["Markup", "code", "hidden", "image", "machine", "provenance", "table", "text"]

#: Unicode categories of characters not shown as themselves (as in textsafe.py).
HIDDEN_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})

#: Characters escaped with a backslash wherever they are (CommonMark allows a backslash
#: before any ASCII punctuation).
_BACKSLASHED = frozenset("\\`*_[]|~$#")
#: Characters written as entities: a backslash before them is not an escape to every
#: renderer, an entity is.
_ENTITIES = {"&": "&amp;", "<": "&lt;", ">": "&gt;"}
#: What starts a block at the start of a line: a bullet list item ("- x", "+ x"), an
#: ordered one ("1. x", "2) x"), a thematic break or a setext underline ("---", "= =").
_LIST_ITEM = re.compile(r"[-+](?=\s|$)")
_ORDERED_ITEM = re.compile(r"^(\d{1,9})([.)])(?=\s|$)")
_RULE = re.compile(r"[-=][-=\s]*")

#: Alignment of a table column: none, left, right, centre.
_DELIMITERS = {"-": "---", "l": ":---", "r": "---:", "c": ":---:"}


class Markup(str):
    """Markdown the project wrote itself (or :func:`text` made safe): written as it is."""

    __slots__ = ()


def hidden(ch: str) -> bool:
    """Whether a character is not shown as itself (see HIDDEN_CATEGORIES)."""
    return unicodedata.category(ch) in HIDDEN_CATEGORIES


def _escaped(ch: str) -> str:
    if hidden(ch):
        return f"&lt;U+{ord(ch):04X}&gt;"
    if ch in _ENTITIES:
        return _ENTITIES[ch]
    return "\\" + ch if ch in _BACKSLASHED else ch


def text(value: object) -> Markup:
    """`value` (str() of it) as literal Markdown text on one line: shown as it is in a
    paragraph, a heading or a table cell, with hidden characters as <U+XXXX> and the
    spaces at either end dropped. Markup is returned unchanged."""
    if isinstance(value, Markup):
        return value
    raw = str(value).strip(" ")
    out = "".join(_escaped(ch) for ch in raw)
    if _LIST_ITEM.match(out) or _RULE.fullmatch(out):
        out = "\\" + out
    else:
        out = _ORDERED_ITEM.sub(r"\1\\\2", out, count=1)
    return Markup(out)


def code(value: object) -> Markup:
    """`value` as a code span, where one can carry it literally both in a paragraph and
    in a table cell (no backtick, no '|', no hidden character, no space at either end);
    else as :func:`text`."""
    raw = str(value)
    plain = raw and raw == raw.strip() and not any(ch in "`|" or hidden(ch) for ch in raw)
    return Markup(f"`{raw}`") if plain else text(raw)


def image(alt: object, target: str) -> Markup:
    """An image of the file `target` (a path relative to the report), `alt` its text."""
    return Markup(f"![{text(alt)}]({quote(target)})")


def _cell(value: object) -> str:
    """A table cell: text(value); Markup that would end the row is refused."""
    cell = text(value)
    if "\n" in cell or "\r" in cell:
        raise ValueError(f"a Markdown table cell must be one line: {cell!r}")
    return cell


def table(
    header: Sequence[object], rows: Iterable[Sequence[object]], align: str = ""
) -> list[Markup]:
    """A table as lines: `header`, the delimiter row, then `rows`; every cell goes
    through :func:`text` (Markup as it is). `align` has one letter per column: '-' none
    (the default), 'l' left, 'r' right, 'c' centre. A row whose length is not the
    header's is refused (ValueError), as is an empty header."""
    width = len(header)
    if width == 0:
        raise ValueError("a Markdown table needs at least one column")
    align = align or "-" * width
    if len(align) != width or any(a not in _DELIMITERS for a in align):
        raise ValueError(f"align {align!r}: one of '-lrc' per column, {width} columns")
    lines = [Markup("| " + " | ".join(map(_cell, header)) + " |")]
    lines.append(Markup("|" + "|".join(_DELIMITERS[a] for a in align) + "|"))
    for k, row in enumerate(rows, start=1):
        if len(row) != width:
            raise ValueError(f"Markdown table row {k} has {len(row)} cells, its header {width}")
        lines.append(Markup("| " + " | ".join(map(_cell, row)) + " |"))
    return lines


def machine() -> str:
    """This machine as a report names it: its processor, cores, system and Python."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}, "
        f"Python {platform.python_version()}"
    )


def provenance(command: str) -> Markup:
    """The line under a report's title: when (UTC), on which machine and by which command
    its figures were measured, so that a figure quoted elsewhere can be traced and
    measured again."""
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return Markup(f"Measured {now} on {text(machine())} by {code(command)}.")

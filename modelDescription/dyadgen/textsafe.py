"""Text a user wrote (a scene's description, its file name) on its way into generated
files: the rule a description must satisfy, and one escaping function per target
language. Every user string that reaches a generated file goes through exactly one of
them; nothing is pasted raw.

    c_comment(text)      inside a C block comment  /* ... */
    c_string(text)       a C string literal, quotes included
    xml_attribute(text)  an XML attribute value between double quotes
    xml_comment(text)    inside an XML comment  <!-- ... -->
    html(text)           HTML text or a double-quoted attribute value
    plain(text)          one line for a terminal or a log (error messages)

A character that is not shown as itself (a control, format, bidi, private-use,
unassigned or separator character) is written visibly as <U+XXXX> wherever the target
cannot carry it safely, so that no invisible character reorders or hides generated
text.

Python 3.11 standard library only.
"""

from __future__ import annotations

import html as _html
import re
import unicodedata

#: Unicode categories of characters that are not shown as themselves: controls (Cc),
#: format characters (Cf: bidi controls, zero-width characters, the soft hyphen),
#: surrogates (Cs), private use (Co), unassigned (Cn), line and paragraph separators.
HIDDEN_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})

#: The trigraphs' third characters: "??/" is a backslash to a C compiler in strict
#: ISO mode (-std=c99), and a backslash before a newline joins two lines.
_TRIGRAPH = re.compile(r"\?\?(?=[=(/)'<!>-])")
#: Text that needs no escaping in an XML attribute (most text, and all of a long
#: dependency list): printable ASCII without markup characters.
_XML_PLAIN = re.compile(r"[ !#-%'-;=?-~]*")


def hidden(ch: str) -> bool:
    """Whether a character is not shown as itself (see HIDDEN_CATEGORIES)."""
    return unicodedata.category(ch) in HIDDEN_CATEGORIES


def shown(ch: str) -> str:
    """A character as visible text: <U+XXXX>."""
    return f"<U+{ord(ch):04X}>"


def _char_name(ch: str) -> str:
    name = unicodedata.name(ch, "")
    return f"{shown(ch)} ({name})" if name else shown(ch)


def description_problem(text: object) -> str | None:
    """Why `text` is not a valid description, or None. A description is one non-empty line
    of printable text: no control characters (U+0000-U+001F, U+007F-U+009F, tab and newline
    included), no format or bidi characters (U+202A-U+202E, U+2066-U+2069, U+200E, U+200F,
    U+061C, ...), no line or paragraph separator, and no '*/'."""
    if not isinstance(text, str):
        return f"must be a string, not {type(text).__name__}"
    if not text.strip():
        return "must be one non-empty line"
    for position, ch in enumerate(text, start=1):
        if hidden(ch):
            what = (
                "a line break"
                if ch in "\n\r\u2028\u2029\x85\x0b\x0c"
                else "a control character"
                if unicodedata.category(ch) == "Cc"
                else "a bidi or format character"
                if unicodedata.category(ch) == "Cf"
                else "not printable text"
            )
            return (
                f"has {what}, {_char_name(ch)}, at character {position}; a description is "
                "one line of printable text"
            )
    if "*/" in text:
        return "must not contain '*/' (it is copied into a C comment, which '*/' would end)"
    return None


def c_comment(text: str) -> str:
    """`text` for the inside of a C block comment: it cannot end the comment ('*/'),
    open a nested one ('/*', which -Wcomment rejects), join the next line (a backslash,
    or the trigraph '??/') or hide characters. Backslashes and hidden characters are
    written <U+XXXX>; '*' and '/' that touch are parted by a space."""
    out = []
    for ch in text:
        out.append(shown(ch) if ch == "\\" or hidden(ch) else ch)
    safe = _TRIGRAPH.sub("?" + shown("?"), "".join(out))
    safe = re.sub(r"\*(?=/)", "* ", safe)
    return re.sub(r"/(?=\*)", "/ ", safe)


def c_string(text: str) -> str:
    """`text` as a C string literal (quotes included) holding its UTF-8 bytes: printable
    ASCII as itself, '\\', '"' and '?' (no trigraph can form) escaped, every other byte
    as a three-digit octal escape."""
    out = []
    for byte in text.encode("utf-8"):
        ch = chr(byte)
        if ch in '\\"?':
            out.append("\\" + ch)
        elif 0x20 <= byte < 0x7F:
            out.append(ch)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def _xml_char(ch: str) -> bool:
    """The XML 1.0 Char production."""
    c = ord(ch)
    return (
        c in (0x9, 0xA, 0xD)
        or 0x20 <= c <= 0xD7FF
        or 0xE000 <= c <= 0xFFFD
        or 0x10000 <= c <= 0x10FFFF
    )


def xml_attribute(text: object) -> str:
    """`text` for an XML attribute value in double quotes: markup characters as entities,
    hidden characters XML allows as character references (so that the value reads back
    unchanged, tab and newline included), characters XML cannot carry at all as
    <U+XXXX>."""
    text = str(text)
    if _XML_PLAIN.fullmatch(text):
        return text
    out = []
    for ch in text:
        if ch == "&":
            out.append("&amp;")
        elif ch == "<":
            out.append("&lt;")
        elif ch == ">":
            out.append("&gt;")
        elif ch == '"':
            out.append("&quot;")
        elif not _xml_char(ch):
            out.append(f"&lt;U+{ord(ch):04X}&gt;")
        elif hidden(ch):
            out.append(f"&#{ord(ch)};")
        else:
            out.append(ch)
    return "".join(out)


def xml_comment(text: str) -> str:
    """`text` for the inside of an XML comment, which has no escapes: '--' may not occur
    in a comment, nor '-' at its end, so dashes that touch are parted by a space and a
    dash at either end of `text` gets a space outside it; hidden characters as
    <U+XXXX>."""
    safe = "".join(shown(ch) if hidden(ch) or not _xml_char(ch) else ch for ch in text)
    safe = re.sub(r"-(?=-)", "- ", safe)
    if safe.startswith("-"):
        safe = " " + safe
    if safe.endswith("-"):
        safe += " "
    return safe


def html(text: object) -> str:
    """`text` for HTML text or a double-quoted attribute value: markup characters as
    entities, hidden characters as visible <U+XXXX>."""
    return _html.escape("".join(shown(ch) if hidden(ch) else ch for ch in str(text)), quote=True)


def plain(text: object) -> str:
    """`text` as one line for a terminal or a log: hidden characters (escape sequences,
    newlines, bidi controls) as <U+XXXX>."""
    return "".join(shown(ch) if hidden(ch) else ch for ch in str(text))

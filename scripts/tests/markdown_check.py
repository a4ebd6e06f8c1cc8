"""A written report read back with a Markdown parser (markdown-it-py: CommonMark with
GitHub's tables and strikethrough, HTML allowed as GitHub allows it): every line that
starts with '|' belongs to a table the parser found, and every row of a table has, in its
source line split as the parser splits it, as many cells as its header and its delimiter
row (the parser itself pads a short row and drops a long row's extra cells, so its tokens
alone would not show a ragged row)."""

from __future__ import annotations

from dataclasses import dataclass

from markdown_it import MarkdownIt
from markdown_it.rules_block.table import escapedSplit
from markdown_it.token import Token


def parser() -> MarkdownIt:
    """The parser every report is read with."""
    return MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"])


def _trimmed(columns: list[str]) -> list[str]:
    """The cells of a split row without the empty ones outside its outer pipes."""
    if columns and not columns[0].strip():
        columns = columns[1:]
    if columns and not columns[-1].strip():
        columns = columns[:-1]
    return columns


def source_cells(line: str) -> int:
    """The cells of a table row in its source, split at unescaped pipes as the parser does."""
    return len(_trimmed(escapedSplit(line.strip())))


def delimiter_cells(line: str) -> int:
    """The cells of a table's delimiter row (which the parser splits at every pipe)."""
    return len(_trimmed(line.strip().split("|")))


def literal(inline: Token) -> str | None:
    """The text an inline token shows, where it is all literal text (no code, emphasis,
    link, HTML, strikethrough or line break); None where anything in it is marked up."""
    children = inline.children or []
    if any(c.type != "text" for c in children):
        return None
    return "".join(c.content for c in children)


@dataclass
class Table:
    """A table of a report: its first line (1-based) and its rows' cells (header first)."""

    line: int
    rows: list[list[Token]]

    def texts(self, row: int) -> list[str | None]:
        """The literal text of each cell of a row (0: the header)."""
        return [literal(c) for c in self.rows[row]]


def _rows(tokens: list[Token], start: int) -> tuple[list[list[Token]], list[int]]:
    """The cells (inline tokens) and source line of each row of the table opened at
    tokens[start]."""
    rows, lines = [], []
    for token in tokens[start + 1 :]:
        if token.type == "table_close":
            break
        if token.type == "tr_open":
            rows.append([])
            lines.append(token.map[0])
        elif token.type == "inline":
            rows[-1].append(token)
    return rows, lines


def tables(text: str, where: str = "report") -> list[Table]:
    """Every table of a Markdown document, each checked: the same number of cells in its
    header, its delimiter row and each of its rows; no line starting with '|' outside a
    table. An AssertionError names `where` and the line."""
    source = text.splitlines()
    tokens = parser().parse(text)
    found, covered = [], set()
    for k, token in enumerate(tokens):
        if token.type != "table_open":
            continue
        first, end = token.map
        covered.update(range(first, end))
        rows, lines = _rows(tokens, k)
        width = len(rows[0])
        assert source_cells(source[first]) == width, f"{where}:{first + 1}: header"
        assert delimiter_cells(source[first + 1]) == width, f"{where}:{first + 2}: delimiter row"
        for line in lines[1:]:
            cells = source_cells(source[line])
            assert cells == width, (
                f"{where}:{line + 1}: {cells} cells under a header of {width}: {source[line]!r}"
            )
        found.append(Table(first + 1, rows))
    stray = [n + 1 for n, line in enumerate(source) if line.lstrip().startswith("|")]
    stray = [n for n in stray if n - 1 not in covered]
    assert not stray, f"{where}: lines {stray} start with '|' but are in no table"
    return found


def paragraphs(text: str) -> list[Token]:
    """The inline token of every paragraph and heading of a Markdown document."""
    tokens = parser().parse(text)
    return [
        tokens[k + 1]
        for k, t in enumerate(tokens)
        if t.type in ("paragraph_open", "heading_open") and tokens[k + 1].type == "inline"
    ]


def check_file(path: object) -> list[Table]:
    """tables() of a written report."""
    from pathlib import Path

    return tables(Path(str(path)).read_text(encoding="utf-8"), str(path))

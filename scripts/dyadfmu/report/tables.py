"""Tables of the reports: rows of strings as aligned text and as Markdown, and the error
table of a co-simulation checked against its reference (Markdown and CSV)."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

from ..cosim.compare import OutputError
from . import markdown

#: The header of an error table.
ERROR_HEADER = ["output", "unit", "peak |reference|", "max |FMU - reference|", "relative to peak"]


def error_rows(errors: Sequence[OutputError]) -> list[list[str]]:
    """The error table of a co-simulation: one row per output, under :data:`ERROR_HEADER`."""
    rows = [list(ERROR_HEADER)]
    for e in errors:
        rows.append([e.name, e.unit, f"{e.peak:.6g}", f"{e.max_abs:.3e}", f"{e.relative:.3e}"])
    return rows


def format_text(rows: list[list[str]]) -> str:
    """The rows as aligned plain text, the first one a header underlined with dashes."""
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    lines = [
        "  ".join(
            cell.rjust(w) if c else cell.ljust(w)
            for c, (cell, w) in enumerate(zip(row, widths, strict=False))
        )
        for row in rows
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def format_markdown(rows: list[list[str]], align: str = "") -> str:
    """The rows as a Markdown table, the first one its header, every cell literal text
    (:func:`dyadfmu.report.markdown.table`)."""
    return "\n".join(markdown.table(rows[0], rows[1:], align))


def write_error_tables(stem: Path, title: str, rows: list[list[str]]) -> list[Path]:
    """<stem>_errors.md (titled) and <stem>_errors.csv of an error table."""
    md = Path(f"{stem}_errors.md")
    md.write_text(
        f"# {markdown.text(title)}\n\n{markdown.provenance('scripts/run-main')}\n\n"
        f"{format_markdown(rows, '--rrr')}\n",
        encoding="utf-8",
    )
    path_csv = Path(f"{stem}_errors.csv")
    with open(path_csv, "w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows(rows)
    return [md, path_csv]

"""generate.py: the files of a variable table, and the golden model descriptions."""

from __future__ import annotations

import argparse
import difflib
import sys
from pathlib import Path

from dyadgen.golden import golden_files
from dyadgen.locations import relative_to_checkout
from dyadgen.pipeline import load_table, outputs_of, write_files
from dyadgen.table import TableError


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        description="Generate the model descriptions, C variable table and documentation "
        "of a dyad, drive or motor FMU from its variable table."
    )
    parser.add_argument("table", nargs="?", type=Path, help="the variable table (TOML)")
    parser.add_argument("--out", type=Path, help="directory to write the generated files to")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument(
        "--update-golden",
        action="store_true",
        help="rewrite modelDescription/interface/golden/*.xml from the tables",
    )
    mode.add_argument(
        "--check-golden",
        action="store_true",
        help="exit 1 with a unified diff if a golden file differs",
    )
    return parser


def update_golden() -> int:
    """Rewrite every golden file."""
    for path, text in golden_files().items():
        write_files(path.parent, {path.name: text})
        print(f"wrote {relative_to_checkout(path)}")
    return 0


def check_golden() -> int:
    """Print a unified diff of every golden file that differs; 1 if one does."""
    differs = []
    for path, text in golden_files().items():
        old = path.read_text(encoding="utf-8") if path.is_file() else ""
        if old != text:
            differs.append(path)
            rel = relative_to_checkout(path)
            sys.stdout.writelines(
                difflib.unified_diff(
                    old.splitlines(keepends=True),
                    text.splitlines(keepends=True),
                    f"{rel} (golden)",
                    f"{rel} (generated)",
                )
            )
    if differs:
        print(
            f"{len(differs)} golden file(s) differ from the tables; review the diff "
            "and run 'modelDescription/generate.py --update-golden'",
            file=sys.stderr,
        )
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    """generate.py TABLE --out DIR | --update-golden | --check-golden."""
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        if args.update_golden or args.check_golden:
            if args.table or args.out:
                parser.error("--update-golden and --check-golden take no table or --out")
            return update_golden() if args.update_golden else check_golden()
        if args.table is None or args.out is None:
            parser.error("give a TABLE and --out DIR (or --update-golden / --check-golden)")
        write_files(args.out, outputs_of(load_table(args.table)))
        return 0
    except TableError as exc:
        for problem in exc.args[0]:
            print(f"error: {problem}", file=sys.stderr)
        return 1

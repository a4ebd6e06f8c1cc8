"""``dyadfmu rows``: an FMU run over a CSV table of inputs (or its DefaultExperiment), every
row written with the inputs and outputs of one instant (see :mod:`.rows`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from .. import argtypes, paths
from .rows import Rows, RowsError, run_table

#: The arguments naming a path, checked before any work (cli.py).
PATHS = (
    ("FMU", "fmu", paths.FILE),
    ("--input", "input", paths.FILE),
    ("--out", "out", paths.OUT),
)


def parser() -> argparse.ArgumentParser:
    """The options of `dyadfmu rows`."""
    command = argparse.ArgumentParser(
        prog="dyadfmu rows",
        description="Run an FMU (FMI 2 or 3 co-simulation) over a table of inputs and write "
        "every row with the inputs and the outputs of the same instant: the inputs of t are "
        "set, the outputs read, then the FMU steps to the next row (fmpy's simulate_fmu "
        "records an algebraic FMU's outputs one row after their inputs). Without --input, "
        "the FMU's DefaultExperiment on the start values.",
    )
    command.add_argument("fmu", metavar="FMU", type=Path, help="the .fmu file")
    command.add_argument(
        "--input",
        type=Path,
        metavar="CSV",
        help="inputs: a 'time' column (s, increasing), then any inputs or tunable "
        "parameters by name (fmpy's CSV form); the others keep their start values",
    )
    command.add_argument(
        "--output",
        nargs="+",
        metavar="NAME",
        help="the outputs to record (default: every output)",
    )
    command.add_argument(
        "--start",
        nargs="+",
        metavar="NAME=VALUE",
        type=argtypes.assignment,
        default=[],
        help="parameters' start values (in the variables' units)",
    )
    command.add_argument(
        "--out",
        type=Path,
        default=Path("out/rows"),
        help="folder of the written <FMU>.csv (default out/rows)",
    )
    return command


def _read_csv(path: Path) -> np.ndarray:
    from fmpy.util import read_csv

    try:
        return read_csv(str(path))
    except Exception as exc:  # fmpy's reader raises what numpy raises
        raise RowsError(f"--input {path}: not a CSV table with a header row ({exc})") from None


def _summary(rows: Rows, written: Path) -> str:
    columns = ", ".join(f"{n} ({rows.units[n] or '-'})" for n in rows.names)
    lines = [
        f"{len(rows)} rows from t = {rows['time'][0]:g} s to {rows['time'][-1]:g} s",
        f"columns (unit): {columns}",
    ]
    if "status" in rows.names:
        flagged = int(np.count_nonzero(rows["status"] != 0))
        lines.append(f"rows with status other than 0 (ok): {flagged}")
    lines.append(f"wrote {written}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run the command; 0, or 1 with one line where the FMU or the table is refused."""
    args = paths.parse_checked(parser(), argv, PATHS)
    try:
        table = _read_csv(args.input) if args.input else None
        rows = run_table(args.fmu, table, args.output, dict(args.start))
    except RowsError as exc:
        print(f"dyadfmu rows: error: {exc}", file=sys.stderr)
        return 1
    args.out.mkdir(parents=True, exist_ok=True)
    written = args.out / f"{args.fmu.stem}.csv"
    header = ",".join('"' + n.replace('"', '""') + '"' for n in rows.names)
    values = rows.table.view(float).reshape(len(rows), len(rows.names))
    np.savetxt(written, values, "%.17g", ",", header=header, comments="")
    print(_summary(rows, written))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The stages joined: read and check a scene (scenefile), its model and what it needs
(model, needs), its interface table (table, kinds), the generated files (emit)."""

from __future__ import annotations

from pathlib import Path

from dyadgen.kinds import KINDS, build_table
from dyadgen.model import Scene
from dyadgen.scenefile.c_names import c_names
from dyadgen.scenefile.read import read_scene
from dyadgen.table import Table, read_table_data, table_from_data

__all__ = ["build_table", "load_scene", "load_table", "outputs_of", "write_files"]


def load_scene(path: Path, *, check_c_names: bool = True) -> Scene:
    """Read and validate a scene; raises SceneError listing every problem.
    `check_c_names`: refuse names whose C names clash (off only for the C names
    probe, from which the clashes are learnt)."""
    return read_scene(Path(path), c_names if check_c_names else None)


def load_table(path: Path) -> Table:
    """Read and validate a table file; raises TableError listing every problem."""
    return table_from_data(read_table_data(Path(path)), path, KINDS)


def outputs_of(table: Table) -> dict[str, str]:
    """Relative path -> text of every generated file of the table's FMU."""
    return table.kind.files(table)


def write_files(out: Path, files: dict[str, str]) -> None:
    """Write generated files below `out` (LF line ends, UTF-8)."""
    for rel, text in files.items():
        path = Path(out) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)

"""The golden model descriptions (interface/golden/): the generated FMI 2 and FMI 3
descriptions of the tables written by hand and of the generic dyads' scenes, kept so
that every interface change shows in review."""

from __future__ import annotations

from pathlib import Path

from dyadgen.emit import fmi2, fmi3
from dyadgen.locations import GOLDEN_DIR, HAND_TABLES, INTERFACE_DIR, SCENES_DIR
from dyadgen.pipeline import build_table, load_scene, load_table

#: The variable tables written by hand; the dyad FMUs' tables come from their scenes.
TABLES = HAND_TABLES
#: The scenes of the generic per-type dyad FMUs, whose model descriptions are golden.
GOLDEN_SCENES = (
    "dyad_rrr.toml",
    "dyad_rrt.toml",
    "dyad_rtr.toml",
    "dyad_trt.toml",
    "dyad_rtt.toml",
)


def golden_files() -> dict[Path, str]:
    """Golden path -> expected text for every table in TABLES and scene in GOLDEN_SCENES."""
    tables = [load_table(INTERFACE_DIR / name) for name in TABLES]
    tables += [build_table(load_scene(SCENES_DIR / name)) for name in GOLDEN_SCENES]
    result = {}
    for table in tables:
        result[GOLDEN_DIR / f"{table.identifier}_fmi2.xml"] = fmi2.model_description(table)
        result[GOLDEN_DIR / f"{table.identifier}_fmi3.xml"] = fmi3.model_description(table)
    return result

"""Where the generator's data and the project's folders are."""

from __future__ import annotations

from pathlib import Path

#: modelDescription/, the generator's home.
MODEL_DESCRIPTION = Path(__file__).resolve().parent.parent
#: The checkout.
ROOT = MODEL_DESCRIPTION.parent
#: The interface data: the drive's and the motor's tables, the generic dyads'
#: descriptions, the C names probe scene and the golden model descriptions.
INTERFACE_DIR = MODEL_DESCRIPTION / "interface"
GOLDEN_DIR = INTERFACE_DIR / "golden"
SCENES_DIR = ROOT / "modelDescription" / "scenes"
#: The scenes the build adds with its tests (fmu/CMakeLists.txt: tests/scenes/*.toml).
TEST_SCENES_DIR = ROOT / "tests" / "scenes"
#: The variable tables written by hand (interface/), each an FMU of the build.
HAND_TABLES = ("drive.toml", "motor.toml")
#: A scene with every feature of the generated code (see the file and scenefile.c_names).
C_NAMES_PROBE = INTERFACE_DIR / "c_names_probe.toml"
#: every probe: external kinematics, internal with a crank, a ram, a cylinder, several
#: drivers, and internal with nothing tunable (the lanes without the bounds)
C_NAMES_PROBES = (
    C_NAMES_PROBE,
    INTERFACE_DIR / "c_names_probe_internal.toml",
    INTERFACE_DIR / "c_names_probe_ram.toml",
    INTERFACE_DIR / "c_names_probe_cylinder.toml",
    INTERFACE_DIR / "c_names_probe_drivers.toml",
    INTERFACE_DIR / "c_names_probe_bare.toml",
)
#: Where the headers the generated code includes are found.
HEADER_DIRS = (ROOT / "src" / "include", ROOT / "src", ROOT / "fmu")


def relative_to_checkout(path: Path) -> str:
    """A path relative to the checkout where it lies inside it."""
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)

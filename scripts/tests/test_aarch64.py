"""The FMI 3 FMUs' 64-bit ARM Linux binaries (binaries/aarch64-linux, cross-compiled with
gcc-aarch64-linux-gnu and -ffp-contract=off) under qemu-aarch64 against their x86-64 Linux
binaries: over the harness's inputs every output and status bit for bit
(tests/fmu_replay.c, built for both, drives them). FMI 2 names no folder for 64-bit ARM, so
an FMI 2 FMU carries none.

Without the cross compiler or QEMU the tests skip, except under CI (CI=true), where they
fail: scripts/run-tests installs both and builds with the aarch64 binaries.
"""

from __future__ import annotations

import subprocess
import zipfile

import pytest
from dyadfmu import paths
from dyadfmu.cosim import importers, windows
from replay_checks import assert_the_columns_entry_ran_where_algebraic
from tool_checks import required, required_tool

FMI3 = [f"{name}_fmi3" for name in importers.fmu_names()]
#: The shared libraries a 64-bit ARM binary may need: the C library and libm.
SYSTEM_LIBRARIES = {"libc.so.6", "libm.so.6"}


@pytest.fixture(scope="module")
def arm_build():
    program = windows.replay_program("aarch64")
    required(program.is_file(), f"{program} is missing: configure with -DDYADFMU_AARCH64=ON")
    return paths.build_dir()


@pytest.fixture(scope="module")
def replays(arm_build, tmp_path_factory):
    required(windows.qemu_aarch64_executable() is not None, "qemu-aarch64 is not installed")
    rows = windows.replay_all(tmp_path_factory.mktemp("aarch64"), arm_build, platform="aarch64")
    return {d.fmu: d for d in rows}


@pytest.mark.parametrize("fmu", FMI3)
def test_the_arm_binary_gives_the_x86_outputs_bit_for_bit(replays, fmu):
    """Every output at every step, the statuses and the integer outputs: with no fused
    multiply-add on either side the two compute the same operations; glibc's libm gives
    the same results on both."""
    d = replays[fmu]
    assert d.steps >= 100 and d.outputs > 0
    assert d.samples in (0, d.steps)  # the columns entry's rows, where the model is algebraic
    assert d.same_status, f"{fmu}: doStep statuses or integer outputs differ"
    assert d.identical == d.outputs, f"{fmu}: {d.ulps} (in units in the last place)"


def test_the_columns_entry_ran_on_every_algebraic_fmu(replays):
    """The batch evaluation too, its lanes compiled for the ARM binary with the flags
    that vectorise them."""
    assert_the_columns_entry_ran_where_algebraic(replays)


@pytest.mark.parametrize("fmu", FMI3)
def test_every_fmi3_fmu_carries_an_arm_binary_needing_only_libc_and_libm(arm_build, fmu):
    identifier = fmu.rsplit("_fmi", 1)[0]
    with zipfile.ZipFile(arm_build / "fmus" / f"{fmu}.fmu") as archive:
        names = set(archive.namelist())
    assert f"binaries/aarch64-linux/{identifier}.so" in names
    assert not any(n.startswith("binaries/aarch64-linux/") for n in _fmi2_names(arm_build, fmu))
    readelf = required_tool("aarch64-linux-gnu-readelf")
    binary = arm_build / "fmus" / "stage" / fmu / "binaries" / "aarch64-linux" / f"{identifier}.so"
    dump = subprocess.run([readelf, "-d", str(binary)], capture_output=True, text=True, check=True)
    needed = {
        line.split("[", 1)[1].rstrip("]") for line in dump.stdout.splitlines() if "(NEEDED)" in line
    }
    assert needed <= SYSTEM_LIBRARIES, needed - SYSTEM_LIBRARIES
    header = subprocess.run([readelf, "-h", str(binary)], capture_output=True, text=True)
    assert "AArch64" in header.stdout


def _fmi2_names(build, fmu: str) -> set:
    with zipfile.ZipFile(build / "fmus" / f"{fmu[:-1]}2.fmu") as archive:
        return set(archive.namelist())

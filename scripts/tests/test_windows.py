"""The FMUs' Windows binaries (cross-compiled with MinGW-w64) under Wine against their Linux
binaries: every FMU carries both, each Windows DLL needs nothing beyond the Windows system
DLLs, and over the harness's inputs it gives the Linux binary's outputs and statuses bit
for bit (tests/fmu_replay.c, built for both platforms, drives them).

Without Wine or the Windows build the tests skip, except under CI (CI=true), where they
fail: scripts/run-tests installs both and configures build/ with -DDYADFMU_WINDOWS=ON.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from dyadfmu import paths
from dyadfmu.cosim import importers, windows
from replay_checks import assert_the_columns_entry_ran_where_algebraic
from tool_checks import required, required_tool

ALL = [f"{name}_fmi{version}" for name in importers.fmu_names() for version in importers.VERSIONS]
#: The DLLs a Windows binary may import: the system's, which every Windows has.
SYSTEM_DLLS = {"KERNEL32.dll", "msvcrt.dll"}


@pytest.fixture(scope="module")
def windows_build():
    linux, exe = windows.replay_programs()
    required(exe.is_file(), f"{exe} is missing: configure the build with -DDYADFMU_WINDOWS=ON")
    required(linux.is_file(), f"{linux} is missing: build the tests")
    return paths.build_dir()


@pytest.fixture(scope="module")
def replays(windows_build, tmp_path_factory):
    required(windows.wine_executable() is not None, "wine is not installed")
    rows = windows.replay_all(tmp_path_factory.mktemp("windows"), windows_build)
    return {d.fmu: d for d in rows}


@pytest.mark.parametrize("fmu", ALL)
def test_the_windows_binary_gives_the_linux_outputs_bit_for_bit(replays, fmu):
    """Every output bit for bit, a plant's integrated motion and its solver's step too, but
    an angle (an output named *.angle), which comes from the C runtime's atan2 (MinGW's
    own, glibc's on Linux) and may be one unit in the last place apart; nothing computed
    from it is."""
    d = replays[fmu]
    assert d.steps >= 100 and d.outputs > 0
    assert d.samples in (0, d.steps)  # the columns entry's rows, where the model is algebraic
    assert d.same_status, f"{fmu}: doStep statuses or integer outputs differ"
    apart = {n: u for n, u in d.ulps.items() if not (n.endswith(".angle") and u <= 1)}
    assert not apart, (
        f"{fmu}: {len(apart)} outputs differ, worst {d.worst:.3g} of its peak "
        f"({d.worst_output}); in units in the last place: {apart}"
    )
    assert d.identical + len(d.ulps) == d.outputs


def test_the_columns_entry_ran_on_every_algebraic_fmu(replays):
    """The batch evaluation too, its lanes compiled for the Windows binary with the flags
    that vectorise them."""
    assert_the_columns_entry_ran_where_algebraic(replays)


@pytest.mark.parametrize("fmu", ALL)
def test_every_fmu_carries_a_windows_binary_needing_only_system_dlls(windows_build, fmu):
    path = windows_build / "fmus" / f"{fmu}.fmu"
    version = int(fmu[-1])
    identifier = fmu.rsplit("_fmi", 1)[0]
    platform = {2: "win64", 3: "x86_64-windows"}[version]
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
    assert f"binaries/{platform}/{identifier}.dll" in names
    assert f"binaries/{paths.PLATFORM[version]}/{identifier}.so" in names
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump is None:
        pytest.skip("x86_64-w64-mingw32-objdump is not installed")
    dll = windows_build / "fmus" / "stage" / fmu / "binaries" / platform / f"{identifier}.dll"
    dump = subprocess.run([objdump, "-p", str(dll)], capture_output=True, text=True, check=True)
    imported = {
        line.split(":", 1)[1].strip() for line in dump.stdout.splitlines() if "DLL Name:" in line
    }
    assert imported <= SYSTEM_DLLS, imported - SYSTEM_DLLS


#: An aligned move of a vector wider than 16 bytes against the stack (rsp or rbp): Win64
#: aligns the stack to 16 bytes only, so it faults wherever the frame falls otherwise
#: (src/dyad_lanes.h: GCC bug 54412, which Debian's MinGW-w64 GCC is patched against).
ALIGNED_WIDE_STACK_MOVE = re.compile(
    r"\bvmov(?:ap[sd]|dqa(?:32|64)?)\s+(?:%[yz]mm\d+,.*\(%r[sb]p\)|.*\(%r[sb]p\),%[yz]mm\d+)"
)


def _aligned_wide_stack_moves(disassembly: str) -> list[str]:
    return [line for line in disassembly.splitlines() if ALIGNED_WIDE_STACK_MOVE.search(line)]


def test_the_check_of_stack_moves_sees_an_aligned_wide_one():
    dump = "\n".join(
        [
            "  4010: c5 fd 29 44 24 40  vmovapd %ymm0,0x40(%rsp)",
            "  4016: 62 f1 fd 48 28 45 02  vmovapd 0x80(%rbp),%zmm0",
            "  401d: 62 f1 fe 48 6f 04 24  vmovdqa64 %zmm8,(%rsp)",
            "  4024: c5 fd 11 44 24 40  vmovupd %ymm0,0x40(%rsp)",
            "  402a: c5 f9 29 44 24 40  vmovapd %xmm0,0x40(%rsp)",
            "  4030: c5 fd 28 03  vmovapd (%rbx),%ymm0",
        ]
    )
    assert len(_aligned_wide_stack_moves(dump)) == 3


def test_no_windows_binary_moves_a_wide_vector_aligned_against_the_stack(windows_build):
    """The lanes for AVX2 and AVX-512 spill 32- and 64-byte vectors to the stack; in a
    Windows DLL each such move must be an unaligned one (vmovupd, vmovdqu)."""
    objdump = required_tool("x86_64-w64-mingw32-objdump")
    dlls = sorted((windows_build / "fmus" / "stage").glob("*/binaries/*/*.dll"))
    assert dlls
    wide, found = 0, {}
    for dll in dlls:
        dump = subprocess.run([objdump, "-d", str(dll)], capture_output=True, text=True).stdout
        wide += dump.count("%zmm")
        if moves := _aligned_wide_stack_moves(dump):
            found[dll.name] = moves[:3]
    assert wide > 0  # the AVX-512 lanes are there
    assert not found, found


def test_the_comparison_sees_one_ulp_and_a_status():
    bits = np.array([1.0, -2.5, 3.0])
    linux = windows.Replay(
        np.zeros(3, int), {7: bits.copy(), 8: bits.copy()}, {9: np.zeros(2, int)}, 2, 0
    )
    same = windows.compare("x", {7: "a", 8: "b"}, linux, linux)
    assert same.identical == 2 and same.worst == 0 and same.same_status
    moved = bits.copy()
    moved[1] = np.nextafter(moved[1], 0.0)
    other = windows.Replay(
        np.array([0, 2, 0]), {7: bits.copy(), 8: moved}, {9: np.zeros(2, int)}, 2, 0
    )
    d = windows.compare("x", {7: "a", 8: "b"}, linux, other)
    assert d.identical == 1 and d.worst_output == "b" and not d.same_status
    assert d.worst == pytest.approx(np.spacing(2.5) / 3.0, rel=1e-12, abs=0)
    assert d.ulps == {"b": 1.0}
    moved[1] = np.nextafter(np.nextafter(moved[1], 0.0), 0.0)
    assert windows.compare("x", {7: "a", 8: "b"}, linux, other).ulps == {"b": 3.0}
    moved[1] = 2.5
    assert windows.compare("x", {7: "a", 8: "b"}, linux, other).ulps == {"b": float("inf")}
    refused = windows.Replay(linux.status, linux.reals, linux.integers, 2, 3)
    assert not windows.compare("x", {7: "a", 8: "b"}, linux, refused).same_status

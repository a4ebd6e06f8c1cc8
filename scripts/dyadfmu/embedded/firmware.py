"""Building a scene's tick program for the host and for a Cortex-M4F, and running it: on
the host directly, on the Cortex-M4F under QEMU's ``mps2-an386`` board (a Cortex-M4 with
its single-precision FPU), with an instruction trace when asked.

Both builds are float builds of the bundle (``DYAD_REAL_FLOAT``) at ``-O2`` with ISO C's
rules for ``a*b+c`` (``-ffp-contract=off``: no fused multiply-add, which the host build
does not use either) unless ``contract`` asks for GCC's default on the M4F (``fast``: its
``vfma.f32``), to show what contraction changes. Both define ``DYAD_SCENE_TERSE``: a
refusal's reason is written without the C library's printf (its numbers as '?'), so that
the firmware links no stdio.
"""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import paths
from .ticks import EmbeddedError

__all__ = [
    "PORT_DIR",
    "M4F_CC",
    "QEMU_ARM",
    "Build",
    "TickRun",
    "missing_tools",
    "build_host",
    "build_m4f",
    "run",
    "parse",
]

#: The ports and start-up code of the tick programs.
PORT_DIR = paths.project_dir() / "src" / "examples" / "firmware"
M4F_CC = "arm-none-eabi-gcc"
QEMU_ARM = "qemu-system-arm"
#: The Cortex-M4F with its FPU (fpv4-sp-d16: single precision only), hard-float calls.
M4F_CPU = ("-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard")
#: float; a refusal's reason without printf (DYAD_SCENE_TERSE: no stdio linked)
COMMON = (
    "-std=c99",
    "-O2",
    "-DDYAD_REAL_FLOAT",
    "-DDYAD_SCENE_TERSE",
    "-Wall",
    "-Wextra",
    "-Wpedantic",
    "-Werror",
)
QEMU_COMMAND = (
    QEMU_ARM,
    "-machine",
    "mps2-an386",
    "-nographic",
    "-monitor",
    "none",
    "-serial",
    "none",
    "-semihosting-config",
    "enable=on,target=native",
)
#: A run's wall-clock limit (s): a firmware that hangs fails the run instead.
TIMEOUT = 600


def missing_tools() -> list[str]:
    """The programs the Cortex-M4F build and run need that are not on the PATH, each with
    its Debian package."""
    needed = {
        M4F_CC: "gcc-arm-none-eabi and libnewlib-arm-none-eabi",
        QEMU_ARM: "qemu-system-arm",
        "arm-none-eabi-objdump": "binutils-arm-none-eabi",
    }
    return [f"{tool} ({package})" for tool, package in needed.items() if not shutil.which(tool)]


@dataclass(frozen=True)
class Build:
    """A built tick program: the executable (an ELF for the M4F), its link map, and the
    objects of the scene and the core (by file stem) as opposed to the port's."""

    program: Path
    map_file: Path | None
    scene_objects: tuple[str, ...]
    m4f: bool


def _sources(bundle: Path) -> list[Path]:
    return sorted(bundle.glob("scene/*.c")) + sorted(bundle.glob("core/src/*.c"))


def _includes(bundle: Path) -> list[str]:
    return [f"-I{PORT_DIR}", f"-I{bundle / 'scene'}", f"-I{bundle / 'core' / 'include'}"]


def _compile(cc: str, flags: list[str], sources: list[Path], work: Path) -> list[Path]:
    objects = []
    work.mkdir(parents=True, exist_ok=True)
    for source in sources:
        obj = work / f"{source.stem}.o"
        _run_tool([cc, *flags, "-c", str(source), "-o", str(obj)])
        objects.append(obj)
    return objects


def _run_tool(command: list[str]) -> str:
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        shown = " ".join(command[:2] + ["...", command[-1]])
        raise EmbeddedError(f"{shown} failed:\n{(done.stderr or done.stdout).strip()}")
    return done.stdout


def build_host(bundle: Path, ticks_c: Path, work: Path) -> Build:
    """The tick program for this machine: cc, float, -O2, no contraction."""
    flags = [*COMMON, "-ffp-contract=off", *_includes(bundle)]
    ports = [ticks_c, PORT_DIR / "ticks_common.c", PORT_DIR / "host_port.c"]
    objects = _compile("cc", flags, ports + _sources(bundle), work)
    program = work / f"{ticks_c.stem}_host"
    _run_tool(["cc", "-o", str(program), *map(str, objects), "-lm"])
    return Build(program, None, tuple(s.stem for s in _sources(bundle)), m4f=False)


def build_m4f(bundle: Path, ticks_c: Path, work: Path, contract: bool = False) -> Build:
    """The tick program as Cortex-M4F firmware: arm-none-eabi-gcc, float, -O2, each
    function in its own section (the link keeps what is called), newlib-nano's C library
    and its libm, no heap (m4f_start.c), each object's call graph with its functions'
    frames (-fcallgraph-info=su: <object>.ci beside it)."""
    flags = [
        *COMMON,
        *M4F_CPU,
        "-ffp-contract=fast" if contract else "-ffp-contract=off",
        "-ffunction-sections",
        "-fdata-sections",
        "-fstack-usage",
        "-fcallgraph-info=su",
        *_includes(bundle),
    ]
    ports = [ticks_c, PORT_DIR / "ticks_common.c", PORT_DIR / "m4f_start.c"]
    objects = _compile(M4F_CC, flags, ports + _sources(bundle), work)
    program = work / f"{ticks_c.stem}.elf"
    map_file = work / f"{ticks_c.stem}.map"
    link = [M4F_CC, *M4F_CPU, "-nostartfiles", "--specs=nano.specs"]
    link += ["-T", str(PORT_DIR / "m4f.ld"), "-Wl,--gc-sections", f"-Wl,-Map={map_file}"]
    _run_tool([*link, "-o", str(program), *map(str, objects), "-lm"])
    return Build(program, map_file, tuple(s.stem for s in _sources(bundle)), m4f=True)


def run(build: Build, trace: Path | None = None) -> str:
    """What the tick program writes; under QEMU for the M4F, with every executed
    instruction logged into `trace` when given (one translation block per instruction)."""
    if not build.m4f:
        command = [str(build.program)]
    else:
        command = [*QEMU_COMMAND, "-kernel", str(build.program)]
        if trace is not None:
            command += ["-singlestep", "-d", "exec,nochain", "-D", str(trace)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT, check=False)
    except subprocess.TimeoutExpired as error:
        raise EmbeddedError(f"{build.program.name} ran over {TIMEOUT} s: stopped") from error
    # QEMU writes what the firmware sends through semihosting to its standard error
    text = done.stderr if build.m4f else done.stdout
    if done.returncode != 0 or "exit status nonzero" in text or "fault:" in text:
        raise EmbeddedError(
            f"{build.program.name} failed (status {done.returncode}): "
            f"{(done.stdout[-400:] + done.stderr[-400:]).strip()}"
        )
    return text


@dataclass(frozen=True)
class TickRun:
    """A tick program's output: per tick its status and every output (float outputs
    widened to the block's double), the reasons of the refused ticks, and the deepest
    stack (bytes; 0 where not known)."""

    status: np.ndarray
    values: np.ndarray  # ticks x outputs
    stack: int
    reasons: tuple[str, ...] = ()


def parse(text: str, outputs: int) -> TickRun:
    """The TickRun of what a tick program wrote."""
    status, rows, stack, reasons = [], [], 0, []
    for line in text.splitlines():
        words = line.split()
        if words[:1] == ["tick"] and len(words) == 3 + outputs:
            status.append(int(words[2]))
            rows.append([int(w, 16) for w in words[3:]])
        elif words[:1] == ["stack"] and len(words) == 2:
            stack = int(words[1])
        elif words[:1] == ["reason"]:
            reasons.append(line.removeprefix("reason "))
    if not rows:
        raise EmbeddedError(f"the tick program wrote no ticks: {text[:200]!r}")
    bits = np.array(rows, dtype=np.uint64)
    return TickRun(np.array(status), bits.view(np.float64), stack, tuple(reasons))

"""The FMUs' binaries for other platforms against their Linux x86-64 ones, over the
harness's inputs.

Every FMU carries a Windows binary (binaries/win64, binaries/x86_64-windows) cross-compiled
with MinGW-w64 beside its Linux one, and every FMI 3 FMU a 64-bit ARM Linux one
(binaries/aarch64-linux). tests/fmu_replay.c drives an extracted FMU over given inputs and
writes every output as its bit pattern; the build makes it for Linux (build/fmu/fmu_replay),
for Windows (build/fmu_replay.exe, run under Wine) and for 64-bit ARM Linux
(build/fmu_replay_aarch64, run under qemu-aarch64). Each runs each FMU's stage directory
(build/fmus/stage/<id>_fmi<v>: what the .fmu holds) over the inputs of
:func:`dyadfmu.cosim.importers.setup_of`, and :func:`compare` sets two side by side.

``python -m dyadfmu.cosim.windows [--platform aarch64]`` prints the table over every FMU of
the build.
"""

from __future__ import annotations

import argparse
import os
import shutil
import struct
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from .. import paths
from ..fmi.simulate import CoSimSetup
from ..report import markdown
from . import importers

__all__ = [
    "Replay",
    "Difference",
    "PLATFORMS",
    "wine_executable",
    "qemu_aarch64_executable",
    "replay_programs",
    "replay_program",
    "write_inputs",
    "read_outputs",
    "run",
    "compare",
    "replay_all",
]


def wine_executable() -> str | None:
    """Wine (Debian ``wine``), None where it is not installed."""
    return shutil.which("wine")


#: The platforms whose binaries replay against Linux x86-64's, and the FMI versions whose
#: FMUs carry one (FMI 2 names no folder for 64-bit ARM).
PLATFORMS = {"windows": (2, 3), "aarch64": (3,)}
#: Where qemu-aarch64 finds the 64-bit ARM C library (Debian libc6-arm64-cross).
AARCH64_SYSROOT = "/usr/aarch64-linux-gnu"


def qemu_aarch64_executable() -> str | None:
    """QEMU's 64-bit ARM user mode (Debian ``qemu-user``), None where it is not installed."""
    return shutil.which("qemu-aarch64")


def replay_programs(build: Path | None = None) -> tuple[Path, Path]:
    """(the Linux fmu_replay, the Windows fmu_replay.exe) of the build."""
    return replay_program("linux", build), replay_program("windows", build)


def replay_program(platform: str, build: Path | None = None) -> Path:
    """The build's fmu_replay for `platform`: linux, windows or aarch64."""
    build = build or paths.build_dir()
    names = {"linux": Path("fmu") / "fmu_replay", "windows": Path("fmu_replay.exe")}
    return build / names.get(platform, Path(f"fmu_replay_{platform}"))


def _bits(x: float) -> str:
    return f"{struct.unpack('<Q', struct.pack('<d', float(x)))[0]:016x}"


def _double(bits: str) -> float:
    return struct.unpack("<d", struct.pack("<Q", int(bits, 16)))[0]


def write_inputs(setup: CoSimSetup, path: Path) -> None:
    """The setup's inputs in fmu_replay's form: one row per communication step, each
    value as its bit pattern (exact on every C library)."""
    md = read_model_description(str(setup.path))
    vr = {v.name: v.valueReference for v in md.modelVariables if v.causality == "input"}
    names = [n for n in setup.inputs if n in vr]  # a setup may feed more than this FMU takes
    steps = len(setup.time) - 1
    lines = [
        f"steps {steps} step {_bits(setup.step)} inputs {len(names)} "
        + " ".join(str(vr[n]) for n in names)
    ]
    for k in range(steps):
        lines.append(" ".join(_bits(setup.inputs[n][k]) for n in names))
    path.write_text("\n".join(lines) + "\n", encoding="ascii")


@dataclass
class Replay:
    """One run's outputs: per step the doStep status, the real and the integer outputs,
    by value reference; then, where the model is algebraic, the same rows through the
    FMU's columns entry (dyadfmu_evaluate_columns: its batch evaluation) in one call, each
    row's status and real outputs after the steps' in ``status`` and ``reals``."""

    status: np.ndarray
    reals: dict  # value reference -> values per step, then per row of the columns call
    integers: dict  # value reference -> values per step
    steps: int
    columns: int  # the status the columns call returned (0 for an algebraic model)


def read_outputs(path: Path) -> Replay:
    """What fmu_replay wrote."""
    lines = path.read_text(encoding="ascii").splitlines()
    real_vrs = [int(x) for x in lines[0].split()[2:]]
    integer_vrs = [int(x) for x in lines[1].split()[2:]]
    marker = next(k for k, line in enumerate(lines) if line.startswith("columns "))
    steps = [line.split() for line in lines[2:marker]]
    samples = [line.split() for line in lines[marker + 1 :]]
    rows = steps + samples
    status = np.array([int(r[0]) for r in rows])
    reals = {vr: np.array([_double(r[1 + j]) for r in rows]) for j, vr in enumerate(real_vrs)}
    base = 1 + len(real_vrs)
    integers = {vr: np.array([int(r[base + j]) for r in steps]) for j, vr in enumerate(integer_vrs)}
    return Replay(status, reals, integers, len(steps), int(lines[marker].split()[1]))


def _windows_path(path: Path) -> str:
    """The path as a Windows program under Wine sees it (drive Z: is /)."""
    return "Z:" + str(path.resolve()).replace("/", "\\")


def _wine_env(build: Path) -> dict:
    env = dict(os.environ)
    env.update(
        WINEPREFIX=str((build / "wine-prefix").resolve()),
        WINEDEBUG="-all",
        WINEDLLOVERRIDES="mscoree,mshtml=",  # no Mono or Gecko installer prompts
    )
    env.pop("DISPLAY", None)
    return env


def _command(platform: str, build: Path, jobs: Path) -> tuple[list[str], dict | None]:
    program = str(replay_program(platform, build))
    if platform == "windows":
        return ["wine", program, _windows_path(jobs)], _wine_env(build)
    if platform == "aarch64":
        return ["qemu-aarch64", "-L", AARCH64_SYSROOT, program, str(jobs.resolve())], None
    return [program, str(jobs.resolve())], None


def run(jobs: list, workdir: Path, platform: str, build: Path | None = None) -> None:
    """Runs fmu_replay for `platform` (linux; windows under Wine; aarch64 under
    qemu-aarch64) over [(stage dir, input, output)]."""
    build = build or paths.build_dir()
    workdir.mkdir(parents=True, exist_ok=True)
    spell = _windows_path if platform == "windows" else (lambda p: str(p.resolve()))
    listing = workdir / f"jobs_{platform}.txt"
    listing.write_text(
        "".join(" ".join(spell(Path(p)) for p in job) + "\n" for job in jobs), encoding="ascii"
    )
    command, env = _command(platform, build, listing)
    done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=1800)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stdout}\n{done.stderr}")


@dataclass
class Difference:
    """The Windows binary's outputs against the Linux one's over one run."""

    fmu: str
    steps: int
    outputs: int
    identical: int  # outputs equal bit for bit at every step and every columns row
    worst: float  # largest |windows - linux| / peak |linux| over the outputs
    worst_output: str
    same_status: bool  # doStep statuses, integer outputs and the columns call's equal
    #: each output that differs -> its largest distance in units in the last place
    #: (inf where one is finite and the other not, or their signs differ)
    ulps: dict = field(default_factory=dict)
    #: rows compared through the columns entry (0: a model with states has none)
    samples: int = 0


def compare(fmu: str, names: dict, linux: Replay, windows: Replay) -> Difference:
    """``names``: value reference -> output name."""
    identical, worst, worst_output = 0, 0.0, ""
    ulps: dict = {}
    for vr, a in linux.reals.items():
        b = windows.reals[vr]
        same = np.array_equal(a.view(np.uint64), b.view(np.uint64))
        identical += same
        if same:
            continue
        finite = np.isfinite(a) & np.isfinite(b)
        ulps[names[vr]] = _ulps(a, b)
        if not np.array_equal(np.isfinite(a), np.isfinite(b)):
            worst, worst_output = float("inf"), names[vr]
            continue
        peak = float(np.max(np.abs(a[finite]))) if finite.any() else 0.0
        diff = float(np.max(np.abs(a[finite] - b[finite]))) / (peak or 1.0)
        if diff > worst:
            worst, worst_output = diff, names[vr]
    same_status = (
        np.array_equal(linux.status, windows.status)
        and all(np.array_equal(v, windows.integers[vr]) for vr, v in linux.integers.items())
        and (linux.steps, linux.columns) == (windows.steps, windows.columns)
    )
    samples = len(linux.status) - linux.steps
    return Difference(
        fmu, linux.steps, len(linux.reals), identical, worst, worst_output, same_status, ulps,
        samples,
    )  # fmt: skip


def _ulps(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance between two runs of one output in units in the last place."""
    if not np.array_equal(np.isfinite(a), np.isfinite(b)) or np.any(np.signbit(a) != np.signbit(b)):
        return float("inf")
    finite = np.isfinite(a)
    ia, ib = np.abs(a[finite]).view(np.int64), np.abs(b[finite]).view(np.int64)
    return float(np.max(np.abs(ia - ib))) if finite.any() else 0.0


def replay_all(
    workdir: Path, build: Path | None = None, names: list | None = None, platform: str = "windows"
) -> list:
    """[Difference] of every FMU of the build (or those in ``names``, each as
    ``<name>_fmi<v>``) whose FMI version carries a `platform` binary: that binary (under
    Wine or QEMU) against the Linux x86-64 one."""
    build = build or paths.build_dir()
    workdir.mkdir(parents=True, exist_ok=True)
    jobs, runs = [], []
    for name in importers.fmu_names():
        for version in PLATFORMS[platform]:
            fmu = f"{name}_fmi{version}"
            if names is not None and fmu not in names:
                continue
            setup = importers.setup_of(name, version, build)
            stage = build / "fmus" / "stage" / fmu
            write_inputs(setup, workdir / f"{fmu}.in")
            jobs.append((stage, workdir / f"{fmu}.in", workdir / f"{fmu}.linux"))
            runs.append((fmu, setup))
    run(jobs, workdir, "linux", build)
    run([(s, i, o.with_suffix(f".{platform}")) for s, i, o in jobs], workdir, platform, build)
    out = []
    for (fmu, setup), (_, _, linux) in zip(runs, jobs, strict=True):
        md = read_model_description(str(setup.path))
        names_of = {v.valueReference: v.name for v in md.modelVariables}
        other = read_outputs(linux.with_suffix(f".{platform}"))
        out.append(compare(fmu, names_of, read_outputs(linux), other))
    return out


def main(argv: list | None = None) -> int:
    """Prints, per FMU, how a platform's binary's outputs compare with the Linux one's."""
    parser = argparse.ArgumentParser(
        prog="python -m dyadfmu.cosim.windows",
        description="Every FMU's binary for another platform (Windows under Wine, 64-bit ARM "
        "Linux under qemu-aarch64) against its Linux x86-64 binary over the harness's inputs: "
        "outputs equal bit for bit, and the largest difference relative to an output's peak.",
    )
    parser.add_argument("--build", type=Path, default=None, help="the build (default build/)")
    parser.add_argument(
        "--platform", choices=sorted(PLATFORMS), default="windows", help="default windows"
    )
    parser.add_argument(
        "--work", type=Path, default=None, help="folder for the runs' files (default out/PLATFORM)"
    )
    args = parser.parse_args(argv)
    runner = wine_executable() if args.platform == "windows" else qemu_aarch64_executable()
    if runner is None:
        tool = "wine" if args.platform == "windows" else "qemu-aarch64 (Debian qemu-user)"
        print(f"python -m dyadfmu.cosim.windows: {tool} is not installed", file=sys.stderr)
        return 2
    work = args.work or Path("out") / args.platform
    print("\n".join(table_lines(replay_all(work, args.build, platform=args.platform))))
    return 0


#: The table's header.
TABLE_HEADER = (
    "FMU",
    "steps",
    "columns rows",
    "outputs",
    "bit-identical",
    "largest difference / peak",
    "statuses",
)


def table_lines(differences: list[Difference]) -> list[str]:
    """The Markdown table of the Windows binaries against the Linux ones."""
    rows = []
    for d in differences:
        where = f" ({d.worst_output})" if d.worst_output else ""
        rows.append(
            [
                d.fmu,
                str(d.steps),
                str(d.samples),
                str(d.outputs),
                str(d.identical),
                f"{d.worst:.2g}{where}",
                "equal" if d.same_status else "DIFFER",
            ]
        )
    return markdown.table(TABLE_HEADER, rows, "-rrrrr-")


if __name__ == "__main__":
    raise SystemExit(main())

"""Long chain scenes, and how long the scene generator takes on them.

A long chain is a crank followed by N RRR dyads: dyad 1 hangs on the crank's pin, and
each later dyad's link m on a point of the previous dyad's rocker, each rocker pivoted on
the frame. The generator takes chains of at most MAX_CHAIN dyads (its dependency lists
grow as dyads x chain length): more dyads than that come as several chains, each
starting on the crank's pin. Every dyad but the last of its chain is loaded by the next
one, so the chain exercises what grows with the number of dyads: the dyads that load a
dyad, the inputs each output depends on, the generated code. Geometry is arbitrary (the
generator does not solve the kinematics), so the scenes serve the generator, not
co-simulation.

``dyadfmu scene-bench`` prints the time of ``scene.py --check`` and of ``scene.py --out``
(the FMU's generated files) for 25, 50, 100 and 200 dyads: the elapsed time and the CPU
time (user + system) of the generator's process, which a busy machine disturbs less.
Timings are printed, never asserted.
"""

from __future__ import annotations

import argparse
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from .. import paths
from ..argtypes import whole
from ..paths import GENERATOR
from ..report import markdown

SIZES = (25, 50, 100, 200)
#: The most dyads in one chain the generator takes (MAX_CHAIN of
#: modelDescription/dyadgen/scenefile/mechanism.py).
MAX_CHAIN = 200


def chain_scene(dyads: int, identifier: str | None = None, chain: int = MAX_CHAIN) -> str:
    """The TOML text of a crank and `dyads` RRR dyads in chains of `chain` dyads (the
    last one shorter), inertia, gravity, a force and a moment on every rocker, every
    output, a few tunable parameters."""
    if dyads < 1 or chain < 1:
        raise ValueError(f"a chain has at least one dyad, not {min(dyads, chain)}")
    ident = identifier or f"chain{dyads}"
    chains = "a chain" if dyads <= chain else f"chains of {chain}"
    lines = [
        "[scene]",
        f'identifier = "{ident}"',
        f'description = "A crank and {chains} of {dyads} RRR dyads"',
        'kinematics = "external"',
        'outputs = ["all"]',
        'tunable = ["gravity", "rocker1.mass"]',
        "",
        "[effects]",
        "inertia = true",
        "gravity = true",
        "",
        "[gravity]",
        "x = 0.0",
        "y = -9.81",
        "",
        "[crank]",
        "length = 0.05",
        "com = [0.01, 0.0]",
        "mass = 0.8",
        "inertia = 6.0e-4",
        "",
    ]
    for k in range(1, dyads + 1):
        first = (k - 1) % chain == 0
        carrier = '"crank"' if first else f'{{ link = "rocker{k - 1}", at = [0.12, 0.02] }}'
        lines += [
            "[[dyad]]",
            f'name = "d{k}"',
            'type = "RRR"',
            f'm = "coupler{k}"',
            f'n = "rocker{k}"',
            f"k = {carrier}",
            'p = "frame"',
            "",
        ]
    for k in range(1, dyads + 1):
        for link, length in (("coupler", 0.2), ("rocker", 0.15)):
            lines += [
                "[[link]]",
                f'name = "{link}{k}"',
                f"length = {length}",
                "com = [0.07, 0.01]",
                "mass = 1.0",
                "inertia = 3.0e-3",
                "",
            ]
    rockers = ", ".join(f'"rocker{k}"' for k in range(1, dyads + 1))
    lines += ["[loads]", f"force = [{rockers}]", f"moment = [{rockers}]", ""]
    return "\n".join(lines)


def write_chain(dyads: int, folder: Path, chain: int = MAX_CHAIN) -> Path:
    """`dyads` RRR dyads in chains of `chain` written to <folder>/chain<dyads>.toml."""
    path = Path(folder) / f"chain{dyads}.toml"
    path.write_text(chain_scene(dyads, chain=chain), encoding="utf-8")
    return path


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timed(command: list) -> tuple[float, float]:
    """(elapsed, CPU) seconds of a command."""
    cpu, start = _cpu(), time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    elapsed, cpu = time.perf_counter() - start, _cpu() - cpu
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed:\n{done.stderr}")
    return elapsed, cpu


def measure(
    sizes: tuple[int, ...] = SIZES,
    generator: Path = GENERATOR,
    python: str = sys.executable,
    log: Callable | None = None,
    chain: int = MAX_CHAIN,
) -> list[tuple]:
    """(dyads, (elapsed, CPU) of --check, (elapsed, CPU) of --out, bytes of the FMI 2
    model description) for each size, in s, the dyads in chains of `chain`."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="dyadfmu-chain-") as tmp:
        for n in sizes:
            scene = write_chain(n, Path(tmp), chain)
            check = _timed([python, str(generator), str(scene), "--check"])
            out = _timed([python, str(generator), str(scene), "--out", str(Path(tmp) / f"g{n}")])
            size = (Path(tmp) / f"g{n}" / "fmi2" / "modelDescription.xml").stat().st_size
            shutil.rmtree(Path(tmp) / f"g{n}")
            rows.append((n, check, out, size))
            if log:
                log(
                    f"{n} dyads: --check {check[0]:.2f} s ({check[1]:.2f} s CPU), "
                    f"--out {out[0]:.2f} s ({out[1]:.2f} s CPU), {size / 1e6:.1f} MB"
                )
    return rows


#: The most dyads 'dyadfmu scene-bench' generates: a scene of 2,900 such dyads is just
#: under the 1,000,000 bytes the generator reads (modelDescription/dyadgen/tomltext.py).
MAX_CHAIN_DYADS = 2_900


def parser() -> argparse.ArgumentParser:
    """The options of 'dyadfmu scene-bench'."""
    found = argparse.ArgumentParser(
        prog="dyadfmu scene-bench",
        description="Time the scene generator (modelDescription/scene.py --check and --out) "
        "on chains of 25, 50, 100 and 200 RRR dyads; print a Markdown table.",
    )
    found.add_argument(
        "--chain",
        type=whole(1, MAX_CHAIN),
        default=MAX_CHAIN,
        help=f"dyads per chain: more dyads come as several chains on the crank "
        f"(default and most: {MAX_CHAIN}, the generator's limit)",
    )
    found.add_argument(
        "--sizes",
        type=whole(1, MAX_CHAIN_DYADS),
        nargs="+",
        default=list(SIZES),
        help=f"numbers of dyads (default 25 50 100 200; 1 to {MAX_CHAIN_DYADS})",
    )
    found.add_argument(
        "--generator",
        type=Path,
        default=GENERATOR,
        help="the scene.py to time (default: this checkout's)",
    )
    found.add_argument(
        "--write",
        type=whole(1, MAX_CHAIN_DYADS),
        metavar="N",
        help="only write the chain of N dyads to stdout",
    )
    return found


#: The path arguments, checked before any work (dyadfmu.paths.parse_checked).
PATHS = (("--generator", "generator", paths.FILE),)


def main(argv: list[str] | None = None) -> int:
    """Run 'dyadfmu scene-bench' with `argv`: print the generator's times."""
    args = paths.parse_checked(parser(), argv, PATHS)
    if args.write is not None:
        sys.stdout.write(chain_scene(args.write, chain=args.chain))
        return 0
    rows = measure(
        args.sizes, args.generator, log=lambda t: print(t, file=sys.stderr), chain=args.chain
    )
    print("\n".join(table_lines(rows)))
    return 0


#: The table's header.
TABLE_HEADER = (
    "dyads",
    "--check: elapsed (s)",
    "--check: CPU (s)",
    "--out: elapsed (s)",
    "--out: CPU (s)",
    "FMI 2 model description (MB)",
)


def table_lines(rows: list) -> list[str]:
    """The Markdown table of measure()'s rows: (dyads, --check (elapsed, CPU) s, --out
    (elapsed, CPU) s, model description bytes)."""
    cells = [
        [str(n), f"{check[0]:.2f}", f"{check[1]:.2f}", f"{out[0]:.2f}", f"{out[1]:.2f}"]
        + [f"{size / 1e6:.1f}"]
        for n, check, out, size in rows
    ]
    return markdown.table(TABLE_HEADER, cells)


if __name__ == "__main__":
    sys.exit(main())

"""The documentation says what the build does: its counts, example messages and commands
are checked against the build and the tools, so that a change that makes one untrue fails
here instead of misleading a user (test_docs.py runs the examples and checks the links).

- README.md is a front door: at most 250 lines, and every user task of its table is one
  click from the top;
- every example error of the scene checker (``error: FILE.toml:LINE: ...``) in any
  document is what the checker prints word for word for the malformed scene of that name;
- every command shown in a code block that runs a file of the checkout: the file exists
  and is executable, or is run through the venv's Python;
- the Windows comparison's count of FMUs (fmu/README.md).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from dyadfmu import paths
from dyadfmu.cosim import importers
from test_docs import DOCUMENTS, anchors, links

ROOT = paths.ROOT
README = ROOT / "README.md"


def _text(path: Path = README) -> str:
    return path.read_text(encoding="utf-8")


def _code_blocks(text: str) -> list[str]:
    """The shell blocks: what a reader types (other blocks show output, files, C)."""
    return re.findall(r"^```(?:sh|bash)\n(.*?)^```", text, re.S | re.M)


def test_the_readme_is_a_front_door():
    """At most 250 lines; its table of tasks leads in one click to a section of its own
    that shows a complete example or links to the reference that has one."""
    text = _text()
    assert len(text.splitlines()) <= 250
    table = text[text.index("## Where to start") :].split("\n## ", 1)[0]
    targets = re.findall(r"\]\(#([^)]+)\)", table)
    assert len(targets) >= 6, targets
    own = anchors(README)
    for target in targets:
        assert target in own, target
    blocks = len(re.findall(r"^<!-- example -->$", text, re.M))
    assert blocks >= 4, "the front door shows tested examples"
    for _, target in links(README):
        if not re.match(r"^[a-z]+:", target):
            assert (ROOT / target.partition("#")[0]).exists() or target.startswith("#"), target


def _check_scene(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(paths.GENERATOR), str(path), "--check"],
        capture_output=True,
        text=True,
    )


def _example_errors() -> list[tuple[str, str]]:
    found = []
    for document in DOCUMENTS:
        for line in _text(document).splitlines():
            m = re.match(r"error: ([a-z_]+\.toml):\d+: ", line)
            if m:
                found.append((m.group(1), line))
    return found


@pytest.mark.parametrize("file,line", _example_errors(), ids=lambda x: x[:40])
def test_an_example_error_is_what_the_checker_prints(file, line):
    done = _check_scene(ROOT / "modelDescription" / "scenes" / "malformed" / file)
    assert done.returncode != 0
    assert line in done.stderr.splitlines(), done.stderr


def _commands() -> list[tuple[str, str]]:
    commands = []
    for document in DOCUMENTS:
        for block in _code_blocks(_text(document)):
            for line in block.splitlines():
                line = line.removeprefix("$ ").strip()
                first = line.split(" ", 1)[0]
                if first.startswith(("scripts/", "modelDescription/", ".venv/bin/")):
                    commands.append((str(document.relative_to(ROOT)), line))
    return commands


@pytest.mark.parametrize("document,command", _commands(), ids=lambda x: x[:50])
def test_a_command_shown_runs_a_file_that_exists(document, command):
    words = command.split()
    program = ROOT / words[0]
    if words[0].startswith(".venv/bin/"):
        name = words[0].removeprefix(".venv/bin/")
        assert name in ("python", "pip", "dyadfmu", "fmpy", "fmutool"), f"{document}: {command}"
        if name == "python" and len(words) > 1 and not words[1].startswith("-"):
            assert (ROOT / words[1]).is_file(), f"{document}: {command}"
        return
    assert program.is_file(), f"{document}: {command}: no {words[0]}"
    assert os.access(program, os.X_OK), f"{document}: {command}: {words[0]} is not executable"


def test_the_windows_comparison_counts():
    """fmu/README.md's count of the FMUs the Windows comparison covers is the importers'."""
    said = re.search(
        r"all (\d+) FMUs it covers", " ".join(_text(ROOT / "fmu" / "README.md").split())
    )
    assert said, "fmu/README.md no longer states the Windows comparison's count"
    assert int(said.group(1)) == 2 * len(importers.fmu_names())


def _durations(text: str, about: str = "") -> set[tuple[float, str]]:
    """Every duration a text gives after `about`: (number, 's' or 'min')."""
    pattern = about + r"(\d+(?:\.\d+)?) ?(s|min|minutes?)\b"
    found = re.findall(pattern, " ".join(text.split()), re.IGNORECASE)
    return {(float(n), "s" if unit == "s" else "min") for n, unit in found}


def _help(*command: str) -> str:
    return subprocess.run(command, capture_output=True, text=True, check=True).stdout


@pytest.mark.parametrize("name", ["study", "cosim"])
def test_a_commands_time_is_the_same_wherever_it_is_given(name):
    """The durations of run-study and run-cosim: scripts/README.md's table and 'dyadfmu
    NAME --help' give those that the script's --help gives."""
    script = _help(str(ROOT / "scripts" / f"run-{name}"), "--help")
    given = _durations(script, "about ")
    assert len(given) >= 3, script  # the full run, --quick, the build's check
    row = next(
        line
        for line in _text(ROOT / "scripts" / "README.md").splitlines()
        if line.startswith(f"| `scripts/run-{name}")
    )
    table = _durations(re.split(r"(?<!\\)\|", row)[4])
    assert table and table <= given, (row, given)
    command = _help(sys.executable, "-m", "dyadfmu", name, "--help")
    stated = _durations(command, "about ")
    assert stated and stated <= given, (command, given)

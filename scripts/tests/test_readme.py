"""The README says what the build does: its counts, example messages and commands are
checked against the build and the tools, so that a change that makes one untrue fails
here instead of misleading a user.

- the number of variables of the generic dyad FMUs;
- every example error of the scene checker (``error: FILE.toml:LINE: ...``), which the
  checker must print word for word for the malformed scene of that name;
- the example scene ``my_press.toml``: its inputs, parameters and outputs;
- every command shown in a code block that runs a file of the checkout: the file exists
  and is executable, or is run through the venv's Python;
- the Windows comparison's counts of FMUs, models and outputs.
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
from fmpy import read_model_description

ROOT = paths.ROOT
DOCUMENTS = [
    ROOT / "README.md",
    ROOT / "modelDescription" / "scenes" / "README.md",
    ROOT / "modelDescription" / "scenes" / "studies" / "README.md",
]
TYPES = ("rrr", "rrt", "rtr", "trt", "rtt")


def _text(path: Path = ROOT / "README.md") -> str:
    return path.read_text(encoding="utf-8")


def _code_blocks(text: str) -> list[str]:
    return re.findall(r"^```[a-z]*\n(.*?)^```", text, re.S | re.M)


def _check_scene(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(paths.GENERATOR), str(path), "--check"],
        capture_output=True,
        text=True,
    )


def _built(name: str) -> Path:
    path = paths.build_dir() / "fmus" / f"{name}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (scripts/run-tests does)")
    return path


def test_the_generic_dyads_variable_counts():
    said = re.search(r"carries every variable of its type: (\d+) to (\d+) of them", _text())
    assert said, "the README no longer states the generic dyads' variable counts"
    counts = [
        len(read_model_description(str(_built(f"dyad_{t}_fmi2"))).modelVariables) for t in TYPES
    ]
    assert (int(said.group(1)), int(said.group(2))) == (min(counts), max(counts)), counts
    for t in TYPES:  # FMI 3 adds the independent variable time
        md3 = read_model_description(str(_built(f"dyad_{t}_fmi3")))
        assert len(md3.modelVariables) == counts[TYPES.index(t)] + 1


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


def test_the_example_scene_has_the_variables_the_readme_names(tmp_path):
    text = _text()
    scene = re.search(r"cat > my_press\.toml <<'TOML'\n(.*?)\nTOML\n", text, re.S)
    assert scene, "the README no longer has the my_press example"
    path = tmp_path / "my_press.toml"
    path.write_text(scene.group(1) + "\n")
    done = _check_scene(path)
    assert done.returncode == 0, done.stderr
    counts = re.search(
        r"(\d+) inputs?, (\d+) parameters?, (\d+) outputs?", done.stdout + done.stderr
    )
    said = re.search(
        r"(\d+) inputs \(.*?\),\s+(no|\d+)\s+parameters?\b.*?,\s+and\s+(\d+)\s+outputs",
        text,
        re.S,
    )
    assert counts and said
    stated = tuple(0 if g == "no" else int(g) for g in said.groups())
    assert tuple(map(int, counts.groups())) == stated


def _commands() -> list[tuple[str, str]]:
    commands = []
    for document in DOCUMENTS:
        for block in _code_blocks(_text(document)):
            for line in block.splitlines():
                line = line.removeprefix("$ ").strip()
                first = line.split(" ", 1)[0]
                if first.startswith(("scripts/", "modelDescription/", ".venv/bin/")):
                    commands.append((document.name, line))
    return commands


@pytest.mark.parametrize("document,command", _commands(), ids=lambda x: x[:50])
def test_a_command_shown_runs_a_file_that_exists(document, command):
    words = command.split()
    program = ROOT / words[0]
    if words[0].startswith(".venv/bin/"):
        name = words[0].removeprefix(".venv/bin/")
        assert name in ("python", "pip", "dyadfmu", "fmpy"), f"{document}: {command}"
        if name == "python" and len(words) > 1 and not words[1].startswith("-"):
            assert (ROOT / words[1]).is_file(), f"{document}: {command}"
        return
    assert program.is_file(), f"{document}: {command}: no {words[0]}"
    assert os.access(program, os.X_OK), f"{document}: {command}: {words[0]} is not executable"


def test_the_windows_comparison_counts():
    said = re.search(
        r"all (\d+) FMUs \((\d+) models, FMI 2 and 3; (\d+) outputs\)", " ".join(_text().split())
    )
    assert said, "the README no longer states the Windows comparison's counts"
    names = importers.fmu_names()
    outputs = 0
    for name in names:
        for version in importers.VERSIONS:
            md = read_model_description(str(_built(f"{name}_fmi{version}")))
            outputs += sum(
                1
                for v in md.modelVariables
                if v.causality == "output" and v.type in ("Real", "Float64")
            )
    assert tuple(map(int, said.groups())) == (2 * len(names), len(names), outputs)

"""Every test executable of the build answers --help with its usage and what it does,
exit 0, as every command of the project does."""

from __future__ import annotations

import subprocess

import pytest
from dyadfmu import paths

TOOLS = (
    "dyad_tests_double",
    "dyad_tests_float",
    "fmu/fmu_api_tests",
    "fmu/fmu_fuzz",
    "fmu/fmu_state_fuzz",
    "fmu/fmu_threads",
    "fmu/fmu_replay",
)


@pytest.mark.parametrize("tool", TOOLS)
def test_a_test_tool_answers_help(tool):
    path = paths.build_dir() / tool
    if not path.is_file():
        pytest.fail(f"{path} is missing: build first (scripts/run-tests does)")
    done = subprocess.run([str(path), "--help"], capture_output=True, text=True, timeout=60)
    text = done.stdout + done.stderr
    assert done.returncode == 0, text
    assert text.startswith("usage: ") and len(text.splitlines()) >= 2, text

"""Each command installs only the system packages it needs (scripts/env.sh,
dyadfmu_ensure_system): without root, a command that misses one stops and names itself
and the packages; one that misses nothing it needs goes on."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from dyadfmu import paths


def _fake_machine(tmp_path: Path) -> Path:
    """A PATH with the compiler, make, CMake, pkg-config and Python but no cross compiler, Wine or
    valgrind, and an `id` that says the user is not root."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("cmake", "cc", "make", "pkg-config", "dirname", "basename"):
        found = shutil.which(tool)
        if found is None:
            pytest.skip(f"{tool} is not installed")
        (bin_dir / tool).symlink_to(found)
    (bin_dir / "python3").symlink_to(os.path.realpath(sys.executable))
    (bin_dir / "id").write_text("#!/bin/sh\necho 1000\n")
    (bin_dir / "id").chmod(0o755)
    return bin_dir


def _ensure(tmp_path: Path, needs: str) -> subprocess.CompletedProcess:
    script = tmp_path / "run-something"
    env_sh = paths.ROOT / "scripts" / "env.sh"
    script.write_text(f'#!/bin/bash\nsource "{env_sh}"\ndyadfmu_ensure_system {needs}\n')
    script.chmod(0o755)
    env = dict(os.environ, PATH=str(_fake_machine(tmp_path)))
    return subprocess.run(["/bin/bash", str(script)], capture_output=True, text=True, env=env)


def test_a_command_names_itself_and_the_packages_it_misses(tmp_path):
    done = _ensure(tmp_path, "windows study")
    assert done.returncode == 1
    message = done.stderr
    assert "run-something needs the system packages" in message
    for package in ("gcc-mingw-w64-x86-64", "wine", "valgrind"):
        assert package in message


def test_a_command_that_misses_nothing_it_needs_goes_on(tmp_path):
    done = _ensure(tmp_path, "")
    assert done.returncode == 0, done.stderr


def test_an_unknown_need_is_refused(tmp_path):
    done = _ensure(tmp_path, "gpu")
    assert done.returncode == 2 and "unknown need 'gpu'" in done.stderr

"""What the tests that need an outside tool share: skip where it is missing, except under
CI (CI=true), where scripts/run-tests installs it and a missing one is a failure."""

from __future__ import annotations

import os
import shutil

import pytest

CI = os.environ.get("CI", "").lower() == "true"


def required(ok: bool, message: str) -> None:
    """Skip (fail under CI) with ``message`` unless ``ok``."""
    if not ok:
        if CI:
            pytest.fail(message + "; under CI it must run (scripts/run-tests installs it)")
        pytest.skip(message)


def required_tool(tool: str) -> str:
    """The path of ``tool`` on PATH; skip (fail under CI) where it is missing."""
    path = shutil.which(tool)
    required(path is not None, f"{tool} is not installed")
    return str(path)

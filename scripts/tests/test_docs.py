"""The documentation is tested where it is followed: in every Markdown file of the
checkout, every relative link reaches a file and every anchor a heading of it, and every
code block marked as an example runs as printed.

An example is a fenced code block whose previous line is ``<!-- example -->``:

- ``sh``: run by bash (``set -e``) from the checkout's root, with the venv's ``bin`` first
  on PATH; it must exit 0;
- ``python``: run by the venv's Python from a temporary folder; it must exit 0;
- ``c``: compiled with ``cc -std=c99 -Wall -Wextra -Wpedantic -Werror`` against the
  core's headers and sources (``src/``), run, and it must exit 0.

Where a block's previous line is ``<!-- example: output -->`` instead, its text is what
the example block before it prints (each line of it must appear in that output).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from dyadfmu import paths

ROOT = paths.ROOT
#: every Markdown file of the checkout (tracked or not), but those of builds and outputs
SKIP = ("build", "out", ".venv", "node_modules", ".git")
DOCUMENTS = sorted(
    p
    for p in ROOT.rglob("*.md")
    if not any(
        part in SKIP or part.startswith(("build-", ".")) for part in p.relative_to(ROOT).parts
    )
)
LINK = re.compile(r"(?<!!)\[[^\]\n]*\]\(([^)\s]+)\)|!\[[^\]\n]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```([a-z]*)\n(.*?)^```", re.S | re.M)


def slug(heading: str) -> str:
    """A heading's anchor as GitHub makes it: lower case, punctuation dropped, spaces to
    hyphens."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """Every heading's anchor in a Markdown file (repeated headings get -1, -2, ...)."""
    seen: dict[str, int] = {}
    out = set()
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    for line in text.splitlines():
        m = re.match(r"^#{1,6} (.*)$", line)
        if m:
            base = slug(m.group(1))
            n = seen.get(base, 0)
            seen[base] = n + 1
            out.add(base if n == 0 else f"{base}-{n}")
    return out


def links(path: Path) -> list[tuple[int, str]]:
    """(line, target) of every link of a Markdown file outside code blocks."""
    text = path.read_text(encoding="utf-8")
    blanked = FENCE.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    blanked = re.sub(r"`[^`\n]*`", "", blanked)
    found = []
    for number, line in enumerate(blanked.splitlines(), 1):
        for m in LINK.finditer(line):
            found.append((number, m.group(1) or m.group(2)))
    return found


def _relative(target: str) -> bool:
    return not re.match(r"^[a-z][a-z0-9+.-]*:", target)


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_and_anchor_resolves(document):
    broken = []
    for number, target in links(document):
        if not _relative(target):
            continue
        file, _, anchor = target.partition("#")
        where = (document.parent / file).resolve() if file else document
        if not where.exists():
            broken.append(f"{document.name}:{number}: {target}: no such file")
        elif anchor and where.suffix == ".md" and anchor not in anchors(where):
            broken.append(f"{document.name}:{number}: {target}: no such heading")
    assert not broken, "\n".join(broken)


def examples() -> list[tuple[Path, int, str, str, str | None]]:
    """(document, line, language, code, expected output or None) of every example."""
    found = []
    for document in DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        blocks = list(FENCE.finditer(text))
        for k, m in enumerate(blocks):
            before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1].strip()
            if before != "<!-- example -->":
                continue
            expected = None
            if k + 1 < len(blocks):
                nxt = blocks[k + 1]
                between = text[m.end() : nxt.start()].strip()
                if between == "<!-- example: output -->":
                    expected = nxt.group(2)
            line = text.count("\n", 0, m.start()) + 1
            found.append((document, line, m.group(1), m.group(2), expected))
    return found


def _environment(tmp_path: Path) -> dict:
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    # absolute: the Python examples run from a temporary folder
    env["DYADFMU_BUILD"] = str((ROOT / paths.build_dir()).resolve())
    # an example's `mktemp -d` (its --out) inside the test's folder, which pytest removes
    env["TMPDIR"] = str(tmp_path)
    return env


def _run(language: str, code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = _environment(tmp_path)
    if language == "sh":
        return subprocess.run(
            ["bash", "-e", "-c", code], cwd=ROOT, env=env, capture_output=True, text=True
        )
    if language == "python":
        return subprocess.run(
            [sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True
        )
    if language == "c":
        source = tmp_path / "example.c"
        source.write_text(code)
        cores = [str(p) for p in sorted((ROOT / "src").glob("dyad_*.c"))]
        flags = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O1"]
        include = ["-I", str(ROOT / "src" / "include"), "-I", str(ROOT / "src")]
        binary = tmp_path / "example"
        done = subprocess.run(
            ["cc", *flags, *include, str(source), *cores, "-lm", "-o", str(binary)],
            capture_output=True,
            text=True,
        )
        if done.returncode != 0:
            return done
        return subprocess.run([str(binary)], cwd=tmp_path, capture_output=True, text=True)
    pytest.fail(f"an example in {language or 'no language'}: say sh, python or c")


@pytest.mark.parametrize(
    "document,line,language,code,expected",
    examples(),
    ids=lambda x: str(x.relative_to(ROOT)) if isinstance(x, Path) else None,
)
def test_every_example_runs_as_printed(document, line, language, code, expected, tmp_path):
    done = _run(language, code, tmp_path)
    where = f"{document.relative_to(ROOT)}:{line}"
    assert done.returncode == 0, f"{where}:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    if expected is not None:
        for want in expected.strip().splitlines():
            assert want.strip() in done.stdout, f"{where}: {want!r} not in\n{done.stdout}"


def test_a_broken_link_or_anchor_is_found(tmp_path):
    """The checks can fail: a link to a missing file and one to a missing heading."""
    doc = tmp_path / "a.md"
    (tmp_path / "b.md").write_text("# Only heading\n\n## Second `code` part\n")
    doc.write_text(
        "See [b](b.md#only-heading), [c](b.md#second-code-part), [x](missing.md), "
        "[y](b.md#nothing) and `[z](skipped.md)`.\n"
    )
    targets = [t for _, t in links(doc)]
    assert targets == ["b.md#only-heading", "b.md#second-code-part", "missing.md", "b.md#nothing"]
    assert anchors(tmp_path / "b.md") == {"only-heading", "second-code-part"}

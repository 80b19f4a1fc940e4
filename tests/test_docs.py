"""Every example in the docs (and the README) runs.

Conventions for fenced blocks: ```fsl is a whole spec, which must check without errors;
```python blocks of one page run in order in one namespace, from the repository root;
```console blocks hold `$ fossilc ...` commands, each followed by its documented output:
the command must exit as the output says (1 for NOT CERTIFIED, 2 for an error, else 0)
and every documented line without digits (timings and weights vary) must be printed.
```sh, ```text and untagged blocks are not examples (installs, templates).
"""
from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

import fossil_dsl

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "README.md"]
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)


def blocks(page: Path, kind: str) -> list[str]:
    return [body for tag, body in FENCE.findall(page.read_text()) if tag == kind]


def cases(kind: str):
    return [pytest.param(page, body, id=f"{page.relative_to(ROOT)}#{i}")
            for page in PAGES for i, body in enumerate(blocks(page, kind))]


@pytest.mark.parametrize("page, body", cases("fsl"))
def test_fsl_examples_check(page, body):
    result = fossil_dsl.check_text(body, f"{page.name}")
    assert result.ok, result.render()


@pytest.mark.parametrize("page", [p for p in PAGES if blocks(p, "python")],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_python_examples_run(page, tmp_path):
    """In a process of their own (an example may register a certificate), from a copy
    of the repository's specs."""
    script = tmp_path / "example.py"
    script.write_text("\n".join(blocks(page, "python")))
    (tmp_path / "specs").symlink_to(ROOT / "specs")
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr


def commands(body: str) -> list[tuple[str, list[str]]]:
    found: list[tuple[str, list[str]]] = []
    for line in body.splitlines():
        if line.startswith("$ "):
            found.append((line[2:], []))
        elif found:
            found[-1][1].append(line)
    return found


def console_cases():
    return [pytest.param(command, output, id=f"{page.relative_to(ROOT)}: {command[:60]}")
            for page in PAGES for body in blocks(page, "console")
            for command, output in commands(body)]


@pytest.mark.parametrize("command, output", console_cases())
def test_console_examples_run_as_shown(command, output, fossilc):
    """Run through the session's shared runs (tests/conftest.py): test_region.py looks
    into what the tutorial's largest-region commands produced."""
    words = shlex.split(command)
    assert words[0] == "fossilc", f"docs commands are fossilc commands: {command}"
    run = fossilc(words[1:])
    printed = run.stdout + run.stderr
    text = "\n".join(output)
    expected = 2 if "error:" in text else 1 if "NOT CERTIFIED" in text else 0
    assert run.returncode == expected, printed
    for line in output:
        if line.strip() and not re.search(r"\d", line) and "..." not in line:
            assert line.strip() in printed, f"documented but not printed: {line!r}\n{printed}"

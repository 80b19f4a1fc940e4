"""The pipeline flows one way: a stage imports only the stages before it."""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "fossil_dsl"

# What each part of the package may import from the package (besides itself).
ALLOWED = {
    "version": set(),
    "diagnostics": set(),
    "ir": {"diagnostics"},
    "syntax": {"diagnostics"},
    "smt": {"diagnostics", "ir"},
    "check": {"diagnostics", "ir", "syntax", "smt"},
    "certificates": {"diagnostics", "ir"},
    "plan": {"diagnostics", "ir", "certificates", "smt"},
    "learn": {"ir"},
    "cegis": {"ir", "certificates", "learn", "plan", "smt"},
    "plot": {"diagnostics", "ir", "learn"},
    "result": {"version", "ir", "learn", "plan", "plot", "cegis", "smt"},
    "recheck": {"diagnostics", "ir", "smt"},
    "extend": {"ir", "check", "certificates"},
    "build": {"diagnostics", "ir", "syntax", "check", "learn"},
    "api": {"build", "diagnostics", "ir", "syntax", "check", "plan", "cegis", "result", "smt"},
    "bench": {"version", "diagnostics", "api", "plan"},
    "cli": {"version", "diagnostics", "api", "plan", "result", "smt", "bench", "recheck", "plot",
            "yaml_import"},
    "yaml_import": {"diagnostics", "syntax"},
}


def part_of(path: Path) -> str:
    relative = path.relative_to(PACKAGE)
    return relative.parts[0] if len(relative.parts) > 1 else relative.stem


def is_part(name: str) -> bool:
    return (PACKAGE / name).is_dir() or (PACKAGE / f"{name}.py").is_file()


def imported_parts(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    parts = set()
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        for name in names:
            pieces = name.split(".")
            if pieces[0] == "fossil_dsl":
                parts.add(pieces[1] if len(pieces) > 1 and is_part(pieces[1]) else "__init__")
    return parts


MODULES = sorted(p for p in PACKAGE.rglob("*.py") if part_of(p) != "__init__")


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_only_earlier_stages(path):
    part = part_of(path)
    assert part in ALLOWED, f"{part} is not placed in the pipeline (add it to ALLOWED)"
    upward = imported_parts(path) - ALLOWED[part] - {part}
    assert not upward, f"{path.name} ({part}) imports later stages: {sorted(upward)}"


def test_solvers_are_imported_lazily():
    """Only the backend modules themselves import a solver package at top level."""
    for path in MODULES:
        if path.name.endswith("_backend.py"):
            continue
        top_level = {n.names[0].name.split(".")[0] for n in ast.parse(path.read_text()).body
                     if isinstance(n, ast.Import)}
        top_level |= {n.module.split(".")[0] for n in ast.parse(path.read_text()).body
                      if isinstance(n, ast.ImportFrom) and n.module}
        assert not top_level & {"cvc5", "dreal"}, path


def test_no_eval_or_exec_anywhere():
    for path in MODULES:
        tree = ast.parse(path.read_text())
        calls = {n.func.id for n in ast.walk(tree)
                 if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
        assert not calls & {"eval", "exec", "compile", "sympify"}, path

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
    # the proof kernel: the IR and the solvers only (no learner, no torch)
    "kernel": {"ir", "smt"},
    "plan": {"diagnostics", "ir", "certificates", "smt", "kernel"},
    "learn": {"ir"},
    "cegis": {"ir", "certificates", "learn", "plan", "smt"},
    "plot": {"diagnostics", "ir", "learn"},
    "result": {"version", "ir", "learn", "plan", "plot", "cegis", "smt", "kernel"},
    "recheck": {"diagnostics", "ir", "smt", "syntax", "check", "kernel"},
    "extend": {"ir", "check", "certificates", "kernel"},
    "build": {"diagnostics", "ir", "syntax", "check", "learn", "smt"},
    "api": {"build", "diagnostics", "ir", "syntax", "check", "plan", "cegis", "result", "smt",
            "kernel"},
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


def test_kernel_imports_no_learner():
    """Nothing in the kernel can reach torch or the learner, even lazily."""
    for path in sorted((PACKAGE / "kernel").glob("*.py")):
        imported = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imported |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module:
                imported.add(node.module.split(".")[0])
                imported.add(".".join(node.module.split(".")[:2]))
        assert not imported & {"torch", "fossil_dsl.learn", "fossil_dsl.cegis",
                               "fossil_dsl.certificates", "fossil_dsl.plan"}, path

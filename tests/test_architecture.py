"""The pipeline flows one way: a stage imports only the stages before it."""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "fossil_dsl"

# What each part of the package may import from the package (besides itself). The folders
# are the pipeline: syntax -> check -> plan -> engine -> outputs, with the kernel apart (it
# sees only the IR and the solvers) and the front ends on top.
ALLOWED = {
    "version": set(),
    "diagnostics": set(),
    "ir": {"diagnostics"},
    "solvers": {"diagnostics", "ir"},
    # the proof kernel: the IR and the solvers only (no learner, no torch, no plan)
    "kernel": {"ir", "solvers"},
    "syntax": {"diagnostics"},
    "check": {"diagnostics", "ir", "syntax", "solvers"},
    "plan": {"diagnostics", "ir", "solvers", "kernel"},
    # the engine asks the kernel for its obligations, to hand it evidence (sum-of-squares
    # refutations) that the kernel checks exactly: evidence, never a verdict
    "engine": {"ir", "plan", "solvers", "kernel"},
    "outputs": {"version", "diagnostics", "ir", "syntax", "check", "plan", "engine", "solvers",
                "kernel"},
    "extend": {"ir", "check", "plan", "kernel"},
    # jobs and where they run (local processes, Dask workers): data in, data out
    "cluster": {"version", "ir", "solvers"},
    "frontends": {"version", "diagnostics", "ir", "syntax", "check", "plan", "engine",
                  "outputs", "solvers", "kernel", "cluster"},
}
MAX_LINES = 350


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
        assert not imported & {"torch", "fossil_dsl.engine", "fossil_dsl.plan",
                               "fossil_dsl.outputs", "fossil_dsl.frontends"}, path


def test_no_module_is_over_the_size_where_one_job_fits():
    long = {str(p.relative_to(PACKAGE)): n for p in MODULES
            if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path, known: set[str]) -> set[str]:
    """The package's modules that `path` imports, at any depth (a circle closed by an
    import inside a function is still a circle)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            candidates = [f"{node.module}.{a.name}" for a in node.names] + [node.module]
        elif isinstance(node, ast.Import):
            candidates = [a.name for a in node.names]
        else:
            continue
        found |= {c for c in candidates if c in known}
    return found


def import_graph() -> dict[str, set[str]]:
    paths = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph = {name: imported_modules(path, set(paths)) - {name} for name, path in paths.items()}
    # a package's __init__ importing its own modules is not a circle of jobs
    return {name: {m for m in deps if not m.startswith(name + ".")}
            for name, deps in graph.items()}


def test_no_import_circles():
    circles = [c for c in strongly_connected(import_graph()) if len(c) > 1]
    assert not circles, f"modules importing each other: {circles}"


def test_the_circle_finder_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert sorted(map(sorted, strongly_connected(graph))) == [["a", "b", "c"], ["d"]]


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's algorithm."""
    index, low, stack, on_stack, result = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while not component or component[-1] != node:
                component.append(stack.pop())
                on_stack.discard(component[-1])
            result.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return result


HEAVY = ("torch", "sympy", "matplotlib", "cvc5", "codac")


@pytest.mark.parametrize("command", [["--help"], ["--version"],
                                     ["check", "specs/stability_continuous.fsl"],
                                     ["check", "specs/rar_controlled.fsl"]])
def test_commands_that_learn_nothing_import_no_heavy_library(command):
    """`fossilc --help` and `fossilc check` run in an editor loop: no torch, sympy,
    matplotlib, cvc5 or codac at start-up (python -X importtime lists every import)."""
    run, imported = _run_listing_imports(command)
    assert run.returncode == 0, run.stderr[-2000:]
    assert not imported & set(HEAVY), sorted(imported & set(HEAVY))


def _run_listing_imports(command):
    """`fossilc COMMAND` under python -X importtime, and the modules it imported."""
    import subprocess
    import sys
    run = subprocess.run([sys.executable, "-X", "importtime", "-m", "fossil_dsl.frontends.cli",
                          *command], cwd=PACKAGE.parent, capture_output=True, text=True,
                         timeout=300)
    imported = {line.rsplit("|", 1)[-1].strip() for line in run.stderr.splitlines()
                if line.startswith("import time:")}
    return run, imported


VERIFIER_ONLY = """\
state x0, x1
dynamics continuous {
    x0' = -x0 + x0*x1
    x1' = -x1
}
domain ball([0, 0], 1)
set I = ball([0.3, 0], 0.1)
prove from I: stable
synthesis {
    candidate: x0^2 + x1^2
}
"""


def test_a_verifier_only_run_imports_no_torch(tmp_path):
    """`candidate:` with nothing to learn: the levels come from numpy samples; the run,
    its -o files and its phase portrait need no torch (and it certifies)."""
    spec = tmp_path / "given.fsl"
    spec.write_text(VERIFIER_ONLY)
    run, imported = _run_listing_imports([str(spec), "-o", str(tmp_path / "out"), "--plot"])
    assert run.returncode == 0, run.stdout + run.stderr[-2000:]
    assert "CERTIFIED" in run.stdout and "level beta = " in run.stdout
    assert "torch" not in imported
    assert (tmp_path / "out" / "phase_portrait.png").exists()
    assert not (tmp_path / "out" / "networks.pt").exists()  # nothing was trained


@pytest.mark.parametrize("spec", ["specs/probe45/z02_lorenz_subcritical_stable.fsl",
                                  "specs/probe45/z28_bilinear_reach_4d.fsl"])
def test_a_run_certified_without_learning_imports_no_torch(spec, tmp_path):
    """A sum-of-squares Lyapunov function, a sum-of-squares reach certificate: torch and
    torch._dynamo were 2-3 s of the 4.5 s such a `fossilc` call took."""
    run, imported = _run_listing_imports([spec, "-o", str(tmp_path / "out")])
    assert run.returncode == 0, run.stdout + run.stderr[-2000:]
    assert "CERTIFIED" in run.stdout and "sum-of-squares" in run.stdout
    assert "torch" not in imported


LEARNING_RUN_TIMES = """\
import time
import fossil_dsl
from fossil_dsl.engine import torch_import
spec = fossil_dsl.load("specs/stability_controlled.fsl")  # learned, in under a second
started = time.monotonic()
result = fossil_dsl.synthesise(spec, timeout=60)
print(result.certified, result.total_seconds, torch_import.seconds_spent(),
      time.monotonic() - started)
"""


def test_a_run_that_learns_leaves_the_torch_import_out_of_its_time():
    import subprocess
    import sys
    run = subprocess.run([sys.executable, "-c", LEARNING_RUN_TIMES], cwd=PACKAGE.parent,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    certified, total, imported, wall = run.stdout.split()[-4:]
    assert certified == "True"
    assert float(imported) > 0.1  # torch was imported in the run, and timed
    assert float(total) + float(imported) <= float(wall) + 0.01

"""Verifier backends by name, imported only when used (a missing solver never breaks
the others). A new backend is one module with one class plus one entry here."""
from __future__ import annotations

import importlib
import importlib.util
from dataclasses import dataclass

from fossil_dsl.diagnostics import FslError
from fossil_dsl.solvers.api import Backend


@dataclass(frozen=True)
class BackendInfo:
    name: str
    module: str  # fossil_dsl module holding the class
    class_name: str
    requires: str  # the Python package the backend needs
    transcendental: bool  # can decide sin, exp, ... (possibly delta-complete)
    summary: str
    rank: int  # preference among backends for transcendental problems (lower first)
    delta_decision: bool = False  # UNSAT is sound, SAT means delta-SAT (closed relaxation)
    caveat: str = ""  # what a proof by this backend assumes beyond UNSAT
    search_option: str = ""  # keyword for a faster mode whose answers are leads only


BACKENDS: dict[str, BackendInfo] = {b.name: b for b in (
    BackendInfo("z3", "fossil_dsl.solvers.z3_backend", "Z3Backend", "z3", False,
                "Z3, complete for polynomial real arithmetic", 9),
    BackendInfo("cvc5", "fossil_dsl.solvers.cvc5_backend", "Cvc5Backend", "cvc5", True,
                "CVC5, polynomial arithmetic and some transcendental queries", 3),
    BackendInfo("dreal", "fossil_dsl.solvers.dreal_backend", "DrealBackend", "dreal", True,
                "dReal, delta-complete for transcendental functions (optional)", 1, True,
                "dReal's API reads each exact constant as the nearest double"),
    BackendInfo("interval", "fossil_dsl.solvers.interval_backend", "IntervalBackend", "codac",
                True, "a delta-decision procedure on outward-rounded interval arithmetic", 2,
                True, search_option="leads_only"),
)}


class BackendUnavailable(FslError):
    pass


def names() -> tuple[str, ...]:
    return tuple(BACKENDS)


def is_installed(name: str) -> bool:
    info = BACKENDS[name]
    return (importlib.util.find_spec(info.requires) is not None
            and importlib.util.find_spec(info.module) is not None)


def load(name: str, delta: float | None = None, search: bool = False) -> Backend:
    """The backend called `name`; `delta` sets a delta-decision verifier's precision.
    `search`: its answers only guide the CEGIS loop (the kernel proves afresh), so a
    backend with a faster mode whose answers are leads, not proofs, may use it."""
    info = BACKENDS[name]
    if not is_installed(name):
        others = ", ".join(n for n in BACKENDS if n != name and is_installed(n))
        raise BackendUnavailable(
            f"verifier `{name}` is not available on this machine (it needs the Python "
            f"package `{info.requires}`); available: {others}")
    module = importlib.import_module(info.module)
    backend = getattr(module, info.class_name)
    options = {"delta": delta} if info.delta_decision and delta else {}
    if search and info.search_option:
        options[info.search_option] = True
    return backend(**options)

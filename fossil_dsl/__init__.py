"""fossil_dsl: prove properties of dynamical systems, and synthesise controllers, from
.fsl specifications.

    import fossil_dsl
    spec = fossil_dsl.load("specs/paper_lyapunov.fsl")     # a CheckedSpec
    result = fossil_dsl.check_file("spec.fsl")             # diagnostics as objects
    outcome = fossil_dsl.synthesise(spec, seed=1)          # learn and prove: a Result
    outcome = fossil_dsl.race(spec, 4, cluster=None)       # 4 seeds race; the first wins
    outcome.sympy["V"], outcome.networks["V"]              # sympy formula, torch module
    outcome.save("out"); outcome.plot("portrait.png")      # artefacts, phase portrait
    spec = fossil_dsl.build_spec(...)                      # a spec built in Python
"""
from fossil_dsl.diagnostics import Diagnostic, FslError, Severity, SpecError, SpecSyntaxError
from fossil_dsl.frontends.checking import (CheckResult, check_file, check_source, check_text,
                                           load, loads, parse)
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.version import __version__

# Names whose modules import torch or sympy are loaded on first use (PEP 562), so that
# `import fossil_dsl` and `fossilc check` stay fast.
_LAZY = {"synthesise": "fossil_dsl.frontends.api", "Result": "fossil_dsl.outputs.result",
         "BespokeSet": "fossil_dsl.frontends.build", "BuildError": "fossil_dsl.frontends.build",
         "build_spec": "fossil_dsl.frontends.build", "spec_text": "fossil_dsl.frontends.build",
         "OptionError": "fossil_dsl.frontends.arguments",
         "load_result": "fossil_dsl.outputs.load", "race": "fossil_dsl.frontends.portfolio", "LoadError": "fossil_dsl.outputs.load"}

__all__ = ["BespokeSet", "BuildError", "CheckResult", "CheckedSpec", "Result", "build_spec",
           "spec_text", "Diagnostic", "FslError", "LoadError", "OptionError", "Severity", "SpecError",
           "SpecSyntaxError", "check_file", "check_source", "check_text", "load", "loads",
           "load_result", "parse", "race", "synthesise", "__version__"]


def __getattr__(name: str):
    if name in _LAZY:
        import importlib
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'fossil_dsl' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))

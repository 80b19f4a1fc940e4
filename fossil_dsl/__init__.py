"""fossil_dsl: prove properties of dynamical systems, and synthesise controllers, from
.fsl specifications.

    import fossil_dsl
    spec = fossil_dsl.load("specs/paper_lyapunov.fsl")     # a CheckedSpec
    result = fossil_dsl.check_file("spec.fsl")             # diagnostics as objects
    outcome = fossil_dsl.synthesise(spec, seed=1)          # learn and prove: a Result
    outcome.sympy["V"], outcome.networks["V"]              # sympy formula, torch module
    outcome.save("out"); outcome.plot("portrait.png")      # artefacts, phase portrait
    spec = fossil_dsl.build_spec(...)                      # a spec built in Python
"""
from fossil_dsl.api import (BespokeSet, BuildError, CheckResult, build_spec, check_file,
                            check_source, check_text, load, loads, parse, spec_text,
                            synthesise)
from fossil_dsl.result import Result
from fossil_dsl.diagnostics import Diagnostic, FslError, Severity, SpecError, SpecSyntaxError
from fossil_dsl.ir.spec import CheckedSpec

from fossil_dsl.version import __version__

__all__ = ["BespokeSet", "BuildError", "CheckResult", "CheckedSpec", "Result", "build_spec",
           "spec_text", "Diagnostic", "FslError", "Severity", "SpecError",
           "SpecSyntaxError", "check_file", "check_source", "check_text", "load", "loads",
           "parse", "synthesise", "__version__"]

"""fossil_dsl: prove properties of dynamical systems, and synthesise controllers, from
.fsl specifications.

    import fossil_dsl
    spec = fossil_dsl.load("specs/paper_lyapunov.fsl")     # a CheckedSpec
    result = fossil_dsl.check_file("spec.fsl")             # diagnostics as objects
    outcome = fossil_dsl.synthesise(spec, seed=1)          # learn and prove
"""
from fossil_dsl.api import (CheckResult, check_file, check_source, check_text, load, loads,
                            parse, synthesise)
from fossil_dsl.diagnostics import Diagnostic, FslError, Severity, SpecError, SpecSyntaxError
from fossil_dsl.ir.spec import CheckedSpec

from fossil_dsl.version import __version__

__all__ = ["CheckResult", "CheckedSpec", "Diagnostic", "FslError", "Severity", "SpecError",
           "SpecSyntaxError", "check_file", "check_source", "check_text", "load", "loads",
           "parse", "synthesise", "__version__"]

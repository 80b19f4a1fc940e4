"""What a user needs to add a property form and its certificate from outside the package,
in one place (docs/extending.md has a worked example):

    from fossil_dsl.extend import Certificate, Condition, PropertyForm, register, ...

A `PropertyForm` registered with `register_form` teaches the checker a new `prove`
formula; a `Certificate` subclass decorated with `@register` (its `form` naming the
property form) tells the compiler how to search for a certificate, and a `kernel_rule`
tells the kernel what must be proved before the run is CERTIFIED. Nothing else changes:
the learner gets one loss term per condition and the verifier one query per condition.
"""
from fossil_dsl.plan.certificates import (Certificate, Condition, LearnedFunction, Level,
                                     change_of, level_of, register, value_of)
from fossil_dsl.check.properties import PropertyForm, register_form
from fossil_dsl.ir import expr, logic, sets
from fossil_dsl.ir.spec import Layer
from fossil_dsl.kernel.obligations import Facts
from fossil_dsl.kernel.registry import rule as kernel_rule

__all__ = ["Certificate", "Condition", "Facts", "LearnedFunction", "Layer", "Level",
           "PropertyForm", "kernel_rule",
           "change_of", "expr", "level_of", "logic", "register", "register_form", "sets",
           "value_of"]

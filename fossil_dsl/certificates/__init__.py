"""Certificate rules: one file per rule, registered by the property form it proves."""
from fossil_dsl.certificates import barrier, lyapunov  # noqa: F401  (registration)
from fossil_dsl.certificates.base import (Certificate, Condition, LearnedFunction,
                                          certificate_for, register)

__all__ = ["Certificate", "Condition", "LearnedFunction", "certificate_for", "register"]

"""Certificate rules: one file per rule, registered by the property form it proves.

Every module of this package is imported here, so a new rule is one new file."""
import importlib
import pkgutil

from fossil_dsl.plan.certificates.base import (Certificate, Condition, LearnedFunction, Level,
                                          certificate_for, change_of, level_of, register,
                                          value_of)

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")

__all__ = ["Certificate", "Condition", "LearnedFunction", "Level", "certificate_for",
           "change_of", "level_of", "register", "value_of"]

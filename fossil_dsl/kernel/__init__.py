"""The proof kernel: the only part of fossil_dsl that can say CERTIFIED.

It takes the checked spec and the final exact functions (a `Claim`), derives every
obligation the guarantee rests on (`obligations.py`; the rules by property and time
domain in `registry.py`: `rules.py`, `safety_rules.py`, `inward_rules.py`, `step_rules.py`
for difference equations; `definedness.py`), discharges each with a sound procedure (`prove.py`) and
returns the verdict (`verdict.py`: the main rule, else its variants). It imports the IR and the solvers only: no torch, no learner.
"""
from fossil_dsl.kernel.obligations import Claim, NoRule, Obligation
from fossil_dsl.kernel.registry import guarantee_text
from fossil_dsl.kernel.prove import Outcome, Proof
from fossil_dsl.kernel.verdict import Verdict, judge, list_obligations, not_certified

__all__ = ["Claim", "NoRule", "Obligation", "Outcome", "Proof", "Verdict", "guarantee_text",
           "judge", "list_obligations", "not_certified"]

"""Barrier programs for fields with elementary functions (engine/sos_barrier.py): each
application becomes a variable bounded by its facts (solvers/atom_facts.py), so the
found B satisfies the flow condition for every function obeying them."""
import time

import fossil_dsl
from fossil_dsl.engine import sos, sos_barrier
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.plan.compile import compile_spec
from fossil_dsl.solvers.atom_facts import abstracted_terms

FRICTION = """\
spec friction
state x, v
dynamics continuous {
    x' = v
    v' = -x - 0.1*v - 0.3*tanh(3*v)
}
domain box([-1.5, -1.5], [1.5, 1.5])
set init = box([0.2, -0.05], [0.3, 0.05])
set unsafe = { x >= 1 }
prove from init: always not unsafe
"""


def test_a_tanh_friction_oscillator_gets_a_barrier_the_kernel_proves_by_refutations():
    """A mass with smoothed Coulomb friction: the learned barriers' flow condition took
    the interval procedure minutes in the 6-state chain of probe61/ag03."""
    plan = compile_spec(fossil_dsl.loads(FRICTION))
    assert sos.applies(plan)
    found = sos_barrier.barrier(plan, time.monotonic() + 30)
    assert found is not None and found.margin > 0 and "facts" in found.condition
    assert E.free_vars(found.formula) <= {"x", "v"}
    result = fossil_dsl.synthesise(fossil_dsl.loads(FRICTION), timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming")


def test_pumping_friction_gets_no_barrier():
    """The same with the friction reversed (it feeds energy in): orbits from I grow
    until they reach x >= 1, so no B may be found."""
    plan = compile_spec(fossil_dsl.loads(FRICTION.replace("- 0.3*tanh", "+ 0.3*tanh")))
    assert sos_barrier.barrier(plan, time.monotonic() + 30) is None


def test_the_field_is_rewritten_with_one_variable_per_application_and_its_facts():
    x, v = E.Var("x"), E.Var("v")
    tanh = E.Apply("tanh", E.mul(E.Num(3), v))
    region = L.conjunction(L.Compare("<=", v, E.Num(1)), L.Compare(">=", v, E.Num(-1)))
    terms, facts, names = abstracted_terms([v, E.add(x, tanh, tanh)], region, ("x", "v"))
    assert len(names) == 3 and names[:2] == ("x", "v")  # the two tanh(3v) are one
    assert E.free_vars(terms[1]) == {"x", names[2]}
    assert len(facts) == 3  # t^2 <= 1, between 0 and 3v, between 3v and k 3v on |3v| <= 3
    assert abstracted_terms([E.Apply("log", E.add(E.Num(2), x))], region, ("x", "v")) is None

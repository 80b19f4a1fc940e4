"""dReal, through its Python API, where it is installed (`pip install fossil_dsl[dreal]`
on a machine whose dReal wheel finds its libibex.so). Never required: the registry
imports this module only when `dreal` can be imported.

dReal is a delta-decision procedure: UNSAT is a proof, delta-SAT a lead. Each query runs
in a child process, so that a timeout can end it (the API has no interrupt).
"""
from __future__ import annotations

import multiprocessing
import time
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory

DELTA = 1e-3


class DrealBackend:
    name = "dreal"

    def __init__(self, delta: float = DELTA):
        self.delta = delta

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop=None) -> Answer:
        names = sorted(set(variables) | L.free_vars(formula))
        receiver, sender = multiprocessing.Pipe(duplex=False)
        worker = multiprocessing.Process(target=_solve_in_child,
                                         args=(formula, names, self.delta, sender))
        worker.start()
        sender.close()
        try:
            if not _wait(receiver, timeout, stop):
                return Answer(Status.UNKNOWN, reason=f"dReal stopped or timed out "
                              f"(after at most {timeout:g} s)")
            status, model, reason = receiver.recv()
        except EOFError:
            return Answer(Status.UNKNOWN, reason="dReal stopped without an answer")
        finally:
            worker.terminate()
            worker.join()
        if status == "unsat":
            return Answer(Status.UNSAT)
        if status == "sat":
            point = {name: Fraction(value) for name, value in model.items()}
            return Answer(Status.SAT, {v: point[v] for v in variables if v in point},
                          reason=f"delta-sat (delta = {self.delta:g})", approximate=True)
        return Answer(Status.UNKNOWN, reason=reason)


def _solve_in_child(formula, names, delta, sender) -> None:
    import dreal
    try:
        variables = {name: dreal.Variable(name) for name in names}
        query = _Translator(dreal, variables).formula(formula)
        box = dreal.CheckSatisfiability(query, delta)
    except UnsupportedTheory as exc:
        sender.send(("unknown", None, str(exc)))
        return
    if box is None:
        sender.send(("unsat", None, ""))
    else:
        sender.send(("sat", {n: box[v].mid() for n, v in variables.items()}, ""))


class _Translator:
    def __init__(self, dreal, variables):
        self.dreal = dreal
        self.variables = variables

    def formula(self, formula: L.Formula):
        dreal = self.dreal
        if isinstance(formula, L.BoolConst):
            return dreal.Formula.TRUE() if formula.value else dreal.Formula.FALSE()
        if isinstance(formula, L.Not):
            return dreal.Not(self.formula(formula.arg))
        if isinstance(formula, L.Compare):
            left, right = self.expr(formula.left), self.expr(formula.right)
            return {"<": left < right, "<=": left <= right, ">": left > right,
                    ">=": left >= right}[formula.relation]
        parts = [self.formula(arg) for arg in formula.args]
        return dreal.And(*parts) if isinstance(formula, L.And) else dreal.Or(*parts)

    def expr(self, expr: E.Expr):
        dreal = self.dreal
        if isinstance(expr, E.Num):
            # dReal's API takes doubles: the nearest double to the exact constant
            return dreal.Expression(float(expr.value))
        if isinstance(expr, E.Pi):
            return dreal.Expression(3.141592653589793)
        if isinstance(expr, E.Var):
            return dreal.Expression(self.variables[expr.name])
        if isinstance(expr, E.Neg):
            return -self.expr(expr.operand)
        if isinstance(expr, E.Add):
            return sum((self.expr(t) for t in expr.terms[1:]), self.expr(expr.terms[0]))
        if isinstance(expr, E.Mul):
            result = self.expr(expr.factors[0])
            for factor in expr.factors[1:]:
                result = result * self.expr(factor)
            return result
        if isinstance(expr, E.Div):
            return self.expr(expr.numerator) / self.expr(expr.denominator)
        if isinstance(expr, E.Pow):
            return self.expr(expr.base) ** self.expr(expr.exponent)
        if isinstance(expr, E.Apply) and hasattr(dreal, expr.func):
            return getattr(dreal, expr.func)(self.expr(expr.arg))
        raise UnsupportedTheory(f"dReal cannot express {expr!r}")


def _wait(receiver, timeout: float, stop) -> bool:
    """Whether an answer arrived within `timeout`, unless `stop` was set first."""
    end = time.monotonic() + timeout
    while (left := end - time.monotonic()) > 0:
        if receiver.poll(min(left, 0.05)):
            return True
        if stop is not None and stop.is_set():
            return False
    return False

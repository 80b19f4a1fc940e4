"""Z3: converts neutral formulas to Z3 terms and decides them (nonlinear real arithmetic).

Closed irrational constants (pi, sqrt(2), sin(1)) become fresh variables bounded by a
sound enclosure; the answer then carries `approximate=True`.
"""
from __future__ import annotations

import _thread
import threading
import time
from fractions import Fraction
from typing import Sequence

import z3

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import bounds
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory

STOP_POLL = 0.02  # s between looks at whether to interrupt Z3
KEYBOARD = "interrupted from keyboard"  # Z3's reason after Ctrl-C
ABANDON_AFTER = 5.0  # s after its interrupt that a check still running is left behind
LEFT_BEHIND = "Z3 did not stop when interrupted; its check was left behind"
CANCELED = "Z3's check was canceled (its timeout or an interrupt)"


class Z3Converter:
    def __init__(self, context: z3.Context):
        self.context = context
        self.variables: dict[str, z3.ArithRef] = {}
        self.side_conditions: list[z3.BoolRef] = []
        self.constants: dict[E.Expr, z3.ArithRef] = {}  # the same constant, one variable

    def var(self, name: str) -> z3.ArithRef:
        if name not in self.variables:
            self.variables[name] = z3.Real(name, self.context)
        return self.variables[name]

    def number(self, value: Fraction) -> z3.ArithRef:
        return z3.RealVal(f"{value.numerator}/{value.denominator}", self.context)

    def formula(self, formula: L.Formula) -> z3.BoolRef:
        if isinstance(formula, L.Compare):
            left, right = self.expr(formula.left), self.expr(formula.right)
            return {"<=": left <= right, "<": left < right,
                    ">=": left >= right, ">": left > right}[formula.relation]
        if isinstance(formula, L.And):
            return z3.And([self.formula(a) for a in formula.args])
        if isinstance(formula, L.Or):
            return z3.Or([self.formula(a) for a in formula.args])
        if isinstance(formula, L.Not):
            return z3.Not(self.formula(formula.arg))
        if isinstance(formula, L.BoolConst):
            return z3.BoolVal(formula.value, self.context)
        raise TypeError(f"not a formula: {formula!r}")

    def expr(self, expr: E.Expr) -> z3.ArithRef:
        if isinstance(expr, E.Num):
            return self.number(expr.value)
        if isinstance(expr, E.Var):
            return self.var(expr.name)
        if not E.free_vars(expr) and not traversal.is_arithmetic(expr):
            return self._enclosed_constant(expr)
        if isinstance(expr, E.Add):
            return z3.Sum([self.expr(t) for t in expr.terms])
        if isinstance(expr, E.Mul):
            return z3.Product([self.expr(f) for f in expr.factors])
        if isinstance(expr, E.Neg):
            return -self.expr(expr.operand)
        if isinstance(expr, E.Div):
            return self.expr(expr.numerator) / self.expr(expr.denominator)
        if isinstance(expr, E.Pow):
            return self._power(expr)
        if isinstance(expr, E.Apply) and expr.func == "abs":
            arg = self.expr(expr.arg)
            return z3.If(arg >= 0, arg, -arg)
        raise UnsupportedTheory(f"Z3 cannot decide `{expr}` (a transcendental function "
                                "of the state)")

    def _power(self, expr: E.Pow) -> z3.ArithRef:
        exponent = expr.exponent
        if not (isinstance(exponent, E.Num) and exponent.value.denominator == 1):
            raise UnsupportedTheory(f"Z3 cannot decide the non-integer power `{expr}`")
        n = int(exponent.value)
        base = self.expr(expr.base)
        result = base ** abs(n) if abs(n) != 1 else base
        return 1 / result if n < 0 else result

    def _enclosed_constant(self, expr: E.Expr) -> z3.ArithRef:
        if expr in self.constants:
            return self.constants[expr]
        enclosure = bounds(expr)
        if enclosure is None:
            raise UnsupportedTheory(f"cannot bound the constant `{expr}`")
        fresh = z3.FreshReal("const", self.context)
        low, high = enclosure
        self.side_conditions += [fresh >= self.number(low), fresh <= self.number(high)]
        self.constants[expr] = fresh
        return fresh


class Z3Backend:
    name = "z3"

    def check_text(self, text: str, timeout: float, variables=()) -> Answer:
        return check_smtlib(text, timeout)

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop: threading.Event | None = None) -> Answer:
        context = z3.Context()
        converter = Z3Converter(context)
        try:
            term = converter.formula(formula)
        except UnsupportedTheory as exc:
            return Answer(Status.UNKNOWN, reason=str(exc))
        solver = z3.Solver(ctx=context)
        solver.set("timeout", max(1, int(timeout * 1000)))
        solver.add(term, *converter.side_conditions)
        approximate = bool(converter.side_conditions)
        result = _check_with_deadline(solver, context, timeout, stop)
        if isinstance(result, Answer):
            return result
        if result == z3.unsat:
            return Answer(Status.UNSAT, approximate=approximate)
        if result == z3.sat:
            values = [solver.model().eval(converter.var(v), model_completion=True)
                      for v in variables]
            irrational = any(z3.is_algebraic_value(v) for v in values)
            model = dict(zip(variables, map(_to_fraction, values)))
            return Answer(Status.SAT, model, approximate=approximate or irrational)
        return Answer(Status.UNKNOWN, reason=solver.reason_unknown(), approximate=approximate)


def check_smtlib(text: str, timeout: float) -> Answer:
    """Decide an SMT-LIB 2 script (as exported next to a result)."""
    context = z3.Context()
    solver = z3.Solver(ctx=context)
    solver.set("timeout", max(1, int(timeout * 1000)))
    try:
        solver.from_string(text)
    except z3.Z3Exception as exc:
        return Answer(Status.UNKNOWN, reason=f"Z3 could not read the script: {exc}")
    result = _check_with_deadline(solver, context, timeout)
    if isinstance(result, Answer):
        return result
    if result == z3.unsat:
        return Answer(Status.UNSAT)
    if result == z3.sat:
        return Answer(Status.SAT)
    return Answer(Status.UNKNOWN, reason=solver.reason_unknown())


def _check_with_deadline(solver: z3.Solver, context: z3.Context, timeout: float,
                         stop: threading.Event | None = None):
    """solver.check() in a worker thread, interrupted once `stop` is set or once Z3
    overruns its own timeout (nlsat does not always look at the clock, e.g. on
    high-degree polynomials). A check still running ABANDON_AFTER s after its interrupt
    is left behind (a daemon thread) and the answer is unknown: the run goes on. So is
    a check that Z3 ends by raising "canceled" rather than answering unknown (its own
    timeout or our interrupt caught inside a tactic: probe f62's run ended with
    "internal error: Z3Exception: b'canceled'" after 51 s). Returns Z3's result, or the
    Answer for these two."""
    done, lock = threading.Event(), threading.Lock()
    found = {}

    def work():
        try:
            result = solver.check()
        except BaseException as exc:  # raised again in the caller's thread
            result = exc
        with lock:  # never interrupt a context whose check has returned
            found["result"] = result
            done.set()

    worker = threading.Thread(target=work, daemon=True)
    worker.start()

    def interrupt():
        with lock:
            if not done.is_set():
                context.interrupt()

    end, interrupted = time.monotonic() + timeout + 1.0, None
    try:
        while not done.wait(STOP_POLL):
            now = time.monotonic()
            if interrupted is None and ((stop is not None and stop.is_set()) or now > end):
                interrupt()
                interrupted = now
            elif interrupted is not None and now > interrupted + ABANDON_AFTER:
                return Answer(Status.UNKNOWN, reason=LEFT_BEHIND)
    except KeyboardInterrupt:  # Python's own handler ran: stop Z3 too
        interrupt()
        raise
    result = found["result"]
    if isinstance(result, z3.Z3Exception) and _canceled(result):
        return Answer(Status.UNKNOWN, reason=CANCELED)
    if isinstance(result, BaseException):
        raise result
    if result == z3.unknown and solver.reason_unknown() == KEYBOARD:
        # Z3 catches Ctrl-C itself, in whichever thread it runs: pass it on to the main
        # thread, where the run stops with what it has
        _thread.interrupt_main()
    return result


def _canceled(exc: z3.Z3Exception) -> bool:
    value = exc.value
    return (value.decode() if isinstance(value, bytes) else str(value)) == "canceled"


def _to_fraction(value) -> Fraction:
    if z3.is_rational_value(value):
        return Fraction(value.numerator_as_long(), value.denominator_as_long())
    if z3.is_algebraic_value(value):
        approx = value.approx(20)
        return Fraction(approx.numerator_as_long(), approx.denominator_as_long())
    raise TypeError(f"unexpected model value {value}")

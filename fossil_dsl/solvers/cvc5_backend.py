"""CVC5: decides the SMT-LIB 2 text of a query (the same text that is exported), so what
CVC5 proves is exactly what a user can re-check."""
from __future__ import annotations

import multiprocessing
import signal
import time
from fractions import Fraction
from typing import Sequence

import cvc5

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory
from fossil_dsl.solvers.smtlib import query_text


class Cvc5Backend:
    name = "cvc5"

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop=None) -> Answer:
        """CVC5's API cannot be interrupted; its child process is killed when `stop` is
        set (another solver of a race has answered)."""
        missing = _functions(formula) & NOT_IN_CVC5
        if missing:
            return Answer(Status.UNKNOWN, reason="CVC5 has no " + ", ".join(sorted(missing)))
        try:
            text = query_text(formula, variables)
        except UnsupportedTheory as exc:
            return Answer(Status.UNKNOWN, reason=str(exc))
        return self.check_text(text, timeout, variables, stop)

    def check_text(self, text: str, timeout: float, variables: Sequence[str] = (),
                   stop=None) -> Answer:
        """In a child process that is killed at the deadline: CVC5's nonlinear module
        (libpoly's root isolation in its coverings procedure) was seen running for 30
        minutes past its `tlimit-per` of 60 s, holding a benchmark run and a recheck."""
        context = multiprocessing.get_context("fork")
        receive, send = context.Pipe(duplex=False)
        # daemon: a run stopped by Ctrl-C while this waits in a worker thread does not
        # wait for CVC5 at exit
        child = context.Process(target=_answer_into, args=(send, text, timeout, tuple(variables)),
                                daemon=True)
        child.start()
        send.close()
        try:
            if _wait(receive, time.monotonic() + timeout + GRACE_SECONDS, stop):
                return receive.recv()
            if stop is not None and stop.is_set():
                return Answer(Status.UNKNOWN, reason="stopped")
            return Answer(Status.UNKNOWN, reason=f"timeout: CVC5 ran past {timeout:g} s "
                          "and was stopped")
        except EOFError:
            return Answer(Status.UNKNOWN, reason=f"CVC5 ended without an answer "
                          f"(exit code {child.exitcode})")
        finally:
            if child.is_alive():
                child.kill()
            child.join()
            receive.close()


GRACE_SECONDS = 2.0  # past the time limit, for CVC5 to stop by itself and reply
STOP_POLL = 0.02  # s between looks at the stop event


def _wait(receive, deadline: float, stop) -> bool:
    """Whether the answer arrived before the deadline (False at once when stopped)."""
    if stop is None:
        return receive.poll(max(0.0, deadline - time.monotonic()))
    while not stop.is_set():
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        if receive.poll(min(STOP_POLL, left)):
            return True
    return False


def _answer_into(connection, text: str, timeout: float, variables) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    connection.send(_solve(text, timeout, variables))
    connection.close()


def _solve(text: str, timeout: float, variables: Sequence[str]) -> Answer:
    solver = cvc5.Solver()
    solver.setOption("produce-models", "true")
    solver.setOption("tlimit-per", str(max(1, int(timeout * 1000))))
    symbols = cvc5.SymbolManager(solver.getTermManager())
    parser = cvc5.InputParser(solver, symbols)
    parser.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, _without_check_sat(text), "query")
    try:
        while not (command := parser.nextCommand()).isNull():
            command.invoke(solver, symbols)
    except RuntimeError as exc:  # cvc5's parse and API errors
        return Answer(Status.UNKNOWN, reason=f"CVC5 could not read the script: {exc}")
    result = solver.checkSat()
    if result.isUnsat():
        return Answer(Status.UNSAT)
    if result.isSat():
        declared = {str(t): t for t in symbols.getDeclaredTerms()}
        values = {v: solver.getValue(declared[v]) for v in variables if v in declared}
        irrational = not all(value.isRealValue() for value in values.values())
        model = {v: _rational(value) for v, value in values.items()}
        return Answer(Status.SAT, model, approximate=irrational)
    return Answer(Status.UNKNOWN, reason=str(result.getUnknownExplanation()))


NOT_IN_CVC5 = frozenset({"log", "sqrt"})


def _functions(formula: L.Formula) -> set[str]:
    return {node.func for c in L.comparisons(formula) for side in (c.left, c.right)
            for node in E.walk(side) if isinstance(node, E.Apply)}


def _rational(value) -> Fraction:
    """An exact rational, or the midpoint of an isolating interval of an algebraic one."""
    if value.isRealValue():
        return value.getRealValue()
    low = value.getRealAlgebraicNumberLowerBound().getRealValue()
    high = value.getRealAlgebraicNumberUpperBound().getRealValue()
    return (low + high) / 2


def _without_check_sat(text: str) -> str:
    return "\n".join(line for line in text.splitlines() if line.strip() != "(check-sat)")

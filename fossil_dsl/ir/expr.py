"""Solver-neutral real-valued expressions: immutable, hashable, exact (Fraction) numbers.

Every later stage (solvers, learner, printers) consumes these; none of them sees the
syntax tree. Simplification is limited to exact constant folding.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from fossil_dsl.ir.functions import FUNCTIONS, DomainError, exact_at_pi_multiple
from fossil_dsl.ir.hash_cache import hash_cached
from fossil_dsl.ir.numbers import number_text

_SUM, _PRODUCT, _UNARY, _POWER, _ATOM = range(5)  # binding, loosest first
MAX_CONSTANT_BITS = 4_000  # about 1e1200; beyond it constants are rejected, not computed


class ExprError(ValueError):
    """An expression that cannot be built exactly (division by zero, a huge constant)."""


class Expr:
    """Base class; operators build new nodes with constant folding."""

    def __add__(self, other): return add(self, lift(other))
    def __radd__(self, other): return add(lift(other), self)
    def __sub__(self, other): return add(self, neg(lift(other)))
    def __rsub__(self, other): return add(lift(other), neg(self))
    def __mul__(self, other): return mul(self, lift(other))
    def __rmul__(self, other): return mul(lift(other), self)
    def __truediv__(self, other): return div(self, lift(other))
    def __rtruediv__(self, other): return div(lift(other), self)
    def __pow__(self, other): return power(self, lift(other))
    def __neg__(self): return neg(self)

    def __str__(self) -> str:
        return to_text(self)


@dataclass(frozen=True, eq=True)
class Num(Expr):
    value: Fraction

    def __post_init__(self):
        if not isinstance(self.value, Fraction):
            object.__setattr__(self, "value", Fraction(self.value))


@dataclass(frozen=True)
class Var(Expr):
    name: str


@dataclass(frozen=True)
class Pi(Expr):
    """The exact constant π."""


def _compound(cls):
    return hash_cached(dataclass(frozen=True)(cls))


@_compound
class Add(Expr):
    terms: tuple[Expr, ...]


@_compound
class Mul(Expr):
    factors: tuple[Expr, ...]


@_compound
class Div(Expr):
    numerator: Expr
    denominator: Expr


@_compound
class Neg(Expr):
    operand: Expr


@_compound
class Pow(Expr):
    base: Expr
    exponent: Expr


@_compound
class Apply(Expr):
    """A named function of one argument, from FUNCTIONS."""

    func: str
    arg: Expr


ZERO = Num(Fraction(0))
ONE = Num(Fraction(1))


def lift(value) -> Expr:
    if isinstance(value, Expr):
        return value
    if isinstance(value, (int, Fraction)):
        return Num(Fraction(value))
    if isinstance(value, float):
        return Num(Fraction(value))
    raise TypeError(f"cannot make an expression of {value!r}")


def _checked(value: Fraction) -> Num:
    if too_large(value):
        raise ExprError("constant too large to compute exactly")
    return Num(value)


def too_large(value: Fraction) -> bool:
    return max(abs(value.numerator).bit_length(), value.denominator.bit_length()) \
        > MAX_CONSTANT_BITS


def is_num(expr: Expr, value=None) -> bool:
    return isinstance(expr, Num) and (value is None or expr.value == value)


# ---- smart constructors (exact folding of rational constants) -----------------------
def add(*terms: Expr) -> Expr:
    """A sum with its constants folded and like terms collected (c*t + d*t = (c+d)*t)."""
    coefficients: dict[Expr, Fraction] = {}
    constant = Fraction(0)
    for term in terms:
        for part in _summands(term):
            if isinstance(part, Num):
                constant += part.value
            else:
                base, factor = _split_coefficient(part)
                coefficients[base] = coefficients.get(base, Fraction(0)) + factor
    flat = [mul(Num(c), base) for base, c in coefficients.items() if c != 0]
    if constant != 0 or not flat:
        flat.append(_checked(constant))
    return flat[0] if len(flat) == 1 else Add(tuple(flat))


def _summands(term: Expr):
    if isinstance(term, Add):
        return term.terms
    if isinstance(term, Neg) and isinstance(term.operand, Add):  # -(a + b) = -a - b
        return tuple(neg(t) for t in term.operand.terms)
    return (term,)


def _split_coefficient(term: Expr) -> tuple[Expr, Fraction]:
    if isinstance(term, Neg):
        base, factor = _split_coefficient(term.operand)
        return base, -factor
    if isinstance(term, Mul) and isinstance(term.factors[0], Num):
        rest = term.factors[1:]
        return (rest[0] if len(rest) == 1 else Mul(rest)), term.factors[0].value
    return term, Fraction(1)


def mul(*factors: Expr) -> Expr:
    flat: list[Expr] = []
    constant = Fraction(1)
    for factor in factors:
        for part in (factor.factors if isinstance(factor, Mul) else (factor,)):
            if isinstance(part, Num):
                constant = _checked(constant * part.value).value
            else:
                flat.append(part)
    if constant == 0:
        return ZERO
    if constant == -1 and flat:
        return neg(flat[0] if len(flat) == 1 else Mul(tuple(flat)))
    if constant != 1 or not flat:
        flat.insert(0, Num(constant))
    return flat[0] if len(flat) == 1 else Mul(tuple(flat))


def squared_norm(names) -> Expr:
    """x1^2 + ... + xn^2 over the named variables."""
    return add(*(power(Var(name), Num(2)) for name in names))


def neg(operand: Expr) -> Expr:
    if isinstance(operand, Num):
        return Num(-operand.value)
    if isinstance(operand, Neg):
        return operand.operand
    return Neg(operand)


def div(numerator: Expr, denominator: Expr) -> Expr:
    if is_num(denominator, 0):
        raise ExprError("division by zero")
    if isinstance(denominator, Num):
        return mul(numerator, Num(1 / denominator.value))
    if is_num(numerator, 0):
        return ZERO
    return Div(numerator, denominator)


MAX_EXPONENT = 10_000
MAX_DEGREE = 64  # integer powers of non-constants: solvers stall on higher degrees


def power(base: Expr, exponent: Expr) -> Expr:
    if isinstance(exponent, Num) and exponent.value.denominator == 1:
        n = exponent.value.numerator
        if abs(n) > MAX_EXPONENT:
            raise ExprError(f"exponent {n} is too large (at most {MAX_EXPONENT})")
        if n == 1:
            return base
        if n == 0:
            return ONE
        if isinstance(base, Num):
            return _fold_power(base.value, n)
        if abs(n) > MAX_DEGREE and free_vars(base):
            raise ExprError(f"exponent {n} is too large for a power of a variable "
                            f"(at most {MAX_DEGREE})")
    return Pow(base, exponent)


def _fold_power(base: Fraction, n: int) -> Num:
    if base == 0 and n < 0:
        raise ExprError("division by zero (0 to a negative power)")
    bits = max(abs(base.numerator).bit_length(), base.denominator.bit_length())
    if bits * abs(n) > MAX_CONSTANT_BITS:
        raise ExprError("constant too large to compute exactly")
    return Num(base ** n)


def apply(func: str, arg: Expr) -> Expr:
    if isinstance(arg, Num):
        try:
            value = FUNCTIONS[func].exact(arg.value)
        except DomainError as error:
            raise ExprError(str(error)) from None
        if value is not None:
            return Num(value)
    multiple = _pi_multiple(arg)
    if multiple is not None:
        value = exact_at_pi_multiple(func, multiple)
        if value is not None:
            return Num(value)
    return Apply(func, arg)


def _pi_multiple(arg: Expr) -> Fraction | None:
    """c where the argument is pi, c * pi or -(c * pi) (c rational), else None."""
    if isinstance(arg, Pi):
        return Fraction(1)
    if isinstance(arg, Neg):
        inner = _pi_multiple(arg.operand)
        return None if inner is None else -inner
    if isinstance(arg, Mul) and len(arg.factors) == 2 \
            and {type(f) for f in arg.factors} == {Num, Pi}:
        return next(f.value for f in arg.factors if isinstance(f, Num))
    return None


# ---- the tree -----------------------------------------------------------------
def children(expr: Expr) -> tuple[Expr, ...]:
    if isinstance(expr, Add):
        return expr.terms
    if isinstance(expr, Mul):
        return expr.factors
    if isinstance(expr, Div):
        return (expr.numerator, expr.denominator)
    if isinstance(expr, Pow):
        return (expr.base, expr.exponent)
    if isinstance(expr, (Neg,)):
        return (expr.operand,)
    if isinstance(expr, Apply):
        return (expr.arg,)
    return ()


def walk(expr: Expr):
    """Every node of the tree, parents before children."""
    stack = [expr]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(children(node))


def free_vars(expr: Expr) -> frozenset[str]:
    return frozenset(node.name for node in walk(expr) if isinstance(node, Var))


# ---- text, in the .fsl expression syntax ------------------------------------
def to_text(expr: Expr) -> str:
    return _text(expr)[0]


def _text(expr: Expr) -> tuple[str, int]:
    if isinstance(expr, Num):
        text = number_text(expr.value)
        return text, (_ATOM if expr.value >= 0 and "/" not in text else _UNARY)
    if isinstance(expr, Var):
        return expr.name, _ATOM
    if isinstance(expr, Pi):
        return "pi", _ATOM
    if isinstance(expr, Apply):
        return f"{expr.func}({to_text(expr.arg)})", _ATOM
    if isinstance(expr, Neg):
        return "-" + _wrap(expr.operand, _UNARY), _UNARY
    if isinstance(expr, Pow):
        return f"{_wrap(expr.base, _ATOM)}^{_wrap(expr.exponent, _ATOM)}", _POWER
    if isinstance(expr, Div):
        return f"{_wrap(expr.numerator, _PRODUCT)}/{_wrap(expr.denominator, _POWER)}", _PRODUCT
    if isinstance(expr, Mul):
        return "*".join([_wrap(expr.factors[0], _PRODUCT)]
                        + [_later_factor(f) for f in expr.factors[1:]]), _PRODUCT
    if isinstance(expr, Add):
        return _sum_text(expr.terms), _SUM
    raise TypeError(f"not an expression: {expr!r}")


def _later_factor(factor: Expr) -> str:
    """A factor after the first, in parentheses where it has a `/` of its own: c*1/u
    reads back as (c*1)/u, another tree (recheck compared the obligations derived from
    it with those exported and called every sigmoid certificate's "altered")."""
    text, own = _text(factor)
    return f"({text})" if own < _UNARY or "/" in text and own < _POWER else text


def _sum_text(terms) -> str:
    parts = [_wrap(terms[0], _SUM)]
    for term in terms[1:]:
        if isinstance(term, Neg):
            parts.append(" - " + _wrap(term.operand, _PRODUCT))
        elif isinstance(term, Num) and term.value < 0:
            parts.append(" - " + number_text(-term.value))
        elif isinstance(term, Mul) and isinstance(term.factors[0], Num) \
                and term.factors[0].value < 0:
            parts.append(" - " + _wrap(mul(Num(-term.factors[0].value),
                                             *term.factors[1:]), _PRODUCT))
        else:
            parts.append(" + " + _wrap(term, _PRODUCT))
    return "".join(parts)


def _wrap(expr: Expr, level: int) -> str:
    text, own = _text(expr)
    return text if own >= level else f"({text})"

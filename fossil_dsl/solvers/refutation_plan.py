"""Which refutation programs sos_refutation.py tries for a conjunction, and in what order:
the parts of the conjunction that share no variable (each refuted on its own), the
products of a box's opposite bounds, and the variants of one program (power, lowest
multiplier degree, products, raised degree, closure)."""
from __future__ import annotations

from fossil_dsl.ir import polynomials as P
from fossil_dsl.solvers.positivstellensatz import Product, Refutation, SumOfSquares


def independent_parts(atoms) -> list[tuple[list[int], tuple[int, ...]]]:
    """The atoms' indices grouped by shared variables (connected components), most atoms
    first, each with the variables it uses. A conjunction whose groups share no variable
    is unsatisfiable only if one group is, and a program over variables that a group does
    not constrain has s0 monomials in them whose rounding residue nothing absorbs: a
    4-state query sin(a) + b c <= a - a^3/6 + a^5/120 - 0.01 with d only bounded had no
    refutation (the program solved with t ~ 1; rounding failed), the same query without
    d's bounds one in 0.4 s. Atoms without variables join every group."""
    used = [{v for m in h for v, e in enumerate(m) if e} for h, _ in atoms]
    groups: list[tuple[set, list[int]]] = []  # (variables, atoms), disjoint in variables
    for index, variables in enumerate(used):
        if not variables:
            continue
        meeting = [g for g in groups if g[0] & variables]
        groups = [g for g in groups if not g[0] & variables]
        groups.append((variables.union(*(g[0] for g in meeting)),
                       [index] + [i for g in meeting for i in g[1]]))
    constants = [index for index, variables in enumerate(used) if not variables]
    parts = [(sorted(members + constants), tuple(sorted(variables)))
             for variables, members in groups] or [(constants, ())]
    return sorted(parts, key=lambda part: (-len(part[0]), part[0]))


def restricted(atoms, variables: tuple[int, ...]):
    """The atoms as polynomials in `variables` only (the others do not occur in them)."""
    return [({tuple(m[v] for v in variables): c for m, c in h.items()}, strict)
            for h, strict in atoms]


def widened(refutation: Refutation, kept: list[int], count: int,
            variables: tuple[int, ...], n: int) -> Refutation:
    """A refutation of the atoms `kept`, over `variables`, as one of all `count` atoms
    over n variables: the other atoms get no multiplier."""
    def lifted(square: SumOfSquares) -> SumOfSquares:
        monomials = []
        for m in square.monomials:
            full = [0] * n
            for v, e in zip(variables, m):
                full[v] = e
            monomials.append(tuple(full))
        return SumOfSquares(tuple(monomials), square.gram)

    multipliers: list = [None] * count
    for index, multiplier in zip(kept, refutation.multipliers):
        is_square = isinstance(multiplier, SumOfSquares)
        multipliers[index] = lifted(multiplier) if is_square else multiplier
    products = tuple(Product(kept[p.first], kept[p.second], lifted(p.square))
                     for p in refutation.products)
    return Refutation(tuple(multipliers), lifted(refutation.rest), refutation.constant,
                      products)


def variants(powers, pairs, raise_too: bool, lows=(1, 2, 0), closure: bool = False):
    """(power, low, products, raised, closed) of the programs tried, in order.

    Each power with each low of `lows` in turn (1, 2, 0; 0 first where the origin is left
    out), and the first power again with the box's products, if there are any (not in
    every variant: a 3-state map's unrefutable query took 8.4 s instead of 3.3 s), and
    none for abstracted queries, whose facts' bounds would make their programs larger.
    After the first power's programs, where it differs (`closure`), the program for the
    query's closure (`closed`): every comparison read as h >= 0, with sums of squares as
    multipliers, and the constant 1 > 0, a proof that even the closure is empty. A strict
    comparison such as "outside the goal ball", |x|^2 - r^2 > 0, otherwise has a constant
    multiplier only, where the decrease it guards may need a polynomial one (probe59/ac15:
    a map's quartic V, found with a margin of 0.28 on D outside G, had no other
    refutation of its decrease).
    Last, where they are small, the programs with low 0 with multipliers of one degree
    more (`raised`): a decrease on a sublevel set {V <= β} of a degree-6 V (probe48/c02,
    tight against the basin) needs a multiplier of β - V of degree 4, not 2."""
    found = []
    for power, low in ((m, low) for m in powers for low in lows):
        found.append((power, low, (), 0, False))
        if pairs and power == powers[0] and low != 2:
            found.append((power, low, pairs, 0, False))
        if closure and power == powers[0] and low == lows[-1]:
            found.append((power, 0, pairs or (), 0, True))
    if raise_too:
        found += [(powers[0], 0, products, 1, False)
                  for products in ((pairs,) if pairs else ()) + ((),)]
    return found


def opposite_bounds(atoms) -> list[tuple[int, int]] | None:
    """The pairs of non-strict comparisons among `opposite_pairs`, or None where there
    are none. Without their products a box's multipliers of low degree cannot see that
    it is bounded: a degree-4 V for a 4-state cubic system (probe44/y02), found by a
    program with them, had no refutation of its decrease without them (6 programs,
    4.5 s); with them the first program (a third larger) is one."""
    pairs = [(i, k) for i, k in opposite_pairs([h for h, _ in atoms])
             if not atoms[i][1] and not atoms[k][1]]
    return pairs or None


def opposite_pairs(polynomials) -> list[tuple[int, int]]:
    """The index pairs of linear polynomials that bound one expression from both sides
    (l <= x_i and x_i <= u as x_i - l >= 0 and u - x_i >= 0: their sum is a constant, and
    their product (x_i - l)(u - x_i) >= 0)."""
    linear = [i for i, h in enumerate(polynomials) if P.degree(h) == 1]
    return [(i, k) for a, i in enumerate(linear) for k in linear[a + 1:]
            if P.degree(P.add(polynomials[i], polynomials[k])) < 1]

"""Sum-of-squares refutations (positivstellensatz.py) as JSON (obligations/NAME.sos.json,
and within the other evidence files), which anyone can check again."""
from __future__ import annotations

from fractions import Fraction
from typing import Sequence

from fossil_dsl.solvers.positivstellensatz import (CaseSplit, Evidence, Multiplier, Power,
                                                  Product, Refutation, SlabSplit,
                                                  SumOfSquares)


def refutation_json(refutation: Evidence, states: Sequence[str]) -> dict:
    if isinstance(refutation, SlabSplit):
        return {"states": list(states), "variable": refutation.variable,
                "edges": [str(e) for e in refutation.edges],
                "slabs": [refutation_json(r, states) for r in refutation.slabs]}
    if isinstance(refutation, CaseSplit):
        return {"states": list(states), "conjunct": refutation.conjunct,
                "cases": [refutation_json(r, states) for r in refutation.cases]}
    found = {"states": list(states),
             "multipliers": [_multiplier_json(m) for m in refutation.multipliers],
             "rest": _square_json(refutation.rest), "constant": str(refutation.constant)}
    if refutation.products:
        found["products"] = [{"comparisons": [p.first, p.second], "square": _square_json(p.square)}
                             for p in refutation.products]
    return found


def refutation_from_json(data: dict) -> Evidence:
    """Raises ValueError (or KeyError, TypeError) where the data is malformed."""
    if "slabs" in data:
        return SlabSplit(str(data["variable"]), tuple(Fraction(e) for e in data["edges"]),
                         tuple(refutation_from_json(piece) for piece in data["slabs"]))
    if "cases" in data:
        return CaseSplit(int(data["conjunct"]),
                         tuple(refutation_from_json(case) for case in data["cases"]))
    products = tuple(Product(int(p["comparisons"][0]), int(p["comparisons"][1]),
                             _square(p["square"])) for p in data.get("products", ()))
    return Refutation(tuple(_multiplier(m) for m in data["multipliers"]),
                      _square(data["rest"]), Fraction(data.get("constant", "0")), products)


def _multiplier_json(multiplier: Multiplier):
    if multiplier is None or isinstance(multiplier, SumOfSquares):
        return None if multiplier is None else _square_json(multiplier)
    if isinstance(multiplier, Power):
        return {"coefficient": str(multiplier.coefficient), "power": multiplier.exponent}
    return str(multiplier)


def _square_json(square: SumOfSquares) -> dict:
    return {"monomials": [list(m) for m in square.monomials],
            "gram": [[str(v) for v in row] for row in square.gram]}


def _multiplier(data) -> Multiplier:
    if data is None:
        return None
    if isinstance(data, dict) and "power" in data:
        return Power(Fraction(data["coefficient"]), int(data["power"]))
    return _square(data) if isinstance(data, dict) else Fraction(data)


def _square(data: dict) -> SumOfSquares:
    return SumOfSquares(tuple(tuple(int(k) for k in m) for m in data["monomials"]),
                        tuple(tuple(Fraction(v) for v in row) for row in data["gram"]))

"""Writes specs/scaling/hi_ord_N.fsl: row 4 of the portfolio (an 8-state chain of
integrators) generalised to N states, N = 4, 6, 8, 10, 12.

Row 4's closing row is the characteristic polynomial ((s+1)(s+2)(s+3)(s+4))^2; for N
states it is the product of (s+i)^2 for i = 1..N/2 (stable: every root is negative), so
N = 8 gives row 4 exactly. The boxes are row 4's in every coordinate.

    python benchmarks/make_scaling_specs.py
"""
from pathlib import Path

import sympy

SIZES = (4, 6, 8, 10, 12)
FOLDER = Path(__file__).resolve().parent.parent / "specs" / "scaling"


def characteristic(n: int) -> list[int]:
    """Coefficients c_0..c_{n-1} of s^n + c_{n-1} s^{n-1} + ... + c_0."""
    s = sympy.Symbol("s")
    poly = sympy.Poly(sympy.prod([(s + i) ** 2 for i in range(1, n // 2 + 1)]), s)
    coefficients = poly.all_coeffs()[::-1]  # c_0 first
    return [int(c) for c in coefficients[:n]]


def spec_text(n: int) -> str:
    states = [f"x{i}" for i in range(n)]
    chain = [f"    x{i}' = x{i + 1}" for i in range(n - 1)]
    last = " - ".join(f"{c}*x{i}" for i, c in enumerate(characteristic(n)))
    box = lambda value: "[" + ", ".join([value] * n) + "]"
    return "\n".join([
        f"# Row 4 of the portfolio (hi_ord_8) generalised to {n} states: a chain of",
        f"# integrators closed by prod_(i=1..{n // 2}) (s+i)^2, row 4's boxes in every coordinate.",
        "# Written by benchmarks/make_scaling_specs.py.",
        f"spec hi_ord_{n}",
        "",
        f"state {', '.join(states)}",
        "",
        "dynamics continuous {",
        *chain,
        f"    x{n - 1}' = -{last}",
        "}",
        "",
        f"domain box({box('-2.2')}, {box('2.2')})",
        f"set init   = box({box('0.9')}, {box('1.1')})",
        f"set unsafe = box({box('-2.2')}, {box('-1.8')})",
        "",
        "prove from init: always not unsafe",
        "",
        "synthesis {",
        "    certificate: linear(10)",
        "    samples: domain 3000, init 3000, unsafe 3000",
        "    max_iters: 25",
        "}",
        "",
    ])


if __name__ == "__main__":
    FOLDER.mkdir(parents=True, exist_ok=True)
    for n in SIZES:
        (FOLDER / f"hi_ord_{n:02d}.fsl").write_text(spec_text(n))

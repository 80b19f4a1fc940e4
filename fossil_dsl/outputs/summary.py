"""The text `fossilc` prints for a result: verdict, formulas, conditions, the kernel's
side facts, guarantee, assumptions and times."""
from __future__ import annotations

import base64
import html
import io
from fractions import Fraction


def summary_text(result: Result) -> str:
    plan = result.plan
    lines = [f"{plan.spec.name}: {result.verdict.upper()} ({plan.spec.property.form}, "
             f"{plan.certificate.title})"]
    if not result.certified:
        lines.append(f"  why: {result.reason}")
    for name, formula in result.formulas.items():
        lines.append(f"  {name}(x) = {formula}")
    for name, formula in result.controller.items():
        lines.append(f"  controller {name} = {formula}")
    for name, value in result.levels.items():
        lines.append(f"  level {name} = {value} (≈ {float(value):.6g})")
    for report in result.conditions:
        mark = {"unsat": "proved", "sat": "fails", "unknown": "unknown",
                "not verified": "not verified"}[report.status]
        if report.status == "unsat" and report.solver != plan.verifier:
            mark += f" by {report.solver}"
        extra = ""
        point = ", ".join(format(float(v), ".6g") for v in report.counterexample or ())
        if report.status == "sat" and point:
            extra = f" at ({point})"
        elif report.reason or point:  # undecided: a point with it is no counterexample
            notes = [report.reason] if report.reason else []
            notes += [f"last point looked at: ({point})"] if point else []
            extra = " (" + "; ".join(notes) + ")"
        lines.append(f"  [{mark}] {report.text}{extra}")
    lines += kernel_lines(result.kernel)
    if result.learn_only:
        lines.append("  learn-only: NOTHING WAS PROVED; the rates above are of fresh samples "
                     "that violate each condition, which no verifier has checked")
    lines.append(f"  guarantee: {result.guarantee()}")
    if result.certified:
        lines += [f"  assumes: {a}" for a in result.assumptions()]
    lines.append(f"  found by: {result.strategy}")
    if result.portfolio:
        lines.append(f"  portfolio: {portfolio_line(result.portfolio)}")
    if result.region:
        lines.append(f"  region: {region_line(result.region)}")
    verifier = "no verifier (learn-only)" if result.learn_only else f"verifier {plan.verifier}"
    lines.append(f"  time: {result.total_seconds:.2f} s (learning {result.learn_seconds:.2f} s, "
                 f"verifying {result.verify_seconds:.2f} s), {result.iterations} iteration"
                 f"{'' if result.iterations == 1 else 's'}, {verifier}, "
                 f"seed {plan.options.seed}")
    return "\n".join(lines)


def region_line(region: dict) -> str:
    """`region: largest` in words (its numbers are estimates from samples)."""
    tried = len(region["levels_tried"])
    refused = [float(Fraction(t["beta"])) for t in region["levels_tried"] if not t["proved"]]
    cap = f"the smallest level not proved: {min(refused):.4g}; " if refused else ""
    failing = region.get("level_failing_sample")
    if failing is not None and failing < region["level_upper_bound"]:
        cap += f"a sampled point of D fails a condition at V = {failing:.4g}; "
    coverage = region["basin_coverage"]
    basin = "no sampled point of D converges" if coverage is None else \
        f"{100 * coverage:.1f} % of the simulated basin within D"
    return (f"Ω = {{x in D : V(x) <= {region['level']}}}, the largest level the kernel "
            f"proved ({tried} level{'s' if tried != 1 else ''} tried; {cap}V >= "
            f"{region['level_upper_bound']:.4g} "
            f"on the sampled boundary of D); it covers "
            f"{100 * region['share_of_domain']:.1f} % of D (volume {region['volume']:.3g} of "
            f"{region['domain_volume']:.3g}) and {basin} ({region['samples']} samples; "
            f"{region['region_points_not_converging']} sampled points of Ω do not converge "
            "in simulation)")


def portfolio_line(record: dict) -> str:
    outcomes = ", ".join(f"{s['strategy']} {s['outcome']}" for s in record["strategies"])
    line = f"{outcomes} ({record['where']}, {record['seconds']:.2f} s)"
    if record.get("repeat"):
        line += f"; repeat the winner alone with {record['repeat']}"
    return line


def kernel_lines(verdict: Verdict) -> list[str]:
    """The side facts the kernel proved (the conditions are listed above them), and a
    tally of its procedures."""
    if not verdict.proofs:
        return []
    lines = [f"  [proved by {p.procedure}] {p.obligation.text}" for p in verdict.proofs
             if p.proved and not p.obligation.name.startswith("condition:")]
    tally: dict[str, int] = {}
    for proof in verdict.proofs:
        tally[proof.procedure] = tally.get(proof.procedure, 0) + proof.proved
    used = ", ".join(f"{name} {count}" for name, count in tally.items())
    done = sum(p.proved for p in verdict.proofs)
    lines.append(f"  kernel: {done} of {len(verdict.proofs)} obligations proved from the "
                 f"spec and the exact formulas ({used}) in {verdict.seconds:.2f} s")
    return lines


def summary_html(result: Result) -> str:
    """The summary (and, for 2 and 3 states, the phase portrait) for a notebook."""
    parts = [f"<pre>{html.escape(summary_text(result))}</pre>"]
    if len(result.plan.states) in (2, 3):
        import matplotlib.pyplot as plt
        from fossil_dsl.outputs.plot import phase_portrait
        figure = phase_portrait(result)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=80)
        plt.close(figure)
        picture = base64.b64encode(buffer.getvalue()).decode("ascii")
        parts.append(f'<img alt="phase portrait of {html.escape(result.plan.spec.name)}" '
                     f'src="data:image/png;base64,{picture}">')
    return "\n".join(parts)

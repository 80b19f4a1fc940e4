"""Readable forms of a plan: what `fossilc compile` prints (`--explain`, `--loss`) and the
verifier queries as SMT-LIB 2 before anything is learned."""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.kernel import guarantee_text
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers.smtlib import query_text

def plan_text(plan: Plan, explain: bool = False) -> str:
    spec = plan.spec
    lines = [f"spec {spec.name}: {spec.property.form} ({spec.property.text})",
             f"certificate: {plan.certificate.title}"]
    for function in plan.functions:
        shape = f"candidate {function.candidate}" if function.candidate else \
            "network " + ", ".join(map(str, function.layers))
        origin = f", {function.name}(0) = 0 by construction" if function.zero_at_origin else ""
        lines.append(f"  learn {function.name}: {shape}{origin}")
    if plan.controller:
        controller = plan.controller
        origin = ", k(0) = 0 by construction" if controller.zero_at_origin else ""
        lines.append(f"  learn controller ({', '.join(controller.inputs)}) = k(x): network "
                     + ", ".join(map(str, controller.layers)) + f"{origin}; every condition "
                     "is proved for the closed loop with k's exact formula substituted")
    for level in plan.levels:
        lines.append(f"  level {level.text}, chosen at each iteration")
    lines.append("conditions (each proved by showing its negation unsatisfiable):")
    for condition in plan.conditions:
        lines.append(f"  [{condition.name}] {condition.text}")
        lines.append(f"      x ranges over {_set_words(spec, condition.region)}; "
                     f"{plan.samples[condition.name]} training samples")
    lines.append("dynamics (" + spec.time.value + " time):")
    mark = "'" if spec.time.value == "continuous" else ""
    for state, f in zip(spec.states, spec.dynamics):
        left = f"{state}{mark}" if mark else f"next({state})"
        lines.append(f"  {left} = {f}")
    lines.append(f"verifier: {plan.verifier} ({plan.verifier_reason})")
    if plan.excludes_a_ball:
        lines.append(f"  it is a delta-decision procedure: conditions for x ≠ 0 are proved for "
                     f"|x| > {plan.origin_radius} (ε-stability for ε = {plan.origin_radius})")
    options = plan.options
    lines.append(f"loop: at most {options.max_iters} iterations, {options.timeout:g} s, "
                 f"seed {options.seed}")
    if explain:
        radius = plan.origin_radius if plan.excludes_a_ball else Fraction(0)
        lines.append("guarantee, once every obligation is proved: "
                     + guarantee_text(plan.spec, radius, plan.controller is not None))
        variant = plan.certificate.variant_conditions()
        if variant is not None:
            lines.append("or, where the conditions above cannot all be met, the kernel's "
                         "variant rule with: " + "; ".join(c.text for c in variant))
    return "\n".join(lines)


def _control_loss_words(target: S.SetExpr | None) -> str:
    if target is None:
        return "cos(x, f(x, k(x))) over samples of the domain (f should point to 0)"
    return (f"cos(x - c, f(x, k(x))) over samples of the domain and as many near "
            f"{target.text()} (f should point to c, the centre of its bounding box)")


def loss_text(plan: Plan) -> str:
    """The learner's loss terms: one per condition, summed."""
    margin = plan.options.margin
    lines = ["loss = sum of one term per condition (mean over that condition's samples):"]
    for condition in plan.conditions:
        violation = _violation_words(condition.claim)
        shown_margin = f"{margin:g}*|x|^2" if condition.scaled_margin else f"{margin:g}"
        where = f"samples of {condition.region.text()}"
        if condition.exclude_origin:
            where += ", x != 0"
        if condition.guard != L.TRUE:
            where += f", where {condition.guard} (within a band)"
        weight = "" if condition.weight == 1 else f"{condition.weight:g} * "
        lines.append(f"  [{condition.name}] {weight}relu({violation} + {shown_margin}) "
                     f"over {where}")
    if plan.controller:
        lines.append(f"  [control] {plan.options.control_weight:g} * mean of "
                     + _control_loss_words(plan.controller.target))
    lines.append("  ($V is the network's value, $dV its "
                 + ("one-step difference, $next_x the next state's x" if plan.certificate.discrete
                    else "derivative along the flow by automatic differentiation")
                 + (", $beta a level set from the current samples)" if plan.levels else ")"))
    return "\n".join(lines)


def _violation_words(claim: L.Formula) -> str:
    """How far the claim is from holding, as the learner measures it (loss.violation_of)."""
    if isinstance(claim, L.Compare):
        if claim.relation in ("<", "<="):
            return f"({claim.left}) - ({claim.right})"
        return f"({claim.right}) - ({claim.left})"
    if isinstance(claim, L.Not):
        return f"-[{_violation_words(claim.arg)}]"
    combine = "max" if isinstance(claim, L.And) else "min"
    return f"{combine}(" + ", ".join(_violation_words(a) for a in claim.args) + ")"


def _set_words(spec: CheckedSpec, region: S.SetExpr) -> str:
    if region is spec.domain:
        return f"the domain D = {region.text()}"
    return region.text()


def symbolic_queries(plan: Plan) -> dict[str, str]:
    """The verifier queries as SMT-LIB 2, with each learned function still unknown."""
    functions = {}
    for function in plan.functions:
        functions[function.name] = None
        functions[f"d{function.name}"] = None
    next_state = {f"next_{s}": None for s in plan.states
                  if any(f"$next_{s}" in L.free_vars(c.claim) for c in plan.conditions)}
    result = {}
    for condition in plan.conditions:
        comments = [f"{plan.spec.name}: condition {condition.name}: {condition.text}",
                    "unsat means the condition holds; d" + plan.functions[0].name +
                    (" is the one-step difference" if plan.certificate.discrete
                     else " is the derivative along the flow")]
        if next_state:
            comments.append("next_x is the closed loop's next state f(x), coordinate x")
        result[condition.name] = query_text(plan.query(condition), plan.states,
                                            {**functions, **next_state}, comments,
                                            levels={level.name: None for level in plan.levels})
    return result

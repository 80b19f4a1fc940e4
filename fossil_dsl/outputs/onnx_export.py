"""The proved formulas as ONNX models, for ONNX Runtime, TensorRT or a ROS node.

What is exported is the exact formula the kernel judged (the network with its weights
rounded to the rationals that were proved), not the float network that was trained:
each node of the formula becomes an ONNX node in double precision, shared subterms
once. Input `x`: a batch of states, shape [N, n] (columns in the spec's state order);
output `y`: shape [N, outputs].
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir.enclosure import enclose

OPSET = 17
UNARY = {"sin": "Sin", "cos": "Cos", "tan": "Tan", "exp": "Exp", "log": "Log",
         "sqrt": "Sqrt", "tanh": "Tanh", "atan": "Atan", "abs": "Abs"}


class OnnxExportError(Exception):
    """A formula has a part ONNX cannot express."""


class _Graph:
    def __init__(self, states: Sequence[str]):
        from onnx import helper
        self.helper = helper
        self.states = list(states)
        self.nodes, self.initialisers, self.names = [], [], {}

    def constant(self, value: float) -> str:
        from onnx import TensorProto
        name = f"c{len(self.initialisers)}"
        self.initialisers.append(self.helper.make_tensor(name, TensorProto.DOUBLE, [], [value]))
        return name

    def node(self, op: str, inputs: list[str], **attributes) -> str:
        name = f"n{len(self.nodes)}"
        self.nodes.append(self.helper.make_node(op, inputs, [name], **attributes))
        return name

    def emit(self, expr: E.Expr) -> str:
        """The name of a [N, 1] tensor holding expr at each state of the batch."""
        if expr not in self.names:
            self.names[expr] = self._emit(expr)
        return self.names[expr]

    def _emit(self, expr: E.Expr) -> str:
        if isinstance(expr, E.Var):
            column = self.constant_index(self.states.index(expr.name))
            return self.node("Gather", ["x", column], axis=1)
        if isinstance(expr, (E.Num, E.Pi)):
            low, high = enclose(expr)
            return self.node("Mul", ["ones", self.constant((low + high) / 2)])
        if isinstance(expr, E.Add):
            return self._fold("Add", expr.terms)
        if isinstance(expr, E.Mul):
            return self._fold("Mul", expr.factors)
        if isinstance(expr, E.Div):
            return self.node("Div", [self.emit(expr.numerator), self.emit(expr.denominator)])
        if isinstance(expr, E.Neg):
            return self.node("Neg", [self.emit(expr.operand)])
        if isinstance(expr, E.Pow):
            return self._power(expr)
        if isinstance(expr, E.Apply) and expr.func in UNARY:
            return self.node(UNARY[expr.func], [self.emit(expr.arg)])
        raise OnnxExportError(f"no ONNX form for {E.to_text(expr)[:60]}")

    def constant_index(self, index: int) -> str:
        from onnx import TensorProto
        name = f"i{len(self.initialisers)}"
        self.initialisers.append(self.helper.make_tensor(name, TensorProto.INT64, [1], [index]))
        return name

    def _fold(self, op: str, parts) -> str:
        names = [self.emit(p) for p in parts]
        result = names[0]
        for name in names[1:]:
            result = self.node(op, [result, name])
        return result

    def _power(self, expr: E.Pow) -> str:
        base = self.emit(expr.base)
        exponent = expr.exponent
        if isinstance(exponent, E.Num) and exponent.value.denominator == 1 \
                and 1 <= exponent.value <= 8:
            result = base
            for _ in range(int(exponent.value) - 1):
                result = self.node("Mul", [result, base])
            return result
        return self.node("Pow", [base, self.emit(exponent)])


def model(formulas: Sequence[E.Expr], states: Sequence[str], name: str):
    """An ONNX model computing the formulas (one output column each)."""
    import onnx
    from onnx import TensorProto, helper
    graph = _Graph(states)
    # a [N, 1] column of ones (x0 * 0 + 1): numbers reach the batch's shape through it
    first = graph.node("Gather", ["x", graph.constant_index(0)], axis=1)
    graph.nodes.append(helper.make_node("Mul", [first, graph.constant(0.0)], ["zeros"]))
    graph.nodes.append(helper.make_node("Add", ["zeros", graph.constant(1.0)], ["ones"]))
    columns = [graph.emit(f) for f in formulas]
    graph.nodes.append(helper.make_node("Concat", columns, ["y"], axis=1))
    n = len(states)
    body = helper.make_graph(
        graph.nodes, name,
        [helper.make_tensor_value_info("x", TensorProto.DOUBLE, ["N", n])],
        [helper.make_tensor_value_info("y", TensorProto.DOUBLE, ["N", len(formulas)])],
        graph.initialisers)
    built = helper.make_model(body, opset_imports=[helper.make_opsetid("", OPSET)],
                              producer_name="fossil_dsl")
    onnx.checker.check_model(built)
    return built


def write(formulas: Sequence[E.Expr], states: Sequence[str], path: Path, name: str) -> Path:
    import onnx
    onnx.save(model(formulas, states, name), str(path))
    return path

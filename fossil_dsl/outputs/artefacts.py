"""What `-o DIR` writes: result.json, certificate.txt, the kernel's obligations as
SMT-LIB 2 (and the sum-of-squares refutations that proved some, as NAME.sos.json, or
that proved them within a ball round the origin, with its radius, as NAME.split.json), the
networks' weights (networks.pt) and the proved formulas as ONNX models
(certificate.onnx, controller.onnx)."""
from __future__ import annotations

import json
from pathlib import Path

from fossil_dsl.kernel.obligations import file_stem
from fossil_dsl.solvers.ball_split import BallSplit, split_json
from fossil_dsl.solvers.evidence_json import refutation_json
from fossil_dsl.outputs import onnx_export
from fossil_dsl.outputs.summary import summary_text


# what an earlier result in the same folder may have left that this one does not rewrite
OWN_FILES = ("obligations/*.smt2", "obligations/*.sos.json", "obligations/*.split.json",
             "certificate.onnx", "controller.onnx", "networks.pt")


def write_artefacts(result: Result, directory: str | Path) -> Path:
    out = Path(directory)
    (out / "obligations").mkdir(parents=True, exist_ok=True)
    for pattern in OWN_FILES:  # a stale refutation or obligation would be re-checked
        for path in out.glob(pattern):
            path.unlink()
    (out / "result.json").write_text(json.dumps(result.to_json(), indent=2) + "\n")
    (out / "certificate.txt").write_text(summary_text(result) + "\n")
    for name, text in result.obligations.items():
        (out / "obligations" / f"{name}.smt2").write_text(text)
    for name, evidence in result.refutations.items():
        states = result.plan.states
        split = isinstance(evidence, BallSplit)
        data = {"obligation": name, **(split_json(evidence, states) if split
                                       else refutation_json(evidence, states))}
        suffix = "split" if split else "sos"
        (out / "obligations" / f"{file_stem(name)}.{suffix}.json").write_text(
            json.dumps(data) + "\n")
    write_onnx(result, out)
    if result.networks:
        import torch
        torch.save({name: network.state_dict() for name, network in result.networks.items()},
                   out / "networks.pt")
    return out


def write_onnx(result: Result, out: Path) -> None:
    """certificate.onnx: one output column per function, in the certificate's order
    (V, then B); controller.onnx: one column per input. A formula with a part ONNX has
    no operator for gets no file (every function of the language has one today)."""
    states = result.plan.states
    files = {"certificate.onnx": list(result.formulas.values()),
             "controller.onnx": list(result.controller.values())}
    for name, formulas in files.items():
        if formulas:
            try:
                onnx_export.write(formulas, states, out / name, result.plan.spec.name)
            except onnx_export.OnnxExportError:
                continue

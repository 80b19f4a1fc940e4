"""Writing .fsl text: the declarations and dynamics block that every generated spec starts
with (specs built in Python, imported YAML configurations)."""
from __future__ import annotations

from typing import Sequence


def spec_head(name: str, states: Sequence[str], inputs: Sequence[str], time: str,
              right_sides: Sequence[str]) -> list[str]:
    """`spec`, `state`, `input` and the `dynamics` block, one line per item."""
    lines = [f"spec {name}", "", f"state {', '.join(states)}"]
    if inputs:
        lines.append(f"input {', '.join(inputs)}")
    lines += ["", f"dynamics {time} {{"]
    for state, value in zip(states, right_sides):
        left = f"next({state})" if time == "discrete" else f"{state}'"
        lines.append(f"    {left} = {value}")
    return lines + ["}", ""]

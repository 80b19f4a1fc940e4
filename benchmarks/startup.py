"""Start-up of the commands that learn nothing, side by side with `import torch`, in one run.

    python benchmarks/startup.py [--repeats 7]

Each command runs `repeats` times, the commands interleaved (so a change of load hits
all alike); the table gives each one's median wall time and its ratio to the median of
`python -c "import torch"`. Targets (issue 23): `fossilc check` at most 0.5 of it,
`fossilc --help` at most 0.3 s.
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOSSILC = shutil.which("fossilc") or str(Path(sys.executable).with_name("fossilc"))
COMMANDS = {
    "python -c 'import torch'": [sys.executable, "-c", "import torch"],
    "fossilc --help": [FOSSILC, "--help"],
    "fossilc --version": [FOSSILC, "--version"],
    "fossilc check SPEC": [FOSSILC, "check", "-q", str(ROOT / "specs" / "stability_continuous.fsl")],
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(args.repeats):
        for name, command in COMMANDS.items():
            started = time.perf_counter()
            subprocess.run(command, capture_output=True, check=True)
            times[name].append(time.perf_counter() - started)
    torch_median = statistics.median(times["python -c 'import torch'"])
    print("| command | median (s) | min (s) | / import torch |\n|---|---|---|---|")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"| `{name}` | {median:.3f} | {min(values):.3f} | {median / torch_median:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Option values checked before any work: the command line's argument types and the
Python API's keyword options share these checks, so a bad value costs no run.

Each check takes the value (text from the command line, or a Python value) and returns
it converted, or raises OptionError saying what is allowed.
"""
from __future__ import annotations

import argparse
import math
import re
import tempfile
from pathlib import Path

from fossil_dsl.solvers import registry


class OptionError(ValueError):
    """An option's value is not allowed; the message says what is."""


def whole(value, least: int, what: str) -> int:
    number = None
    if isinstance(value, str) and re.fullmatch(r"\s*-?\d+\s*", value):
        number = int(value)
    elif isinstance(value, (int, float)) and not isinstance(value, bool) \
            and float(value).is_integer():
        number = int(value)
    if number is None or number < least:
        raise OptionError(f"{what} must be a whole number of at least {least}, not {value!r}")
    return number


def positive(value, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if isinstance(value, bool) or not math.isfinite(number) or number <= 0:
        raise OptionError(f"{what} must be a positive finite number, not {value!r}")
    return number


def solver_name(value) -> str:
    if value not in registry.names():
        raise OptionError(f"unknown solver {value!r}; the solvers are: "
                          + ", ".join(registry.names()))
    return value


SCHEDULER = re.compile(r"((tcp|tls|ucx)://)?[\w.\-]+:\d{1,5}|((tcp|tls)://)?\[[0-9a-fA-F:]+\]:\d{1,5}")


def scheduler_address(value) -> str:
    """A Dask scheduler's address: tcp://HOST:PORT (the scheme may be left out)."""
    text = value.strip() if isinstance(value, str) else ""
    if not SCHEDULER.fullmatch(text):
        raise OptionError(f"a Dask scheduler's address looks like tcp://HOST:PORT, not {value!r}")
    return text if "://" in text else "tcp://" + text


def writable_directory(value) -> Path:
    """The folder, created if need be, and shown writable by writing a file in it."""
    folder = Path(value)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise OptionError(f"cannot write to the folder {value} ({reason})") from exc
    return folder


def writable_file(value) -> Path:
    path = Path(value)
    if path.is_dir():
        raise OptionError(f"{value} is a folder; give a file name")
    writable_directory(path.parent if str(path.parent) else ".")
    return path


# ---- the same checks as argparse types (exit 2 with the message) ------------------
def argument(check, *args):
    def convert(text: str):
        try:
            return check(text, *args)
        except OptionError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    convert.__name__ = check.__name__
    return convert


SEED = argument(whole, 0, "the seed")
ITERATIONS = argument(whole, 1, "the number of iterations")
COUNT = argument(whole, 1, "the count")
SECONDS = argument(positive, "the time in seconds")
SOLVER = argument(solver_name)
FOLDER = argument(writable_directory)
FILE = argument(writable_file)
SCHEDULER_ADDRESS = argument(scheduler_address)

# ---- the Python API's keyword options --------------------------------------------
API_CHECKS = {
    "seed": lambda v: whole(v, 0, "seed"),
    "max_iters": lambda v: whole(v, 1, "max_iters"),
    "digits": lambda v: whole(v, 1, "digits"),
    "timeout": lambda v: positive(v, "timeout"),
    "query_timeout": lambda v: positive(v, "query_timeout"),
    "learning_rate": lambda v: positive(v, "learning_rate"),
    "delta": lambda v: positive(v, "delta"),
    "margin": lambda v: 0.0 if v == 0 else positive(v, "margin"),
    "verifier": lambda v: v if v is None else solver_name(v),
}


def check_options(options: dict) -> dict:
    """The options with each known one checked (unknown ones are left to the plan)."""
    return {key: API_CHECKS[key](value) if key in API_CHECKS and value is not None
            else value for key, value in options.items()}

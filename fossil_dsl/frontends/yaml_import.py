"""`fossilc import-yaml`: a reference-tool (Fossil 2.0) YAML configuration as a .fsl spec.

The YAML is read with PyYAML's safe loader (data only). Every expression in it (the
SYSTEM equations, the numbers inside set constructors) is parsed by this tool's own
expression grammar; the set constructors (Rectangle, Sphere, Torus, Union, SetMinus,
Intersection) are read by a small reader that only splits arguments. Nothing is
evaluated. What cannot be translated is listed in `notes`, never silently dropped.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import yaml

from fossil_dsl.diagnostics import FslError, SpecError
from fossil_dsl.syntax.parser import parse_expression
from fossil_dsl.syntax.writer import spec_head

SET_ROLES = {"XD": "domain", "XI": "init", "XU": "unsafe", "XS": "safe", "XG": "goal",
             "XF": "final"}
# the reference's certificate names -> our property, and the sets each needs
PROPERTIES = {
    "LYAPUNOV": ("stable", ()),
    "ROA": ("from init: stable", ("init",)),
    "BARRIER": ("from init: always not unsafe", ("init", "unsafe")),
    "BARRIERALT": ("from init: always not unsafe", ("init", "unsafe")),
    "STABLESAFE": ("from init: stable and always not unsafe", ("init", "unsafe")),
    "SWA": ("from init: stable and always not unsafe", ("init", "unsafe")),
    "RWA": ("from init: safe until goal", ("init", "safe", "goal")),
    "RSWA": ("from init: safe until always goal", ("init", "safe", "goal")),
    "RAR": ("from init: safe until (goal and always final)", ("init", "safe", "goal", "final")),
}
ACTIVATIONS = {"LINEAR": "linear", "SQUARE": "square", "CUBIC": "cube", "CUBE": "cube",
               "POLY_2": "poly2", "POLY_3": "poly3", "POLY_4": "poly4", "RELU": "relu",
               "SIGMOID": "sigmoid", "TANH": "tanh", "SOFTPLUS": "softplus"}
VERIFIERS = {"Z3": "z3", "CVC5": "cvc5"}  # DREAL: left to the default (see below)
HANDLED = {"SYSTEM", "N_VARS", "CERTIFICATE", "TIME_DOMAIN", "DOMAINS", "N_DATA",
           "N_HIDDEN_NEURONS", "ACTIVATION", "N_HIDDEN_NEURONS_ALT", "ACTIVATION_ALT",
           "CTRLAYER", "CTRLACTIVATION", "VERIFIER", "SEED", "CEGIS_MAX_ITERS",
           "LEARNING_RATE"}


class YamlImportError(FslError):
    """The configuration cannot be read or has no translation at all."""


@dataclass
class Translation:
    text: str  # the .fsl spec
    notes: list[str] = field(default_factory=list)  # what was not translated, or changed


def import_yaml(text: str, name: str = "imported") -> Translation:
    try:
        config = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise YamlImportError(f"not valid YAML: {exc}") from None
    if not isinstance(config, dict):
        raise YamlImportError("the configuration must be a mapping of KEY: value")
    return _Importer(config, name).translate()


class _Importer:
    def __init__(self, config: dict, name: str):
        self.config = {str(k).upper(): v for k, v in config.items()}
        self.name = re.sub(r"\W", "_", name) or "imported"
        self.notes: list[str] = []

    def translate(self) -> Translation:
        system = self._system()
        states = [f"x{i}" for i in range(self._n_vars(system))]
        inputs = sorted({u for e in system for u in re.findall(r"\bu\d+\b", e)},
                        key=lambda u: int(u[1:]))
        prove, roles = self._property()
        sets = self._sets(roles)
        time = str(self.config.get("TIME_DOMAIN", "CONTINUOUS")).lower()
        if time not in ("continuous", "discrete"):
            raise YamlImportError(f"TIME_DOMAIN: {time!r} is neither CONTINUOUS nor DISCRETE")
        lines = ["# Imported from a Fossil 2.0 YAML configuration by `fossilc import-yaml`."]
        lines += spec_head(self.name, states, inputs, time, system)
        declared = set(sets)
        lines += [f"domain {sets.pop('domain')}"] if "domain" in sets else []
        lines += [f"set {role} = {text}" for role, text in sets.items()]
        lines += ["", f"prove {prove}"]
        options = self._synthesis(len(inputs), declared)
        if options:
            lines += ["", "synthesis {"] + [f"    {k}: {v}" for k, v in options] + ["}"]
        for key in self.config:
            if key not in HANDLED:
                self.notes.append(f"{key}: not translated (no .fsl counterpart)")
        return Translation("\n".join(lines) + "\n", self.notes)

    # ---- the model ----
    def _system(self) -> list[str]:
        system = self.config.get("SYSTEM")
        if not isinstance(system, list) or not system:
            raise YamlImportError("SYSTEM must be a list of expressions, one per state")
        return [_expression(str(e), f"SYSTEM[{i}]") for i, e in enumerate(system)]

    def _n_vars(self, system: list[str]) -> int:
        n = self.config.get("N_VARS", len(system))
        if n != len(system):
            raise YamlImportError(f"N_VARS is {n} but SYSTEM has {len(system)} equations")
        return n

    def _property(self) -> tuple[str, tuple[str, ...]]:
        kind = str(self.config.get("CERTIFICATE", "")).upper().replace("-", "")
        if kind not in PROPERTIES:
            raise YamlImportError(f"CERTIFICATE: {kind or 'missing'} has no .fsl property "
                               f"(known: {', '.join(sorted(PROPERTIES))})")
        if kind == "BARRIERALT":
            self.notes.append("CERTIFICATE BarrierAlt: imported as safety; fossil_dsl "
                              "proves it with its own barrier conditions")
        return PROPERTIES[kind]

    def _sets(self, roles: tuple[str, ...]) -> dict[str, str]:
        domains = self.config.get("DOMAINS") or {}
        found = {}
        for key, value in domains.items():
            role = SET_ROLES.get(str(key).upper())
            if role is None:
                self.notes.append(f"DOMAINS.{key}: not translated (unknown set label)")
                continue
            try:
                found[role] = self._domain_text(str(value), f"DOMAINS.{key}") \
                    if role == "domain" else _set_text(str(value), f"DOMAINS.{key}")
            except YamlImportError as exc:
                self.notes.append(f"DOMAINS.{key}: not translated ({exc})")
        for role in ("domain",) + roles:
            if role not in found:
                self.notes.append(f"the property needs the set `{role}`, which the YAML does "
                                  "not give in a form that could be translated: add it")
        return found

    def _domain_text(self, text: str, where: str) -> str:
        """The reference writes a domain as a Torus to keep its verifier away from the
        origin; a domain with a hole there cannot show stability, and makes a goal round
        the origin leave the domain. The whole ball is the domain here (the excluded ball
        is the verifier's business, proved apart by the kernel)."""
        match = _CONSTRUCTOR.fullmatch(text)
        args = _split(match.group(2)) if match else []
        if not match or match.group(1) != "Torus" or len(args) != 3:
            return _set_text(text, where)
        self.notes.append(f"{where}: the Torus's inner ball (radius {args[2].strip()}) is "
                          "not excluded: the domain is the whole ball")
        return _set_text(f"Sphere({args[0]}, {args[1]})", where)

    # ---- learning ----
    def _synthesis(self, inputs: int, declared: set[str]) -> list[tuple[str, str]]:
        options = []
        for key, alt in (("certificate", ""), ("certificate2", "_ALT")):
            layers = self._layers(f"N_HIDDEN_NEURONS{alt}", f"ACTIVATION{alt}")
            if layers:
                options.append((key, layers))
        controller = self._controller(inputs)
        if controller:
            options.append(("controller", controller))
        samples = self._samples(declared)
        if samples:
            options.append(("samples", samples))
        verifier = self.config.get("VERIFIER")
        if verifier is not None:
            name = str(verifier).upper()
            if name in VERIFIERS:
                options.append(("verifier", VERIFIERS[name]))
            else:
                self.notes.append(f"VERIFIER {verifier}: left to the default (dReal where "
                                  "it is installed, else the interval verifier, for "
                                  "non-polynomial problems; Z3 for polynomial ones)")
        for key, option in (("SEED", "seed"), ("CEGIS_MAX_ITERS", "max_iters")):
            if key in self.config:
                options.append((option, str(int(self.config[key]))))
        if "LEARNING_RATE" in self.config:
            options.append(("learning_rate",
                            _expression(str(self.config["LEARNING_RATE"]), "LEARNING_RATE")))
        return options

    def _layers(self, widths_key: str, activations_key: str) -> str:
        widths = self.config.get(widths_key)
        activations = self.config.get(activations_key)
        if widths is None and activations is None:
            return ""
        widths, activations = list(widths or []), list(activations or [])
        if len(widths) != len(activations):
            built = min(len(widths), len(activations))
            self.notes.append(f"{widths_key} has {len(widths)} widths and {activations_key} "
                              f"{len(activations)} activations: as in the reference, only "
                              f"the first {built} layer{'s' if built != 1 else ''} "
                              f"{'are' if built != 1 else 'is'} built")
        layers = []
        for width, activation in zip(widths, activations):
            name = ACTIVATIONS.get(str(activation).upper())
            if name is None:
                self.notes.append(f"{activations_key}: {activation} has no .fsl counterpart "
                                  f"(known: {', '.join(sorted(ACTIVATIONS))}); layer dropped")
                continue
            layers.append(f"{name}({int(width)})")
        return ", ".join(layers)

    def _controller(self, inputs: int) -> str:
        widths = list(self.config.get("CTRLAYER") or [])
        activations = list(self.config.get("CTRLACTIVATION") or [])
        if not widths:
            return ""
        hidden, output = widths[:-1], widths[-1]
        if inputs and output != inputs:
            self.notes.append(f"CTRLAYER ends with {output} outputs but SYSTEM uses {inputs} "
                              "inputs; the controller has one output per input")
        layers = []
        for width, activation in zip(hidden, activations):
            name = ACTIVATIONS.get(str(activation).upper())
            if name is None:
                self.notes.append(f"CTRLACTIVATION: {activation} has no .fsl counterpart; "
                                  "layer dropped")
                continue
            layers.append(f"{name}({int(width)})")
        return ", ".join(layers)

    def _samples(self, declared: set[str]) -> str:
        """`samples:` for the sets the spec declares; a count for a set it has not (the
        reference's configs give XU counts for safe-set certificates) is a note."""
        data = self.config.get("N_DATA")
        if isinstance(data, int):
            return str(data)
        if not isinstance(data, dict):
            return ""
        parts = []
        for key, count in data.items():
            role = SET_ROLES.get(str(key).upper())
            if role is None:
                self.notes.append(f"N_DATA.{key}: not translated (unknown set label)")
                continue
            if role not in declared:
                self.notes.append(f"N_DATA.{key}: not translated (the spec has no set "
                                  f"`{role}`; its samples follow the sets it has)")
                continue
            parts.append(f"{role} {int(count)}")
        return ", ".join(parts)


# ---- set constructors and expressions ----
_CONSTRUCTOR = re.compile(r"\s*([A-Za-z_]\w*)\s*\((.*)\)\s*", re.S)


def _set_text(text: str, where: str) -> str:
    match = _CONSTRUCTOR.fullmatch(text)
    if not match:
        raise YamlImportError(f"`{text}` is not a set constructor such as Rectangle(lb, ub)")
    name, args = match.group(1), _split(match.group(2))
    if name == "Rectangle" and len(args) == 2:
        return f"box({_vector(args[0], where)}, {_vector(args[1], where)})"
    if name == "Sphere" and len(args) == 2:
        return f"ball({_vector(args[0], where)}, {_expression(args[1], where)})"
    if name == "Torus" and len(args) == 3:  # the closed shell minus its inner sphere
        centre = _vector(args[0], where)
        return (f"ball({centre}, {_expression(args[1], where)}) - "
                f"ball({centre}, {_expression(args[2], where)})")
    combine = {"Union": "|", "SetMinus": "-", "Intersection": "&"}
    if name in combine and len(args) == 2:
        left, right = (_set_text(a, where) for a in args)
        return f"({left}) {combine[name]} ({right})"
    raise YamlImportError(f"{name} with {len(args)} arguments has no .fsl counterpart "
                       "(translated: Rectangle, Sphere, Torus, Union, SetMinus, Intersection)")


def _vector(text: str, where: str) -> str:
    text = text.strip()
    if not (text.startswith("[") and text.endswith("]")):
        raise YamlImportError(f"`{text}` is not a list of numbers")
    return "[" + ", ".join(_expression(item, where) for item in _split(text[1:-1])) + "]"


def _expression(text: str, where: str) -> str:
    """The text, once our grammar has parsed it as exactly one expression."""
    text = text.strip()
    try:
        parse_expression(text, where)
    except SpecError as exc:
        raise YamlImportError(f"{where}: `{text}` is not an expression of the language: "
                           f"{exc.diagnostics[0].message}") from None
    return text


def _split(text: str) -> list[str]:
    """Split at the commas that are not inside brackets."""
    parts, depth, current = [], 0, []
    for char in text:
        if char in "([":
            depth += 1
        elif char in ")]":
            depth -= 1
        if char == "," and depth == 0:
            parts.append("".join(current))
            current = []
        else:
            current.append(char)
    if "".join(current).strip():
        parts.append("".join(current))
    return parts

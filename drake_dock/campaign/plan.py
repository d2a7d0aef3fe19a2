"""The campaign plan: a typed dataclass loaded from YAML with Drake's ``yaml_load_typed``.

Fields: ``scenario`` (the base scenario file, relative to the plan's directory), ``samples``,
``seed``, ``sampler`` (`SAMPLERS`), ``batch`` (samples per Dask task), ``axes`` (the two inputs
of the capture-probability figure), ``set`` (optional: a map from a scenario field's dotted
path to the value every sample takes instead of the base scenario's) and ``vary``: a map from a numeric scenario field's dotted
path to one distribution, ``uniform: [lo, hi]``, ``normal: [mean, sd]`` or ``choice: [...]``;
for a vector field one ``[lo, hi]`` (or ``[mean, sd]``) per component, and each choice a list
of its components. Every bad value raises `InputError` naming the field (``vary.<path>`` for a
distribution), before anything is simulated; so does a range whose ends make an invalid
scenario (`validate_plan`).
"""

import copy
import dataclasses
import math
import typing
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_load_typed

from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.schema import Scenario
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import InputError

SAMPLERS = ("sobol", "lhs", "uniform", "edges")
KINDS = ("uniform", "normal", "choice")
MAX_SAMPLES = 1_000_000
MAX_BATCH = 1000
DEFAULT_AXES = ("initial.lateral_offset", "initial.tilt_deg")


@dataclasses.dataclass
class Distribution:
    """Exactly one of the three is given; stored per component (a scalar field has one)."""

    uniform: list[list[float]] = dataclasses.field(default_factory=list)
    normal: list[list[float]] = dataclasses.field(default_factory=list)
    choice: list[list[float]] = dataclasses.field(default_factory=list)

    @property
    def kind(self) -> str:
        return next(k for k in KINDS if getattr(self, k))


@dataclasses.dataclass
class CampaignPlan:
    scenario: str = "paper_example.yaml"
    samples: int = 100
    seed: int = 0
    sampler: str = "sobol"
    batch: int = 8
    axes: list[str] = dataclasses.field(default_factory=list)
    vary: dict[str, Distribution] = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class Field:
    """A varied scenario field: its dotted path, its number of components (0 for a scalar)
    and its distribution."""

    path: str
    size: int
    dist: Distribution

    @property
    def columns(self) -> list[str]:
        """The result columns of its value: the path, or path[k] per component."""
        return [self.path] if self.size == 0 else [f"{self.path}[{k}]" for k in range(self.size)]

    @property
    def dims(self) -> int:
        """Dimensions of the unit cube it takes: one per component, one for a choice."""
        return 1 if self.dist.kind == "choice" else max(self.size, 1)


# Raw checks: names and types before the typed loader -----------------------------------------
def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _per_component(field, kind, node):
    """``[a, b]`` (a scalar field) or ``[[a, b], ...]`` (one pair per component) -> the list of
    pairs; the pairs are checked in `_check_distribution`."""
    if not isinstance(node, list) or not node:
        raise InputError(field, node, f"[{_PAIR[kind]}] or one [{_PAIR[kind]}] per component")
    return [node] if not isinstance(node[0], list) else node


_PAIR = {"uniform": "lo, hi", "normal": "mean, sd"}


def _normalized_vary(raw_vary):
    if not isinstance(raw_vary, dict) or not raw_vary:
        raise InputError("vary", raw_vary, "a map from a scenario field's dotted path to a "
                         "distribution (uniform, normal or choice)")
    out = {}
    for path, dist in raw_vary.items():
        field = f"vary.{path}"
        if not isinstance(path, str):
            raise InputError("vary", path, "dotted paths of scenario fields (strings)")
        if not isinstance(dist, dict) or len(dist) != 1 or next(iter(dist)) not in KINDS:
            raise InputError(field, dist, "one of {uniform: [lo, hi]}, {normal: [mean, sd]}, "
                             "{choice: [...]}")
        (kind, node), = dist.items()
        if kind == "choice":
            if not isinstance(node, list) or not node:
                raise InputError(f"{field}.choice", node, "a non-empty list of values")
            node = [x if isinstance(x, list) else [x] for x in node]
        else:
            node = _per_component(f"{field}.{kind}", kind, node)
        for k, entry in enumerate(node):
            if not isinstance(entry, list) or not all(map(_is_number, entry)):
                raise InputError(f"{field}.{kind}[{k}]", entry, "finite numbers")
        out[path] = {kind: node}
    return out


_TOP = {f.name for f in dataclasses.fields(CampaignPlan)} | {"set"}


def _raw(data: str, filename: str) -> dict:
    try:
        raw = yaml.safe_load(data)
    except yaml.YAMLError as e:
        raise InputError("plan file", filename, "valid YAML", str(e).splitlines()[0]) from None
    if not isinstance(raw, dict):
        raise InputError("plan", raw, "a mapping of fields")
    for key, value in raw.items():
        if key not in _TOP:
            raise InputError(str(key), value, f"a field of a campaign plan "
                             f"({', '.join(sorted(_TOP))})", "unknown key")
    for key in ("samples", "seed", "batch"):
        if key in raw and (not isinstance(raw[key], int) or isinstance(raw[key], bool)):
            raise InputError(key, raw[key], "an integer")
    for key in ("scenario", "sampler"):
        if key in raw and not isinstance(raw[key], str):
            raise InputError(key, raw[key], "a string")
    if "axes" in raw and not (isinstance(raw["axes"], list)
                              and all(isinstance(a, str) for a in raw["axes"])):
        raise InputError("axes", raw["axes"], "a list of two varied fields' dotted paths")
    overrides = raw.get("set") or {}
    if not isinstance(overrides, dict) or not all(isinstance(k, str) for k in overrides):
        raise InputError("set", overrides, "a map from a scenario field's dotted path to a value")
    raw["vary"] = _normalized_vary(raw.get("vary"))
    return raw


def _base_scenario(scenario_file: Path, overrides: dict) -> Scenario:
    """The base scenario file with the plan's ``set`` values written into its fields, loaded
    and validated as one scenario (a path through a value is named as ``set.<path>``; a path
    or value the scenario refuses as ``set``, with the scenario's own message)."""
    if not overrides:
        return load_scenario(scenario_file)
    try:
        tree = yaml.safe_load(scenario_file.read_text(encoding="utf-8")) or {}
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return load_scenario(scenario_file)          # names the file's own error
    for path, value in overrides.items():
        node, parts = tree, path.split(".")
        for part in parts[:-1]:
            if node.get(part) is None:                  # absent, or an empty section
                node[part] = {}
            node = node[part]
            if not isinstance(node, dict):
                raise InputError(f"set.{path}", value, "the dotted path of a scenario field")
        node[parts[-1]] = value
    try:
        return load_scenario(data=yaml.safe_dump(tree))
    except InputError as e:
        raise InputError("set", overrides, "scenario fields and valid values", str(e)) from None


# Field paths against the scenario's schema -----------------------------------------------------
def _resolve(path: str, base: Scenario) -> int:
    """The number of components of the numeric scenario field at ``path`` (0: a scalar)."""
    node, schema = base, Scenario
    for part in path.split("."):
        hints = typing.get_type_hints(schema) if dataclasses.is_dataclass(schema) else {}
        if part not in hints:
            raise InputError(f"vary.{path}", path, "the dotted path of a numeric scenario field "
                             "(e.g. initial.lateral_offset, contact.mu)", f"no field '{part}'")
        node, schema = getattr(node, part), _present(hints[part])
        if node is None and dataclasses.is_dataclass(schema):
            node = schema()                     # an optional section the base leaves out
    if schema is float:
        return 0
    if typing.get_origin(schema) is list and typing.get_args(schema) == (float,):
        return len(node)
    raise InputError(f"vary.{path}", path, "a numeric field (a number or a list of numbers)",
                     "not a number")


def _check_distribution(f: Field):
    field = f"vary.{f.path}.{f.dist.kind}"
    entries = getattr(f.dist, f.dist.kind)
    if f.dist.kind == "choice":
        n = max(f.size, 1)
        for k, c in enumerate(entries):
            if len(c) != n:
                raise InputError(f"{field}[{k}]", c if f.size else c[0],
                                 f"a list of {n} numbers" if f.size else "a number")
        return
    n = max(f.size, 1)
    if len(entries) != n:
        raise InputError(field, entries, f"one [{_PAIR[f.dist.kind]}] per component ({n})")
    for k, (pair) in enumerate(entries):
        where = field if f.size == 0 else f"{field}[{k}]"
        if len(pair) != 2:
            raise InputError(where, pair, f"[{_PAIR[f.dist.kind]}]")
        if f.dist.kind == "uniform" and not pair[0] <= pair[1]:
            raise InputError(where, pair, "[lo, hi] with lo <= hi")
        if f.dist.kind == "normal" and not pair[1] > 0:
            raise InputError(where, pair, "[mean, sd] with sd > 0")


def _present(schema):
    """X of an optional section's type X | None; other types as they are."""
    args = typing.get_args(schema)
    if type(None) in args and len(args) == 2:
        return next(a for a in args if a is not type(None))
    return schema


def _field_names(kind) -> set:
    """The field names of a scenario section's type: a dataclass, or a Drake config struct
    (its ``__fields__``); none for a value's type."""
    if dataclasses.is_dataclass(kind):
        return {f.name for f in dataclasses.fields(kind)}
    return {f.name for f in getattr(kind, "__fields__", ())}


def _check_path(path: str, value) -> None:
    """Raises `InputError` unless ``path`` runs through fields of the scenario's schema (by
    the types, so that an optional section the scenario leaves out is checked too)."""
    kind = Scenario
    for p in path.split("."):
        if p not in _field_names(kind):
            raise InputError(path, value, "the dotted path of a scenario field",
                             f"no field '{p}' in {getattr(kind, '__name__', kind)}")
        kind = (_present(typing.get_type_hints(kind)[p]) if dataclasses.is_dataclass(kind)
                else None)                  # a Drake struct's fields are values here


def set_field(scenario: Scenario, path: str, value):
    """Sets the dotted field ``path`` of ``scenario`` (in place) to ``value``; an optional
    section the scenario leaves out (``thrust``) is added with its defaults first. A path
    through no field raises `InputError` and leaves the scenario as it was."""
    _check_path(path, value)
    *parents, last = path.split(".")
    node = scenario
    for p in parents:
        child = getattr(node, p)
        if child is None:
            kind = _present(typing.get_type_hints(type(node))[p])
            child = kind()
            setattr(node, p, child)
        node = child
    setattr(node, last, value)


def _ends(f: Field):
    """The values at the ends of its range: the lo and hi corners, or every choice."""
    entries = getattr(f.dist, f.dist.kind)
    ends = entries if f.dist.kind == "choice" else [[p[0] for p in entries],
                                                   [p[1] for p in entries]]
    if f.dist.kind == "normal":
        return []
    return [list(map(float, e)) if f.size else float(e[0]) for e in ends]


def validate_plan(plan: CampaignPlan, base: Scenario) -> list[Field]:
    """The varied fields in sorted path order, after checking every plan value and that each
    end of each range (the others at the base scenario's values) is a valid scenario."""
    if not 1 <= plan.samples <= MAX_SAMPLES:
        raise InputError("samples", plan.samples, f"1 <= samples <= {MAX_SAMPLES}")
    if not 0 <= plan.seed < 2**63:
        raise InputError("seed", plan.seed, "0 <= seed < 2**63")
    if plan.sampler not in SAMPLERS:
        raise InputError("sampler", plan.sampler, f"one of {', '.join(SAMPLERS)}")
    if not 1 <= plan.batch <= MAX_BATCH:
        raise InputError("batch", plan.batch, f"1 <= batch <= {MAX_BATCH}")
    fields = [Field(p, _resolve(p, base), plan.vary[p]) for p in sorted(plan.vary)]
    for f in fields:
        _check_distribution(f)
        for value in _ends(f):
            s = copy.deepcopy(base)
            set_field(s, f.path, value)
            try:
                validate(s)
            except InputError as e:
                raise InputError(f"vary.{f.path}", getattr(f.dist, f.dist.kind),
                                 "a range whose ends make valid scenarios", str(e)) from None
    varied = [f.path for f in fields]
    if plan.axes:
        if len(plan.axes) != 2 or len(set(plan.axes)) != 2:
            raise InputError("axes", plan.axes, "two different varied fields")
        for a in plan.axes:
            if a not in varied:
                raise InputError("axes", a, f"a varied field ({', '.join(varied)})")
    return fields


def figure_axes(plan: CampaignPlan, fields: list[Field]) -> list[str]:
    """The two inputs of the capture-probability figure: the plan's ``axes``, else lateral
    offset against tilt when both are varied, else the first two varied fields."""
    varied = [f.path for f in fields]
    if plan.axes:
        return list(plan.axes)
    if all(a in varied for a in DEFAULT_AXES):
        return list(DEFAULT_AXES)
    return varied[:2]


def load_plan(filename) -> tuple[CampaignPlan, Scenario, list[Field]]:
    """Loads and validates a plan file and its base scenario: (plan, base scenario, varied
    fields). Raises `InputError` naming the field for any bad value."""
    filename = Path(filename)
    try:
        data = filename.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise InputError("plan file", str(filename), "a readable YAML text file",
                         getattr(e, "strerror", None) or str(e)) from None
    raw = _raw(data, str(filename))
    overrides = raw.pop("set", None) or {}
    try:
        plan = yaml_load_typed(schema=CampaignPlan, data=yaml.safe_dump(raw))
    except (RuntimeError, ValueError, TypeError) as e:
        raise InputError("plan", str(filename), "values of the documented types",
                         str(e)) from None
    scenario_file = filename.parent / plan.scenario
    base = _base_scenario(scenario_file, overrides)
    plan.scenario = str(scenario_file)
    return plan, base, validate_plan(plan, base)

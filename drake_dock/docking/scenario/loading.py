"""The scenario file: loaded from YAML into the schema (`drake_dock.docking.scenario.schema`) with
Drake's ``yaml_load_typed`` and validated (`drake_dock.docking.scenario.validation`), and
written back (`scenario_dict`, `scenario_yaml`).

Every value is validated on load; a bad one raises `InputError` naming the dotted field, the
value and the allowed range. Unknown keys are errors too (named with their full path).
"""

import dataclasses
import types
import typing
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_load_typed

from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.docking.scenario.schema import Scenario
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import InputError


# Raw checks ------------------------------------------------------------------------------------
def _schema_fields(schema):
    """{name: type} of a dataclass or of a Drake class that Drake's YAML loader reads through
    its ``__fields__`` (SimulatorConfig); None for other types."""
    if dataclasses.is_dataclass(schema):
        return typing.get_type_hints(schema)
    if isinstance(schema, type) and hasattr(schema, "__fields__"):
        return {f.name: f.type for f in schema.__fields__}
    return None


def _check_raw(node, schema, path):
    """Walks the raw YAML against the dataclass tree, so that an unknown key or a value of the
    wrong type is named by its dotted path before Drake's loader sees it."""
    where = path.rstrip(".") or "scenario"
    hints = _schema_fields(schema)
    if hints is not None:
        if not isinstance(node, dict):
            raise InputError(where, node, "a mapping of fields")
        for key, value in node.items():
            if key not in hints:
                allowed = ", ".join(hints)
                raise InputError(f"{path}{key}", value, f"a known field of '{where}' ({allowed})",
                                 "unknown key")
            _check_raw(value, hints[key], f"{path}{key}.")
    elif schema is float:
        # Drake's typed loader applies float() to scalars (so '1.0e9', a YAML 1.1 string, loads).
        ok = isinstance(node, (int, float, str)) and not isinstance(node, bool)
        if ok and isinstance(node, str):
            try:
                float(node)
            except ValueError:
                ok = False
        if not ok:
            raise InputError(where, node, "a number")
    elif schema is str:
        if not isinstance(node, str):
            raise InputError(where, node, "a string")
    elif schema is bool:
        if not isinstance(node, bool):
            raise InputError(where, node, "true or false")
    elif typing.get_origin(schema) is list:
        if not isinstance(node, list):
            raise InputError(where, node, "a list of numbers")
        (item,) = typing.get_args(schema)
        for k, x in enumerate(node):
            _check_raw(x, item, f"{where}[{k}].")
    elif typing.get_origin(schema) is types.UnionType and node is not None:
        (item,) = [a for a in typing.get_args(schema) if a is not type(None)]   # X | None
        _check_raw(node, item, path)


# Writing ---------------------------------------------------------------------------------------
def scenario_dict(node):
    """A scenario (or any part of it) as plain data: every field, the defaults filled in and
    None kept (null: a tolerance left out), in the order of the dataclasses; what
    `load_scenario` reads back to an equal scenario."""
    fields = _schema_fields(type(node))
    if fields is not None:
        return {name: scenario_dict(getattr(node, name)) for name in fields}
    if isinstance(node, (list, tuple)):
        return [scenario_dict(x) for x in node]
    return node


class _Dumper(yaml.SafeDumper):
    """Sections and fields one a line, vectors on one line ([x, y, z])."""


_Dumper.add_representer(list, lambda d, v: d.represent_sequence("tag:yaml.org,2002:seq", v,
                                                                flow_style=True))


def scenario_yaml(scenario: Scenario) -> str:
    """The full scenario as YAML (`scenario_dict`): `drake-dock run --print-scenario`."""
    return yaml.dump(scenario_dict(scenario), Dumper=_Dumper, sort_keys=False,
                     default_flow_style=False, width=100)


def load_scenario(filename=None, *, data: str | None = None) -> Scenario:
    """Loads and validates a scenario from a YAML file (default: the paper's example) or a
    string. Raises `InputError` (a ValueError) naming the field for any bad value, and for an
    unreadable file."""
    if data is None:
        filename = Path(filename) if filename is not None else PAPER_EXAMPLE
        try:
            data = filename.read_text(encoding="utf-8")
        except OSError as e:
            raise InputError("scenario file", str(filename), "a readable YAML file",
                             e.strerror or str(e)) from None
        except UnicodeDecodeError as e:
            raise InputError("scenario file", str(filename), "a YAML text file (UTF-8)",
                             f"byte {e.start} is not UTF-8 text: a binary file?") from None
    try:
        raw = yaml.safe_load(data)
    except yaml.YAMLError as e:
        raise InputError("scenario file", str(filename or "<string>"), "valid YAML",
                         str(e).splitlines()[0]) from None
    if raw is None:
        raise InputError("scenario file", str(filename or "<string>"),
                         f"a YAML mapping of sections "
                         f"({', '.join(f.name for f in dataclasses.fields(Scenario))}); "
                         f"`drake-dock run --print-scenario` prints a complete one",
                         "the file holds no YAML content (empty, or only comments)")
    if not isinstance(raw, dict):
        raise InputError("scenario", raw, "a mapping of fields")
    _check_raw(raw, Scenario, "")
    try:
        s = yaml_load_typed(schema=Scenario, data=data)
    except (RuntimeError, ValueError, TypeError) as e:
        raise InputError("scenario", str(filename or "<string>"),
                         "values of the documented types", str(e)) from None
    return validate(s)

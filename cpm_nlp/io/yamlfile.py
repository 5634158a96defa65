"""Reading YAML input files (problem files, presets, mechanism files)."""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import yaml

from ..core.errors import InputError


class _Loader(yaml.SafeLoader):
    """YAML with two YAML 1.2 readings that users expect:

    * ``1e-10`` is a float (PyYAML's YAML 1.1 wants ``1.0e-10`` and would hand
      the solver the string "1e-10"),
    * only true/false are booleans (``ipopt.sb: yes`` stays the string IPOPT wants).
    """


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def load_yaml_text(text: str) -> Any:
    """Parse YAML text with the problem-file rules (see :class:`_Loader`)."""
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass


def read_yaml(path: str | os.PathLike) -> Any:
    """Parse a YAML file; errors name the file and the line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except IsADirectoryError:
        raise InputError("expected a YAML file, got a directory", file=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the file ({exc.__class__.__name__}: {exc})", file=str(path)) from None
    try:
        return load_yaml_text(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"malformed YAML: {where}{problem}", file=str(path)) from None
    except (ValueError, OverflowError, RecursionError) as exc:  # e.g. timestamps out of range
        raise InputError(f"malformed YAML: {exc}", file=str(path)) from None

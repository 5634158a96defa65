"""Where a mechanism came from, as a typed value (never parsed back from its text).

`Origin` is what `cpm_nlp.core.mechanism.Mechanism.origin` holds and
what a result records (``"origin"`` in its JSON), so that a plot or a new solve
rebuilds the very mechanism that was solved:

- ``built-in``: a mechanism shipped with cpm_nlp, by its name;
- ``file``: a mechanism file, by its path and the SHA-256 of its bytes;
- ``inline``: a mechanism described in a problem file (the description itself is
  recorded, with the SHA-256 of its canonical JSON) or in code;
- ``plugin``: a package's entry point (``detail``: the entry point and package);
- ``code``: a declaration registered in code (``detail``: what its author wrote).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .digest import sha256_hex

#: the kinds of origin
ORIGIN_KINDS = ("built-in", "file", "inline", "plugin", "code")


@dataclass(frozen=True)
class Origin:
    """Where a mechanism came from (see the module's text).

    Attributes
    ----------
    kind
        one of `ORIGIN_KINDS`;
    name
        the mechanism's name (in a result's record);
    path
        a mechanism file's path (``file``), or the folder an inline description's relative paths
        are read from;
    sha256
        of the file's bytes, or of the inline description's canonical JSON;
    detail
        free text for messages (a plugin's entry point);
    description
        an inline description as written (data).
    """

    kind: str
    name: str = ""
    path: str = ""
    sha256: str = ""
    detail: str = ""
    description: Any = field(default=None, compare=False, hash=False, repr=False)

    def __post_init__(self) -> None:
        if self.kind not in ORIGIN_KINDS:
            raise ValueError(f"origin kind must be one of {', '.join(ORIGIN_KINDS)}, got {self.kind!r}")

    def __str__(self) -> str:
        """The text of messages: "built-in", "file <path>", "plugin 'x' (...)", ..."""
        if self.kind == "built-in":
            return "built-in"
        if self.kind == "file":
            return f"file {self.path}"
        if self.kind == "plugin":
            return f"plugin {self.name!r} ({self.detail})" if self.detail else f"plugin {self.name!r}"
        if self.kind == "inline":
            return self.detail or "described in code"
        return self.detail or "declared in code"

    def to_dict(self) -> dict[str, Any]:
        """The record a result keeps (only the keys that say something)."""
        out: dict[str, Any] = {"kind": self.kind, "name": self.name}
        for key in ("path", "sha256", "detail"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        if self.description is not None:
            out["description"] = self.description
        return out

    @classmethod
    def from_dict(cls, d: Any) -> Origin | None:
        """The origin a result records, None if the record is missing or damaged."""
        if not isinstance(d, dict) or d.get("kind") not in ORIGIN_KINDS:
            return None
        text = {k: d.get(k) if isinstance(d.get(k), str) else "" for k in ("name", "path", "sha256", "detail")}
        return cls(d["kind"], description=d.get("description"), **text)


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex)."""
    return sha256_hex(Path(path).read_bytes())


def data_sha256(data: Any) -> str:
    """SHA-256 of data's canonical JSON (sorted keys, no spaces; hex)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False, default=str)
    return sha256_hex(text.encode())


def as_origin(value: Any, name: str = "") -> Origin:
    """An origin given as an `Origin`, or as the text a declaration in code wrote
    ("built-in" is the built-in kind; any other text is kept as the ``code`` kind's detail)."""
    if isinstance(value, Origin):
        return value
    if value == "built-in":
        return Origin("built-in", name)
    return Origin("code", name, detail=str(value))

"""A mechanism file's declared options: its parameters (validated like a built-in mechanism's
options) and its joint-limit options with the descriptions its ``limits`` section gives."""

from __future__ import annotations

import dataclasses

from ...core.errors import InputError, suggest
from ...core.options import Option
from .spec import Description


def parameter_options(d: Description) -> tuple[Option, ...]:
    """The declared parameters as options (validated like a built-in mechanism's)."""
    return tuple(
        Option(
            p.name,
            p.dimension,
            p.description or p.name,
            default=p.default,
            lower=p.lower,
            upper=p.upper,
            strict=p.strict,
        )
        for p in d.parameters
    )


def described_limits(options: tuple[Option, ...], d: Description) -> tuple[Option, ...]:
    """The joint-limit options with the descriptions the file's ``limits:`` gives (a family
    the mechanism does not have is an error, with a "did you mean")."""
    names = [o.name for o in options]
    for fam in d.limits:
        if fam not in names:
            raise InputError(
                f"unknown joint-limit family {fam!r}; this mechanism's are: {', '.join(names) or 'none'}",
                path=("limits", fam),
                suggestions=suggest(fam, names),
            )
    return tuple(dataclasses.replace(o, description=d.limits[o.name]) if d.limits.get(o.name) else o for o in options)


__all__ = ["described_limits", "parameter_options"]

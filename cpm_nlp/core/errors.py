"""Exceptions of cpm_nlp.

Two kinds of failure are kept apart on purpose:

* [`InputError`][cpm_nlp.core.errors.InputError] -- the problem as given cannot be solved as written (a
  malformed file, an unknown key, a wrong unit, a negative length ...).  The CLI
  turns it into one line on stderr and exit status 2.
* A solve that runs but does not reach a trustworthy answer is *not* an
  exception: it is a [`Result`][cpm_nlp.core.result.Result] whose ``status`` says why
  (exit status 1 on the CLI).
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence

# The library logs and never prints: its logger has a NullHandler, so that a warning is not
# written to stderr by logging's last resort when the application configured no logging.  It
# is attached here, not in cpm_nlp/__init__, because every module that logs imports this one
# (a test checks it) and ``cpm-nlp --help``, which imports neither, then starts without the
# logging module (4 ms of its 50, issue 23).
logging.getLogger("cpm_nlp").addHandler(logging.NullHandler())

KeyPath = tuple  # tuple[str | int, ...]


def format_key_path(path: Sequence[str | int]) -> str:
    """Render ``("inputs", "dz", 2)`` as ``inputs.dz[2]``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def suggest(word: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """Close matches of ``word`` among ``candidates`` (for "did you mean")."""
    import difflib  # only where a name is wrong: a run that goes well never loads it (issue 23, start-up)

    candidates = [str(c) for c in candidates]
    lowered = {c.lower(): c for c in candidates}
    w = str(word).lower()
    hits = difflib.get_close_matches(w, list(lowered), n=n, cutoff=0.6)
    if len(w) >= 3:  # "tolerance" -> "tol", "beta" -> "beta_m"
        hits += [c for c in lowered if len(c) >= 3 and c not in hits and (w.startswith(c) or c.startswith(w))]
    return [lowered[h] for h in hits[:n]]


#: Longest message part of an error (a message quoting a large input is cut).
MAX_MESSAGE = 400


def _shorten(text: str, limit: int) -> str:
    """``text`` cut to about ``limit`` characters, saying how much was left out."""
    text = str(text)
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... ({len(text) - limit} more characters)"


class CpmError(Exception):
    """Base class of every exception raised by cpm_nlp on purpose."""


class InputError(CpmError):
    """The input (file, key path, value) is not what was expected.

    Parameters
    ----------
    message
        What was expected and what was found, e.g. ``"expected a positive length
        (e.g. '47.91 mm'), got '-3 mm'"``.
    path
        Key path inside the problem file, e.g. ``("mechanism", "parameters", "b")``.
    file
        The problem file, when there is one.
    suggestions
        Candidates for a "did you mean" hint.
    hint
        What the user can do next, when it is not obvious from the message.
    """

    def __init__(
        self,
        message: str,
        *,
        path: Sequence[str | int] = (),
        file: str | None = None,
        suggestions: Sequence[str] = (),
        hint: str | None = None,
    ) -> None:
        self.message = message
        self.path = tuple(path)
        self.file = file
        self.suggestions = tuple(suggestions)
        self.hint = hint
        super().__init__(self.render())

    def render(self) -> str:
        where = []
        message = _shorten(self.message, MAX_MESSAGE)
        if self.file:
            where.append(_shorten(str(self.file), 200))
        if self.path:
            where.append(_shorten(format_key_path(self.path), 200))
        text = ": ".join(where + [message]) if where else message
        if self.suggestions:
            text += "; did you mean " + " or ".join(f"'{_shorten(s, 80)}'" for s in self.suggestions[:3]) + "?"
        if self.hint:
            text += f" ({_shorten(self.hint, 300)})"
        # one message, one line: control characters from the input are escaped
        return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in text)

    def __str__(self) -> str:
        return self.render()

    def at(self, *, file: str | None = None, prefix: Sequence[str | int] = ()) -> InputError:
        """Return a copy located in ``file`` under the key path ``prefix``."""
        return InputError(
            self.message,
            path=tuple(prefix) + self.path,
            file=file if file is not None else self.file,
            suggestions=self.suggestions,
            hint=self.hint,
        )


def unknown_key_error(key: str, allowed: Iterable[str], path: Sequence[str | int], what: str) -> InputError:
    """An [`InputError`][cpm_nlp.core.errors.InputError] for a key that is not allowed, with suggestions."""
    allowed = sorted(allowed)
    return InputError(
        f"unknown {what} {key!r}; expected one of: {', '.join(allowed)}",
        path=tuple(path),
        suggestions=suggest(key, allowed),
    )

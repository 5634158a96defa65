"""Where the shipped problem files and solver presets are."""

from __future__ import annotations

from pathlib import Path

#: the checkout (or installation) root that holds problems/ and configs/
_ROOT = Path(__file__).resolve().parents[2]


def shipped_problems_dir() -> Path:
    """The directory of the problem files shipped with cpm_nlp."""
    return _ROOT / "problems"


def shipped_configs_dir() -> Path:
    """The directory of the solver presets shipped with cpm_nlp."""
    return _ROOT / "configs"

"""Writing figures: the file types, early checks of the path and the plotting
library it needs, and `save` (atomic; PNG, SVG, PDF, or a Plotly HTML file).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..core.errors import InputError
from ..io.atomic import check_output_path, replace_atomically

#: file types `save` writes (.html: an interactive Plotly figure, `cpm_nlp.plot.interactive`)
FIGURE_FORMATS = (".png", ".svg", ".pdf", ".html")

# -- saving -----------------------------------------------------------------------------------


def check_figure_path(path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Fail early (an [`InputError`][cpm_nlp.core.errors.InputError]) if a figure cannot be written there
    (or would replace one of ``inputs``)."""
    if Path(path).suffix.lower() not in FIGURE_FORMATS:
        raise InputError(
            f"expected a figure file ending in {', '.join(FIGURE_FORMATS)}, got {str(path)!r}", path=(option,)
        )
    check_output_path(str(path), inputs, option=option)


def require_backend(path: str | os.PathLike) -> None:
    """The plotting library a figure file needs is installed (an [`InputError`][cpm_nlp.core.errors.InputError] saying
    which extra installs it if not): Plotly for .html, Matplotlib for the others."""
    from ..core.extras import require

    if Path(path).suffix.lower() == ".html":
        require("plotly", "plot", "interactive (.html) plots")
    else:
        require("matplotlib", "plot", "plotting")


def save(fig: Any, path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Write a figure (format from the suffix) all at once; .html: a Plotly figure,
    self-contained (plotly.js embedded: it opens without a network)."""
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt == "html":
        replace_atomically(
            path,
            lambda tmp: fig.write_html(tmp, include_plotlyjs=True, full_html=True),
            suffix=".html",
            inputs=inputs,
            option=option,
        )
        return
    replace_atomically(
        path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=150), suffix=f".{fmt}", inputs=inputs, option=option
    )

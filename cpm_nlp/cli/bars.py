"""Progress bars on a terminal: `cpm_nlp.core.progress` reports, the CLI draws (tqdm)."""

from __future__ import annotations

import argparse
import contextlib

from ..core import progress

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any


#: the unit a progress bar counts, by the name of the computation (default: items)
_UNITS = {
    "forward kinematics": "poses",
    "inverse kinematics": "poses",
    "assembly-mode search": "starts",
    "assembly-mode search, Newton": "starts",
    "certifying the assembly modes": "sub-boxes",
    "merging the converged starts": "poses",
    "sweep": "points",
    "reproducing the published figures": "problem files",
}


def progress_bars(args: argparse.Namespace) -> progress.Callback | None:
    """On a terminal (stderr), a tqdm progress bar per long computation
    (`cpm_nlp.core.progress` reports, the CLI draws); none with ``-q`` or
    when stderr is not a terminal (a log, a pipe)."""
    if getattr(args, "quiet", False) or not getattr(args.err, "isatty", lambda: False)():
        return None
    from tqdm import tqdm

    bars: dict[str, Any] = {}
    args.bars = bars  # closed by main() on Ctrl-C, so that "interrupted" starts a line

    def show(what: str, done: int, total: int) -> None:
        bar = bars.get(what)
        if bar is None:
            unit = _UNITS.get(what, "items")
            bar = bars[what] = tqdm(
                total=total or None,
                initial=done,  # a bar starts at its first report: its rate counts from there
                desc=what,
                unit=f" {unit}",
                file=args.err,
                dynamic_ncols=True,
                disable=False,
                leave=False,  # a finished bar is erased: the result follows on a clean screen
                mininterval=0,  # cpm_nlp.core.progress reports every 0.2 s at most already
            )
        bar.update(done - bar.n)
        if total and done >= total:
            bar.close()
            del bars[what]

    return show


def close_bars(args: argparse.Namespace) -> None:
    """Close the progress bars left open by an interruption (each ends its line)."""
    for bar in list(getattr(args, "bars", {}).values()):
        with contextlib.suppress(Exception):
            bar.close()
    getattr(args, "bars", {}).clear()

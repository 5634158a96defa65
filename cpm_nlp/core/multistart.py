"""Seeded multi-start for the NLPs of cpm_nlp (IPOPT finds local optima).

Starts are reproducible: the first is the caller's (e.g. the home pose or the
design of the problem file), the rest are drawn from a seeded generator.
The best converged start is reported with how many others reached the same
objective.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .options import Option

#: two objectives agree when they differ by at most this, relative to the best
AGREEMENT = 1e-4

#: starts of an assembly-mode search (`cpm_nlp.analysis.assembly.assembly_modes`, the
#: ``mode_starts`` of a forward_kinematics problem): all 40 modes of Dietmaier's platform with
#: probability 0.999 (estimated from the basins of 100 000 starts; benchmarks/bench_assembly_modes.py
#: measures it over seeds).  Here, not in the search's module, so that the kind declaring
#: the option does not import the search (issue 23, start-up)
DEFAULT_STARTS = 12000


def uniform_starts(lower, upper, count: int, seed: int, first=None) -> np.ndarray:
    """``count`` points in the box [lower, upper] (count, n): ``first`` (clipped
    into the box) if given, then seeded uniform draws."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    rng = np.random.default_rng(seed)
    pts = lower + (upper - lower) * rng.random((count, lower.size))
    if first is not None and count:
        pts[0] = np.clip(np.asarray(first, dtype=float), lower, upper)
    return pts


def best_and_agreement(objectives: Sequence[float | None], tolerance: float = AGREEMENT) -> tuple[int | None, int]:
    """Index of the smallest objective among converged starts (None entries
    did not converge) and how many converged starts agree with it."""
    vals = [(k, v) for k, v in enumerate(objectives) if v is not None and np.isfinite(v)]
    if not vals:
        return None, 0
    best, fbest = min(vals, key=lambda kv: kv[1])
    scale = max(abs(fbest), 1e-300)
    return best, sum(1 for _, v in vals if abs(v - fbest) <= tolerance * scale)


def start_options(default: int = 8) -> list[Option]:
    """The inputs ``starts`` and ``seed`` of a multi-start problem kind."""
    return [
        Option("starts", "int", "number of IPOPT starts (seeded)", default=default, lower=1, upper=200),
        Option("seed", "int", "seed of the random starts", default=0, lower=0, upper=2**32 - 1),
    ]

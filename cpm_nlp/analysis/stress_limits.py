"""Stress limits as joint limits: each hinge's largest rotation at the allowable stress, as
the limits of the joint coordinates it carries (a workspace or cuboid under a stress limit)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from ..core.model import Model
from .compliance import HingeSet


def stress_angle_limits(hs: HingeSet, sigma_allow: float) -> dict[str, tuple[float, float]]:
    """Joint limits from a stress limit: for each joint coordinate carried by a hinge
    with a geometry, θ0 ± δ, δ the deflection about that axis alone at which the hinge
    reaches sigma_allow (the smallest over the hinges on that joint).  The minimal
    generalization of pantograph-3d-elgammal-2016.md eq 31 (ψ = π/2 ∓ δ_max): deflections
    about several axes of one hinge at once add up, which per-axis limits do not see."""
    out: dict[str, tuple[float, float]] = {}
    for h in hs.hinges:
        for axis, i in h.axes.items():
            delta = h.angle_limit(axis, sigma_allow)
            if delta is None:
                continue
            name = hs.names[i]
            lo, hi = hs.theta0[i] - delta, hs.theta0[i] + delta
            if name in out:
                lo, hi = max(lo, out[name][0]), min(hi, out[name][1])
            out[name] = (float(lo), float(hi))
    return out


def with_limits(model: Model, limits: Mapping[str, tuple[float, float]]) -> Model:
    """A copy of the model with extra joint limits (each intersected with any it has)."""
    merged = dict(model.limits)
    coords = {c.name: c for c in list(model.closure.x) + list(model.closure.q) + list(model.closure.passive_coords)}
    for name, (lo, hi) in limits.items():
        old = model.limit_of(coords[name])
        if old is not None:
            lo, hi = max(lo, old[0]), min(hi, old[1])
        merged[name] = (lo, hi)
    return dataclasses.replace(model, limits=merged)

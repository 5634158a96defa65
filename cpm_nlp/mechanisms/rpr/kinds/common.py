"""What the RPR's problem kinds share: the kind base (the ``rpr`` mechanism only), the pose
inputs and the result of a kind."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from ....analysis import flexure
from ....core.errors import InputError
from ....core.kind import ProblemKind
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output, declared_for, declared_result
from ....core.result import STATUS_TEXT, Result, SolverInfo, Status
from ....kinds.kinematic import _model_info

MM = 1e-3


class RprKind(ProblemKind):
    """A problem kind that applies to the RPR mechanism only."""

    def supports(self, model: Model) -> str | None:
        return None if model.name == "rpr" else "it is specific to the RPR mechanism (type rpr)"


def _pose_options(model: Model) -> list[Option]:
    """The pose (theta, alpha, P) of the file's closure, each defaulting to the initial pose."""
    return [
        Option(c.name, c.kind, c.description + " (default: the initial pose)", default=None) for c in model.closure.x
    ]


def _pose(model: Model, inputs: Mapping[str, Any]) -> np.ndarray:
    return np.array(
        [model.x_home[i] if inputs.get(c.name) is None else inputs[c.name] for i, c in enumerate(model.closure.x)]
    )


def _matrix(a: np.ndarray) -> list:
    return np.asarray(a, dtype=float).tolist()


def _finish(
    kind: ProblemKind,
    model: Model,
    status: Status,
    values: Mapping[str, Any],
    solver: SolverInfo | None = None,
    message: str = "",
) -> Result:
    """The result of an RPR kind: its values (none unless solved), each of an output the kind
    declares ([`outputs`][cpm_nlp.core.kind.ProblemKind.outputs])."""
    if not status.ok:
        values = {}
    return declared_result(
        kind.name,
        status,
        declared_for(kind.name, kind.outputs(model), values),
        values,
        solver=solver,
        message=message or STATUS_TEXT[status],
        model=_model_info(model),
    )


def _declare(dims: Mapping[str, str], units: Mapping[str, str] | None = None) -> list[Output]:
    """The outputs of an RPR kind by their dimensions, in order, each with its own unit text
    from ``units`` where the dimension's SI unit does not say it (a matrix or a flag has none
    unless given)."""
    texts = units or {}
    out = []
    for name, dimension in dims.items():
        unit = texts.get(name)
        if unit is None and dimension in ("matrix", "bool"):
            unit = ""
        out.append(Output(name, dimension, dimension if dimension in ("matrix", "text") else "value", unit=unit))
    return out


def _check_material(mat: Any, path: tuple) -> flexure.Material:
    mat = flexure.material(mat, path)
    if mat.nu is None or mat.yield_strength is None:
        raise InputError(f"material '{mat.name}' needs nu and yield_strength (eq 32 and the shear modulus)", path=path)
    return mat


def _material_option() -> Any:
    """``material``: a name or inline, with nu and yield strength (eq 32 and the shear modulus)."""
    node = flexure.material_node("material", "the joints' material, with nu and yield_strength", "Al 7075-T6")
    return dataclasses.replace(node, convert=_check_material)

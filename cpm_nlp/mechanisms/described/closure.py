"""The closure of a description: its generator -- the legs' (`Generator`,
each leg's passive joints eliminated) or the graph's (`GraphGenerator`, a
mixed file's legs expanded into bodies and joints) -- and the functions it built; a legs file
whose drawing need not close gets its reference configuration by the assembly of the graph
its legs expand into (`LegsAssembler`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...core.errors import InputError
from ...core.options import REQUIRED
from .builder import ClosureBuilder
from .generate import Generator
from .spec import Description


def closure_parts(d: Description) -> tuple[ClosureBuilder, dict[str, Any]]:
    """The generator of a description -- its legs (`Generator`) or its bodies and joints
    (`GraphGenerator`) -- and the functions it built.  A legs file whose drawing need not
    close (`assembled_from_drawing`) gets its reference configuration by the assembly of
    the graph its legs expand into (`LegsAssembler`); its closures stay the legs'."""
    if d.is_graph:
        # the graph's generator and its assembly are imported for a graph file only: a legs
        # file (the 3-PRS) never loads them (issue 23, start-up)
        from .expand import expand_legs
        from .graph import GraphGenerator

        if d.legs:  # a mixed file: its legs expanded, one graph with its bodies and joints
            d = expand_legs(d)
        g = GraphGenerator(d)
        return g, g.build()
    g = Generator(d)
    fns = g.build()
    if assembled_from_drawing(d):
        fns["assemble"] = LegsAssembler(d, g)
        fns["fk_closed"] = None  # its branch sign would be the drawing's, not the assembled reference's
    return g, fns


def assembled_from_drawing(d: Description) -> bool:
    """Whether a legs file's reference configuration is assembled: a leg's links are drawn by
    their joints, so its drawing closes by construction, except where a rod (a distance joint)
    gives its ``length``: then the drawing's ``to`` (and the platform's home) is only roughly
    there."""
    return any(j.length is not None for leg in d.legs for j in leg.joints)


class LegsAssembler:
    """The reference configuration of a legs file from a rough drawing: the `assembly.Assembler` of
    the graph its legs expand into (`expand.expand_legs`; Gauss-Newton on its loops with the
    actuators at their drawn values), its pose coordinates read by name into the legs' (the
    platform's, then each proximal chain's passive joints')."""

    def __init__(self, d: Description, legs: Generator) -> None:
        from .expand import expand_legs, expansion_gap
        from .graph import GraphGenerator

        gap = expansion_gap(d)
        if gap is not None:
            raise InputError(
                f"a rod's given length makes the reference configuration an assembly, and {gap}",
                path=("legs",),
                hint="give the rods' lengths by their drawing (no 'length'), or write the loops as legs",
            )
        for par in d.parameters:
            if par.default is REQUIRED:
                raise InputError(
                    f"a legs file assembled from its drawing (a rod gives its 'length') needs a default for every "
                    f"parameter ({par.name!r} has none): the loops' rank is taken with the defaults",
                    path=("parameters", par.name, "default"),
                )
        try:
            self.graph = GraphGenerator(expand_legs(d))
            self.graph.build()
        except InputError as exc:
            raise _in_legs(exc) from None
        self.assembler = self.graph.assembler
        where = {n: k for k, n in enumerate(self.graph.x_names)}
        self.columns = []
        for name in legs.x_names:
            # a passive joint of one motion is the graph's joint name (the legs add "_1")
            short = name[:-2] if name.endswith("_1") else name
            k = where.get(name, where.get(short))
            if k is None:  # every legs coordinate is a tree coordinate of the expansion
                raise RuntimeError(f"the expanded graph of {d.name} has no coordinate {name!r}")
            self.columns.append(k)

    def solve(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        x, q, status = self.assembler.solve(p)
        return x[self.columns], q, status

    def __call__(self, p: Any) -> tuple[np.ndarray, np.ndarray]:
        try:
            x, q = self.assembler(p)
        except InputError as exc:
            raise _in_legs(exc) from None
        return x[self.columns], q


def _in_legs(exc: InputError) -> InputError:
    """An error of the expanded graph, located in the legs file (its joints are the legs')."""
    path = exc.path if exc.path and exc.path[0] != "joints" else ("legs",)
    return InputError(exc.message, path=path, suggestions=exc.suggestions, hint=exc.hint)


__all__ = ["LegsAssembler", "assembled_from_drawing", "closure_parts"]

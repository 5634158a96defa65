"""Aliases for the module paths of cpm_nlp 0.1, before the package had layers.

``import cpm_nlp.workspace`` (or ``from cpm_nlp import workspace``) still works and
gives the module at its new place, with a DeprecationWarning that names it.
``cpm_nlp.prs3``, ``cpm_nlp.prc3``, ``cpm_nlp.rpr`` and ``cpm_nlp.pantograph`` are gone (`REMOVED`):
they are mechanism files now.
Three old modules became packages of the same name and are not aliased:
``cpm_nlp.problems`` (its ``ProblemKind`` is in `cpm_nlp.core.kind`, its
``problem_kind`` in `cpm_nlp.problems.registry`), ``cpm_nlp.mechanisms``
(now `cpm_nlp.mechanisms.registry`) and ``cpm_nlp.sweep`` (now
`cpm_nlp.sweep.run`).  See docs/changelog.md.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module name (under cpm_nlp) -> its module now
MOVED = {
    "errors": "core.errors",
    "units": "core.units",
    "options": "core.options",
    "result": "core.result",
    "solver": "core.solver",
    "model": "core.model",
    "kernels": "core.kernels",
    "kinematics": "core.kinematics",
    "batch": "core.batch",
    "compiled": "core.compiled",
    "multistart": "core.multistart",
    "screws": "core.screws",
    "workspace": "analysis.workspace",
    "cuboid_ik": "analysis.cuboid_ik",
    "requirements": "analysis.requirements",
    "flexure": "analysis.flexure",
    "flexure_compliance": "analysis.flexure_compliance",
    "dynamics": "analysis.dynamics",
    "export": "io.export",
    "embed": "io.embed",
    "sweep_files": "io.results",
    "kinematic_problems": "kinds.kinematic",
    "workspace_problems": "kinds.workspace",
    "analysis_problems": "kinds.analysis",
    "synthesis": "kinds.synthesis",
    "rpr_design": "mechanisms.rpr.design",
    "rpr_compliance": "mechanisms.rpr.compliance",
    "rpr_problems": "mechanisms.rpr.kinds",
    "pantograph_synthesis": "mechanisms.pantograph.synthesis",
    "problem_file": "problems.file",
    "reproduce": "problems.reproduce",
    "plots": "plot.draw",
    "figures": "plot.figures",
}


#: old module name (under cpm_nlp) -> why it is gone and what replaces it
REMOVED = {
    "prc3": "the 3-PRC is the mechanism file problems/mechanisms/prc3.yaml since issue 21, with the add-on "
    "cpm_nlp.mechanisms.prc3 (its amplifier kind, its dynamics): cpm_nlp.build_model('prc3', {...}) builds it",
    "pantograph": "the pantograph is the mechanism file problems/mechanisms/pantograph.yaml since issue 21, with "
    "the add-on cpm_nlp.mechanisms.pantograph (the paper's limits, workspace and cuboid in "
    "cpm_nlp.mechanisms.pantograph.analysis, its synthesis): cpm_nlp.build_model('pantograph', {...}) builds it",
    "rpr": "the RPR is the mechanism file problems/mechanisms/rpr.yaml since issue 21, with the add-on "
    "cpm_nlp.mechanisms.rpr (its screw-theory, twist, transmission, joint-design and compliance kinds, its "
    "synthesis; the screw theory of eq 7-13 in cpm_nlp.mechanisms.rpr.screws): cpm_nlp.build_model('rpr', {...}) "
    "builds it",
    "prs3": "the 3-PRS is the mechanism file problems/mechanisms/prs3.yaml since issue 21: "
    "cpm_nlp.build_model('prs3', {...}) builds it, cpm_nlp.mechanism_type('prs3') declares it",
}


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``cpm_nlp.<old>`` and loads it as the module at its new place."""

    def __init__(self) -> None:
        self._specs: dict = {}

    def find_spec(self, fullname, path=None, target=None):  # noqa: ARG002 - the finder protocol
        package, _, leaf = fullname.rpartition(".")
        if package == "cpm_nlp" and leaf in REMOVED:
            raise ModuleNotFoundError(f"{fullname} was removed: {REMOVED[leaf]}", name=fullname)
        if package != "cpm_nlp" or leaf not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        new = f"cpm_nlp.{MOVED[spec.name.rpartition('.')[2]]}"
        warnings.warn(f"{spec.name} moved to {new}; the old name will be removed", DeprecationWarning, stacklevel=2)
        module = importlib.import_module(new)
        self._specs[spec.name] = module.__spec__
        return module

    def exec_module(self, module):
        """The module is already executed at its new place; keep its own spec (the import
        system set the alias's)."""
        module.__spec__ = self._specs.get(module.__spec__.name, module.__spec__)


def install() -> None:
    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.append(_Alias())

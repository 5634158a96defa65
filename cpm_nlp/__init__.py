"""cpm_nlp: kinematics and design of compliant parallel mechanisms with CasADi and IPOPT.

Quick start::

    import cpm_nlp as cn
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    pose = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3])
    pose.status, pose.x          # Status.SOLVED, (px, py, pz, psi, theta, phi) in SI

or, from a problem file::

    result = cn.solve(cn.load_problem("problems/prs3_forward_kinematics.yaml"))

The public names are those of `cpm_nlp.api` (listed once, there), loaded
on first use (PEP 562): ``import cpm_nlp`` and the ``cpm-nlp`` command start
without loading CasADi and the solvers until a name is used.  The package's
layers: ``core`` (model, kernels, solvers, units), ``analysis`` (workspace,
cuboid, flexures, dynamics), ``io`` (atomic files, export, results files),
``kinds`` (the generic problem kinds), ``mechanisms`` (the registry and the
built-in mechanisms), ``problems`` (problem files, kinds registry, reproduce),
``sweep``, ``plot`` and ``cli``.
"""

import importlib

from . import _legacy
from .core.version import __version__ as __version__

_legacy.install()
# the package logger's NullHandler is attached by cpm_nlp.core.errors, which every module that
# logs imports: ``cpm-nlp --help`` then starts without the logging module (issue 23, start-up)


def __getattr__(name: str) -> object:
    """A public name of `cpm_nlp.api` (and ``__all__`` itself), imported on first use."""
    api = importlib.import_module(".api", __name__)
    if name == "__all__" or name in api.__all__:
        value = getattr(api, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(importlib.import_module(".api", __name__).__all__))

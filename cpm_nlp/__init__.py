"""cpm_nlp: kinematics and design of compliant parallel mechanisms with CasADi and IPOPT.

Quick start::

    import cpm_nlp as cn
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    pose = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3])
    pose.status, pose.x          # Status.SOLVED, (px, py, pz, psi, theta, phi) in SI

or, from a problem file::

    result = cn.solve(cn.load_problem("problems/prs3_forward_kinematics.yaml"))

The public names are those of :mod:`cpm_nlp.api` (listed once, there).  The
package's layers: ``core`` (model, kernels, solvers, units), ``analysis``
(workspace, cuboid, flexures, dynamics), ``io`` (atomic files, export,
results files), ``kinds`` (the generic problem kinds), ``mechanisms`` (the
registry and the built-in mechanisms), ``problems`` (problem files, kinds
registry, reproduce), ``sweep``, ``plot`` and ``cli``.
"""

import logging

from . import _legacy
from .api import *  # noqa: F403 - the public API, listed once in api.__all__
from .api import __all__, __version__  # noqa: F401

_legacy.install()
logging.getLogger(__name__).addHandler(logging.NullHandler())

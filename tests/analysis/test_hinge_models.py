"""The hinge models as objects (cpm_nlp.analysis.hinge_models, issue 22 item 4): each model is
prepared once per problem and solves the platform compliance itself; the kind
``platform_compliance`` only calls the chosen object.

Byte-identical results before and after the move were checked on every shipped compliance
problem and on 162 platform_compliance cases (every mechanism, hinge model, actuator and load
setting; see the changelog); these tests keep the paths the shipped files do not reach."""

from __future__ import annotations

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import hinge_models as hm
from cpm_nlp.analysis.hinge_chains import SixAxisModel
from cpm_nlp.core.kinematics import inverse_kinematics
from cpm_nlp.core.outputs import Output, Values
from cpm_nlp.core.result import SolverInfo, Status
from cpm_nlp.core.solver import SolverConfig

PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
WHERE = ("inputs", "hinge_axes")


def _problem(**inputs):
    return cn.problem_from_dict(
        {"problem": "platform_compliance", "mechanism": {"type": "prs3", "parameters": PRS3}, "inputs": inputs}
    )


@pytest.fixture(scope="module")
def prs3():
    model = cn.build_model("prs3", PRS3)
    pose = inverse_kinematics(model, model.task_of(model.x_home), SolverConfig())
    assert pose.ok
    return model, cm.hinge_set(model, None), pose


def test_the_kind_only_calls_the_chosen_model():
    """platform_compliance hands the solved pose to the prepared model and reports what it gives."""

    class Fixed(hm.HingeModel):
        def prepare(self, model, hs, path, chosen):  # noqa: ARG002 - the signature of every hinge model
            return hm.Prepared(self, None, chosen)

        def solve(self, prepared, model, hs, pose, load, k_actuator, info):  # noqa: ARG002 - as above
            values = Values().add(Output("hinge_model", "text", "text"), self.name)
            return hm.HingeSolution(Status.SOLVED, values, SolverInfo("fixed", 7), "from the object")

    problem = _problem(k_actuator="1e5 N/m", hinge_axes="kinematic")
    problem.inputs["hinge_model"] = Fixed("fixed", "a test model").prepare(problem.model, None, WHERE, True)
    res = cn.solve(problem)
    assert res.ok and res.values["hinge_model"] == "fixed" and res.message == "from the object"
    assert res.solver.name == "fixed" and res.solver.iterations == 7
    assert list(res.values)[-1] == "hinge_model"  # the pose's values, then the object's only
    assert not {"C", "deflection_linear", "deflection", "q_loaded"} & set(res.values)


def test_a_singular_six_axis_default_falls_back_to_the_kinematic_model(prs3, monkeypatch):
    """The default ``all`` whose stiffness is singular at the pose gives the kinematic model's
    answer with a note; ``all`` chosen by the file is reported singular instead."""
    model, hs, pose = prs3
    ka, load = np.full(3, 1e5), np.eye(model.closure.nx)[0]  # 1 N along the first pose coordinate
    info = SolverInfo("newton")
    kinematic = hm.KINEMATIC.solve(hm.KINEMATIC.prepare(model, hs, WHERE, False), model, hs, pose, load, ka, info)

    def singular(*_args):
        raise np.linalg.LinAlgError("singular")

    monkeypatch.setattr(SixAxisModel, "compliance", singular)
    default = hm.default_hinge_model(model).prepare(model, hs, WHERE, False)
    assert default.hinges is hm.HINGE_MODELS["all"] and default.six_axis is not None
    got = default.solve(model, hs, pose, load, ka, info)
    assert got.status is Status.SOLVED and got.values.values["hinge_model"] == "kinematic"
    assert got.message == kinematic.message + hm.SINGULAR_FALLBACK
    assert got.values.values == kinematic.values.values  # the kinematic model's numbers
    chosen = hm.HINGE_MODELS["all"].prepare(model, hs, WHERE, True).solve(model, hs, pose, load, ka, info)
    assert chosen.status is Status.SINGULAR and "six-axis hinge model's stiffness is singular" in chosen.message
    assert chosen.values.values == {} and chosen.solver is info  # no number that looks like an answer


def test_six_axis_without_an_unloaded_equilibrium_is_not_converged(prs3, monkeypatch):
    model, hs, pose = prs3
    prepared = hm.HINGE_MODELS["all"].prepare(model, hs, WHERE, True)
    monkeypatch.setattr(SixAxisModel, "newton", lambda *_args: (False, None, None, 50))
    got = prepared.solve(model, hs, pose, np.zeros(model.closure.nx), None, SolverInfo("newton", 3))
    assert got.status is Status.NOT_CONVERGED and "no unloaded equilibrium" in got.message
    assert got.values.values == {} and got.solver.iterations == 3


def test_the_six_axis_model_is_the_more_compliant(prs3):
    """Rayleigh: the six-axis model frees the axes the kinematic model holds rigid (with the same
    stiffness about the moved axes), so C_all - C_kinematic is positive semidefinite at home."""
    model, hs, pose = prs3
    ka, info = np.full(3, 1e5), SolverInfo("newton")
    f = np.zeros(model.closure.nx)
    kin = hm.KINEMATIC.prepare(model, hs, WHERE, True).solve(model, hs, pose, f, ka, info)
    six = hm.HINGE_MODELS["all"].prepare(model, hs, WHERE, True).solve(model, hs, pose, f, ka, info)
    assert kin.status is Status.SOLVED and six.status is Status.SOLVED
    c_kin, c_six = np.array(kin.values.values["C"]), np.array(six.values.values["C"])
    scale = np.max(np.abs(c_six))
    assert np.min(np.linalg.eigvalsh(0.5 * ((c_six - c_kin) + (c_six - c_kin).T))) >= -1e-9 * scale
    assert np.trace(c_six) > np.trace(c_kin)  # strictly: the legs' extra axes do deflect

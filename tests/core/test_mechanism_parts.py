"""A smaller Mechanism and formulations as objects (issue 22, items 3 and 4): the parts a kind
reads, the hinges parsed once, a model that records its mechanism, a closure without a
back-pointer or a solver cache, and the cuboid formulation and hinge model as tables of
objects."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import hinge_models as hm
from cpm_nlp.analysis.workspace import cuboid as wc
from cpm_nlp.core import solver as cs
from cpm_nlp.core.mechanism import CHECKS, Addon, Mechanism, MechanismDeclarationError, with_addon
from tests.conftest import PROBLEMS

PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}


def test_core_mechanism_names_no_kind():
    """Mechanism keeps what every mechanism has; the parts live with their kinds."""
    fields = set(Mechanism.__dataclass_fields__)
    assert fields == {
        "name",
        "title",
        "parameters",
        "limits",
        "closure",
        "build",
        "paper",
        "check_parameters",
        "check_limits",
        "geometry",
        "parts",
        "kinds",
        "problem_files",
        "origin",
    }
    assert set(CHECKS) <= fields
    homes = {
        cn.SynthesisFormulation: "cpm_nlp.kinds.synthesis",
        cn.CuboidExtras: "cpm_nlp.kinds.workspace",
        cn.PaperMembership: "cpm_nlp.kinds.workspace",
        cn.DynamicsModel: "cpm_nlp.analysis.dynamics",
        cn.JointStiffness: "cpm_nlp.analysis.compliance",
        cn.LegChains: "cpm_nlp.core.chains",  # beside its Chains: no scipy at start-up
    }
    for part, module in homes.items():
        assert part.__module__ == module and issubclass(part, cn.Part)


def test_the_shipped_mechanisms_register_their_parts():
    pantograph, prc3, rpr, prs3 = (cn.mechanism_type(n) for n in ("pantograph", "prc3", "rpr", "prs3"))
    assert [p.capability for p in pantograph.parts] == ["synthesis", "cuboid", "paper_membership"]
    assert [p.capability for p in prc3.parts] == ["dynamics"]
    assert [p.capability for p in rpr.parts] == ["synthesis", "stiffness", "chains"]
    assert [p.capability for p in prs3.parts] == ["stiffness", "chains"]
    assert prs3.capabilities() == ["geometry", "stiffness", "chains", "problem_files"]
    # a built model reads them through its mechanism
    model = cn.build_model("prs3", PRS3)
    assert model.mechanism is prs3 and model.mechanism.part(cn.DynamicsModel) is None


def test_an_addon_part_of_a_type_the_file_has_is_refused():
    prs3 = cn.mechanism_type("prs3")
    again = Addon(parts=(prs3.part(cn.JointStiffness),))
    with pytest.raises(MechanismDeclarationError, match=r"repeats what the file declares \(stiffness\)"):
        with_addon(prs3, again)
    # a part made from the file's closure (as prc3's Lagrange model is) is registered too
    made = []

    def chains_from(closure):
        made.append(closure)
        return cn.LegChains(lambda model: None)

    with pytest.raises(MechanismDeclarationError, match=r"repeats what the file declares \(chains\)"):
        with_addon(prs3, Addon(closure_parts=(chains_from,)))
    assert made == [prs3.closure()]


def test_the_hinges_are_parsed_once_when_declared(monkeypatch):
    """The declared hinges are typed records in SI at declaration; a solve merges a problem's
    hinge over them key by key and never parses the declaration again."""
    stiffness = cn.mechanism_type("prs3").part(cn.JointStiffness)
    rev = stiffness.records["revolute"]
    assert isinstance(rev, cm.HingeSpec)
    assert (rev.joints, rev.type) == ("alpha", "circular_notch_paros_weisbord")
    assert rev.dims == {"t": pytest.approx(2e-3), "r": pytest.approx(8e-3), "w": pytest.approx(10e-3)}
    # k stays as written until the joint it is on is known (N*m/rad on an angle, N/m on a length)
    assert rev.k == "98.37 N*m/rad" and stiffness.parsed_material.E == pytest.approx(72e9)
    # key by key: the problem's k over the declared geometry; a key given as null clears it
    over = cm.HingeSpec.parsed({"k": 50.0}).over(rev)
    assert (over.k, over.type, over.dims["t"]) == (50.0, "circular_notch_paros_weisbord", pytest.approx(2e-3))
    assert cm.HingeSpec.parsed({"type": None}).over(rev).type is None
    model = cn.build_model("prs3", PRS3)
    seen = []

    class Counted:  # the hinges' declaration, counting its parses
        def parse(self, value, path):
            seen.append(path)
            return HINGES.parse(value, path)

    HINGES = cm.HINGES
    monkeypatch.setattr(cm, "HINGES", Counted())
    hs = cm.hinge_set(model, {"revolute": {"k": "50 N*m/rad"}})
    assert seen == [("inputs", "hinges")]  # the problem's hinges only
    k = dict(zip(hs.names, hs.k))
    assert k["alpha1"] == k["alpha2"] == k["alpha3"] == pytest.approx(50.0)


def test_a_declared_hinge_is_checked_when_declared():
    with pytest.raises(cn.InputError, match=r"stiffness\.hinges\.h\.t"):
        cn.JointStiffness(hinges={"h": {"joints": "q", "type": "circular_notch", "t": "2 kg"}})


def test_the_closure_carries_no_mechanism_and_no_solver_cache():
    model = cn.build_model("prs3", PRS3)
    c = model.closure
    assert "mechanism" not in vars(c) and "solvers" not in vars(c)
    assert cs.solvers_of(c) is cs.solvers_of(c)  # one cache per closure, held by the solver layer
    assert not hasattr(c, "solvers")  # 0.3: the property is gone (changelog: use solvers_of)
    by_hand = cn.Model(c, dict(model.parameters), dict(model.limits), dict(model.derived))
    assert by_hand.mechanism is None and model.mechanism is cn.mechanism_type("prs3")


def test_a_closures_solvers_are_freed_with_it():
    from tests.reference import prs3_closures as P3

    def closure():
        return cn.LoopClosure(
            "prs3_freed",
            x=P3.X,
            q=P3.Q,
            parameters=("b", "L", "alpha0"),
            phi=P3.loop_closure(),
            task=P3.TASK,
            home=P3.home,
            bounds=P3.bounds,
        )

    c = closure()
    cs.solvers_of(c).memo(("test",), lambda: "built")
    before = len(cs._BUILT)
    del c
    gc.collect()
    assert len(cs._BUILT) == before - 1


def test_cuboid_formulations_are_objects():
    assert set(wc.FORMULATIONS) == {"auto", "closed_form", "poses"}
    assert all(isinstance(f, wc.CuboidFormulation) and f.name == n for n, f in wc.FORMULATIONS.items())
    model = cn.build_model("prs3", PRS3)
    assert wc.cuboid_formulation("poses") is wc.FORMULATIONS["poses"]
    own = wc.CuboidFormulation("mine", False)
    assert wc.cuboid_formulation(own) is own and not own.closed_form(model, True)
    assert wc.FORMULATIONS["closed_form"].closed_form(model, False)
    auto = wc.FORMULATIONS["auto"]
    assert auto.closed_form(model, True) and not auto.closed_form(model, False)
    with pytest.raises(cn.InputError, match="did you mean 'closed_form'"):
        wc.cuboid_formulation("closed")


def test_hinge_models_are_objects_and_the_inputs_choices():
    kind = cn.problem_kind("platform_compliance")
    model = cn.build_model("prs3", PRS3)
    option = next(o for o in kind.input_options(model) if o.name == "hinge_axes")
    assert option.choices == tuple(hm.HINGE_MODELS) == ("all", "kinematic")
    assert hm.default_hinge_model(model) is hm.HINGE_MODELS["all"]  # prs3 gives its legs as chains
    five_bar = cn.build_model("five_bar", {})
    assert hm.default_hinge_model(five_bar) is hm.HINGE_MODELS["kinematic"]
    hs = cm.hinge_set(model, None)
    where = ("inputs", "hinge_axes")
    assert hm.HINGE_MODELS["kinematic"].prepare(model, hs, where, True) == hm.Prepared(hm.KINEMATIC, None, True)
    six = hm.HINGE_MODELS["all"].prepare(model, hs, where, True)
    assert six.hinges is hm.HINGE_MODELS["all"] and six.six_axis is not None and six.note == ""
    # the default on a mechanism without chains is the kinematic model; "all" chosen there is bad input
    assert hm.default_hinge_model(five_bar).prepare(five_bar, hs, where, False).hinges is hm.KINEMATIC
    with pytest.raises(cn.InputError, match="needs the legs of five_bar as serial chains"):
        hm.HINGE_MODELS["all"].prepare(five_bar, hs, where, True)
    problem = (PROBLEMS / "prs3_table2_forces.yaml").read_text()
    assert "hinge_axes" not in problem
    with pytest.raises(cn.InputError, match="did you mean 'kinematic'"):
        cn.problem_from_dict(
            {
                "problem": "platform_compliance",
                "mechanism": {"type": "prs3", "parameters": PRS3},
                "inputs": {"hinge_axes": "kinematics", "k_actuator": "1e5 N/m"},
            }
        )
    assert np.isfinite(hs.k).all()

"""Plot types as an open registry (issue 22, item 6): the built-in plot types, a
mechanism's own (named by its add-on, drawn only for its results) and plugins of the
entry-point group ``cpm_nlp.plots``; ``--help`` lists every one; a bad plugin is
refused with its name; nothing registers a plot type as a side effect."""

from __future__ import annotations

import contextlib
import io
import json
import sys
import textwrap
from pathlib import Path

import pytest

import cpm_nlp as cn
from cpm_nlp.cli.main import main
from cpm_nlp.plot import figures
from cpm_nlp.plot.builtin import BUILTIN
from cpm_nlp.plot.plot_type import PlotDeclarationError, PlotType
from cpm_nlp.plot.registry import (
    REGISTRY,
    PlotPluginError,
    plot_type,
    plot_type_names,
    plot_types,
    register,
    unregister,
)
from cpm_nlp.plot.results import NotApplicable, ResultData

ROOT = Path(__file__).resolve().parents[2]

matplotlib = pytest.importorskip("matplotlib")

PLUGIN = """
from matplotlib.figure import Figure

from cpm_nlp.plot.plot_type import PlotType


def radar(data, options):
    fig = Figure()
    fig.add_subplot().plot(data.values["a"])
    return fig


RADAR = PlotType("radar", radar, "a demo plot from a plugin")
WSONLY = PlotType("wsonly", radar, "a plugin plot of workspace results only", kinds=("workspace",))
NOT_A_PLOT = 3
WRONG_NAME = PlotType("other", radar, "declares another name than its entry point")
TWO_LINES = PlotType("twolines", radar, "a description\\nof two lines")


def BOOM():
    raise RuntimeError("boom")
"""


@pytest.fixture
def site(tmp_path, monkeypatch):
    """A fake installed package ``plugplots`` (module and .dist-info with entry points) on
    sys.path; the registry reads the entry points again, and forgets them afterwards."""
    root = tmp_path / "site"
    root.mkdir()
    monkeypatch.syspath_prepend(str(root))

    def install(entries: dict[str, str]) -> None:
        (root / "plugplots.py").write_text(textwrap.dedent(PLUGIN))
        info = root / "plugplots-1.0.dist-info"
        info.mkdir(exist_ok=True)
        (info / "METADATA").write_text("Metadata-Version: 2.1\nName: plugplots\nVersion: 1.0\n")
        lines = ["[cpm_nlp.plots]"] + [f"{k} = {v}" for k, v in entries.items()]
        (info / "entry_points.txt").write_text("\n".join(lines) + "\n")
        REGISTRY.forget_plugins()

    yield install
    monkeypatch.undo()
    REGISTRY.forget_plugins()
    sys.modules.pop("plugplots", None)


def _result(tmp_path: Path, problem: str = "forward_kinematics", mechanism: str = "zzz") -> Path:
    path = tmp_path / "r.json"
    path.write_text(
        json.dumps(
            {"problem": problem, "status": "solved", "values": {"a": [1.0, 2.0, 4.0]}, "model": {"type": mechanism}}
        )
    )
    return path


def _help(*argv: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):  # argparse prints the help to sys.stdout
        code = main([*argv, "--help"], out=io.StringIO(), err=io.StringIO())
    assert code == 0
    return out.getvalue()


# -- plugins --------------------------------------------------------------------------------------


def test_a_plugin_plot_is_registered_through_its_entry_point(site, tmp_path, cli):
    site({"radar": "plugplots:RADAR"})
    assert "radar" in plot_type_names()
    plot = plot_type("radar")
    assert plot.origin == "plugin 'radar' (plugplots:RADAR, package plugplots)"
    fig, kind = figures.figure(figures.load(_result(tmp_path)), "radar")
    assert kind == "radar"
    assert list(fig.axes[0].lines[0].get_ydata()) == [1.0, 2.0, 4.0]  # drawn from the result's values
    png = tmp_path / "f.png"
    run = cli("plot", str(_result(tmp_path)), "-o", str(png), "--type", "radar")
    assert run.code == 0, run.err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "radar" in _help("plot") and "a demo plot from a plugin [plugin 'radar'" in " ".join(_help("plot").split())


def test_a_plugin_plot_of_some_kinds_refuses_other_results(site, tmp_path):
    site({"wsonly": "plugplots:WSONLY"})
    with pytest.raises(NotApplicable, match="'wsonly' draws results of workspace; this is a forward_kinematics result"):
        figures.figure(figures.load(_result(tmp_path)), "wsonly")
    fig, _ = figures.figure(figures.load(_result(tmp_path, "workspace")), "wsonly")
    assert fig.axes


@pytest.mark.parametrize(
    ("name", "target", "message"),
    [
        ("bad", "plugplots:NOT_A_PLOT", "must name a PlotType declaration, got int"),
        ("boom", "plugplots:BOOM", "failed to load: RuntimeError: boom"),
        ("gone", "plugplots_missing:RADAR", "failed to load: ModuleNotFoundError: No module named 'plugplots_missing'"),
        ("radar2", "plugplots:WRONG_NAME", "declares the name 'other'; the two must agree"),
        ("twolines", "plugplots:TWO_LINES", "its description must be one line of text"),
    ],
)
def test_a_bad_plugin_is_refused_with_its_name(site, tmp_path, cli, name, target, message):
    site({name: target})
    named = f"plot type {name!r} (plugin {name!r} ({target}, package plugplots))"
    with pytest.raises(PlotPluginError if "load" in message or "agree" in message else PlotDeclarationError) as exc:
        plot_type(name)
    assert named in str(exc.value) and message in str(exc.value)
    run = cli("plot", str(_result(tmp_path)), "-o", str(tmp_path / "f.png"), "--type", name)
    assert run.code == 2 and "Traceback" not in run.err
    assert named in run.err and message in run.err
    assert not (tmp_path / "f.png").exists()
    text = " ".join(_help("plot").split())  # the help is printed still, naming the plugin and what is wrong
    assert name in text and message.split()[0] in text


def test_a_plugin_cannot_take_a_built_in_name(site):
    site({"map": "plugplots:RADAR"})
    assert plot_type("map") is next(p for p in BUILTIN if p.name == "map")


# -- --help -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["plot", "solve", "sweep"])
def test_help_lists_every_registered_plot_type(command):
    text = _help(command)
    listed = text[text.index("plot types (--type):") :]
    names = plot_type_names()
    assert len(names) >= 16  # the 14 built-in and the papers' amplifier and twists
    for plot in plot_types():
        assert f"\n  {plot.name} " in listed, plot.name
        assert plot.description.split()[0] in listed


# -- a mechanism's own plots --------------------------------------------------------------------------


def test_a_mechanisms_plot_is_drawn_only_for_its_results():
    """twists is the RPR paper's (eq 45), amplifier the 3-PRC paper's (eq 1-2): each is
    named by its add-on and found for that mechanism's results only."""
    from cpm_nlp.mechanisms.prc3.plots import amplifier_plot
    from cpm_nlp.mechanisms.rpr.plots import twists_plot

    assert plot_type("twists", "rpr").function.resolve() is twists_plot
    assert plot_type("amplifier", "prc3").function.resolve() is amplifier_plot
    for name, other in (("twists", "pantograph"), ("twists", "prc3"), ("amplifier", "rpr"), ("twists", None)):
        assert plot_type(name, other) is None, (name, other)
    assert {"twists", "amplifier"} <= set(plot_type_names())  # known to --type, before anything is solved
    data = ResultData("r.json", "rpr_twists", {"T": [[0.0, 1.0]] * 6}, {}, model={"type": "pantograph"})
    with pytest.raises(NotApplicable, match="'twists' is a plot of the rpr mechanism.*this result is of pantograph"):
        figures.figure(data, "twists")


def test_loading_or_solving_a_problem_registers_no_plot_type():
    before = dict(REGISTRY._types)
    problem = cn.load_problem(ROOT / "problems" / "prc3_amplifier.yaml")
    cn.solve(problem)
    assert REGISTRY._types == before
    assert "amplifier" not in REGISTRY.shared()


def test_a_plot_type_registered_in_code_is_validated_and_removed(tmp_path):
    def flat(data, options):
        raise NotApplicable("never drawn")

    with pytest.raises(PlotDeclarationError, match="its name must be lower case"):
        register(PlotType("Bad Name", flat, "x"))
    with pytest.raises(PlotDeclarationError, match="must name a PlotType declaration, got dict"):
        register({"name": "x"})
    with pytest.raises(PlotDeclarationError, match="'map' is already registered \\(built-in\\)"):
        register(PlotType("map", flat, "a second map"))
    register(PlotType("flat", flat, "a plot registered in code", origin="a test"))
    try:
        assert "flat" in plot_type_names()
        with pytest.raises(NotApplicable, match="never drawn"):
            figures.figure(figures.load(_result(tmp_path)), "flat")
    finally:
        unregister("flat")
    assert "flat" not in plot_type_names()


def test_a_bad_plot_of_an_addon_is_an_error_naming_it(monkeypatch):
    from cpm_nlp.mechanisms import names
    from cpm_nlp.plot import registry

    def declare(*plots):
        monkeypatch.setitem(names.ADDON_PLOTS, "prc3", plots)

    declare(names.AddonPlot("workspace", "cpm_nlp.plot.workspace_plots:workspace_plot", "a second workspace"))
    with pytest.raises(PlotDeclarationError, match="the plot type 'workspace' is declared twice"):
        registry._Registry().mechanism_plots("prc3")
    declare(names.AddonPlot("amp", "no colon", "an amplifier"))
    with pytest.raises(PlotDeclarationError, match="plot 'amp' of the add-on of mechanism 'prc3'.*'module:attribute'"):
        registry._Registry().mechanism_plots("prc3")
    declare(names.AddonPlot("Amp", "m:f", "an amplifier"))
    with pytest.raises(PlotDeclarationError, match="its name must be lower case"):
        registry._Registry().mechanism_plots("prc3")
    declare("cpm_nlp.mechanisms.prc3.plots:amplifier_plot")
    with pytest.raises(PlotDeclarationError, match="must be an AddonPlot declaration, got str"):
        registry._Registry().mechanism_plots("prc3")

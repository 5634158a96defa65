"""The figure checks themselves: each passes a sound figure and fails a figure
built to break it in one way."""

from __future__ import annotations

import pytest

from tests.figure_checks import assert_figure_readable, assert_legend_matches_artists

matplotlib = pytest.importorskip("matplotlib")


def _figure():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3, 2.2), dpi=60, layout="constrained")
    return fig, fig.add_subplot()


def _sound():
    fig, ax = _figure()
    ax.plot([0, 1, 2], [0, 1, 0], "o-", color="C0", label="line with markers")
    ax.scatter([0.5, 1.5], [0.2, 0.4], color="C1", marker="s", label="points")
    ax.fill_between([0, 2], 0.6, 0.8, color="C2", alpha=0.4, label="band")
    ax.axhline(0.9, color="k", ls="--", label="limit")
    ax.errorbar([0.3, 1.2], [1.2, 1.3], yerr=0.05, fmt="D", color="C3", label="with error bars")
    ax.bar([1.8], [0.3], width=0.1, color="C4", label="bar")
    ax.legend()
    return fig, ax


def test_a_sound_figure_passes():
    assert_legend_matches_artists(_sound()[0])


def test_a_figure_legend_with_proxy_handles_passes_when_the_artists_match():
    from matplotlib.lines import Line2D

    fig, ax = _figure()
    ax.scatter([0, 1], [0, 1], color="C0", marker="^", label="samples")
    fig.legend(handles=[Line2D([], [], color="C0", marker="^", ls="none")], labels=["samples"])
    assert_legend_matches_artists(fig)


def test_a_colour_mapped_scatter_matches_a_legend_colour_it_draws():
    fig, ax = _figure()
    ax.scatter([0, 1, 2], [0, 1, 2], c=[0, 1, 2], cmap="viridis", label="samples")
    ax.legend()  # the legend shows one of the drawn colours
    assert_legend_matches_artists(fig)


def _broken(way):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    fig, ax = _figure()
    ax.set_xlim(0, 2)
    ax.set_ylim(0, 2)
    if way == "unlabelled":
        ax.plot([0, 1], [0, 1], color="C0")
        ax.legend(handles=[Line2D([], [], color="C0")], labels=["curve"])
    elif way == "colour":  # issue 24: a yellow legend marker for blue points
        ax.scatter([0.5, 1], [0.5, 1], color="tab:blue", label="samples")
        ax.legend(handles=[Line2D([], [], color="yellow", marker="o", ls="none")], labels=["samples"])
    elif way == "marker":
        ax.scatter([0.5, 1], [0.5, 1], color="C0", marker="o", label="samples")
        ax.legend(handles=[Line2D([], [], color="C0", marker="s", ls="none")], labels=["samples"])
    elif way == "transparent":
        ax.plot([0, 1], [0, 1], color="C0", alpha=0.0, label="curve")
        ax.legend(handles=[Line2D([], [], color="C0")], labels=["curve"])
    elif way == "hidden":
        (line,) = ax.plot([0, 1], [0, 1], color="C0", label="curve")
        ax.legend()
        line.set_visible(False)
    elif way == "outside":
        ax.plot([5, 6], [5, 6], color="C0", label="curve")
        ax.legend()
    elif way == "covered":  # an opaque box drawn over the curve
        ax.plot([0.5, 1.5], [1, 1], color="C0", label="curve")
        ax.add_patch(Rectangle((0.2, 0.5), 1.6, 1, color="C3", zorder=5))
        ax.legend()
    elif way == "on_top":  # issue 24: F1 = F2 = F3 drawn on top of each other
        ax.plot([0, 2], [1, 1], color="C0", lw=1.5, label="F1")
        ax.plot([0, 2], [1, 1], color="C0", lw=1.5, label="F2")
        ax.legend(loc="upper right")
    return fig


@pytest.mark.parametrize(
    "way, message",
    [
        ("unlabelled", "no drawn artist"),
        ("colour", "colour"),
        ("marker", "marker"),
        ("transparent", "colour"),  # a zero-alpha artist has no colour a reader sees
        ("hidden", "not visible"),
        ("outside", "not visible"),
        ("covered", "not visible"),
        ("on_top", "not visible"),
    ],
)
def test_a_figure_built_to_fail_fails(way, message):
    with pytest.raises(AssertionError, match=message):
        assert_legend_matches_artists(_broken(way))


def test_a_baseline_in_the_fixed_style_matches_itself_and_catches_a_lost_layer(tmp_path, monkeypatch):
    from tests import figure_checks

    monkeypatch.setattr(figure_checks, "BASELINES", tmp_path / "baselines")
    monkeypatch.setenv("CPM_NLP_UPDATE_BASELINES", "1")
    fig = figure_checks.assert_matches_baseline(lambda: _sound()[0], "sound", tmp_path, tol=1, reason="same run")
    assert fig.texts is not None and (tmp_path / "baselines" / "sound.png").exists()
    monkeypatch.delenv("CPM_NLP_UPDATE_BASELINES")
    figure_checks.assert_matches_baseline(lambda: _sound()[0], "sound", tmp_path, tol=1, reason="same run")

    def without_band():
        fig, ax = _sound()
        ax.collections[-2].set_visible(False)  # the band (the bar and error bars come after it)
        return fig

    with pytest.raises(AssertionError, match="did not match"):
        figure_checks.assert_matches_baseline(without_band, "sound", tmp_path, tol=1, reason="same run")
    with pytest.raises(AssertionError, match="say why"):
        figure_checks.assert_matches_baseline(lambda: _sound()[0], "sound", tmp_path, tol=1, reason=" ")


def test_readable_passes_a_sound_figure_and_fails_overlapping_or_clipped_labels():
    assert_figure_readable(_sound()[0])
    fig, ax = _figure()
    ax.set_title("a title long enough to run past both edges of a small figure, clipped")
    with pytest.raises(AssertionError, match="is clipped"):
        assert_figure_readable(fig)
    fig, ax = _figure()
    ax.set_xticks([0.0, 0.02], ["first long tick label", "second long tick label"])
    with pytest.raises(AssertionError, match="overlap"):
        assert_figure_readable(fig)


def _panels(cover: bool):
    """Three panels; the line of the first is covered by an opaque axes of its own when ``cover``
    (the visibility check renders only the axes that can draw where an artist does)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 2.2), dpi=60, layout="constrained")
    first, second, third = fig.subplots(1, 3)
    first.plot([0, 1], [0, 1], color="C0", label="covered line")
    second.plot([0, 1], [1, 0], color="C1", label="line beside")
    third.scatter([0.5], [0.5], color="C2", label="point far away")
    if cover:
        over = fig.add_axes((0.0, 0.0, 0.36, 1.0), in_layout=False)  # the left third, opaque
        over.set_xticks([])
        over.set_yticks([])
    fig.legend(loc="outside upper center", ncols=3)
    return fig


def test_the_visibility_check_sees_cover_from_another_axes_and_artists_in_other_panels():
    assert_legend_matches_artists(_panels(cover=False))
    with pytest.raises(AssertionError, match="'covered line'.*not visible"):
        assert_legend_matches_artists(_panels(cover=True))

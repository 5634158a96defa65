"""Checks of figures: a file is valid and drawn (not blank), texts are not clipped,
legend entries match what is drawn, and a figure matches its baseline image drawn in
a fixed style."""

from __future__ import annotations

import os
import shutil
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from pathlib import Path

import numpy as np

SVG = "{http://www.w3.org/2000/svg}"


def assert_png_drawn(path, min_ink=0.03):
    """A PNG with a real picture: enough non-white pixels, varied colours."""
    from matplotlib.image import imread

    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rgb = imread(path)[..., :3]
    ink = (rgb < 0.9).any(axis=-1).mean()
    q = (rgb * 15).round().astype(np.int64)  # 16 levels per channel: one integer per colour,
    colours = len(np.unique((q[..., 0] * 16 + q[..., 1]) * 16 + q[..., 2]))  # not unique rows (40x slower)
    assert ink > min_ink and rgb.std() > 0.05 and colours > 8, (ink, rgb.std(), colours)
    return rgb


def assert_svg_drawn(path, min_paths=50):
    """A well-formed SVG document with many drawn elements."""
    root = ET.parse(path).getroot()
    assert root.tag == f"{SVG}svg"
    n = sum(1 for _ in root.iter(f"{SVG}path")) + sum(1 for _ in root.iter(f"{SVG}use"))
    assert n >= min_paths, n


def _labels(fig):
    """The texts a reader must see whole: titles, axis labels, legends, tick labels
    of 2-D axes within their view limits."""
    out = [fig._suptitle] if fig._suptitle is not None else []
    for legend in fig.legends:
        out += [*legend.get_texts(), legend.get_title()]
    for ax in fig.axes:
        out += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        if hasattr(ax, "zaxis"):
            out.append(ax.zaxis.label)
        else:
            for axis in (ax.xaxis, ax.yaxis):
                lo, hi = sorted(axis.get_view_interval())
                out += [t.label1 for t in axis.get_major_ticks() if lo <= t.get_loc() <= hi]
        if ax.get_legend() is not None:
            out += [*ax.get_legend().get_texts(), ax.get_legend().get_title()]
    return out


def _axes_texts(artist):
    """The texts drawn in an axes, at any depth (point labels, annotations, contour labels,
    titles), not those of its axis ticks and labels nor of its legend."""
    from matplotlib.axis import Axis
    from matplotlib.legend import Legend
    from matplotlib.text import Text

    for child in artist.get_children():
        if isinstance(child, (Axis, Legend)):
            continue
        if isinstance(child, Text):
            yield child
        else:
            yield from _axes_texts(child)


def assert_labels_apart(fig, slack=1.0):
    """No two texts drawn in one axes of a Matplotlib figure overlap (point labels of a
    mechanism, annotations, contour labels, titles), measured on the rendered figure; boxes
    may touch within ``slack`` pixels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    for ax in fig.axes:
        shown = [t for t in _axes_texts(ax) if t.get_visible() and t.get_text().strip()]
        boxes = [t.get_window_extent(renderer).expanded(1.0, 1.0).padded(-slack) for t in shown]
        for a in range(len(shown)):
            for b in range(a + 1, len(shown)):
                assert not boxes[a].overlaps(boxes[b]), (
                    f"texts {shown[a].get_text()!r} and {shown[b].get_text()!r} overlap: {boxes[a]} and {boxes[b]}"
                )


#: two texts may share this many square pixels (anti-aliased edges of neighbouring glyphs)
OVERLAP_PIXELS = 4.0


def assert_figure_readable(fig):
    """Every title, label and legend text of a Matplotlib figure lies inside the
    figure (nothing clipped at its edges), no two of them overlap, and no legend
    holds a template placeholder."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    boxes = []
    for t in _labels(fig):
        if t is None or not t.get_visible() or not t.get_text().strip():
            continue
        box = t.get_window_extent(renderer)
        assert box.x0 >= -1 and box.y0 >= -1 and box.x1 <= width + 1 and box.y1 <= height + 1, (
            f"text {t.get_text()!r} is clipped: {box} outside the figure {width} x {height}"
        )
        boxes.append((t, box))
    for k, (t, a) in enumerate(boxes):
        for u, b in boxes[k + 1 :]:
            shared = max(0.0, min(a.x1, b.x1) - max(a.x0, b.x0)) * max(0.0, min(a.y1, b.y1) - max(a.y0, b.y0))
            assert shared <= OVERLAP_PIXELS, f"texts {t.get_text()!r} and {u.get_text()!r} overlap ({shared:.0f} px²)"
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    for legend in legends:
        for t in legend.get_texts():
            text = t.get_text()
            assert not any(c in text.replace("$", "") for c in "<>`"), f"legend holds a placeholder: {text!r}"


def _rgba(c):
    from matplotlib.colors import to_rgba_array

    if c is None or (isinstance(c, str) and c == "none"):
        return np.empty((0, 4))
    return to_rgba_array(c).reshape(-1, 4)


def _line_colours(line):
    from matplotlib.colors import to_rgba

    alpha, rows = line.get_alpha(), []
    if line.get_linestyle() not in ("None", "", " ") and line.get_linewidth() > 0:
        rows.append(to_rgba(line.get_color(), alpha))
    if line.get_marker() not in (None, "None", "", " "):
        face = line.get_markerfacecolor()
        if not (isinstance(face, str) and face == "none"):
            rows.append(to_rgba(face, alpha))
        if line.get_markeredgewidth() > 0:
            rows.append(to_rgba(line.get_markeredgecolor(), alpha))
    return [np.array(rows).reshape(-1, 4)]


def _collection_colours(coll):
    rows = [_rgba(coll.get_facecolor())]
    if coll.get_array() is not None:
        rows.append(_rgba(coll.to_rgba(coll.get_array())))  # colour-mapped faces
    if np.any(np.asarray(coll.get_linewidth()) > 0):
        rows.append(_rgba(coll.get_edgecolor()))
    return rows


def _patch_colours(patch):
    rows = [_rgba(patch.get_facecolor())] if patch.get_fill() else []
    if patch.get_linewidth() > 0:
        rows.append(_rgba(patch.get_edgecolor()))
    return rows


def _rgba_set(artist):
    """The colours a reader sees of one artist (or legend handle), as RGBA rows:
    a line's colour when its line is drawn, a marker's face and edge, a patch's or
    collection's faces and edges. Fully transparent colours are dropped."""
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    if isinstance(artist, Line2D):
        rows = _line_colours(artist)
    elif isinstance(artist, Collection):
        rows = _collection_colours(artist)
    elif isinstance(artist, Patch):
        rows = _patch_colours(artist)
    else:  # an artist this check does not know: its single colour, when it has one
        get = getattr(type(artist), "get_color", None)
        rows = [_rgba(get(artist))] if get is not None else []
    out = np.concatenate(rows) if rows else np.empty((0, 4))
    return out[out[:, 3] > 0]


def _marker_path(artist):
    """The marker shape of a line or scatter (vertices in marker units, unit size), or None."""
    from matplotlib.collections import PathCollection
    from matplotlib.lines import Line2D
    from matplotlib.markers import MarkerStyle

    if isinstance(artist, Line2D):
        if artist.get_marker() in (None, "None", "", " "):
            return None
        m = MarkerStyle(artist.get_marker())
        verts = m.get_path().transformed(m.get_transform()).vertices
    elif isinstance(artist, PathCollection) and artist.get_paths():
        verts = artist.get_paths()[0].vertices
    else:
        return None
    span = np.ptp(verts, axis=0).max()
    return verts / span if span > 0 else verts


def _same_marker(handle, artist):
    a, b = _marker_path(handle), _marker_path(artist)
    if a is None:  # the legend shows no marker: nothing to match
        return True
    if b is None:
        return False
    return a.shape == b.shape and np.allclose(a, b, atol=1e-6)


def _pixels(fig, canvas=None):
    """The figure rendered by Agg, as int16 RGBA rows; ``canvas``: one to render on again (its
    renderer, and Matplotlib's text metrics cached for it, kept from one render to the next)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = canvas or FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).astype(np.int16)


class _Renders:
    """The renders of one figure for the visibility checks, on one canvas: the figure with the
    axes drawn that can touch a given artist's pixels, once per set of axes (the reference),
    and again with the artist hidden.

    Hiding an artist changes only the pixels it draws, inside its own axes' tight bounding box
    (or its own window extent, if it is drawn outside them).  An axes whose tight bounding box
    (everything it draws: patch, spines, ticks, labels, children) does not overlap that region
    draws no pixel there, so it is left out of both renders: the pixels that hiding changes are
    the same as on the whole figure, and an 8-panel figure renders 2 to 3 panels per entry.
    Figure-level artists (legends, titles) are always drawn."""

    def __init__(self, fig):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.fig = fig
        self.canvas = FigureCanvasAgg(fig)
        self.full = _pixels(fig, self.canvas)
        self.renderer = self.canvas.get_renderer()
        self.boxes = [(ax, ax.get_tightbbox(self.renderer, for_layout_only=False)) for ax in fig.axes]
        self.references: dict[frozenset, np.ndarray] = {}

    def _drawn_axes(self, artist) -> frozenset | None:
        """The axes that can draw where ``artist`` does; None: every axes (not known)."""
        from matplotlib.transforms import Bbox

        ax = getattr(artist, "axes", None)
        own = next((b for a, b in self.boxes if a is ax), None)
        try:
            extent = artist.get_window_extent(self.renderer)
        except Exception:  # an artist without a usable extent: the whole figure
            return None
        if own is None or extent is None or not np.all(np.isfinite(extent.extents)):
            return None
        region = Bbox.union([own, extent]) if extent.width > 0 or extent.height > 0 else own
        keep = frozenset(id(a) for a, b in self.boxes if b is not None and b.overlaps(region)) | {id(ax)}
        return None if len(keep) == len(self.boxes) else keep  # every axes: the whole figure's render

    def _render(self, keep: frozenset | None) -> np.ndarray:
        if keep is None:
            return _pixels(self.fig, self.canvas)
        hidden = [a for a, _ in self.boxes if id(a) not in keep and a.get_visible()]
        for a in hidden:
            a.set_visible(False)
        try:
            return _pixels(self.fig, self.canvas)
        finally:
            for a in hidden:
                a.set_visible(True)

    def draws_pixels(self, artist, min_pixels=3, min_step=8) -> bool:
        """Whether hiding the artist changes the rendered figure (at least `min_pixels`
        pixels by more than `min_step` of 255): an artist that is invisible, fully
        transparent, outside the view or covered by others changes nothing. The figure is
        rendered without anti-aliasing, so that a curve drawn exactly on top of an equal
        one changes no pixel (anti-aliased edges would darken where two equal curves overlap)."""
        if not artist.get_visible():
            return False
        keep = self._drawn_axes(artist)
        if keep is None:
            reference = self.full
        else:
            if keep not in self.references:
                self.references[keep] = self._render(keep)
            reference = self.references[keep]
        artist.set_visible(False)
        try:
            without = self._render(keep)
        finally:
            artist.set_visible(True)
        changed = (np.abs(without - reference) > min_step).any(axis=-1)
        return int(changed.sum()) >= min_pixels


class _Aliased:
    """Anti-aliasing off on every drawn artist for the duration of a check."""

    def __init__(self, artists):
        self.saved = [(a, a.get_antialiased()) for a in artists if hasattr(a, "set_antialiased")]

    def __enter__(self):
        for a, _ in self.saved:
            a.set_antialiased(False)

    def __exit__(self, *exc):
        for a, aa in self.saved:
            a.set_antialiased(aa)


def _legend_entries(fig):
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    for legend in legends:
        for handle, text in zip(legend.legend_handles, legend.get_texts(), strict=True):
            yield handle, text.get_text()


def _drawn_artists(fig):
    """Every artist of the figure that a legend could describe (not legends themselves, not texts)."""
    from matplotlib.legend import Legend
    from matplotlib.text import Text

    seen = set()
    for ax in fig.axes:
        for a in ax.get_children():
            if isinstance(a, (Legend, Text)) or id(a) in seen:
                continue
            seen.add(id(a))
            yield a


def assert_legend_matches_artists(fig, atol=0.02):
    """Every legend entry of a Matplotlib figure describes what is drawn: an artist with
    the entry's label exists, has the legend's colours (line, marker face/edge, patch
    face/edge, compared as RGBA within `atol`) and marker shape, and shows on the
    rendered figure (hiding it changes pixels: not invisible, not zero alpha, not outside
    the view, not covered by other artists)."""
    artists = list(_drawn_artists(fig))
    with _Aliased(artists):
        _pixels(fig)  # laid out once: every render below compares the same positions
        engine = fig.get_layout_engine()
        fig.set_layout_engine("none")  # (and skips the layout: half of each render)
        try:
            _check_legends(fig, artists, atol)
        finally:
            fig.set_layout_engine(engine)


def _candidates(fig, artists, label):
    """The drawn things a legend entry may name, each as the list of its artists: single
    artists with the label, and containers (bars, error bars) with it."""
    out = [[a] for a in artists if a.get_label() == label]
    for ax in fig.axes:
        for c in ax.containers:
            if c.get_label() == label:
                out.append([a for a in _flat(c) if a is not None])
    return out


def _flat(container):
    for a in container:
        if isinstance(a, (tuple, list)):
            yield from _flat(a)
        else:
            yield a


def _check_legends(fig, artists, atol):
    renders = _Renders(fig)
    for handle, label in _legend_entries(fig):
        if handle is None:
            continue
        named = _candidates(fig, artists, label)
        assert named, f"legend entry {label!r}: no drawn artist carries this label"
        want = _rgba_set(handle)
        problems = []
        for group in named:
            have = np.concatenate([_rgba_set(a) for a in group])
            missing = [c for c in want if not len(have) or np.abs(have - c).max(axis=1).min() > atol]
            if missing:
                problems.append(f"colour {np.round(missing[0], 3).tolist()} not among the artist's colours")
            elif not any(_same_marker(handle, a) for a in group):
                problems.append("marker differs from the legend's")
            elif not any(renders.draws_pixels(a) for a in group):
                problems.append("not visible (hidden, transparent, outside the view or covered)")
            else:
                break
        else:
            raise AssertionError(f"legend entry {label!r} does not match what is drawn: {'; '.join(problems)}")


# -- baseline images -------------------------------------------------------------------------------

#: the committed baseline images
BASELINES = Path(__file__).resolve().parent / "baseline_images"

#: the style a baseline image is drawn in, so that it holds on other platforms: the fonts
#: Matplotlib ships (DejaVu Sans, DejaVu mathtext: never a system font found by family), no
#: font hinting (FreeType versions hint glyphs differently), a fixed resolution
BASELINE_STYLE = {
    "font.family": "sans-serif",
    "font.sans-serif": ["DejaVu Sans"],
    "mathtext.fontset": "dejavusans",
    "text.hinting": "none",
    "figure.dpi": 100,
    "savefig.dpi": 100,
}


@contextmanager
def baseline_style():
    """Matplotlib's settings of :data:`BASELINE_STYLE` while a baseline figure is built and drawn."""
    import matplotlib

    with matplotlib.rc_context(BASELINE_STYLE):
        yield


def assert_matches_baseline(build, name, tmp_path, *, tol, reason, dpi=100):
    """The figure ``build()`` makes, drawn in :data:`BASELINE_STYLE`, against the
    committed ``baseline_images/<name>.png`` within ``tol`` (RMS difference of 0-255
    pixels, :func:`matplotlib.testing.compare.compare_images`); ``reason`` says why that
    tolerance (required: a tolerance without one is a guess). Regenerate with
    CPM_NLP_UPDATE_BASELINES=1 after a deliberate change, and look at the images.
    Returns the figure (its texts and legends checked by the caller within
    :func:`baseline_style`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.testing.compare import compare_images

    assert reason.strip(), "say why the tolerance is what it is"
    with baseline_style():
        fig = build()
        out = tmp_path / f"{name}.png"
        FigureCanvasAgg(fig)
        fig.savefig(out, dpi=dpi)
    baseline = BASELINES / f"{name}.png"
    if os.environ.get("CPM_NLP_UPDATE_BASELINES"):
        BASELINES.mkdir(exist_ok=True)
        shutil.copy(out, baseline)
    assert baseline.exists(), f"no baseline image {baseline}; run with CPM_NLP_UPDATE_BASELINES=1"
    diff = compare_images(str(baseline), str(out), tol=tol)
    assert diff is None, diff
    return fig

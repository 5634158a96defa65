"""Checks that a figure file is valid and drawn (not blank)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

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


def assert_figure_readable(fig):
    """Every title, label and legend text of a Matplotlib figure lies inside the
    figure (nothing clipped at its edges), and no legend holds a template placeholder."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    for t in _labels(fig):
        if t is None or not t.get_visible() or not t.get_text().strip():
            continue
        box = t.get_window_extent(renderer)
        assert box.x0 >= -1 and box.y0 >= -1 and box.x1 <= width + 1 and box.y1 <= height + 1, (
            f"text {t.get_text()!r} is clipped: {box} outside the figure {width} x {height}"
        )
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    for legend in legends:
        for t in legend.get_texts():
            text = t.get_text()
            assert not any(c in text.replace("$", "") for c in "<>`"), f"legend holds a placeholder: {text!r}"

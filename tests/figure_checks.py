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
    colours = len(np.unique((rgb * 15).round().reshape(-1, 3), axis=0))
    assert ink > min_ink and rgb.std() > 0.05 and colours > 8, (ink, rgb.std(), colours)
    return rgb


def assert_svg_drawn(path, min_paths=50):
    """A well-formed SVG document with many drawn elements."""
    root = ET.parse(path).getroot()
    assert root.tag == f"{SVG}svg"
    n = sum(1 for _ in root.iter(f"{SVG}path")) + sum(1 for _ in root.iter(f"{SVG}use"))
    assert n >= min_paths, n

"""``cpm-nlp import``: a mechanism file of bodies and joints from a URDF and its sidecar."""

from __future__ import annotations

import argparse

from ..core.errors import InputError
from ..io.atomic import check_output_path, write_atomic
from ..io.inputs import check_input_file
from .exits import EXIT_OK

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import TextIO


def cmd_import(args: argparse.Namespace, out: TextIO) -> int:
    from ..io.import_urdf import import_urdf

    inputs = [args.file] + ([args.sidecar] if args.sidecar else [])
    for f in inputs:
        check_input_file(f)
    check_output_path(args.output, inputs)
    imported = import_urdf(
        args.file,
        args.sidecar,
        actuated=_comma_list(args.actuated, "--actuated"),
        name=args.name,
        platform=args.platform,
        task=_comma_list(args.task, "--task"),
        planar=False if args.spatial else None,
    )
    if args.output is None:
        out.write(imported.text)
        return EXIT_OK
    write_atomic(args.output, imported.text, inputs=inputs)
    kind = "planar" if imported.planar else "spatial"
    out.write(
        f"{args.output}: {len(imported.bodies)} bodies, {len(imported.joints)} joints ({kind}) from {args.file}\n"
    )
    return EXIT_OK


def _comma_list(text: str | None, option: str) -> list[str] | None:
    if text is None:
        return None
    items = [t.strip() for t in text.split(",")]
    if not all(items):
        raise InputError(f"expected names separated by commas, got {text!r}", path=(option,))
    return items

"""``cpm-nlp export``: a mechanism's FK, IK and Jacobian as CasADi files or C code."""

from __future__ import annotations

import argparse
from pathlib import Path

from .exits import EXIT_OK

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import TextIO


def cmd_export(args: argparse.Namespace, out: TextIO) -> int:
    from ..io.export import check_format, check_out_dir, export_kinematics, parse_what
    from ..problems.file import load_problem

    what = parse_what(args.what)
    check_format(args.format)
    check_out_dir(args.out, inputs=[args.file])
    problem = load_problem(args.file, args.set or [])
    data = export_kinematics(
        problem.model, args.out, what, args.format, problem.solver, source=args.file, inputs=[args.file]
    )
    for f in [*data["files"], "manifest.json"]:
        out.write(f"{Path(args.out) / f}\n")
    return EXIT_OK

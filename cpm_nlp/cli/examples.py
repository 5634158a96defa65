"""``cpm-nlp examples``: the shipped problem files and solver presets, copied to edit."""

from __future__ import annotations

import argparse

from .exits import EXIT_OK

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import TextIO


def cmd_examples(args: argparse.Namespace, out: TextIO) -> int:
    from ..problems.shipped import copy_examples

    written = copy_examples(args.dir, force=args.force)
    n_problems = sum(1 for f in written if f.parent.name != "configs")
    out.write(
        f"{args.dir}: {n_problems} problem files in problems/, {len(written) - n_problems} solver presets in "
        f"configs/\n(edit them, then e.g. cd {args.dir} && cpm-nlp solve problems/prs3_forward_kinematics.yaml "
        "or cpm-nlp reproduce)\n"
    )
    return EXIT_OK

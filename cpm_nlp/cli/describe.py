"""``cpm-nlp describe``: the mechanisms and problem kinds, one of them, or a mechanism file."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ..core.errors import InputError
from ..io.inputs import check_input_file
from .exits import EXIT_OK
from .streams import solver_output

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO


def cmd_describe(args: argparse.Namespace, out: TextIO) -> int:
    if args.name and _names_a_file(args.name) and not args.mechanism and args.name != "-":
        check_input_file(args.name, allow_pipe=True)  # a sparse file, a device: refused before the imports
    if args.plot:
        _check_graph_plot(args)
    from ..mechanisms.registry import mechanism_type
    from ..problems.registry import kind_names, problem_kind

    if not args.name:
        return _list_all(out)
    if args.name in kind_names():
        return _describe_kind(args, out)
    if args.mechanism:
        problem_kind(args.name, path=("describe",))  # the unknown kind, with a "did you mean"
    if _names_a_file(args.name) and not args.mechanism:  # a mechanism file: loaded and checked
        from ..mechanisms.described import load_file_description

        with solver_output(args):
            mt, description = load_file_description(args.name, allow_pipe=True)
        _write_mechanism(mt, out)
        _write_file_summary(args, mt, description, out)
        return EXIT_OK
    _write_mechanism(mechanism_type(args.name, path=("describe",)), out)
    return EXIT_OK


def _list_all(out: TextIO) -> int:
    """``describe`` alone: every mechanism and every problem kind, one a line."""
    from ..mechanisms.registry import mechanism_names, mechanism_type
    from ..problems.registry import kind_names, problem_kind

    out.write("mechanisms:\n")
    for name in mechanism_names():
        mt = mechanism_type(name)
        origin = "" if mt.origin.kind == "built-in" else f"  ({mt.origin})"
        out.write(f"  {name:<12} {mt.title}{origin}\n")
    out.write("problem kinds:\n")
    for name in kind_names():
        out.write(f"  {name:<20} {problem_kind(name).description}\n")
    return EXIT_OK


def _write_mechanism(mt: Any, out: TextIO) -> None:
    """What every mechanism declares: its parameters, limits, capabilities, default joint
    stiffness and own problem kinds."""
    out.write(f"{mt.name}: {mt.title}\n{mt.paper}\n[{mt.origin}]\n\nparameters:\n")
    for o in mt.parameters:
        default = "" if o.required or o.default is None else f" (default {o.format_value(o.default)})"
        out.write(f"  {o.name:<8} {o.expectation()}{default}\n           {o.description}\n")
    out.write("limits (optional, [low, high]):\n")
    for o in mt.limits:
        out.write(f"  {o.name:<8} {o.description}\n")
    caps = mt.capabilities()
    out.write("capabilities: " + (", ".join(caps) if caps else "none beyond the required parts") + "\n")
    from ..analysis.compliance import JointStiffness

    stiffness = mt.part(JointStiffness)
    if stiffness is not None:  # the default hinges of the compliance kinds
        out.write(f"joint stiffness ({stiffness.source}):\n")
        for hname, spec in stiffness.hinges.items():
            text = ", ".join(f"{k}: {v}" for k, v in spec.items())
            out.write(f"  {hname:<10} {text}\n")
        for bname, spec in (stiffness.bodies or {}).items():  # flexible bodies (beams)
            text = ", ".join(f"{k}: {v}" for k, v in spec.items())
            out.write(f"  {bname:<10} flexible body: {text}\n")
    if mt.kinds:
        out.write("its own problem kinds: " + ", ".join(sorted(mt.kinds)) + "\n")


def _write_file_summary(args: argparse.Namespace, mt: Any, description: Any, out: TextIO) -> None:
    """A mechanism file: its derived values, legs, loops and mobility; with ``--plot``, its body graph."""
    from ..mechanisms.described.summary import summary_text
    from ..problems.describe import model_of

    with solver_output(args):
        model, source = model_of(mt)
        text = summary_text(description, model, source)
    out.write(text)
    if args.plot:
        from ..mechanisms.described.summary import body_graph
        from ..plot.draw import save
        from ..plot.mechanism_graph import graph_figure

        nodes, edges = body_graph(description)
        note = "" if edges else "no legs: the loops are written as closures"
        save(graph_figure(f"{mt.name}: bodies and joints", nodes, edges, note), args.plot, "--plot", [args.name])
        out.write(f"body graph: {args.plot}\n")


def _check_graph_plot(args: argparse.Namespace) -> None:
    """``describe FILE --plot FIGURE``: a mechanism file, and a .png, .svg or .pdf to write."""
    from ..plot.draw import check_figure_path, require_backend

    if not args.name or args.mechanism or not _names_a_file(args.name):
        raise InputError(
            f"expected a mechanism file to draw the body graph of (cpm-nlp describe FILE.yaml --plot graph.png), "
            f"got {args.name!r}" + (" with --mechanism" if args.mechanism else ""),
            path=("--plot",),
        )
    if Path(args.plot).suffix.lower() == ".html":
        raise InputError(f"expected a .png, .svg or .pdf figure, got {args.plot!r}", path=("--plot",))
    check_figure_path(args.plot, "--plot", [args.name])
    require_backend(args.plot)


def _names_a_file(name: str) -> bool:
    """Whether ``describe NAME`` names a mechanism file: ``.yaml``/``.yml``, ``-``
    (standard input), or a path with a folder (``/dev/fd/63`` of ``<(cat m.yaml)``)."""
    return name.endswith((".yaml", ".yml")) or name == "-" or ("/" in name or os.sep in name)


def _describe_kind(args: argparse.Namespace, out: TextIO) -> int:
    """The inputs (name, unit, default, meaning) and values of a kind: on the mechanism
    named by --mechanism, else on every mechanism it applies to."""
    from ..mechanisms.registry import mechanism_names
    from ..problems.describe import describe_kind, kind_text

    if args.mechanism:
        name = args.mechanism
        if _names_a_file(name):  # a mechanism file, wherever a mechanism name is taken
            from ..mechanisms.described import load_file
            from ..mechanisms.registry import resolve_described

            check_input_file(name, allow_pipe=True)
            with solver_output(args):  # described on its own model: the registry is not changed
                name = resolve_described(load_file(name, allow_pipe=True), ("--mechanism",))
        out.write(kind_text(describe_kind(args.name, name)))
        return EXIT_OK
    descriptions = [describe_kind(args.name, m) for m in mechanism_names()]
    applies = [d for d in descriptions if not d.unsupported]
    for k, desc in enumerate(applies or descriptions[:1]):
        out.write(("\n" if k else "") + kind_text(desc))
    skipped = [d.mechanism for d in descriptions if d.unsupported]
    if applies and skipped:
        out.write(f"\n(does not apply to: {', '.join(skipped)})\n")
    return EXIT_OK

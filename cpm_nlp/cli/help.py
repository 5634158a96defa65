"""The ``--help`` text of ``cpm-nlp`` and of each subcommand: a one-line summary (listed by
``cpm-nlp --help``), a paragraph saying what the subcommand does, and examples that run as
written from a checkout or from a directory made by ``cpm-nlp examples`` (they name only the
shipped problem and mechanism files, or files an earlier example wrote).

The commands that plot list the plot types under their help, from the plot registry
(`cpm_nlp.plot.registry`: the built-in types, the mechanisms' own, plugins), read only
when the help is printed.  This module imports nothing but the standard library: it is
loaded by every ``cpm-nlp`` run (issue 23, start-up).
"""

from __future__ import annotations

import argparse
import textwrap


class CommandHelp:
    """The help of one subcommand.

    Attributes
    ----------
    summary
        one line, listed under ``cpm-nlp --help``.
    description
        one paragraph, at the top of the ``--help`` of each subcommand.
    examples
        ``(command line, what it does)`` pairs, listed under the options.
    plot_types
        list the registered plot types under the examples (commands that plot).
    """

    # a plain class: dataclasses (and inspect, which it imports) would cost --help 5 ms

    def __init__(
        self, summary: str, description: str, examples: tuple[tuple[str, str], ...], *, plot_types: bool = False
    ) -> None:
        self.summary = summary
        self.description = description
        self.examples = examples
        self.plot_types = plot_types


FK = "problems/prs3_forward_kinematics.yaml"

#: the help of every subcommand, in the order ``cpm-nlp --help`` lists them
COMMANDS: dict[str, CommandHelp] = {
    "solve": CommandHelp(
        "solve a problem file and print the result",
        "Load the problem file FILE (its mechanism, inputs and solver; --set changes any value "
        "first), solve it and print the result: its status, the solver's iterations and time, the "
        "model's parameters and every output in SI units beside a readable unit.  Exit status 0 "
        "when solved, 1 when the solve did not succeed (the status says why), 2 for bad input.  "
        "-o writes the result as JSON, which 'cpm-nlp plot' draws; --plot draws it at once.",
        (
            (f"cpm-nlp solve {FK}", "the 3-PRS stage's platform pose for three actuator displacements"),
            (f"cpm-nlp solve {FK} --set inputs.s1='2 mm'", "the same with another displacement s1"),
            (f"cpm-nlp solve {FK} --set solver=newton", "the same by Newton's method (the fast path)"),
            (f"cpm-nlp solve {FK} --json", "the result as JSON on stdout"),
            (
                "cpm-nlp solve problems/pantograph_cuboid.yaml --plot cuboid.png",
                "the pantograph's largest cuboid, and its figure",
            ),
        ),
        plot_types=True,
    ),
    "sweep": CommandHelp(
        "solve a problem at every point of its sweep section (Dask)",
        "Solve the problem of FILE at every point of its 'sweep' section (each point as "
        "'cpm-nlp solve FILE --set KEY=VALUE' would), on a local Dask cluster or an existing one, "
        "streaming one row per point to a Parquet or CSV file; a sweep run again resumes where it "
        "stopped.  --plot draws the results (a map over two swept parameters, lines over one).",
        (
            (
                "cpm-nlp sweep problems/sweep_prs3_requirements.yaml -o prs3.csv --workers 2",
                "the 3-PRS joint requirements over its swept parameters, 2 processes",
            ),
            (
                "cpm-nlp sweep problems/sweep_pantograph_cuboid.yaml -o b_t.csv --plot b_t.png",
                "the pantograph's largest cuboid over b and its hinges' t, and its map",
            ),
        ),
        plot_types=True,
    ),
    "plot": CommandHelp(
        "plot a result (JSON of solve -o) or a sweep results file",
        "Draw the figure of RESULT, a result written by 'cpm-nlp solve -o' or a results file of "
        "'cpm-nlp sweep', to FIGURE (.png, .svg, .pdf; .html: an interactive 3-D figure where the "
        "plot type draws one).  The plot type is chosen from the result unless --type names one of "
        "those listed below.",
        (
            (
                "cpm-nlp solve problems/prs3_jacobian.yaml -o jacobian.json",
                "first, a result to plot: the 3-PRS Jacobian at a pose",
            ),
            ("cpm-nlp plot jacobian.json -o jacobian.png", "its figure, of the type chosen from the result"),
            ("cpm-nlp plot jacobian.json -o mechanism.svg --type mechanism", "the mechanism at that pose"),
        ),
        plot_types=True,
    ),
    "check": CommandHelp(
        "validate a problem file without solving it",
        "Load the problem file FILE (with the --set changes) and check it as 'cpm-nlp solve' would: "
        "keys, units, the mechanism and its parameters, the problem kind's inputs, the solver; "
        "nothing is solved.  Prints one line when the file is good; otherwise one message naming "
        "the file, the key and what was expected, with exit status 2.",
        (
            (f"cpm-nlp check {FK}", "the 3-PRS forward kinematics file is good"),
            (f"cpm-nlp check {FK} --set inputs.s1='2 mm'", "and with another displacement s1"),
        ),
    ),
    "reproduce": CommandHelp(
        "solve every problem file that reproduces a published figure",
        "Solve every problem file with a 'reproduce' section (those of problems/ by default, or "
        "the files and directories given) and compare each computed value with the figure its "
        "paper prints: whether it agrees, differs for a stated reason, or cannot be reproduced, "
        "and by how much.  Exit status 1 if a verdict is not the one the file expects.",
        (
            ("cpm-nlp reproduce", "every shipped problem file that reproduces a published figure"),
            (
                "cpm-nlp reproduce problems/prs3_table2_forces.yaml --json",
                "one file's comparison (the 3-PRS Table 2 forces), as JSON",
            ),
        ),
    ),
    "export": CommandHelp(
        "write a mechanism's FK, IK and Jacobian as CasADi files or C",
        "Export the kinematics of the mechanism of the problem file FILE -- its forward and "
        "inverse kinematics and Jacobian, with its parameters, joint limits and solver tolerance "
        "built in -- as serialized CasADi Functions (--format casadi) or as C source and header "
        "(--format c), with a manifest.json saying what each file holds, into the directory DIR.",
        (
            (f"cpm-nlp export {FK} --out prs3_casadi", "FK, IK and Jacobian of the 3-PRS as .casadi files"),
            (f"cpm-nlp export {FK} --what fk --out prs3_fk", "the FK alone"),
            ("cpm-nlp export problems/prs3_jacobian.yaml --format c --out prs3_c", "FK, IK, Jacobian as C code"),
        ),
    ),
    "examples": CommandHelp(
        "copy the shipped problem files and solver presets, to edit",
        "Copy the shipped problem files (and their mechanism files) into DIR/problems and the "
        "solver presets into DIR/configs, where cpm-nlp looks for them when run in DIR; the "
        "examples of cpm-nlp's help then run in DIR too.  Existing files are left alone unless --force.",
        (("cpm-nlp examples my_study", "the shipped files in my_study/problems and my_study/configs"),),
    ),
    "describe": CommandHelp(
        "list mechanisms and kinds; describe one, or a mechanism file",
        "Without NAME: list every mechanism and problem kind.  With a mechanism's name: its "
        "paper, parameters, limits, capabilities and hinges.  With a problem kind: its inputs with "
        "their defaults and bounds, and the values it returns, for a mechanism (--mechanism).  "
        "With a mechanism file (.yaml): load it, check it and describe it; --plot draws its graph "
        "of bodies and joints.",
        (
            ("cpm-nlp describe", "every mechanism and problem kind"),
            ("cpm-nlp describe prs3", "the 3-PRS stage: paper, parameters, limits, hinges"),
            ("cpm-nlp describe forward_kinematics --mechanism prs3", "the inputs and values of the FK for the 3-PRS"),
            (
                "cpm-nlp describe problems/mechanisms/five_bar.yaml --plot five_bar_graph.png",
                "check a mechanism file and draw its graph",
            ),
        ),
    ),
    "import": CommandHelp(
        "write a mechanism file from a URDF and its sidecar",
        "Read a URDF (its links, joints and zero configuration) and the loop closures and actuated "
        "joints of its Extended URDF sidecar (robot.yaml: closed_loop, type, name_mot, joint_name, "
        "joint_type); write a mechanism file of bodies and joints.  Nothing the URDF names "
        "(meshes, includes) is opened.  No URDF ships with cpm_nlp: ROBOT.urdf and robot.yaml below "
        "are your own files.",
        (
            (
                "cpm-nlp import ROBOT.urdf --sidecar robot.yaml -o robot_mechanism.yaml",
                "your URDF as a mechanism file, to describe, check and solve",
            ),
        ),
    ),
}

#: placeholders an example may name that do not ship: (command, file name) -> why
USER_FILES = {
    ("import", "ROBOT.urdf"): "no URDF ships; the help says it is the user's",
    ("import", "robot.yaml"): "the URDF's sidecar, the user's too",
}

#: the top-level help's examples
TOP_EXAMPLES = (
    (f"cpm-nlp solve {FK}", "solve a shipped problem file"),
    ("cpm-nlp reproduce", "compare every published figure with its computed value"),
    ("cpm-nlp describe", "list the mechanisms and problem kinds"),
    ("cpm-nlp examples my_study", "copy the shipped problem files, to edit"),
    ("cpm-nlp solve --help", "a command's description, options and examples (here solve's)"),
)

TOP_DESCRIPTION = (
    "Kinematics and design of compliant parallel mechanisms (CasADi + IPOPT).  Every problem is a "
    "YAML file -- a mechanism, its parameters, a problem kind and its inputs -- solved with "
    "'cpm-nlp solve FILE'.  Exit status: 0 solved, 1 solve failed, 2 bad input."
)


def parser_help(name: str) -> dict[str, object]:
    """The keyword arguments of ``add_parser`` for the subcommand ``name``."""
    h = COMMANDS[name]
    return {
        "help": h.summary,
        "description": h.description,
        "epilog": Epilog(examples_text(h.examples), plot_types=h.plot_types),
        "formatter_class": Formatter,
    }


def examples_text(examples: tuple[tuple[str, str], ...]) -> str:
    """The examples as printed: each command on a line of its own, what it does below it."""
    lines = ["examples:"]
    for command, what in examples:
        lines += [f"  {command}", f"      {what}"]
    return "\n".join(lines)


class Epilog(str):
    """The text under a subcommand's options: its examples and, for a command that plots,
    the registered plot types (listed only when the help is printed: a subcommand that runs
    never reads the plot registry)."""

    plot_types: bool

    def __new__(cls, text: str, *, plot_types: bool = False) -> Epilog:
        self = super().__new__(cls, text)
        self.plot_types = plot_types
        return self


class Formatter(argparse.HelpFormatter):
    """Paragraphs filled to the terminal's width; lines that start with a space (examples)
    kept as written; the plot types under the help of a command that plots."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        blocks = []
        for block in text.split("\n\n"):
            lines = block.splitlines()
            if any(line.startswith(" ") for line in lines):
                blocks.append("\n".join(indent + line for line in lines))
            else:
                text = " ".join(block.split())
                blocks.append(textwrap.fill(text, width, initial_indent=indent, subsequent_indent=indent))
        return "\n\n".join(blocks)

    def _format_text(self, text: str) -> str:
        formatted = super()._format_text(text)
        if isinstance(text, Epilog) and text.plot_types:
            formatted += plot_types_text(self._width) + "\n\n"
        return formatted


def plot_types_text(width: int) -> str:
    """The registered plot types, one a line with its summary (and who declared it when it is
    not built in); nothing of a plot is imported (the add-ons' plots are declared by name)."""
    from ..core.errors import CpmError
    from ..plot.registry import plot_type_names, plot_types

    try:
        types = plot_types()
    except CpmError as exc:  # a broken plugin: the names, and what is wrong (the help is still printed)
        return f"plot types (--type): {', '.join(plot_type_names())}\n(error: {exc})"
    column = max(len(t.name) for t in types) + 4
    lines = ["plot types (--type):"]
    for t in types:
        text = t.description + ("" if t.origin == "built-in" else f" [{t.origin}]")
        lines += textwrap.wrap(
            text,
            max(width, column + 30),
            initial_indent=f"  {t.name:<{column - 2}}",
            subsequent_indent=" " * column,
        )
    return "\n".join(lines)

"""MkDocs hooks of the cpm_nlp site (docs/mkdocs.yml).

* ``reference/kinds.md`` is generated from the problem kinds' declared options by
  `cpm_nlp.problems.describe.reference_markdown` at every build, so the page
  cannot drift from the code (``cpm-nlp describe KIND --mechanism NAME`` prints the same);
* ``reference/solver-options.md`` is generated from the solver options' allow-list by
  `cpm_nlp.core.solver_options.reference_markdown`;
* ``reference/mechanisms.md`` and one page per registered mechanism,
  ``reference/mechanisms/NAME.md``, are generated from the mechanisms themselves (title,
  paper, parameters, limits, orientation, the problem kinds that apply, the shipped problem
  files, the sketch drawn by docs/figures.py), and added to the navigation;
* ``changelog.md`` is docs/changelog.md, which stays where it is.
"""

from __future__ import annotations

import sys
from pathlib import Path

import yaml

from cpm_nlp.core.solver_options import reference_markdown as solver_options_markdown
from cpm_nlp.problems.describe import reference_markdown

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:
    sys.path.insert(0, str(_HERE))

import figures  # noqa: E402 - docs/figures.py, beside this file

MECHANISMS_INDEX = "reference/mechanisms.md"
ROTATION_PAGE = "reference/rotation.md"


def _cell(text: object) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def mechanism_page_path(name: str) -> str:
    return f"reference/mechanisms/{name}.md"


def _rotation_text(mt) -> str:
    """The platform's orientation as its mechanism file writes it: R as a product of
    elementary rotations about the base axes, or fixed."""
    path = Path(mt.origin.path) if mt.origin.kind == "file" and mt.origin.path else None
    if path is None:
        return "declared in code"
    platform = (yaml.safe_load(path.read_text(encoding="utf-8")) or {}).get("platform") or {}
    if "rotation" not in platform:
        return "not a platform rotation (the mechanism's bodies and joints give the orientation of each link)"
    rotation = platform["rotation"]
    if not rotation:
        return "fixed: R = I (the platform translates only)"
    return "R = " + " ".join(f"R{axis}({angle})" for axis, angle in rotation)


def _kinds(mt) -> tuple[list[str], str]:
    """The problem kinds that apply to the mechanism (on the model of its first shipped problem file)."""
    from cpm_nlp.core.errors import InputError
    from cpm_nlp.problems.describe import reference_model
    from cpm_nlp.problems.registry import kind_names, problem_kind

    try:
        model, source = reference_model(mt.name)
    except InputError as exc:
        return [], exc.message
    return [k for k in kind_names() if not problem_kind(k).supports(model)], source


def mechanism_page(name: str, problem_files: dict[str, list[str]] | None = None) -> str:
    """The reference page of one registered mechanism, from its declaration."""
    from cpm_nlp.mechanisms.registry import mechanism_type

    mt = mechanism_type(name)
    by_mechanism = problem_files if problem_files is not None else figures.problem_files_by_mechanism()
    files = by_mechanism.get(name, [])
    out = [f"# `{name}`: {mt.title}", ""]
    sketch = figures.ASSETS / "mechanisms" / f"{name}.png"
    drawn_from = figures.sketch_problem(name, by_mechanism) if sketch.is_file() else ""
    out += [
        f"![{name} drawn by cpm-nlp](../../assets/mechanisms/{name}.png)",
        "",
        f"*Drawn by `cpm-nlp solve problems/{drawn_from} --plot {name}.png --type mechanism`: "
        "the pose of that file, the home pose dashed.*"
        if sketch.is_file()
        else "",
        "",
        "**Paper**: " + (_cell(mt.paper) if mt.paper else "none declared (a textbook mechanism)") + ".",
        "",
    ]
    if mt.origin.kind == "file":
        out += [
            f"**Mechanism file**: `problems/mechanisms/{Path(mt.origin.path).name}` "
            "(`cpm-nlp examples DIR` copies it; `cpm-nlp describe` reads it).",
            "",
        ]
    from cpm_nlp.mechanisms.registry import ALIASES

    old = sorted(alias for alias, target in ALIASES.items() if target == name)
    if old:
        out += [f"**Also named** (an older name, still accepted as `type:`): {', '.join(f'`{o}`' for o in old)}.", ""]
    out += [f"**Orientation** ([rotation convention](../rotation.md)): {_rotation_text(mt)}.", ""]
    out += ["## Parameters", "", "| name | meaning | unit | default | range |", "| --- | --- | --- | --- | --- |"]
    for o in mt.parameters:
        from cpm_nlp.core.units import DIMENSIONS

        unit = DIMENSIONS[o.kind].display if o.kind in DIMENSIONS else ""
        default = "required" if o.required or o.default is None else o.format_value(o.default)
        span = o.expectation().split(" in ", 1)[1] if " in " in o.expectation() else ""
        out.append(f"| `{o.name}` | {_cell(o.description)} | {unit} | {_cell(default)} | {_cell(span)} |")
    out += ["", "## Limits", "", "Optional, each `[low, high]`, under `mechanism.limits`.", ""]
    out += ["| name | meaning |", "| --- | --- |"]
    out += [f"| `{o.name}` | {_cell(o.description)} |" for o in mt.limits]
    kinds, source = _kinds(mt)
    out += ["", "## Problem kinds", ""]
    if kinds:
        own = set(mt.kinds)
        links = [f"[`{k}`](../kinds.md#{k})" + (" (its own)" if k in own else "") for k in kinds]
        out += [
            f"The kinds that apply (on the model of {source}); "
            "`cpm-nlp describe KIND --mechanism " + name + "` lists each one's inputs: " + ", ".join(links) + ".",
            "",
        ]
    else:
        out += [f"No kind is described on it ({_cell(source)}).", ""]
    out += ["## Shipped problem files", ""]
    if files:
        out += ["`cpm-nlp examples DIR` copies them into `DIR/problems/`.", "", "| file | what it solves |"]
        out.append("| --- | --- |")
        for f in files:
            data = yaml.safe_load((figures.PROBLEMS / f).read_text(encoding="utf-8"))
            out.append(f"| `{f}` | {_cell(data.get('description', ''))} (`{data.get('problem')}`) |")
        out.append("")
    else:
        out += ["None.", ""]
    return "\n".join(out)


def mechanisms_index(names: list[str]) -> str:
    from cpm_nlp.mechanisms.registry import mechanism_type

    out = [
        "# Mechanisms",
        "",
        "Every mechanism that ships, generated from its declaration when the site is built: "
        "one page each, with its sketch, paper, parameters, limits, problem kinds and problem files. "
        "`cpm-nlp describe` lists the same (and the mechanisms of installed plugins), "
        "`cpm-nlp describe NAME` prints one. To describe your own, see "
        "[Describe your own mechanism in a file](../tutorials/file-mechanism.md) and "
        "[Add a mechanism](../howto/add-mechanism.md).",
        "",
        "| type | mechanism | paper |",
        "| --- | --- | --- |",
    ]
    for name in names:
        mt = mechanism_type(name)
        paper = _cell(mt.paper) if mt.paper else "(a textbook mechanism)"
        out.append(f"| [`{name}`](mechanisms/{name}.md) | {_cell(mt.title)} | {paper} |")
    return "\n".join(out) + "\n"


def _registered() -> list[str]:
    from cpm_nlp.mechanisms.registry import mechanism_names

    return list(mechanism_names())


def on_config(config):
    """The generated mechanism pages join the navigation, under Reference, after the index."""
    names = _registered()
    entry = {"Mechanisms": [MECHANISMS_INDEX] + [{name: mechanism_page_path(name)} for name in names]}
    for section in config["nav"]:
        if isinstance(section, dict) and "Reference" in section:
            items = section["Reference"]
            for k, item in enumerate(items):
                if isinstance(item, dict) and MECHANISMS_INDEX in item.values():
                    items[k] = entry
    return config


def on_files(files, config):
    from mkdocs.structure.files import File  # here: the tests import this module without the docs extra

    files.append(File.generated(config, "reference/kinds.md", content=reference_markdown()))
    files.append(File.generated(config, "reference/solver-options.md", content=solver_options_markdown()))
    names = _registered()
    by_mechanism = figures.problem_files_by_mechanism()
    files.append(File.generated(config, MECHANISMS_INDEX, content=mechanisms_index(names)))
    for name in names:
        files.append(File.generated(config, mechanism_page_path(name), content=mechanism_page(name, by_mechanism)))
    files.append(File.generated(config, "changelog.md", content=(_HERE / "changelog.md").read_text(encoding="utf-8")))
    return files

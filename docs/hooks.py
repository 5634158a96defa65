"""MkDocs hooks of the cpm_nlp site (docs/mkdocs.yml).

* ``reference/kinds.md`` is generated from the problem kinds' declared options by
  :func:`cpm_nlp.problems.describe.reference_markdown` at every build, so the page
  cannot drift from the code (``cpm-nlp describe KIND --mechanism NAME`` prints the same);
* ``reference/solver-options.md`` is generated from the solver options' allow-list by
  :func:`cpm_nlp.core.solver_options.reference_markdown`;
* ``changelog.md`` is docs/changelog.md, which stays where it is.
"""

from __future__ import annotations

from pathlib import Path

from mkdocs.structure.files import File

from cpm_nlp.core.solver_options import reference_markdown as solver_options_markdown
from cpm_nlp.problems.describe import reference_markdown

_HERE = Path(__file__).resolve().parent


def on_files(files, config):
    files.append(File.generated(config, "reference/kinds.md", content=reference_markdown()))
    files.append(File.generated(config, "reference/solver-options.md", content=solver_options_markdown()))
    files.append(File.generated(config, "changelog.md", content=(_HERE / "changelog.md").read_text(encoding="utf-8")))
    return files

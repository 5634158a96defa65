"""Installs (issue 13): the shipped problem files and presets are found where an
install puts them, `cpm-nlp examples DIR` copies them for the user to edit, and
`cpm-nlp --version`.  The wheel itself is built, installed into a fresh venv and
run from outside the checkout by .ci/smoke.sh (CI)."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest

from cpm_nlp.core.version import __version__
from cpm_nlp.problems.shipped import example_files, shipped_configs_dir, shipped_problems_dir
from tests.conftest import PROBLEMS, ROOT


def test_version_is_the_one_of_core_version_and_of_the_installed_metadata(cli):
    run = cli("--version")
    assert run.code == 0 and run.out == f"cpm-nlp {__version__}\n"
    assert importlib.metadata.version("cpm_nlp") == __version__


def test_shipped_dirs_of_a_checkout_are_the_top_level_ones():
    assert shipped_problems_dir() == PROBLEMS
    assert shipped_configs_dir() == ROOT / "configs"
    assert {f.stem for f in shipped_configs_dir().glob("*.yaml")} >= {"ipopt", "newton"}


def test_setup_maps_the_same_directories_into_the_package():
    text = (ROOT / "setup.py").read_text()
    assert '"cpm_nlp.data.problems": "problems"' in text and '"cpm_nlp.data.configs": "configs"' in text
    assert (ROOT / "cpm_nlp" / "data" / "__init__.py").is_file()


def _tree(d: Path) -> dict[str, bytes]:
    return {str(f.relative_to(d)): f.read_bytes() for f in sorted(d.rglob("*")) if f.is_file()}


def test_examples_copies_problems_and_presets_that_then_run_in_place(cli, tmp_path, monkeypatch):
    dest = tmp_path / "mine"
    run = cli("examples", str(dest))
    assert run.code == 0, run.err
    tree = _tree(dest)
    assert set(tree) == {str(rel) for _, rel in example_files()}
    assert tree["problems/prs3_forward_kinematics.yaml"] == (PROBLEMS / "prs3_forward_kinematics.yaml").read_bytes()
    assert "configs/newton.yaml" in tree
    # the user's copy, edited, is what runs: presets are found beside it
    monkeypatch.chdir(dest)
    f = Path("problems/prs3_forward_kinematics.yaml")
    f.write_text(f.read_text().replace("s1: 1.0 mm", "s1: 0.8 mm"))
    assert cli("check", str(f), "--set", "solver=newton").code == 0
    assert cli("solve", str(f), "--set", "solver=newton", "-q").code == 0


def test_examples_refuses_to_overwrite_without_force(cli, tmp_path):
    dest = tmp_path / "ex"
    assert cli("examples", str(dest)).code == 0
    edited = dest / "problems" / "rpr_twists.yaml"
    edited.write_text("# mine\n")
    before = _tree(dest)
    run = cli("examples", str(dest))
    assert run.code == 2 and run.out == ""
    assert "already exist" in run.err and "--force" in run.err and str(dest) in run.err
    assert run.err.count("\n") == 1 and "Traceback" not in run.err
    assert _tree(dest) == before  # nothing written
    assert cli("examples", str(dest), "--force").code == 0
    assert edited.read_bytes() == (PROBLEMS / "rpr_twists.yaml").read_bytes()


def test_examples_only_into_a_directory(cli, tmp_path):
    f = tmp_path / "afile"
    f.write_text("x")
    run = cli("examples", str(f))
    assert run.code == 2 and "not a directory" in run.err and str(f) in run.err
    assert f.read_text() == "x"


def test_examples_never_replaces_what_is_not_a_regular_file(cli, tmp_path):
    dest = tmp_path / "ex"
    (dest / "problems").mkdir(parents=True)
    target = tmp_path / "elsewhere.txt"
    target.write_text("keep")
    (dest / "problems" / "rpr_twists.yaml").symlink_to(target)
    run = cli("examples", str(dest), "--force")
    assert run.code == 2 and "not a regular file" in run.err
    assert target.read_text() == "keep" and (dest / "problems" / "rpr_twists.yaml").is_symlink()


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc")
def test_examples_into_an_unwritable_place_is_exit_2(cli):
    run = cli("examples", "/proc/cpm_nlp_examples")
    assert run.code == 2 and "cannot create" in run.err and "Traceback" not in run.err

"""A result records where its mechanism came from (issue 22, item 2): a built-in by name,
a mechanism file by its path and the SHA-256 of its bytes, an inline description as
written; a plot rebuilds that very mechanism, or refuses with one clear message."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from cpm_nlp.core.origin import Origin, data_sha256
from cpm_nlp.mechanisms.registry import REGISTRY, unregister

SHIPPED = Path(__file__).resolve().parents[2] / "problems" / "mechanisms" / "five_bar.yaml"
NAME = "my_five_bar_origin"  # a user's own mechanism (a copy of the shipped five-bar under a name of its own)


def _user_file(tmp_path: Path) -> Path:
    text = SHIPPED.read_text().replace("name: five_bar\n", f"name: {NAME}\n", 1)
    assert f"name: {NAME}\n" in text
    f = tmp_path / "stage.yaml"
    f.write_text(text)
    return f


def _solve(tmp_path: Path, cli, mechanism: str) -> tuple[Path, dict]:
    p = tmp_path / "ik.yaml"
    p.write_text(f"problem: inverse_kinematics\nmechanism: {mechanism}\ninputs: {{x: 20 mm, y: 180 mm}}\n")
    out = tmp_path / "r.json"
    run = cli("solve", str(p), "--json", "-o", str(out), "-q")
    assert run.code == 0, run.err
    unregister(NAME)  # as in a new process: the plot below must not lean on the solve's registration
    return out, json.loads(out.read_text())


def test_a_user_file_is_recorded_by_path_and_hash_and_plots_again(tmp_path, cli):
    f = _user_file(tmp_path)
    out, data = _solve(tmp_path, cli, "{file: stage.yaml}")
    assert data["model"]["type"] == NAME
    origin = data["origin"]
    assert origin["kind"] == "file" and origin["name"] == NAME
    assert origin["path"] == str(f.resolve())
    assert origin["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest()  # of the bytes, independently
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m.png"))
    assert run.code == 0, run.err
    assert (tmp_path / "m.png").stat().st_size > 0
    assert REGISTRY.lookup(NAME) is None  # reading the file for the plot registered nothing


def test_an_edited_file_is_refused(tmp_path, cli):
    f = _user_file(tmp_path)
    out, _data = _solve(tmp_path, cli, "{file: stage.yaml}")
    f.write_text(f.read_text().replace("title:", "title: edited", 1))
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m.png"))
    assert run.code == 2, run.out
    assert str(f.resolve()) in run.err and "has changed since this result was solved" in run.err
    assert "Traceback" not in run.err and not (tmp_path / "m.png").exists()
    assert REGISTRY.lookup(NAME) is None


def test_a_moved_file_is_refused(tmp_path, cli):
    f = _user_file(tmp_path)
    out, _data = _solve(tmp_path, cli, "{file: stage.yaml}")
    f.rename(tmp_path / "elsewhere.yaml")
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m.png"))
    assert run.code == 2, run.out
    assert str(f.resolve()) in run.err and "missing (moved or deleted)" in run.err
    assert not (tmp_path / "m.png").exists()


def test_a_result_names_only_a_yaml_mechanism_file(tmp_path, cli):
    """A result file is data: the plot reads the mechanism file it records only if it is one
    (.yaml, .yml), as a problem file's ``mechanism: {file:}``; never, e.g., /etc/passwd."""
    _user_file(tmp_path)
    out, data = _solve(tmp_path, cli, "{file: stage.yaml}")
    data["origin"]["path"] = "/etc/passwd"
    out.write_text(json.dumps(data))
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m.png"))
    assert run.code == 2, run.out
    assert "origin.path" in run.err and "ending in .yaml or .yml" in run.err and "Traceback" not in run.err
    assert not (tmp_path / "m.png").exists()


def test_an_inline_description_is_recorded_and_plots_again(tmp_path, cli):
    import yaml

    desc = yaml.safe_load(_user_file(tmp_path).read_text())
    out, data = _solve(tmp_path, cli, json.dumps({"description": desc}))
    origin = data["origin"]
    assert origin["kind"] == "inline" and origin["description"]["name"] == NAME
    assert origin["sha256"] == data_sha256(origin["description"])
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m.png"))
    assert run.code == 0, run.err
    assert REGISTRY.lookup(NAME) is None
    # a description edited in the result file no longer matches its hash: refused, not drawn
    data["origin"]["description"]["title"] = "edited"
    out.write_text(json.dumps(data))
    run = cli("plot", str(out), "--type", "mechanism", "-o", str(tmp_path / "m2.png"))
    assert run.code == 2 and "does not match its recorded SHA-256" in run.err


def test_a_built_in_is_recorded_by_name(cli):
    run = cli("solve", str(SHIPPED.parents[1] / "prs3_inverse_kinematics.yaml"), "--json", "-q")
    assert run.code == 0, run.err
    assert json.loads(run.out)["origin"] == {"kind": "built-in", "name": "prs3"}


@pytest.mark.parametrize(
    "origin, text",
    [
        (Origin("built-in", "prs3"), "built-in"),
        (Origin("file", "s", path="/a/s.yaml", sha256="ab"), "file /a/s.yaml"),
        (Origin("plugin", "delta", detail="pkg.delta:M, package pkg"), "plugin 'delta' (pkg.delta:M, package pkg)"),
        (Origin("inline", "s"), "described in code"),
    ],
)
def test_origin_reads_as_its_old_text_and_round_trips(origin, text):
    assert str(origin) == text
    assert Origin.from_dict(json.loads(json.dumps(origin.to_dict()))) == origin

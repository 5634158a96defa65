"""A shipped mechanism is found by its file name (issue 23, start-up): resolving a name reads
that one mechanism file, no other, and reads no plugin's entry points; a plugin's names are
read only for a name that is not a shipped one, and never take a shipped name."""

import json
import subprocess
import sys

import pytest

import cpm_nlp as cn
from cpm_nlp.mechanisms import described, registry
from tests.conftest import ROOT

SHIPPED = ROOT / "problems" / "mechanisms"


@pytest.mark.parametrize("path", sorted(SHIPPED.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_file_is_named_by_its_file_name(path):
    """The index of shipped names is the file names: each file's own name must repeat it."""
    assert described.read_yaml(path)["name"] == path.stem


def _opened(body: str) -> tuple[list[str], bool]:
    """The mechanism files a fresh process opens while running ``body``, and whether it read
    the entry points of plugins (importlib.metadata imported)."""
    code = (
        "import json, sys\n"
        "seen = []\n"
        "sys.addaudithook(lambda event, args: seen.append(str(args[0])) if event == 'open' else None)\n"
        f"{body}\n"
        f"print(json.dumps([p for p in seen if p.startswith({str(SHIPPED)!r})]))\n"
        "print('importlib.metadata' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    files, metadata = out.stdout.strip().splitlines()[-2:]
    return [p.rsplit("/", 1)[-1] for p in json.loads(files)], metadata == "True"


def test_a_shipped_name_reads_its_file_only():
    files, metadata = _opened("from cpm_nlp.mechanisms.registry import mechanism_type; mechanism_type('five_bar')")
    assert set(files) == {"five_bar.yaml"} and not metadata
    files, metadata = _opened("from cpm_nlp.mechanisms.registry import mechanism_type; mechanism_type('prs3')")
    assert set(files) == {"prs3.yaml"} and not metadata


def test_an_unknown_name_reads_the_plugins_and_no_mechanism_file():
    body = (
        "from cpm_nlp.mechanisms.registry import mechanism_type\n"
        "try:\n    mechanism_type('five_bars')\n"
        "except Exception as exc:\n    print(type(exc).__name__, exc)"
    )
    files, metadata = _opened(body)
    assert files == [] and metadata  # the names listed are the file names: none is read


def test_the_names_listed_are_the_file_names():
    names = cn.mechanism_names()
    assert {p.stem for p in SHIPPED.glob("*.yaml")} <= set(names)


def test_a_file_whose_name_differs_from_its_file_name_is_refused(tmp_path, monkeypatch):
    text = (SHIPPED / "five_bar.yaml").read_text().replace("name: five_bar", "name: six_bar", 1)
    (tmp_path / "five_bar2.yaml").write_text(text)
    monkeypatch.setattr(described, "SHIPPED_DIR", tmp_path)
    fresh = registry._Registry()
    with pytest.raises(cn.InputError, match=r"declares the name 'six_bar', but its file name says 'five_bar2'"):
        fresh.get("five_bar2")


@pytest.mark.parametrize("name", ["../mechanisms/five_bar", "five_bar.yaml", "", "five bar"])
def test_only_a_name_is_looked_up_never_a_path(name):
    assert registry._shipped_spec(name) is None

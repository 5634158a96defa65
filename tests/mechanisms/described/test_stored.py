"""A mechanism file's generated closure kept across processes
(`cpm_nlp.mechanisms.described.stored`, issue 23 item 2, start-up).

* the shipped forward-kinematics problems give the same result JSON, byte for byte (the
  solve's timings aside), with an empty cache and with the entries the first run wrote, each
  in a fresh process, and the second process generates none of the closures it found kept;
* an entry that is corrupt, truncated, of another key or format, or holds a Function CasADi
  cannot read is ignored, and the file generated again and its entry rewritten;
* the key changes with the file's bytes, the format, the versions and the generator's modules;
* a graph file's closure (its assembly is Python) is not kept; a cache directory that cannot
  be written is no error.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zlib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from cpm_nlp.core.chains import LegChains
from cpm_nlp.io.yamlfile import parse_yaml
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described import stored

ROOT = Path(__file__).resolve().parents[3]
MECH = ROOT / "problems" / "mechanisms"
FK_FILES = sorted(p.name for p in (ROOT / "problems").glob("*.yaml") if "problem: forward_kinematics" in p.read_text())
#: the timings of a solve, the only values that differ between two runs
TIMINGS = {"seconds", "build_seconds"}

#: solves each problem file named on the command line with ``cpm-nlp solve FILE -o OUT/NAME.json``
#: in this one process, then prints the mechanisms whose closure it generated and those it kept
CHILD = """
import json, sys
from cpm_nlp.cli.main import main
from cpm_nlp.mechanisms.described import stored
made, kept = [], []
generate, save = stored.generate, stored.save
def counted_generate(d):
    made.append(d.name)
    return generate(d)
def counted_save(key, d, g):
    save(key, d, g)
    if stored.entry_path(key).is_file():
        kept.append(d.name)
stored.generate, stored.save = counted_generate, counted_save
out = sys.argv[1]
codes = {f: main(["solve", "problems/" + f, "-o", out + "/" + f[:-5] + ".json"]) for f in sys.argv[2:]}
print(json.dumps({"codes": codes, "made": sorted(set(made)), "kept": sorted(set(kept))}))
"""


def _run(out: Path, cache: Path) -> dict:
    out.mkdir()
    env = {**os.environ, "CPM_NLP_CACHE": str(cache), "PYTHONPATH": str(ROOT)}
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(out), *FK_FILES],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=True,
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _without_timings(value):
    if isinstance(value, dict):
        return {k: _without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [_without_timings(v) for v in value]
    return value


def test_cold_and_warm_cache_give_the_same_results_byte_for_byte(tmp_path):
    assert len(FK_FILES) >= 10 and "prs3_forward_kinematics.yaml" in FK_FILES
    cache = tmp_path / "cache"
    cold = _run(tmp_path / "cold", cache)
    warm = _run(tmp_path / "warm", cache)
    assert cold["codes"] == warm["codes"]
    assert cold["codes"]["prs3_forward_kinematics.yaml"] == 0
    # the first process kept the legs files' closures; the second generated none of them
    assert {"prs3", "rpr", "prc3", "rps3", "ups6"} <= set(cold["kept"])
    assert "jansen" not in cold["kept"]  # a graph file: its assembly is Python, not kept
    assert not set(warm["made"]) & set(cold["kept"]), warm["made"]
    assert not warm["kept"]
    assert len(list((cache / "described").glob("*.json"))) == len(cold["kept"])
    for name in FK_FILES:
        a = (tmp_path / "cold" / name.replace(".yaml", ".json")).read_text()
        b = (tmp_path / "warm" / name.replace(".yaml", ".json")).read_text()
        da, db = json.loads(a), json.loads(b)
        assert da.get("status") == db.get("status"), name
        # the written JSON less its timings, as written (floats round-trip exactly through JSON)
        assert json.dumps(_without_timings(da)) == json.dumps(_without_timings(db)), name
        assert len(a.splitlines()) == len(b.splitlines()), name


def _mechanism(data, file, base_dir, text):
    """The mechanism of a mechanism file's parsed text, its closure kept under the file's bytes."""
    return described._description_and_mechanism(data, file, base_dir, text)[0]


def _read(name: str) -> tuple:
    path = MECH / f"{name}.yaml"
    text = path.read_text()
    return parse_yaml(text, str(path)), str(path), text.encode()


def _entry(text: bytes) -> Path:
    return stored.entry_path(stored.entry_key(text))


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("CPM_NLP_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _fk(mech) -> np.ndarray:
    """The generated closure at a pose off home: Φ, the passive joints, the IK and the frame."""
    c = mech.closure()
    model = mech.model(c, {"b": 0.04791, "L": 0.109215, "alpha0": np.pi / 4}, {}, ())
    x = np.asarray(model.x_home) + 1e-3 * np.arange(1, c.nx + 1)
    q = np.asarray(model.q_home) + 1e-3
    p = model.p
    t = x[c.task_index]
    parts = [c.phi(x, q, p), c.passive(x, q, p), *c.ik(t, p), *c.frame(x, p), c.branch(x, q, p)]
    return np.concatenate([np.asarray(v, dtype=float).ravel() for v in parts])


def test_an_entry_is_written_read_back_and_holds_what_was_generated(cache):
    data, file, text = _read("prs3")
    first = _mechanism(data, file, None, text)
    path = _entry(text)
    assert path.is_file() and path.parent == cache / "described"
    g = stored.load(stored.entry_key(text))
    assert g is not None and g.gen is None
    d = described.read_description(MECH / "prs3.yaml")
    assert stored._same(stored.generate(d), g)
    second = _mechanism(data, file, None, text)  # from the entry
    assert np.array_equal(_fk(first), _fk(second))
    # the entry is CasADi's serialized expression graphs and JSON: no pickle, no code
    digest, _, payload = path.read_bytes().partition(b"\n")
    assert f"{zlib.crc32(payload):08x}".encode() == digest
    entry = json.loads(payload)
    assert set(entry["functions"]) <= set(stored.FUNCTIONS)
    assert all(ca.Function.deserialize(s).name() == stored.FUNCTIONS[k] for k, s in entry["functions"].items())
    # the legs as serial chains (the six-axis hinge model's part) from the entry, as generated
    chains_first = first.part(LegChains).of(first.model(first.closure(), _P, {}, ()))
    chains_second = second.part(LegChains).of(second.model(second.closure(), _P, {}, ()))
    assert chains_first.legs[0].joints[0].type == chains_second.legs[0].joints[0].type == "P"
    for la, lb in zip(chains_first.legs, chains_second.legs):
        for ja, jb in zip(la.joints, lb.joints):
            assert np.array_equal(ja.at, jb.at) and np.array_equal(ja.axes, jb.axes)
            assert _joint(ja) == _joint(jb)


def _joint(j) -> tuple:
    return (j.type, j.motions, j.coordinates, j.actuated, j.gain)


_P = {"b": 0.04791, "L": 0.109215, "alpha0": np.pi / 4}


def _rewrite(path: Path, payload: bytes, *, digest: bool = True) -> None:
    head = f"{zlib.crc32(payload):08x}".encode() if digest else b"0" * 8
    path.write_bytes(head + b"\n" + payload)


def _corruptions(path: Path) -> list:
    raw = path.read_bytes()
    _digest, _, payload = raw.partition(b"\n")
    entry = json.loads(payload)
    flipped = bytearray(raw)
    flipped[len(raw) // 2] ^= 0x01
    garbage_fn = dict(entry, functions=dict(entry["functions"], phi="not a serialized function"))
    swapped = dict(entry, functions=dict(entry["functions"], phi=entry["functions"]["frame"]))
    return [
        ("a flipped bit", lambda: path.write_bytes(bytes(flipped))),
        ("truncated", lambda: path.write_bytes(raw[: len(raw) // 3])),
        ("empty", lambda: path.write_bytes(b"")),
        ("a wrong digest", lambda: _rewrite(path, payload, digest=False)),
        ("not JSON", lambda: _rewrite(path, b"{not json")),
        ("another format", lambda: _rewrite(path, json.dumps(dict(entry, format=-1)).encode())),
        ("another key", lambda: _rewrite(path, json.dumps(dict(entry, key="0" * 64)).encode())),
        ("a Function CasADi cannot read", lambda: _rewrite(path, json.dumps(garbage_fn).encode())),
        ("another Function in its place", lambda: _rewrite(path, json.dumps(swapped).encode())),
        ("a field missing", lambda: _rewrite(path, json.dumps({k: v for k, v in entry.items() if k != "x"}).encode())),
        ("a directory", lambda: (path.unlink(), path.mkdir())),
    ]


def test_a_corrupt_entry_is_ignored_and_the_file_generated_again(cache):
    data, file, text = _read("prs3")
    reference = _fk(_mechanism(data, file, None, text))
    path = _entry(text)
    key = stored.entry_key(text)
    good = path.read_bytes()
    for what, corrupt in _corruptions(path):
        corrupt()
        assert stored.load(key) is None, what
        mech = _mechanism(data, file, None, text)  # never an error
        assert np.array_equal(_fk(mech), reference), what
        if path.is_dir():
            path.rmdir()
            mech = _mechanism(data, file, None, text)
        assert path.read_bytes() == good, what  # rewritten as the first process wrote it
        assert stored.load(key) is not None, what


def test_the_key_changes_with_the_file_the_format_and_the_versions(monkeypatch):
    _data, _file, text = _read("prs3")
    key = stored.entry_key(text)
    assert stored.entry_key(text) == key
    assert stored.entry_key(text + b"\n# a comment\n") != key
    assert stored.entry_key(text.replace(b"109.215", b"109.216")) != key
    monkeypatch.setattr(stored, "FORMAT", stored.FORMAT + 1)
    assert stored.entry_key(text) != key
    monkeypatch.undo()
    monkeypatch.setattr(stored.version, "__version__", "0.0.0-other")
    assert stored.entry_key(text) != key
    monkeypatch.undo()
    monkeypatch.setattr(stored.ca, "__version__", "0.0.0-other")
    assert stored.entry_key(text) != key
    monkeypatch.undo()
    monkeypatch.setattr(stored, "_generator_fingerprint", lambda: "an edited generator")
    assert stored.entry_key(text) != key


def test_the_generator_fingerprint_covers_its_modules():
    fingerprint = stored._generator_fingerprint()
    modules = ("described/generate.py", "described/expr.py", "described/stored.py", "core/model.py")
    for module in modules + ("analysis/compliance.py", "analysis/hinge_types.py"):
        assert module + ":" in fingerprint


def test_a_graph_file_is_not_kept(cache):
    data, file, text = _read("jansen")
    _mechanism(data, file, None, text)
    assert not _entry(text).exists()


def test_a_cache_that_cannot_be_written_is_no_error(tmp_path, monkeypatch):
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    monkeypatch.setenv("CPM_NLP_CACHE", str(blocker / "cache"))  # under a regular file
    data, file, text = _read("prs3")
    mech = _mechanism(data, file, None, text)
    assert mech.name == "prs3" and not _entry(text).exists()


def test_a_solve_with_the_closure_kept_loads_no_generator(tmp_path):
    """With the 3-PRS's closure kept, `cpm-nlp solve` of its FK file imports neither the
    expression language nor the generator, nor hashlib (OpenSSL), nor the validity module, nor
    numpy.polynomial (issue 23, start-up); the first solve, which generates, checks and keeps
    it, does."""
    watched = (
        "cpm_nlp.mechanisms.described.expr",
        "cpm_nlp.mechanisms.described.generate",
        "cpm_nlp.mechanisms.described.builder",
        "cpm_nlp.mechanisms.described.closure",
        "cpm_nlp.mechanisms.described.motions",
        "cpm_nlp.analysis.validity",
        "hashlib",
        "numpy.polynomial",  # the filleted rod's formula: its hinges are not checked again
    )
    body = (
        "import sys, io; from cpm_nlp.cli.main import main; "
        "assert main(['solve', 'problems/prs3_forward_kinematics.yaml'], out=io.StringIO()) == 0; "
        f"print('loaded:' + ','.join(m for m in {watched!r} if m in sys.modules))"
    )
    # the child runs without pytest-cov's subprocess coverage (coverage itself imports hashlib)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("COV_CORE_", "COVERAGE_"))}
    env.update(CPM_NLP_CACHE=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))

    def loaded() -> set[str]:
        run = subprocess.run([sys.executable, "-c", body], cwd=ROOT, env=env, capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        line = [ln for ln in run.stdout.splitlines() if ln.startswith("loaded:")][-1]
        return {m for m in line[len("loaded:") :].split(",") if m}

    first = loaded()
    assert {"cpm_nlp.mechanisms.described.generate", "cpm_nlp.mechanisms.described.expr", "numpy.polynomial"} <= first
    assert loaded() == set()


def test_a_file_read_back_is_not_checked_again(cache, monkeypatch):
    """An entry is written only after the file's checks passed (its declared hinges): read
    back with the same code (the key), they are not run again; generated, they are."""
    data, file, text = _read("prs3")
    _mechanism(data, file, None, text)  # generated, checked, kept
    calls = []
    monkeypatch.setattr(described, "check_declared", lambda *a: calls.append(a))
    _mechanism(data, file, None, text)  # read back
    assert calls == []
    _entry(text).unlink()
    _mechanism(data, file, None, text)  # generated again: checked again
    assert len(calls) == 1

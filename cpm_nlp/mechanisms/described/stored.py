"""A mechanism file's generated closure kept across processes (issue 23, start-up).

Generating a file's closure (its expressions parsed into CasADi SX, the legs' closures,
the closed-form IK, the common subexpressions merged) is most of what reading a mechanism
file costs: about 30 ms of the 3-PRS's, in every process.  What the generator makes is
CasADi Functions and a few names; `Generated` holds exactly what a `Mechanism` is made of,
and an entry of the cache directory (`cpm_nlp.core.cache.cache_dir`, ``CPM_NLP_CACHE``,
under ``described/``) keeps it:

* **what it holds**: the Functions as CasADi's own serialization of their expression
  graphs (``Function.serialize`` of SX Functions: instructions and constants, no code; an
  entry's Function of another class is refused), and the names,
  dimensions, limits and drawing layout as JSON; no pickle, nothing a reader executes;
* **its key**: the SHA-256 of the file's bytes, the entry's format, the versions of cpm_nlp
  and CasADi, and the size and modification time of every module of the generator and of
  the checks a file passes when it is read (`cpm_nlp.mechanisms.described`, `cpm_nlp.core`,
  `cpm_nlp.analysis`), so that an edited generator never reads an entry an older one wrote;
  an entry is written only after those checks passed, so a file read back from it is not
  checked again (its declared hinges, its reference configuration).  The Functions are symbolic in the parameters: the
  parameters a problem gives are applied to them when its model is built, as without the
  cache, so they are not part of the key;
* **when it is written**: after the file generated without error and its reference
  configuration was checked, once, atomically (`cpm_nlp.io.atomic.write_atomic`);
  only for a legs file (a graph file's and a drawn-rods legs file's assembly is Python,
  rebuilt every time) and only if the entry reads back equal to what was generated;
* **when it is read**: the entry's checksum (CRC-32 of its JSON, made for catching
  corruption, and 0.05 ms where a SHA-256 takes 1 ms) is checked before CasADi reads a byte
  of it; an entry that is missing, truncated, corrupt, of another format or another key is
  ignored (logged at debug level) and the file generated again -- never an error, never a
  stale Function.
"""

from __future__ import annotations

import json
import logging
import os
import zlib
from pathlib import Path
from typing import Any

import casadi as ca

from ...core import version
from ...core.digest import sha256
from ...core.model import Coordinate
from ...core.options import Option

log = logging.getLogger(__name__)

#: the layout of an entry; a new one makes every older entry unread (its key changes)
FORMAT = 1

#: the Functions of a generated closure: their key in ``fns`` (absent or None: not made) and their name
FUNCTIONS = {
    "phi": "phi",
    "branch": "branch",
    "frame": "frame",
    "passive": "passive",
    "home": "home",
    "extras": "described_values",
    "ik": "ik",
    "fk_closed": "fk_closed",
    "drawing": "drawing_points",
}
#: the names the Functions come with
METADATA = ("drawing_legs", "branch_names", "branch_descriptions", "row_names", "requirements")


class Generated:
    """What a `Mechanism` of a legs file is made of, from its generator or from the cache.

    Attributes
    ----------
    x_coords, q_coords, passive_coords
        the pose, actuator and reported passive coordinates;
    limits
        the joint-limit options;
    derived
        (name, dimension, size) of each derived value;
    symbol_dims
        the dimension (`expr.Dim`) of each parameter and derived value;
    fns
        the Functions (`FUNCTIONS`) and their names (`METADATA`), as `closure.closure_parts`
        gives them;
    chains
        `chains.chain_parts` (None: the legs are no serial chains);
    gen
        the generator (None when read from the cache; a graph's drawing needs it)."""

    __slots__ = ("x_coords", "q_coords", "passive_coords", "limits", "derived", "symbol_dims", "fns", "chains", "gen")

    def __init__(
        self,
        x_coords: list[Coordinate],
        q_coords: list[Coordinate],
        passive_coords: list[Coordinate],
        limits: tuple[Option, ...],
        derived: list[tuple[str, str, int]],
        symbol_dims: dict[str, tuple[float, float]],
        fns: dict[str, Any],
        chains: tuple | None,
        gen: Any = None,
    ) -> None:
        self.x_coords = x_coords
        self.q_coords = q_coords
        self.passive_coords = passive_coords
        self.limits = limits
        self.derived = derived
        self.symbol_dims = symbol_dims
        self.fns = fns
        self.chains = chains
        self.gen = gen


def generate(d: Any) -> Generated:
    """A description's closure, generated (`closure.closure_parts`)."""
    from .chains import chain_parts
    from .chains import supported as chains_supported
    from .closure import closure_parts

    gen, fns = closure_parts(d)
    names = [p.name for p in d.parameters]
    derived = [(n, dim, int(sx.numel())) for n, sx, dim in gen.derived]
    return Generated(
        x_coords=list(gen.x_coords),
        q_coords=list(gen.q_coords),
        passive_coords=[r.coord for r in gen.reported],
        limits=gen.limit_options(),
        derived=derived,
        symbol_dims={n: gen.env[n].dim for n in names + [n for n, _, _ in derived]},
        fns=fns,
        chains=chain_parts(gen) if chains_supported(gen) else None,
        gen=gen,
    )


def entry_key(text: bytes) -> str:
    """The key of a mechanism file's entry: its bytes, the format, the versions and the generator's modules."""
    h = sha256()
    h.update(f"cpm_nlp-described {FORMAT} {version.__version__} casadi {ca.__version__}\0".encode())
    h.update(_generator_fingerprint().encode())
    h.update(b"\0")
    h.update(text)
    return h.hexdigest()


def _generator_fingerprint() -> str:
    """The size and modification time (ns) of every module of the generator, of core and of
    the analysis modules that check a file's hinges (an entry stands for those checks too)."""
    package = Path(__file__).resolve().parents[2]
    parts = []
    for folder in (package / "mechanisms" / "described", package / "core", package / "analysis"):
        with os.scandir(folder) as it:
            for e in sorted(it, key=lambda e: e.name):
                if e.name.endswith(".py"):
                    st = e.stat()
                    parts.append(f"{folder.name}/{e.name}:{st.st_size}:{st.st_mtime_ns}")
    return ";".join(parts)


def entry_path(key: str) -> Path:
    """Where the entry of ``key`` lives in the cache directory."""
    from ...core.cache import cache_dir

    return cache_dir() / "described" / f"{key}.json"


# -- writing ---------------------------------------------------------------------------------------
def storable(d: Any, g: Generated) -> bool:
    """Whether a generated closure is all data: a legs file's, its Functions CasADi's and its
    assembly not Python (a drawn rod's legs file assembles by a Python solver: not kept)."""
    if d.is_graph or g.gen is None:
        return False
    if set(g.fns) - set(FUNCTIONS) - set(METADATA):  # a part an entry does not hold (an assembly)
        return False
    return all(g.fns.get(k) is None or isinstance(g.fns[k], ca.Function) for k in FUNCTIONS)


def _payload(key: str, g: Generated) -> dict[str, Any]:
    fns = {k: g.fns[k].serialize() for k in FUNCTIONS if g.fns.get(k) is not None}
    chains = None
    if g.chains is not None:
        geom, frame, refs, layout = g.chains
        chains = {"geometry": geom.serialize(), "frame": frame.serialize(), "reference": refs.serialize()}
        chains["layout"] = layout
    return {
        "format": FORMAT,
        "key": key,
        "x": [_coord(c) for c in g.x_coords],
        "q": [_coord(c) for c in g.q_coords],
        "passive": [_coord(c) for c in g.passive_coords],
        "limits": [[o.name, o.kind, o.description, None if o.default is None else list(o.default)] for o in g.limits],
        "derived": [list(t) for t in g.derived],
        "symbol_dims": {n: list(v) for n, v in g.symbol_dims.items()},
        "functions": fns,
        "metadata": {k: g.fns[k] for k in METADATA},
        "chains": chains,
    }


def _coord(c: Coordinate) -> list[str]:
    return [c.name, c.kind, c.description, c.family]


def save(key: str, d: Any, g: Generated) -> None:
    """Keep a generated closure (nothing written if it is not `storable`, if it would not read
    back equal, or if the cache directory cannot be written: the next process generates it)."""
    from ...core.errors import InputError
    from ...io.atomic import write_atomic

    if not storable(d, g):
        return
    if any(o.check is not None or o.shape != "range" for o in g.limits):
        return
    try:
        text = json.dumps(_payload(key, g), separators=(",", ":"))
        back = _read_payload(key, json.loads(text))
    except (TypeError, ValueError, RuntimeError) as exc:  # a value JSON or CasADi cannot keep: not kept
        log.debug("mechanism %s: closure not kept (%s)", d.name, exc)
        return
    if not _same(g, back):
        log.debug("mechanism %s: closure not kept (it reads back different)", d.name)
        return
    path = entry_path(key)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(str(path), _checksum(text.encode()) + "\n" + text)
    except (OSError, InputError) as exc:
        log.debug("mechanism %s: closure not kept in %s (%s)", d.name, path, exc)


def _checksum(payload: bytes) -> str:
    """The checksum of an entry's JSON: its CRC-32, 8 hex digits."""
    return f"{zlib.crc32(payload):08x}"


def _same(a: Generated, b: Generated) -> bool:
    """Whether an entry read back holds what was generated (the Functions by their serialization)."""
    if (a.x_coords, a.q_coords, a.passive_coords, a.limits) != (b.x_coords, b.q_coords, b.passive_coords, b.limits):
        return False
    if (a.derived, a.symbol_dims) != (b.derived, b.symbol_dims):
        return False
    if any(a.fns[k] != b.fns[k] for k in METADATA):
        return False
    for k in FUNCTIONS:
        fa, fb = a.fns.get(k), b.fns.get(k)
        if (fa is None) != (fb is None) or (fa is not None and fa.serialize() != fb.serialize()):
            return False
    if (a.chains is None) != (b.chains is None):
        return False
    if a.chains is not None:
        if any(x.serialize() != y.serialize() for x, y in zip(a.chains[:3], b.chains[:3])):
            return False
        if _tuples(a.chains[3]) != b.chains[3]:
            return False
    return True


# -- reading ---------------------------------------------------------------------------------------
def load(key: str) -> Generated | None:
    """The entry of ``key``, or None (missing, unreadable, corrupt or another key's: generate it)."""
    path = entry_path(key)
    try:
        raw = path.read_bytes()
    except OSError:
        return None
    digest, _, text = raw.partition(b"\n")
    if _checksum(text).encode() != digest:
        log.debug("cached closure %s is corrupt: ignored", path)
        return None
    try:
        return _read_payload(key, json.loads(text))
    except (TypeError, ValueError, KeyError, IndexError, AttributeError, RuntimeError) as exc:
        log.debug("cached closure %s is unreadable (%s): ignored", path, exc)
        return None


def _read_payload(key: str, data: dict[str, Any]) -> Generated:
    if data["format"] != FORMAT or data["key"] != key:
        raise ValueError("another format or key")
    fns: dict[str, Any] = {k: None for k in FUNCTIONS}
    for k, s in data["functions"].items():
        if k not in FUNCTIONS:
            raise ValueError(f"unknown function {k!r}")
        fns[k] = _function(s, FUNCTIONS[k])
    meta = data["metadata"]
    fns["drawing_legs"] = [(str(n), [tuple(j) for j in joints]) for n, joints in meta["drawing_legs"]]
    fns["branch_names"] = [str(s) for s in meta["branch_names"]]
    fns["branch_descriptions"] = [str(s) for s in meta["branch_descriptions"]]
    fns["row_names"] = [str(s) for s in meta["row_names"]]
    fns["requirements"] = [(str(what), tuple(path)) for what, path in meta["requirements"]]
    chains = None
    if data["chains"] is not None:
        c = data["chains"]
        chains = (
            _function(c["geometry"], "chain_geometry"),
            _function(c["frame"], "platform_frame_p"),
            _function(c["reference"], "chain_reference"),
            _tuples(c["layout"]),
        )
    return Generated(
        x_coords=[Coordinate(*c) for c in data["x"]],
        q_coords=[Coordinate(*c) for c in data["q"]],
        passive_coords=[Coordinate(*c) for c in data["passive"]],
        limits=tuple(
            Option(n, kind, desc, default=None if lim is None else tuple(float(v) for v in lim), shape="range")
            for n, kind, desc, lim in data["limits"]
        ),
        derived=[(str(n), str(dim), int(size)) for n, dim, size in data["derived"]],
        symbol_dims={n: (float(v[0]), float(v[1])) for n, v in data["symbol_dims"].items()},
        fns=fns,
        chains=chains,
    )


def _function(text: str, name: str) -> ca.Function:
    """A Function of an entry: an SX expression graph (nothing else is ever written: no
    external library, no compiled code, no MX) of the name it is kept under."""
    f = ca.Function.deserialize(text)
    if f.class_name() != "SXFunction" or f.name() != name:
        raise ValueError(f"expected the SX function {name!r}, found {f.class_name()} {f.name()!r}")
    return f


def _tuples(layout: list) -> list:
    """A chains layout with its rows as tuples (JSON keeps lists)."""
    return [(str(leg), [(str(t), list(k), tuple(n), a) for t, k, n, a in rows]) for leg, rows in layout]


__all__ = ["FORMAT", "Generated", "entry_key", "entry_path", "generate", "load", "save", "storable"]

"""Mechanisms described in files (or built in code from the same dataclasses).

`load_file` reads a mechanism file, `from_dict` a parsed mapping
(inline under ``mechanism:`` in a problem file) and `mechanism` a
[`Description`][cpm_nlp.mechanisms.described.spec.Description] built in code; each returns a
[`Mechanism`][cpm_nlp.core.mechanism.Mechanism] with its symbolic closure, ready to
register.  A description is generated once per content (SHA-256 of the file's
text, or of the description) and kept in memory; a file's generated closure is
also kept on disk for the next process (`stored`), and compiled kernels are cached
on disk by their source like the built-ins'.
"""

from __future__ import annotations

import logging
import math
import threading
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis.compliance import check_declared
from ...core.chains import LegChains
from ...core.digest import sha256_hex
from ...core.errors import InputError
from ...core.mechanism import Mechanism
from ...core.model import LoopClosure, Model
from ...core.origin import Origin
from ...io.inputs import display_name, input_dir, read_input_text
from ...io.yamlfile import load_yaml_text, parse_yaml, read_yaml
from . import stored
from .chains import chains_maker
from .drawing import geometry_of, graph_geometry
from .options import described_limits, parameter_options
from .read import description_from_dict
from .spec import Description

log = logging.getLogger(__name__)

__all__ = [
    "Description",
    "load_file",
    "load_file_description",
    "from_dict",
    "mechanism",
    "shipped_files",
    "read_yaml",
    "load_yaml_text",
]

#: the shipped mechanism files
#: the shipped mechanism files: the package data of an installed wheel (setup.py maps
#: problems/ to cpm_nlp/data/problems), else the checkout's problems/mechanisms
_INSTALLED_DIR = Path(__file__).resolve().parents[2] / "data" / "problems" / "mechanisms"
SHIPPED_DIR = (
    _INSTALLED_DIR if _INSTALLED_DIR.is_dir() else Path(__file__).resolve().parents[3] / "problems" / "mechanisms"
)

_LOCK = threading.Lock()
#: content hash -> Mechanism (code, not problem data: one per distinct description)
_CACHE: dict[str, Mechanism] = {}
#: id of a Mechanism read from a file (kept alive by _CACHE) -> SHA-256 of the file's text alone
_TEXT_HASH: dict[int, str] = {}
#: mechanisms made from a file's (with_same_text), kept alive so that their ids stay theirs
_KEEP: list[Mechanism] = []


def shipped_files() -> list[Path]:
    """The mechanism files shipped in ``problems/mechanisms/``."""
    return sorted(SHIPPED_DIR.glob("*.yaml")) if SHIPPED_DIR.is_dir() else []


def load_file(path: str | Path, *, allow_pipe: bool = False) -> Mechanism:
    """The mechanism a file describes (errors name the file and the key path).

    The file is read once, through `cpm_nlp.io.inputs.read_input_text`
    (its type and size checked before it is opened); ``allow_pipe``: a file
    named on the command line may be ``-`` or a pipe."""
    return load_file_description(path, allow_pipe=allow_pipe)[0]


def load_file_description(path: str | Path, *, allow_pipe: bool = False) -> tuple[Mechanism, Description]:
    """The mechanism a file describes and its description (the file read once)."""
    text = read_input_text(path, allow_pipe=allow_pipe)
    file = display_name(path)
    base_dir = input_dir(path)
    text_key = sha256_hex(text.encode() + b"\0" + str(base_dir / Path(str(path)).name).encode())
    data = parse_yaml(text, file)
    mech, d = _cached(text_key, lambda: _description_and_mechanism(data, file, base_dir, text.encode()))
    with _LOCK:
        _TEXT_HASH[id(mech)] = sha256_hex(text.encode())
    # made now, or read again (a description of its own; without error: it was read before)
    return mech, d if d is not None else description_from_dict(data, file=file)


def same_text(a: Mechanism, b: Mechanism) -> bool:
    """Whether two mechanisms were read from files of the same text (a shipped file and an
    unchanged copy of it elsewhere: ``cpm-nlp examples``' problems/mechanisms)."""
    with _LOCK:
        ha, hb = _TEXT_HASH.get(id(a)), _TEXT_HASH.get(id(b))
    return ha is not None and ha == hb


def with_same_text(mech: Mechanism, read: Mechanism) -> Mechanism:
    """``mech`` (a mechanism made from ``read``, e.g. with an add-on) counted as read from the
    same text as ``read``, for `same_text`."""
    with _LOCK:
        if id(read) in _TEXT_HASH:
            _TEXT_HASH[id(mech)] = _TEXT_HASH[id(read)]
            _KEEP.append(mech)
    return mech


def _cached(key: str, make: Any) -> tuple[Mechanism, Description | None]:
    """The mechanism of ``key`` made once per process: ``make() -> (mechanism, description)``;
    the description only where it was made now (None: the mechanism was made before)."""
    with _LOCK:
        mech = _CACHE.get(key)
    if mech is not None:
        return mech, None
    mech, d = make()
    with _LOCK:
        _CACHE[key] = mech
    return mech, d


def inline(data: Any, *, base_dir: Path | None = None) -> Mechanism:
    """The mechanism a problem file's inline ``description:`` describes: `from_dict`, once per
    content (SHA-256 of the description's canonical JSON and of ``base_dir``), so that problems
    of one description (a sweep, a test suite) share its closure and its built solvers.  A
    description JSON cannot write (a key that is no string) is read every time."""
    import json  # only an inline description needs it (a solve of a mechanism file does not)

    try:
        canonical = json.dumps(data, sort_keys=True, allow_nan=True, default=repr)
    except (TypeError, ValueError):
        return from_dict(data, base_dir=base_dir)
    key = "inline:" + sha256_hex(f"{canonical}\0{base_dir}".encode())
    return _cached(key, lambda: _description_and_mechanism(data, None, base_dir, None))[0]


def from_dict(data: Any, *, file: str | None = None, base_dir: Path | None = None) -> Mechanism:
    """The mechanism a parsed mapping describes."""
    return _description_and_mechanism(data, file, base_dir, None)[0]


def _description_and_mechanism(
    data: Any, file: str | None, base_dir: Path | None, text: bytes | None
) -> tuple[Mechanism, Description]:
    """The mechanism a parsed mapping describes, and its description; ``text``: the bytes of
    the file it was read from, whose generated closure is kept across processes (`stored`)."""
    try:
        d = description_from_dict(data, file=file)
    except InputError as exc:
        raise exc.at(file=file) from None
    return _made(d, base_dir, None if text is None else stored.entry_key(text)), d


def mechanism(d: Description, *, base_dir: Path | None = None) -> Mechanism:
    """A [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] from a description built in code or read from a file."""
    return _made(d, base_dir, None)


def _made(d: Description, base_dir: Path | None, key: str | None) -> Mechanism:
    """The mechanism of a description: its closure generated, or read from the entry ``key`` of
    the cache (`stored`; None: not kept), where a file's closure generated here is kept."""
    try:
        kept = stored.load(key) if key is not None else None
        g = kept or stored.generate(d)
        mech = _mechanism(d, base_dir, g, checked=kept is not None)
        if key is not None and kept is None:  # generated and its reference configuration checked
            stored.save(key, d, g)
        return mech
    except InputError as exc:
        raise exc.at(file=d.file) from None


def _mechanism(d: Description, base_dir: Path | None, g: stored.Generated, checked: bool = False) -> Mechanism:
    """The mechanism of a description and its generated closure; ``checked``: the closure was
    read back from the cache, whose entry is written only once the checks below passed on
    the same file's bytes with the same code (the entry's key), so they are not run again
    (the declared hinges' formulas, 4-5 ms of the 3-PRS's start-up)."""
    fns = g.fns
    closure = LoopClosure(
        d.name,
        x=g.x_coords,
        q=g.q_coords,
        parameters=[p.name for p in d.parameters],
        phi=fns["phi"],
        task=d.platform.task,
        home=fns.get("assemble") or (lambda p: tuple(np.asarray(v, dtype=float).ravel() for v in fns["home"](p))),
        bounds=lambda p: tuple(np.asarray(v, dtype=float).ravel() for v in fns["extras"](p)[:2]),
        ik=fns["ik"],
        passive=fns["passive"],
        passive_coords=g.passive_coords,
        branch=fns["branch"],
        offsets=d.platform.offsets,
        branch_names=fns["branch_names"],
        branch_descriptions=fns["branch_descriptions"],
        frame=fns["frame"],
        loops=fns.get("loops"),
        fk_closed=fns.get("fk_closed"),
        fk_seed=fns.get("fk_seed"),
    )
    if d.stiffness is not None and not checked:  # a bad hinge is an error of the mechanism file, at load
        check_declared(closure, d.stiffness.hinges, d.stiffness.material, ("stiffness",), d.stiffness.bodies)
    params = parameter_options(d)
    limits = described_limits(g.limits, d)
    examples = tuple(str((base_dir / e).resolve()) if base_dir else e for e in d.examples)
    #: (name, dimension, size): a derived vector is reported as a vector under its name
    derived_names = g.derived
    symbol_dims = g.symbol_dims

    loading = [True]  # while the mechanism is loaded, errors are located in its file by mechanism()

    def build(closure_: LoopClosure, parameters: dict, lims: dict) -> Model:
        try:
            return _build(closure_, parameters, lims, fns, derived_names, d, symbol_dims)
        except InputError as exc:
            if loading[0] or d.file is None or exc.file is not None:
                raise
            # the problem's parameters make a value of the mechanism file fail: name both
            inner = InputError(exc.message, path=exc.path, file=d.file).render()
            raise InputError(
                f"in the mechanism file {inner}",
                path=("mechanism", "parameters"),
                suggestions=exc.suggestions,
                hint=exc.hint,
            ) from None

    mech = Mechanism(
        name=d.name,
        title=d.title,
        paper=d.paper,
        parameters=params,
        limits=limits,
        closure=lambda: closure,
        build=build,
        problem_files=examples,
        geometry=graph_geometry(*fns["graph_drawing"], g.gen)
        if d.is_graph
        else geometry_of(fns["drawing"], fns["drawing_legs"], d.platform.planar),
        origin=Origin("file", d.name, path=d.file) if d.file else Origin("inline", d.name),
        # its hinges, and its legs as serial chains (legs only: a graph has none)
        parts=tuple(p for p in (d.stiffness, LegChains(chains_maker(*g.chains)) if g.chains else None) if p),
    )
    if all(not p.required for p in params) and not checked:  # the reference configuration, with the defaults
        model = mech.model(closure, {}, {}, ())
        log.debug("%s: reference configuration checked (%d coordinates)", d.name, len(model.x_home))
    loading[0] = False
    return mech


def _build(
    closure: LoopClosure,
    parameters: dict,
    limits: dict,
    fns: dict,
    derived_names: list,
    d: Description,
    symbol_dims: dict,
) -> Model:
    p = np.array([float(parameters[n]) for n in closure.parameters])
    values = fns["extras"](p)
    lower, upper = (np.asarray(v, dtype=float).ravel() for v in values[:2])
    for name, lo, hi in zip(closure.x_names, lower, upper):
        if name in d.platform.bounds and not lo < hi:
            raise InputError(
                f"expected [low, high] with low < high, got [{lo:.6g}, {hi:.6g}] (SI) with these parameters",
                path=("platform", "bounds", name),
            )
    length = float(values[2])
    flat = np.asarray(values[3], dtype=float).ravel()
    ends = np.cumsum([size for _n, _dim, size in derived_names]).tolist()
    derived_vals = [flat[end - size : end] for (_n, _dim, size), end in zip(derived_names, ends)]
    _check_finite(d, parameters, derived_vals, symbol_dims)
    for k, (lo, hi) in enumerate(zip(np.asarray(values[0]).ravel(), np.asarray(values[1]).ravel())):
        if not (math.isfinite(lo) and math.isfinite(hi)):
            name = closure.x_names[k]
            raise InputError(
                f"the bounds of {name} are not finite ([{lo}, {hi}]) for the parameters given",
                path=("platform", "bounds"),
            )
    if not math.isfinite(length):
        raise InputError(f"not finite ({length}) for the parameters given", path=("characteristic_length",))
    dims = {par.name: par.dimension for par in d.parameters}
    dims.update({n: dim for n, dim, _size in derived_names})
    model = Model(
        closure,
        parameters={n: parameters[n] for n in closure.parameters},
        limits={k: v for k, v in limits.items() if v is not None},
        derived={
            n: float(v[0]) if size == 1 else [float(e) for e in v]
            for (n, _, size), v in zip(derived_names, derived_vals)
        },
        dimensions=dims,
        characteristic_length=length if length > 0 else 1.0,
    )
    for (what, path), value in zip(fns["requirements"], np.asarray(values[4], dtype=float).ravel()):
        if not abs(value) < 1e-9:
            if what.startswith("expected"):  # a rule of the file, not a deviation (the S joint's axes)
                raise InputError(what, path=path)
            raise InputError(
                f"the reference configuration does not assemble: {what} (deviation {value:.3e})", path=path
            )
    check_reference(model, fns["row_names"])
    return model


def _check_finite(d: Description, parameters: dict, derived: list[np.ndarray], symbol_dims: dict) -> None:
    """Every derived value (each element of a derived vector) is finite for these parameters; else
    an error naming it, its expression and the operation that made a number that is not finite."""
    known: dict[str, tuple[Any, Any]] = {
        n: (float(v), symbol_dims[n]) for n, v in parameters.items() if n in symbol_dims
    }
    for q, vec in zip(d.derived, derived):
        v = float(vec[0]) if vec.size == 1 else vec.tolist()
        if not np.all(np.isfinite(vec)):
            from . import expr as ex  # the expression language, for the message only

            exc = ex.diagnose(q.value, known)
            why = f": column {exc.column}: {exc.message}" if exc is not None else ""
            names = ex.names_in(q.value)
            given = ", ".join(f"{n} = {_quantity(val, dim)}" for n, (val, dim) in known.items() if n in names)
            raise InputError(
                f"{q.value!r} is not finite ({_shown(v)}) with {given or 'the parameters given'}{why}",
                path=("derived", q.name),
            )
        known[q.name] = (v, symbol_dims[q.name])


def _quantity(value: float | list[float], dim: Any) -> str:
    """A parameter's value for a message, in the unit people read (``20 mm``, ``60 deg``)."""
    from ...core.units import format_quantity
    from . import expr as ex

    name = {ex.LENGTH: "length", ex.ANGLE: "angle", ex.NUMBER: "dimensionless"}.get(dim)
    if name is None or isinstance(value, list):
        unit = ex.si_text(dim)
        return _shown(value) + (f" {unit}" if unit else "")
    return format_quantity(value, name, 6)


def _shown(value: float | list[float]) -> str:
    """``0.0735`` or ``[0.0735, 0.01152, 0]`` (a derived vector)."""
    if isinstance(value, list):
        return "[" + ", ".join(f"{e:g}" for e in value) + "]"
    return f"{value:g}"


def check_reference(model: Model, row_names: list[str]) -> None:
    """The reference configuration assembles, and the closures determine the pose there (rank of Φ_x)."""
    c = model.closure
    res = np.asarray(c.phi(model.x_home, model.q_home, model.p), dtype=float).ravel()
    scale = max(model.characteristic_length, 1e-12)
    worst = int(np.argmax(np.abs(res)))
    if not np.all(np.isfinite(res)) or abs(res[worst]) > 1e-9 * scale:
        raise InputError(
            f"the reference configuration does not assemble: residual {res[worst]:.3e} "
            f"({c.residual_unit}) in {row_names[worst]}; max |Φ| = {np.max(np.abs(res)):.3e}",
            path=("platform", "home"),
            hint="check the joints' locations against the home pose",
        )
    if c.branch is not None:
        g = np.asarray(c.branch(model.x_home, model.q_home, model.p), dtype=float).ravel()
        if not np.all(g > 0):
            bad = ", ".join(f"{n} = {v:.3g}" for n, v in zip(c.branch_names, g) if not v > 0)
            raise InputError(f"branch indicators not positive at the reference configuration: {bad}", path=("legs",))
    J = np.asarray(c.phi_x(model.x_home, model.q_home, model.p), dtype=float)
    s = np.linalg.svd(J, compute_uv=False)
    tol = max(J.shape) * np.finfo(float).eps * max(s[0], 1.0) * 1e3
    rank = int(np.sum(s > tol))
    if rank < c.nx:
        _u, _s, vt = np.linalg.svd(J)
        # the coordinates the free motions move: the rows of the whole null space (not one
        # SVD vector of it, which is any vector of a null space of dimension 2 or more and
        # changes with the BLAS kernel), by their share of it, in the coordinates' order
        share = np.linalg.norm(vt[rank:], axis=0)
        names = [c.x_names[k] for k in range(c.nx) if share[k] > 1e-6 * np.max(share)]
        raise InputError(
            f"wrong mobility: with the actuators locked the closures leave {c.nx - rank} free motion(s) of the "
            f"platform at the reference configuration (rank Φ_x = {rank} < {c.nx}); free: {', '.join(names)} "
            "(under-constrained: fix these coordinates under platform.fixed, or add a leg); or two equations "
            "repeat each other (over-constrained in the others)",
            path=("platform", "coordinates"),
        )
    Jq = np.asarray(c.phi_q(model.x_home, model.q_home, model.p), dtype=float)
    if np.linalg.matrix_rank(Jq) < c.nq:
        raise InputError(
            f"an actuator does not move the platform at the reference configuration (rank Φ_q < {c.nq})",
            path=("legs",),
        )


def read_description(path: str | Path) -> Description:
    """The description in a mechanism file (no generation)."""
    try:
        return description_from_dict(read_yaml(path), file=str(path))
    except InputError as exc:
        raise exc.at(file=str(path)) from None

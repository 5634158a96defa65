"""Sidecar data files: a large batch of inputs (100 000 poses) beside the problem file.

A problem file holds at most `MAX_INPUT_BYTES`; a
batch larger than that comes from a data file that the problem file names
under ``inputs.data``::

    inputs:
      data: poses.csv                                # header: s1, s2, s3 (SI), or "s1 [mm]", ...
      # or: data: {file: poses.npy, columns: [s1, s2, s3]}   # an (N, 3) array, SI

* the path is relative to the problem file's folder (the working directory
  for a problem read from standard input) and stays inside it: no absolute
  path, no ``..`` out of it, no symbolic link out of it;
* CSV (a header line naming the columns, then one row per point), NPY (a
  2-D numeric array; ``columns`` names its columns) or Parquet (numeric
  columns; needs pyarrow);
* read with the bounds of every input: a regular file (no FIFO, no device),
  at most `MAX_DATA_BYTES`, at most `MAX_DATA_ROWS` rows, every
  value finite; each column names an input of the problem kind that takes a
  list (the actuators of ``forward_kinematics``, the task coordinates of
  ``inverse_kinematics`` ...), once, and not also given in the file;
* an error names the row and the column, never the file's content.
"""

from __future__ import annotations

import io
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InputError, suggest
from ..core.units import parse_quantity
from .inputs import read_input_bytes, resolve

#: Largest data file read (bytes), and most rows (points) in one.
MAX_DATA_BYTES = 256 << 20  # 256 MiB
MAX_DATA_ROWS = 1_000_000
#: The formats, by file name suffix.
FORMATS = (".csv", ".npy", ".parquet")
#: The input key that names a data file.
DATA_KEY = "data"

_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[\s*([^\]]*?)\s*\])?\s*$")


def merge_data_file(
    raw: Mapping[str, Any], options: Sequence[Any], base_dir: Path | None, path: tuple = ("inputs",)
) -> dict[str, Any]:
    """``raw`` (a problem file's inputs) with ``data`` replaced by the columns
    of the data file it names, as lists of SI values (validated afterwards as
    if they had been written in the file)."""
    where = path + (DATA_KEY,)
    spec = raw[DATA_KEY]
    if isinstance(spec, Mapping):
        unknown = [k for k in spec if k not in ("file", "columns")]
        if unknown:
            raise InputError(
                f"unknown key {unknown[0]!r}; expected file and columns",
                path=where,
                suggestions=suggest(str(unknown[0]), ["file", "columns"]),
            )
        name, columns = spec.get("file"), spec.get("columns")
    else:
        name, columns = spec, None
    listed = {o.name: o for o in options if getattr(o, "shape", "scalar") in ("list", "grid")}
    target = _locate(name, base_dir, where)
    if columns is not None:
        if not isinstance(columns, list) or not columns or not all(isinstance(c, str) for c in columns):
            raise InputError(f"expected a list of input names, got {columns!r}", path=where + ("columns",))
    headers, table = _read(target, columns, where)
    names = [h.split("[")[0].strip() for h in headers]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(f"the column {twice[0]!r} is named twice", path=where)
    out = {k: v for k, v in raw.items() if k != DATA_KEY}
    for j, header in enumerate(headers):
        column, unit = _column(header, listed, out, where + (("columns", j) if columns else ()))
        option = listed[column]
        factor = 1.0 if not unit else parse_quantity(f"1 {unit}", option.kind, where + ("columns", column))
        out[column] = (table[:, j] * factor).tolist()
    return out


def _locate(name: Any, base_dir: Path | None, where: tuple) -> Path:
    """The data file, inside the problem file's folder."""
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"expected the name of a data file ({', '.join(FORMATS)}), got {name!r}", path=where)
    if Path(name).suffix.lower() not in FORMATS:
        raise InputError(
            f"expected a data file ending in {', '.join(FORMATS)}, got {name!r}",
            path=where,
            suggestions=[str(Path(name).with_suffix(s)) for s in FORMATS if Path(name).suffix],
        )
    folder = resolve(base_dir if base_dir is not None else Path.cwd())
    if Path(name).is_absolute() or ".." in Path(name).parts:
        raise InputError(
            f"expected a path relative to the problem file's folder, without '..', got {name!r}", path=where
        )
    target = folder / name
    if not resolve(target).is_relative_to(folder):
        raise InputError(f"{name!r} leads out of the problem file's folder (a symbolic link)", path=where)
    return target


def _read(target: Path, columns: list[str] | None, where: tuple) -> tuple[list[str], np.ndarray]:
    """(column headers, an (N, k) float array) of a data file, with the checks of the module docstring."""
    suffix = target.suffix.lower()
    try:
        data = read_input_bytes(target, MAX_DATA_BYTES)
    except InputError as exc:
        raise InputError(exc.message, path=where, hint=f"the data file {target.name}") from None
    if suffix == ".csv":
        headers, table = _csv(data, where)
        if columns is not None and [h.split("[")[0].strip() for h in headers] != columns:
            raise InputError("give the columns in the CSV header, not under 'columns'", path=where + ("columns",))
    elif suffix == ".npy":
        headers, table = _npy(data, columns, where)
    else:
        headers, table = _parquet(data, columns, where)
    if table.shape[0] == 0:
        raise InputError(f"{target.name} holds no rows", path=where)
    if table.shape[0] > MAX_DATA_ROWS:
        raise InputError(f"{target.name} holds {table.shape[0]} rows; at most {MAX_DATA_ROWS}", path=where)
    bad = np.argwhere(~np.isfinite(table))
    if bad.size:
        row, col = (int(v) for v in bad[0])
        raise InputError(
            f"{target.name}: row {row + 1}, column {headers[col]!r}: expected a finite number "
            f"({len(bad)} value(s) are not)",
            path=where,
        )
    return headers, table


def _csv(data: bytes, where: tuple) -> tuple[list[str], np.ndarray]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"the CSV file is not UTF-8 text (byte {exc.start})", path=where) from None
    first, _, body = text.partition("\n")
    headers = [h.strip() for h in first.strip().split(",")]
    if not headers or not all(headers):
        raise InputError("expected a header line naming the columns (e.g. 's1, s2, s3')", path=where)
    rows = [line for line in body.splitlines() if line.strip()]
    if len(rows) > MAX_DATA_ROWS:
        raise InputError(f"the CSV file holds {len(rows)} rows; at most {MAX_DATA_ROWS}", path=where)
    split = [line.split(",") for line in rows]
    if all(len(cells) == len(headers) for cells in split):
        try:  # every value at once; any error: the loop below names its row and column
            flat = [float(c) for cells in split for c in cells]
            return headers, np.array(flat, dtype=float).reshape(len(rows), len(headers))
        except ValueError:
            pass
    table = np.empty((len(rows), len(headers)))
    for i, line in enumerate(rows):
        cells = line.split(",")
        if len(cells) != len(headers):
            raise InputError(
                f"row {i + 1} has {len(cells)} value(s); the header names {len(headers)} column(s)", path=where
            )
        try:
            table[i] = [float(c) for c in cells]
        except ValueError:
            col = next(j for j, c in enumerate(cells) if not _is_float(c))
            raise InputError(f"row {i + 1}, column {headers[col]!r}: expected a number", path=where) from None
    return headers, table


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _npy(data: bytes, columns: list[str] | None, where: tuple) -> tuple[list[str], np.ndarray]:
    if columns is None:
        raise InputError("an NPY file has no header: name its columns, {file: ..., columns: [...]}", path=where)
    try:
        arr = np.load(io.BytesIO(data), allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"not a readable NPY file ({exc.__class__.__name__})", path=where) from None
    if not isinstance(arr, np.ndarray) or arr.dtype.kind not in "iuf":
        raise InputError("expected an array of numbers in the NPY file", path=where)
    arr = arr.reshape(-1, 1) if arr.ndim == 1 else arr
    if arr.ndim != 2 or arr.shape[1] != len(columns):
        raise InputError(
            f"expected an (N, {len(columns)}) array for the columns {', '.join(columns)}, got shape {arr.shape}",
            path=where,
        )
    return list(columns), arr.astype(float)


def _parquet(data: bytes, columns: list[str] | None, where: tuple) -> tuple[list[str], np.ndarray]:
    from ..core.extras import require

    require("pyarrow", "sweep", "Parquet data files")
    import pyarrow.parquet as pq

    try:
        handle = pq.ParquetFile(io.BytesIO(data))
        meta = handle.metadata
        if meta.num_rows > MAX_DATA_ROWS:
            raise InputError(f"the Parquet file holds {meta.num_rows} rows; at most {MAX_DATA_ROWS}", path=where)
        names = columns if columns is not None else list(handle.schema_arrow.names)
        missing = [c for c in names if c not in handle.schema_arrow.names]
        if missing:
            raise InputError(f"the Parquet file has no column {missing[0]!r}", path=where)
        table = handle.read(columns=names)
        arr = np.column_stack([np.asarray(table.column(c).to_numpy(zero_copy_only=False), dtype=float) for c in names])
    except InputError:
        raise
    except Exception as exc:  # pyarrow: ArrowInvalid, OSError ... for a file that is not Parquet
        raise InputError(f"not a readable Parquet file of numbers ({exc.__class__.__name__})", path=where) from None
    return names, arr


def _column(header: str, listed: Mapping[str, Any], given: Mapping[str, Any], where: tuple) -> tuple[str, str]:
    """(input name, unit) of a column header ``name`` or ``name [unit]``."""
    match = _HEADER.match(header)
    if match is None:
        raise InputError("expected a column header 'name' or 'name [unit]'", path=where)
    name, unit = match.group(1), match.group(2) or ""
    if name not in listed:
        raise InputError(
            f"column {name!r} is not an input that takes a list of values; expected one of: "
            f"{', '.join(listed) or 'none (this problem kind takes no batch)'}",
            path=where,
            suggestions=suggest(name, listed),
        )
    if given.get(name) is not None:
        raise InputError(f"{name!r} is given both in the data file and in the problem file", path=where)
    return name, unit


def data_file_of(raw: Any) -> bool:
    """Whether a problem file's inputs name a data file."""
    return isinstance(raw, Mapping) and raw.get(DATA_KEY) is not None


__all__ = ["DATA_KEY", "FORMATS", "MAX_DATA_BYTES", "MAX_DATA_ROWS", "data_file_of", "merge_data_file"]

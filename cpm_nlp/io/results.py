"""Results files of sweeps: one row per point, written as points finish.

Columns: ``point`` (its number in the sweep), one column per swept key (SI
values), ``status``, ``message``, ``seconds`` (wall time of the point),
``warnings`` (the point's result warnings, a JSON list of
``{code, message, where, value, limit}``, ``[]`` when clean), then
the recorded result values (SI; ``null``/empty where the point did not
solve; a list is stored as JSON text).  The file also carries metadata: the
sweep's fingerprint, its parameters and their dimensions, and the units of
the values.

* **CSV** (``.csv``): the first line is ``# cpm_nlp sweep {json metadata}``,
  the second the header; each finished point is appended as one line and
  flushed (``pandas.read_csv(path, skiprows=1)`` reads it).
* **Parquet** (``.parquet``, needs pyarrow): a Parquet file cannot be appended
  to, so finished points are appended to a journal ``<file>.journal`` (JSON
  lines) at once, and the Parquet file is rewritten whole, atomically, every
  few seconds and at the end, when the journal is removed.  The metadata is
  the schema's ``cpm_nlp`` key.

Resuming reads what is there (a Parquet file and its journal, or the CSV
rows; a line cut short by a crash is dropped and that point solved again),
so nothing solved is lost and nothing is solved twice.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import time
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core.errors import InputError
from ..core.result import jsonable
from .atomic import check_output_path, replace_atomically
from .inputs import MAX_RESULTS_BYTES, check_input_file, read_input_text

META_PREFIX = "# cpm_nlp sweep "
FORMATS = (".parquet", ".csv")
#: fixed columns besides the swept keys and the values
TEXT_COLUMNS = ("status", "message")


@dataclass
class SweepTable:
    """A results file read back: metadata and rows (column -> Python value)."""

    path: str
    meta: dict[str, Any]
    rows: list[dict[str, Any]] = field(default_factory=list)

    @property
    def parameters(self) -> list[dict[str, Any]]:
        return list(self.meta.get("parameters", []))

    @property
    def values(self) -> list[str]:
        return list(self.meta.get("values", []))

    def column(self, name: str) -> list[Any]:
        return [r.get(name) for r in self.rows]

    def warnings(self) -> list[list[Any]]:
        """Each row's result warnings ([`ResultWarning`][cpm_nlp.core.result.ResultWarning]; [] for a
        file written before sweeps recorded them)."""
        from ..core.result import ResultWarning

        out = []
        for r in self.rows:
            raw = r.get("warnings")
            out.append([ResultWarning.from_dict(w) for w in raw] if isinstance(raw, list) else [])
        return out


def results_format(path: str | os.PathLike) -> str:
    """``.parquet`` or ``.csv`` from the file name (an [`InputError`][cpm_nlp.core.errors.InputError] otherwise)."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise InputError(f"expected a results file ending in .parquet or .csv, got {str(path)!r}", path=("-o",))
    return suffix


# -- cells ------------------------------------------------------------------------------------


def _cell(value: Any) -> str:
    """A CSV cell: numbers exactly (repr), lists as JSON, None empty."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return json.dumps(value)
    if isinstance(value, (int, float)):
        return repr(value) if math.isfinite(value) else ""
    if isinstance(value, str):
        return value
    return json.dumps(jsonable(value), allow_nan=False)


def _uncell(text: str) -> Any:
    if text == "":
        return None
    try:
        return float(text)
    except ValueError:
        pass
    if text[:1] in "[{" or text in ("true", "false"):
        try:
            return json.loads(text)
        except ValueError:
            return text
    return text


def _decode_row(raw: Mapping[str, str], path: Path, line: int) -> dict[str, Any]:
    row: dict[str, Any] = {}
    for name, text in raw.items():
        if name == "point":
            try:
                row[name] = int(text)
            except (TypeError, ValueError):
                raise InputError(
                    f"line {line}: expected a point number in column 'point', got {str(text)[:40]!r}", file=str(path)
                ) from None
        elif name in TEXT_COLUMNS:
            row[name] = text
        else:
            row[name] = _uncell(text)
    return row


# -- stores -----------------------------------------------------------------------------------


class _Store:
    """Rows of one sweep in one file; subclasses write CSV or Parquet.

    An existing file of the same sweep is adopted (its points are ``done``);
    a new file (or, with ``overwrite``, the replacement of the old one) is
    only created with the first record, so a run that fails before solving
    anything leaves the disk as it was.
    """

    def __init__(self, path: Path, meta: dict[str, Any], columns: list[str], overwrite: bool) -> None:
        self.path = path
        self.meta = meta
        self.columns = columns
        self.overwrite = overwrite
        self.done: dict[int, str] = {}  # point -> status
        self.added = 0  # points written by this run
        self._fh: Any = None
        self._closed = False
        self._meta_seen = ""

    def append(self, records: list[dict[str, Any]], units: Mapping[str, str], dims: Mapping[str, str]) -> None:
        self.meta["units"].update(units)
        self.meta["dimensions"].update(dims)
        fresh = [r for r in records if r["point"] not in self.done]
        for r in fresh:
            self.done[r["point"]] = r["status"]
        self.added += len(fresh)
        if fresh:
            if self._fh is None:
                self._open()
            self._write(fresh)

    def status_counts(self) -> dict[str, int]:
        return dict(Counter(self.done.values()))

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if self._fh is not None:
            self._fh.close()
        self._finish()

    def _adopt(self, table: SweepTable) -> None:
        """Take over the rows and metadata of an existing file of the same sweep."""
        _check_same_sweep(table, self.meta, self.columns, self.path)
        self._meta_seen = json.dumps(table.meta, sort_keys=True)  # what the file says now
        for key in ("units", "dimensions"):
            self.meta[key] = {**table.meta.get(key, {}), **self.meta[key]}
        for r in table.rows:
            self.done[r["point"]] = r["status"]

    def _meta_changed(self) -> bool:
        return json.dumps(self.meta, sort_keys=True) != self._meta_seen

    def _open(self) -> None:
        raise NotImplementedError

    def _write(self, records: list[dict[str, Any]]) -> None:
        raise NotImplementedError

    def _finish(self) -> None:
        raise NotImplementedError


def _check_same_sweep(table: SweepTable, meta: Mapping[str, Any], columns: list[str], path: Path) -> None:
    if table.meta.get("fingerprint") != meta["fingerprint"] or (table.rows and list(table.rows[0]) != columns):
        raise InputError(
            f"{path} holds the results of another sweep (the problem or its sweep section changed "
            "since it was written); give another output file, or --overwrite to start again",
            path=("-o",),
        )


class CsvStore(_Store):
    def __init__(self, path: Path, meta: dict[str, Any], columns: list[str], overwrite: bool) -> None:
        super().__init__(path, meta, columns, overwrite)
        self.resumed = path.exists() and not overwrite
        if self.resumed:
            self._adopt(read_csv(path))  # a file of ours and of this sweep, before anything is changed in it
            _truncate_partial_line(path)

    def _head(self) -> str:
        buf = io.StringIO()
        buf.write(META_PREFIX + json.dumps(self.meta, sort_keys=True) + "\n")
        csv.writer(buf, lineterminator="\n").writerow(self.columns)
        return buf.getvalue()

    def _open(self) -> None:
        if not self.resumed:
            replace_atomically(self.path, lambda tmp: Path(tmp).write_text(self._head(), encoding="utf-8"))
            self._meta_seen = json.dumps(self.meta, sort_keys=True)
        self._fh = open(self.path, "a", encoding="utf-8", newline="")  # noqa: SIM115 - closed in close()
        self._csv = csv.writer(self._fh, lineterminator="\n")

    def _write(self, records: list[dict[str, Any]]) -> None:
        for r in records:
            self._csv.writerow([_cell(r.get(c)) for c in self.columns])
        self._fh.flush()

    def _finish(self) -> None:
        if self._fh is not None and self._meta_changed():  # units learned: refresh line 1
            body = self.path.read_text(encoding="utf-8").split("\n", 2)[2]
            replace_atomically(self.path, lambda tmp: Path(tmp).write_text(self._head() + body, encoding="utf-8"))


def _truncate_partial_line(path: Path) -> None:
    """Drop a last line cut short by a crash (every record ends with a newline)."""
    with open(path, "rb+") as fh:
        data = fh.read()
        if data and not data.endswith(b"\n"):
            fh.truncate(data.rfind(b"\n") + 1)


class ParquetStore(_Store):
    #: rewrite the Parquet file at most this often (seconds), and not more
    #: often than 20 times the time one rewrite takes
    INTERVAL = 5.0

    def __init__(self, path: Path, meta: dict[str, Any], columns: list[str], overwrite: bool) -> None:
        super().__init__(path, meta, columns, overwrite)
        require_pyarrow()
        self.journal = journal_path(path)
        self.rows: dict[int, dict[str, Any]] = {}
        self._dirty = False  # rows not yet in the Parquet file
        if not overwrite and (path.exists() or self.journal.exists()):
            table = read_parquet(path)
            if table.meta or path.exists():  # else: a journal cut short in its first line (nothing solved)
                self._adopt(table)
            self.rows = {r["point"]: r for r in table.rows}
            if self.journal.exists():
                _truncate_partial_line(self.journal)
                self._dirty = bool(table.rows)  # a run that stopped before writing its Parquet file
        self._last = time.monotonic()
        self._cost = 0.0

    def _open(self) -> None:
        if self.overwrite:
            self.path.unlink(missing_ok=True)
            self.journal.unlink(missing_ok=True)
        self._fh = open(self.journal, "a", encoding="utf-8")  # noqa: SIM115 - closed in close()
        if self._fh.tell() == 0:
            self._fh.write(json.dumps(self.meta, sort_keys=True) + "\n")
            self._fh.flush()

    def _write(self, records: list[dict[str, Any]]) -> None:
        for r in records:
            self.rows[r["point"]] = r
            self._fh.write(json.dumps(jsonable(r), allow_nan=False) + "\n")
        self._fh.flush()
        self._dirty = True
        if time.monotonic() - self._last > max(self.INTERVAL, 20 * self._cost):
            self._snapshot()

    def _snapshot(self) -> None:
        t0 = time.monotonic()
        write_parquet(self.path, self.meta, self.columns, [self.rows[k] for k in sorted(self.rows)])
        self._last = time.monotonic()
        self._cost = self._last - t0
        self._dirty = False
        self._meta_seen = json.dumps(self.meta, sort_keys=True)

    def _finish(self) -> None:
        if self._dirty or (self._fh is not None and self._meta_changed()):
            self._snapshot()
        if self._fh is not None or self.journal.exists():
            self.journal.unlink(missing_ok=True)


def journal_path(path: Path) -> Path:
    return path.with_name(path.name + ".journal")


def open_store(path: str | os.PathLike, meta: dict[str, Any], columns: list[str], *, overwrite: bool = False) -> _Store:
    """The results file of a sweep, ready to append to (existing rows adopted)."""
    target = Path(path)
    fmt = results_format(target)
    check_output_path(str(target))
    if fmt == ".parquet":  # the journal is appended to: a regular file too, never an input
        check_output_path(str(journal_path(target)))
    meta = json.loads(json.dumps(meta))  # a copy: the store adds units as it learns them
    if fmt == ".csv":
        return CsvStore(target, meta, columns, overwrite)
    return ParquetStore(target, meta, columns, overwrite)


# -- reading ------------------------------------------------------------------------------------


def _meta_of(first: str, path: Path) -> dict[str, Any]:
    if not first.startswith(META_PREFIX):
        raise InputError(
            f"the file is not a cpm_nlp sweep results file (its first line is not '{META_PREFIX.strip()} ...')",
            file=str(path),
        )
    try:
        meta = json.loads(first[len(META_PREFIX) :])
    except ValueError:
        meta = None
    if not isinstance(meta, dict):
        raise InputError("the metadata line (line 1) of the results file is damaged", file=str(path))
    return meta


def read_csv(path: Path) -> SweepTable:
    """Rows of a CSV results file; a last line cut short by a crash (no newline) is dropped."""
    text = read_input_text(path, MAX_RESULTS_BYTES, record=False)
    text = text[: text.rfind("\n") + 1]  # every record ends with a newline
    first, _, body = text.partition("\n")
    meta = _meta_of(first, path)
    reader = csv.DictReader(io.StringIO(body, newline=""))
    rows = []
    for raw in reader:
        if None in raw.values() or None in raw:
            raise InputError(
                f"line {reader.line_num + 1}: expected {len(reader.fieldnames or ())} columns", file=str(path)
            )
        rows.append(_decode_row(raw, path, reader.line_num + 1))
    return SweepTable(str(path), meta, rows)


def require_pyarrow() -> Any:
    from ..core.extras import require

    require("pyarrow.parquet", "sweep", "a Parquet results file")


def read_parquet(path: Path) -> SweepTable:
    """Rows of the Parquet file and of its journal (a sweep still running or interrupted)."""
    require_pyarrow()
    meta: dict[str, Any] = {}
    rows: dict[int, dict[str, Any]] = {}
    if path.exists():
        meta = _read_parquet_rows(path, rows)
    journal = journal_path(path)
    if journal.exists():
        meta = _read_journal(journal, path, meta, rows)
    meta.pop("json_columns", None)
    return SweepTable(str(path), meta, [rows[k] for k in sorted(rows)])


def _read_parquet_rows(path: Path, rows: dict[int, dict[str, Any]]) -> dict[str, Any]:
    """The rows of the Parquet file itself, into ``rows`` by point; its metadata."""
    import pyarrow.parquet as pq

    check_input_file(path, None)
    try:
        table = pq.read_table(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid, OSError ... for a file that is not Parquet
        raise InputError(f"{path} is not a readable Parquet file ({exc.__class__.__name__}: {exc})") from None
    raw_meta = (table.schema.metadata or {}).get(b"cpm_nlp")
    if raw_meta is None:
        raise InputError(f"{path} is not a cpm_nlp sweep results file (no cpm_nlp metadata)")
    meta = json.loads(raw_meta)
    json_cols = set(meta.get("json_columns", []))
    for r in table.to_pylist():
        for c in json_cols:
            if r.get(c) is not None:
                r[c] = json.loads(r[c])
        rows[r["point"]] = r
    return meta


def _read_journal(journal: Path, path: Path, meta: dict[str, Any], rows: dict[int, dict[str, Any]]) -> dict[str, Any]:
    """The rows of the journal beside ``path`` (they replace the file's of the same point), into
    ``rows``; the metadata (the file's, else the journal's first line)."""
    text = read_input_text(journal, MAX_RESULTS_BYTES, record=False)
    lines = text[: text.rfind("\n") + 1].split("\n")[:-1]  # a last line cut short by a crash is dropped
    if lines:
        try:
            head = json.loads(lines[0])
        except ValueError:
            head = None
        if not isinstance(head, dict):
            raise InputError("the journal's first line (the sweep's metadata) is damaged", file=str(journal))
        meta = meta or head
        if head.get("fingerprint") != meta.get("fingerprint"):
            raise InputError(f"{journal} belongs to another sweep than {path}; remove one of them")
    for n, line in enumerate(lines[1:], start=2):
        try:
            r = json.loads(line)
            rows[int(r["point"])] = r
        except (ValueError, TypeError, KeyError):
            raise InputError(f"line {n} of the journal is damaged", file=str(journal)) from None
    return meta


def write_parquet(path: Path, meta: Mapping[str, Any], columns: list[str], rows: list[dict[str, Any]]) -> None:
    """All rows, typed: numbers as float64, anything else as JSON text."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrays, fields, json_cols = [], [], []
    for c in columns:
        values = [r.get(c) for r in rows]
        if c == "point":
            typ = pa.int64()
        elif c in TEXT_COLUMNS:
            typ = pa.string()
        elif all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values):
            typ = pa.float64()
            values = [None if v is None or not math.isfinite(v) else float(v) for v in values]
        else:
            typ = pa.string()
            values = [None if v is None else json.dumps(jsonable(v), allow_nan=False) for v in values]
            json_cols.append(c)
        arrays.append(pa.array(values, type=typ))
        fields.append(pa.field(c, typ))
    full = dict(meta, json_columns=json_cols)
    schema = pa.schema(fields, metadata={b"cpm_nlp": json.dumps(full, sort_keys=True).encode()})
    table = pa.Table.from_arrays(arrays, schema=schema)
    replace_atomically(path, lambda tmp: pq.write_table(table, tmp))


def read_results(path: str | os.PathLike) -> SweepTable:
    """Read a sweep results file (``.parquet`` or ``.csv``)."""
    p = Path(path)
    if not p.exists() and not journal_path(p).exists():
        if p.is_symlink():
            raise InputError("a symbolic link to a file that does not exist", file=str(path))
        raise InputError("file not found", file=str(path))
    if results_format(p) == ".csv":
        return read_csv(p)
    return read_parquet(p)

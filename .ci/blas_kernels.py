"""Every number of every shipped problem, to compare two BLAS CPU kernels.

    python .ci/blas_kernels.py solve OUT.json     # solve problems/*.yaml, write {file: result JSON}
    python .ci/blas_kernels.py compare A.json B.json   # exit 1 on any difference
    python .ci/blas_kernels.py kernel             # the BLAS kernel that runs here (threadpoolctl)
    python .ci/blas_kernels.py other-kernel       # an OPENBLAS_CORETYPE other than this one ('' if none)

CI (.ci/run) solves every problem under the kernel the machine picks, then again
under another (OPENBLAS_CORETYPE), and compares.  Two numbers are the same when
they agree to 1e-9 relative: of the larger of the two, or, in a list or matrix,
of the largest entry of that list (so that an entry that is zero by symmetry and
comes out as 1e-17 on one kernel and -3e-17 on the other is the same zero).  A
length (m) or an angle (rad) that is zero by symmetry throughout its list (an
equilibrium's pose at equal actuator inputs) has no scale of its own: two such
values within `ZERO_FLOOR` of each other (1e-15 m, 1e-15 rad, against a pose's own
round-off of about 2e-17 m in a 0.1 m mechanism, amplified by the linear solves of
an equilibrium) are the same zero; the printed values are 0 on both.  A
status, a string or a list length must be identical.  Wall-clock times (values
named ``*seconds``) are left out.  The comparison is what
"every number is identical under two BLAS kernels" means: the last bits of a
floating-point sum differ between kernels, the answer must not.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RTOL = 1e-9
#: the absolute floor below which two lengths (m) or angles (rad) are the same zero
ZERO_FLOOR = {"m": 1e-15, "rad": 1e-15}
#: files left out: none today (all 55 take about 60 s in one process on a loaded machine)
SKIP: tuple[str, ...] = ()


def kernel() -> str:
    """The CPU kernel of the OpenBLAS that numpy and scipy load, e.g. 'Haswell'
    (several names joined by '+' if the libraries disagree)."""
    import numpy as np
    import scipy.linalg  # noqa: F401 - loads scipy's own OpenBLAS
    from threadpoolctl import threadpool_info

    np.ones(2) @ np.ones(2)
    kinds = sorted({str(i.get("architecture")) for i in threadpool_info() if i.get("user_api") == "blas"})
    return "+".join(kinds) or "unknown"


def other_kernel(current: str) -> str:
    """An x86-64 OpenBLAS kernel other than ``current``, older (safe on any CPU
    that runs ``current``): Sandybridge (AVX), or Nehalem (SSE4) when Sandybridge
    already runs.  '' on a machine without OpenBLAS x86-64 kernels."""
    x86 = ("Haswell", "SkylakeX", "Zen", "Cooperlake", "Sapphirerapids", "Sandybridge", "Nehalem")
    if not any(k in current for k in x86):
        return ""
    return "Nehalem" if "Sandybridge" in current else "Sandybridge"


def solve_all(out: Path) -> int:
    from cpm_nlp.problems.file import load_problem, solve

    found: dict = {"kernel": kernel(), "problems": {}}
    start = time.perf_counter()
    for path in sorted((ROOT / "problems").glob("*.yaml")):
        if path.name in SKIP:
            continue
        result = solve(load_problem(path))
        doc = json.loads(result.to_json())
        values = {k: v for k, v in doc["values"].items() if not k.endswith("seconds")}  # wall-clock times
        units = {k: doc.get("units", {}).get(k) for k in values}
        found["problems"][path.name] = {"status": doc["status"], "values": values, "units": units}
    out.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
    n = len(found["problems"])
    print(f"{n} problems solved under the {found['kernel']} kernel in {time.perf_counter() - start:.1f} s")
    return 0


def _scale(value) -> float:
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return 0.0
    if isinstance(value, (int, float)):
        return abs(value) if math.isfinite(value) else 0.0
    if isinstance(value, list):
        return max((_scale(v) for v in value), default=0.0)
    return 0.0


def differences(a, b, where: str = "", scale: float = 0.0, floor: float = 0.0, units=None) -> list[str]:
    """Where ``a`` and ``b`` differ (see the module's docstring for 'differ').  ``units``: the
    unit of each value, in a problem's ``values``; ``floor``: the value's `ZERO_FLOOR`."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}.{k}: only in one run" for k in sorted(set(a) ^ set(b))]
        problem = "values" in a and "units" in a
        for k in sorted(set(a) & set(b)):
            path = f"{where}.{k}" if where else k
            if problem and k == "units":
                continue
            if problem and k == "values":
                out += differences(a[k], b[k], path, units=a["units"] or {})
            elif units is not None:  # a problem's values: each its unit's floor
                out += differences(a[k], b[k], path, floor=ZERO_FLOOR.get(units.get(k) or "", 0.0))
            else:
                out += differences(a[k], b[k], path)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: lengths {len(a)} and {len(b)}"]
        s = max(scale, _scale(a), _scale(b))
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(x, y, f"{where}[{i}]", s, floor)]
    return [] if _same(a, b, scale, floor) else [f"{where}: {a!r} and {b!r}"]


def _same(a, b, scale: float, floor: float) -> bool:
    """Two leaves agree: numbers to `RTOL` of the larger or of ``scale``, or both within
    ``floor`` of zero; anything else identical."""
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool) and not isinstance(b, bool):
        return a == b or abs(a - b) <= RTOL * max(abs(a), abs(b), scale) or max(abs(a), abs(b)) <= floor
    return a == b


def compare(first: Path, second: Path) -> int:
    a, b = json.loads(first.read_text()), json.loads(second.read_text())
    if a["kernel"] == b["kernel"]:
        print(f"error: both runs used the {a['kernel']} kernel: nothing was compared", file=sys.stderr)
        return 1
    found = differences(a["problems"], b["problems"])
    count = sum(_count(v) for v in a["problems"].values())
    if found:
        kernels = f"the {a['kernel']} and {b['kernel']} kernels"
        print(f"error: {len(found)} numbers differ between {kernels}:", file=sys.stderr)
        for line in found[:40]:
            print(f"  {line}", file=sys.stderr)
        return 1
    print(f"{len(a['problems'])} problems, {count} numbers: the same under the {a['kernel']} and {b['kernel']} kernels")
    return 0


def _count(value) -> int:
    if isinstance(value, dict):
        return sum(_count(v) for v in value.values())
    if isinstance(value, list):
        return sum(_count(v) for v in value)
    return int(isinstance(value, (int, float)) and not isinstance(value, bool))


def main(argv: list[str]) -> int:
    if argv[:1] == ["solve"] and len(argv) == 2:
        return solve_all(Path(argv[1]))
    if argv[:1] == ["compare"] and len(argv) == 3:
        return compare(Path(argv[1]), Path(argv[2]))
    if argv == ["kernel"]:
        print(kernel())
        return 0
    if argv == ["other-kernel"]:
        print(other_kernel(kernel()))
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

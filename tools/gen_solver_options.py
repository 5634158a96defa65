"""Regenerate ``cpm_nlp/core/solver_options.json``: the option documentation of
the IPOPT and CasADi that cpm_nlp ships with, as data.

Run from the repository root after upgrading CasADi (a development step; the
package never runs this)::

    python tools/gen_solver_options.py

It asks the installed IPOPT for its own documentation (the option
``print_options_documentation yes`` in doxygen form, advanced options
included, printed on a one-variable problem solved through ``casadi.nlpsol``),
and CasADi for the options of ``nlpsol('ipopt')`` and of
``rootfinder('newton')`` (``Function.print_options``).  Both print on the C
library's stdout, so each runs in a child Python whose stdout is captured.
Every IPOPT linear solver that is built in (not loaded from a library at run
time) is tried on the same tiny problem, so the table records which ones work.

The table is raw documentation; the policy (which options a problem file may
set) is in :mod:`cpm_nlp.core.solver_options`.
"""

from __future__ import annotations

import html
import json
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import casadi as ca

OUT = Path(__file__).resolve().parents[1] / "cpm_nlp" / "core" / "solver_options.json"

_TINY = """
import casadi as ca
y = ca.SX.sym("y")
"""


def _child(code: str) -> str:
    """stdout (the C library's too) of ``code`` run in a fresh Python, in an empty directory."""
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run(
            [sys.executable, "-c", _TINY + code], capture_output=True, text=True, cwd=tmp, check=False, timeout=120
        )
    if run.returncode != 0:
        raise SystemExit(f"child failed:\n{run.stderr}")
    return run.stdout


def ipopt_documentation() -> str:
    return _child(
        "s = ca.nlpsol('s', 'ipopt', {'x': y, 'f': (y - 1)**2}, {'print_time': False,"
        " 'ipopt.print_options_documentation': 'yes', 'ipopt.print_options_mode': 'doxygen',"
        " 'ipopt.print_advanced_options': 'yes'})\ns(x0=3)\n"
    )


def _number(text: str) -> float:
    text = text.strip().replace("&le;", "").strip()
    m = re.fullmatch(r"([-+]?)([\d.]+ &middot; )?10<sup>([-+]\d+)</sup>", text)  # 10<sup>-08</sup>
    if m:
        mantissa = float(m.group(2).split()[0]) if m.group(2) else 1.0
        return float(f"{m.group(1)}{mantissa!r}e{m.group(3)}")
    if text in ("+inf", "inf"):
        return math.inf
    if text == "-inf":
        return -math.inf
    return float(text)


def _range(name: str, text: str) -> dict:
    """``0 < tol``, ``0 &le; max_iter &le; 12``, ``unrestricted`` -> bounds."""
    out = {"lower": None, "lower_strict": False, "upper": None, "upper_strict": False}
    if text.strip() == "unrestricted":
        return out
    parts = [p.strip() for p in re.split(r"(&le;|<)", text)]
    # tokens: [lo, op, name, op, hi] or [lo, op, name] or [name, op, hi]
    i = parts.index(name)
    if i >= 2:
        out["lower"], out["lower_strict"] = _number(parts[i - 2]), parts[i - 1] == "<"
    if i + 2 < len(parts):
        out["upper"], out["upper_strict"] = _number(parts[i + 2]), parts[i + 1] == "<"
    return out


def parse_ipopt(doc: str) -> list[dict]:
    options = []
    sections = _sections(doc)
    blocks = re.split(r"^\\anchor OPT_", doc, flags=re.M)
    for block in blocks:
        head = re.match(
            r"(\w+)\n<strong>(\w+)</strong>( \(<em>advanced</em>\))?(?:: (.*?))?\n<blockquote>\n(.*?)</blockquote>",
            block,
            flags=re.S,
        )
        if not head:
            if block.strip() and not block.lstrip().startswith("\\subsection") and "<strong>" in block:
                raise SystemExit(f"cannot parse this IPOPT option block:\n{block[:500]}")
            continue
        name, advanced, short, body = head.group(2), bool(head.group(3)), head.group(4) or "", head.group(5)
        entry: dict = {"name": name, "section": sections[name], "advanced": advanced}
        entry["description"] = html.unescape(short)
        num = re.search(
            r"The valid range for this (real|integer) option is (.*?) and its default value is (.*?)\.\s*$",
            body,
            flags=re.M,
        )
        if num:
            entry["type"] = num.group(1)
            entry.update(_range(name, num.group(2)))
            default = _number(num.group(3))
            entry["default"] = int(default) if num.group(1) == "integer" else default
        else:
            s = re.search(r'The default value for this string option is "(.*?)"\.', body)
            if not s:
                raise SystemExit(f"cannot parse the IPOPT option {name}:\n{body}")
            entry["type"] = "string"
            entry["default"] = s.group(1)
            inline = re.search(r"^Possible values: (.*)$", body, flags=re.M)
            if inline:
                entry["choices"] = [[c.strip(), ""] for c in inline.group(1).split(",")]
            else:
                entry["choices"] = [
                    [c.group(1), html.unescape(c.group(2) or "").strip()]
                    for c in re.finditer(r"^ - (\S+?)(?::\s*(.*))?$", body, flags=re.M)
                ]
        for key in ("lower", "upper", "default"):
            if isinstance(entry.get(key), float) and not math.isfinite(entry[key]):
                entry[key] = None  # JSON has no infinity: unbounded
        options.append(entry)
    return options


def _sections(doc: str) -> dict[str, str]:
    """option name -> the section (subsection heading) it is documented under."""
    out, section = {}, ""
    for line in doc.splitlines():
        m = re.match(r"\\subsection OPT_\S+ (.+)$", line)
        if m:
            section = m.group(1).strip()
        m = re.match(r"\\anchor OPT_(\w+)$", line)
        if m:
            out[m.group(1)] = section
    return out


def casadi_options(code: str) -> list[dict]:
    text = _child(code + ".print_options()\n")
    out = []
    for m in re.finditer(r'^> "(\w+)"\s+\[(\w+)\]\s+"(.*)"$', text, flags=re.M):
        out.append({"name": m.group(1), "type": m.group(2), "description": m.group(3)})
    if not out:
        raise SystemExit(f"cannot parse CasADi's options:\n{text[:2000]}")
    return out


def builtin_linear_solvers(ipopt: list[dict]) -> list[str]:
    """The choices of ``linear_solver`` not loaded from a library at run time that solve a tiny problem."""
    choices = next(o["choices"] for o in ipopt if o["name"] == "linear_solver")
    works = []
    for value, what in choices:
        if "library" in what or value == "custom":
            continue
        text = _child(
            f"s = ca.nlpsol('s', 'ipopt', {{'x': y, 'f': (y - 1)**2}}, {{'print_time': False, 'ipopt.sb': 'yes',"
            f" 'ipopt.print_level': 0, 'ipopt.linear_solver': '{value}'}})\n"
            "s(x0=3)\nprint('STATUS', s.stats()['return_status'])\n"
        )
        if "STATUS Solve_Succeeded" in text:
            works.append(value)
    return works


def main() -> None:
    doc = ipopt_documentation()
    version = re.search(r"This is Ipopt version (\S+?),", doc)
    ipopt = parse_ipopt(doc)
    table = {
        "generated_by": "tools/gen_solver_options.py",
        "casadi_version": ca.__version__,
        "ipopt_version": version.group(1) if version else None,
        "ipopt_builtin_linear_solvers": builtin_linear_solvers(ipopt),
        "ipopt": ipopt,
        "casadi_nlpsol_ipopt": casadi_options("ca.nlpsol('s', 'ipopt', {'x': y, 'f': y**2}, {'print_time': False})"),
        "casadi_rootfinder_newton": casadi_options("ca.rootfinder('r', 'newton', ca.Function('g', [y], [y]))"),
    }
    OUT.write_text(json.dumps(table, indent=1, allow_nan=False) + "\n")
    print(
        f"wrote {OUT}: {len(ipopt)} IPOPT options, {len(table['casadi_nlpsol_ipopt'])} nlpsol options, "
        f"{len(table['casadi_rootfinder_newton'])} rootfinder options"
    )


if __name__ == "__main__":
    main()

"""Fit the constants of the default circular notch formula to the 3-D finite-element reference.

    python benchmarks/fit_notch_3d.py [--reference tests/data/notch_fem_reference.json]
                                      [--json benchmarks/fit_notch_3d.json]

`cpm_nlp.analysis.flexure_compliance.circular_notch_compliances_3d` multiplies each beam
compliance (rotation ``rz``, other bending ``ry``, axial ``x``; torsion ``rx`` after adding the
restrained warping) by (1 - ν² (w/t)/(w/t + s0)) (1 + a (t/r)^p).  This script fits (s0, a, p) per
compliance by least squares on log(c_formula / c_3D) over the grid of the reference (rotation and
axial: the notch between elastic blocks; other bending and torsion: its end faces clamped and tied
to the rigid body, see ``FROM_BLOCKS``; R = 1 mm,
t/R 0.05-0.5, w/t 10-100; benchmarks/bench_notch_fem.py regenerates it), prints the constants to
paste into ``NOTCH_3D_FIT`` and the residual of every stored point (grid, the w = 5 mm
cross-check points, the 3-PRS hinge), for the fitted constants and for the constants in the code,
and writes them to the JSON.  Derived here; nothing in it is a published number.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from cpm_nlp.analysis import flexure_compliance as fc  # noqa: E402

#: compliance key -> the reference's stiffness key
QUANTITIES = {"rz": "bend", "ry": "bend2", "x": "axial", "rx": "torsion"}


#: the quantities taken from the notch between elastic blocks (their beam compliances subtracted);
#: the other bending and the torsion come from the notch's end faces as clamp and rigid body, since
#: the blocks' own (deep, short, warping-restrained) compliances in those cannot be subtracted
#: reliably (the Saint-Venant estimate exceeds the whole body's torsional compliance for wide notches)
FROM_BLOCKS = ("bend", "axial")


def points(reference: dict) -> list[tuple[str, dict]]:
    """(label, point) of every stored 3-D point, its ``fem`` merged: rotation and axial from the
    notch with blocks, the other bending and torsion from the end-faces model of the same notch."""
    faces = {(round(p["t"], 9), round(p["w"], 9)): p for p in reference.get("end_faces_grid", [])}

    def merged(blocks, end_faces):
        fem = {k: v for k, v in blocks["fem"].items() if k not in ("bend2", "torsion")}
        if end_faces is not None:
            fem.update({k: end_faces["fem"][k] for k in ("bend2", "torsion")})
        return {**blocks, "fem": fem}

    out = [("grid", merged(p, faces.get((round(p["t"], 9), round(p["w"], 9))))) for p in reference.get("grid", [])]
    for entry in reference.get("cross_check", {}).get("points", []):
        if "blocks" in entry:
            out.append(("cross_check", merged(entry["blocks"], entry.get("end_faces"))))
    if "prs3_hinge" in reference:
        out.append(("prs3_hinge", merged(reference["prs3_hinge"], None)))
    return out


def deviations(reference: dict, fit=None, formula=None) -> list[dict]:
    """k_formula / k_3D - 1 per point and quantity (formula: circular_notch_compliances_3d with
    ``fit``, or another function of (E, G, b, t, r))."""
    E, nu = reference["material"]["E"], reference["material"]["nu"]
    G = E / (2.0 * (1.0 + nu))
    rows = []
    for label, p in points(reference):
        if formula is None:
            c = fc.circular_notch_compliances_3d(E, G, p["w"], p["t"], p["R"], fit=fit)
        else:
            c = formula(E, G, p["w"], p["t"], p["R"])
        row = {"set": label, "t_over_R": p["t"] / p["R"], "w_over_t": p["w"] / p["t"]}
        for key, name in QUANTITIES.items():
            if name not in p["fem"]:
                continue
            k3d = p["fem"][name]["extrapolated"]
            row[name] = float(1.0 / c[key] / k3d - 1.0)
            row[name + "_fem_error"] = p["fem"][name]["relative_error"]
        rows.append(row)
    return rows


def fit_constants(reference: dict) -> dict:
    fit = {k: tuple(v) for k, v in fc.NOTCH_3D_FIT.items()}
    grid = {k: reference[k] for k in ("grid", "end_faces_grid", "material")}
    for key, name in QUANTITIES.items():

        def residual(theta, key=key, name=name):
            trial = dict(fit)
            trial[key] = (float(np.exp(theta[0])), *(float(v) for v in theta[1:]))
            return np.log1p([row[name] for row in deviations(grid, trial) if name in row])

        lower, upper = [np.log(1e-2), -0.5, 0.05], [np.log(1e4), 5.0, 4.0]  # 1 + a (t/R)^p > 0 on the grid
        start = [np.log(5.0), 0.1, 1.0]
        sol = least_squares(residual, np.array(start), bounds=(lower, upper))
        fit[key] = (float(np.exp(sol.x[0])), *(float(v) for v in sol.x[1:]))
    return fit


def _table(rows):
    for r in rows:
        print(
            f"  {r['set']:11s} t/R {r['t_over_R']:.3f} w/t {r['w_over_t']:6.1f}  "
            + "  ".join(f"{n} {100 * r[n]:+6.2f} %" for n in QUANTITIES.values() if n in r)
        )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default=str(ROOT / "tests" / "data" / "notch_fem_reference.json"))
    parser.add_argument("--json", default=str(ROOT / "benchmarks" / "fit_notch_3d.json"))
    parser.add_argument("--markdown", action="store_true", help="also print the table of the flexure reference")
    args = parser.parse_args(argv)
    reference = json.loads(Path(args.reference).read_text())
    fitted = fit_constants(reference)
    print("NOTCH_3D_FIT = {")
    for key, values in fitted.items():
        print(f'    "{key}": (' + ", ".join(f"{v:.4g}" for v in values) + "),")
    print("}")
    out = {"fitted": fitted, "in_code": {k: list(v) for k, v in fc.NOTCH_3D_FIT.items()}}
    for name, kwargs in (
        ("paros_weisbord", {"formula": fc.circular_notch_compliances}),
        ("fitted", {"fit": fitted}),
        ("in_code", {}),
    ):
        rows = deviations(reference, **kwargs)
        out[name + "_deviation"] = rows
        grid = [r for r in rows if r["set"] == "grid"]
        worst = {n: max(abs(r[n]) for r in grid if n in r) for n in QUANTITIES.values()}
        out[name + "_worst_on_grid"] = worst
        print(
            f"{name}: k_formula / k_3D - 1 (worst on the grid: "
            + ", ".join(f"{n} {100 * v:.2f} %" for n, v in worst.items())
            + ")"
        )
        _table(rows)
    Path(args.json).write_text(json.dumps(out, indent=1) + "\n")
    if args.markdown:
        print(markdown(out))
        print(stress_markdown(reference))
    return 0


def markdown(out: dict) -> str:
    """The table of docs/site/reference/flexures.md: per point, the 3-D stiffnesses' Richardson error
    and k_formula / k_3D - 1 of the papers' formula (PW) and the default (new), in percent."""
    head = (
        "| set | t/R | w/t | rotation PW | rotation new | axial PW | axial new | bend2 PW | bend2 new "
        "| torsion PW | torsion new | 3-D error (max) |\n" + "| --- " * 12 + "|"
    )
    lines = [head]
    pw, new = out["paros_weisbord_deviation"], out["in_code_deviation"]
    for a, b in zip(pw, new):
        err = max(a[n + "_fem_error"] for n in QUANTITIES.values() if n in a)
        cells = [a["set"].replace("_", " "), f"{a['t_over_R']:.3g}", f"{a['w_over_t']:.3g}"]
        for n in ("bend", "axial", "bend2", "torsion"):
            cells += [f"{100 * a[n]:+.1f} %", f"{100 * b[n]:+.1f} %"] if n in a else ["", ""]
        cells.append(f"{100 * err:.2f} %")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def stress_markdown(reference: dict) -> str:
    """The root stresses under a moment about the compliant axis, as ratios to the nominal
    6M/(w t²): 3-D σ_xx and von Mises at mid-width, σ_xx at the free edge, beside Roark's K_t
    (`cpm_nlp.analysis.hinge_types.circular_notch_kt`, the default peak-stress factor)."""
    from cpm_nlp.analysis.hinge_types import circular_notch_kt

    lines = [
        "| set | t/R | w/t | σ_xx mid-width | von Mises mid-width | σ_xx edge | Roark K_t |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for label, p in points(reference):
        f = p["fem"]
        if "sxx_mid" not in f:
            continue
        cells = [label.replace("_", " "), f"{p['t'] / p['R']:.3g}", f"{p['w'] / p['t']:.3g}"]
        cells += [f"{f[k]['extrapolated']:.3f}" for k in ("sxx_mid", "vm_mid", "sxx_edge")]
        cells.append(f"{circular_notch_kt(p['t'], p['R']):.3f}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())

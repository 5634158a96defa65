"""The documentation's figures, drawn by the ``cpm-nlp`` command line from the shipped problem files.

Run from the repository (it writes under ``docs/site/assets/``)::

    python docs/figures.py                     # every figure
    python docs/figures.py --mechanisms        # only the mechanism sketches (after a drawing change)
    python docs/figures.py overview/dynamics   # some figures, by name

Every figure is the command ``cpm-nlp solve FILE --plot PNG`` (or ``sweep``) on a problem
file that ships with the package, so a user who runs the same command gets the same picture;
the rotation figure is the one drawn here, from the rotation matrix of the 3-PRS model.
``tests/test_docs.py`` checks that this list and the images on disk agree, that every
registered mechanism has its sketch, and that the pages show only images listed here.
``docs/hooks.py`` reads :func:`problem_files_by_mechanism` to list each mechanism's problem files.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
ASSETS = ROOT / "docs" / "site" / "assets"
PROBLEMS = ROOT / "problems"
#: the folders whose every image is one of the figures below
GENERATED_DIRS = ("overview", "mechanisms")


@dataclass(frozen=True)
class Figure:
    """One image: its name (its path under assets/, without .png), the command line drawing it and what it shows."""

    name: str
    argv: tuple[str, ...]  # cpm-nlp's arguments; PNG stands for the image's path
    caption: str
    #: the exit statuses that still draw the figure (a sweep with infeasible points exits 1)
    exits: tuple[int, ...] = (0,)

    @property
    def path(self) -> Path:
        return ASSETS / f"{self.name}.png"


def _solve(problem: str, *extra: str) -> tuple[str, ...]:
    return ("solve", f"problems/{problem}.yaml", "-q", "--plot", "PNG", *extra)


#: the overview page's pictures, one per capability, and the home page's
FIGURES: tuple[Figure, ...] = (
    Figure("pantograph_cuboid", _solve("pantograph_cuboid"), "the pantograph's largest cuboid inside its workspace"),
    Figure("overview/kinematics", _solve("prs3_forward_kinematics"), "forward kinematics of the 3-PRS stage"),
    Figure("overview/jacobian", _solve("prs3_jacobian"), "the 3-PRS Jacobian: conditioning over a workspace slice"),
    Figure("overview/workspace", _solve("five_bar_inscribed_cuboid"), "the five-bar's workspace and largest rectangle"),
    Figure(
        "overview/synthesis",
        _solve("five_bar_synthesis", "--type", "design"),
        "a synthesised five-bar drawn over the file's design",
    ),
    Figure("overview/compliance", _solve("rrr3_platform_compliance"), "the 3-RRR's compliance ellipsoid"),
    Figure("overview/forces", _solve("prs3_fem_table2"), "3-PRS actuator forces and stresses"),
    Figure("overview/dynamics", _solve("prs3_natural_frequencies"), "the 3-PRS stage's natural frequencies and modes"),
    Figure(
        "overview/sweep",
        ("sweep", "problems/sweep_rpr_transmission.yaml", "-q", "--workers", "1", "--overwrite", "-o", "RESULTS")
        + ("--plot", "PNG", "--best", "max"),
        "the RPR's transmission index over a sampled design plane",
        exits=(0, 1),  # 1033 of its 1500 points lie outside the design triangle: infeasible, exit 1
    ),
)

#: the rotation page's figure, drawn here (not a command line)
ROTATION = Figure("rotation", (), "R = Ry(theta) Rx(psi) Rz(phi) of the 3-PRS, one factor at a time")


def mechanism_of(problem: Path) -> str | None:
    """The mechanism a problem file names: its type, or the name inside its mechanism file."""
    data = yaml.safe_load(problem.read_text(encoding="utf-8"))
    mech = data.get("mechanism") if isinstance(data, dict) else None
    if isinstance(mech, str):
        return mech
    if not isinstance(mech, dict):
        return None
    if "file" in mech:
        described = yaml.safe_load((problem.parent / mech["file"]).read_text(encoding="utf-8"))
        return described.get("name")
    return mech.get("type")


def problem_files_by_mechanism() -> dict[str, list[str]]:
    """mechanism name -> the shipped problem files (names under problems/) that use it."""
    out: dict[str, list[str]] = {}
    for path in sorted(PROBLEMS.glob("*.yaml")):
        name = mechanism_of(path)
        if name:
            out.setdefault(name, []).append(path.name)
    return out


def sketch_problem(mechanism: str, by_mechanism: dict[str, list[str]] | None = None) -> str:
    """The problem file a mechanism's sketch is drawn from: its forward kinematics (a pose near home)."""
    files = (problem_files_by_mechanism() if by_mechanism is None else by_mechanism).get(mechanism, [])
    preferred = f"{mechanism}_forward_kinematics.yaml"
    fk = [f for f in files if f.endswith("forward_kinematics.yaml")]
    if preferred in files:
        return preferred
    if fk:
        return fk[0]
    raise LookupError(f"no shipped forward-kinematics problem file of {mechanism!r} to draw its sketch from")


def sketches() -> tuple[Figure, ...]:
    """One sketch per registered mechanism, drawn at the pose of its forward-kinematics problem file."""
    from cpm_nlp.mechanisms.registry import mechanism_names

    files = problem_files_by_mechanism()
    return tuple(
        Figure(
            f"mechanisms/{name}",
            _solve(Path(sketch_problem(name, files)).stem, "--type", "mechanism"),
            f"{name}, drawn from problems/{sketch_problem(name, files)}",
        )
        for name in mechanism_names()
    )


def all_figures() -> tuple[Figure, ...]:
    return FIGURES + (ROTATION,) + sketches()


def draw_rotation(path: Path) -> None:
    """The three elementary rotations of R = Ry(theta) Rx(psi) Rz(phi) (the 3-PRS, eq 4 of
    Ruiz et al.), each applied to the platform frame in turn; R is the model's own (its
    ``frame`` Function), so the picture is the code's convention."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np
    from matplotlib.figure import Figure as MplFigure

    import cpm_nlp as cn

    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"})
    names = [c.name for c in model.closure.x]
    angles = {"psi": np.radians(25.0), "theta": np.radians(20.0), "phi": np.radians(30.0)}

    def frame(**given: float) -> np.ndarray:
        x = np.zeros(len(names))
        for k, v in given.items():
            x[names.index(k)] = v
        return np.array(model.closure.frame(x, model.p)[0])

    steps = [
        ("1. Rz(φ)\nφ = 30° about z", frame(phi=angles["phi"])),
        ("2. Rx(ψ) Rz(φ)\nthen ψ = 25° about the base x", frame(phi=angles["phi"], psi=angles["psi"])),
        ("3. R = Ry(θ) Rx(ψ) Rz(φ)\nthen θ = 20° about the base y", frame(**angles)),
    ]
    fig = MplFigure(figsize=(12, 4.6))
    colours = ("tab:red", "tab:green", "tab:blue")
    for k, (title, R) in enumerate(steps):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        for i, (c, label) in enumerate(zip(colours, "xyz")):
            e = np.eye(3)[:, i]
            ax.plot(*zip((0, 0, 0), e), color="0.6", lw=1.0, ls="--")
            ax.text(*(1.12 * e), label, color="0.4", fontsize=10)
            u = R[:, i]
            ax.quiver(0, 0, 0, *u, color=c, lw=2.2, arrow_length_ratio=0.12)
            ax.text(*(1.15 * u), "uvw"[i], color=c, fontsize=12, fontweight="bold")
        ax.set(xlim=(-0.8, 0.8), ylim=(-0.8, 0.8), zlim=(-0.3, 1.2), xticks=[], yticks=[], zticks=[])
        ax.set_box_aspect((1, 1, 1), zoom=1.1)
        ax.view_init(elev=18, azim=-35)
        ax.set_axis_off()
        ax.set_title(title, fontsize=10)
    fig.suptitle(
        "The platform frame u, v, w (the columns of R) against the base x, y, z (dashed), 3-PRS",
        fontsize=11,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight", metadata={"Software": None})


def draw(figure: Figure, workdir: Path) -> None:
    """Draw one figure with the command line (the rotation figure here)."""
    figure.path.parent.mkdir(parents=True, exist_ok=True)
    if figure is ROTATION or not figure.argv:
        draw_rotation(figure.path)
        return
    argv = [
        str(figure.path) if a == "PNG" else str(workdir / "results.csv") if a == "RESULTS" else a for a in figure.argv
    ]
    run = subprocess.run([sys.executable, "-m", "cpm_nlp", *argv], cwd=ROOT, check=False)
    if run.returncode not in figure.exits or not figure.path.is_file():
        raise SystemExit(f"{figure.name}: cpm-nlp {' '.join(argv)} exited {run.returncode}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="figures to draw (default: all), e.g. overview/dynamics")
    parser.add_argument("--mechanisms", action="store_true", help="only the mechanism sketches")
    args = parser.parse_args(argv)
    figures = sketches() if args.mechanisms else all_figures()
    if args.names:
        known = {f.name: f for f in all_figures()}
        unknown = [n for n in args.names if n not in known]
        if unknown:
            parser.error(f"unknown figures {unknown}; known: {', '.join(known)}")
        figures = tuple(known[n] for n in args.names)
    with tempfile.TemporaryDirectory() as tmp:
        for figure in figures:
            print(f"{figure.path.relative_to(ROOT)}: cpm-nlp {' '.join(figure.argv) or '(drawn here)'}")
            draw(figure, Path(tmp))
    return 0


if __name__ == "__main__":
    sys.exit(main())

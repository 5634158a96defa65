"""A URDF mechanism, with the loop closures of an "Extended URDF" sidecar, as a mechanism file.

The formats read (learnt from their public descriptions, no code taken from them):

* **URDF** (ROS): a ``<robot>`` of ``<link name>`` and ``<joint name type>`` elements; a joint
  has a ``<parent link>``, a ``<child link>``, an ``<origin xyz rpy>`` (the child link's frame
  in the parent link's frame at joint value 0; rpy are fixed-axis roll, pitch, yaw:
  R = Rz(yaw) Ry(pitch) Rx(roll)) and an ``<axis xyz>`` in that frame (default 1 0 0).  Types
  read: ``revolute`` and ``continuous`` (R), ``prismatic`` (P), ``fixed`` (the two links are one
  body).  The links form a tree.
* **The Extended URDF sidecar** (``robot.yaml``; V. Batto, L. de Matteis, N. Mansard,
  "Extended URDF: accounting for parallel mechanism in robot description", arXiv:2504.04767,
  and its examples github.com/Gepetto/example-parallel-robots, robots/*/robot.yaml):
  ``closed_loop: [[frame_A, frame_B], ...]`` the loop closures, each between two frames (a
  joint or link name: the frame of that joint's child link, or of that link);
  ``type: ['6d' | '3d', ...]`` for each closure (6d: the two frames coincide -- the two bodies
  are welded; 3d: their origins coincide -- a spherical joint); ``name_mot: [joint, ...]`` the
  actuated joints; ``joint_name`` / ``joint_type``: joints read as another type
  (``SPHERICAL``, ``FIXED``, ``UJOINT_XY`` ... -- a universal joint about the joint frame's
  X then Y axis).

What is written: a mechanism file of bodies and joints (``bodies:``, ``joints:``; see
docs/site/guide/mechanism-files.md) whose drawing is the URDF's zero configuration in world
coordinates (the root link's frame), lengths in metres.  Every non-fixed URDF joint is a joint
between the bodies of its parent and child links, at the origin of its frame, its axis a world
direction; each 3d closure is an S joint, each 6d closure merges the two bodies.  A body that
only links two joints turning about one axis or point (the dummy links at which example files
close their loops, or between revolutes crossing at one point: a U, an S) is removed and its
two joints become one; a passive joint to a body that
carries nothing else (a free spin) is dropped; a rod between two S joints is a distance joint
(or, where the mechanism hangs on it, keeps its body with a U instead of one S).  An actuated
joint's actuator is named after it, its own coordinate ``<name>_joint``.  All R axes parallel
(and P axes normal to them): a planar file, in the plane normal to the axes.

The URDF is data: it is parsed with `xml.etree.ElementTree` after refusing any document
type declaration or entity (``<!DOCTYPE``, ``<!ENTITY``), nothing it names (meshes, xacro
includes, ``package://`` paths) is ever opened, and its size and element count are capped.
Errors are [`InputError`][cpm_nlp.core.errors.InputError] naming the file and the element
(``joint[mot1].origin.rpy``) or the sidecar's key path (``closed_loop[0][1]``).

The steps live in `cpm_nlp.io.urdf`: reading the URDF (``read``) and the sidecar
(``sidecar``), the drawing with the loops closed (``assembly``), the bodies and joints
(``graph``) made smaller (``simplify``), and the file written (``write``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InputError
from .inputs import MAX_INPUT_BYTES, display_name, read_input_text
from .urdf.graph import Graph, build_graph
from .urdf.read import link_tree, parse_urdf, read_urdf
from .urdf.sidecar import Sidecar, read_sidecar
from .urdf.simplify import simplify
from .urdf.write import (
    NAME,
    Layout,
    body_lines,
    check_task,
    drawing_points,
    joint_entry,
    mechanism_name,
    plane_basis,
    platform_frame,
    platform_lines,
    title_text,
    vec,
)

log = logging.getLogger(__name__)


@dataclass
class Imported:
    """A URDF imported as a mechanism file: its text (YAML), what it holds, and the notes
    (what was merged, simplified, renamed) that its header also carries."""

    text: str
    planar: bool
    bodies: dict[str, dict[str, list[float]]]
    joints: list[dict[str, Any]]
    notes: list[str]


def import_urdf(
    path: str,
    sidecar: str | None = None,
    *,
    actuated: list[str] | None = None,
    name: str | None = None,
    platform: str | None = None,
    task: list[str] | None = None,
    planar: bool | None = None,
) -> Imported:
    """The mechanism file (bodies and joints) of the URDF ``path`` and its Extended URDF
    ``sidecar`` (closures, actuated joints, joint types).

    ``actuated``: the actuated joints (URDF names), instead of the sidecar's ``name_mot``.
    ``platform``: the frame (a link or joint name) whose body is the platform and whose origin
    is its point (default: a link named platform, effector or end_effector).  ``task``: the
    task coordinates, the platform's or passive joints' (default: by the number of actuators --
    planar 1: phi, 2: x, y, 3: x, y, phi; spatial 3: x, y, z, 6: all six).  ``planar``: None --
    a planar file when every R axis is one direction; False -- always spatial; True -- planar or
    an error.
    """
    file = display_name(path)
    text = read_input_text(path, limit=MAX_INPUT_BYTES)
    robot, links, joints = read_urdf(parse_urdf(text, file), file)
    root, order, _parents = link_tree(links, joints, file)
    side = read_sidecar(sidecar) if sidecar is not None else Sidecar()
    side_name = display_name(sidecar) if sidecar is not None else None
    graph, pbody, ppoint, pframe, assembled = build_graph(
        links, joints, root, order, side, actuated, platform, file, side_name or file
    )
    simplify(graph, root, keep={root, pbody})
    n_act = sum(g.actuated for g in graph.joints)
    if n_act == 0:
        raise InputError(
            "no actuated joint: the sidecar names none (name_mot)",
            file=side_name or file,
            path=("name_mot",),
            hint="name them in the sidecar's name_mot or with --actuated J1,J2",
        )
    layout = Layout(_basis(graph, planar, file), graph.scale)
    glob, bodies = drawing_points(graph, layout)
    flipped: list[str] = []
    entries = [joint_entry(g, graph, layout, flipped) for g in graph.joints]
    out_joints = [entry for entry, _line in entries]
    frame = platform_frame(layout.basis is not None, n_act)
    task = check_task(task, frame, out_joints, n_act)
    if name is not None and not NAME.fullmatch(name):
        raise InputError(
            f"expected a mechanism name of at most 64 ASCII letters, digits and single underscores, "
            f"starting with a letter, got {name!r:.80}",
            path=("--name",),
        )
    mech_name = name or mechanism_name(robot or Path(path).stem)
    notes = _notes(graph, flipped)
    lines = _header(mech_name, file, side_name, assembled, layout.basis, notes) + [
        f"name: {mech_name}",
        f"title: {title_text(robot or Path(file).stem)} imported from {title_text(Path(file).name)}",
    ]
    lines += body_lines(glob, bodies, layout.scale)
    lines += ["joints:", *(line for _entry, line in entries)]
    lines += platform_lines(frame, layout, graph.names[pbody], ppoint, layout.coords(pframe[:3, 3]), task)
    log.info("imported %s: %d bodies, %d joints", file, len(bodies), len(out_joints))
    return Imported(
        "\n".join(lines) + "\n",
        layout.basis is not None,
        {b: {p: (None if v is None else list(v)) for p, v in own.items()} for b, own in bodies.items()},
        out_joints,
        notes,
    )


def _basis(graph: Graph, planar: bool | None, file: str) -> np.ndarray | None:
    """The plane the file is written in (`plane_basis`), None for a
    spatial file; ``planar`` True where the mechanism is not planar is an error."""
    basis = plane_basis(graph)
    if planar is True and basis is None:
        raise InputError(
            "the mechanism is not planar: its R axes are not all one direction (or a P axis is not normal to them)",
            file=file,
            path=("robot",),
        )
    return None if planar is False else basis


def _notes(graph: Graph, flipped: list[str]) -> list[str]:
    """What the conversion merged, simplified, flipped and renamed."""
    notes = list(graph.notes)
    if flipped:
        notes.append("the URDF axis of " + ", ".join(flipped) + " is -n: the angle here (about n) is minus the URDF's")
    if graph.renamed:
        notes.append("renamed: " + ", ".join(f"{k!r} -> {v}" for k, v in graph.renamed.items()))
    return notes


def _header(
    mech_name: str, file: str, side_name: str | None, assembled: bool, basis: np.ndarray | None, notes: list[str]
) -> list[str]:
    """The file's comment lines: where it comes from, its drawing, its plane, the notes."""
    header = [
        f"# {mech_name}: imported by cpm-nlp import from {Path(file).name} (URDF)"
        + (f" and {Path(side_name).name} (Extended URDF sidecar)" if side_name else "")
        + ".",
        "# The drawing is the URDF's "
        + ("configuration with the loops closed" if assembled else "zero configuration")
        + " in the root link's frame, lengths in metres (SI);",
        "# the reference pose is assembled from it with the actuators at 0 (their URDF zero).",
    ]
    if basis is not None:
        e1, e2, n = basis
        header.append(
            f"# Planar: every R axis is n = {vec(n, 1.0)}; the plane's x, y are the URDF's "
            f"{vec(e1, 1.0)}, {vec(e2, 1.0)}."
        )
    return header + [f"# - {n}" for n in notes]

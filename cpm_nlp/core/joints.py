"""The joint types of mechanism files: one table, read by the file reader
(`cpm_nlp.mechanisms.described.read_joint`), the generator of loop closures
(`generate`), the legs' serial chains
(`cpm_nlp.core.chains`) and the ``describe`` text.

A joint's degrees of freedom are its elementary motions, in the order of its
coordinates: a rotation ("R") about, or a translation ("P") along, one of its
axes, composed as a product of exponentials about its reference axes (a
joint's variable is its displacement from the reference configuration).  The
axis of each motion comes from the joint's ``axis`` key (``"axis"``) or from
entry k of its ``axes`` list (``k``; an S without ``axes`` turns about the base
frame's x, y, z).

The flexure hinges that can sit at a joint are given by name (the hinge types
of `cpm_nlp.analysis.hinge_types.HINGE_TABLE`, which reads this table for
where each may sit): where the project's mechanisms put them, and by a hinge's
geometry where none does.

* As a revolute: a circular notch (prs3-ruiz.md section 5; the pantograph,
  pantograph-3d-elgammal-2016.md eq 38; the five-bar's and 3-RRR's elbows in
  problems/), a corner-filleted (cantilever) notch (pantograph eq 30-31), a
  leaf spring (offered for the pantograph's joints as a rotation limit; it bends
  about one axis).
* As a U: a circular notch on each axis (rpr-2rpu-upr-zhang-2022.md Table 1 as
  problems/mechanisms/rpr.yaml reads it); a round neck (circular or filleted rod), which bends
  about two axes (geometry: no shipped mechanism has one there).
* As an S: a filleted rod (prs3-ruiz.md section 5), a circular rod (the same
  neck without fillets: geometry).
* No hinge of the library is a prismatic or a cylindrical joint, nor a distance.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from .errors import InputError, suggest


@dataclass(frozen=True)
class JointType:
    """One joint type of a mechanism file.

    Attributes
    ----------
    name
        its ``type`` in a file;
    description
        one line.
    letter
        the letter a drawing marks it with (P, R, C, U, S).
    motion
        its elementary motions in coordinate order, ("R" | "P", axis source): "axis" (the
        joint's ``axis``) or k (entry k of its ``axes``).
    axis
        "given" (the file gives ``axis``), "z" (fixed: a planar revolute) or None (it has no
        single axis).
    n_axes
        how many vectors its ``axes`` key holds (0: it takes none);
    default_axes
        the base-frame axes used when ``axes`` is not given (empty: ``axes`` is required if
        ``n_axes``).
    planar, spatial
        whether a planar, a spatial mechanism takes it.
    actuable
        whether an actuator may drive it.
    point
        a point joint (all rotations about its location: S in space, R in the plane), through
        which a leg reaches its platform point.
    sphere
        it turns about a point, so the link after it sweeps a sphere (a circle in the plane): U,
        S, planar R.
    twin
        the same joint in the other kind of mechanism (R <-> planar_R).
    in_plane
        the type a planar mechanism file gives it (a planar type is its own; R and S turn
        about z in the plane, planar_R; P slides in it, planar_P; None: no planar form).
    hinges
        names of the flexure hinge types that can sit at it (see the module).
    """

    name: str
    description: str
    letter: str
    motion: tuple[tuple[str, str | int], ...]
    axis: str | None = None
    n_axes: int = 0
    default_axes: tuple[str, ...] = ()
    planar: bool = False
    spatial: bool = True
    actuable: bool = False
    point: bool = False
    sphere: bool = False
    twin: str | None = None
    in_plane: str | None = None
    hinges: tuple[str, ...] = ()

    @property
    def dof(self) -> int:
        """Degrees of freedom: the number of its coordinates (a distance joint has none)."""
        return len(self.motion)

    @property
    def dims(self) -> tuple[str, ...]:
        """The dimension of each coordinate: an angle for a rotation, a length for a slide."""
        return tuple("angle" if kind == "R" else "length" for kind, _source in self.motion)


#: hinge types that realise a revolute (see the module's docstring for the sources)
_REVOLUTE_HINGES = ("circular_notch", "circular_notch_paros_weisbord", "cantilever_notch", "leaf_spring")

#: the joint types, in the order the reader lists them
JOINT_TYPES: Mapping[str, JointType] = MappingProxyType(
    {
        t.name: t
        for t in (
            JointType(
                "P",
                "prismatic (spatial)",
                "P",
                (("P", "axis"),),
                axis="given",
                actuable=True,
                twin="planar_P",
                in_plane="planar_P",
            ),
            JointType(
                "R",
                "revolute (spatial)",
                "R",
                (("R", "axis"),),
                axis="given",
                actuable=True,
                twin="planar_R",
                in_plane="planar_R",
                hinges=_REVOLUTE_HINGES,
            ),
            JointType(
                "C",
                "cylindrical: a revolute and a prismatic on one axis",
                "C",
                (("R", "axis"), ("P", "axis")),
                axis="given",
            ),
            JointType(
                "U",
                "universal: two revolutes, axes[0] on the proximal body, axes[1] on the distal one",
                "U",
                (("R", 0), ("R", 1)),
                n_axes=2,
                sphere=True,
                hinges=("circular_notch", "circular_notch_paros_weisbord", "circular_rod", "filleted_rod"),
            ),
            JointType(
                "S",
                "spherical",
                "S",
                (("R", 0), ("R", 1), ("R", 2)),
                n_axes=3,
                default_axes=("x", "y", "z"),
                point=True,
                sphere=True,
                in_plane="planar_R",
                hinges=("circular_rod", "filleted_rod"),
            ),
            JointType(
                "planar_R",
                "revolute of a planar mechanism (axis z)",
                "R",
                (("R", "axis"),),
                axis="z",
                planar=True,
                spatial=False,
                actuable=True,
                point=True,
                sphere=True,
                twin="R",
                in_plane="planar_R",
                hinges=_REVOLUTE_HINGES,
            ),
            JointType(
                "planar_P",
                "prismatic of a planar mechanism (axis in the plane)",
                "P",
                (("P", "axis"),),
                axis="given",
                planar=True,
                spatial=False,
                actuable=True,
                twin="P",
                in_plane="planar_P",
            ),
            JointType(
                "distance",
                "rigid distance between two points (an S-S strut or a parallelogram's link)",
                "S",
                (),
                planar=True,
                in_plane="distance",
            ),
        )
    }
)

#: the letters a drawing marks joints with
JOINT_LETTERS = tuple(dict.fromkeys(t.letter for t in JOINT_TYPES.values()))

#: what each letter is called in a drawing's legend
LETTER_NAMES: Mapping[str, str] = MappingProxyType(
    {"P": "prismatic", "R": "revolute", "C": "cylindrical", "U": "universal", "S": "spherical"}
)


def joint_type(name: object, path: tuple = ()) -> JointType:
    """The joint type called ``name``, or an [`InputError`][cpm_nlp.core.errors.InputError] at ``path`` naming the
    types and the nearest ones."""
    if isinstance(name, str) and name in JOINT_TYPES:
        return JOINT_TYPES[name]
    raise InputError(
        f"unknown joint type {name!r}; expected one of: {', '.join(JOINT_TYPES)}",
        path=path,
        suggestions=suggest(str(name), JOINT_TYPES),
    )


def joint_types(planar: bool) -> tuple[str, ...]:
    """The joint types a planar (True) or a spatial (False) mechanism takes, in table order."""
    return tuple(n for n, t in JOINT_TYPES.items() if (t.planar if planar else t.spatial))


__all__ = (
    "JOINT_LETTERS",
    "JOINT_TYPES",
    "JointType",
    "joint_type",
    "joint_types",
)

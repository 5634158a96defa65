"""Dietmaier's 6-6 Stewart-Gough platform with 40 real assembly modes: the source's numbers
and an independent numpy check of a pose (the leg lengths), for tests/analysis/test_dietmaier_modes.py
and benchmarks/bench_assembly_modes.py.

Source: P. Dietmaier, "The Stewart-Gough platform of general geometry can have 40 real
postures", Advances in Robot Kinematics: Analysis and Control, Kluwer, 1998, pp. 7-16.  The
numbers are those of the public reproduction github.com/martyushev/fkSGP, julia/test_fkSGP.jl
and python/test_fkSGP.py (commit 17bba6212845ac35776f54d6d30b6f2ad02b279b, block "40 real
roots by P. Dietmaier"), equal digit for digit to a second copy in a Drake-based C++ example
of global inverse kinematics (see tests/corpus/dietmaier_6_6.yaml); the paper itself was not
available here.
"""

from pathlib import Path

import numpy as np

from tests.gallery_reference import rot_x, rot_y, rot_z

MECHANISM = Path(__file__).resolve().parent / "corpus" / "dietmaier_6_6.yaml"
PROBLEM = Path(__file__).resolve().parent / "corpus" / "problems" / "dietmaier_6_6_modes.yaml"
#: real assembly modes of the platform for LENGTHS (the paper's title); a general 6-6 platform
#: has at most 40 (complex) ones, so 40 distinct real poses are all there are
MODES = 40

#: base joints A_i (source: martyushev/fkSGP test_fkSGP, X)
A = np.array(
    [
        [0, 0, 0],
        [1.107915, 0, 0],
        [0.549094, 0.756063, 0],
        [0.735077, -0.223935, 0.525991],
        [0.514188, -0.526063, -0.368418],
        [0.590473, 0.094733, -0.205018],
    ]
)
#: platform joints B_i in the platform frame (source: x)
B = np.array(
    [
        [0, 0, 0],
        [0.542805, 0, 0],
        [0.956919, -0.528915, 0],
        [0.665885, -0.353482, 1.402538],
        [0.478359, 1.158742, 0.107672],
        [-0.137087, -0.235121, 0.353913],
    ]
)
#: leg lengths l_i (source: L = [...].^2, the squares of these)
LENGTHS = np.array([1, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071])


def rotation(psi: float, theta: float, phi: float) -> np.ndarray:
    """R = Rz(phi) Ry(theta) Rx(psi), the file's rotation [[z, phi], [y, theta], [x, psi]]."""
    return rot_z(phi) @ rot_y(theta) @ rot_x(psi)


def lengths(pose: np.ndarray) -> np.ndarray:
    R = rotation(*pose[3:])
    return np.linalg.norm(pose[:3] + B @ R.T - A, axis=1)


def model():
    """The mechanism file's model (default parameters)."""
    from cpm_nlp.mechanisms.described import load_file

    mech = load_file(MECHANISM)
    return mech.model(mech.closure(), {}, {}, ())

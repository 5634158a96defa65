"""General 6-6 Stewart-Gough platforms drawn at random (seeded), written as
mechanism files (six U-P-S legs, no symmetry), with their inverse kinematics in
numpy (the leg lengths), for the round trip of the assembly-mode search: a
random pose -> its leg lengths -> the search must find that pose among the
modes (tests/analysis/test_assembly_modes.py, benchmarks/bench_assembly_modes.py)."""

from __future__ import annotations

import math

import numpy as np

from cpm_nlp.mechanisms.described import from_dict

H0 = 0.2  # platform height at the reference configuration, m


def _rot(psi: float, theta: float, phi: float) -> np.ndarray:
    """R = Rz(phi) Ry(theta) Rx(psi), the file's rotation [[z, phi], [y, theta], [x, psi]]."""
    cx, sx, cy, sy, cz, sz = (
        math.cos(psi),
        math.sin(psi),
        math.cos(theta),
        math.sin(theta),
        math.cos(phi),
        math.sin(phi),
    )
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


class Platform66:
    """Base joints A (6 x 3) and platform joints B (6 x 3, platform frame, origin at its centre)."""

    def __init__(self, seed: int) -> None:
        rng = np.random.default_rng(seed)
        ang_a = np.sort(rng.uniform(0, 2 * math.pi, 6))
        ang_b = np.sort(rng.uniform(0, 2 * math.pi, 6))
        ra, rb = rng.uniform(0.12, 0.2, 6), rng.uniform(0.06, 0.12, 6)
        self.A = np.c_[ra * np.cos(ang_a), ra * np.sin(ang_a), rng.uniform(-0.02, 0.02, 6)]
        self.B = np.c_[rb * np.cos(ang_b), rb * np.sin(ang_b), rng.uniform(-0.02, 0.02, 6)]
        self.seed = seed

    def lengths(self, pose: np.ndarray) -> np.ndarray:
        R = _rot(*pose[3:])
        return np.linalg.norm(pose[:3] + self.B @ R.T - self.A, axis=1)

    def pose_matrix(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return _rot(*pose[3:]), np.asarray(pose[:3])

    def random_pose(self, rng: np.random.Generator) -> np.ndarray:
        return np.r_[rng.uniform(-0.04, 0.04, 2), H0 + rng.uniform(-0.04, 0.04), rng.uniform(-0.4, 0.4, 3)]

    def description(self) -> dict:
        legs = []
        for i in range(6):
            a = [float(v) for v in self.A[i]]
            b = [float(self.B[i, 0]), float(self.B[i, 1]), float(self.B[i, 2] + H0)]
            d = np.array(b) - np.array(a)
            u1 = np.cross([0, 0, 1.0], d)
            u1 /= np.linalg.norm(u1)
            u2 = np.cross(d, u1)
            u2 /= np.linalg.norm(u2)
            legs.append(
                {
                    "name": f"leg{i + 1}",
                    "joints": [
                        {"type": "U", "at": a, "axes": [u1.tolist(), u2.tolist()]},
                        {
                            "type": "P",
                            "at": a,
                            "axis": d.tolist(),
                            "actuated": f"l{i + 1}",
                            "home": [float(np.linalg.norm(d))],
                        },
                        {"type": "S", "at": b},
                    ],
                }
            )
        return {
            "name": f"random66_{self.seed}",
            "title": f"random 6-6 Stewart-Gough platform (seed {self.seed})",
            "parameters": {},
            "platform": {
                "coordinates": {
                    n: ("length" if n[0] == "p" and len(n) == 2 else "angle")
                    for n in ("px", "py", "pz", "psi", "theta", "phi")
                },
                "position": ["px", "py", "pz"],
                "rotation": [["z", "phi"], ["y", "theta"], ["x", "psi"]],
                "task": ["px", "py", "pz", "psi", "theta", "phi"],
                "home": {"pz": H0},
            },
            "legs": legs,
        }

    def model(self):
        mech = from_dict(self.description())
        return mech.model(mech.closure(), {}, {}, ())


def contains(found, platform: Platform66, pose: np.ndarray, atol: float = 1e-6) -> bool:
    """Whether the modes found include the pose (rotation matrix and position)."""
    R0, p0 = platform.pose_matrix(pose)
    for md in found.modes:
        R, p = platform.pose_matrix(md.x)
        if np.max(np.abs(R - R0)) < atol and np.max(np.abs(p - p0)) < atol:
            return True
    return False

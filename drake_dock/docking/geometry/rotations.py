"""Rotation matrices of the docking scene: about the x and z axes, and of a rotation vector
(Rodrigues). Used by the scene and by the independent interpenetration check alike."""
import math

import numpy as np


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_vec(r):
    """Rotation matrix of the rotation vector r (Rodrigues)."""
    r = np.asarray(r, dtype=float)
    a = float(np.linalg.norm(r))
    if a == 0.0:
        return np.eye(3)
    k = r / a
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(a) * K + (1.0 - math.cos(a)) * (K @ K)

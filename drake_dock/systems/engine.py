"""The compiled engine at the Drake boundary: the layout records of
`drake_dock.core.kernels.engine` read once from a plant whose bodies all move freely, and the
call that packs one evaluation's modes and unpacks its results.

The plant stays the model: it builds the bodies and the force elements, gives the generalized
force of its force elements (one Drake call per evaluation), and is the reference the tests
compare the kernel's kinematics, mass matrix, Jacobians and bias terms with
(tests/systems/test_engine.py). A plant with any other joint, or a pair the couple kernels do
not describe (point-surface), is evaluated with the plant as calculator
(`drake_dock.systems.evaluation.PlantEvaluator`)."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from pydrake.multibody.tree import BodyIndex

from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import engine as E
from drake_dock.core.kernels.solve import SLIDE, STICK


def free_bodies(plant, frames, ctx) -> E.Bodies | None:
    """The `Bodies` record of ``plant`` (every body but the world on a quaternion floating
    joint, nothing else) and of ``frames``; None when the plant has another joint."""
    bodies = [plant.get_body(BodyIndex(i)) for i in range(1, plant.num_bodies())]
    if not bodies or not all(b.is_floating_base_body() and b.has_quaternion_dofs() for b in bodies):
        return None
    if (plant.num_positions() != 7 * len(bodies) or plant.num_velocities() != 6 * len(bodies)
            or plant.num_joints() != len(bodies)):
        return None
    where = {b.index(): k for k, b in enumerate(bodies)}
    m, c_B, I_B = [], [], []
    for b in bodies:
        M = b.CalcSpatialInertiaInBodyFrame(ctx)
        com = np.asarray(M.get_com())
        m.append(M.get_mass())
        c_B.append(com)
        I_B.append(M.Shift(com).CalcRotationalInertia().CopyToFullMatrix3())
    I_B = np.array(I_B)
    fb, R_BF, p_BF = [], [], []
    for f in frames:
        X = f.GetFixedPoseInBodyFrame()
        fb.append(where.get(f.body().index(), -1))
        R_BF.append(X.rotation().matrix())
        p_BF.append(X.translation())
    return E.Bodies(np.array([b.floating_positions_start() for b in bodies], dtype=np.int64),
                    np.array([b.floating_velocities_start_in_v() for b in bodies],
                             dtype=np.int64),
                    np.array(m, dtype=float), np.array(c_B, dtype=float), I_B,
                    np.linalg.inv(I_B), np.array(fb, dtype=np.int64),
                    np.array(R_BF, dtype=float), np.array(p_BF, dtype=float))


def couple_set(kernel) -> E.CoupleSet:
    """The `CoupleSet` record of a `TrackedCouples`."""
    pc = np.zeros(len(kernel.cc), dtype=np.bool_)
    pc[kernel.pc] = True
    return E.CoupleSet(kernel.cc, pc, kernel.kind1, kernel.prm1, kernel.kind2, kernel.prm2,
                       kernel.fidx, kernel.uoff, kernel.spans)


class Poses(Sequence):
    """The frames' world poses (R, o) of an evaluation, by frame index, over the engine's
    stacked arrays R (F, 3, 3) and o (F, 3)."""

    __slots__ = ("R", "o")

    def __init__(self, R, o):
        self.R, self.o = R, o

    def __len__(self):
        return len(self.R)

    def __getitem__(self, f):
        return self.R[f], self.o[f]


class ModePack:
    """The arrays of one sealed `ContactModes` that the engine takes: the tracked pairs, the
    tracked point-curve pairs, the pairs in contact, their mode codes and held sliding
    directions."""

    __slots__ = ("active", "pc", "rows", "codes", "held_dir", "has_dir")

    def __init__(self, k, near, states, pc=()):
        self.active = np.zeros(k, dtype=np.bool_)
        self.active[list(near)] = True
        self.pc = np.array([i for i in pc if self.active[i]], dtype=np.intp)
        rows = [i for i in near if states[i].mode.in_contact]
        self.rows = np.array(rows, dtype=np.int64)
        self.codes = np.array([STICK if states[i].mode == Mode.STICKING else SLIDE
                               for i in rows], dtype=np.int64)
        self.held_dir = np.zeros((len(rows), 2))
        self.has_dir = np.zeros(len(rows), dtype=np.bool_)
        for j, i in enumerate(rows):
            if states[i].slide_dir is not None:
                self.held_dir[j] = states[i].slide_dir
                self.has_dir[j] = True

"""The compiled engine at the Drake boundary: the `Model` record read once from a plant whose
bodies all move freely and from the declared pairs, the `ModeArrays` record of each sealed set
of modes, one compiled call per evaluation (`drake_dock.core.kernels.engine.evaluate`), and the
calculators the events use (kinematics, couples, contact rows, M, M^-1 and the free
acceleration), all compiled.

The plant stays the model: it holds the bodies, their inertias and frames, gravity and the
force elements, and it is the reference the tests compare the kernels' kinematics, mass matrix,
force elements, Jacobians and bias terms with (tests/systems/test_engine.py). What the engine
describes: bodies on quaternion floating joints (no other joint), uniform gravity and
LinearBushingRollPitchYaw force elements; a plant with anything else is refused with a
`ValueError` naming it.
"""
from __future__ import annotations


import numpy as np
from pydrake.multibody.tree import (BodyIndex, ForceElementIndex, LinearBushingRollPitchYaw,
                                    UniformGravityFieldElement)

from drake_dock.core.constraints import ContactRow
from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels import calculators as KC
from drake_dock.core.kernels import model as E
from drake_dock.core.kernels.engine import evaluate as evaluate_kernel
from drake_dock.core.kernels.jets import N_PARAMS, patch_spec
from drake_dock.core.kernels import records
from drake_dock.core.kernels.records import pack
from drake_dock.core.kernels.couple_row import CoupleRow
from drake_dock.core.relations import relation
from drake_dock.systems.evaluation import Evaluation, Kinematics


def frame_list(pairs, extra=()):
    """The distinct frames of the pairs (then of ``extra``), and per pair the indices of its
    two frames."""
    frames = []
    for f in [f for p in pairs for f in (p.frame1, p.frame2)] + list(extra):
        if all(f is not g for g in frames):
            frames.append(f)
    index = [(next(i for i, g in enumerate(frames) if g is p.frame1),
              next(i for i, g in enumerate(frames) if g is p.frame2)) for p in pairs]
    return frames, index


def _index(frames, f):
    return next(i for i, g in enumerate(frames) if g.index() == f.index())


def _bodies(plant):
    """The plant's bodies but the world, each on a quaternion floating joint; a ValueError
    names what the engine does not describe."""
    bodies = [plant.get_body(BodyIndex(i)) for i in range(1, plant.num_bodies())]
    for b in bodies:
        if not (b.is_floating_base_body() and b.has_quaternion_dofs()):
            raise ValueError(f"plant: body {b.name()!r} must be free on a quaternion floating "
                             f"joint (the contact engine describes free bodies only)")
    if plant.num_joints() != len(bodies):
        raise ValueError(f"plant: {plant.num_joints()} joints for {len(bodies)} bodies; the "
                         f"contact engine describes free bodies only (no other joint)")
    return bodies


def _force_elements(plant, ctx):
    """(gravity (3,), [LinearBushingRollPitchYaw]) of the plant; a ValueError names any other
    force element."""
    gravity, bushings = np.zeros(3), []
    for k in range(plant.num_force_elements()):
        fe = plant.get_force_element(ForceElementIndex(k))
        if isinstance(fe, UniformGravityFieldElement):
            gravity = np.array(fe.gravity_vector(), dtype=float)
        elif isinstance(fe, LinearBushingRollPitchYaw):
            bushings.append(fe)
        else:
            raise ValueError(f"plant: force element {type(fe).__name__} is not described by "
                             f"the contact engine (uniform gravity and "
                             f"LinearBushingRollPitchYaw only)")
    return gravity, bushings


def _edges(pairs, links):
    """The hand-over edges of the edge pairs (`HandoverLinks.of_edge`) in the `Model` layout:
    per pair (first, count), per edge (surface pair, (fixed, upper, map kind), map)."""
    first, count = np.zeros(len(pairs), np.int64), np.zeros(len(pairs), np.int64)
    surface, info, maps = [], [], []
    for i in range(len(pairs)):
        edges = links.of_edge.get(i, ())
        first[i], count[i] = len(surface), len(edges)
        for j, edge in edges:
            kmap = edge.kernel_map
            if kmap is None:
                raise ValueError(f"handovers[{pairs[i].name}, {pairs[j].name}]: the edge has "
                                 f"no kernel_map (`SurfaceEdge.kernel_map`)")
            kind = {"affine": E.AFFINE, "component": E.COMPONENT}[kmap[0]]
            surface.append(j)
            info.append((edge.fixed, int(edge.upper), kind))
            maps.append((float(kmap[1]), float(kmap[2]) if len(kmap) > 2 else 0.0))
    return (first, count, np.array(surface, np.int64), np.array(info, np.int64).reshape(-1, 3),
            np.array(maps, float).reshape(-1, 2))


def _pair_arrays(pairs):
    """Per pair: kind code, the patches' kernel kinds and parameters, u's bounds; a
    ValueError names a patch that no kernel describes."""
    k = len(pairs)
    kind = np.zeros(k, np.int64)
    kind1, kind2 = np.zeros(k, np.int64), np.zeros(k, np.int64)
    prm1, prm2 = np.zeros((k, N_PARAMS)), np.zeros((k, N_PARAMS))
    lower, upper = np.zeros((k, 3)), np.ones((k, 3))
    bounded, spans = np.zeros((k, 3), np.int64), np.ones((k, 3))
    dims = np.zeros(k, np.int64)
    for i, p in enumerate(pairs):
        rel = relation(p.kind)
        kind[i] = rel.code
        if rel.point:
            prm1[i, :4] = (*p.patch1.p, p.patch1.radius)
        else:
            s1 = patch_spec(p.patch1)
            if s1 is None:
                raise ValueError(f"pairs[{p.name}]: patch 1 ({type(p.patch1).__name__}) has "
                                 f"no kernel description (`jets.patch_spec`)")
            kind1[i], prm1[i] = s1
        s2 = patch_spec(p.patch2)
        if s2 is None:
            raise ValueError(f"pairs[{p.name}]: patch 2 ({type(p.patch2).__name__}) has no "
                             f"kernel description (`jets.patch_spec`)")
        kind2[i], prm2[i] = s2
        lo = np.concatenate([p.patch1.lower, p.patch2.lower])
        hi = np.concatenate([p.patch1.upper, p.patch2.upper])
        per = tuple(p.patch1.periodic) + tuple(p.patch2.periodic)
        span = np.concatenate([p.patch1.span, p.patch2.span])
        n = len(lo)
        dims[i] = n
        lower[i, :n], upper[i, :n], spans[i, :n] = lo, hi, span
        bounded[i, :n] = [not a for a in per]
    return kind, kind1, kind2, prm1, prm2, lower, upper, bounded, spans, dims


class Engine:
    """The compiled contact dynamics of ``pairs`` (`ContactPair`) on a finalized
    continuous-time ``plant`` of free bodies: the packed `Model`, the modes' packs, one
    evaluation per call and the events' calculators. ``dampers``: (name, bushing) whose damper
    work is integrated (its power is a state's rate); ``links`` the `HandoverLinks`; ``far`` the
    `FarPairs` (its bounding spheres); ``frames``, ``fidx`` as `frame_list`."""

    def __init__(self, plant, pairs, law, options, frames, fidx, links, far, dampers=(),
                 energy_scale=1.0):
        self.plant, self.pairs, self.law, self.options = plant, list(pairs), law, options
        self.energy_scale = float(energy_scale)
        ctx = plant.CreateDefaultContext()
        bodies = _bodies(plant)
        where = {b.index(): k for k, b in enumerate(bodies)}
        gravity, bushings = _force_elements(plant, ctx)
        self.damper_names = []
        damper_of = {}
        for name, bushing in dampers:
            damper_of[bushing.index()] = name
        order = sorted(bushings, key=lambda b: damper_of.get(b.index()) is None)
        for bushing in order:
            if bushing.index() in damper_of:
                self.damper_names.append(damper_of[bushing.index()])
        if len(self.damper_names) != len(dampers):
            raise ValueError("dampers: each must be a LinearBushingRollPitchYaw of the plant")
        bush_frames_list = [f for b in order for f in (b.frameA(), b.frameC())]
        self.frames, self.fidx = frames, fidx
        extra = [f for f in bush_frames_list if all(f.index() != g.index() for g in frames)]
        self.frames = frames = list(frames) + extra
        self.nq, self.nv = plant.num_positions(), plant.num_velocities()
        kind, kind1, kind2, prm1, prm2, lower, upper, bounded, spans, dims = \
            _pair_arrays(self.pairs)
        self.uoff = np.concatenate([[0], np.cumsum(dims)]).astype(np.int64)
        self.nu = int(self.uoff[-1])
        self.ie = self.nq + self.nv + self.nu
        self.nx = self.ie + 3 + len(self.damper_names)
        self.k = len(self.pairs)
        m, com, inertia = [], [], []
        for b in bodies:
            Mb = b.CalcSpatialInertiaInBodyFrame(ctx)
            c = np.asarray(Mb.get_com())
            m.append(Mb.get_mass())
            com.append(c)
            inertia.append(Mb.Shift(c).CalcRotationalInertia().CopyToFullMatrix3())
        inertia = np.array(inertia).reshape(-1, 3, 3)
        fb, R_BF, p_BF = [], [], []
        for f in frames:
            X = f.GetFixedPoseInBodyFrame()
            fb.append(where.get(f.body().index(), -1))
            R_BF.append(X.rotation().matrix())
            p_BF.append(X.translation())
        gains = [[b.torque_stiffness_constants(), b.torque_damping_constants(),
                  b.force_stiffness_constants(), b.force_damping_constants()] for b in order]
        frame_pairs = sorted(set(map(tuple, fidx)))
        first, count, surface, info, maps = _edges(self.pairs, links)
        opt = options
        options_arr = np.zeros(E.N_OPTIONS)
        options_arr[[E.O_MU, E.O_MU_S, E.O_OMEGA, E.O_V_SLIP, E.O_DRIFT_FB, E.O_DRIFT_TOL,
                     E.O_COND_MIN, E.O_ENERGY, E.O_GUARD, E.O_EARLY, E.O_HORIZON]] = (
            law.mu, law.static_mu, opt.baumgarte, opt.v_slip, opt.drift_feedback,
            opt.drift_tol, opt.conditioning_min, self.energy_scale, GUARD_BAND,
            opt.reseek_early, opt.reseek_horizon)
        sizes = np.zeros(E.N_SIZES, np.int64)
        sizes[[E.Z_NQ, E.Z_NV, E.Z_NU, E.Z_IE, E.Z_NX]] = (self.nq, self.nv, self.nu, self.ie,
                                                           self.nx)
        self.model = E.Model(
            np.array([b.floating_positions_start() for b in bodies], np.int64),
            np.array([b.floating_velocities_start_in_v() for b in bodies], np.int64),
            np.array(m, float), np.array(com, float).reshape(-1, 3), inertia,
            np.linalg.inv(inertia) if len(bodies) else inertia, gravity,
            np.array(fb, np.int64), np.array(R_BF, float).reshape(-1, 3, 3),
            np.array(p_BF, float).reshape(-1, 3),
            np.array([[_index(frames, b.frameA()), _index(frames, b.frameC())] for b in order],
                     np.int64).reshape(-1, 2),
            np.array(gains, float).reshape(-1, 4, 3),
            kind, kind1, kind2, prm1, prm2, np.array(fidx, np.int64).reshape(-1, 2), self.uoff,
            spans, lower, upper, bounded,
            np.array([frame_pairs.index(tuple(ab)) for ab in fidx], np.int64),
            np.array(frame_pairs, np.int64).reshape(-1, 2), far.centres.reshape(-1, 3),
            far.radii, first, count, surface, info, maps, options_arr, sizes)
        self.packed = pack(self.model)
        self.nbush = len(order)
        self.nframes = len(frames)
        self.nb = len(bodies)
        self.evaluations = 0

    # ------------------------------------------------------------------ modes
    def mode_arrays(self, modes) -> E.ModeArrays:
        """The `ModeArrays` of a `ContactModes` (computed once when sealed: kept on its
        index)."""
        index = modes.index()
        hit = index.derived.get("engine")
        if hit is None:
            hit = index.derived["engine"] = pack(self._mode_arrays(modes.pairs, index))
        return hit

    def patch_far(self, modes, new, changed):
        """The `ModeArrays` of the sealed modes ``new`` from those of ``modes``, where only the
        far pairs ``changed`` (still far) have new far-pair data, kept on ``new``'s index."""
        packed = records.copy(self.mode_arrays(modes))
        V = records.views(packed, E.ModeArrays)
        for i in changed:
            st = new.pairs[i]
            V.clearance[i], V.distance[i] = st.clearance, st.distance
            if st.ref_X21 is not None:
                V.R0[i], V.p0[i] = st.ref_X21
            V.sought[i] = st.ref_X21 is not None
        new.index().derived["engine"] = packed

    def _mode_arrays(self, states, index) -> E.ModeArrays:
        k = self.k
        code = np.array([int(st.mode) for st in states], np.int64)
        slide, has = np.zeros((k, 2)), np.zeros(k, np.int64)
        R0, p0 = np.tile(np.eye(3), (k, 1, 1)), np.zeros((k, 3))
        sought = np.zeros(k, np.int64)
        for i, st in enumerate(states):
            if st.slide_dir is not None:
                slide[i], has[i] = st.slide_dir, 1
            if st.mode == Mode.FAR and st.ref_X21 is not None:
                R0[i], p0[i] = st.ref_X21
                sought[i] = 1
        rows = np.array([i for i in index.near if states[i].mode.in_contact], np.int64)
        near = np.array(index.near, np.int64)
        slot = np.full(k, -1, np.int64)
        slot[near] = np.arange(len(near))
        return E.ModeArrays(code, index.sigma.copy(), slide, has, rows,
                            np.array([st.clearance for st in states], float),
                            np.array([st.distance for st in states], float), R0, p0, sought,
                            near, slot)

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, t, x, modes, tau_in) -> "Evaluation":
        """The evaluation at time t, state x (the system's continuous state), `ContactModes`
        modes and the inputs' generalized force tau_in (nv,)."""
        self.evaluations += 1
        packed, layout = self.prepared(modes)
        buf = np.empty(layout[-1])
        evaluate_kernel(self.packed, packed, x, tau_in, buf)
        return Evaluation(self, t, x, modes, buf, layout)

    def prepared(self, modes) -> tuple:
        """(`mode_arrays`, `layout_of`) of ``modes`` (kept on their index)."""
        derived = modes.index().derived
        hit = derived.get("prepared")
        if hit is None:
            hit = derived["prepared"] = (self.mode_arrays(modes), self.layout_of(modes))
        return hit

    def slot_of(self, modes) -> np.ndarray:
        """Each pair's place among the pairs not far under ``modes`` (-1 for a far one; kept on
        their index)."""
        derived = modes.index().derived
        hit = derived.get("slot")
        if hit is None:
            hit = np.full(self.k, -1, dtype=np.intp)
            hit[list(modes.index().near)] = np.arange(len(modes.index().near))
            derived["slot"] = hit
        return hit

    def layout_of(self, modes) -> tuple:
        """The result buffer's layout under ``modes`` (`model.layout`; kept on their index)."""
        derived = modes.index().derived
        hit = derived.get("layout")
        if hit is None:
            hit = derived["layout"] = E.layout(self.nx, self.k, self.nv, self.nframes,
                                               self.nbush, len(modes.index().near))
        return hit

    # ------------------------------------------------------------------ calculators
    def kinematics(self, q, v) -> "Kinematics":
        """The bodies' and frames' poses and twists at (q, v)."""
        nb, F = self.nb, len(self.frames)
        K_ = Kinematics(np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)),
                        np.empty((nb, 3)), np.empty((F, 3, 3)), np.empty((F, 3)),
                        np.empty((F, 3)), np.empty((F, 3)))
        KC.kinematics(self.packed, q, v, K_.Rb, K_.pb, K_.wb, K_.vb, K_.R, K_.o, K_.w, K_.v)
        return K_

    def couples(self, kin, u, sigma, which, project=True):
        """The couples u (the layout of u*) of the pairs ``which`` with the orientations sigma
        (per pair, (k,)), as `CoupleRow`s by pair; a point-curve couple whose point lies on its
        curve is NaN in its gap."""
        out = np.zeros((self.k, K.ROW))
        which = np.asarray(which, np.int64)
        KC.couples_at(self.packed, kin.R, kin.o, kin.w, kin.v, np.asarray(u, float),
                     np.asarray(sigma, float), which, project, self.options.drift_feedback,
                     out)
        return {int(i): CoupleRow(out[i], int(self.uoff[i + 1] - self.uoff[i])) for i in which}

    def couple(self, i, u_i, kin, sigma, project=True):
        """Pair i's couple u_i (`couples`)."""
        u = np.zeros(self.nu)
        u[self.uoff[i]:self.uoff[i + 1]] = u_i
        sig = np.ones(self.k)
        sig[i] = sigma
        return self.couples(kin, u, sig, [i], project)[i]

    def row(self, i, c, kin) -> ContactRow:
        """Pair i's `ContactRow` at its couple c (a `CoupleRow`), Eq. (11) and (52)."""
        W, bias = np.empty((self.nv, 3)), np.empty(3)
        KC.contact_row(self.packed, i, c.row, kin.pb, kin.wb, W, bias)
        return ContactRow(self.pairs[i].name, W[:, 0], W[:, 1:], float(bias[0]), bias[1:],
                          c.gap, c.vn, c.vt, self.law.mu, self.law.static_mu)

    def mass_matrix(self, kin) -> np.ndarray:
        """M (nv, nv) at the `Kinematics` kin."""
        M = np.empty((self.nv, self.nv))
        KC.mass_at(self.packed, kin.Rb, M)
        return M

    def dynamics(self, q, v, tau_in):
        """(M, M^-1, a0 = M^-1 (tau - C v), power of the force elements, of the inputs,
        kinetic and potential energy)."""
        nv = self.nv
        M, Minv, a0, scal = np.empty((nv, nv)), np.empty((nv, nv)), np.empty(nv), np.empty(4)
        KC.dynamics_at(self.packed, q, v, np.asarray(tau_in, float), M, Minv, a0, scal)
        return M, Minv, a0, float(scal[0]), float(scal[1]), float(scal[2]), float(scal[3])


# The hand-over guard's witness fires at n . b = -GUARD_BAND (`drake_dock.systems.witnesses`).
GUARD_BAND = 1e-9

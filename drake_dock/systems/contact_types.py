"""The contact system's data: the declared pairs, the options, the per-pair state (its `Mode`),
the abstract state, one evaluation, and the layout of each couple's output port."""
from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np

from drake_dock.core.contact_law import ContactLaw
from drake_dock.core.handover import SurfaceEdge
from drake_dock.core.hybrid import Mode
from drake_dock.errors import InputError

__all__ = ["COUPLE_FIELDS", "COUPLE_OUTPUT_SIZE", "COUPLE_SLICES", "ContactLaw", "ContactModes",
           "ContactOptions", "ContactPair", "Handover", "ModesIndex",
           "PairState", "SurfaceEdge"]

# Layout of each couple's output port; "status" is the pair's `Mode` (0 far, 1 tracked,
# 2 sliding, 3 sticking).
COUPLE_FIELDS = (("status", 1), ("gap", 1), ("vn", 1), ("lambda_n", 1), ("lambda_t", 2),
                 ("vt", 2), ("u", 3), ("p1", 3), ("p2", 3), ("frame", 9))
COUPLE_SLICES = {}
_offset = 0
for _name, _size in COUPLE_FIELDS:
    COUPLE_SLICES[_name] = slice(_offset, _offset + _size)
    _offset += _size
COUPLE_OUTPUT_SIZE = _offset
PAINLEVE = ("impact", "error")   # `ContactOptions.painleve`


@dataclasses.dataclass
class ContactPair:
    """A declared pair: ``patch1`` (a curve, or a `Point` for "PC" and "PS") on ``frame1``,
    ``patch2`` (a curve for "CC" and "PC", a surface for "CS" and "PS") on ``frame2``; the
    couple's normal points
    from body 2 to body 1.
    ``sigma`` (+-1) fixes the orientation of n (Definition 2) when the scene knows it (a body
    that starts resting on a plane); by default it is taken when the pair becomes potential,
    from the side the patches are on."""

    name: str
    kind: str
    frame1: object
    patch1: object
    frame2: object
    patch2: object
    sigma: float | None = None


@dataclasses.dataclass(frozen=True)
class Handover:
    """A declared hand-over (`drake_dock.core.handover`): pair ``edge_pair`` (C-C) and pair
    ``surface_pair`` (C-S) share their curve on Body 1, and the edge pair's curve on Body 2 is
    the boundary ``edge`` of the surface pair's surface."""

    edge_pair: str
    surface_pair: str
    edge: SurfaceEdge


@dataclasses.dataclass
class ContactOptions:
    baumgarte: float = 20.0          # omega (rad/s) of the constraint stabilisation
    drift_feedback: float = 50.0     # 1/s, feedback of the couple projection into u*
    drift_tol: float = 1e-3          # largest projection step, relative to the domain span
    handover_tol: float = 1e-3       # a hand-over's couple: largest Newton step onto its
                                     # closest-point conditions, relative to the span
    track_distance: float = 0.02     # m: nearer interior isolated couples are tracked
    reseek_floor: float = 1e-4       # m: smallest relative travel between two re-seeks
    reseek_early: float = 0.9        # far pairs are sought again at the first step start where
                                     # this fraction of their clearance is used (0: never)
    reseek_horizon: float = 0.0      # s: or will be within this time at the present rate of
                                     # their travel bound (`witness_values.due_in`); the
                                     # docking diagram sets the step cap, so that no step is
                                     # cut short to end where one falls due
    conditioning_min: float = 1e-6   # |det J| / prod(row norms) below which J is singular
    v_slip: float = 1e-6             # m/s: a couple slower than this may stick
    zeno_speed: float = 1e-3         # m/s: the Zeno guard (`drake_dock.core.hybrid`)
    impact_gap_tol: float = 1e-8     # m: couples this near join an impact
    impact_rtol: float = 1e-10       # LZB's impulse-domain integration (`solve_lzb`); the
                                     # docking diagram sets 1e-2 x the simulation accuracy
    seek_rtol: float = 1e-7          # a seek's Newton ends when a step shortens the distance
                                     # by less than this fraction, for pairs farther than
                                     # track_distance (`seek_couple`): their distance only sets
                                     # the clearance, which keeps track_distance / 2 in hand
    max_impacts: int = 10000
    painleve: str = "impact"         # no consistent mode (`PainleveInconsistency`): "impact",
                                     # an impact without collision (`drake_dock.core.iwc`), or
                                     # "error", stop with it
    joint_witness: bool = True       # Drake is given one witness, the least of the armed
                                     # ones positive after an event, beside each of the others
                                     # (False: one witness function per transition;
                                     # `witnesses`)
    broad_phase: bool | None = None  # a far pair whose covers are at least track_distance
                                     # apart is not sought (`Transitions.screen`). None: the
                                     # scene's policy (`docking.diagram.contact_options`: on
                                     # for every pair set but paper); off where no scene
                                     # resolves it (a contact system built directly)

    def __post_init__(self):
        if not 0.0 <= self.reseek_horizon < math.inf:
            raise InputError("ContactOptions.reseek_horizon", self.reseek_horizon,
                             "a time >= 0 s")
        if self.painleve not in PAINLEVE:
            raise InputError("ContactOptions.painleve", self.painleve,
                             f"one of {', '.join(map(repr, PAINLEVE))}")


@dataclasses.dataclass
class PairState:
    mode: Mode = Mode.FAR
    sigma: float = 1.0
    slide_dir: np.ndarray | None = None   # unit sliding direction (SLIDING)
    clearance: float = 0.0                # relative travel left before a seek (FAR)
    ref_X21: tuple | None = None          # pose of frame 1 in frame 2 at the last seek
    distance: float = math.inf            # distance at the last seek

    def track(self):
        """Enters TRACKED (from contact: the couple separates, or is left out of an impact)."""
        self.mode, self.slide_dir = Mode.TRACKED, None

    def __setattr__(self, name, value):
        if self.__dict__.get("_sealed"):
            raise AttributeError(f"PairState.{name}: the state is sealed (held by a context, "
                                 "`ContactModes.seal`); change a `ContactModes.working_copy`")
        object.__setattr__(self, name, value)

    def copied(self) -> "PairState":
        """A copy that an event may change, never sealed: its arrays are replaced, never
        written in place, so they are shared (`copy.copy` without its generic protocol)."""
        new = PairState.__new__(PairState)
        new.__dict__.update(self.__dict__)
        new.__dict__.pop("_sealed", None)
        return new

    __copy__ = copied

    def __deepcopy__(self, memo):
        """A copy, never sealed, of copied arrays."""
        new = self.copied()
        new.__dict__.update(copy.deepcopy(new.__dict__, memo))
        return new

    def __getstate__(self):
        """Pickled unsealed: the seal belongs to the context that holds the state."""
        return {k: v for k, v in self.__dict__.items() if k != "_sealed"}


def copied_states(states) -> list:
    """`PairState.copied` of each of ``states``."""
    return [st.copied() for st in states]


@dataclasses.dataclass
class ContactModes:
    """The abstract state: per pair its `PairState`, and the impact log. A context holds them
    sealed (`seal`): then nothing of them changes, and a change raises."""

    pairs: list                     # a tuple once sealed
    impacts: list = dataclasses.field(default_factory=list)   # `impacts.Impact`s, in order
    impact_loss: float = 0.0
    mode_changes: int = 0           # events that resolved transitions
    reseeks: int = 0                # steps whose start sought far pairs again, nothing else
    # The continuous state that the event which set these modes left (`read_only`; None
    # for the initial modes): a step that starts at an event starts from it.
    x_after: object = dataclasses.field(default=None, compare=False, repr=False)

    def __setattr__(self, name, value):
        if "_index" in self.__dict__:
            raise AttributeError(f"ContactModes.{name}: the modes are sealed (`seal`); change "
                                 "a `working_copy`")
        object.__setattr__(self, name, value)

    def __deepcopy__(self, memo):
        """Copies (Drake clones the abstract state at every step and event). Sealed modes are
        never changed, so their copy shares the pair states and the index, sealed. Otherwise
        the pair states are copied (their arrays are replaced, never written in place). The
        impact log's entries are never changed once logged, so the log is copied as a list of
        the same entries."""
        index = self.__dict__.get("_index")
        if index is None:
            return self.working_copy()
        new = ContactModes(self.pairs, list(self.impacts), self.impact_loss, self.mode_changes,
                           self.reseeks, self.x_after)
        new.__dict__["_index"] = index
        return new

    def __getstate__(self):
        """Pickled unsealed, the pair states as a list (`PairState.__getstate__`)."""
        state = {k: v for k, v in self.__dict__.items() if k != "_index"}
        state["pairs"] = list(self.pairs)
        return state

    def working_copy(self) -> "ContactModes":
        """A copy whose pair states an event may change (not sealed)."""
        return ContactModes(copied_states(self.pairs), list(self.impacts), self.impact_loss,
                            self.mode_changes, self.reseeks)

    def seal(self, index: "ModesIndex | None" = None) -> "ContactModes":
        """Marks these modes as final: a context holds them, and neither they nor their pair
        states change again (a change raises; the pairs become a tuple). What the evaluations
        and witnesses read of them (`index`) is then computed once, not in a pass over every
        pair at each evaluation."""
        self.pairs = tuple(self.pairs)
        for st in self.pairs:
            st.__dict__["_sealed"] = True
        self.__dict__["_index"] = ModesIndex.of(self.pairs) if index is None else index
        return self

    def index(self) -> "ModesIndex":
        """The `ModesIndex` of the pair states: kept when sealed, else computed now."""
        index = self.__dict__.get("_index")
        return ModesIndex.of(self.pairs) if index is None else index


def _patched(a, at, values):
    b = a.copy()
    b[at] = values
    b.flags.writeable = False
    return b


def read_only(a):
    """The array a, made unwritable (in place)."""
    a.flags.writeable = False
    return a


# What `ModesIndex.derived` keeps that depends only on which pairs are near and far and on
# their modes (not on far-pair data).
LAYOUT_DERIVED = ("armed", "armed_arrays", "far_u", "slot", "layout")


@dataclasses.dataclass(frozen=True, eq=False)
class ModesIndex:
    """What the evaluations and witnesses read of the pairs' states, over the pairs at once:
    the pairs not far (``near``, ascending) and the far ones (``far``) with their clearances,
    their distances at the last seek and whether they were ever sought (read-only arrays), and
    every pair's sigma (writable: the compiled kernel takes one signature); ``derived`` keeps
    what the contact system computes from these (the armed witnesses, the far pairs' stacked
    reference poses)."""

    near: tuple
    far: np.ndarray
    clearance: np.ndarray
    distance: np.ndarray
    sought: np.ndarray
    sigma: np.ndarray
    derived: dict
    far_not: np.ndarray = None     # ``near`` as an array

    def with_far(self, changed, states) -> "ModesIndex":
        """This index for ``states`` where only the far pairs ``changed`` (still far) have new
        far-pair data: the same pairs near and far, their clearances, distances and whether
        sought patched; what the contact system derived of the modes' layout (the armed
        witnesses) kept, the rest of ``derived`` dropped."""
        at = np.searchsorted(self.far, changed)
        keep = {k: v for k, v in self.derived.items() if k in LAYOUT_DERIVED}
        return ModesIndex(self.near, self.far,
                          _patched(self.clearance, at, [states[i].clearance for i in changed]),
                          _patched(self.distance, at, [states[i].distance for i in changed]),
                          _patched(self.sought, at, [states[i].ref_X21 is not None
                                                     for i in changed]),
                          self.sigma, keep, self.far_not)

    @staticmethod
    def of(states) -> "ModesIndex":
        FAR = Mode.FAR
        far = [i for i, st in enumerate(states) if st.mode == FAR]
        near = tuple(i for i, st in enumerate(states) if st.mode != FAR)
        return ModesIndex(
            near,
            read_only(np.array(far, dtype=np.intp)),
            read_only(np.array([states[i].clearance for i in far], dtype=float)),
            read_only(np.array([states[i].distance for i in far], dtype=float)),
            read_only(np.array([states[i].ref_X21 is not None for i in far], dtype=bool)),
            np.array([st.sigma for st in states], dtype=float), {},
            read_only(np.array(near, dtype=np.intp)))

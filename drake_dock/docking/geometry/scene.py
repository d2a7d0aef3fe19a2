"""The docking scene a scenario declares, made once (`DockingScene`): the APDS's patches, the
contact pairs of its set with their families, and the hand-overs among them. The placement
searches its pairs, the docking Diagram declares them to the contact system, and the run's
report names its couples by them."""
from __future__ import annotations

import copy
import dataclasses

from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import PairSpec, apds_pairs
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.errors import InputError


class DockingScene:
    """The patches (`apds.ApdsPatches`, shared by both APDSes), the pairs of the contact set
    ``pair_set`` (`pairs.apds_pairs`, in their declared order) and the hand-overs among them,
    for a copy of ``geometry``. Two scenes of equal geometry and set are equal (``key``): what
    their patches keep (covers, coarse grids, kernel descriptions) serves every approach and
    every run on them."""

    def __init__(self, geometry: ApdsGeometry, pair_set: str):
        self.geometry = copy.deepcopy(geometry)
        self.pair_set = pair_set
        self.key = self.key_of(geometry, pair_set)
        self.patches = apds_patches(self.geometry)
        declared = apds_pairs(self.geometry, pair_set, self.patches)
        self.pairs: tuple[PairSpec, ...] = tuple(declared.pairs)
        self.handovers = tuple(declared.handovers)
        self._by_name = {p.name: p for p in self.pairs}

    @classmethod
    def of(cls, scenario) -> "DockingScene":
        """The scene of a scenario: its ``geometry`` and ``contact.pairs``."""
        return cls(scenario.geometry, scenario.contact.pairs)

    @staticmethod
    def key_of(geometry: ApdsGeometry, pair_set: str) -> tuple:
        """What a scene is made of: the geometry's values and the set's name."""
        return dataclasses.astuple(geometry), pair_set

    def __eq__(self, other):
        return isinstance(other, DockingScene) and self.key == other.key

    def __hash__(self):
        return hash(self.key)

    def __repr__(self):
        return f"DockingScene({self.geometry!r}, {self.pair_set!r}: {len(self.pairs)} pairs)"

    def pair(self, name: str) -> PairSpec:
        """The pair named ``name``; `InputError` for a name the scene does not declare."""
        try:
            return self._by_name[name]
        except KeyError:
            raise InputError("pair", name, f"a pair of the scene's {self.pair_set!r} set "
                             f"({len(self.pairs)} pairs)") from None

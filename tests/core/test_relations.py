"""The relation table of the pair kinds (`drake_dock.core.relations`): each kind's patches
are what its couple kernel evaluates (a couple of the wrong dimensions is refused), an
unknown kind is refused by name, and the orientation sigma by hand (Definition 2)."""
import numpy as np
import pytest

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.patches import PlaneRect, Point, Segment
from drake_dock.core.relations import RELATIONS, kind_of, relation

PATCHES = {0: Point(np.zeros(3), 0.01), 1: Segment(np.zeros(3), np.array([1.0, 0.0, 0.0])),
           2: PlaneRect(np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))}
AT = (np.eye(3), np.zeros(3))
STILL = (np.zeros(3), np.zeros(3))


def test_an_unknown_kind_is_refused_by_name():
    with pytest.raises(ValueError, match="CC, CS, PC, PS.*'SS'"):
        relation("SS")


@pytest.mark.parametrize("kind", sorted(RELATIONS))
def test_each_kind_takes_its_patches_and_no_others(kind):
    d1, d2 = relation(kind).dims
    assert relation(kind).point == (d1 == 0)
    for w1 in (0, 1):
        for w2 in (1, 2):
            if (w1, w2) == (d1, d2):
                continue
            with pytest.raises(ValueError, match="dimensions"):
                evaluate_couple(kind, PATCHES[w1], AT, STILL, PATCHES[w2], AT, STILL,
                                np.zeros(w1 + w2), 1.0)


def test_the_kind_of_two_patches_dimensions_is_the_relation_that_takes_them():
    """kind_of inverts Relation.dims, and the patches a relation takes have those dimensions
    (a point 0, a segment 1, a rectangle 2); dimensions no relation has are refused."""
    shapes = {0: Point((0.0, 0.0, 0.0)), 1: Segment((0, 0, 0), (1, 0, 0)),
              2: PlaneRect((0, 0, 0), (1, 0, 0), (0, 1, 0))}
    for kind, r in RELATIONS.items():
        assert kind_of(shapes[r.dims[0]].dim, shapes[r.dims[1]].dim) == kind
    for dims in ((2, 2), (2, 1), (1, 0), (0, 0)):
        with pytest.raises(ValueError, match=f"dimensions {dims[0]} and {dims[1]}"):
            kind_of(*dims)


def test_sigma_by_hand():
    r = 0.01
    assert relation("PC").sigma(-1.0, -0.3) == 1.0         # along d whatever is declared
    assert relation("CS").sigma(-1.0, 0.3) == -1.0         # declared
    assert relation("CC").sigma(None, -0.2) == -1.0 and relation("CC").sigma(None, 0.0) == 1.0
    # A sphere overlapping a surface from its +N side (gap -r/2) is on that side; one past
    # it (gap -3r/2, its centre below) is not.
    assert relation("PS").sigma(None, -0.5 * r, r) == 1.0
    assert relation("PS").sigma(None, -1.5 * r, r) == -1.0

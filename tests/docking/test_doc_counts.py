"""The pair counts the docs quote, against the pair set: each quoted phrase is found in its file
(a changed sentence fails here, to be checked again) and its number is the count of the
`DockingScene`'s pairs of the families it names (`PairSpec.family`), for the paper's geometry
or the funnel variant's (`models/apds_funnel.yaml`, petals on the inside circle)."""
import re
from pathlib import Path

import pytest

from drake_dock.docking.geometry import pairs as P
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR

ROOT = Path(__file__).resolve().parents[2]


def _scenes():
    funnel = load_scenario(MODELS_DIR / "apds_funnel.yaml").geometry
    return {(g, which): DockingScene(geometry, which)
            for g, geometry in (("paper", ApdsGeometry()), ("funnel", funnel))
            for which in ("paper", "complete")}


SCENES = _scenes()


def count(which="complete", families=None, geometry="paper", body1=None) -> int:
    """The pairs of the set ``which`` (of the families given, with Body 1 on ``body1``)."""
    return sum(1 for p in SCENES[geometry, which].pairs
               if (families is None or p.family in families)
               and (body1 is None or p.body1 == body1))


def added(geometry="paper", families=None) -> int:
    """The pairs `complete` adds to `paper` (of the families given)."""
    return count("complete", families, geometry) - count("paper", families, geometry)


LARGE_ROLL = (P.CORNER_SURFACE, P.TIP_TIP, P.CORNER_LAND)
# The paper's set named by its count ("the 12 pairs do not model", "the paper's 12 pairs").
PAPERS = r"(?:the|paper's|its) (\d+) pairs(?! of `complete`)"
# (file, phrase with the quoted number as its group; whitespace matches any line break, the
# expected count)
QUOTED = [
    ("README.md", r"`paper` is the paper's (\d+) pairs", count("paper")),
    ("README.md", r"an off-axis approach reaches \((\d+) pairs\)", count()),
    ("docs/scenario.md", r"states `paper`, the (\d+) pairs of the paper", count("paper")),
    ("docs/scenario.md", r"`complete`, the (\d+) pairs an off-axis approach can reach", count()),
    ("docs/scenario.md", r"contact set: `complete` \((\d+) pairs;", count()),
    ("docs/scenario.md", r"; (\d+) with the petals on the inside circle\) or `paper`",
     count(geometry="funnel")),
    ("docs/scenario.md", r"or `paper` \((\d+)\) \|", count("paper")),
    ("docs/model.md", r"\*\*The (\d+) pairs of Sect\. 2\.2 and 8\.1\*\*", count("paper")),
    ("docs/model.md", r"- (\d+) guide side against guide side \(C-C\)",
     count("paper", [P.SIDE_SIDE])),
    ("docs/model.md", r"- (\d+) chaser ring circle against a target guide surface",
     count("paper", [P.RING_SURFACE], body1=P.CHASER_APDS)),
    ("docs/model.md", r"- (\d+) target ring circle against a chaser guide surface",
     count("paper", [P.RING_SURFACE], body1=P.TARGET_APDS)),
    ("docs/model.md", r"`complete`, the default, adds (\d+) pairs", added()),
    ("docs/model.md", r"adds \d+ pairs \((\d+) with the petals on the inside circle",
     added("funnel")),
    ("docs/model.md", r"(\d+) side-side and \d+ side-tip pairs", added(families=[P.SIDE_SIDE])),
    ("docs/model.md", r"\d+ side-side and (\d+) side-tip pairs", count(families=[P.SIDE_TIP])),
    ("docs/model.md", r"reaches each of these (\d+) pairs",
     added(families=[P.SIDE_SIDE, P.SIDE_TIP])),
    ("docs/model.md", r"spans lie 37 deg from its own \((\d+) pairs\)",
     count(families=[P.TIP_TIP])),
    ("docs/model.md", r"at its root \((\d+) pairs\)", count(families=[P.CORNER_SURFACE])),
    ("docs/model.md", r"excluded end of the roll range \((\d+) pairs\)",
     count(families=[P.CORNER_LAND])),
    ("docs/model.md", r"`paper` \((\d+) pairs\) or `complete`", count("paper")),
    ("docs/performance.md", r"What the (\d+) pairs of `complete` that only a large relative roll",
     count(families=LARGE_ROLL)),
] + [(path, PAPERS, count("paper")) for path in ("README.md", "docs/model.md", "docs/algorithms.md",
                                       "docs/results.md")]


def _quoted(path, phrase) -> list:
    """(start, number) of each match of the phrase's group in the file."""
    text = (ROOT / path).read_text()
    return [(m.start(1), int(m.group(1))) for m in re.finditer(phrase.replace(" ", r"\s+"), text)]


@pytest.mark.parametrize("path, phrase, expected", QUOTED,
                         ids=[f"{p}: {q[:40]}" for p, q, _ in QUOTED])
def test_a_pair_count_the_docs_quote_is_the_pair_sets(path, phrase, expected):
    found = _quoted(path, phrase)
    assert found, f"{path} no longer says {phrase!r}: check its count and update this test"
    assert [n for _, n in found] == [expected] * len(found), (path, phrase)


def test_every_pair_count_in_the_docs_is_checked():
    """Every "<n> pairs" in the docs and the README is one of the quoted phrases above, but a
    count of something else (a small scene's pairs)."""
    others = {("docs/performance.md", "the stool at rest, 3 pairs")}
    checked = {(path, start) for path, phrase, _ in QUOTED for start, _ in _quoted(path, phrase)}
    docs = sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").glob("*.md"))
    for path in ["README.md", *docs]:
        text = (ROOT / path).read_text()
        for m in re.finditer(r"(\d+)\s+pairs\b", text):
            if (path, m.start(1)) in checked:
                continue
            context = " ".join(text[max(0, m.start() - 30):m.end()].split())
            assert any(p == path and o in context for p, o in others), \
                f"{path}: {context!r} is not checked"

"""Fuzz of the command line over scenario files (hypothesis): the paper's example mutated (values
of every kind put in, keys removed and added, the document replaced, truncated, bytes changed,
binary content). Whatever the file, `drake-dock run` exits 0, 2 or 3; on 2 or 3 with a
one-paragraph message and nothing written: no directory at --out and no temporary one next to
it.

Speed: a file that fails validation costs milliseconds, one that passes costs a simulation
(--duration 0.02 s, past the first impact) and the figures, about 3 s. At most SIMULATED
examples may pass validation; further ones are discarded (``assume``) and replaced by new ones,
so that EXAMPLES scenario files run in about half a minute."""
import contextlib
import io
import math
import tempfile
from pathlib import Path

import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from drake_dock.cli import main
from drake_dock.docking.report.out_dir import MARKER
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.errors import InputError

PAPER = yaml.safe_load(PAPER_EXAMPLE.read_text())
TEXT = yaml.safe_dump(PAPER)          # without comments: every byte is content
EXAMPLES = 150
SIMULATED = 6
SEEN = {}


def _paths(node, path=()):
    """Every key and list item of the document, as paths of keys and indices."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return []
    out = []
    for k, v in items:
        out.append(path + (k,))
        out += _paths(v, path + (k,))
    return out


def _at(doc, path):
    for k in path:
        doc = doc[k]
    return doc


PATHS = _paths(PAPER)
MAPPINGS = [()] + [p for p in PATHS if isinstance(_at(PAPER, p), dict)]

SPECIAL = [math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0, 1e-300, 1e300, -1e300, 2**70,
           "", "1.0e9", "nan", "fast", None, True, [], {}, [1.0, 2.0], {"x": 1.0}]
values = st.one_of(
    st.sampled_from(SPECIAL),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**20, max_value=10**20),
    st.text(max_size=8),
    st.lists(st.floats(-10, 10), max_size=4),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)


def _mutate(draw, doc):
    """One mutation of the document in place: a value replaced or scaled, a key removed, an
    unknown key added."""
    what = draw(st.sampled_from(["set", "set", "set", "scale", "delete", "extra"]))
    try:
        if what == "extra":
            node = _at(doc, draw(st.sampled_from(MAPPINGS)))
            if isinstance(node, dict):
                node[draw(st.sampled_from(["friction", "mass2", "x", "R"]))] = draw(values)
            return
        path = draw(st.sampled_from(PATHS))
        parent = _at(doc, path[:-1])
        old = parent[path[-1]]
    except (KeyError, IndexError, TypeError):
        return                            # an earlier mutation removed or replaced it
    if what == "delete":
        del parent[path[-1]]
    elif what == "scale" and isinstance(old, float):
        parent[path[-1]] = old * draw(st.floats(0.5, 2.0))
    else:
        parent[path[-1]] = draw(values)


@st.composite
def documents(draw):
    """A mutated copy of the paper's example, as bytes."""
    kind = draw(st.sampled_from(["edit"] * 6 + ["binary", "truncate", "bytes", "root"]))
    if kind == "binary":
        return draw(st.binary(max_size=200))
    if kind == "truncate":
        return TEXT.encode()[:draw(st.integers(0, len(TEXT)))]
    if kind == "bytes":
        data = bytearray(TEXT.encode())
        for _ in range(draw(st.integers(1, 4))):
            data[draw(st.integers(0, len(data) - 1))] = draw(st.integers(0, 255))
        return bytes(data)
    if kind == "root":
        return yaml.safe_dump(draw(values)).encode()
    doc = yaml.safe_load(TEXT)
    for _ in range(draw(st.integers(1, 3))):
        _mutate(draw, doc)
    return yaml.safe_dump(doc).encode()


def _validates(data: bytes) -> bool:
    try:
        load_scenario(data=data.decode("utf-8"))
    except (InputError, UnicodeDecodeError):
        return False
    return True


@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                 HealthCheck.data_too_large])
@given(documents())
def _fuzz(data):
    if _validates(data):
        assume(SEEN.get("simulated", 0) < SIMULATED)
        SEEN["simulated"] = SEEN.get("simulated", 0) + 1
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        scenario = d / "scenario.yaml"
        scenario.write_bytes(data)
        out = d / "out"
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = main(["run", str(scenario), "--out", str(out), "--no-progress",
                       "--duration", "0.02"])
        SEEN[rc] = SEEN.get(rc, 0) + 1
        assert rc in (0, 2, 3), err.getvalue()
        if rc == 0:
            assert (out / "summary.json").is_file() and (out / MARKER).is_file()
            return
        text = err.getvalue().strip()
        msg = " ".join(text.split())      # one paragraph, wrapped at 100 columns: rejoined
        assert msg.startswith("drake-dock: "), text
        assert "\n\n" not in text and "Traceback" not in text, text
        assert "internal error" not in msg, text          # every failure is a typed one
        assert ("not allowed" if rc == 2 else "numerical failure") in msg, text
        assert sorted(p.name for p in d.iterdir()) == ["scenario.yaml"]  # no output, no temp


def test_any_scenario_file_exits_0_2_or_3_without_traceback_or_partial_output():
    """EXAMPLES scenario files; among them valid runs and rejected inputs."""
    SEEN.clear()
    _fuzz()
    runs = sum(SEEN.get(rc, 0) for rc in (0, 2, 3))
    print("outcomes", SEEN)
    assert runs >= EXAMPLES and SEEN.get(0) and SEEN.get(2), SEEN

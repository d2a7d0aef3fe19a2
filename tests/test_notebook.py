"""The tutorial notebook runs top to bottom (executed with nbclient, as a user's kernel) and
shows what it promises: the off-axis approach stated, its outcome and loads read from
summary.json and equal to the peaks recomputed from timeseries.npz, the couples in plain
words, the plots, the post-contact thrust's impulse and work, a campaign of six
samples with a row each and the counts of its summary, and the inline replay with its time
readout."""
import collections
import re
from pathlib import Path

import nbformat
from nbclient import NotebookClient


NB = Path(__file__).resolve().parent.parent / "notebooks" / "tutorial.ipynb"


def test_tutorial_notebook_executes(tmp_path):
    nb = nbformat.read(NB, as_version=4)
    NotebookClient(nb, timeout=900, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    text = "".join(o.get("text", "") for o in outputs
                   if o.get("output_type") == "stream" and o.get("name") == "stdout")
    errors = "".join(o.get("text", "") for o in outputs
                     if o.get("output_type") == "stream" and o.get("name") == "stderr")
    assert "INFO" not in errors and "Warning" not in errors, errors
    # The approach stated, its outcome read.
    assert "lateral_offset: [0.1, 0.0]" in text and "tilt_deg: [0.0, 4.0]" in text
    assert re.search(r"^outcome: (\w+) \(", text, re.M).group(1) == "captured"
    assert "force: 300.0" in text
    # The summary's peaks are those of the time series.
    force, at = re.search(r"peak force at the target ring: (\S+) N at (\S+) s", text).groups()
    stroke = re.search(r"peak Stewart stroke: (\S+) mm", text).group(1)
    assert re.search(rf"from the time series: peak force {re.escape(force)} N at "
                     rf"{re.escape(at)} s, peak stroke {re.escape(stroke)} mm", text)
    assert float(force) > 10.0
    assert re.search(r"^ *cc_\w+ +(chaser|target) ring inside circle / .* +peak +\d", text, re.M)
    # The thrust: 300 N, an impulse and a work that its force and windows bound.
    force_, impulse, work = map(float, re.search(
        r"^thrust: (\S+) N .* impulse (\S+) N s, work (\S+) J", text, re.M).groups())
    assert force_ == 300.0 and 0.0 < impulse <= 300.0 * 5.0 and 0.0 < work
    assert float(re.search(r"momentum drift less the impulse (\S+)", text).group(1)) < 1e-8
    # The campaign: six rows, counted as its summary counts them.
    n, counts = re.search(r"^(\d+) samples: (.*)$", text, re.M).groups()
    rows = re.findall(r"^ +\d\.\d{3} +\d+\.\d{2} +(\w+) ", text, re.M)
    assert int(n) == len(rows) == 6
    said = dict((k, int(v)) for k, v in (c.split() for c in counts.split(", ")))
    assert said == dict(collections.Counter(rows))
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 3
    html = [o for o in outputs if "text/html" in o.get("data", {})]
    page = html[-1]["data"]["text/html"]
    assert "iframe" in page and "time-readout" in page
    assert "apds_funnel: drake_dock replay" in page

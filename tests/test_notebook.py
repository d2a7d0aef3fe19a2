"""The tutorial notebook runs top to bottom (executed with nbclient, as a user's kernel) and
shows what it promises: the paper's example captured, an inconsistent scenario edit refused,
the controlled run's input work in its energy ledger, the timeseries read back from disk, the
interface loads figure and the inline replay with its time readout."""
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
    text = "".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    assert "captured: True" in text
    assert "refused: contact.mu_s" in text
    # The thrust does work on the chaser, and the ledger still closes.
    work, closure = re.search(r"controlled: captured at t = \S+ s; input work (\S+) J; "
                              r"closure (\S+)", text).groups()
    assert float(work) > 1.0 and float(closure) < 1e-6
    assert "interface_loads.png" in text and "summary.json" in text
    assert re.search(r"cc_T\d_C\d: peak lambda_n +\d", text)
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2
    html = [o for o in outputs if "text/html" in o.get("data", {})]
    assert html and "iframe" in html[-1]["data"]["text/html"]
    assert "time-readout" in html[-1]["data"]["text/html"]

"""The campaign's capture-probability figure draws every outcome a run can end in
(`drake_dock.docking.model.outcome.OUTCOMES`) and the errors: one legend entry per outcome present,
with its count."""
import numpy as np

from drake_dock.campaign import figures
from drake_dock.campaign.progress import ORDER


def test_every_outcome_is_drawn_with_its_count(tmp_path, monkeypatch):
    outcomes = [name for name in ORDER for _ in range(ORDER.index(name) + 1)]
    n = len(outcomes)
    rng = np.random.default_rng(1)
    columns = {"outcome": outcomes, "a": rng.uniform(-1, 1, n).tolist(),
               "b": rng.uniform(-1, 1, n).tolist()}
    legends = []
    close = figures.plt.close

    def keep(fig):
        legends.append([t.get_text() for t in fig.axes[0].get_legend().get_texts()])
        close(fig)

    monkeypatch.setattr(figures.plt, "close", keep)
    figures.capture_probability_figure(columns, ["a", "b"], tmp_path / "p.png")
    assert legends == [[f"{name} ({ORDER.index(name) + 1})" for name in ORDER]]
    assert (tmp_path / "p.png").stat().st_size > 0

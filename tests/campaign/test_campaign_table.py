"""The campaigns' side-by-side table: each cell against a count, scipy's Wilson interval or the
order statistics of the rows; the rows' CSV round trip; the export replaces only its own
files; and the table in docs/results.md is the one its committed rows give."""
import re
from pathlib import Path

import pytest
from scipy.stats import binomtest

from drake_dock.campaign import table as T
from drake_dock.errors import InputError

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _row(k, outcome, **kw):
    row = {"sample": k, "seed": 2**62 + k, "initial.chaser_speed": 0.05 + 0.001 * k,
           "outcome": outcome, "reason": kw.pop("reason", f"why {k}"), "capture_time": None,
           "end_time": 1.0 + k, "peak_contact_force": 10.0 * k, "peak_stewart_stroke": 1e-3 * k,
           "peak_stewart_force": 100.0 + k, "final_axial": 0.004, "final_lateral": 1e-3 * k,
           "final_tilt_deg": 0.01 * k, "impacts": k, "momentum_drift": 1e-12 * k,
           "energy_closure": 1e-9 * k, "wall_time": 3.0 + k / 3, "error": None}
    row.update(kw)
    return row


def _rows():
    rows = [_row(k, "captured", capture_time=0.5 + k) for k in range(20)]
    rows += [_row(20, "jammed"), _row(21, "jammed"), _row(22, "missed")]
    rows += [_row(23, "error", reason="PainleveInconsistency", error="no consistent mode",
                  **dict.fromkeys(["peak_contact_force", "peak_stewart_stroke",
                                   "peak_stewart_force", "final_lateral", "momentum_drift",
                                   "energy_closure"])),
             _row(24, "error", reason="KeyError", error="internal error (KeyError): 'x'",
                  **dict.fromkeys(["peak_contact_force", "peak_stewart_force"]))]
    return rows


def test_each_cell_is_the_rows_count_interval_or_order_statistic():
    rows = _rows()
    c = T.column(rows)
    assert c["samples"] == "25" and c["captured"] == "20"
    assert c["other outcomes"] == "1 `missed`, 2 `jammed`"
    assert c["typed numerical errors"] == "1 (`PainleveInconsistency`)"
    assert c["untyped errors"] == "1"
    ci = binomtest(20, 23).proportion_ci(method="wilson")            # the errors left out
    assert c["capture probability (95 % interval)"] == (
        f"{20 / 23:.3f} ({ci.low:.3f}-{ci.high:.3f})")
    times = sorted(0.5 + k for k in range(20))                      # 0.5 .. 19.5
    p95 = times[18] + 0.05 * (times[19] - times[18])                # linear, rank 0.95 (n - 1)
    assert c["capture time, median / 95th percentile / max"] == (
        f"{(times[9] + times[10]) / 2:.2f} / {p95:.2f} / {times[-1]:.2f} s")
    strokes = [1e-3 * k for k in range(25) if k != 23]   # the typed error's None left out
    assert c["peak Stewart stroke, median / 95th percentile / max"].endswith(
        f" / {max(strokes) * 1e3:.0f} mm")
    assert c["misalignment at capture, median / max"] == "9.5 / 19.0 mm, 0.10 / 0.19 deg"
    worst = "momentum drift (less the thrust's impulse), energy-ledger closure, worst"
    assert c[worst] == f"{24e-12:.1e}, {24e-9:.1e}"
    lines = T.table([("a", rows), ("b", rows[:20])])
    assert lines[0] == "| IDSS box | a | b |" and len(lines) == 2 + len(c)
    assert "| captured | 20 | 20 |" in lines and "| untyped errors | 1 | 0 |" in lines


def test_the_rows_csv_round_trips_every_float_and_drops_the_wall_time(tmp_path):
    rows = _rows()
    path = tmp_path / "rows.csv"
    assert T.main(["export", str(_parquet(rows, tmp_path)), str(path)]) == 0
    back = T.read_rows(path)
    assert [set(r) for r in back] == [set(r) - {"wall_time"} for r in rows]
    for a, b in zip(rows, back):
        for k, v in b.items():
            assert v == a[k] and type(v) is type(a[k]), k        # bitwise, ints stay ints
    assert T.column(back) == T.column(rows)


def test_the_rows_csv_reads_each_column_as_its_schema_type(tmp_path):
    """Text that reads as a number stays text in a text column, and a cell that is not of its
    column's type is an InputError naming the file's line and column (the store's schema, not
    a guess from the cell)."""
    rows = _rows()
    rows[0]["reason"], rows[1]["error"], rows[2]["outcome"] = "404", "nan", "1e3"
    path = tmp_path / "rows.csv"
    assert T.main(["export", str(_parquet(rows, tmp_path)), str(path)]) == 0
    back = T.read_rows(path)
    assert (back[0]["reason"], back[1]["error"], back[2]["outcome"]) == ("404", "nan", "1e3")
    text = path.read_text().splitlines()
    header = text[0].split(",")
    cells = text[3].split(",")
    cells[header.index("impacts")] = "3.5"
    path.write_text("\n".join(text[:3] + [",".join(cells)] + text[4:]) + "\n")
    with pytest.raises(InputError, match="line 4, column impacts = '3.5'.*an integer"):
        T.read_rows(path)


def _parquet(rows, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq
    path = tmp_path / "rows.parquet"
    pq.write_table(pa.Table.from_pylist(rows), path)
    return path


def test_the_export_replaces_only_a_rows_csv_of_its_own(tmp_path, capsys):
    src = _parquet(_rows(), tmp_path)
    mine, theirs = tmp_path / "mine.csv", tmp_path / "theirs.csv"
    T.export(src, mine)
    T.export(src, mine)                                        # its own: replaced
    theirs.write_text("name,value\nkeep,1\n")
    with pytest.raises(InputError, match="target"):
        T.export(src, theirs)
    assert theirs.read_text() == "name,value\nkeep,1\n"
    assert T.main(["show", "no title"]) == 2
    assert T.main(["show", f"x={tmp_path / 'absent'}"]) == 2
    err = capsys.readouterr().err
    assert "columns" in err and "TITLE=SOURCE" in err and "results.parquet" in err


def _docs_table(text: str) -> tuple[list[str], dict[str, list[str]]]:
    lines = [ln for ln in text.splitlines() if ln.startswith("| IDSS box |")]
    assert len(lines) == 1, "one campaign table in results.md"
    start = text.splitlines().index(lines[0])
    body = text.splitlines()[start:]
    titles = [t.strip() for t in body[0].strip("|").split("|")][1:]
    cells = {}
    for ln in body[2:]:
        if not ln.startswith("|"):
            break
        label, *vals = [c.strip() for c in ln.strip().strip("|").split("|")]
        cells[label] = vals
    return titles, cells


def test_the_docs_campaign_table_is_the_committed_rows():
    """Every column of results.md's campaign table whose rows docs/ keeps (its title names
    the CSV) is the column those rows give, cell by cell."""
    titles, cells = _docs_table((DOCS / "results.md").read_text())
    checked = 0
    for j, title in enumerate(titles):
        m = re.search(r"\(`?(campaign_\w+\.csv)`?\)", title)
        if not m:
            continue
        rows = T.read_rows(DOCS / m.group(1))
        assert len(rows) == 1000
        expected = T.column(rows)
        assert set(expected) == set(cells)
        for label, value in expected.items():
            assert cells[label][j] == value, (title, label)
        checked += 1
    assert checked >= 1

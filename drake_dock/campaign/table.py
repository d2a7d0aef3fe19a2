"""Campaigns side by side: one Markdown column per campaign, from its rows (``results.parquet``
or the CSV that `write_rows_csv` makes of it): outcomes, capture probability with its 95 %
Wilson interval, capture times, loads, strokes, misalignment at capture and conservation;
no wall time (docs/performance.md has those).
``python -m drake_dock.campaign.table show "TITLE=DIR" ...`` prints the table of the campaigns
in those directories (docs/results.md, "The IDSS envelope campaigns"); ``export DIR FILE``
writes a campaign's rows as the CSV that docs/ keeps."""
from __future__ import annotations

import argparse
import collections
import csv
import io
import math
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from drake_dock.campaign.progress import ORDER
from drake_dock.campaign.report import wilson
from drake_dock.campaign.sample import RESULT_COLUMNS
from drake_dock.campaign.store import atomic_write
from drake_dock.errors import DrakeDockError, InputError

UNTYPED = "internal error"       # `sample.run_sample`'s message of an untyped failure


def read_rows(path) -> list[dict]:
    """A campaign's rows from its directory (``results.parquet``), a parquet or a CSV file."""
    path = Path(path)
    if path.is_dir():
        path = path / "results.parquet"
    if not path.is_file():
        raise InputError("campaign", str(path), "a campaign directory with results.parquet, "
                         "or a .parquet or .csv file of its rows")
    if path.suffix == ".csv":
        with open(path, newline="") as f:
            return [{k: _cell(path, n, k, v) for k, v in row.items()}
                    for n, row in enumerate(csv.DictReader(f), start=2)]
    return pq.read_table(path).to_pylist()


# The CSV's column types as the store's schema has them (`store.schema`): the sample and its
# seed, the result columns, and every other column a varied input (a float).
_CSV_TYPES = {"sample": int, "seed": int, **RESULT_COLUMNS}


def _cell(path, line: int, column: str, text: str):
    """A CSV cell as its column's type (`write_rows_csv`: an empty cell is None)."""
    if text == "":
        return None
    kind = _CSV_TYPES.get(column, float)
    try:
        return kind(text)
    except ValueError:
        raise InputError(f"{path} line {line}, column {column}", text,
                         f"{'an integer' if kind is int else 'a number'} or an empty cell")


def write_rows_csv(rows: list[dict]) -> bytes:
    """The rows as CSV, floats with repr's round trip, None as an empty cell, without the
    wall time (the one column a re-run does not give bitwise)."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=[k for k in rows[0] if k != "wall_time"],
                       lineterminator="\n", extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: "" if v is None else (repr(v) if isinstance(v, float) else v)
                    for k, v in r.items()})
    return buf.getvalue().encode()


def _spread(values, scale: float, unit: str, digits: int = 0, p95: bool = True) -> str:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], float) * scale
    if not v.size:
        return "-"
    parts = [np.median(v)] + ([np.percentile(v, 95)] if p95 else []) + [v.max()]
    return " / ".join(f"{x:.{digits}f}" for x in parts) + f" {unit}"


def column(rows: list[dict]) -> dict[str, str]:
    """The table's cells of one campaign, by row label."""
    counts = collections.Counter(r["outcome"] for r in rows)
    errors = [r for r in rows if r["outcome"] == "error"]
    is_untyped = [str(r["error"] or "").startswith(UNTYPED) for r in errors]
    untyped = sum(is_untyped)
    typed = collections.Counter(r["reason"] for r, u in zip(errors, is_untyped) if not u)
    named = len(rows) - len(errors)
    k = counts["captured"]
    ci = wilson(k, named)
    cap = [r for r in rows if r["outcome"] == "captured"]
    others = [f"{counts[o]} `{o}`" for o in ORDER if o not in ("captured", "error")
              and counts[o]]
    typed_text = ", ".join(f"{n} (`{kind}`)" for kind, n in sorted(typed.items()))
    return {
        "samples": f"{len(rows)}",
        "captured": f"{k}",
        "other outcomes": ", ".join(others) or "none",
        "typed numerical errors": typed_text or "0",
        "untyped errors": f"{untyped}",
        "capture probability (95 % interval)":
            f"{k / named:.3f} ({ci[0]:.3f}-{ci[1]:.3f})" if named else "-",
        "capture time, median / 95th percentile / max":
            _spread([r["capture_time"] for r in cap], 1.0, "s", 2),
        "peak contact force, median / 95th percentile / max":
            _spread([r["peak_contact_force"] for r in rows], 1.0, "N"),
        "peak Stewart force, median / 95th percentile / max":
            _spread([r["peak_stewart_force"] for r in rows], 1.0, "N"),
        "peak Stewart stroke, median / 95th percentile / max":
            _spread([r["peak_stewart_stroke"] for r in rows], 1e3, "mm"),
        "misalignment at capture, median / max":
            (_spread([r["final_lateral"] for r in cap], 1e3, "mm", 1, p95=False) + ", "
             + _spread([r["final_tilt_deg"] for r in cap], 1.0, "deg", 2, p95=False))
            if cap else "-",
        "momentum drift (less the thrust's impulse), energy-ledger closure, worst":
            ", ".join(_worst([r[c] for r in rows]) for c in ("momentum_drift",
                                                              "energy_closure")),
    }


def _worst(values) -> str:
    v = [x for x in values if x is not None and math.isfinite(x)]
    return f"{max(v):.1e}" if v else "-"


def table(columns: list[tuple[str, list[dict]]]) -> list[str]:
    """The Markdown lines of the table: ``columns`` is (title, rows) per campaign."""
    cells = [column(rows) for _, rows in columns]
    lines = ["| IDSS box | " + " | ".join(t for t, _ in columns) + " |",
             "| --- |" + " --- |" * len(columns)]
    for label in cells[0]:
        lines.append(f"| {label} | " + " | ".join(c[label] for c in cells) + " |")
    return lines


def export(source, target) -> Path:
    """Writes the rows of the campaign ``source`` as CSV (`write_rows_csv`) to ``target``,
    atomically; an existing ``target`` is replaced only if it is such a CSV itself."""
    rows, target = read_rows(source), Path(target)
    data = write_rows_csv(rows)
    if target.exists():
        with open(target, "rb") as f:
            head = f.readline()
        if head != data.split(b"\n", 1)[0] + b"\n":
            raise InputError("target", str(target), "a new file or a campaign rows CSV of "
                             "the same columns (drake-dock replaces nothing it did not write)")
    atomic_write(target, data)
    return target


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m drake_dock.campaign.table",
                                     description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    show = sub.add_parser("show", help="print the Markdown table of the campaigns")
    show.add_argument("columns", nargs="+", metavar="TITLE=SOURCE",
                      help="a column's title and its campaign directory or rows file")
    exp = sub.add_parser("export", help="write a campaign's rows as CSV (no wall times)")
    exp.add_argument("source", help="a campaign directory or its rows file")
    exp.add_argument("target", help="the CSV file to write")
    args = parser.parse_args(argv)
    try:
        if args.command == "export":
            print(f"wrote {export(args.source, args.target)}")
            return 0
        if any("=" not in a for a in args.columns):
            raise InputError("columns", " ".join(args.columns), 'each "TITLE=SOURCE"')
        columns = [(a.split("=", 1)[0], read_rows(a.split("=", 1)[1])) for a in args.columns]
    except DrakeDockError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print("\n".join(table(columns)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The campaign directory: its checks, its Parquet parts (written atomically as batches finish)
and resuming.

Layout: ``.drake_dock_output`` (the marker, kind ``campaign``), ``plan.json`` (what identifies
the campaign: the plan's samples, seed, sampler and distributions and the whole base scenario),
``parts/part-FIRST-LAST.parquet`` (the rows of one finished batch), and at the end
``results.parquet`` (every row, by sample), ``summary.json``, the figures and ``worst/`` (the
scenario of each worst sample). Every file is written under a temporary name and renamed.

The directory must be new, empty, or a campaign of the same plan: then only its missing samples
are run (a rerun resumes). Anything else is refused with `InputError` naming ``--out``, and
nothing drake_dock did not write is ever removed.
"""
from __future__ import annotations

import fnmatch
import json
import os
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from drake_dock import __version__
from drake_dock.campaign.sample import RESULT_COLUMNS
from drake_dock.docking.report.out_dir import MARKER, PRODUCER, check_destination
from drake_dock.errors import InputError

KIND = "campaign"
PARTS = "parts"
TMP_PREFIX = ".tmp-"
# Every entry a campaign directory may hold.
LAYOUT = (MARKER, "plan.json", PARTS, f"{PARTS}/part-*.parquet", f"{PARTS}/{TMP_PREFIX}*",
          "results.parquet", "summary.json", "*.png", "worst", "worst/sample_*.yaml",
          f"{TMP_PREFIX}*", f"worst/{TMP_PREFIX}*")
_TYPES = {str: pa.string(), float: pa.float64(), int: pa.int64()}


def schema(input_columns: list[str]) -> pa.Schema:
    """The rows' schema: sample, seed, the varied inputs, then `RESULT_COLUMNS`."""
    return pa.schema([("sample", pa.int64()), ("seed", pa.int64())]
                     + [(c, pa.float64()) for c in input_columns]
                     + [(c, _TYPES[t]) for c, t in RESULT_COLUMNS.items()])


def atomic_write(path: Path, data: bytes):
    """Writes ``data`` to ``path`` through a temporary sibling and a rename."""
    tmp = path.with_name(f"{TMP_PREFIX}{path.name}")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _entries(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*"))


def _marker_kind(root: Path):
    try:
        data = json.loads((root / MARKER).read_text())
    except (OSError, ValueError):
        return None
    return data.get("kind") if isinstance(data, dict) and data.get("producer") == PRODUCER \
        else None


class CampaignStore:
    """A campaign directory for a plan identified by ``identity`` (a JSON-able dict):
    ``check`` it, then ``create`` it; ``done`` holds the samples already saved."""

    def __init__(self, out, identity: dict, input_columns: list[str]):
        self.root = Path(out)
        self.identity = identity
        self.schema = schema(input_columns)
        self.done: set[int] = set()
        self.existing = False

    def check(self, *, resume: bool) -> "CampaignStore":
        """Refuses a directory that is neither new, empty nor a campaign of the same plan;
        reads the samples saved there. Writes nothing."""
        root = self.root
        self.existing = root.is_dir() and not root.is_symlink() and _marker_kind(root) == KIND
        if resume and not self.existing:
            raise InputError("--resume", str(root), f"a campaign directory (holding {MARKER} "
                             f"of kind '{KIND}') to resume", "nothing to resume there")
        if self.existing:
            self._check_existing()
            self.done = self._saved_samples()
        else:
            check_destination(root)
            if root.is_dir() and any(os.scandir(root)):
                raise InputError("--out", str(root), "a new path, an empty directory or a "
                                 "campaign directory of the same plan",
                                 "a drake_dock output of another kind")
        return self

    def create(self):
        """Makes the directory (if new), clears interrupted writes, writes the marker."""
        root = self.root
        if self.existing:
            for tmp in list(root.glob(f"{TMP_PREFIX}*")) + list(root.glob(f"*/{TMP_PREFIX}*")):
                tmp.unlink()         # a write interrupted before its rename
        else:
            (root / PARTS).mkdir(parents=True, exist_ok=True)
            atomic_write(root / "plan.json", (json.dumps(self.identity, indent=1) + "\n").encode())
        self.write_marker()

    def _check_existing(self):
        root = self.root
        foreign = [e for e in _entries(root)
                   if not any(fnmatch.fnmatchcase(e, p) for p in LAYOUT)]
        if foreign:
            raise InputError("--out", str(root), "a campaign directory holding only what "
                             "drake_dock wrote", f"it also holds {', '.join(foreign[:5])}")
        try:
            saved = json.loads((root / "plan.json").read_text())
        except (OSError, ValueError):
            saved = None
        if saved != self.identity:
            keys = sorted(k for k in self.identity if (saved or {}).get(k) != self.identity[k])
            raise InputError("--out", str(root), "a new path, an empty directory or a campaign "
                             "of the same plan", f"it holds a campaign of another plan "
                             f"({', '.join(keys) or 'plan.json unreadable'} differ)")

    def write_marker(self):
        atomic_write(self.root / MARKER, (json.dumps(
            {"producer": PRODUCER, "version": __version__, "kind": KIND,
             "entries": _entries(self.root)}, indent=1) + "\n").encode())

    def _parts(self) -> list[Path]:
        return sorted((self.root / PARTS).glob("part-*.parquet"))

    def _saved_samples(self) -> set[int]:
        done: set[int] = set()
        for part in self._parts():
            try:
                done.update(pq.read_table(part, columns=["sample"])["sample"].to_pylist())
            except (OSError, pa.ArrowException) as e:
                raise InputError("--out", str(self.root), "a campaign directory with readable "
                                 "parts", f"{part.name}: {e}") from None
        return done

    def write_part(self, rows: list[dict]) -> list[dict]:
        """Saves the rows not saved yet as one part; returns them."""
        rows = sorted((r for r in rows if r["sample"] not in self.done),
                      key=lambda r: r["sample"])
        if not rows:
            return rows
        first, last = rows[0]["sample"], rows[-1]["sample"]
        path = self.root / PARTS / f"part-{first:07d}-{last:07d}.parquet"
        tmp = path.with_name(f"{TMP_PREFIX}{path.name}")
        pq.write_table(pa.Table.from_pylist(rows, schema=self.schema), tmp)
        os.replace(tmp, path)
        self.done.update(r["sample"] for r in rows)
        return rows

    def table(self) -> pa.Table:
        """Every saved row, sorted by sample."""
        parts = [pq.read_table(p) for p in self._parts()]
        if not parts:
            return self.schema.empty_table()
        table = pa.concat_tables([p.cast(self.schema) for p in parts])
        return table.sort_by("sample")

    def write_results(self, table: pa.Table):
        tmp = self.root / f"{TMP_PREFIX}results.parquet"
        pq.write_table(table, tmp)
        os.replace(tmp, self.root / "results.parquet")

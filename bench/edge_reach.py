"""Which guide sides reach which petal edges of the other APDS
(`drake_dock.docking.geometry.reach`): over seeded random poses (roll -60..60 deg, tilt up to
10 deg, offset up to 0.15 m, ring-face distance -0.2..0.45 m), per candidate pair, the poses
where its closest couple is interior and within 2 cm, the rolls where that happens and the
least interior distance found; and whether `contact.pairs: complete` declares the pair
(`drake_dock.docking.geometry.pairs.side_edge_pairs`). The tip arcs against the other APDS's
tip arcs are swept too (`tip_tip_pairs`).

    python bench/edge_reach.py [N]        (default 20000 poses)

It prints no wall time: `make docs` keeps its output as docs/edge_reach.txt.
"""
import math
import sys

from drake_dock.docking.geometry.reach import reach_sweep, side_candidates, tip_candidates
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry

n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
g = ApdsGeometry()
declared = {p.name for p in DockingScene(g, "complete").pairs}
rows = reach_sweep(g, side_candidates(g) + tip_candidates(g), n)
print(f"{n} poses, {len(rows)} candidate pairs")
for name, (hits, least, (lo, hi)) in sorted(rows.items(), key=lambda r: (-r[1][0], r[0])):
    rolls = f"roll {lo:6.1f} .. {hi:6.1f} deg" if hits else " " * 25
    least = f"{least * 1e3:7.2f} mm" if math.isfinite(least) else "   never interior"
    print(f"{name:13s} {'declared' if name in declared else '        '} {hits:5d} within 2 cm,"
          f" {rolls}, least interior distance {least}")
missed = sorted(k for k, v in rows.items() if v[0] and k not in declared)
extra = sorted(k for k, v in rows.items() if not v[0] and k in declared)
print(f"reached but not declared: {missed or 'none'}; declared but not reached: {extra or 'none'}")

"""What the placement (`place`: the first contact of the scenario's contact set on a straight
approach, the consistent aim with a lateral velocity, and the independent check of the path
down to it) costs: the paper example, and the first ``--conditions`` conditions of
`drake-dock study conditions` (seed 2026, inside the IDSS box; 75 for all but the first), with
the contact set ``--pairs`` (`complete`, as the IDSS envelope plan, or `paper`). Per placement
(on a fresh `PlacementCache` of the scenario's scene) it prints the wall time, the
first-contact searches it ran (those its cache served not counted; those of a bracket among
some pairs, and those stopped at a height, `_among_height`, also apart) and their time, and
the path check's time; then one search alone on each final approach (on a fresh cache), and,
for a placement whose bracket is closed among some pairs, the same placement with the bracket
closed with the whole set; then the medians. A first placement loads the compiled kernels and
is not counted.

    python bench/placement.py [--conditions 12] [--pairs complete|paper]
"""
import argparse
import time
from unittest import mock

import numpy as np

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement import aim, path_check, search
from drake_dock.docking.placement.place import PlacementCache, contact_approach, place
from drake_dock.docking.placement.search import first_contact
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition


class _Timed:
    """Wraps f: its calls and their wall time; for the search (`search._search`: scene,
    approach, among, stop, step, xtol), the searches with the whole set, among some pairs and
    stopped at a travel."""

    def __init__(self, f):
        self.f, self.calls, self.wall = f, 0, 0.0
        self.whole = self.among = self.stopped = 0

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return self.f(*args, **kwargs)
        finally:
            self.calls += 1
            self.wall += time.perf_counter() - t0
            if len(args) == 6:
                if args[2] is not None:
                    self.among += 1
                elif args[3] is not None:
                    self.stopped += 1
                else:
                    self.whole += 1


def _cache(s):
    return PlacementCache(DockingScene.of(s))


def _whole_set_bracket(s):
    """The placement's wall time and searches with the bracket closed with the whole set
    (`_bracketed_height` for `_among_height`), on a fresh cache."""
    timed = _Timed(search._search)
    cache = _cache(s)
    with mock.patch.object(search, "_search", timed), \
            mock.patch.object(aim, "_among_height", aim._bracketed_height):
        t0 = time.perf_counter()
        place(s, cache)
        wall = time.perf_counter() - t0
    return wall, timed.whole + timed.among + timed.stopped


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--conditions", type=int, default=12)
    ap.add_argument("--pairs", choices=("complete", "paper"), default="complete")
    args = ap.parse_args(argv)
    base = load_scenario(PAPER_EXAMPLE)
    base.contact.pairs = args.pairs
    plan = conditions(ConditionsPlan())
    place(with_condition(base, plan[0][1]))                          # kernels loaded
    cases = [("paper example", base)] + [(n, with_condition(base, c))
                                         for n, c in plan[1:1 + args.conditions]]
    totals, checks, alone, counts = [], [], [], []
    for name, s in cases:
        cache = _cache(s)
        timed, check = _Timed(search._search), _Timed(path_check._crossing)
        with mock.patch.object(search, "_search", timed), \
                mock.patch.object(path_check, "_crossing", check):
            t0 = time.perf_counter()
            place(s, cache)
            total = time.perf_counter() - t0
        searches = timed.whole + timed.among + timed.stopped
        approach = contact_approach(s, cache)[0]
        fresh = _cache(s)
        t0 = time.perf_counter()
        first_contact(fresh, approach)
        one = time.perf_counter() - t0
        totals.append(total)
        counts.append(searches)
        checks.append(check.wall)
        alone.append(one)
        print(f"{name}: placement {1e3 * total:.0f} ms; {searches} searches ({timed.among} "
              f"among some pairs, {timed.stopped} stopped) {1e3 * timed.wall:.0f} ms; path "
              f"check {1e3 * check.wall:.0f} ms; one search alone {1e3 * one:.0f} ms",
              flush=True)
        if timed.among:
            whole, searches_whole = _whole_set_bracket(s)
            print(f"    with the whole set in the bracket: {1e3 * whole:.0f} ms, "
                  f"{searches_whole} searches ({whole / total:.2f} times the placement)")
    print(f"median over {len(cases)}: placement {1e3 * np.median(totals):.0f} ms (fastest "
          f"{1e3 * min(totals):.0f}, slowest {1e3 * max(totals):.0f}); path check "
          f"{1e3 * np.median(checks):.0f} ms; one search {1e3 * np.median(alone):.0f} ms")
    print(f"{counts.count(2)} of {len(cases)} placed in two searches; "
          f"{sum(t < 0.1 for t in totals)} under 0.1 s")


if __name__ == "__main__":
    main()

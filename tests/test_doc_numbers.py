"""The numbers docs/results.md's prose quotes from the committed outputs under docs/, against
those outputs: the stability study's `docs/stability_summary.txt`, the funnel study's
`docs/funnel.csv` (with the shipped plan read from `drake_dock/studies/funnel.py`'s source),
the two campaigns' `docs/campaign_paper.csv` and `docs/campaign_funnel.csv`, the
crosscheck's `docs/crosscheck.csv`, the roll study's `docs/roll.csv`, the examples study's
`docs/examples.csv`, the conditions sweep's `docs/conditions.csv`, the edge reach sweep's
`docs/edge_reach.txt` and the speed-accuracy study's `docs/speed_accuracy_points.csv` and
`docs/speed_accuracy_speedups.txt`.

`make docs` rewrites those files; the prose around them is copied by hand. Each quoted number
is found by a short literal phrase of its section (`{}` a number, `{w}` a name), which must
occur there exactly once, so a reworded sentence fails here naming the phrase. Each is then
compared, at the precision it is quoted with (2.2e-6: two significant digits; 0.26: two
decimals), with the value computed from the file the way the prose describes it. The
headline table, the campaign table and the pair counts have their own tests
(tests/docking/test_paper_example.py, tests/campaign/test_campaign_table.py,
tests/docking/test_doc_counts.py). Nothing here needs Drake: the files are read with csv, the
paper example's geometry with yaml."""
import ast
import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.stats import binomtest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
RESULTS = (DOCS / "results.md").read_text()
NUM = r"([-+]?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?)"
WORD = r"([\w*]+)"


def section(title: str) -> str:
    """The text of results.md's section ``## title``, up to the next ``## ``."""
    m = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", RESULTS, flags=re.M | re.S)
    assert m, f"docs/results.md has no section '## {title}'"
    return m.group(1)


def _regex(phrase: str) -> str:
    parts = re.split(r"(\{w?\})", phrase)
    return "".join(NUM if p == "{}" else WORD if p == "{w}"
                   else re.escape(p).replace(r"\ ", r"\s+") for p in parts)


def agrees(quoted: str, value) -> bool:
    """Whether ``value`` rounds to the number quoted, at the quoted precision; a name or a
    bool equals its text."""
    if isinstance(value, (str, bool)):
        return quoted == str(value)
    q = quoted.replace(",", "").lstrip("+")
    mantissa, e, _ = q.lower().partition("e")
    digits = len(mantissa.partition(".")[2])
    return float(f"{value:.{digits}{'e' if e else 'f'}}") == float(q)


class Quotes:
    """Collects the disagreements of one section's quoted numbers, to report them together."""

    def __init__(self, title: str):
        self.title, self.text, self.bad, self.checked = title, section(title), [], 0

    def check(self, phrase: str, *values):
        """The phrase occurs once in the section and its numbers are ``values``."""
        found = re.findall(_regex(phrase), self.text)
        if len(found) != 1:
            self.bad.append(f"'{phrase}' occurs {len(found)} times in '## {self.title}', "
                            "not once: reworded? check its numbers against the output again")
            return
        if not values:
            return
        quoted = found[0] if isinstance(found[0], tuple) else (found[0],)
        assert len(quoted) == len(values), phrase
        for q, v in zip(quoted, values):
            self.checked += 1
            if not agrees(q, v):
                self.bad.append(f"'{phrase}': quoted {q}, the output gives {v!r}")

    def done(self):
        assert not self.bad, "\n".join(self.bad)


def _num(text: str):
    """A CSV cell: None if empty, a number where it is one, else the text."""
    if text == "":
        return None
    try:
        return float(text)
    except ValueError:
        return text


def read_csv(name: str) -> list[dict]:
    with open(DOCS / name, newline="") as f:
        return [{k: _num(v) for k, v in row.items()} for row in csv.DictReader(f)]


def wilson(k: int, n: int):
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return ci.low, ci.high


# 1. Stability where methods fail: docs/stability_summary.txt ---------------------------------
STABILITY = (DOCS / "stability_summary.txt").read_text()


def _summary(pattern: str) -> tuple:
    m = re.search(pattern, STABILITY)
    assert m, f"docs/stability_summary.txt has no line matching {pattern!r}"
    return m.groups()


def test_stability_numbers_are_the_summary_files():
    s = Quotes("Stability where methods fail")
    sawtooth, top_step = _summary(r"drake_dock at most (\S+) at output steps up to (\S+) s")
    s.check("Its index is at most {} at output steps (step caps) from 1e-3 to {} s",
            float(sawtooth), float(top_step))
    lo, hi, lzb = _summary(r"stiffness ratio (\S+?e[-+]\d+)-(\S+): LZB within (\S+) of")
    s.check("contact stiffness ratio K2/K1 from {} to {}.", float(lo), float(hi))
    s.check("DOP853) within {} over the whole range", float(lzb))
    mu_c, k, n = _summary(r"mu_c = (\S+);.*\((\d+) of (\d+) values\)")
    s.check("consistent only for mu < mu_c = {}.", float(mu_c))
    s.check("for the {} of {} values there", int(k), int(n))
    captures = re.findall(r"docking at mu = (\S+): captured at (\S+) s", STABILITY)
    assert len(captures) == 4, captures
    s.check("It captures at {}, {}, {} and {} s for mu = {}, {}, {} and {}.",
            *[float(t) for _, t in captures], *[float(mu) for mu, _ in captures])
    grazing, = _summary(r"\(d\) grazing: impacts detected for delta < 0 only: (\w+)")
    assert grazing == "True", "the summary no longer finds impacts for delta < 0 only"
    s.check("For delta >= +1e-9 m there is no impact.")
    zeno, max_impacts, couple = _summary(r"closed form: (\w+); guard off: more than "
                                         r"max_impacts = (\d+) impacts \[.*couples (\w+)\]")
    assert zeno == "True", "the summary's Zeno impact counts no longer equal the closed form"
    s.check("the number of impacts equals the closed form")
    s.check("at `max_impacts` ({}), naming the couple (`{w}`) and the time of the {}th impact",
            int(max_impacts), couple, int(max_impacts) + 1)
    s.done()
    # The headline table repeats case (c)'s capture time at mu = 0.1.
    h = Quotes("The paper's example (Sect. 8.2)")
    h.check("| capture (axial ring-centre distance 5 mm) | t = {} s |",
            float(dict(captures)["0.1"]))
    h.done()


# 2. The funnel: docs/funnel.csv and the shipped plan -----------------------------------------
def shipped_plan() -> dict:
    """`FunnelPlan.shipped()`'s fields, read from funnel.py's source (importing it needs
    Drake): the class's defaults, with the keywords `shipped` passes."""
    tree = ast.parse((ROOT / "drake_dock" / "studies" / "funnel.py").read_text())
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "FunnelPlan")
    plan = {n.target.id: ast.literal_eval(n.value) for n in cls.body
            if isinstance(n, ast.AnnAssign)}
    shipped = next(n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "shipped")
    call = next(n for n in ast.walk(shipped) if isinstance(n, ast.Call))
    plan.update({k.arg: ast.literal_eval(k.value) for k in call.keywords})
    return plan


def probes(found: float, hi: float, steps: int) -> list:
    """The offsets `funnel.capture_range` tries on [0, hi] when it finds ``found``, the
    coaxial run capturing (as the prose says): 0, hi, then the halvings."""
    tried = [0.0, hi]
    if found >= hi - 1e-12:
        return tried
    lo = 0.0
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        tried.append(mid)
        lo, hi = (mid, hi) if mid <= found + 1e-12 else (lo, mid)
    return tried


def test_funnel_numbers_are_the_funnel_csvs():
    plan = shipped_plan()
    points = read_csv("funnel.csv")
    assert len(points) == 2 * len(plan["thrusts"])
    pt = {(p["geometry"].split()[0], p["thrust_N"]): p for p in points}
    runs = {}          # (geometry, thrust, direction) -> [offsets probed], in m
    for (geometry, thrust), p in pt.items():
        ranges = [float(x) for x in p["ranges_by_direction_m"].strip("[]").split(",")]
        for d, r in zip(plan["directions_deg"], ranges):
            runs[geometry, thrust, d] = (r, probes(r, p["clearance_m"] + plan["beyond"],
                                                   plan["steps"]))
    mm = 1e3
    f = Quotes("The funnel")
    paper, funnel = pt["paper", 0.0], pt["funnel", 0.0]
    f.check("Rs = Rp = {} m, H = {} m, so the tips clear", funnel["Rs"], funnel["H"])
    f.check("c = H cot(alpha1) = {} mm), without thrust and with {} N for {} s, offsets at {} deg "
            "(the middle of a petal) and {} deg (between two petals), {} halvings between 0 and "
            "c + {} mm, a {} m/s probe approach with {} deg of roll",
            mm * funnel["clearance_m"], plan["thrusts"][1], plan["thrust_duration"],
            *plan["directions_deg"], plan["steps"], mm * plan["beyond"],
            plan["closing_speed"], plan["roll_deg"])
    for label, thrust in (("paper (Rs {} m, petals on R)", 0.0), ("paper", 300.0)):
        r30, r90 = (mm * runs["paper", thrust, d][0] for d in plan["directions_deg"])
        first_off = mm * min(o for o in runs["paper", thrust, 90.0][1] if o > 0)
        how = "none" if thrust == 0 else "300 N for 3 s"
        f.check(f"| {label} | {{}} | {how} | {{}} / {{}}: coaxial captures, {{}} mm off does not |",
                *([paper["Rs"]] if thrust == 0 else []), mm * pt["paper", thrust]["clearance_m"],
                r30, r90, first_off)
    for label, thrust in (("funnel (Rs = Rp {} m, H {} m)", 0.0), ("funnel", 300.0)):
        (r30, _), (r90, tried) = (runs["funnel", thrust, d] for d in plan["directions_deg"])
        how = "none" if thrust == 0 else "300 N for 3 s"
        f.check(f"| {label} | {{}} mm | {how} | at least {{}} / {{}} mm ({{}} mm does not) |",
                *([funnel["Rs"], funnel["H"]] if thrust == 0 else []),
                mm * pt["funnel", thrust]["clearance_m"], mm * r30, mm * r90,
                mm * min(o for o in tried if o > r90 + 1e-12))
    f.check("off the axis by the smallest offset probed, {} mm, no run captures",
            mm * min(o for o in runs["paper", 0.0, 30.0][1] if o > 0))
    r90 = runs["funnel", 0.0, 90.0][0]
    f.check("captures up to {} mm between the petals, {} % of its clearance",
            mm * r90, 100 * r90 / funnel["clearance_m"])
    (r30, _), (r90, _) = (runs["funnel", 300.0, d] for d in plan["directions_deg"])
    f.check("with 300 N up to its full clearance, {} mm, and over a petal up to the bisection's "
            "end, {} mm", mm * r90, mm * r30)
    assert abs(r90 - pt["funnel", 300.0]["clearance_m"]) < 1e-9, "300 N: range != clearance"
    past = [o for (g, _, d), (_, tried) in runs.items() if g == "funnel" and d == 90.0
            for o in tried if o > pt["funnel", 0.0]["clearance_m"] + 1e-9]
    f.check("{} of the {} probes, all at {} mm or more, between the petals",
            len(past), sum(len(t) for _, t in runs.values()), mm * min(past))
    at_c = [o for d in plan["directions_deg"] for o in runs["funnel", 0.0, d][1]
            if abs(o - funnel["clearance_m"]) < 1e-9]
    f.check("the one run at exactly {} mm without thrust", mm * funnel["clearance_m"])
    assert len(at_c) == 1, f"{len(at_c)} probes at the clearance without thrust, not one"
    captured = sum(r["outcome"] == "captured" for r in read_csv("campaign_funnel.csv"))
    f.check("the IDSS campaign {} of its 1,000 samples", captured)
    f.done()


# 3. The IDSS envelope campaigns: docs/campaign_paper.csv, docs/campaign_funnel.csv -----------
CAMPAIGNS = "The IDSS envelope campaigns: the paper geometry and the funnel"


def _error_times_couples(rows):
    """[(t, couples)] of the typed errors: the time and couples their message ends with."""
    out = []
    for r in rows:
        m = re.search(r"\[t = (\S+) s; couples ([^\]]+)\]$", r["error"])
        assert m, f"sample {r['sample']:.0f}: no time and couples in {r['error']!r}"
        out.append((float(m.group(1)), m.group(2).split(", ")))
    return out


def _kinetic(rows):
    return [float(re.search(r"relative kinetic energy (\S+) J", r["reason"]).group(1))
            for r in rows]


def test_campaign_bullets_are_the_campaigns_rows():
    c = Quotes(CAMPAIGNS)
    rows = read_csv("campaign_paper.csv")
    by = {o: [r for r in rows if r["outcome"] == o]
          for o in ("captured", "jammed", "missed", "rebound", "error")}
    n = len(rows)
    c.check("**The paper's geometry captures none of the {} samples** (the 95 % interval's "
            "upper end is {})", n, wilson(len(by["captured"]), n - len(by["error"]))[1])
    assert not by["captured"], "the paper geometry's campaign captures"
    jam = by["jammed"]
    c.check("{} samples end `jammed`: {} of them with the rings within {} cm of the petal "
            "height ({} m) apart", len(jam),
            sum(abs(r["final_axial"] - 0.2) <= 0.05 for r in jam), 5, 0.2)
    free = [r for r in jam if "held by no couple" in r["reason"]]
    c.check("{} of the {} held by no couple at the end", len(free), len(jam))
    c.check("with {} to {} J of relative kinetic energy left after the thrust)",
            min(_kinetic(free)), max(_kinetic(free)))
    off = [r["final_lateral"] for r in by["missed"]]
    c.check("{} end `missed`: the thrust pushes", len(off))
    c.check("passes the target's ring plane {} to {} m off the axis.", min(off), max(off))
    apart = [r["final_axial"] for r in by["rebound"]]
    c.check("{} end `rebound` once the thrust has ended, the rings {} to {} m apart",
            len(apart), min(apart), max(apart))
    err = by["error"]
    c.check("{} samples ({} %) stop in a typed `PainleveInconsistency`",
            len(err), 100 * len(err) / n)
    assert {r["reason"] for r in err} == {"PainleveInconsistency"}
    found = list(zip(err, _error_times_couples(err)))
    lips = [t for _, (t, couples) in found if sorted(re.sub(r"\d+$", "*", x) for x in couples)
            == ["cc_Cring_Ttip*", "cc_Tring_Ctip*"]]
    rest = [(r, t, couples) for r, (t, couples) in found if t not in lips]
    c.check("{} with the tips of both APDS on both lips at once", len(lips))
    c.check("`cc_Cring_Ttip*` with `cc_Tring_Ctip*`, at {} to {} s), and one (sample {}, at {} s)",
            min(lips), max(lips), rest[0][0]["sample"], rest[0][1])
    c.check("(`{w}`, `{w}`, `{w}`). No error is untyped.", *rest[0][2])
    assert len(rest) == 1, "the prose names one error off the lips"
    assert not any(r["error"] and r["error"].startswith("internal error") for r in rows)
    force = [r for r in rows if r["peak_contact_force"] is not None]
    top = max(force, key=lambda r: r["peak_contact_force"])
    c.check("The largest peak contact force, {} N (sample {} at",
            top["peak_contact_force"], top["sample"])
    c.check("the 95th percentile is {} N.",
            np.percentile([r["peak_contact_force"] for r in force], 95))
    drift = [r["momentum_drift"] for r in rows if r["momentum_drift"] is not None]
    c.check("stays at {} at most (the quadrature", max(drift))
    ledger = sorted((r for r in rows if r["energy_closure"] is not None),
                    key=lambda r: r["energy_closure"])
    worst = ledger[-1]
    second = ledger[-2]
    c.check("closes to {} or better but in two samples: {}, a jam after {} impacts, at {}, and "
            "{}, a miss after {} impacts, at {}.", ledger[-3]["energy_closure"],
            worst["sample"], worst["impacts"], worst["energy_closure"], second["sample"],
            second["impacts"], second["energy_closure"])
    assert (worst["outcome"], second["outcome"]) == ("jammed", "missed")

    rows = read_csv("campaign_funnel.csv")
    n, cap = len(rows), [r for r in rows if r["outcome"] == "captured"]
    named = n - sum(r["outcome"] == "error" for r in rows)     # the table's: errors left out
    c.check("**The funnel variant captures {} of the {} samples**", len(cap), n)
    c.check("capture probability {} (95 % interval {}-{})", len(cap) / named,
            *wilson(len(cap), named))
    jam = sorted((r for r in rows if r["outcome"] == "jammed"), key=lambda r: r["sample"])
    short = [1e3 * float(re.search(r"distance to capture .*?\(at (\S+) m", r["reason"]).group(1))
             for r in jam]
    c.check("samples ({}, {}, {}) end `jammed` {} to {} mm short of the capture distance",
            *[r["sample"] for r in jam], min(short), max(short))
    assert all("held by no couple" in r["reason"] for r in jam)
    c.check("held by no couple, with {} to {} J of relative kinetic energy left after the "
            "thrust has ended", min(_kinetic(jam)), max(_kinetic(jam)))
    assert not any(r["outcome"] == "error" for r in rows), "the prose says none is an error"
    c.check("thrust has ended; none stops in an error. The loads")
    force = [r["peak_contact_force"] for r in rows if r["peak_contact_force"] is not None]
    c.check("the peak contact force is {} N at the median and {} N at most",
            np.median(force), max(force))
    stroke = [1e3 * r["peak_stewart_stroke"] for r in rows if r["peak_stewart_stroke"] is not None]
    c.check("strokes {} mm at the median and {} mm at most", np.median(stroke), max(stroke))
    c.done()


# 4. A referee, Drake's compliant contact: docs/crosscheck.csv ---------------------------------
CROSSCHECK = "A referee: Drake's compliant contact"


def crosscheck():
    """The crosscheck's rows (each counts and agrees) and its columns as arrays."""
    rows = read_csv("crosscheck.csv")
    assert all(r["counts"] == "True" for r in rows), "a compliant run no longer counts"
    return rows, lambda k: np.array([r[k] for r in rows], float)


def test_crosscheck_numbers_are_the_crosscheck_csvs():
    rows, col = crosscheck()
    n = len(rows)
    agree = sum(r["agree"] == "True" for r in rows)
    diff, near = np.abs(col("capture_time_difference")), np.abs(col("near_capture_time_difference"))
    x = Quotes(CROSSCHECK)
    x.check("outcome agreement: {}/{} ({}%;", agree, n, 100 * agree / n)
    x.check("median capture-time difference: {} % ({} conditions captured by both; largest {} %, "
            "{} within 10 %; signed median {} %", 100 * np.median(diff), n, 100 * diff.max(),
            int(np.sum(diff <= 0.1)), 100 * np.median(col("capture_time_difference")))
    x.check("median near-capture-time difference: {} % (the first time within 1 mm of the "
            "capture box; {} conditions where both come near; largest {} %)",
            100 * np.median(near), n, 100 * near.max())
    x.check("compliant runs that count: {}/{}", n, n)
    x.check("the outcomes agree in all {} conditions", agree)
    largest = rows[int(np.argmax(diff))]["name"]
    x.check("{} of the {} capture times agree within 10 %: the median difference is {} %, the "
            "largest {} % ({w} {}, below), and {} of them agree within 1 %.",
            int(np.sum(diff <= 0.1)), n, 100 * np.median(diff), 100 * diff.max(),
            *largest.split(), int(np.sum(diff <= 0.01)))
    rigid, compliant = col("rigid_peak_interface_force_N"), col("compliant_peak_interface_force_N")
    x.check("peaks at {} to {} N.", rigid.min(), rigid.max())
    x.check("at {} to {} kN.", compliant.min() / 1e3, compliant.max() / 1e3)
    q = col("refined_peak_interface_force_N") / compliant
    x.check("the refined runs give {} to {} times it (median {},", q.min(), q.max(), np.median(q))
    m = col("rigid_peak_mean_interface_force_N")
    q1, q2 = col("compliant_peak_mean_interface_force_N") / m, col(
        "refined_peak_mean_interface_force_N") / m
    x.check("Drake's value is {} to {} times drake_dock's (median {}); the refined runs' {} to {} "
            "(median {})", q1.min(), q1.max(), np.median(q1), q2.min(), q2.max(), np.median(q2))
    r11, = [r for r in rows if r["name"] == "random 11"]
    t = {w: r11[f"{w}_capture_time_s"] for w in ("rigid", "compliant", "refined")}
    tn = {w: r11[f"{w}_near_capture_time_s"] for w in ("rigid", "compliant", "refined")}
    x.check("| random 11 | captured {} s | captured {} s ({} %) | captured {} s ({} %) | "
            "{} / {} / {} s |", t["rigid"], t["compliant"], 100 * r11["capture_time_difference"],
            t["refined"], 100 * (t["refined"] / t["rigid"] - 1), *tn.values())
    x.check("at the same time ({} and {} s)", tn["rigid"], tn["refined"])
    x.check("enter the box on an early swing, at {} and {} s;", t["compliant"], t["refined"])
    x.check("the thrust brings it in on a later swing, at {} s.", t["rigid"])
    assert max(t["compliant"], t["refined"]) < t["rigid"], "the compliant runs capture first"
    x.check("the outcomes agree in {} of {} conditions ({} %), and {} of the {} capture times "
            "agree within 10 % (median {} %)", agree, n, 100 * agree / n,
            int(np.sum(diff <= 0.1)), n, 100 * np.median(diff))
    impacts = col("rigid_impacts")
    x.check("runs have a median of {} impacts ({} to {})", np.median(impacts), impacts.min(),
            impacts.max())
    x.done()


def test_crosscheck_refined_runs_beyond_one_per_cent():
    """The refined compliant runs against the compliant ones: how many conditions agree within
    1 %, the median, the largest difference but one, and the largest."""
    rows, col = crosscheck()
    refined = np.abs(col("refined_capture_time_s") / col("compliant_capture_time_s") - 1)
    order = np.argsort(refined)
    worst = rows[order[-1]]["name"]
    x = Quotes(CROSSCHECK)
    x.check("within {} % of the compliant runs in {} of the {} conditions (median {} %); {} "
            "others differ by at most {} %, and {w} {} by {} %.", 1,
            int(np.sum(refined <= 0.01)), len(rows), 100 * np.median(refined),
            int(np.sum(refined > 0.01)) - 1, 100 * refined[order[-2]], *worst.split(),
            100 * refined[order[-1]])
    x.done()


# 5. Beyond the box, the relative roll: docs/roll.csv ------------------------------------------
ROLL = "Beyond the box: the relative roll"


def two_theta_end_deg() -> float:
    """2 theta_end of the paper example's geometry (deg): theta_end = arcsin(R sin(alpha2) /
    (R - H cot(alpha1))) - alpha2, the angular extent of a guide side (Eq. 15 as the paper
    example's geometry reads it)."""
    g = yaml.safe_load((ROOT / "drake_dock/models/paper_example.yaml").read_text())["geometry"]
    a1, a2 = np.radians(g["alpha1_deg"]), np.radians(g["alpha2_deg"])
    return 2 * np.degrees(np.arcsin(g["R"] * np.sin(a2) / (g["R"] - g["H"] / np.tan(a1))) - a2)


def test_roll_numbers_are_the_roll_csv():
    rows = read_csv("roll.csv")
    by = {r["target_yaw_deg"]: r for r in rows}
    captured = sorted(r["target_yaw_deg"] for r in rows if r["outcome"] == "captured")
    jammed = sorted(abs(r["target_yaw_deg"]) for r in rows if r["outcome"] == "jammed")
    x = Quotes(ROLL)
    x.check("whole roll range, {} to {} deg every {} deg ({} runs)", min(by), max(by),
            sorted(by)[2] - sorted(by)[1], len(rows))
    x.check("Every run ends in a named outcome: {} captured ({} to {} deg) and {} jammed",
            len(captured), captured[0], captured[-1], len(jammed))
    x.check("Momentum holds to {} (linear) and {} (angular), and the energy ledger closes to {}.",
            max(r["momentum_drift_linear"] for r in rows),
            max(r["momentum_drift_angular"] for r in rows),
            max(abs(r["energy_closure"]) for r in rows))
    x.check("captured at {} s with no contact", by[0.0]["capture_time_s"])
    inner = [by[r] for r in sorted(by) if 0 < r <= captured[-1]]
    x.check("From {} to {} deg the petals meet guide side on guide side, {} impacts", inner[0][
        "target_yaw_deg"], inner[-1]["target_yaw_deg"], inner[0]["impacts"])
    x.check("grows with the roll, from {} s to {} s", inner[0]["capture_time_s"],
            inner[-1]["capture_time_s"])
    x.done()
    # What the prose says without a number: no outcome an error, no run found interpenetrating
    # by either check, the impacts of the guide-on-guide runs, the jams all beyond 2 theta_end
    # (the paper's closed form on the example's geometry), and outcomes and capture times
    # symmetric in the roll.
    assert all(r["outcome"] in ("captured", "jammed") for r in rows)
    assert all(r["penetration_m"] <= 0 for r in rows)
    assert {r["impacts"] for r in inner} == {inner[0]["impacts"]}
    assert by[0.0]["impacts"] == 0
    assert min(jammed) > two_theta_end_deg()
    for r in rows:
        m = by[-r["target_yaw_deg"]]
        assert m["outcome"] == r["outcome"]
        if r["outcome"] == "captured":
            assert m["capture_time_s"] == pytest.approx(r["capture_time_s"], rel=1e-6)


# 6. The named examples and the free drift: docs/examples.csv ---------------------------------
def test_example_numbers_are_the_examples_csv():
    by = {r["name"]: r for r in read_csv("examples.csv")}
    mm = 1e3
    x = Quotes("The named off-axis examples")
    box, lat, tilt = by["idss_box_corner"], by["idss_lateral"], by["idss_tilted"]
    x.check("`idss_box_corner` ends `jammed` at {} s after {} impacts, the rings {} m apart "
            "axially", box["end_time_s"], box["impacts"], box["final_axial_m"])
    x.check("momentum kept to {} (linear) and {} (angular) and the energy ledger closed to {}.",
            box["momentum_drift_linear"], box["momentum_drift_angular"], box["energy_closure"])
    x.check("`idss_lateral` after {} impacts at {} s ({} m), `idss_tilted` after {} impacts at "
            "{} s ({} m); their ledgers close to {} and {}.", lat["impacts"], lat["end_time_s"],
            lat["final_axial_m"], tilt["impacts"], tilt["end_time_s"], tilt["final_axial_m"],
            lat["energy_closure"], tilt["energy_closure"])
    by_couple = json.loads(box["impacts_by_couple"])
    x.check("`cc_Cring_Ttip3`, the chaser's ring on target tip arc 3, takes part in {} of the {} "
            "and `cc_T2_C4` in {}, and {} land", by_couple["cc_Cring_Ttip3"], box["impacts"],
            by_couple["cc_T2_C4"], by_couple["pc_Tcorner6_Cring"])
    H = yaml.safe_load((ROOT / "drake_dock/models/idss_lateral.yaml").read_text())["geometry"]["H"]
    x.check("about H = {} m apart", H)
    x.done()
    # What the prose says without a number: the three jam, neither check finds a crossing,
    # and the two at the tip arcs stop within a centimetre of H.
    assert all(r["outcome"] == "jammed" and r["penetration_m"] == 0 for r in (box, lat, tilt))
    assert abs(lat["final_axial_m"] - H) < 0.01 and abs(tilt["final_axial_m"] - H) < 0.01
    d = Quotes("Free drift at the IDSS box's slowest closing rate")
    slow, slow1, mid = (by["slow 0.05 m/s"], by["slow 0.05 m/s, roll 1 deg"],
                        by["slow 0.08 m/s"])
    d.check("the rings stall at an axial ring distance of {} mm (capture: {} mm)",
            mm * slow["final_axial_m"], mm * yaml.safe_load(
                (ROOT / "drake_dock/models/paper_example.yaml").read_text()
            )["simulation"]["capture_distance"])
    d.check("ends `jammed` at {} s", slow["end_time_s"])
    d.check("At 1 deg roll the same rate is captured, at {} s, and so is {} m/s at 5 deg, at {} s",
            slow1["capture_time_s"], mid["chaser_speed"], mid["capture_time_s"])
    d.done()
    assert (slow["outcome"], slow1["outcome"], mid["outcome"]) == ("jammed", "captured",
                                                                   "captured")
    assert slow["chaser_speed"] == slow1["chaser_speed"] == 0.05
    assert (slow["target_yaw_deg"], slow1["target_yaw_deg"], mid["target_yaw_deg"]) == (5, 1, 5)


# 7. The working conditions: docs/conditions.csv ----------------------------------------------
def test_conditions_numbers_are_the_conditions_csv():
    rows = read_csv("conditions.csv")
    cap = [r for r in rows if r["outcome"] == "captured"]
    mm, um = 1e3, 1e6

    def span(key, scale=1.0):
        v = [scale * r[key] for r in cap]
        return min(v), max(v), float(np.median(v))
    tilt = [r["final_tilt_deg"] for r in cap]
    c = Quotes("Working conditions: the IDSS initial-contact box")
    c.check("The conditions study runs {} seeded random conditions inside",
            sum(r["name"].startswith("random") for r in rows))
    c.check("and {} of its corners", sum(r["name"].startswith("corner") for r in rows))
    c.check("All {} runs are captured", len(cap))
    assert len(cap) == len(rows), "the prose says every run is captured"
    lo, hi, med = span("capture_time_s")
    c.check("Capture comes {} to {} s after the start (median {} s)", lo, hi, med)
    lo, hi, med = span("impacts")
    c.check("after {} to {} impacts (median {})", lo, hi, med)
    lo, hi, med = span("final_lateral_m", mm)
    c.check("with the rings {} to {} mm off the axis (median {} mm)", lo, hi, med)
    c.check("and {} to {} deg tilted", min(tilt), max(tilt))
    lo, hi, med = span("peak_contact_force_N")
    c.check("The peak contact force is {} to {} N (median {} N)", lo, hi, med)
    deep = max(rows, key=lambda r: r["penetration_m"])
    c.check("the deepest crossing is {} mm (random {}", mm * deep["penetration_m"],
            int(deep["name"].split()[1]) if deep["name"].startswith("random") else None)
    c.check("at {} s; both checks agree)", float(re.search(r"t = (\S+) s", deep["penetration"])
                                                 .group(1)))
    assert deep["name"].startswith("random")
    assert (abs(deep["penetration_analytic_m"] - deep["penetration_mesh_m"])
            < 0.05 * deep["penetration_m"]), "the prose says both checks agree"
    rest = [r["penetration_m"] for r in rows if r is not deep]
    c.check("{} of them at 0.", sum(p == 0 for p in rest))
    quoted = float(re.search(r"every other run stays\s+below (\S+) um", c.text).group(1))
    assert max(rest) * um < quoted, f"a run other than the deepest crosses {max(rest) * um} um"
    c.check("drifts by at most {} and the angular momentum by {} (relative)",
            max(r["momentum_drift_linear"] for r in rows),
            max(r["momentum_drift_angular"] for r in rows))
    closure = [abs(r["energy_closure"]) for r in rows]
    c.check("closes to {} at worst (median {})", max(closure), float(np.median(closure)))
    c.done()


# 8. The edge reach sweep: docs/edge_reach.txt -----------------------------------------------
def reach_rows() -> dict:
    """{pair: (declared, poses within 2 cm, (least, greatest) roll or None, least interior
    distance in mm or None)} of `bench/edge_reach.py`'s lines."""
    rows = {}
    for line in (DOCS / "edge_reach.txt").read_text().splitlines()[1:-1]:
        m = re.match(r"(\S+)\s+(declared)?\s+(\d+) within 2 cm,\s*(?:roll\s+(\S+) \.\.\s+(\S+) "
                     r"deg)?\s*, least interior distance\s+(\S+)", line)
        assert m, f"docs/edge_reach.txt: unread line {line!r}"
        name, declared, hits, lo, hi, least = m.groups()
        rows[name] = (bool(declared), int(hits), None if lo is None else (float(lo), float(hi)),
                      None if least == "never" else float(least))
    return rows


def test_edge_reach_numbers_are_the_sweeps_lines():
    rows = reach_rows()
    text = (DOCS / "edge_reach.txt").read_text()
    declared = {k: v for k, v in rows.items() if v[0]}
    assert all(v[1] > 0 for v in declared.values()), "a declared pair is not reached"
    assert not any(v[1] for v in rows.values() if not v[0]), "a pair reached, not declared"
    assert text.rstrip().endswith("reached but not declared: none; declared but not reached: "
                                  "none")

    def inner(names):      # the least |roll| at which each of the pairs is reached
        assert all(declared[k][2][0] * declared[k][2][1] > 0 for k in names), \
            "a pair reached on both sides of roll 0"
        return sorted(min(abs(r) for r in declared[k][2]) for k in names)
    side_side = [k for k in declared if re.fullmatch(r"cc_T\d_C\d", k)]
    tip_tip = [k for k in declared if re.fullmatch(r"cc_Ctip\d_Ttip\d", k)]
    side_tip = sorted(set(declared) - set(side_side) - set(tip_tip))
    ends = inner(side_tip)             # two groups: 30 deg and 90 deg from the side
    split = max(range(1, len(ends)), key=lambda i: ends[i] - ends[i - 1])
    x = Quotes("The edge reach sweep")
    x.check("It reaches each of the {} edge pairs the `complete` set declares ({} side-edge, {} "
            "tip-tip) and none of the {} others", len(declared), len(side_side) + len(side_tip),
            len(tip_tip), len(rows) - len(declared))
    x.check("meet at rolls beyond about {} deg", inner(side_side)[0])
    x.check("tip arcs 30 deg from a side from about {} deg of roll, those 90 deg away beyond "
            "about {} deg", ends[0], ends[split])
    x.check("the tip arcs each other's beyond about {} deg", inner(tip_tip)[0])
    rest = {k: v[3] for k, v in rows.items() if not v[0] and v[3] is not None}
    nearest = min(rest, key=rest.get)
    x.check("stays {} mm away", rest[nearest])
    assert re.fullmatch(r"cc_T\d_C\d", nearest), f"the nearest undeclared pair is {nearest}"
    x.done()
    assert split == len(ends) // 2, "the side-tip pairs are not two groups of equal size"
    assert text.startswith("20000 poses")


# 9. Speed against accuracy: docs/speed_accuracy_points.csv and _speedups.txt -----------------
SPEED = "Speed against accuracy: drake_dock and Drake's compliant contact"
METRICS = ("capture_time", "apds_spin_rate", "chaser_axial_velocity", "peak_contact_force",
           "peak_stewart_stroke", "chaser_impulse")


def _worst(row) -> float:
    return max(row[f"error_{m}"] for m in METRICS)


def test_speed_accuracy_numbers_are_the_studys_files():
    points = read_csv("speed_accuracy_points.csv")
    scenes = ("paper_example", "idss_slow_roll")
    rigid = {s: [r for r in points if r["scene"] == s and r["method"] == "drake_dock"
                 and r["role"] not in ("reference", "self-convergence")] for s in scenes}
    compliant = {s: [r for r in points if r["scene"] == s and r["method"] != "drake_dock"]
                 for s in scenes}

    def worst(scene, acc, caps, schemes=("runge_kutta5", "bogacki_shampine3")):
        return [_worst(r) for r in rigid[scene] if r["accuracy"] == acc and r["step"] in caps
                and r["scheme"] in schemes]
    coarse = (0.01, 0.02)
    x = Quotes(SPEED)
    x.check("metrics is {} of the contact's effect on the paper example and {} on "
            "`idss_slow_roll` with the 0.002 s cap, and at most {} with the coarser caps",
            max(worst("paper_example", 1e-3, (0.002,))),
            max(worst("idss_slow_roll", 1e-3, (0.002,))),
            max(w for s in scenes for w in worst(s, 1e-3, coarse)))
    x.check("accuracy, to {} and {} at 1e-8;", *(max(worst(s, 1e-8, (0.002,), ("runge_kutta5",)))
                                                  for s in scenes))
    at_1e8 = [w for s in scenes for w in worst(s, 1e-8, coarse)]
    x.check("to between {} and {} at 1e-8.", min(at_1e8), max(at_1e8))
    selfc = {r["scene"]: _worst(r) for r in points if r["role"] == "self-convergence"}
    x.check("is {} on the paper example and {} on `idss_slow_roll`:", selfc["paper_example"],
            selfc["idss_slow_roll"])
    captured = [r for r in compliant["paper_example"] if r["captured"] == 1]
    x.check("on the paper example between {} and {} of the contact's effect on the capture time "
            "and between {} and {} on the spin rate",
            min(r["error_capture_time"] for r in captured),
            max(r["error_capture_time"] for r in captured),
            min(r["error_apds_spin_rate"] for r in captured),
            max(r["error_apds_spin_rate"] for r in captured))
    force = [r["error_peak_contact_force"] for s in scenes for r in compliant[s]
             if r["captured"] == 1]
    x.check("(relative errors {} to {}).", min(force), max(force))
    # The speed-ups file: which metrics no compliant family converges on, and the best errors.
    lines = (DOCS / "speed_accuracy_speedups.txt").read_text().split("scene ")[1:]
    none = {}
    for block in lines:
        scene = block.split(":")[0]
        none[scene] = {m: float(e) for m, e in re.findall(
            r"converged speed-up (\w+): none: no converged compliant configuration \(best "
            r"compliant error (\S+);", block)}
    assert set(none) == set(scenes)
    assert set(none["paper_example"]) == {"apds_spin_rate", "peak_contact_force",
                                          "chaser_axial_velocity", "chaser_impulse"}
    assert set(none["idss_slow_roll"]) == {"apds_spin_rate", "peak_contact_force"}
    others = [e for s in scenes for m, e in none[s].items() if m != "peak_contact_force"]
    peaks = [none[s]["peak_contact_force"] for s in scenes]
    x.check("The best compliant errors there are {} to {} of the contact's effect",
            min(others), max(others))
    x.check("and {} to {} times the reference peak force.", min(peaks), max(peaks))
    x.done()
    # Hydroelastic contact with thin pieces never captures, on either scene.
    assert not any(r["captured"] == 1 for s in scenes for r in compliant[s]
                   if r["model"] == "hydroelastic")

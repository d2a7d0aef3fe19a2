"""The witness table: which witness functions a pair has in each `Mode`, their names and
direction. One guard per transition (module docstring of `contact_system`); every witness is
positive while its transition is not due and triggers when it reaches zero from above. The
values are computed by the compiled evaluation (`drake_dock.core.kernels.engine`, per pair and
kind `W_IMPACT` ... `W_SIDE`, and the far pairs' smallest clearance left); each witness function
reads its own.

The kinds, one per transition:
- impact: the gap g of a tracked couple while it is positive, its rate v_n while it is not; its
  zero is an impact. Just after an impact the gap is at or below zero (the impact is isolated
  to within Drake's window): the witness is then v_n > 0, and triggers if the couple turns back
  (v_n reaches zero) before its gap has become positive; once the gap is positive it is the gap
  (no trigger on the way out), and on the way back it crosses zero at the gap's zero.
- regular: the least of the couple's margin to its domain's ends (of each bounded parameter,
  relative to the span; periodic parameters have none) and of the conditioning of J above
  ``conditioning_min``: at its zero the couple leaves its domain or Eq. (39) fails, and the pair
  is sought again.
- lambda_n of a couple in contact: it detaches at its zero (Eq. 50-51).
- slip: the sliding velocity along its direction: it stops or reverses at its zero.
- friction cone: mu_s lambda_n - |lambda_t| of a sticking couple: it reaches the static cone
  (Eq. 51).
- hand-over: the guard of an edge pair with a declared hand-over (`drake_dock.core.handover`),
  n . b + `drake_dock.systems.engine.GUARD_BAND`, positive while its curve lies beyond the
  edge; at its zero the couple passes onto the surface and is handed to the surface pair. The
  band: a couple that rides on the switching surface (n . b = 0 to round-off, as where a
  symmetric motion keeps a ring's circle over a petal's edge) does not trigger an event at
  every step.
- concave side: a point-curve pair's side (`drake_dock.core.couple.point_curve_side`),
  positive while the point lies on the curve's concave side; at its zero the pair is sought
  again (a potential contact only there).
- the far pairs' clearance: min (clearance - travel bound) over the far pairs (1 if no pair is
  far); its event seeks again every far pair whose clearance is used up.

Every witness has the same direction and the same event, whose handler resolves every
transition due at once: Drake is therefore given one witness, the least value of the armed
ones (`JOINT_WITNESS`), wherever they are all positive just after an event (when Drake asks
which witnesses are active). It triggers where the first of them reaches zero, as that one
would, and Drake calls one function at both ends of a step instead of one per transition.
Where an armed witness is not positive after an event (a transition left at its zero), the
witnesses are given one by one, so that it does not hold back the others
(`ContactOptions.joint_witness` False gives them one by one throughout).
"""
from __future__ import annotations

from pydrake.systems.framework import WitnessFunctionDirection

from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import model as K

FAR_WITNESS = "far pairs clearance"   # the one witness of all far pairs ("clear")
JOINT_WITNESS = "least armed witness"  # the armed witnesses' least value (module docstring)
DIRECTION = WitnessFunctionDirection.kPositiveThenNonPositive

# kind: (name after the pair's name, its code in the evaluation's values)
WITNESSES = {"impact": ("gap", K.W_IMPACT), "regular": ("domain end or Eq. 39", K.W_REGULAR),
             "lambda": ("lambda_n", K.W_LAMBDA), "slip": ("slip", K.W_SLIP),
             "cone": ("friction cone", K.W_CONE), "handover": ("hand-over", K.W_HANDOVER),
             "side": ("concave side", K.W_SIDE)}
CODE = {kind: code for kind, (_, code) in WITNESSES.items()}


# The witnesses of a pair in each mode, in the order they are armed.
BY_MODE = {Mode.FAR: (),
           Mode.TRACKED: ("regular", "impact"),
           Mode.SLIDING: ("regular", "lambda", "slip"),
           Mode.STICKING: ("regular", "lambda", "cone")}


def declare(system, pairs, value_at, far_value, joint_value, event):
    """The witness functions of ``system``: per pair a dict kind -> witness (named
    "<pair> <name>"), the far pairs' one and the joint one; ``value_at(context, i, code)``
    gives pair i's value of the kind ``code``, ``far_value(context)`` the far pairs',
    ``joint_value(context)`` the least armed one."""
    per_pair = [{kind: system.MakeWitnessFunction(f"{p.name} {name}", DIRECTION,
                                                  lambda c, i=i, k=code: value_at(c, i, k),
                                                  event)
                 for kind, (name, code) in WITNESSES.items()}
                for i, p in enumerate(pairs)]
    far = system.MakeWitnessFunction(FAR_WITNESS, DIRECTION, far_value, event)
    joint = system.MakeWitnessFunction(JOINT_WITNESS, DIRECTION, joint_value, event)
    return per_pair, far, joint


def armed(states, edge_pairs=(), side_pairs=()) -> list:
    """(pair index or None, kind) of every witness armed for the pairs' `PairState`s: the far
    pairs' clearance when a pair is far, then each pair's witnesses of its mode, the
    hand-over guard of the pairs in ``edge_pairs`` and the side of the point-curve pairs in
    ``side_pairs`` that are not far."""
    out = [(None, "clear")] if any(st.mode == Mode.FAR for st in states) else []
    for i, st in enumerate(states):
        out += [(i, kind) for kind in BY_MODE[st.mode]]
        if st.mode != Mode.FAR and i in edge_pairs:
            out.append((i, "handover"))
        if st.mode != Mode.FAR and i in side_pairs:
            out.append((i, "side"))
    return out

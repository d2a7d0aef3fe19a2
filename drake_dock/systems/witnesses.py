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
Where some armed witnesses are not positive after an event (a transition left at its zero, a
hand-over guard below zero whose hand-over is not made), each of those is given on its own and
the others are given as one, the least of them (`declare_rest`), so that a held one does not
hold back the others: a witness positive at the event is positive at every step's start until
it triggers, so their least triggers in the same steps and at the same bisection points as the
first of them would (`ContactOptions.joint_witness` False gives them one by one throughout).
"""
from __future__ import annotations

from pydrake.systems.framework import UnrestrictedUpdateEvent, WitnessFunctionDirection

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


def declare_rest(system, held, value, event):
    """The joint witness of the armed witnesses but ``held`` ((pair or None, kind), the ones
    not positive where it is given; module docstring), ``value(context)`` its value."""
    return system.MakeWitnessFunction(f"{JOINT_WITNESS} but {len(held)}", DIRECTION, value,
                                      event)


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


class WitnessFunctions:
    """The witness functions a `RigidContactSystem` gives Drake (`DoGetWitnessFunctions`) and
    their values, read from the context's evaluation (module docstring)."""

    def DoGetWitnessFunctions(self, context):
        """The armed witnesses, or the one joint witness of those positive here beside each
        of the others (module docstring: Drake asks after every event, at the state it left)."""
        armed = self._armed(context)
        if not (armed and self.options.joint_witness):
            return [self._individual(w) for w in armed]
        if self._joint_value(context) > 0.0:
            return [self._w_joint]
        E = self._cache.Eval(context)
        values = E.wv.ravel().take(self._armed_modes(E.modes).flat).tolist()
        if self._far_armed(armed):
            values.insert(0, E.far_witness)
        held = tuple(w for w, v in zip(armed, values) if not v > 0.0)
        if len(held) == len(armed):
            return [self._individual(w) for w in armed]
        return [self._rest_witness(held)] + [self._individual(w) for w in held]

    def _individual(self, armed_witness):
        i, kind = armed_witness
        return self._w_far if i is None else self._w[i][kind]

    @staticmethod
    def _far_armed(armed) -> bool:
        return armed[0][0] is None            # `armed` puts the far pairs' first

    def _rest_witness(self, held):
        """The joint witness of the armed witnesses but ``held`` (`declare_rest`),
        one per held set, kept."""
        w = self._rest.get(held)
        if w is None:
            w = self._rest[held] = declare_rest(
                self, held, lambda c, held=held: self._rest_value(c, held),
                UnrestrictedUpdateEvent(self._on_event))
        return w

    def _armed(self, context) -> list:
        """`armed` for the context's modes, kept on their index when sealed."""
        return self._armed_list(self.get_modes(context))

    def _armed_list(self, modes) -> list:
        derived = modes.index().derived
        hit = derived.get("armed")
        if hit is None:
            hit = derived["armed"] = armed(modes.pairs, self.links.of_edge, self.side_pairs)
        return hit

    def _witness_value(self, context, i, code):
        """The value of pair i's witness of kind ``code`` (`engine.W_GAP` ...), computed by
        the evaluation (Drake evaluates every witness at both ends of every step)."""
        return self._cache.Eval(context).witness_table[i][code]

    def _joint_value(self, context):
        """The least value of the armed witnesses (`JOINT_WITNESS`)."""
        E = self._cache.Eval(context)
        return E.least_witness(self._armed_modes(E.modes))

    def _rest_value(self, context, held):
        """The least value of the armed witnesses but ``held`` (`_rest_witness`)."""
        E = self._cache.Eval(context)
        return E.least_witness(self._armed_modes(E.modes), self._rest_slots(E.modes, held))

    def _rest_slots(self, modes, held):
        """(the places in `ArmedWitnesses.flat_list` of the armed pair witnesses but
        ``held``, whether the far pairs' one is among them), kept on the modes' index."""
        derived = modes.index().derived
        hit = derived.get(("rest", held))
        if hit is None:
            armed = self._armed_list(modes)
            far = self._far_armed(armed) if armed else False
            per = armed[1:] if far else armed
            hit = derived[("rest", held)] = (
                tuple(j for j, w in enumerate(per) if w not in held),
                far and armed[0] not in held)
        return hit

    def _far_value(self, context):
        return self._cache.Eval(context).far_witness

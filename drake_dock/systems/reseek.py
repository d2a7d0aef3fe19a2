"""The seeks at a step's start when nothing else is due (`RigidContactSystem._on_step`): far
pairs whose travel bound has used ``reseek_early`` of their clearance, or will within
``reseek_horizon``, are screened or sought again, without a full event, as long as each stays
far."""
from __future__ import annotations

from drake_dock.core.hybrid import Mode
from drake_dock.systems.contact_types import ContactModes, read_only
from drake_dock.systems.evaluation import Kinematics


def reseek_far(tr, t, x, modes, E):
    """The seeks of the `Transitions` tr due at a step's start when nothing else is (no
    witness crossed, no couple drifted): the far pairs due (`Evaluation.due_pairs`, E the
    evaluation at (t, x, modes)) are screened or sought again, each as in
    `Transitions.resolve`. Returns (x, modes) when each stays far, with only those pairs' far-pair
    data and couples changed (the other pair states are shared, the modes' index patched,
    ``reseeks`` counted); None when a seek would change a mode (the caller resolves the
    event in full)."""
    index = modes.index()
    due = E.due_pairs.tolist()
    if not due:
        return None
    ev = tr.ev
    states = list(modes.pairs)
    u = x[ev.nq + ev.nv:ev.ie].copy()
    kin = Kinematics.of_frames(E.R, E.o, E.w, E.vf)
    poses = kin.poses
    sought = []
    for i in due:
        states[i] = states[i].copied()
        if tr.screen(i, poses, states):
            continue
        after = tr.seek(i, poses, states, u, t, False)
        if states[i].mode != Mode.FAR:
            return None
        sought.append((i, after))
    for i, after in sought:
        tr.carry(i, after, states)
    x_new = x.copy()
    x_new[ev.nq + ev.nv:ev.ie] = u
    new = ContactModes(states, list(modes.impacts), modes.impact_loss, modes.mode_changes,
                       modes.reseeks + 1, read_only(x_new.copy()))
    new.seal(index.with_far(due, states))
    tr.eng.patch_far(modes, new, due)
    return x_new, new

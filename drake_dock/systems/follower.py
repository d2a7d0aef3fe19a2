"""A follower force: a force of constant magnitude along an axis fixed in a free body, acting
in windows of time counted from the first contact (a spacecraft's post-contact thrust is one).

The contact system adds it to the inputs' generalized force from its own state, at every
evaluation, with no Drake port between: the force follows the body's attitude, so a port would
be evaluated afresh at every state, through the state and first-contact outputs."""
from __future__ import annotations

import dataclasses
import math


@dataclasses.dataclass(frozen=True)
class FollowerForce:
    """``force`` (N) along the unit axis ``axis_B`` of the free body whose quaternion starts at
    ``q_start`` in q and whose spatial velocity starts at ``v_start`` in v (wrench order
    [torque, force]), applied at the body's origin, while the time since the first contact is
    in one of ``windows`` ((start, end) s, closed at the start, open at the end)."""

    force: float
    axis_B: tuple
    q_start: int
    v_start: int
    windows: tuple

    def acting(self, since_contact: float) -> bool:
        """Whether it acts ``since_contact`` s after the first contact (-inf before it)."""
        for a, b in self.windows:
            if a <= since_contact < b:
                return True
        return False

    def axis(self, q) -> tuple:
        """The body's axis in the world at the positions q: the body's rotation (its
        quaternion w, x, y, z, normalised as Drake does) applied to ``axis_B``, in plain float
        arithmetic."""
        i = self.q_start
        w, x, y, z = float(q[i]), float(q[i + 1]), float(q[i + 2]), float(q[i + 3])
        s = 2.0 / (w * w + x * x + y * y + z * z)
        a, b, c = self.axis_B
        return ((1.0 - s * (y * y + z * z)) * a + s * (x * y - w * z) * b + s * (x * z + w * y) * c,
                s * (x * y + w * z) * a + (1.0 - s * (x * x + z * z)) * b + s * (y * z - w * x) * c,
                s * (x * z - w * y) * a + s * (y * z + w * x) * b + (1.0 - s * (x * x + y * y)) * c)

    def wrench(self, q, since_contact: float) -> tuple | None:
        """The world wrench [torque, force] at ``since_contact``, None where it does not act."""
        if not (math.isfinite(since_contact) and self.acting(since_contact)):
            return None
        e0, e1, e2 = self.axis(q)
        f = self.force
        return (0.0, 0.0, 0.0, f * e0, f * e1, f * e2)

    def add_to(self, tau, q, since_contact: float) -> None:
        """Adds the wrench to the generalized force ``tau`` where it acts: its force alone
        (adding the torque's zeros would at most turn a -0.0 of tau into +0.0)."""
        w = self.wrench(q, since_contact)
        if w is not None:
            j = self.v_start + 3
            tau[j] += w[3]
            tau[j + 1] += w[4]
            tau[j + 2] += w[5]

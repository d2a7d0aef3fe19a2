"""One memo for the contact system's results that Drake asks for again with equal inputs."""
from __future__ import annotations


class Memo:
    """The last ``size`` results by key (first in, first out).

    Key: everything the result depends on, as hashable values (arrays as bytes), so that equal
    keys mean equal results. Reuse rule: a result is reused for an equal key, passed through
    ``refresh`` when it is given (which may return the same result or an updated one, kept in
    its place); any other key computes the result anew. Drake recomputes its cache entries
    whenever the context's state is written, even with the same values (the integrator
    restores a step's initial state before each trial and each witness isolation), and calls
    an unrestricted update's handler once per triggered witness, all at the same context: the
    memo lets equal requests share one computation. Users do not change a result in place, except to fill values derived from it
that depend on nothing outside its key (an evaluation's witness values)."""

    def __init__(self, size: int):
        self.size = size
        self._items = {}

    def clear(self):
        self._items.clear()

    def find(self, key):
        """The result kept for ``key``, None if none is."""
        return self._items.get(key)

    def put(self, key, value):
        """Keeps ``value`` for ``key`` (a key not kept) and returns it."""
        if len(self._items) >= self.size:
            self._items.pop(next(iter(self._items)))
        self._items[key] = value
        return value

    def get(self, key, compute, refresh=None):
        hit = self._items.get(key)
        if hit is not None:
            if refresh is not None:
                hit = self._items[key] = refresh(hit)
            return hit
        return self.put(key, compute())

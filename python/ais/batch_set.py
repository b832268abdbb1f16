"""Many gathers driven together with arrays: AIS for a renderer written in Python.

A host that traces rays in waves (numpy, Dr.Jit, a GPU) keeps one :class:`BatchSet` of
``G`` gathers and runs rounds; each round costs a few array calls, never a call per ray::

    batches = ais.BatchSet(G, ais="aggressive")
    batches.begin(n=64, seeds=np.arange(G, dtype=np.uint64))
    while True:
        active, u = batches.next_candidates()          # (G,) bool, (G, 2) float32
        if not active.any():
            break
        directions, in_support = my_proposal(u)        # (G, 3), (G,) bool
        trace, weight = batches.decide(directions, in_support)
        values, ratings = my_trace(directions, trace)  # (G, 3) f·L·V/p, (G,) in [0, 1]
        batches.record(values, ratings)
    estimates, candidates, traced = batches.finish()   # (G, 3), (G,), (G,)

Rows of inactive or untraced gathers are ignored, so hosts may fill whole arrays. Each
gather is exactly the library's ``Batch``: the estimates are unbiased, and equal to what
the same batches give one at a time.
"""

from __future__ import annotations

from typing import Any, Dict, Tuple, Union

import numpy as np

from ._ais import _BatchSet

Array = np.ndarray


class BatchSet:
    """``gathers`` batches with one configuration.

    Options: ``ais`` (``"off"``, ``"aggressive"``, ``"conservative"``), ``budget``
    (``"candidates"``: exactly n candidates, only the accepted traced; ``"traced"``: about
    n traced), ``placement`` (``"halton"``, ``"random"``), ``map_res`` (the affinity map's
    height in texels) and ``tol`` (its floor, a_min = 1/(tol·h²)).
    """

    def __init__(self, gathers: int, **options: Any) -> None:
        self._set = _BatchSet(int(gathers), **options)
        self.gathers = int(gathers)

    def __len__(self) -> int:
        return self.gathers

    def begin(self, n: int, seeds: Union[int, Array]) -> None:
        """Starts every gather with ``n`` rays; ``seeds`` is one per gather, or a base seed."""
        if np.isscalar(seeds):
            seeds = np.arange(self.gathers, dtype=np.uint64) + np.uint64(int(seeds) * self.gathers)
        self._set.begin(int(n), np.ascontiguousarray(seeds, dtype=np.uint64))

    def next_candidates(self) -> Tuple[Array, Array]:
        """``(active, u)``: which gathers have a candidate this round, and its two numbers."""
        return self._set.next_candidates()

    def decide(self, directions: Any, in_support: Any) -> Tuple[Array, Array]:
        """``(trace, weight)`` for unit ``directions`` (G, 3) and ``in_support`` (G,)."""
        return self._set.decide(
            np.ascontiguousarray(directions, dtype=np.float32),
            np.ascontiguousarray(in_support, dtype=bool),
        )

    def record(self, contributions: Any, ratings: Any) -> None:
        """The traced rays' values ``f·L·V/p`` (G, 3) and ratings, actual over unoccluded (G,)."""
        self._set.record(
            np.ascontiguousarray(contributions, dtype=np.float32),
            np.ascontiguousarray(ratings, dtype=np.float32),
        )

    def finish(self) -> Tuple[Array, Array, Array]:
        """``(estimates, candidates, traced)`` once no gather is active."""
        return self._set.finish()

    @property
    def stats(self) -> Dict[str, int]:
        """Counters summed over every gather so far."""
        return self._set.stats

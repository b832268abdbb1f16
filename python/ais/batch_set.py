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

from ._ais import VisibilityField as _VisibilityField
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

    def decide(self, directions: Any, in_support: Any, acceptance: Any = None) -> Tuple[Array, Array]:
        """``(trace, weight)`` for unit ``directions`` (G, 3) and ``in_support`` (G,).

        ``acceptance`` (G,), if given, is the host's acceptance probability of each
        candidate instead of the batches' maps (use it with ``ais="off"``), e.g. from
        :meth:`VisibilityField.acceptance`. It may depend on the candidate and on earlier
        rounds, never on whether this candidate's ray is blocked.
        """
        directions = np.ascontiguousarray(directions, dtype=np.float32)
        in_support = np.ascontiguousarray(in_support, dtype=bool)
        if acceptance is None:
            return self._set.decide(directions, in_support)
        return self._set.decide(
            directions, in_support, np.ascontiguousarray(acceptance, dtype=np.float32)
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


class VisibilityField:
    """A visibility field learned over many gathers, fixed while a pass renders.

    Each gather's cell is keyed by its position, its normal and ``spacing`` (the distance
    between neighbouring gathers there, e.g. four pixel footprints); each cell holds an
    equal-area map of ``side × side`` texels counting free and blocked rays. In a pass:
    ``acceptance(...)`` before ``BatchSet.decide(..., acceptance=...)``, ``record(...)``
    for the traced rays, and ``end_pass()`` after the pass. ``cost_ratio`` is what a
    candidate costs besides tracing, over what tracing it costs.
    """

    def __init__(self, side: int = 8, prior: float = 2.0) -> None:
        self._field = _VisibilityField(int(side), float(prior))

    def acceptance(self, positions, normals, spacings, directions, cost_ratio: float) -> Array:
        """Each gather's acceptance for its candidate (1 where the field knows too little)."""
        return self._field.acceptance(
            _rows(positions), _rows(normals), _column(spacings), _rows(directions), float(cost_ratio)
        )

    def record(self, positions, normals, spacings, directions, free, traced) -> None:
        """Counts this pass's traced rays (``traced``), free or blocked (``free``)."""
        self._field.record(
            _rows(positions), _rows(normals), _column(spacings), _rows(directions),
            np.ascontiguousarray(free, dtype=bool), np.ascontiguousarray(traced, dtype=bool),
        )

    def end_pass(self) -> None:
        """Merges the pass's counts into the field."""
        self._field.end_pass()

    @property
    def cell_count(self) -> int:
        """Cells learned so far."""
        return self._field.cell_count

    @property
    def memory_bytes(self) -> int:
        """Bytes held by the field and the pass's counts."""
        return self._field.memory_bytes


def _rows(array) -> Array:
    return np.ascontiguousarray(array, dtype=np.float32)


def _column(array) -> Array:
    return np.ascontiguousarray(array, dtype=np.float32).reshape(-1)

"""ais.BatchSet: a numpy host drives many gathers per call, and the estimates are unbiased."""

from __future__ import annotations

import numpy as np
import pytest

import ais


def hemisphere(u):
    """Uniform directions on the upper hemisphere (pdf 1/2π) from (G, 2) numbers."""
    z = u[:, 0]
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = 2 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def gather(batches, n, seed):
    """Irradiance over π under a sky of radiance 1 whose half x < 0 is blocked: exactly 1/2."""
    batches.begin(n, seed)
    rounds = 0
    while True:
        active, u = batches.next_candidates()
        if not active.any():
            break
        rounds += 1
        directions = hemisphere(u)
        trace, weight = batches.decide(directions, np.ones(len(u), dtype=bool))
        assert not (trace & ~active).any()
        assert (weight[trace] >= 1.0).all()
        visible = directions[:, 0] > 0
        value = np.where(visible, 2.0 * directions[:, 2], 0.0)  # (cos/π) / (1/2π)
        batches.record(np.repeat(value[:, None], 3, axis=1), visible.astype(np.float32))
    return batches.finish(), rounds


@pytest.mark.parametrize("mode", ["off", "aggressive", "conservative"])
def test_estimates_are_unbiased(mode):
    gathers = 20000
    batches = ais.BatchSet(gathers, ais=mode)
    (estimates, candidates, traced), rounds = gather(batches, 16, seed=3)
    assert estimates.shape == (gathers, 3) and estimates.dtype == np.float32
    assert (candidates == 16).all(), "a fixed candidate budget by default"
    assert rounds == 16
    mean = estimates[:, 0].astype(np.float64).mean()
    standard_error = estimates[:, 0].std(ddof=1) / np.sqrt(gathers)
    assert abs(mean - 0.5) < 4 * standard_error, (mean, standard_error)
    if mode == "off":
        assert (traced == 16).all()
    else:
        assert batches.stats["rejected_by_roulette"] > 0
        assert traced.mean() < 16


def test_seeds_reproduce_gathers():
    first, _ = gather(ais.BatchSet(100, ais="aggressive"), 8, seed=5)
    again, _ = gather(ais.BatchSet(100, ais="aggressive"), 8, seed=5)
    other, _ = gather(ais.BatchSet(100, ais="aggressive"), 8, seed=6)
    assert np.array_equal(first[0], again[0])
    assert not np.array_equal(first[0], other[0])


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="off, aggressive or conservative"):
        ais.BatchSet(4, ais="shared")
    with pytest.raises(TypeError, match="unexpected keyword argument 'rays'"):
        ais.BatchSet(4, rays=8)
    batches = ais.BatchSet(4)
    with pytest.raises(ValueError, match="seeds has 3 rows"):
        batches.begin(8, np.arange(3, dtype=np.uint64))
    batches.begin(8, 0)
    batches.next_candidates()
    with pytest.raises(ValueError, match="directions has 2 rows"):
        batches.decide(np.zeros((2, 3)), np.ones(4, dtype=bool))
    with pytest.raises(ValueError, match="finish"):
        batches.finish()
    trace, _ = batches.decide(np.tile([0.0, 0.0, 1.0], (4, 1)), np.ones(4, dtype=bool))
    assert trace.all(), "AIS off traces every candidate"
    with pytest.raises(ValueError, match="record"):
        batches.next_candidates()


def test_a_learned_field_rejects_blocked_candidates_without_bias():
    """Gathers along a line, each under a sky blocked where x < 0; the field learns that
    over passes and the estimates stay unbiased (exactly 1/2)."""
    gathers, n = 4000, 16
    positions = np.zeros((gathers, 3), dtype=np.float32)
    positions[:, 0] = np.linspace(0, 1, gathers)
    normals = np.tile(np.array([0, 0, 1], dtype=np.float32), (gathers, 1))
    spacings = np.full(gathers, 0.05, dtype=np.float32)
    field = ais.VisibilityField()
    passes = []
    for index in range(4):
        batches = ais.BatchSet(gathers, ais="off")
        batches.begin(n, 1000 * index)
        while True:
            active, u = batches.next_candidates()
            if not active.any():
                break
            directions = hemisphere(u)
            acceptance = field.acceptance(positions, normals, spacings, directions, 0.2)
            trace, _ = batches.decide(directions, np.ones(gathers, dtype=bool), acceptance)
            visible = directions[:, 0] > 0
            value = np.where(visible, 2.0 * directions[:, 2], 0.0)
            batches.record(np.repeat(value[:, None], 3, axis=1), visible.astype(np.float32))
            field.record(positions, normals, spacings, directions, visible, trace)
        field.end_pass()
        passes.append((batches.finish(), batches.stats))
    assert field.cell_count > 0 and field.memory_bytes > 0
    (first, first_stats), (last, last_stats) = passes[0], passes[-1]
    assert first_stats["rejected_by_roulette"] == 0, "nothing is known in the first pass"
    # Half the sky is blocked; cells roll only where roulette skips enough, here about 1 in 9.
    assert last_stats["rejected_by_roulette"] > 0.05 * last_stats["candidates"]
    for (estimates, _, _), _ in passes:
        mean = estimates[:, 0].astype(np.float64).mean()
        standard_error = estimates[:, 0].std(ddof=1) / np.sqrt(gathers)
        assert abs(mean - 0.5) < 4 * standard_error, (mean, standard_error)

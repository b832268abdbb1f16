"""Tiles rendered as Ray tasks merge into the single-process render, bit for bit."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import ray

import ais

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "ray_tiles.py"


def load_example():
    spec = importlib.util.spec_from_file_location("ray_tiles", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_tiles_cover_the_image_once():
    example = load_example()
    covered = np.zeros((37, 50), dtype=int)
    for x, y, w, h in example.tiles(50, 37, 16):
        covered[y : y + h, x : x + w] += 1
    assert (covered == 1).all()


def test_tiles_on_ray_equal_the_single_process_render(cornell, tmp_path):
    example = load_example()
    options = dict(spp=2, rays=8, resolution=(70, 45), ais="conservative")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        merged = example.render_on_ray(str(cornell), tile=16, **options)
    finally:
        ray.shutdown()
    single = ais.render(cornell, **options)
    assert merged.shape == single.shape == (45, 70, 3)
    assert np.array_equal(merged, single)
    # And the merged image is a file like any render's.
    ais.write_exr(tmp_path / "merged.exr", merged)
    assert (tmp_path / "merged.exr").read_bytes()[:4] == b"\x76\x2f\x31\x01"  # EXR magic

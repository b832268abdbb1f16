"""Render one image as tiles on a Ray cluster, and merge them.

Every pixel of an ais render has its own seed, so tiles rendered on different machines
paste together into exactly the image one process renders (for gathers whose pixels are
independent: AIS off and the talk's per-batch modes, or any mode with tiles on the
renderer's 16-pixel grid except the learned field, ``ais="auto"``).

Ray does the scheduling: one actor per CPU loads the scene once, and an ActorPool hands
out the tiles. On this machine::

    python examples/ray_tiles.py scenes/cornell_box.xml --spp 16 -o cornell.exr

On a cluster, start Ray there (``ray start --head`` on one machine, ``ray start
--address=HEAD:6379`` on the others), make the scene and its files readable at the same
path on every machine, install ais on each (``pip install .``), and pass ``--address
auto`` when running this script on one of them.
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any, Dict, Iterator, List, Optional, Tuple

import numpy as np
import ray
from ray.util import ActorPool

import ais

Crop = Tuple[int, int, int, int]


def tiles(width: int, height: int, size: int) -> Iterator[Crop]:
    """The `(x, y, w, h)` tiles of a `width × height` image, `size` pixels on a side."""
    for y in range(0, height, size):
        for x in range(0, width, size):
            yield (x, y, min(size, width - x), min(size, height - y))


@ray.remote(num_cpus=1)
class TileRenderer:
    """A worker: the scene loaded once, then any number of its tiles rendered."""

    def __init__(self, scene: str, defines: Dict[str, Any]):
        self.scene = ais.Scene(scene, **defines)

    def render(self, crop: Crop, options: Dict[str, Any]) -> Tuple[Crop, np.ndarray]:
        return crop, self.scene.render(crop=crop, threads=1, **options)


def render_on_ray(
    scene: str,
    *,
    tile: int = 64,
    workers: Optional[int] = None,
    defines: Optional[Dict[str, Any]] = None,
    **options: Any,
) -> np.ndarray:
    """Renders `scene` as tiles on the connected Ray cluster and returns the merged image.

    `options` are `ais.Scene.render`'s (spp, resolution, rays, ais, ...). The scene path
    must be readable on every worker.
    """
    scene = os.path.abspath(scene)
    width, height = options.get("resolution") or ais.Scene(scene, **(defines or {})).resolution
    options = dict(options, resolution=(width, height))
    count = workers or max(1, int(ray.available_resources().get("CPU", 1)))
    pool = ActorPool([TileRenderer.remote(scene, defines or {}) for _ in range(count)])
    image = np.zeros((height, width, 3), dtype=np.float32)
    work: List[Crop] = list(tiles(width, height, tile))
    for (x, y, w, h), part in pool.map_unordered(
        lambda actor, crop: actor.render.remote(crop, options), work
    ):
        image[y : y + h, x : x + w] = part
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="a Mitsuba 3 XML scene file")
    parser.add_argument("-o", "--output", default="tiles.exr", help="the merged image (EXR)")
    parser.add_argument("--spp", type=int, default=None)
    parser.add_argument("--rays", type=int, default=None)
    parser.add_argument(
        "--ais",
        default="off",
        help="the AIS mode (off by default: `auto` learns its field from each tile's pixels, "
        "so its tiles differ from a one-process render)",
    )
    parser.add_argument("--tile", type=int, default=64, help="tile size in pixels")
    parser.add_argument("--address", default=None, help='a Ray cluster ("auto"), else local')
    args = parser.parse_args()
    ray.init(address=args.address)
    started = time.perf_counter()
    image = render_on_ray(args.scene, tile=args.tile, spp=args.spp, rays=args.rays, ais=args.ais)
    ais.write_exr(args.output, image)
    print(f"{args.output}: {image.shape[1]}×{image.shape[0]} in {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()

"""ais: adaptive importance sampling for multi-ray gathering, from Python.

Render Mitsuba 3 scenes' direct light into numpy arrays::

    import ais
    image = ais.render("scenes/cornell_box.xml", spp=16, rays=32)      # (H, W, 3) float32
    image, stats = ais.render("scene.xml", ais="auto", stats=True)

    scene = ais.Scene("scenes/sunlit_room.xml", sun_scale=2.0)       # loaded once
    for seed in range(4):
        part = scene.render(spp=4, seed=seed, crop=(0, 0, 64, 64))

``scene`` is a path, Mitsuba XML text (anything starting with ``<``), or None for the
built-in default scene. Keyword arguments of ``render`` are the render's own (``spp``,
``resolution``, ``seed``, ``threads``, ``crop``, ``progress``, ``stats``) and any parameter
of the gather (``rays``, ``ais``, ``strategy``, ``budget``, ``cost_ratio``, ... as in
docs/cli.md). Bad input raises :class:`SceneError`, which names the file and line.

:func:`compare` runs the study of ``ais compare``: it writes the HTML report and returns
the tables as dicts. :class:`BatchSet` is the library for hosts: many gathers' AIS decisions per call, with
arrays (see ``ais.batch_set``).
"""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Union

from ._ais import Scene, SceneError, __version__, compare, write_exr
from .batch_set import BatchSet, VisibilityField

__all__ = ["BatchSet", "Scene", "VisibilityField", "SceneError", "compare", "render", "write_exr", "__version__"]


def render(
    scene: Union[str, "os.PathLike[str]", None] = None,
    *,
    defines: Optional[Mapping[str, Any]] = None,
    **options: Any,
):
    """Loads ``scene`` (with ``$name`` parameters ``defines``) and renders it once.

    Returns the image as an ``(H, W, 3)`` float32 array, or ``(image, stats)`` with
    ``stats=True``. See :meth:`Scene.render` for the options.
    """
    return Scene(scene, **dict(defines or {})).render(**options)

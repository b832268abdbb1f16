"""Type stubs of the extension module behind ``ais``."""

import os
from typing import Any, Dict, List, Literal, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

class SceneError(ValueError):
    """A scene, mesh or image that cannot be used."""

    file: str
    """The file at fault."""
    line: Optional[int]
    """The 1-based line, where known."""
    message: str
    """What is wrong."""

class Scene:
    """A Mitsuba 3 XML scene, loaded once (meshes read, BVH built) and rendered many times.

    ``scene`` is a path, XML text (starting with ``<``), or None for the built-in default
    scene; ``defines`` set the file's ``$name`` parameters. Scene warnings are issued as
    ``UserWarning``.
    """

    def __init__(
        self, scene: Union[str, "os.PathLike[str]", None] = None, **defines: Any
    ) -> None: ...
    @property
    def resolution(self) -> Tuple[int, int]:
        """The film size ``(width, height)`` renders use unless told otherwise."""
    @property
    def spp(self) -> int:
        """The scene's samples per pixel."""
    @property
    def file(self) -> str:
        """The scene file, or what stands for it."""
    @overload
    def render(
        self,
        *,
        spp: Optional[int] = None,
        resolution: Optional[Tuple[int, int]] = None,
        rays: Optional[int] = None,
        ais: Optional[str] = None,
        strategy: Optional[str] = None,
        seed: int = 0,
        threads: Optional[int] = None,
        crop: Optional[Tuple[int, int, int, int]] = None,
        progress: bool = False,
        stats: Literal[False] = False,
        **gather: Any,
    ) -> npt.NDArray[np.float32]: ...
    @overload
    def render(
        self,
        *,
        spp: Optional[int] = None,
        resolution: Optional[Tuple[int, int]] = None,
        rays: Optional[int] = None,
        ais: Optional[str] = None,
        strategy: Optional[str] = None,
        seed: int = 0,
        threads: Optional[int] = None,
        crop: Optional[Tuple[int, int, int, int]] = None,
        progress: bool = False,
        stats: Literal[True],
        **gather: Any,
    ) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]: ...
    def render(self, **options: Any) -> Any:
        """Renders the scene's direct light with the gather, releasing the GIL.

        - ``spp``: samples per pixel (default: the scene's);
        - ``resolution``: ``(width, height)`` (default: the scene's);
        - ``rays``, ``ais``, ``strategy`` and any other gather parameter (docs/cli.md);
        - ``seed``: the base seed; each pixel derives its own, so images do not depend on
          ``threads`` (default: all cores);
        - ``crop``: ``(x, y, w, h)`` in pixels of the whole image; returns that part, equal
          to the same pixels of the whole render wherever pixels are independent;
        - ``progress``: a progress bar on stderr;
        - ``stats``: return ``(image, stats)``, the stats a dict of render time, rays and
          the gather's counts per gather.
        """

def write_exr(path: Union[str, "os.PathLike[str]"], image: npt.NDArray[np.float32]) -> None:
    """Writes an ``(H, W, 3)`` float32 image as an RGB EXR, all or nothing."""

class _BatchSet:
    """The extension's batch set; use ``ais.BatchSet``, which converts arrays."""

    def __init__(self, gathers: int, **options: Any) -> None: ...
    def __len__(self) -> int: ...
    def begin(self, n: int, seeds: npt.NDArray[np.uint64]) -> None: ...
    def next_candidates(self) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float32]]: ...
    def decide(
        self,
        directions: npt.NDArray[np.float32],
        in_support: npt.NDArray[np.bool_],
        acceptance: Optional[npt.NDArray[np.float32]] = None,
    ) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float32]]: ...
    def record(
        self, contributions: npt.NDArray[np.float32], ratings: npt.NDArray[np.float32]
    ) -> None: ...
    def finish(
        self,
    ) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.uint32]]: ...
    @property
    def stats(self) -> Dict[str, int]: ...

def compare(
    scene: Union[str, "os.PathLike[str]", None] = None,
    *,
    output: Union[str, "os.PathLike[str]"] = "report",
    time_budget: float = 3.0,
    seeds: int = 3,
    strategies: Optional[List[str]] = None,
    configs: Optional[List[str]] = None,
    oracle: bool = True,
    reference_spp: int = 256,
    pass_spp: int = 1,
    pixel: Optional[Tuple[int, int]] = None,
    resolution: Optional[Tuple[int, int]] = None,
    defines: Optional[Dict[str, Any]] = None,
    threads: Optional[int] = None,
    progress: bool = False,
    **gather: Any,
) -> Dict[str, Any]:
    """The study of ``ais compare`` (docs/cli.md): configurations at equal time and equal
    rays against a converged reference, with the oracle. Writes ``output/index.html`` and
    returns ``{"configurations": [...], "tables": str, "report": str, "ray_budget": int,
    "reference_noise": float}``; each configuration is a dict with ``name``, ``label``,
    ``oracle``, ``equal_time`` (None for the oracle: spp, ms_per_spp, traced_rays_per_pixel,
    rejected_per_pixel, ais_kib_per_thread, rel_mse {mean, error}, ratio, mse {mean, error},
    mse_ratio, relative_alike {mean, error}, relative_alike_ratio) and ``equal_rays`` (spp,
    seconds, rel_mse, ratio, oracle_share, mse, mse_ratio, relative_alike,
    relative_alike_ratio); ``mse`` weighs every pixel's error in radiance alike,
    ``relative_alike`` every pixel's relative error (ε = 1e-4). The first configuration is
    the baseline of the ratios. Gather parameters (``rays=…``) set the base settings.
    """

class VisibilityField:
    """The extension's learned field; use ``ais.VisibilityField``, which converts arrays."""

    def __init__(self, side: int = 8, prior: float = 2.0) -> None: ...
    def acceptance(
        self,
        positions: npt.NDArray[np.float32],
        normals: npt.NDArray[np.float32],
        spacings: npt.NDArray[np.float32],
        directions: npt.NDArray[np.float32],
        cost_ratio: float,
    ) -> npt.NDArray[np.float32]: ...
    def record(
        self,
        positions: npt.NDArray[np.float32],
        normals: npt.NDArray[np.float32],
        spacings: npt.NDArray[np.float32],
        directions: npt.NDArray[np.float32],
        free: npt.NDArray[np.bool_],
        traced: npt.NDArray[np.bool_],
    ) -> None: ...
    def end_pass(self) -> None: ...
    @property
    def cell_count(self) -> int: ...
    @property
    def memory_bytes(self) -> int: ...

"""AIS inside Mitsuba 3: a scene's direct light rendered by Mitsuba's own machinery, with
ais deciding which candidates to trace.

    python -m ais.mitsuba SCENE.xml --spp 16 --rays 16 --ais aggressive -o out.exr

Mitsuba loads the scene, traces every ray (``Scene.ray_intersect`` and ``ray_test``), and
its emitters and BSDFs sample and evaluate; ais's :class:`~ais.BatchSet` only decides,
for every pixel's gather at once, which candidate directions are traced. The gather is
the one-sample MIS mixture of emitter and BSDF sampling (half each, balance heuristic):
the same expectation as Mitsuba's ``direct`` integrator, so the two agree within noise.

Needs ``pip install mitsuba``. The default variant ``llvm_ad_rgb`` needs the LLVM library
(Debian: ``apt install libllvm19``); it is found in the usual places, or set
``DRJIT_LIBLLVM_PATH``. Every round is vectorised over all pixels, so the variant must
be a vectorised one (``llvm_ad_rgb``, ``llvm_rgb``); scalar variants are refused.
"""

from __future__ import annotations

import argparse
import glob
import os
import re
import sys
import time
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, Optional, Tuple

import numpy as np

from .batch_set import BatchSet

LLVM_PLACES = (
    "/usr/lib/x86_64-linux-gnu/libLLVM*.so*",
    "/usr/lib/aarch64-linux-gnu/libLLVM*.so*",
    "/usr/lib/llvm-*/lib/libLLVM*.so*",
    "/usr/local/lib/libLLVM*.so*",
)


def find_llvm() -> Optional[str]:
    """The LLVM library Dr.Jit's llvm variants need: ``DRJIT_LIBLLVM_PATH``, else the
    newest one in the usual places."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = sorted({p for pattern in LLVM_PLACES for p in glob.glob(pattern)})
    return found[-1] if found else None


def import_mitsuba(variant: str):
    """Mitsuba with ``variant`` set; for llvm variants, the LLVM library found first."""
    if variant.startswith("scalar"):
        raise RuntimeError(
            f"ais.mitsuba vectorises every round over all pixels: use an llvm variant, not {variant}"
        )
    if variant.startswith("llvm"):
        llvm = find_llvm()
        if llvm is None:
            raise RuntimeError(
                f"Mitsuba's {variant} variant needs the LLVM library: install it (Debian: "
                "apt install libllvm19) or set DRJIT_LIBLLVM_PATH"
            )
        os.environ["DRJIT_LIBLLVM_PATH"] = llvm
    try:
        import mitsuba
    except ImportError as error:
        raise RuntimeError("ais.mitsuba needs Mitsuba 3: pip install mitsuba") from error
    mitsuba.set_variant(variant)
    return mitsuba


@dataclass
class LoadedScene:
    """A Mitsuba scene and what the gather reads from its file."""

    scene: Any
    hide_emitters: bool


def mitsuba_text(text: str) -> str:
    """The scene for Mitsuba: an ais ``gather`` integrator (which Mitsuba does not know)
    becomes ``direct``; the rest is untouched."""
    return re.sub(
        r'<integrator\b[^>]*type="gather"[^>]*(/>|>.*?</integrator>)',
        '<integrator type="direct"/>',
        text,
        flags=re.S,
    )


def hides_emitters(text: str) -> bool:
    """Whether the scene's integrator has ``hide_emitters`` set to true."""
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        return False
    for integrator in root.iter("integrator"):
        for flag in integrator.iter("boolean"):
            if flag.get("name") == "hide_emitters":
                return flag.get("value", "").strip().lower() == "true"
    return False


def load_scene(mi, path: Path, defines: Dict[str, Any]) -> LoadedScene:
    """Loads ``path`` with Mitsuba, relative file names resolved from its folder."""
    text = path.read_text()
    mi.file_resolver().prepend(str(path.resolve().parent))
    scene = mi.load_string(mitsuba_text(text), **{k: str(v) for k, v in defines.items()})
    return LoadedScene(scene=scene, hide_emitters=hides_emitters(text))


class MitsubaGather:
    """The gather, as a host of ais's batch set, on Mitsuba's scene and variant."""

    def __init__(self, mi, loaded: LoadedScene, rays: int, ais: str, seed: int):
        self.mi = mi
        self.dr = __import__("drjit")
        self.scene = loaded.scene
        self.hide_emitters = loaded.hide_emitters
        self.rays = rays
        self.seed = seed
        self.sensor = self.scene.sensors()[0]
        self.width, self.height = (int(v) for v in self.sensor.film().crop_size())
        self.batches = BatchSet(self.width * self.height, ais=ais)

    def render(self, spp: int) -> Tuple[np.ndarray, Dict[str, Any]]:
        """The image, ``(H, W, 3)`` float32, and statistics."""
        started = time.perf_counter()
        total = np.zeros((self.height * self.width, 3))
        for index in range(spp):
            total += self.sample_pass(index)
        image = (total / spp).astype(np.float32).reshape(self.height, self.width, 3)
        stats = dict(self.batches.stats, render_time=time.perf_counter() - started)
        return image, stats

    def sample_pass(self, index: int) -> np.ndarray:
        """One sample per pixel: what the camera ray sees, plus its gather."""
        mi, dr = self.mi, self.dr
        rng = np.random.default_rng([self.seed, index])
        count = self.width * self.height
        pixel = np.arange(count)
        jitter = rng.random((count, 2))
        position = mi.Point2f(
            mi.Float((pixel % self.width + jitter[:, 0]) / self.width),
            mi.Float((pixel // self.width + jitter[:, 1]) / self.height),
        )
        ray, ray_weight = self.sensor.sample_ray(0.0, 0.5, position, mi.Point2f(0.5, 0.5))
        si = self.scene.ray_intersect(ray)
        bsdf = si.bsdf(ray)
        dr.eval(si, bsdf)
        seen = mi.Color3f(0.0)
        if not self.hide_emitters:
            seen = si.emitter(self.scene).eval(si)
        seeds = rng.integers(0, 2**63, size=count, dtype=np.uint64)
        gathered = self.gather(si, bsdf, seeds, rng)
        return rgb(ray_weight) * (rgb(seen) + gathered)

    def gather(self, si, bsdf, seeds: np.ndarray, rng) -> np.ndarray:
        """Every pixel's gather of ``self.rays`` candidates, in rounds of the batch set."""
        self.batches.begin(self.rays, seeds)
        valid = np.asarray(si.is_valid(), dtype=bool)
        while True:
            active, u = self.batches.next_candidates()
            if not active.any():
                break
            candidates = Candidates(self, si, bsdf, u, rng.random(len(u)))
            in_support = valid & active & candidates.in_support()
            trace, _ = self.batches.decide(candidates.directions(), in_support)
            values, ratings = candidates.trace(trace)
            self.batches.record(values, ratings)
        estimates, _, _ = self.batches.finish()
        return estimates.astype(np.float64)


def rgb(value) -> np.ndarray:
    """A Mitsuba colour or float array as ``(N, 3)`` numpy."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim == 1:
        return np.repeat(array[:, None], 3, axis=1)
    return array.T


class Candidates:
    """One round's candidates of every gather: a 50/50 mixture of emitter sampling and BSDF
    sampling, chosen by the first number, so that each candidate's density is
    ``(p_emitter + p_bsdf) / 2`` (the balance heuristic)."""

    def __init__(self, host: MitsubaGather, si, bsdf, u: np.ndarray, lobe: np.ndarray):
        mi, dr = host.mi, host.dr
        self.host, self.si, self.bsdf = host, si, bsdf
        self.context = mi.BSDFContext()
        by_emitter = u[:, 0] < 0.5
        stretched = np.where(by_emitter, 2 * u[:, 0], 2 * u[:, 0] - 1).clip(0, 1 - 1e-7)
        self.by_emitter_np = by_emitter
        self.by_emitter = mi.Bool(by_emitter)
        sample = mi.Point2f(mi.Float(stretched), mi.Float(u[:, 1]))
        # Emitter sampling: a direction toward a light, its radiance and density.
        self.ds, emitter_weight = host.scene.sample_emitter_direction(
            si, sample, False, self.by_emitter
        )
        self.radiance = emitter_weight * dr.select(self.ds.delta, 1.0, self.ds.pdf)
        # BSDF sampling: a direction from the BSDF, its value (with the cosine) and density.
        self.bs, bsdf_weight = bsdf.sample(self.context, si, mi.Float(lobe), sample, ~self.by_emitter)
        self.bsdf_delta = mi.has_flag(self.bs.sampled_type, mi.BSDFFlags.Delta)
        self.bsdf_value = bsdf_weight * dr.select(self.bsdf_delta, 1.0, self.bs.pdf)
        self.direction = dr.select(self.by_emitter, self.ds.d, si.to_world(self.bs.wo))
        wo = si.to_local(self.ds.d)
        self.emitter_bsdf = bsdf.eval(self.context, si, wo, self.by_emitter)
        self.emitter_bsdf_pdf = bsdf.pdf(self.context, si, wo, self.by_emitter)
        dr.eval(self.ds, self.radiance, self.bs, self.bsdf_value, self.direction)
        dr.eval(self.emitter_bsdf, self.emitter_bsdf_pdf)

    def directions(self) -> np.ndarray:
        """``(G, 3)`` world directions."""
        return np.asarray(self.direction, dtype=np.float32).T

    def in_support(self) -> np.ndarray:
        """Whether each candidate can carry light: a density and a BSDF value above zero."""
        mi, dr = self.host.mi, self.host.dr
        emitter_ok = (self.ds.pdf > 0) & (dr.max(self.emitter_bsdf) > 0) & (dr.max(self.radiance) > 0)
        bsdf_ok = (self.bs.pdf > 0) & (dr.max(self.bsdf_value) > 0)
        return np.asarray(dr.select(self.by_emitter, emitter_ok, bsdf_ok), dtype=bool)

    def trace(self, trace: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Traces the accepted candidates: ``(values, ratings)``, ``(G, 3)`` and ``(G,)``."""
        mi, dr = self.host.mi, self.host.dr
        scene, si = self.host.scene, self.si
        traced = mi.Bool(trace)
        # Emitter candidates: a shadow ray to the light.
        to_light = traced & self.by_emitter
        blocked = scene.ray_test(si.spawn_ray_to(self.ds.p), to_light)
        mixture = 0.5 * dr.select(self.ds.delta, 1.0, self.ds.pdf) + 0.5 * dr.select(
            self.ds.delta, 0.0, self.emitter_bsdf_pdf
        )
        emitter_value = self.emitter_bsdf * self.radiance / dr.maximum(mixture, 1e-30)
        emitter_value = dr.select(to_light & ~blocked, emitter_value, 0.0)
        # BSDF candidates: the ray finds what it hits; light arrives if that emits.
        along_bsdf = traced & ~self.by_emitter
        hit = scene.ray_intersect(si.spawn_ray(self.direction), along_bsdf)
        arriving = hit.emitter(scene).eval(hit, along_bsdf)
        emitter_pdf = scene.pdf_emitter_direction(
            si, mi.DirectionSample3f(scene, hit, si), along_bsdf & ~self.bsdf_delta
        )
        mixture = 0.5 * dr.select(self.bsdf_delta, 1.0, self.bs.pdf) + 0.5 * dr.select(
            self.bsdf_delta, 0.0, emitter_pdf
        )
        bsdf_value = dr.select(
            along_bsdf, self.bsdf_value * arriving / dr.maximum(mixture, 1e-30), 0.0
        )
        value = dr.select(self.by_emitter, emitter_value, bsdf_value)
        light_arrived = dr.select(self.by_emitter, ~blocked, dr.max(arriving) > 0)
        values = np.asarray(value, dtype=np.float32).T
        ratings = np.asarray(light_arrived, dtype=np.float32)
        return np.ascontiguousarray(values), ratings


def direct_reference(mi, path: Path, spp: int, defines: Dict[str, Any], samples: int = 4):
    """Mitsuba's own ``direct`` integrator on the scene (``samples`` emitter and BSDF samples
    per camera ray), for comparison: an ``(H, W, 3)`` float32 array."""
    text = mitsuba_text(path.read_text())
    direct = (
        f'<integrator type="direct"><integer name="emitter_samples" value="{samples}"/>'
        f'<integer name="bsdf_samples" value="{samples}"/></integrator>'
    )
    text, count = re.subn(r"<integrator\b.*?(/>|</integrator>)", direct, text, count=1, flags=re.S)
    if count == 0:
        text = text.replace("</scene>", direct + "</scene>")
    mi.file_resolver().prepend(str(path.resolve().parent))
    scene = mi.load_string(text, **{k: str(v) for k, v in defines.items()})
    return np.asarray(mi.render(scene, spp=spp), dtype=np.float32)[:, :, :3]


def render(
    scene: os.PathLike,
    *,
    spp: int,
    rays: int = 16,
    ais: str = "off",
    seed: int = 0,
    variant: str = "llvm_ad_rgb",
    defines: Optional[Dict[str, Any]] = None,
) -> Tuple[np.ndarray, Dict[str, Any]]:
    """Renders ``scene``'s direct light with Mitsuba and ais: ``(image, stats)``."""
    mi = import_mitsuba(variant)
    loaded = load_scene(mi, Path(scene), defines or {})
    return MitsubaGather(mi, loaded, rays=rays, ais=ais, seed=seed).render(spp)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m ais.mitsuba", description=__doc__.splitlines()[0]
    )
    parser.add_argument("scene", type=Path, help="a Mitsuba 3 XML scene file")
    parser.add_argument("--spp", type=int, required=True, help="samples per pixel")
    parser.add_argument("--rays", type=int, default=16, help="candidates per gather")
    parser.add_argument("--ais", default="off", help="off, aggressive or conservative")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant")
    parser.add_argument("-D", dest="defines", action="append", default=[], help="name=value")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output EXR")
    parser.add_argument(
        "--mitsuba-direct", action="store_true",
        help="render with Mitsuba's own direct integrator instead (for comparison)",
    )
    args = parser.parse_args(argv)
    if args.spp < 1 or args.rays < 1:
        parser.error("--spp and --rays must be at least 1")
    if args.output.suffix.lower() != ".exr":
        parser.error(f"{args.output}: the output must be an .exr file")
    defines = dict(d.split("=", 1) for d in args.defines if "=" in d)
    from . import write_exr

    try:
        if args.mitsuba_direct:
            mi = import_mitsuba(args.variant)
            started = time.perf_counter()
            image = direct_reference(mi, args.scene, args.spp, defines)
            write_exr(args.output, np.ascontiguousarray(image))
            print(f"{args.output}: Mitsuba's direct integrator, {time.perf_counter() - started:.2f} s")
            return 0
        image, stats = render(
            args.scene, spp=args.spp, rays=args.rays, ais=args.ais, seed=args.seed,
            variant=args.variant, defines=defines,
        )
    except (RuntimeError, ValueError, OSError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    write_exr(args.output, image)
    gathers = max(stats["gathers"], 1)
    print(
        f"{args.output}: {image.shape[1]}×{image.shape[0]}, {args.spp} spp, n = {args.rays}, "
        f"AIS {args.ais}: {stats['traced'] / gathers:.1f} traced of "
        f"{stats['candidates'] / gathers:.1f} candidates per gather, "
        f"{stats['render_time']:.2f} s"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())

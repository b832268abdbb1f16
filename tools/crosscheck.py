#!/usr/bin/env python3
"""Preliminary cross-check of ais against Mitsuba 3 on the same scene file.

    python3 -m venv .venv && .venv/bin/pip install mitsuba numpy
    cargo build --release -p ais-cli
    .venv/bin/python tools/crosscheck.py scenes/open.xml [--spp 64] [--size 160x90]

Renders the scene with Mitsuba's `direct` integrator (scalar_rgb, emitter and BSDF samples
set by --mitsuba-samples) and with `ais render` (gather, MIS, AIS off), each at the same
resolution and samples per pixel, and prints per-channel mean ratios (ais / Mitsuba) and the
relative MSE between the two images. Mitsuba runs in a child process per scene, since
loading a second scene in one process has been seen to deadlock. The scene's own
<integrator> is replaced by Mitsuba's direct integrator for the Mitsuba render.

This is the first step of issue 5: no standard-error maps or block tests yet.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

MITSUBA_CHILD = r"""
import sys, numpy as np, mitsuba as mi
mi.set_variant('scalar_rgb')
scene = mi.load_file(sys.argv[1], res_x=int(sys.argv[3]), res_y=int(sys.argv[4]), spp=int(sys.argv[5]))
np.save(sys.argv[2], np.array(mi.render(scene)))
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--size", default="160x90")
    parser.add_argument("--rays", type=int, default=16, help="gather rays per camera sample (ais)")
    parser.add_argument("--mitsuba-samples", type=int, default=8, help="emitter and BSDF samples (Mitsuba direct)")
    parser.add_argument("--ais", default=os.path.join("target", "release", "ais"), help="path of the ais binary")
    args = parser.parse_args()
    try:
        import numpy as np
        import mitsuba as mi
    except ImportError as e:
        sys.exit(f"error: {e}; install with `pip install mitsuba numpy` (see the docstring)")
    width, height = (int(v) for v in args.size.lower().split("x"))
    if not os.path.exists(args.ais):
        sys.exit(f"error: {args.ais} not found; run `cargo build --release -p ais-cli` first")
    scene_dir = os.path.dirname(os.path.abspath(args.scene))
    with open(args.scene) as f:
        text = f.read()
    direct = (f'<integrator type="direct"><integer name="emitter_samples" value="{args.mitsuba_samples}"/>'
              f'<integer name="bsdf_samples" value="{args.mitsuba_samples}"/></integrator>')
    text, count = re.subn(r"<integrator\b[^>]*/>|<integrator\b[^>]*[^/]>.*?</integrator>", direct, text, count=1, flags=re.S)
    if count == 0:
        text = re.sub(r"(<scene\b[^>]*>)", r"\1" + direct, text, count=1)
    # ais reconstructs pixels with a box filter; Mitsuba's hdrfilm defaults to a Gaussian.
    if "<rfilter" not in text:
        text = re.sub(r"(<film\b[^>]*>)", r'\1<rfilter type="box"/>', text, count=1)
    with tempfile.TemporaryDirectory() as work:
        mitsuba_scene = os.path.join(scene_dir, f".crosscheck-{os.getpid()}.xml")
        with open(mitsuba_scene, "w") as f:
            f.write(text)
        try:
            reference = os.path.join(work, "mitsuba.npy")
            subprocess.run([sys.executable, "-c", MITSUBA_CHILD, mitsuba_scene, reference,
                            str(width), str(height), str(args.spp)], check=True)
        finally:
            os.remove(mitsuba_scene)
        ours_path = os.path.join(work, "ais.exr")
        subprocess.run([args.ais, "render", args.scene, "--resolution", f"{width}x{height}",
                        "--spp", str(args.spp), "--rays", str(args.rays), "--strategy", "mis",
                        "--ais", "off", "--quiet", "--no-preview", "-o", ours_path],
                       check=True, stdout=subprocess.DEVNULL)
        mi.set_variant("scalar_rgb")
        ours = np.array(mi.Bitmap(ours_path))[..., :3]
        theirs = np.load(reference)[..., :3]
    ratio = ours.reshape(-1, 3).mean(0) / theirs.reshape(-1, 3).mean(0)
    rel_mse = float(((ours - theirs) ** 2 / (theirs ** 2 + 1e-2)).mean())
    print(f"{args.scene}: mean ratio ais/Mitsuba R {ratio[0]:.4f} G {ratio[1]:.4f} B {ratio[2]:.4f}; "
          f"relMSE {rel_mse:.2e} ({args.spp} spp, {width}x{height})")


if __name__ == "__main__":
    main()

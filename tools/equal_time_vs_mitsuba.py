#!/usr/bin/env python3
"""Noise per second against Mitsuba 3: ais (AIS off and `auto`) and Mitsuba's llvm variant
render the same scene files with the same work per camera sample; each render's relMSE
against a long reference, times its render time, is its inverse efficiency.

    cargo build --release -p ais-cli
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
        .venv/bin/python tools/equal_time_vs_mitsuba.py scenes/sunlit_room.xml [more scenes] \\
        [--spp 64] [--seeds 3] [--reference-spp 2048] [--markdown]

Per scene:
- Mitsuba 3 llvm_ad_rgb renders `--seeds` images at `--spp` with its `direct` integrator,
  `--rays`/2 emitter and BSDF samples per camera sample (the rewrite of
  tools/bench_vs_mitsuba.py), after one warm-up render that compiles its kernels; each
  render is timed alone (loading and compiling excluded).
- ais renders `--seeds` images at the same spp with the scene's own gather (`--rays` rays)
  for each of `--modes`, timed by its "render time" line, at the default thread count.
- The reference is ais with AIS off at `--reference-spp`, as two renders of half that
  each; their difference estimates its own noise, which is taken out of every relMSE
  (ais and Mitsuba agree within the cross-check's bounds: BENCHMARKS.md §4).
- relMSE is the mean over pixels of (x − ref)² / (ref² + 0.01). Printed: each renderer's
  median time and mean relMSE, and for each ais mode the efficiency ratio
  (relMSE × time of Mitsuba) / (relMSE × time of ais): above 1, ais has less noise for the
  same time. Its ± is the standard error from the seeds' spread (relMSE only; times
  are medians).
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck  # noqa: E402  (the scene rewrite for Mitsuba)

ROOT = crosscheck.ROOT
EPSILON = crosscheck.RELMSE_EPSILON

# Loads the scene, renders once (the kernels compile), then renders `seeds` times, timing
# each, and saves the stack of images and the times.
MITSUBA_CHILD = r"""
import sys, time, numpy as np, mitsuba as mi, drjit as dr
mi.set_variant('llvm_ad_rgb')
scene = mi.load_file(sys.argv[1])
seeds, spp = int(sys.argv[3]), int(sys.argv[4])
dr.eval(mi.render(scene, seed=0, spp=spp)); dr.sync_thread()
images, times = [], []
for seed in range(1, seeds + 1):
    started = time.perf_counter()
    image = mi.render(scene, seed=seed, spp=spp)
    dr.eval(image); dr.sync_thread()
    times.append(time.perf_counter() - started)
    images.append(np.array(image)[..., :3])
np.save(sys.argv[2], np.stack(images))
np.save(sys.argv[2].replace('.npy', '-times.npy'), np.array(times))
"""


def render_mitsuba(scene, args, work):
    """Mitsuba's images (seeds, H, W, 3) and render times."""
    import numpy as np
    width, height = (int(v) for v in args.size.lower().split("x"))
    with open(scene) as f:
        text = crosscheck.mitsuba_scene_text(f.read(), width, height, args.rays // 2)
    folder = os.path.dirname(os.path.abspath(scene))
    with tempfile.NamedTemporaryFile("w", suffix=".xml", dir=folder, delete=False) as copy:
        copy.write(text)
    out = os.path.join(work, "mitsuba.npy")
    try:
        done = subprocess.run([sys.executable, "-c", MITSUBA_CHILD, copy.name, out, str(args.seeds),
                               str(args.spp)], capture_output=True, text=True)
    finally:
        os.remove(copy.name)
    if done.returncode != 0:
        sys.exit(f"Mitsuba could not render {scene}:\n{done.stderr.strip()}")
    return np.load(out).astype(np.float64), list(np.load(out.replace(".npy", "-times.npy")))


def render_ais(scene, args, mode, spp, seed, out):
    """One ais render: its image and render time."""
    import mitsuba as mi
    import numpy as np
    command = [args.ais, "render", scene, "--resolution", args.size, "--spp", str(spp), "--rays",
               str(args.rays), "--ais", mode, "--seed", str(seed), "--no-preview", "-o", out]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"`{' '.join(command)}` failed:\n{done.stderr.strip()}")
    seconds = next(float(line.split()[2]) for line in done.stdout.splitlines()
                   if line.startswith("render time"))
    return np.array(mi.Bitmap(out))[..., :3].astype(np.float64), seconds


def reference(scene, args, work):
    """The reference image and its own noise per pixel (the variance of the mean of its
    two halves)."""
    half = args.reference_spp // 2
    a, _ = render_ais(scene, args, "off", half, 9001, os.path.join(work, "ref-a.exr"))
    b, _ = render_ais(scene, args, "off", half, 9002, os.path.join(work, "ref-b.exr"))
    return (a + b) / 2, (a - b) ** 2 / 4


def relmse(image, ref, ref_noise):
    """relMSE against `ref`, its own noise taken out."""
    weight = 1.0 / (ref ** 2 + EPSILON)
    return float(((image - ref) ** 2 * weight).mean() - (ref_noise * weight).mean())


def summary(errors, times):
    """Mean relMSE, its standard error, median time."""
    mean = statistics.fmean(errors)
    error = statistics.stdev(errors) / len(errors) ** 0.5 if len(errors) > 1 else 0.0
    return mean, error, statistics.median(times)


def study(scene, args):
    """One scene's row: (name, Mitsuba's summary, {mode: summary})."""
    with tempfile.TemporaryDirectory() as work:
        ref, ref_noise = reference(scene, args, work)
        images, times = render_mitsuba(scene, args, work)
        mitsuba = summary([relmse(image, ref, ref_noise) for image in images], times)
        modes = {}
        for mode in args.modes.split(","):
            errors, seconds = [], []
            for seed in range(1, args.seeds + 1):
                image, t = render_ais(scene, args, mode, args.spp, seed, os.path.join(work, "ais.exr"))
                errors.append(relmse(image, ref, ref_noise))
                seconds.append(t)
            modes[mode] = summary(errors, seconds)
    return os.path.basename(scene), mitsuba, modes


def ratio(mitsuba, ais):
    """Mitsuba's relMSE × time over ais's, and its standard error from the two relMSEs."""
    (m, m_se, m_t), (a, a_se, a_t) = mitsuba, ais
    value = (m * m_t) / (a * a_t)
    return value, value * ((m_se / m) ** 2 + (a_se / a) ** 2) ** 0.5


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--rays", type=int, default=16)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--modes", default="off,auto", help="ais's --ais modes, comma-separated")
    parser.add_argument("--ais", default=os.path.join(ROOT, "target", "release", "ais"))
    parser.add_argument("--markdown", action="store_true")
    args = parser.parse_args()
    modes = args.modes.split(",")
    if args.markdown:
        heads = " | ".join(f"ais {m}: relMSE, s | {m}: Mitsuba / ais" for m in modes)
        print(f"| scene | Mitsuba llvm: relMSE, s | {heads} |")
        print("|---|---|" + "---|---|" * len(modes))
    for scene in args.scenes:
        name, mitsuba, results = study(scene, args)
        cells = [f"{mitsuba[0]:.4g}, {mitsuba[2]:.3f}"]
        for mode in modes:
            value, error = ratio(mitsuba, results[mode])
            cells += [f"{results[mode][0]:.4g}, {results[mode][2]:.3f}", f"{value:.2f}× ± {error:.2f}"]
        if args.markdown:
            print(f"| {name} | " + " | ".join(cells) + " |", flush=True)
        else:
            print(f"{name}: Mitsuba {cells[0]}; " + "; ".join(
                f"{mode} {cells[1 + 2 * k]} ({cells[2 + 2 * k]})" for k, mode in enumerate(modes)), flush=True)


if __name__ == "__main__":
    main()

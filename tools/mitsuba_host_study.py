#!/usr/bin/env python3
"""AIS inside Mitsuba 3 at equal time: `python -m ais.mitsuba`'s gather with AIS off and on.

For each scene: a reference rendered by the same host with AIS off at --reference-spp (same
estimator, same box filter), then every mode at --spp for --seeds seeds, each render timed
after a warm-up (Dr.Jit compiles its kernels on the first). Prints per mode: traced rays
per gather, time, relMSE = mean((x − r)² / (r² + 0.01)) less the reference's own noise,
and the efficiency ratios against AIS off: at equal time, (relMSE_off · t_off) / (relMSE · t),
with its standard error over seeds, and at equal traced rays, (relMSE_off · traced_off) /
(relMSE · traced). One Mitsuba scene per process.

    python tools/mitsuba_host_study.py scenes/sunlit_room.xml scenes/cornell_box.xml

Needs the package and Mitsuba in the running Python (pip install . mitsuba) and the LLVM
library (apt install libllvm19).
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

WORKER = """
import json, sys, time, numpy as np
from pathlib import Path
from ais.mitsuba import MitsubaGather, import_mitsuba, load_scene
path, mode, spp, rays, seeds, out, res = sys.argv[1:8]
width, height = res.split("x")
mi = import_mitsuba("llvm_ad_rgb")
loaded = load_scene(mi, Path(path), {"res_x": width, "res_y": height})
MitsubaGather(mi, loaded, rays=int(rays), ais=mode, seed=999).render(1)  # warm-up
images, times, traced = [], [], []
for seed in json.loads(seeds):
    host = MitsubaGather(mi, loaded, rays=int(rays), ais=mode, seed=seed)
    image, stats = host.render(int(spp))
    images.append(image)
    times.append(stats["render_time"])
    traced.append(stats["traced"] / max(stats["gathers"], 1))
np.save(out, np.stack(images))
print(json.dumps({"times": times, "traced": traced}))
"""


def renders(scene, mode, spp, rays, seeds, resolution, folder):
    out = Path(folder) / f"{Path(scene).stem}-{mode}-{spp}.npy"
    done = subprocess.run(
        [sys.executable, "-c", WORKER, str(scene), mode, str(spp), str(rays),
         json.dumps(list(seeds)), str(out), resolution],
        capture_output=True, text=True, check=False,
    )
    if done.returncode != 0:
        sys.exit(f"{scene} {mode}: {done.stderr[-2000:]}")
    return np.load(out), json.loads(done.stdout.splitlines()[-1])


def rel_mse(image, reference):
    return float(np.mean((image - reference) ** 2 / (reference**2 + 0.01)))


def study(scene, args, folder):
    reference, _ = renders(scene, "off", args.reference_spp, args.rays, [10_000], args.resolution, folder)
    reference = reference[0]
    rows = {}
    for mode in args.modes:
        images, info = renders(scene, mode, args.spp, args.rays, range(args.seeds), args.resolution, folder)
        errors = np.array([rel_mse(image, reference) for image in images])
        # The reference's own noise adds about relMSE · spp / reference_spp to each error.
        errors = errors * (1 - args.spp / args.reference_spp)
        rows[mode] = (errors, np.array(info["times"]), float(np.mean(info["traced"])))
    base_errors, base_times, _ = rows[args.modes[0]]
    base = base_errors.mean() * base_times.mean()
    print(f"\n{scene}: {args.resolution}, {args.spp} spp, n = {args.rays}, {args.seeds} seeds")
    print("| mode | traced/gather | time (s) | relMSE | equal time vs first | equal traced rays vs first |")
    print("|---|---|---|---|---|---|")
    for mode, (errors, times, traced) in rows.items():
        if mode == args.modes[0]:
            print(f"| {mode} | {traced:.1f} | {times.mean():.2f} | {errors.mean():.3e} | 1 (baseline) | 1 |")
            continue
        cost = errors.mean() * times.mean()
        # Relative errors of the two means, combined (seeds are independent).
        spread = np.hypot(errors.std(ddof=1) / errors.mean(), times.std(ddof=1) / times.mean())
        spread = np.hypot(spread, np.hypot(base_errors.std(ddof=1) / base_errors.mean(),
                                           base_times.std(ddof=1) / base_times.mean()))
        ratio = base / cost
        by_rays = base_errors.mean() * rows[args.modes[0]][2] / (errors.mean() * traced)
        print(f"| {mode} | {traced:.1f} | {times.mean():.2f} | {errors.mean():.3e} | "
              f"{ratio:.2f}× ± {ratio * spread / np.sqrt(args.seeds):.2f} | {by_rays:.2f}× |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+", type=Path)
    parser.add_argument("--spp", type=int, default=8)
    parser.add_argument("--rays", type=int, default=16)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--reference-spp", type=int, default=256)
    parser.add_argument("--resolution", default="128x128")
    parser.add_argument("--modes", default="off,aggressive,conservative")
    args = parser.parse_args()
    args.modes = args.modes.split(",")
    with tempfile.TemporaryDirectory() as folder:
        for scene in args.scenes:
            study(scene, args, folder)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Where Mitsuba 3's frame goes: its warm renders of a scene recorded by perf, split between
Embree (tracing) and the kernels its JIT compiled (everything else), beside ais's own profile.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
        .venv/bin/python tools/profile_mitsuba.py scenes/sunlit_room.xml [--renders 12]

The scene is rewritten for Mitsuba as tools/bench_vs_mitsuba.py rewrites it (its `direct`
integrator with `--rays`/2 emitter and BSDF samples, the film at `--size`), loaded, and
rendered once so that the llvm variant compiles its kernels. Only then does `perf record`
attach to the process, for `--renders` more renders at `--spp`. Printed: the median render
time, and the share of the recorded samples in each shared object (`[JIT]` is the compiled
kernels). Needs `perf` and Mitsuba in the Python that runs it.
"""
import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck  # noqa: E402  (the scene rewrite for Mitsuba)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--variant", default="llvm_ad_rgb")
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--rays", type=int, default=16)
    parser.add_argument("--renders", type=int, default=12)
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.lower().split("x"))
    with open(args.scene) as f:
        text = crosscheck.mitsuba_scene_text(f.read(), width, height, args.rays // 2)
    folder = os.path.dirname(os.path.abspath(args.scene))
    with tempfile.NamedTemporaryFile("w", suffix=".xml", dir=folder, delete=False) as copy:
        copy.write(text)
    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    try:
        scene = mi.load_file(copy.name)
    finally:
        os.remove(copy.name)

    def timed(seed):
        started = time.perf_counter()
        dr.eval(mi.render(scene, seed=seed, spp=args.spp))
        dr.sync_thread()
        return time.perf_counter() - started

    timed(0)  # the kernels are compiled here, before perf attaches
    with tempfile.TemporaryDirectory() as scratch:
        data = os.path.join(scratch, "perf.data")
        perf = subprocess.Popen(["perf", "record", "-q", "-o", data, "-p", str(os.getpid())],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1.0)  # perf attaches
        times = [timed(seed) for seed in range(1, args.renders + 1)]
        perf.send_signal(signal.SIGINT)
        perf.wait()
        report = perf_report(data, "dso")
        symbols = perf_report(data, "dso,symbol")
    print(f"{args.scene}: Mitsuba {args.variant}, median render {statistics.median(times):.3f} s "
          f"over {args.renders} renders")
    for line in report.splitlines():
        if "%" in line and not line.lstrip().startswith("#"):
            share, *name = line.split()
            if float(share.rstrip("%")) >= 0.5:
                print(f"  {share:>7}  {' '.join(name)}")
    # Embree's time by query: closest hits (camera and BSDF rays) and occlusion (emitter rays).
    for query in ("intersect", "occluded"):
        total = sum(float(line.split()[0].rstrip("%")) for line in symbols.splitlines()
                    if "libembree" in line and f">::{query}" in line and "%" in line)
        print(f"  {total:6.2f}%  Embree's {query} queries")


def perf_report(data, keys):
    """perf's report of `data`, self time sorted by `keys`."""
    return subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", keys, "--stdio"],
                          capture_output=True, text=True, check=True).stdout


if __name__ == "__main__":
    main()

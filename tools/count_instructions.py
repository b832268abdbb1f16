#!/usr/bin/env python3
"""Instructions a camera sample costs, counted by Valgrind's callgrind: a measure that,
unlike a clock on a shared 2-core host, does not move from one run to the next.

    python3 tools/count_instructions.py scenes/open.xml [default] [more] \\
        [--ais BINARY [--ais OTHER]] [--size 32x32] [--spp 16] [--rays 16] [--top 12] \\
        [--time ROUNDS] [--groups] [-- --ais off]

Only the work of the pixels is counted (`pixel_radiance`, every camera sample's gather
and the pixel's pool, and `Film::splat`), not loading, and it is divided by the camera
samples. With two binaries, each scene's line gives old over new (above 1: NEW runs
fewer instructions). With `--time ROUNDS`, each binary also renders the same frame
ROUNDS times outside Valgrind (one thread), and the fastest render time ("render time",
loading excluded) gives the nanoseconds a camera sample takes and the instructions run
per nanosecond. With `--groups`, a last table sums the functions' counts by the stage of
a camera sample they belong to (`GROUPS`). Everything after `--` is passed to every
render.

Valgrind does not know AVX-512, so the binaries must be built for a CPU without it; the
default binary is such a build, with line tables, brought up to date on every run:

    RUSTFLAGS="-C target-cpu=x86-64-v3" CARGO_PROFILE_RELEASE_DEBUG=line-tables-only \\
        CARGO_TARGET_DIR=target/callgrind cargo build --release -p ais-cli

Fewer instructions is not the same as less time (a wait on memory costs no instruction,
a vector instruction does sixteen lanes' work): a count says where the work is and
whether a change removed some; the clock (tools/compare_builds.py) says whether it paid.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# The same render, on one thread, as the builds' comparison times it.
from compare_builds import RENDER_TIME, render_command  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_BINARY = os.path.join(ROOT, "target", "callgrind", "release", "ais")
# The functions whose instructions are counted, with everything they call.
COUNTED = ["*SampleIntegrator>::pixel_radiance", "ais_render::film::Film::splat"]
# The stages of a camera sample, each with the parts of the function names that go to it
# (the first group that matches takes a function; inlined code counts where it is inlined).
GROUPS = [
    ("shadow rays", ["occluded_after", "blocking_distance", "Packed::intersect",
                     "occluded_aiming", "shaft", "Shaft::", "RecentBlockers"]),
    ("camera ray, first hit", ["Geometry::intersect", "PixelRays::fill", "frame_for",
                               "attribute_site", "camera::"]),
    ("light draws and light hits", ["EnvironmentDraws", "invert_guided", "AreaDraws",
                                    "sample_run", "sample_toward", "spherical_rectangle",
                                    "rectangles_along", "write_source", "all_missed",
                                    "AreaLight", "sources_along", "alias", "mesh_emitter",
                                    "acos", "atan2"]),
    ("the plain lanes", ["PlainLanes", "draw_bsdf_run", "weighed"]),
    ("the pool and map lookups", ["pixel_radiance", "look_up_lanes", "interpolate"]),
    ("a gather's set-up", ["run_plain", "rescramble", "halton", "gather::gather",
                           "gather_point", "run_batch", "try_from_fn", "get_or_insert",
                           "memset", "memcpy"]),
    ("the film", ["Film::splat"]),
]
# A line of `callgrind_annotate`: the count, then `file:function [object]`.
ANNOTATED = re.compile(r"^\s*([0-9,]+)\s+(?:\([^)]*\)\s+)?(\S+?):(.+?)(?: \[.*\])?$")


def build_default():
    """Brings the default binary (portable, with line tables) up to date with the source."""
    env = dict(os.environ, RUSTFLAGS="-C target-cpu=x86-64-v3",
               CARGO_PROFILE_RELEASE_DEBUG="line-tables-only",
               CARGO_TARGET_DIR=os.path.join(ROOT, "target", "callgrind"))
    print("building ais without AVX-512 for Valgrind (target/callgrind)", file=sys.stderr)
    subprocess.run(["cargo", "build", "--release", "-p", "ais-cli"], cwd=ROOT, env=env, check=True)


def run(command, binary, scene):
    """Runs `command`; exits with its error if it fails. Returns what it printed."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"count_instructions: {binary} failed on {scene} (exit {done.returncode}):\n"
                 f"{done.stderr.strip()[-2000:]}")
    return done.stdout + done.stderr


def count(binary, scene, args, folder):
    """The callgrind output file of `binary` rendering `scene` on one thread."""
    out = os.path.join(folder, "callgrind.out")
    command = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
    command += [f"--toggle-collect={name}" for name in COUNTED]
    output = os.path.join(folder, "out.exr")
    run(command + render_command(binary, scene, args, output), binary, scene)
    return out


def fastest_time(binary, scene, args, folder):
    """The fastest of `args.time` render times of `binary` on `scene`, in seconds."""
    times = []
    for _ in range(args.time):
        command = render_command(binary, scene, args, os.path.join(folder, "out.exr"))
        printed = run(command, binary, scene)
        found = RENDER_TIME.search(printed)
        if not found:
            sys.exit(f"count_instructions: no render time in {binary}'s output on {scene}")
        times.append(float(found.group(1)))
    return min(times)


def functions(out):
    """The total and each function's own instructions (by name, over all its files)."""
    done = subprocess.run(["callgrind_annotate", "--auto=no", "--threshold=100", out],
                          capture_output=True, text=True, check=True)
    total, own = None, {}
    for line in done.stdout.splitlines():
        if line.rstrip().endswith("PROGRAM TOTALS"):
            total = int(line.split()[0].replace(",", ""))
            continue
        found = ANNOTATED.match(line)
        if not found:
            continue
        instructions = int(found.group(1).replace(",", ""))
        name = found.group(3).strip()
        own[name] = own.get(name, 0) + instructions
    if not total:
        sys.exit(f"count_instructions: nothing was counted: no function matched {COUNTED} "
                 "(renamed? update COUNTED)")
    return total, own


def grouped(own):
    """`own`'s counts summed by `GROUPS`, and what no group took under "the rest"."""
    sums = {name: 0 for name, _ in GROUPS + [("the rest", [])]}
    for function, instructions in own.items():
        group = next((name for name, parts in GROUPS if any(p in function for p in parts)),
                     "the rest")
        sums[group] += instructions
    return sums


def print_groups(rows, samples):
    """The `--groups` table: per render, each group's instructions per camera sample."""
    names = [name for name, _ in GROUPS] + ["the rest"]
    print("\n| render | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for label, sums in rows:
        total = sum(sums.values())
        cells = (f"{sums[n] / samples:,.0f} ({sums[n] / total:.0%})" for n in names)
        print(f"| {label} | " + " | ".join(cells) + " |")


def camera_samples(args):
    width, height = (int(v) for v in args.size.split("x"))
    return width * height * args.spp


def parse_args():
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scenes", nargs="+", help="scene files, or `default`")
    parser.add_argument("--ais", action="append", help="an ais binary without AVX-512 (twice: old, new)")
    parser.add_argument("--size", default="32x32")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--rays", type=int, default=16)
    parser.add_argument("--top", type=int, default=12, help="functions listed per render")
    parser.add_argument("--time", type=int, default=0, metavar="ROUNDS",
                        help="also time ROUNDS renders outside Valgrind")
    parser.add_argument("--groups", action="store_true",
                        help="also sum the counts by stage of a camera sample")
    args = parser.parse_args(argv)
    args.extra = extra
    if not re.fullmatch(r"[1-9][0-9]*x[1-9][0-9]*", args.size):
        parser.error(f"--size {args.size!r} is not WIDTHxHEIGHT")
    if args.ais and len(args.ais) > 2:
        parser.error("at most two binaries (old and new)")
    return args


def main():
    args = parse_args()
    for tool in ("valgrind", "callgrind_annotate"):
        if shutil.which(tool) is None:
            sys.exit(f"count_instructions: `{tool}` not found; install Valgrind (Debian: valgrind)")
    binaries = args.ais or [DEFAULT_BINARY]
    if not args.ais:
        build_default()
    for binary in binaries:
        if not os.path.exists(binary):
            sys.exit(f"count_instructions: {binary} not found")
    samples = camera_samples(args)
    rows = []
    for scene in args.scenes:
        per_sample = []
        for binary in binaries:
            with tempfile.TemporaryDirectory() as folder:
                total, own = functions(count(binary, scene, args, folder))
                fastest = fastest_time(binary, scene, args, folder) if args.time else None
            per_sample.append(total / samples)
            line = f"{scene} ({binary}): {total / samples:,.0f} instructions per camera sample"
            if fastest:
                line += (f"; fastest of {args.time}: {fastest:.3f} s, "
                         f"{fastest * 1e9 / samples:,.0f} ns per camera sample, "
                         f"{total / (fastest * 1e9):.2f} instructions per ns")
            print(line)
            rows.append((f"{scene} ({os.path.basename(binary)})", grouped(own)))
            for name, instructions in sorted(own.items(), key=lambda kv: -kv[1])[:args.top]:
                print(f"  {instructions / samples:8,.0f}  {instructions / total:6.1%}  {name[:110]}")
        if len(per_sample) == 2:
            print(f"{scene}: old / new = {per_sample[0] / per_sample[1]:.4f}")
    if args.groups:
        print_groups(rows, samples)


if __name__ == "__main__":
    main()

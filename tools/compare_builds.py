#!/usr/bin/env python3
"""Render time of two ais binaries on the same scenes, as ratios measured in one run.

    python3 tools/compare_builds.py OLD NEW scenes/sunlit_room.xml [default] [more] \\
        [--rounds 5] [--method paired|in-turn] [--spp 64] [--size 128x128] [--rays 16] \\
        [-- --ais off]

OLD and NEW are two `ais` binaries (copy `target/release/ais` aside after each build);
`default` stands for the built-in scene. Everything after `--` is passed to both renders.
Each render is one thread, seed 1, its "render time" line (loading excluded).

Two methods, both reporting old time / new time (above 1: NEW is faster):
- `paired` (the default): in each round both binaries render at once, one on each of two
  cores (`taskset`), the cores swapped from round to round, so that the machine's drift
  touches both alike; reported: the median of the rounds' ratios.
- `in-turn`: both binaries render one after the other on one core, alternating, while the
  other core stays idle; reported: the ratio of their fastest times, and of their medians.
  For days when the paired ratios scatter (a host busy with other guests slows one core
  more than the other).

Build the two binaries from commits (or with a part switched by an environment variable
through a wrapper script), and compare a binary against itself first: that control shows
how sure a ratio is on the day.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

RENDER_TIME = re.compile(r"^render time\s+([0-9.]+) s", re.MULTILINE)


def render_command(binary, scene, args, output):
    """The command that renders `scene` with `binary` on one thread."""
    command = [binary, "render"]
    if scene != "default":
        command.append(scene)
    command += ["--rays", str(args.rays), "--resolution", args.size, "--spp", str(args.spp)]
    command += ["--threads", "1", "--seed", "1", "--no-preview", "-q", "-o", output]
    return command + args.extra


def render_times(processes, names):
    """The render times that `processes` (all waited for) printed, or exit with the first
    failure's error."""
    finished = [process.communicate() for process in processes]
    times = []
    for process, (out, err), name in zip(processes, finished, names):
        found = RENDER_TIME.search(err) or RENDER_TIME.search(out)
        if process.returncode != 0 or not found:
            sys.exit(f"compare_builds: {name} failed (exit {process.returncode}):\n{err.strip()}")
        times.append(float(found.group(1)))
    return times


def start(binary, scene, args, core, output):
    """Starts a render of `scene` by `binary` pinned to `core`."""
    command = ["taskset", "-c", str(core)] + render_command(binary, scene, args, output)
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def measure(scene, args, folder):
    """The old and new times of each round for `scene`."""
    outputs = [os.path.join(folder, name) for name in ("old.exr", "new.exr")]
    times = ([], [])
    names = [f"{scene} (old)", f"{scene} (new)"]
    for round_index in range(args.rounds):
        if args.method == "paired":
            cores = (round_index % 2, 1 - round_index % 2)
            running = [
                start(binary, scene, args, core, output)
                for binary, core, output in zip((args.old, args.new), cores, outputs)
            ]
            pair = render_times(running, names)
        else:
            pair = [
                render_times([start(binary, scene, args, 1, output)], [name])[0]
                for binary, output, name in zip((args.old, args.new), outputs, names)
            ]
        for side, time in enumerate(pair):
            times[side].append(time)
    return times


def report(scene, times, method):
    """One line of the markdown table for `scene`."""
    old, new = times
    ratios = [o / n for o, n in zip(old, new)]
    listed = ", ".join(f"{r:.3f}" for r in ratios)
    if method == "paired":
        return f"| {scene} | {statistics.median(ratios):.3f} | {listed} |"
    fastest = min(old) / min(new)
    medians = statistics.median(old) / statistics.median(new)
    return f"| {scene} | {fastest:.3f} | {medians:.3f} | {listed} |"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old", help="the old ais binary")
    parser.add_argument("new", help="the new ais binary")
    parser.add_argument("scenes", nargs="+", help="scene files, or `default`")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--method", choices=("paired", "in-turn"), default="paired")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--rays", type=int, default=16)
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    args = parser.parse_args(argv[: argv.index("--")] if "--" in argv else argv)
    args.extra = extra
    if shutil.which("taskset") is None:
        sys.exit("compare_builds: needs `taskset` (Debian's util-linux) to pin renders to cores")
    if os.cpu_count() < 2:
        sys.exit("compare_builds: needs two cores")
    for binary in (args.old, args.new):
        if not os.access(binary, os.X_OK):
            sys.exit(f"compare_builds: {binary} is not an executable file")
    for scene in args.scenes:
        if scene != "default" and not os.path.isfile(scene):
            sys.exit(f"compare_builds: no scene file {scene}")
    if args.rounds < 1:
        sys.exit("compare_builds: --rounds must be at least 1")
    if args.method == "paired":
        print("| scene | old / new (median of rounds) | rounds |\n|---|---|---|")
    else:
        print("| scene | old / new (fastest) | old / new (medians) | rounds |\n|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for scene in args.scenes:
            print(report(scene, measure(scene, args, folder), args.method), flush=True)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Render time of ais against Mitsuba 3 on the same scene files, side by side.

    cargo build --release -p ais-cli
    python3 tools/bench_vs_mitsuba.py --setup scenes/sunlit_room.xml [more scenes] \\
        [--spp 64] [--rays 16] [--size 128x128] [--runs 3] [--markdown] [--define NAME=VALUE]

Same work in both renderers: the scene's camera at `--size`, `--spp` camera samples per
pixel, and per camera sample `--rays` gather rays. ais runs its gather with MIS and AIS off
(half BSDF, half light samples on average); Mitsuba runs its `direct` integrator with
`--rays`/2 emitter and `--rays`/2 BSDF samples. Every render is one process per scene, as
Mitsuba's llvm variant has deadlocked on a second scene load here (each variant's
process loads the scene once and renders it on request).

The renders are made in `--runs` rounds: each round renders the scene once with every
renderer in turn (ais at 2 and 1 threads, then each Mitsuba variant, which stays loaded
between rounds), so that the machine's drift between rounds touches them all alike.
Reported per scene, medians over the rounds:
- ais's render time at 2 threads (loading excluded: the "render time" line) and at 1 thread,
  and the scaling between them (the median of the rounds' ratios), with how many of the 2
  threads were busy on average (short of 2 where one waited for the other's last tiles;
  a scaling short of 2× with both busy is the machine, not the renderer);
- Mitsuba 3's llvm_ad_rgb and scalar_rgb render times (`mi.render` after one warm-up
  render, so the llvm variant's JIT compilation is excluded; loading excluded);
- rays per second, counted by ais for ais; for Mitsuba, the same nominal count
  (camera rays plus `--rays` per camera sample) over its time;
- the ratio Mitsuba llvm time / ais time (above 1: ais is faster): the median of the
  rounds' ratios;
- with `--ais-embree PATH` (ais built with `--features embree`, Debian's libembree-dev),
  that binary's render time at 2 threads and its ratio to Mitsuba llvm, in the same run.

Mitsuba's llvm variant needs an LLVM library of version 16 or later (Debian: the libllvm19
package). It is found through DRJIT_LIBLLVM_PATH or in the usual library folders; without
one, the llvm column is left out with a message. `--setup` makes `.venv` with Mitsuba and
numpy, as tools/crosscheck.py does.
"""
import argparse
import glob
import json
import os
import re
import queue
import statistics
import subprocess
import sys
import tempfile
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosscheck  # noqa: E402  (the scene rewrite for Mitsuba and the venv set-up)

ROOT = crosscheck.ROOT

# Loads the scene, renders it once (the llvm variant compiles its kernels), prints "ready",
# then renders it once more for every line read and prints that render's time.
MITSUBA_CHILD = r"""
import json, sys, time
import mitsuba as mi, drjit as dr
mi.set_variant(sys.argv[2])
scene = mi.load_file(sys.argv[1], **json.loads(sys.argv[4]))
spp = int(sys.argv[3])
def timed(seed):
    started = time.perf_counter()
    image = mi.render(scene, seed=seed, spp=spp)
    dr.eval(image)
    dr.sync_thread()
    return time.perf_counter() - started
timed(0)
print("ready", flush=True)
for seed, _ in enumerate(sys.stdin, start=1):
    print(timed(seed), flush=True)
"""


def find_libllvm():
    """An LLVM shared library that Dr.Jit can use (version 16 or later), or None."""
    given = os.environ.get("DRJIT_LIBLLVM_PATH")
    if given:
        return given if os.path.exists(given) else None
    candidates = glob.glob("/usr/lib/*/libLLVM-*.so") + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so")
    versioned = []
    for path in candidates:
        match = re.search(r"LLVM-(\d+)", path) or re.search(r"llvm-(\d+)", path)
        if match and int(match.group(1)) >= 16:
            versioned.append((int(match.group(1)), path))
    return max(versioned)[1] if versioned else None


def seconds_in(line):
    """The number a line holds, or None."""
    try:
        return float(line)
    except ValueError:
        return None


class MitsubaRenderer:
    """A Mitsuba process of one variant with `scene` loaded and warmed up, which renders it
    on request (so that its renders can be interleaved with ais's), or why it could not
    start (`note`)."""

    def __init__(self, scene, variant, args, libllvm):
        self.process, self.note, self.timeout = None, None, args.timeout
        width, height = (int(v) for v in args.size.lower().split("x"))
        with open(scene) as f:
            text = crosscheck.mitsuba_scene_text(f.read(), width, height, args.rays // 2)
        self.copy = os.path.join(os.path.dirname(os.path.abspath(scene)), f".bench-{os.getpid()}-{variant}.xml")
        with open(self.copy, "w") as f:
            f.write(text)
        env = dict(os.environ)
        if libllvm:
            env["DRJIT_LIBLLVM_PATH"] = libllvm
        self.variant = variant
        # Its log goes to a file: a pipe nobody reads could fill and stall it.
        self.log = tempfile.TemporaryFile(mode="w+")
        self.process = subprocess.Popen([sys.executable, "-c", MITSUBA_CHILD, self.copy, variant, str(args.spp),
                                         json.dumps(dict(args.define))],
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.log,
                                        text=True, env=env)
        # Its answers are read by a thread, so that waiting for one can time out.
        self.lines = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        if self._answer(lambda line: line if line == "ready" else None) is None:
            self.close()

    def _read(self):
        """Queues the child's lines, then None when it ends."""
        for line in self.process.stdout:
            self.lines.put(line)
        self.lines.put(None)

    def _answer(self, parse):
        """The first line of the child's that `parse` accepts (other lines are its log), or
        None (with `note` set) if it failed or did not answer within the timeout."""
        while True:
            try:
                line = self.lines.get(timeout=self.timeout)
            except queue.Empty:
                self.note = f"Mitsuba {self.variant} did not answer within {self.timeout} s"
                return None
            if line is None:
                self.process.wait()
                self.log.seek(0)
                self.note = f"Mitsuba {self.variant} failed: {self.log.read().strip().splitlines()[-1:]}"
                return None
            answer = parse(line.strip())
            if answer is not None:
                return answer

    def render(self):
        """The time of one render, or None."""
        if self.note:
            return None
        self.process.stdin.write("render\n")
        self.process.stdin.flush()
        return self._answer(seconds_in)

    def close(self):
        """Stops the process and removes its scene file."""
        if self.process and self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        if os.path.exists(self.copy):
            os.remove(self.copy)
        self.log.close()


def ais_render(scene, threads, args, seed, binary=None):
    """Render time, counted rays and threads busy on average (`time`, `rays`, `busy`) of one
    `ais render` (`binary`, else --ais) of `scene` at `threads`."""
    with tempfile.TemporaryDirectory() as work:
        command = [binary or args.ais, "render", scene, "--resolution", args.size, "--spp", str(args.spp),
                   "--integrator", "gather", "--strategy", "mis", "--rays", str(args.rays), "--ais", "off",
                   "--threads", str(threads), "--seed", str(seed), "--no-preview",
                   "-o", os.path.join(work, "ais.exr")]
        command += [word for name, value in args.define for word in ("-D", f"{name}={value}")]
        done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        crosscheck.fail_setup(f"`{' '.join(command)}` failed:\n{done.stderr.strip()}")
    report = done.stdout + done.stderr
    counted = re.search(r"rays\s+(\d+) camera \+ (\d+) occlusion", report)
    timed = re.search(r"render time\s+([0-9.]+) s \(([0-9.]+) threads busy", report)
    return {"time": float(timed.group(1)), "rays": int(counted.group(1)) + int(counted.group(2)),
            "busy": float(timed.group(2))}


def define(text):
    """A scene parameter from NAME=VALUE, as a (name, value) pair."""
    name, equals, value = text.partition("=")
    if not (name and equals):
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=VALUE")
    return name, value


def median_or_none(values):
    """The median of the values that are not None, or None."""
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def median_ratio(rounds, top, bottom):
    """The median over `rounds` of `top` / `bottom` where a round has both, or None."""
    return median_or_none([r[top] / r[bottom] for r in rounds if r.get(top) and r.get(bottom)])


def measure(scene, args, libllvm):
    """One row of the table: `--runs` rounds, each rendering once with every renderer in
    turn, so that the machine's drift between rounds touches all of them alike; medians of
    the times, and of each round's ratios."""
    width, height = (int(v) for v in args.size.lower().split("x"))
    variants = ["llvm_ad_rgb", "scalar_rgb"] if libllvm else ["scalar_rgb"]
    mitsuba = {variant: MitsubaRenderer(scene, variant, args, libllvm) for variant in variants}
    rounds = []
    try:
        for k in range(args.runs):
            two = ais_render(scene, 2, args, k)
            one = {"ais_2": two["time"], "ais_rays": two["rays"], "busy_2": two["busy"],
                   "ais_1": ais_render(scene, 1, args, k)["time"],
                   "embree_2": ais_render(scene, 2, args, k, args.ais_embree)["time"] if args.ais_embree else None}
            for variant, renderer in mitsuba.items():
                one[variant] = renderer.render()
            rounds.append(one)
    finally:
        for renderer in mitsuba.values():
            renderer.close()
    column = {key: median_or_none([r[key] for r in rounds]) for key in rounds[0]}
    row = {"scene": os.path.relpath(scene, ROOT), "nominal_rays": width * height * args.spp * (1 + args.rays),
           **column, "ais_rays": rounds[-1]["ais_rays"],
           "scaling": median_ratio(rounds, "ais_1", "ais_2"),
           "llvm_ratio": median_ratio(rounds, "llvm_ad_rgb", "ais_2"),
           "embree_ratio": median_ratio(rounds, "llvm_ad_rgb", "embree_2")}
    row["llvm_ad_rgb_note"] = (mitsuba["llvm_ad_rgb"].note if libllvm
                               else "no LLVM library (install Debian's libllvm19)")
    row.setdefault("llvm_ad_rgb", None)
    row["scalar_rgb_note"] = mitsuba["scalar_rgb"].note
    return row


def print_rows(rows, markdown):
    def seconds(value):
        return f"{value:.3f}" if value is not None else "—"

    def rate(rays, time):
        return f"{rays / time / 1e6:.1f} M" if time else "—"

    header = ["scene", "ais 2 thr (s)", "ais rays/s", "Mitsuba llvm (s)", "llvm rays/s (nominal)",
              "llvm / ais", "Mitsuba scalar (s)", "ais 1 thr (s)", "1 → 2 threads", "threads busy at 2"]
    embree = any(row["embree_2"] for row in rows)
    if embree:
        header += ["ais Embree 2 thr (s)", "llvm / ais Embree"]
    lines = []
    for row in rows:
        llvm = row["llvm_ad_rgb"]
        lines.append([row["scene"], seconds(row["ais_2"]), rate(row["ais_rays"], row["ais_2"]), seconds(llvm),
                      rate(row["nominal_rays"], llvm), f"{row['llvm_ratio']:.2f}×" if row["llvm_ratio"] else "—",
                      seconds(row["scalar_rgb"]), seconds(row["ais_1"]), f"{row['scaling']:.2f}×",
                      f"{row['busy_2']:.2f}"])
        if embree:
            lines[-1] += [seconds(row["embree_2"]),
                          f"{row['embree_ratio']:.2f}×" if row["embree_ratio"] else "—"]
    if markdown:
        print("| " + " | ".join(header) + " |")
        print("|" + "---|" * len(header))
        for line in lines:
            print("| " + " | ".join(line) + " |")
    else:
        widths = [max(len(str(x)) for x in column) for column in zip(header, *lines)]
        for line in [header] + lines:
            print("  ".join(str(x).ljust(w) for x, w in zip(line, widths)))
    for row in rows:
        for variant in ("llvm_ad_rgb", "scalar_rgb"):
            if row.get(variant + "_note"):
                print(f"note: {row['scene']}: {row[variant + '_note']}", file=sys.stderr)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    parser.add_argument("scenes", nargs="+", help="Mitsuba XML scene files")
    parser.add_argument("--setup", action="store_true", help="create --venv with Mitsuba and numpy, then run in it")
    parser.add_argument("--venv", default=os.path.join(ROOT, ".venv"))
    parser.add_argument("--size", default="128x128", help="film size for both renderers")
    parser.add_argument("--spp", type=int, default=64, help="camera samples per pixel")
    parser.add_argument("--rays", type=int, default=16, help="gather rays per camera sample (even)")
    parser.add_argument("--runs", type=int, default=3, help="timed runs per renderer (medians)")
    parser.add_argument("--timeout", type=int, default=900, help="seconds before a Mitsuba run is given up")
    parser.add_argument("--ais", default=os.path.join(ROOT, "target", "release", "ais"), help="the ais binary")
    parser.add_argument("--ais-embree", help="an ais binary built with --features embree, timed too")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    parser.add_argument("--define", action="append", default=[], type=define, metavar="NAME=VALUE",
                        help="a scene parameter for both renderers (ais's -D; Mitsuba's load_file)")
    args = parser.parse_args()
    if args.setup:
        python = crosscheck.setup_venv(args.venv)
        argv = [a for a in sys.argv[1:] if a != "--setup"]
        sys.exit(subprocess.run([python, os.path.abspath(__file__)] + argv).returncode)
    try:
        import mitsuba  # noqa: F401
    except ImportError as e:
        crosscheck.fail_setup(f"{e}; run with --setup (makes .venv with Mitsuba and numpy)", crosscheck.NO_MITSUBA)
    if args.ais_embree and not os.path.exists(args.ais_embree):
        crosscheck.fail_setup(f"{args.ais_embree} not found; run "
                              "`cargo build --release -p ais-cli --features embree` first")
    if not os.path.exists(args.ais):
        crosscheck.fail_setup(f"{args.ais} not found; run `cargo build --release -p ais-cli` first")
    if args.rays < 2 or args.rays % 2:
        parser.error("--rays must be even: half emitter, half BSDF samples for Mitsuba")
    crosscheck.ensure_assets()
    libllvm = find_libllvm()
    rows = []
    for scene in args.scenes:
        rows.append(measure(os.path.abspath(scene), args, libllvm))
        print(f"bench: {scene} done", file=sys.stderr, flush=True)
    print_rows(rows, args.markdown)


if __name__ == "__main__":
    main()

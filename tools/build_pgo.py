#!/usr/bin/env python3
"""A profile-guided build of the `ais` binary (a few per cent faster frames: BENCHMARKS.md,
section 3, "A profile-guided build").

    rustup component add llvm-tools          # once: llvm-profdata, matched to rustc
    python3 tools/build_pgo.py [--train SCENE ...] [--exclude SCENE ...]

Three steps:
1. builds ais with instrumentation (`-C profile-generate`) into target/pgo/instrumented;
2. renders the training scenes with it, small, with AIS off and with `auto`: by default
   every scene of scenes/ and scenes/crosscheck/ and the built-in one (`--exclude` leaves
   some out, `default` the built-in one, to measure on scenes the profile never saw);
3. merges the profiles with rustup's llvm-profdata and builds again with them
   (`-C profile-use`) into target/pgo/release/ais.

The flags of .cargo/config.toml (the building CPU's vector units) are kept: RUSTFLAGS would
replace them, so they are read from it and given again. The assets of scenes/ are made first if missing
(scenes/make_assets.py).
"""
import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.path.join(ROOT, "target", "pgo")


def config_flags():
    """The rustflags of .cargo/config.toml, which RUSTFLAGS would otherwise replace."""
    with open(os.path.join(ROOT, ".cargo", "config.toml"), "rb") as config:
        return tomllib.load(config).get("build", {}).get("rustflags", [])


def llvm_profdata():
    """rustup's llvm-profdata for the rustc in use, or exit saying how to get it."""
    sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True)
    host = next(
        line.split(": ", 1)[1]
        for line in subprocess.run(["rustc", "-vV"], capture_output=True, text=True, check=True).stdout.splitlines()
        if line.startswith("host: ")
    )
    tool = os.path.join(sysroot.stdout.strip(), "lib", "rustlib", host, "bin", "llvm-profdata")
    if not os.access(tool, os.X_OK):
        sys.exit("build_pgo: no llvm-profdata for this rustc; run `rustup component add llvm-tools`")
    return tool


def build(target_dir, flags):
    """`cargo build --release -p ais-cli` into `target_dir` with `flags` as RUSTFLAGS."""
    environment = dict(os.environ, RUSTFLAGS=" ".join(config_flags() + flags))
    command = ["cargo", "build", "--release", "--locked", "-p", "ais-cli", "--target-dir", target_dir]
    print("build_pgo:", " ".join(command), f"(RUSTFLAGS={environment['RUSTFLAGS']})", flush=True)
    subprocess.run(command, cwd=ROOT, env=environment, check=True)
    return os.path.join(target_dir, "release", "ais")


def training_scenes(args):
    """The scenes to train on: those asked for, or the repository's, less the excluded."""
    scenes = args.train or (
        sorted(glob.glob(os.path.join(ROOT, "scenes", "*.xml")))
        + sorted(glob.glob(os.path.join(ROOT, "scenes", "crosscheck", "*.xml")))
        + ["default"]
    )
    excluded = {name(scene) for scene in args.exclude}
    return [scene for scene in scenes if name(scene) not in excluded]


def name(scene):
    """What tells `scene` apart: `default` for the built-in scene, else the file's path."""
    return scene if scene == "default" else os.path.realpath(scene)


def train(binary, scenes):
    """Renders every scene with `binary`, AIS off and `auto`; exits at the first failure."""
    with tempfile.TemporaryDirectory() as folder:
        output = os.path.join(folder, "train.exr")
        for scene in scenes:
            for ais in ("off", "auto"):
                command = [binary, "render"] + ([] if scene == "default" else [scene])
                command += ["--ais", ais, "--spp", "16", "--resolution", "64x64", "-q", "--no-preview", "-o", output]
                done = subprocess.run(command, capture_output=True, text=True)
                if done.returncode != 0:
                    sys.exit(f"build_pgo: training on {scene} failed:\n{done.stderr.strip()}")
    print(f"build_pgo: trained on {len(scenes)} scenes", flush=True)


def main():
    try:
        build_and_train()
    except FileNotFoundError as error:
        sys.exit(f"build_pgo: {error.filename} not found: install the Rust toolchain (rustup) first")
    except subprocess.CalledProcessError as error:
        sys.exit(f"build_pgo: `{' '.join(error.cmd)}` failed (exit {error.returncode})")


def build_and_train():
    """The three steps, as the module's text describes them."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--train", nargs="+", default=[], help="scene files (or `default`) to train on")
    parser.add_argument("--exclude", nargs="+", default=[], help="scene files (or `default`) to leave out of training")
    args = parser.parse_args()
    profdata = llvm_profdata()
    if not os.path.exists(os.path.join(ROOT, "scenes", "assets", "sky.hdr")):
        subprocess.run([sys.executable, os.path.join(ROOT, "scenes", "make_assets.py")], check=True)
    scenes = training_scenes(args)
    if not scenes:
        sys.exit("build_pgo: no scene left to train on")
    missing = [scene for scene in scenes if name(scene) != "default" and not os.path.isfile(scene)]
    if missing:
        sys.exit(f"build_pgo: no scene file {missing[0]}")
    profiles = os.path.join(TARGET, "profiles")
    shutil.rmtree(profiles, ignore_errors=True)
    instrumented = build(os.path.join(TARGET, "instrumented"), [f"-Cprofile-generate={profiles}"])
    train(instrumented, scenes)
    merged = os.path.join(TARGET, "merged.profdata")
    subprocess.run([profdata, "merge", "-o", merged, profiles], check=True)
    optimised = build(TARGET, [f"-Cprofile-use={merged}"])
    print(f"build_pgo: wrote {os.path.relpath(optimised, ROOT)}")


if __name__ == "__main__":
    main()

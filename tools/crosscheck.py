#!/usr/bin/env python3
"""Cross-check ais against Mitsuba 3 on the same scene files.

    python3 tools/crosscheck.py --setup            # makes .venv with mitsuba and numpy
    cargo build --release -p ais-cli
    .venv/bin/python tools/crosscheck.py scenes/occluded.xml [--spp 512] [--size 64x36]
    .venv/bin/python tools/crosscheck.py --suite   # every scene the test suite checks

Each scene is rendered by Mitsuba's `direct` integrator (scalar_rgb; `--mitsuba-samples`
emitter and BSDF samples per camera sample; the scene's own reconstruction filter, Mitsuba's
Gaussian when it names none, as ais reads it) and by
`ais render` (gather, MIS, once per `--modes` entry: AIS off and `auto`, the default, by default),
at the same resolution. Each renderer runs `--runs` times with independent seeds, and the
spread of those runs gives a per-pixel standard error (SE) for both images. Reported per
scene and ais mode:

- the per-channel ratio of image means, ais / Mitsuba, and the largest difference of the
  channel means in SEs (threshold: a ratio off by more than 1% fails only if it is also more
  than 4 SE, so that the noise of a few tiny bright lights in view is not failed);
- relMSE = mean((ais - mitsuba)^2 / (mitsuba^2 + 0.01)) over pixels and channels, and its
  noise floor, the part that the SEs alone explain (threshold: relMSE exceeds its noise
  floor by less than 1e-3, so that a noisy scene is not failed for its noise);
- the largest deviation of an 8x8 pixel block mean, in SEs (threshold: 5 SE, failed only by
  a block also off by more than 1% of its mean);
- images in --out: both renders (EXR), the per-channel difference in SEs (EXR), and a
  false-colour PNG of that difference (blue: ais darker, red: ais brighter, saturating at
  5 SE).

Exit status 1 when a threshold is exceeded, 2 for a problem of ours (no ais binary, a
scene that does not render), 3 when Mitsuba cannot be installed or imported. Mitsuba runs in a child process per scene, since
loading a second scene in one process has been seen to deadlock.
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MITSUBA_VERSION = "3.9.1"
MEAN_TOLERANCE = 0.01
MEAN_SE_LIMIT = 4.0
RELMSE_EXCESS_LIMIT = 1e-3
RELMSE_EPSILON = 1e-2
BLOCK = 8
BLOCK_LIMIT = 5.0
# A block fails only if it is also off by more than this share of its mean. Beside a sharp
# edge, Mitsuba's scalar variant weighs samples by a 31-step table of the reconstruction
# filter (its llvm variant by the filter itself), which puts pixels there a few percent off
# at 2048 spp; and among the suite's thousands of block tests, a heavy-tailed dark block
# now and then reaches 5 SE by noise alone (seen at 512 spp, gone at 2048).
BLOCK_TOLERANCE = 0.01

# Renders one scene `runs` times with seeds 0..runs-1 and saves the stack (runs, H, W, 3).
MITSUBA_CHILD = r"""
import sys, numpy as np, mitsuba as mi
mi.set_variant('scalar_rgb')
scene = mi.load_file(sys.argv[1])
runs, spp = int(sys.argv[3]), int(sys.argv[4])
np.save(sys.argv[2], np.stack([np.array(mi.render(scene, seed=k, spp=spp))[..., :3]
                               for k in range(runs)]))
"""


NO_MITSUBA = 3


def fail_setup(message, status=2):
    print(f"crosscheck: error: {message}", file=sys.stderr)
    sys.exit(status)


def setup_venv(venv):
    """Creates `venv` with Mitsuba and numpy (pinned Mitsuba) and returns its python."""
    python = os.path.join(venv, "bin", "python")
    probe = [python, "-c", f"import mitsuba, numpy; assert mitsuba.__version__ == '{MITSUBA_VERSION}'"]
    if os.path.exists(python) and subprocess.run(probe, capture_output=True).returncode == 0:
        return python
    print(f"crosscheck: installing mitsuba=={MITSUBA_VERSION} and numpy into {venv}", file=sys.stderr)
    steps = [[sys.executable, "-m", "venv", venv],
             [python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
              f"mitsuba=={MITSUBA_VERSION}", "numpy"]]
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True)
        if done.returncode != 0:
            fail_setup(f"`{' '.join(step)}` failed:\n{done.stdout}{done.stderr}", NO_MITSUBA)
    if subprocess.run(probe, capture_output=True).returncode != 0:
        fail_setup(f"mitsuba {MITSUBA_VERSION} does not import in {venv}", NO_MITSUBA)
    return python


def outer_element(text, tag):
    """The span of the first <tag> element with everything nested in it (integrators nest:
    `moment` around `path`), or None."""
    start = re.search(rf"<{tag}\b", text)
    if not start:
        return None
    depth = 0
    for token in re.finditer(rf"<{tag}\b[^>]*?(/?)>|</{tag}\s*>", text[start.start():]):
        if token.group(0).startswith("</"):
            depth -= 1
        elif token.group(1) != "/":
            depth += 1
        if depth == 0:
            return start.start(), start.start() + token.end()
    return None


def mitsuba_scene_text(text, width, height, samples):
    """The scene for Mitsuba: its `direct` integrator (keeping the scene's hide_emitters) and
    our film size; the reconstruction filter stays the scene's."""
    hidden = re.search(r'<integrator\b.*?<boolean\s+name="hide_emitters"\s+value="true"\s*/>.*?</integrator>',
                       text, flags=re.S)
    hide = '<boolean name="hide_emitters" value="true"/>' if hidden else ''
    direct = (f'<integrator type="direct"><integer name="emitter_samples" value="{samples}"/>'
              f'<integer name="bsdf_samples" value="{samples}"/>{hide}</integrator>')
    span = outer_element(text, "integrator")
    if span:
        text = text[:span[0]] + direct + text[span[1]:]
    else:
        text = re.sub(r"(<scene\b[^>]*>)", r"\1" + direct, text, count=1)

    def film(match):
        body = match.group(0)
        for name, value in (("width", width), ("height", height)):
            body, found = re.subn(rf'(<integer\s+name="{name}"\s+value=")[^"]*(")',
                                  rf"\g<1>{value}\g<2>", body)
            if not found:
                body = re.sub(r"(<film\b[^>]*>)", rf'\1<integer name="{name}" value="{value}"/>', body)
        return body

    text, films = re.subn(r"<film\b.*?</film>", film, text, count=1, flags=re.S)
    if films == 0:
        text = re.sub(r"(<sensor\b[^>]*>)", rf'\1<film type="hdrfilm"><integer name="width" value="{width}"/>'
                      rf'<integer name="height" value="{height}"/></film>', text, count=1)
    return text


# Mitsuba 3.9.1's `direct` weighs every emitter sample of a point, spot, projector or directional light
# by 1 instead of 1 / emitter_samples, so such scenes come out emitter_samples times too
# bright (measured: 8.0x at 8 samples). With them, Mitsuba runs one emitter and one BSDF
# sample per camera sample, and as many more camera samples: the same work, the right weights.
DELTA_EMITTER = re.compile(r'<emitter\b[^>]*\btype="(point|spot|directional|projector)"')


ROUGH_BSDF = re.compile(r'<bsdf\b[^>]*\btype="rough(?:conductor|plastic|dielectric)"[^>]*?(?<!/)>')


def beckmann_sampled_exactly(text):
    """The scene with `sample_visible` false in every rough BSDF of Beckmann's distribution
    (named or by default). Mitsuba samples Beckmann's visible normals exactly but weighs them
    by Walter's rational approximation of G1, as its `eval` does, so its estimate is off its
    own `eval` by a few tenths of a percent (measured against quadrature at alpha 0.4: -0.17%
    for a view 57 degrees off the normal, +0.24% at 74 degrees). Drawn by D(h) cos, the same
    `eval` is integrated without bias."""
    def rewrite(match):
        close = text.find("</bsdf>", match.end())
        body = text[match.end():close]
        if re.search(r'<string\s+name="distribution"\s+value="ggx"', body):
            return match.group(0)
        return match.group(0) + '<boolean name="sample_visible" value="false"/>'

    return ROUGH_BSDF.sub(rewrite, text)


INCLUDE = re.compile(r'<include\s+filename="([^"]+)"\s*/>')


def inline_includes(text, folder, top_folder, depth=0):
    """The scene text with every <include> replaced by the included file's elements (looked
    for beside the including file, then beside the top scene, as both renderers do), so that
    the integrator and film settings below reach elements that live in included files."""
    if depth > 16:
        fail_setup("scene files include one another more than 16 deep")

    def replace(match):
        path = os.path.join(folder, match.group(1))
        if not os.path.exists(path):
            path = os.path.join(top_folder, match.group(1))
        with open(path) as f:
            inner = f.read()
        inner = re.sub(r"<\?xml[^>]*\?>", "", inner)
        inner = re.sub(r"<scene\b[^>]*>", "", inner, count=1)
        inner = re.sub(r"</scene>\s*$", "", inner.strip())
        return inline_includes(inner, os.path.dirname(path), top_folder, depth + 1)

    return INCLUDE.sub(replace, text)


def render_mitsuba(scene, width, height, runs, spp, samples, work):
    with open(scene) as f:
        text = f.read()
    folder = os.path.dirname(os.path.abspath(scene))
    # Without comments, so that a commented-out element is not taken for the real one.
    text = re.sub(r"<!--.*?-->", "", inline_includes(text, folder, folder), flags=re.S)
    if DELTA_EMITTER.search(text):
        spp, samples = spp * samples, 1
    text = beckmann_sampled_exactly(mitsuba_scene_text(text, width, height, samples))
    # Beside the original, so that relative asset paths resolve.
    copy = os.path.join(os.path.dirname(os.path.abspath(scene)), f".crosscheck-{os.getpid()}.xml")
    with open(copy, "w") as f:
        f.write(text)
    out = os.path.join(work, "mitsuba.npy")
    try:
        done = subprocess.run([sys.executable, "-c", MITSUBA_CHILD, copy, out, str(runs), str(spp)],
                              capture_output=True, text=True)
    finally:
        os.remove(copy)
    if done.returncode != 0:
        fail_setup(f"Mitsuba could not render {scene}:\n{done.stderr.strip()}")
    import numpy as np
    return np.load(out).astype(np.float64)


def render_ais(binary, scene, width, height, runs, spp, rays, mode, work):
    import mitsuba as mi
    import numpy as np
    images = []
    for k in range(runs):
        out = os.path.join(work, f"ais-{mode}-{k}.exr")
        command = [binary, "render", scene, "--resolution", f"{width}x{height}", "--spp", str(spp),
                   "--integrator", "gather", "--strategy", "mis", "--rays", str(rays), "--ais", mode,
                   "--seed", str(1000 + k), "--quiet", "--no-preview", "-o", out]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            fail_setup(f"`{' '.join(command)}` failed:\n{done.stderr.strip()}")
        images.append(np.array(mi.Bitmap(out))[..., :3])
    return np.stack(images).astype(np.float64)


def correlation_inflation(ours, theirs, variance):
    """How much larger the variance of an 8x8 block's mean is than the sum of its pixels'
    variances over 64^2: the median over blocks and channels of the ratio, the block means'
    variance taken from the runs' spread (at least 1: pixels rendered independently)."""
    import numpy as np
    height, width = variance.shape[:2]
    ratios = []
    for y in range(0, height, BLOCK):
        for x in range(0, width, BLOCK):
            count = min(BLOCK, height - y) * min(BLOCK, width - x)
            direct = sum(stack[:, y:y + BLOCK, x:x + BLOCK].reshape(stack.shape[0], -1, 3).mean(1)
                         .var(0, ddof=1) / stack.shape[0] for stack in (ours, theirs))
            independent = variance[y:y + BLOCK, x:x + BLOCK].reshape(-1, 3).sum(0) / count ** 2
            ratios.extend(direct[independent > 0] / independent[independent > 0])
    return max(1.0, float(np.median(ratios))) if ratios else 1.0


def statistics(ours, theirs):
    """Compares two stacks of independent runs (runs, H, W, 3)."""
    import numpy as np
    runs = ours.shape[0]
    mean_ours, mean_theirs = ours.mean(0), theirs.mean(0)
    var_ours = ours.var(0, ddof=1) / runs
    var_theirs = theirs.var(0, ddof=1) / theirs.shape[0]
    difference = mean_ours - mean_theirs
    variance = var_ours + var_theirs
    # Pixels that both renderers compute exactly (a constant background, black) have no
    # spread; a float-rounding floor keeps them from dividing by zero. It is 3e-5 of the
    # value: Mitsuba's filter weights, summed in single precision, leave a flat background
    # about 1e-5 off its exact value.
    floor = (3e-5 * (np.abs(mean_theirs) + 1e-6)) ** 2
    z = difference / np.sqrt(variance + floor)
    denominator = mean_theirs ** 2 + RELMSE_EPSILON
    rel_mse = float((difference ** 2 / denominator).mean())
    noise_floor = float((variance / denominator).mean())
    ratio = mean_ours.reshape(-1, 3).mean(0) / np.maximum(mean_theirs.reshape(-1, 3).mean(0), 1e-30)
    # The difference of the image means in SEs: is a ratio's offset noise or a real difference?
    # Rounding is the same in every pixel of a flat region, so its floor does not average
    # away over many pixels as noise does.
    # A reconstruction filter wider than a pixel (Mitsuba's default Gaussian) correlates
    # neighbouring pixels, so the SE of a mean over pixels exceeds what the pixels' own SEs
    # give if taken as independent; `inflation` measures by how much, over all blocks.
    inflation = correlation_inflation(ours, theirs, variance)
    pixels = difference.shape[0] * difference.shape[1]
    mean_z = difference.reshape(-1, 3).mean(0) / np.sqrt(
        inflation * variance.reshape(-1, 3).sum(0) / pixels ** 2 + floor.reshape(-1, 3).mean(0))
    height, width = difference.shape[:2]
    worst, failing = (0.0, None), (0.0, None)
    for y in range(0, height, BLOCK):
        for x in range(0, width, BLOCK):
            d = difference[y:y + BLOCK, x:x + BLOCK].reshape(-1, 3)
            v = variance[y:y + BLOCK, x:x + BLOCK].reshape(-1, 3)
            f = floor[y:y + BLOCK, x:x + BLOCK].reshape(-1, 3)
            block_z = d.mean(0) / np.sqrt(inflation * v.sum(0) / d.shape[0] ** 2 + f.mean(0))
            level = np.abs(mean_theirs[y:y + BLOCK, x:x + BLOCK].reshape(-1, 3).mean(0))
            off = np.abs(d.mean(0)) > BLOCK_TOLERANCE * level
            channel = int(np.abs(block_z).argmax())
            if abs(block_z[channel]) > abs(worst[0]):
                worst = (float(block_z[channel]), (x, y, "RGB"[channel]))
            if off.any():
                channel = int(np.where(off, np.abs(block_z), 0.0).argmax())
                if abs(block_z[channel]) > abs(failing[0]):
                    failing = (float(block_z[channel]), (x, y, "RGB"[channel]))
    # The z of the channel sum, for the false-colour image.
    sums_ours, sums_theirs = ours.sum(-1), theirs.sum(-1)
    sum_variance = sums_ours.var(0, ddof=1) / runs + sums_theirs.var(0, ddof=1) / theirs.shape[0]
    z_sum = (sums_ours.mean(0) - sums_theirs.mean(0)) / np.sqrt(sum_variance + floor.sum(-1))
    return {
        "mean_ratio": [float(r) for r in ratio],
        "mean_difference_se": [float(z) for z in mean_z],
        "rel_mse": rel_mse,
        "correlation_inflation": inflation,
        "rel_mse_noise_floor": noise_floor,
        "worst_block_se": worst[0],
        "worst_block": worst[1],
        "worst_block_off_by_tolerance_se": failing[0],
        "worst_block_off_by_tolerance": failing[1],
        "z": z,
        "z_sum": z_sum,
        "mean_ours": mean_ours,
        "mean_theirs": mean_theirs,
    }


def false_colour(z):
    """Blue (negative) - white - red (positive), saturating at the block limit."""
    import numpy as np
    t = np.clip(z / BLOCK_LIMIT, -1.0, 1.0)[..., None]
    white = np.ones(3)
    red, blue = np.array([0.85, 0.1, 0.1]), np.array([0.1, 0.25, 0.85])
    rgb = np.where(t > 0, white + t * (red - white), white - t * (blue - white))
    return (rgb * 255.0 + 0.5).astype(np.uint8)


def save(path, array):
    import mitsuba as mi
    import numpy as np
    array = np.ascontiguousarray(array)
    temporary = path + ".part" + os.path.splitext(path)[1]
    mi.Bitmap(array.astype(np.float32) if array.dtype != np.uint8 else array).write(temporary)
    os.replace(temporary, path)


def check(stats):
    """The threshold failures of one comparison, as sentences."""
    failures = []
    for channel, ratio, z in zip("RGB", stats["mean_ratio"], stats["mean_difference_se"]):
        # An offset is a failure when it is both larger than the tolerance and larger than
        # the noise: a few tiny, bright, directly visible lights make an image's mean noisy.
        if not (abs(ratio - 1.0) <= MEAN_TOLERANCE or abs(z) <= MEAN_SE_LIMIT):
            failures.append(f"{channel} mean ratio {ratio:.4f} is off by more than {MEAN_TOLERANCE:.0%} "
                            f"({z:+.1f} SE)")
    excess = stats["rel_mse"] - stats["rel_mse_noise_floor"]
    if not excess < RELMSE_EXCESS_LIMIT:
        failures.append(f"relMSE {stats['rel_mse']:.2e} exceeds its noise floor "
                        f"{stats['rel_mse_noise_floor']:.2e} by {excess:.1e}, not below {RELMSE_EXCESS_LIMIT:.0e}")
    if not abs(stats["worst_block_off_by_tolerance_se"]) <= BLOCK_LIMIT:
        x, y, channel = stats["worst_block_off_by_tolerance"]
        failures.append(f"the 8x8 block at pixel ({x}, {y}) deviates by "
                        f"{stats['worst_block_off_by_tolerance_se']:+.1f} SE and by more than "
                        f"{BLOCK_TOLERANCE:.0%} in {channel}")
    return failures


def suite_scenes():
    scenes = sorted(glob.glob(os.path.join(ROOT, "scenes", "*.xml")))
    scenes += sorted(glob.glob(os.path.join(ROOT, "scenes", "crosscheck", "*.xml")))
    return scenes


def ensure_assets():
    assets = os.path.join(ROOT, "scenes", "assets")
    if not all(os.path.exists(os.path.join(assets, name)) for name in ("sky.hdr", "blob.obj", "leaves.obj", "ball.obj", "tiles.png", "bumps.png", "attributes.ply", "quad.obj",
                                                                         "shapes.serialized")):
        subprocess.run([sys.executable, os.path.join(ROOT, "scenes", "make_assets.py")], check=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    parser.add_argument("scenes", nargs="*", help="Mitsuba XML scene files")
    parser.add_argument("--suite", action="store_true",
                        help="check scenes/*.xml and scenes/crosscheck/*.xml against the thresholds")
    parser.add_argument("--setup", action="store_true",
                        help=f"create --venv with mitsuba {MITSUBA_VERSION} and numpy, then run in it")
    parser.add_argument("--venv", default=os.path.join(ROOT, ".venv"))
    parser.add_argument("--size", default="64x36", help="film size for both renderers")
    parser.add_argument("--spp", type=int, default=512, help="camera samples per pixel, over all runs")
    parser.add_argument("--runs", type=int, default=8, help="independent runs per renderer (for the SEs)")
    parser.add_argument("--rays", type=int, default=16, help="ais gather rays per camera sample")
    parser.add_argument("--mitsuba-samples", type=int, default=8,
                        help="Mitsuba direct: emitter and BSDF samples per camera sample")
    parser.add_argument("--modes", default="off,auto", help="ais --ais modes to check")
    parser.add_argument("--ais", default=os.path.join(ROOT, "target", "release", "ais"),
                        help="the ais binary")
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "crosscheck"),
                        help="folder for the images and summary.json")
    parser.add_argument("--markdown", action="store_true", help="also print the results as a Markdown table")
    args = parser.parse_args()

    if args.setup:
        python = setup_venv(args.venv)
        if not args.scenes and not args.suite:
            print(f"crosscheck: ready; run {python} {sys.argv[0]} ...")
            return
        argv = [a for a in sys.argv[1:] if a != "--setup"]
        sys.exit(subprocess.run([python, os.path.abspath(__file__)] + argv).returncode)
    try:
        import numpy  # noqa: F401
        import mitsuba
    except ImportError as e:
        fail_setup(f"{e}; run `python3 tools/crosscheck.py --setup` (makes .venv with "
                   f"mitsuba=={MITSUBA_VERSION} and numpy) or `pip install mitsuba numpy`", NO_MITSUBA)
    mitsuba.set_variant("scalar_rgb")
    scenes = args.scenes + (suite_scenes() if args.suite else [])
    if not scenes:
        parser.error("give scene files or --suite")
    if not os.path.exists(args.ais):
        fail_setup(f"{args.ais} not found; run `cargo build --release -p ais-cli` first")
    if args.spp % args.runs or args.runs < 2:
        parser.error("--spp must be a multiple of --runs, and --runs at least 2")
    width, height = (int(v) for v in args.size.lower().split("x"))
    modes = [m for m in args.modes.split(",") if m]
    ensure_assets()
    os.makedirs(args.out, exist_ok=True)

    spp_per_run = args.spp // args.runs
    print(f"crosscheck: Mitsuba {mitsuba.__version__} scalar_rgb direct ({args.mitsuba_samples}+"
          f"{args.mitsuba_samples} samples) vs ais gather mis n={args.rays}; {width}x{height}, "
          f"{args.spp} spp in {args.runs} runs each")
    header = f"{'scene':<28} {'ais':<11} {'R ratio':>8} {'G ratio':>8} {'B ratio':>8} " \
             f"{'mean SE':>8} {'relMSE':>9} {'(noise)':>9} {'block SE':>9}  verdict"
    print(header)
    summary, failed = [], []
    for scene in scenes:
        name = os.path.splitext(os.path.relpath(scene, os.path.join(ROOT, "scenes")))[0].replace(os.sep, "-")
        started = time.time()
        with tempfile.TemporaryDirectory() as work:
            theirs = render_mitsuba(scene, width, height, args.runs, spp_per_run, args.mitsuba_samples, work)
            mitsuba_seconds = time.time() - started
            save(os.path.join(args.out, f"{name}-mitsuba.exr"), theirs.mean(0))
            for mode in modes:
                started = time.time()
                ours = render_ais(args.ais, scene, width, height, args.runs, spp_per_run, args.rays, mode, work)
                ais_seconds = time.time() - started
                stats = statistics(ours, theirs)
                failures = check(stats)
                stem = os.path.join(args.out, f"{name}-ais-{mode}")
                save(stem + ".exr", stats["mean_ours"])
                save(stem + "-se.exr", stats["z"])
                save(stem + "-se.png", false_colour(stats["z_sum"]))
                r, g, b = stats["mean_ratio"]
                mean_se = max(stats["mean_difference_se"], key=abs)
                print(f"{name:<28} {mode:<11} {r:8.4f} {g:8.4f} {b:8.4f} {mean_se:+8.2f} {stats['rel_mse']:9.2e} "
                      f"{stats['rel_mse_noise_floor']:9.2e} {stats['worst_block_se']:+9.2f}  "
                      f"{'ok' if not failures else 'FAIL'}", flush=True)
                for failure in failures:
                    print(f"    {failure}")
                    failed.append(f"{name} (ais {mode}): {failure}")
                summary.append({key: value for key, value in stats.items()
                                if key not in ("z", "z_sum", "mean_ours", "mean_theirs")}
                               | {"scene": os.path.relpath(scene, ROOT), "mode": mode, "failures": failures,
                                  "mitsuba_seconds": mitsuba_seconds, "ais_seconds": ais_seconds})
    with open(os.path.join(args.out, "summary.json.part"), "w") as f:
        json.dump({"size": [width, height], "spp": args.spp, "runs": args.runs, "rays": args.rays,
                   "mitsuba_samples": args.mitsuba_samples, "results": summary}, f, indent=1)
    os.replace(os.path.join(args.out, "summary.json.part"), os.path.join(args.out, "summary.json"))
    print(f"crosscheck: images and summary.json in {args.out}")
    if args.markdown:
        print("\n| scene | ais AIS | R, G, B mean ratio | mean SE | relMSE | noise | block SE |")
        print("|---|---|---|---|---|---|---|")
        for row in summary:
            scene = os.path.splitext(os.path.relpath(row["scene"], "scenes"))[0]
            ratios = ", ".join(f"{r:.4f}" for r in row["mean_ratio"])
            mean_se = max(row["mean_difference_se"], key=abs)
            print(f"| {scene} | {row['mode']} | {ratios} | {mean_se:+.2f} | {row['rel_mse']:.2e} | "
                  f"{row['rel_mse_noise_floor']:.2e} | {row['worst_block_se']:+.2f} |")
    if failed:
        print(f"crosscheck: {len(failed)} threshold(s) exceeded:", file=sys.stderr)
        for line in failed:
            print(f"  {line}", file=sys.stderr)
        sys.exit(1)
    print("crosscheck: all scenes agree within the thresholds")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Efficiency of AIS configurations against AIS off, per scene and n, at one spp each.

    cargo build --release -p ais-cli
    python3 tools/crosscheck.py --setup          # makes .venv (Mitsuba reads the EXRs)
    SEEDS=5 .venv/bin/python tools/field_study.py 80x60 sunlit_room,interior off,auto 16,128

A configuration is an `--ais` preset, optionally followed by flags after `+`
(`auto+--cost-ratio=2`). FLAGS (an environment variable) adds flags to every render, the
reference's included, which is then cached apart (`FLAGS=--hide-emitters=true`: the sky
the camera sees directly is black in every image).

For each scene of scenes/ (names without .xml; `default` is the built-in scene), a reference is rendered once by ais with AIS
off and 16 rays, as REFERENCE_PARTS (an environment variable, default 4, at least 2) independent parts of
1024 spp each, cached in target/field-study/. The reference is their mean, and the spread of
the parts gives its own variance per pixel. A relMSE against a noisy reference counts that
noise too: E[(x − r)²] = E[(x − μ)²] + Var(r). So every relMSE printed has the reference's
own part, mean(Var(r) / (r² + 0.01)), subtracted (as `ais compare` does). Without that, the
reference's noise (1.7e-4 in the sunlit room from 1024 spp, against 4e-4 measured for
`auto` at 128 candidates and 32 spp) pulls every ratio toward 1. Then every configuration renders
SEEDS times (default 8) at `--spp` 32 for n = 16 and 8 for n = 128 (SPP sets another), in one process, and the
script prints per configuration the mean relMSE against the reference (relMSE = mean((x − r)²
/ (r² + 0.01)), the reference's own part subtracted) with its standard error over seeds, the median render time (configurations
run interleaved, seed by seed), and the
efficiency ratio against the first configuration: (relMSE · time) of the first over that of
the row. Its noise (±, one standard error) has two parts, also printed apart: the relMSE
ratio's, from the seeds' spread with the pairing of seeds counted (a configuration and the
first see the same camera samples at one seed, so their errors are correlated), and the
time ratio's, from the spread of the per-seed time ratios (renders of one seed run back to
back). The efficiency's time factor is the geometric mean of those per-seed ratios.
Configurations whose learning happens between passes (auto) render their spp in passes
within one render here; `ais compare` keeps one field across its 1-spp passes instead.
"""
import os
import re
import subprocess
import sys

import mitsuba as mi
import numpy as np

mi.set_variant('scalar_rgb')
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# AIS_BINARY picks another build (to compare two versions of the renderer).
AIS = os.environ.get('AIS_BINARY', os.path.join(ROOT, 'target', 'release', 'ais'))
WORK = os.path.join(ROOT, 'target', 'field-study')
# Flags for every render, the reference's included.
FLAGS = os.environ.get('FLAGS', '').split()
# Samples per pixel per n; SPP (an environment variable) sets one count for every n.
SPP_FOR = {16: 32, 128: 8}


def render(scene, size, spp, rays, config, seed, out):
    """Renders one configuration: an `--ais` preset, then extra flags after `+`
    (`auto+--cost-ratio=2`)."""
    ais, *flags = config.split('+')
    # `default` is the built-in scene (409k triangles: expensive rays).
    source = [] if scene == 'default' else [os.path.join(ROOT, 'scenes', scene + '.xml')]
    command = [AIS, 'render', *source, '--resolution', size,
               '--spp', str(spp), '--rays', str(rays), '--ais', ais, '--seed', str(seed),
               '--no-preview', '-o', out, *FLAGS, *flags]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode:
        sys.exit(done.stderr)
    report = done.stdout + done.stderr
    seconds = float(re.search(r'render time\s+([0-9.]+)', report).group(1))
    counts = re.search(r'traced ([0-9.]+), rejected outside support ([0-9.]+), by roulette ([0-9.]+)', report)
    return np.array(mi.Bitmap(out))[..., :3].astype(np.float64), seconds, counts.groups() if counts else ()


def rel_mse(image, reference):
    """relMSE against the true image: against the reference's mean, less the reference's
    own noise."""
    mean, variance = reference
    return float(np.mean(((image - mean) ** 2 - variance) / (mean ** 2 + 0.01)))


def load_reference(scene, size, variant):
    """The reference of `scene`: the mean of REFERENCE_PARTS independent AIS-off renders
    (rendered once, cached), and the variance of that mean per pixel and channel."""
    parts = []
    # At least two parts: their spread is the reference's noise.
    for part in range(max(2, int(os.environ.get('REFERENCE_PARTS', '4')))):
        path = os.path.join(WORK, f'reference-{scene}-{size}{variant}-part{part}.exr')
        if not os.path.exists(path):
            render(scene, size, 1024, 16, 'off', 777 + part, path)
        parts.append(np.array(mi.Bitmap(path))[..., :3].astype(np.float64))
    parts = np.stack(parts)
    variance = parts.var(axis=0, ddof=1) / len(parts)
    mean = parts.mean(axis=0)
    noise = float(np.mean(variance / (mean ** 2 + 0.01)))
    print(f'{scene:14s} reference: {len(parts)} × 1024 spp; its own relMSE {noise:.2e} '
          '(subtracted from every relMSE below)', flush=True)
    return mean, variance


def paired_ratio(base, other):
    """mean(base) / mean(other) over paired seeds, and the relative standard error of that
    ratio (delta method, with the pairs' covariance)."""
    base, other = np.asarray(base), np.asarray(other)
    if len(base) < 2:
        return base.mean() / other.mean(), float('nan')
    b, o = base.mean(), other.mean()
    covariance = np.cov(base, other)
    variance = (covariance[0, 0] / b ** 2 + covariance[1, 1] / o ** 2
                - 2 * covariance[0, 1] / (b * o)) / len(base)
    return b / o, float(np.sqrt(max(variance, 0.0)))


def paired_ratio_of_times(base, other):
    """The geometric mean of base / other over paired seeds, and its relative standard
    error."""
    logs = np.log(np.asarray(base)) - np.log(np.asarray(other))
    if len(logs) < 2:
        return float(np.exp(logs.mean())), float('nan')
    return float(np.exp(logs.mean())), float(logs.std(ddof=1) / np.sqrt(len(logs)))


def main():
    size, scenes = sys.argv[1], sys.argv[2].split(',')
    configs = sys.argv[3].split(',') if len(sys.argv) > 3 else ['off', 'auto']
    ns = [int(n) for n in (sys.argv[4] if len(sys.argv) > 4 else '16,128').split(',')]
    seeds = int(os.environ.get('SEEDS', '8'))
    os.makedirs(WORK, exist_ok=True)
    for scene in scenes:
        variant = ''.join('-' + flag.lstrip('-').replace('=', '-') for flag in FLAGS)
        reference = load_reference(scene, size, variant)
        for n in ns:
            # Configurations interleaved per seed, so that the machine's drifting load
            # falls on all of them alike; times are medians.
            errors = {config: [] for config in configs}
            times = {config: [] for config in configs}
            counts = {config: () for config in configs}
            for seed in range(seeds):
                for config in configs:
                    out = os.path.join(WORK, f'{scene}-{config.split("+")[0]}.exr')
                    spp = int(os.environ.get('SPP', SPP_FOR[n]))
                    image, seconds, counts[config] = render(scene, size, spp, n, config, seed, out)
                    errors[config].append(rel_mse(image, reference))
                    times[config].append(seconds)
            base = configs[0]
            for config in configs:
                error = np.mean(errors[config])
                se = np.std(errors[config]) / np.sqrt(seeds)
                error_gain, error_noise = paired_ratio(errors[base], errors[config])
                time_gain, time_noise = paired_ratio_of_times(times[base], times[config])
                efficiency = error_gain * time_gain
                noise = efficiency * np.hypot(error_noise, time_noise)
                per_gather = f'traced {counts[config][0]}, rejected {counts[config][2]} per gather' \
                    if counts[config] else ''
                print(f'{scene:14s} n={n:3d} {config:6s} relMSE {error:.3e}±{se:.1e} '
                      f'time {np.median(times[config]):.3f}s  efficiency {efficiency:.2f}× ±{noise:.2f} '
                      f'(relMSE ±{error_gain * error_noise:.2f}, time ±{time_gain * time_noise:.2f})  '
                      f'{per_gather}', flush=True)


if __name__ == '__main__':
    main()

"""AIS inside Mitsuba 3 (``ais.mitsuba``): it agrees with Mitsuba's own ``direct``
integrator, and AIS keeps it unbiased.

Mitsuba renders one scene per process (a second load in one process can deadlock), so each
render below runs in a subprocess that saves its images with numpy.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import os

import numpy as np
import pytest

from ais.mitsuba import find_llvm

if find_llvm() is None:
    REASON = "Mitsuba's llvm variant needs the LLVM library (apt install libllvm19)"
    if os.environ.get("CI"):
        raise RuntimeError(f"under CI the Mitsuba tests must run: {REASON}")
    pytest.skip(f"SKIPPED the tests of AIS inside Mitsuba: {REASON}", allow_module_level=True)

REFERENCE = """
import sys, numpy as np
from pathlib import Path
from ais.mitsuba import direct_reference, import_mitsuba
mi = import_mitsuba("llvm_ad_rgb")
image = direct_reference(mi, Path(sys.argv[1]), int(sys.argv[2]), {"res_x": 64, "res_y": 48})
np.save(sys.argv[3], image)
"""

OURS = """
import json, sys, numpy as np
from pathlib import Path
from ais.mitsuba import MitsubaGather, import_mitsuba, load_scene
path, spp, mode, seeds, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], json.loads(sys.argv[4]), sys.argv[5]
mi = import_mitsuba("llvm_ad_rgb")
loaded = load_scene(mi, Path(path), {"res_x": 64, "res_y": 48})
images = []
for seed in seeds:
    host = MitsubaGather(mi, loaded, rays=16, ais=mode, seed=seed)
    image, stats = host.render(spp)
    images.append(image)
np.save(out, np.stack(images))
print(json.dumps(stats))
"""


def run(script: str, *args, timeout: float = 600) -> str:
    completed = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert completed.returncode == 0, completed.stderr[-3000:]
    return completed.stdout


@pytest.fixture(scope="module")
def scenes_with_assets(scenes: Path) -> Path:
    if not (scenes / "assets" / "sky.hdr").exists():
        subprocess.run([sys.executable, str(scenes / "make_assets.py")], check=True)
    return scenes


CASES = {"cornell box": "cornell_box.xml", "sun and occluders": "crosscheck/sun.xml"}


@pytest.fixture(scope="module")
def references(scenes_with_assets: Path, tmp_path_factory) -> dict:
    folder = tmp_path_factory.mktemp("mitsuba")
    images = {}
    for name, file in CASES.items():
        out = folder / f"{file.replace('/', '_')}.npy"
        run(REFERENCE, scenes_with_assets / file, 128, out)
        images[name] = np.load(out)
    return images


def ours(scene: Path, spp: int, mode: str, seeds, out: Path):
    stats = json.loads(run(OURS, scene, spp, mode, json.dumps(list(seeds)), out).splitlines()[-1])
    return np.load(out), stats


@pytest.mark.parametrize("mode", ["off", "aggressive"])
@pytest.mark.parametrize("name", list(CASES))
def test_agrees_with_mitsubas_direct_integrator(name, mode, references, scenes_with_assets, tmp_path):
    images, stats = ours(scenes_with_assets / CASES[name], 16, mode, [1], tmp_path / "ours.npy")
    reference = references[name].reshape(-1, 3).mean(axis=0)
    mean = images[0].reshape(-1, 3).mean(axis=0)
    assert images[0].shape == (48, 64, 3)
    np.testing.assert_allclose(mean, reference, rtol=0.01)
    if mode == "aggressive":
        assert stats["rejected_by_roulette"] > 0, "AIS skipped nothing"


def block_means(images: np.ndarray) -> np.ndarray:
    """Per-seed means of 8×8-pixel blocks: (seeds, blocks × channels)."""
    seeds, height, width, _ = images.shape
    blocks = images.reshape(seeds, height // 8, 8, width // 8, 8, 3).mean(axis=(2, 4))
    return blocks.reshape(seeds, -1)


def test_ais_inside_mitsuba_is_unbiased(scenes_with_assets, tmp_path):
    scene = scenes_with_assets / CASES["sun and occluders"]
    seeds = range(8)
    with_ais, _ = ours(scene, 2, "aggressive", seeds, tmp_path / "ais.npy")
    without, _ = ours(scene, 2, "off", [s + 100 for s in seeds], tmp_path / "off.npy")
    a, b = block_means(with_ais), block_means(without)
    difference = a.mean(axis=0) - b.mean(axis=0)
    error = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
    lit = error > 0
    z = np.abs(difference[lit]) / error[lit]
    # 144 block-channel tests: 4.5 standard errors is exceeded by chance once in ~1000 runs.
    assert z.max() < 4.5, f"largest z {z.max():.2f}"
    whole = (a.mean(axis=1), b.mean(axis=1))
    whole_error = np.sqrt(sum(w.var(ddof=1) / len(w) for w in whole))
    assert abs(whole[0].mean() - whole[1].mean()) < 4 * whole_error


def test_scalar_variants_are_refused():
    from ais.mitsuba import import_mitsuba

    with pytest.raises(RuntimeError, match="use an llvm variant"):
        import_mitsuba("scalar_rgb")

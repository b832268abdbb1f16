"""ais.render and ais.Scene: arrays, options, crops, threads, errors and the GIL."""

from __future__ import annotations

import os
import threading
import time
import warnings

import numpy as np
import pytest

import ais

SMALL = dict(spp=2, rays=8, resolution=(48, 32))

XML = """<scene version="3.0.0">
    <default name="radiance" value="1.0"/>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="$radiance"/></emitter>
    <shape type="rectangle"><bsdf type="diffuse"/></shape>
</scene>
"""


def test_render_returns_an_image_array(cornell):
    image = ais.render(cornell, **SMALL)
    assert image.shape == (32, 48, 3)
    assert image.dtype == np.float32
    assert np.isfinite(image).all()
    assert image.mean() > 0.01


def test_stats_come_with_the_image(cornell):
    image, stats = ais.render(cornell, stats=True, **SMALL)
    assert image.shape == (32, 48, 3)
    assert stats["spp"] == 2 and stats["rays"] == 8 and stats["ais"] == "auto"
    assert stats["camera_rays"] == 48 * 32 * 2
    assert stats["candidates_per_gather"] == pytest.approx(8.0)
    assert 0 < stats["traced_per_gather"] <= 8
    assert stats["render_time"] > 0
    # Tiles render on at most the pool's threads, and some thread is always at work.
    assert 0 < stats["threads_busy"] <= os.cpu_count() + 0.01


def test_a_scene_renders_many_times_like_render(cornell):
    scene = ais.Scene(cornell)
    assert scene.resolution == (128, 128) and scene.spp >= 1
    first = scene.render(**SMALL)
    again = scene.render(**SMALL)
    once = ais.render(cornell, **SMALL)
    assert np.array_equal(first, again) and np.array_equal(first, once)
    other_seed = scene.render(seed=1, **SMALL)
    assert not np.array_equal(first, other_seed)
    # A render at another size does not change the scene's own.
    assert scene.render(spp=1, rays=4).shape == (128, 128, 3)
    assert scene.resolution == (128, 128)


def test_xml_text_and_defines():
    dim = ais.render(XML, spp=4, rays=4)
    bright = ais.render(XML, spp=4, rays=4, defines={"radiance": 3.0})
    assert dim.shape == (16, 24, 3)
    np.testing.assert_allclose(bright, 3 * dim, rtol=1e-5, atol=1e-6)
    assert np.array_equal(ais.Scene(XML, radiance=3.0).render(spp=4, rays=4), bright)


def test_gather_parameters_are_keywords(cornell):
    image, stats = ais.render(
        cornell, ais="conservative", strategy="light", budget="traced", stats=True, **SMALL
    )
    assert stats["ais"] == "conservative" and stats["strategy"] == "light"
    assert image.shape == (32, 48, 3)


def test_crops_equal_the_whole_render(cornell):
    # Pixels rendered independently (AIS off); `auto` learns from the pixels it renders,
    # so its crops differ from the whole render (docs/cli.md, `--crop`).
    scene = ais.Scene(cornell)
    whole = scene.render(ais="off", **SMALL)
    left = scene.render(crop=(0, 0, 17, 32), ais="off", **SMALL)
    right = scene.render(crop=(17, 5, 31, 27), ais="off", **SMALL)
    assert left.shape == (32, 17, 3) and right.shape == (27, 31, 3)
    assert np.array_equal(left, whole[:, :17])
    assert np.array_equal(right, whole[5:, 17:])


def test_images_do_not_depend_on_threads(cornell):
    one = ais.render(cornell, threads=1, ais="aggressive", **SMALL)
    two = ais.render(cornell, threads=2, ais="aggressive", **SMALL)
    assert np.array_equal(one, two)


def test_bad_scenes_raise_scene_errors_with_file_and_line(tmp_path):
    broken = tmp_path / "broken.xml"
    broken.write_text('<scene version="3.0.0">\n  <shape type="obj">\n</scene>\n')
    with pytest.raises(ais.SceneError) as raised:
        ais.Scene(broken)
    assert raised.value.file == str(broken)
    assert raised.value.line == 3
    assert "broken.xml:3" in str(raised.value)
    with pytest.raises(ais.SceneError) as missing:
        ais.Scene(tmp_path / "missing.xml")
    assert missing.value.line is None and "missing.xml" in str(missing.value)
    assert isinstance(missing.value, ValueError)


def test_bad_options_raise_clear_errors(cornell):
    scene = ais.Scene(cornell)
    with pytest.raises(TypeError, match="unexpected keyword argument 'sp'"):
        scene.render(sp=4)
    with pytest.raises(ValueError, match="outside"):
        scene.render(crop=(200, 0, 100, 10))
    with pytest.raises(ValueError, match="rays"):
        scene.render(rays=0)
    with pytest.raises(ValueError, match="ais"):
        scene.render(ais="sometimes")
    with pytest.raises(ValueError, match="spp"):
        scene.render(spp=0)
    with pytest.raises(ValueError, match="threads"):
        scene.render(threads=0)
    with pytest.raises(ValueError, match="resolution"):
        scene.render(resolution=(0, 10))


def test_scene_warnings_are_python_warnings(cornell):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ais.Scene(None, unused=1)
    assert any("unused=1 is not used" in str(w.message) for w in caught)


def test_the_gil_is_released_while_rendering():
    scene = ais.Scene(None)
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    started = time.perf_counter()
    scene.render(spp=1, rays=16, resolution=(160, 90), threads=1)
    elapsed = time.perf_counter() - started
    done.set()
    counter.join()
    # With the GIL held, the counter could not run at all during the render.
    assert elapsed > 0.05, "the render is too short to tell"
    assert ticks >= 10, f"{ticks} ticks in {elapsed:.2f} s"

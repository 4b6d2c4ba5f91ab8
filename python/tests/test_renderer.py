"""dvr.Renderer on the Vulkan device (lavapipe in CI): frames equal to the CLI's, scores
equal to the eval's, convergence with samples, the GIL released, and clear errors."""

import csv
import os
import subprocess
import sys
import threading
import time

import numpy as np
import OpenEXR
import pytest

import dvr

SIZE = (24, 20)


def read_exr(path):
    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float32)[..., :3]
        return np.stack([np.asarray(channels[c].pixels, dtype=np.float32) for c in "RGB"], axis=-1)


@pytest.fixture(scope="module")
def phantom_frames():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=SIZE, denoisers=["ours", "svgf"])
    frames = [r.render(frame=f) for f in range(3)]
    return r, frames


def test_frames_are_finite_images_of_each_method(phantom_frames):
    r, frames = phantom_frames
    assert r.denoisers == ("ours", "svgf") and r.frames >= 48 and r.size == SIZE
    for out in frames:
        assert set(out) == {"noisy", "ours", "svgf"}
        for img in out.values():
            assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.float32
            assert np.isfinite(img).all() and (img >= 0).all()
    timings = r.timings()
    assert timings and all(ms >= 0 for ms in timings.values())
    assert any("path_trace" in p for p in timings)


def test_frames_equal_the_clis(phantom_frames, dvr_bin, tmp_path):
    _, frames = phantom_frames
    out = tmp_path / "capture"
    subprocess.run(
        [dvr_bin, "capture", "--quiet", "--scene", "phantom/orbit", "--frames", "3",
         "--size", f"{SIZE[0]}x{SIZE[1]}", "--denoiser", "none,ours,svgf", "--out", str(out)],
        check=True,
    )
    # Bit for bit: the same device, the same sample streams, the same passes (the
    # EXRs hold float32).
    for f in range(3):
        for method, key in (("none", "noisy"), ("ours", "ours"), ("svgf", "svgf")):
            cli = read_exr(out / method / f"{f:04d}.exr")
            assert np.array_equal(frames[f][key], cli), f"{method} frame {f}"


def test_a_numpy_volume_renders_as_the_same_raw_file_through_the_cli(dvr_bin, tmp_path):
    # An int16 CT-like block (windowed to its range as files are), written as raw with
    # a sidecar, rendered by the CLI; the same array handed to Python.
    z, y, x = np.mgrid[0:20, 0:24, 0:28]
    shell = ((x - 14) ** 2 / 150 + (y - 12) ** 2 / 110 + (z - 10) ** 2 / 80) < 1
    rng = np.random.default_rng(3)
    ct = (shell * 1200 - 1000 + rng.integers(0, 60, shell.shape)).astype(np.int16)
    spacing = (1.5, 1.0, 0.8)  # z, y, x
    ct.tofile(tmp_path / "ct.raw")
    (tmp_path / "ct.raw.json").write_text(
        '{"dims": [28, 24, 20], "format": "i16", "spacing": [%g, %g, %g]}' % spacing[::-1]
    )
    (tmp_path / "ct.toml").write_text(
        'name = "ct"\n[volume]\nfile = "ct.raw"\ndensity_scale = 120.0\n'
        '[transfer]\na = "phantom-opaque"\n'
        '[[light]]\nkind = "point"\nposition = [1.0, 1.0, 1.0]\nintensity = 20.0\n'
        "[animation]\nframes = 3\n[animation.orbit]\ndegrees_per_frame = 4.0\n"
    )
    out = tmp_path / "capture"
    subprocess.run(
        [dvr_bin, "capture", "--quiet", "--scene", str(tmp_path / "ct.toml"), "--size", "16x16",
         "--denoiser", "none,ours", "--out", str(out)],
        check=True,
    )
    scene = dvr.Scene.load(tmp_path / "ct.toml")
    scene.volume = dvr.Volume(ct, spacing=spacing)
    r = dvr.Renderer(scene, size=(16, 16), denoisers=["ours"])
    for f in range(3):
        got = r.render(frame=f)
        for method, key in (("none", "noisy"), ("ours", "ours")):
            assert np.array_equal(got[key], read_exr(out / method / f"{f:04d}.exr")), f"{method} frame {f}"


def test_a_thousand_renders_keep_memory_flat():
    def rss_mib():
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) for l in f if l.startswith("VmRSS")) / 1024

    r = dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), denoisers=["ours"])
    for i in range(100):  # allocations that stay: pipelines, histories, staging
        r.render(frame=i % r.frames)
    before = rss_mib()
    for i in range(1000):
        out = r.render(frame=i % r.frames)
        assert np.isfinite(out["ours"]).all()
    grown = rss_mib() - before
    assert grown < 16.0, f"RSS grew {grown:.1f} MiB over 1,000 renders"


def test_scores_equal_the_evals(dvr_bin, tmp_path):
    out = tmp_path / "eval"
    subprocess.run(
        [dvr_bin, "eval", "--quiet", "--scene", "cloud/orbit", "--frames", "2", "--size", "16x16",
         "--ref-spp", "8", "--denoiser", "none", "--out", str(out)],
        check=True,
    )
    # The eval keeps the noisy input's EXRs (the other methods' frames as PNGs).
    rows = list(csv.DictReader(open(out / "metrics.csv")))
    assert len(rows) == 2
    d = out / "cloud_orbit"
    ref = [read_exr(d / "reference" / f"{f:04d}.exr") for f in range(2)]
    for row in rows:
        f = int(row["frame"])
        test = read_exr(d / row["method"] / f"{f:04d}.exr")
        # To the CSV's six decimals.
        assert dvr.metrics.psnr(ref[f], test) == pytest.approx(float(row["psnr"]), abs=1e-6)
        assert dvr.metrics.ssim(ref[f], test) == pytest.approx(float(row["ssim"]), abs=1e-6)
        assert dvr.metrics.flip(ref[f], test) == pytest.approx(float(row["flip"]), abs=1e-6)
        if f == 1:
            prev = read_exr(d / row["method"] / "0000.exr")
            te = dvr.metrics.temporal_error(prev, test, ref[0], ref[1])
            assert te == pytest.approx(float(row["temporal_error"]), abs=1e-6)


def test_a_numpy_volume_renders_and_converges():
    # A ball of density in a 32³ array: more samples, closer to the reference.
    z, y, x = np.mgrid[-1:1:32j, -1:1:32j, -1:1:32j]
    ball = (np.sqrt(x * x + y * y + z * z) < 0.7).astype(np.float32)
    tf = dvr.TransferFunction.from_array([[0.0, 0.9, 0.8, 0.7, 0.0], [0.5, 0.9, 0.8, 0.7, 0.0], [1.0, 0.9, 0.8, 0.7, 0.05]])
    scene = dvr.Scene(dvr.Volume(ball), tf=tf, frames=8, density_scale=80.0)
    r = dvr.Renderer(scene, size=(16, 16), denoisers=["accum"], spp=1)
    ref = r.reference(frame=0, spp=512)
    assert np.isfinite(ref).all() and ref.max() > 0
    errors = []
    for f in range(8):
        out = r.render()  # a still view: accumulation converges
        errors.append(float(np.mean((out["accum"] - ref) ** 2)))
    assert errors[-1] < 0.35 * errors[0], errors
    assert dvr.metrics.psnr(ref, out["accum"]) > dvr.metrics.psnr(ref, out["noisy"]) + 3.0


def test_the_gil_is_released_while_the_gpu_works():
    r = dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(48, 48), denoisers=["none"])
    result = []
    worker = threading.Thread(target=lambda: result.append(r.reference(frame=0, spp=512)))
    ticks = 0
    start = time.perf_counter()
    worker.start()
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert result and result[0].shape == (48, 48, 3), "the reference failed in its thread"
    elapsed = time.perf_counter() - start
    # A held GIL would freeze this loop for the whole reference.
    assert elapsed > 0.1, "the reference was too quick to tell"
    assert ticks > 0.3 * elapsed / 0.0011, (ticks, elapsed)


def test_bad_requests_raise_with_the_engines_messages():
    scene = dvr.Scene.builtin("phantom/orbit")
    with pytest.raises(ValueError, match="no-such"):
        dvr.Renderer(scene, size=(8, 8), denoisers=["no-such"])
    with pytest.raises(ValueError, match="size"):
        dvr.Renderer(scene, size=(0, 8))
    with pytest.raises(ValueError, match="spp"):
        dvr.Renderer(scene, size=(8, 8), spp=1000)
    with pytest.raises(ValueError, match="motion|first-hit"):
        dvr.Renderer(scene, size=(8, 8), motion="sideways")
    r = dvr.Renderer(scene, size=(8, 8), denoisers=["taa"])
    with pytest.raises(ValueError, match="frame=999: must be 0 to 59"):
        r.render(frame=999)
    with pytest.raises(ValueError, match="spp=0: must be 1 to"):
        r.reference(spp=0)


def test_a_missing_device_is_a_runtime_error():
    code = "import dvr\ntry:\n    dvr.Renderer(dvr.Scene.builtin('phantom/orbit'), size=(8, 8))\nexcept RuntimeError as e:\n    print('RuntimeError:', e)\n"
    env = dict(os.environ, DVR_DEVICE="no-such-gpu")
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "RuntimeError:" in p.stdout and "no-such-gpu" in p.stdout


def test_surface_features_come_back_with_a_frame():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(16, 16), denoisers=["taa"])
    out = r.render(features=True, aux=True)
    f = out["features"]
    assert set(f) == {"position", "normal", "albedo"}
    for img in f.values():
        assert img.shape == (16, 16, 4) and np.isfinite(img).all()
    met = f["position"][..., 3] > 0.5  # the threshold surface or visible medium
    surface = f["albedo"][..., 3] > 0.5  # the threshold surface only
    # The phantom fills the middle of the frame and not the corners.
    assert met[8, 8] and not met[0, 0] and surface.any()
    assert not (surface & ~met).any()
    # Unit normals and a positive distance on the surface; albedo in [0, 1].
    n = np.linalg.norm(f["normal"][surface][:, :3], axis=1)
    assert np.allclose(n, 1.0, atol=1e-3) and (f["normal"][surface][:, 3] > 0).all()
    assert (f["albedo"][surface][:, :3] >= 0).all() and (f["albedo"][surface][:, :3] <= 1).all()
    # Positions lie inside the volume's box (longest side 1, centred on the origin).
    assert (np.abs(f["position"][met][:, :3]) <= 0.5 + 1e-3).all()
    assert "features" not in r.render()


def test_a_volume_past_its_budget_is_paged_and_renders_the_same_frames():
    # A blob in one 32³ brick of a 96³ array (864 KiB as uint8): under a 200 KiB budget
    # only that brick is resident, and the frames are the dense path's.
    z, y, x = np.mgrid[0:96, 0:96, 0:96].astype(np.float32) + 0.5
    r2 = ((x - 48) ** 2 + (y - 48) ** 2 + (z - 48) ** 2) / 13.0**2
    blob = (255 * np.clip(1 - np.sqrt(r2), 0, 1) ** 2).astype(np.uint8)
    tf = dvr.TransferFunction.from_array([[0.0, 0.9, 0.8, 0.7, 0.0], [0.1, 0.9, 0.8, 0.7, 0.0], [1.0, 0.9, 0.8, 0.7, 1.0]])
    scene = dvr.Scene(dvr.Volume(blob), tf=tf, frames=2, density_scale=200.0)
    dense = dvr.Renderer(scene, size=(24, 24), denoisers=["none"], spp=1)
    pooled = dvr.Renderer(scene, size=(24, 24), denoisers=["none"], spp=1, gpu_memory="200K")
    for f in range(2):
        a, b = dense.render(frame=f), pooled.render(frame=f)
        assert np.abs(a["noisy"] - b["noisy"]).max() < 1e-4
    assert a["noisy"].max() > 0
    assert dense.volume_residency == "dense volume"
    assert pooled.volume_residency.startswith("brick pool: 1 of 1 visible bricks resident"), pooled.volume_residency
    with pytest.raises(ValueError, match="gpu_memory"):
        dvr.Renderer(scene, size=(8, 8), gpu_memory="lots")
    with pytest.raises(ValueError, match="at least 64K"):
        dvr.Renderer(scene, size=(8, 8), gpu_memory="20K")


def test_argument_errors_name_the_argument_and_its_range():
    r = dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), denoisers=["taa"])
    with pytest.raises(ValueError, match=r"frame=-1: must be 0 to 59"):
        r.render(frame=-1)
    with pytest.raises(TypeError, match="frame"):
        r.render(frame=1.5)
    with pytest.raises(ValueError, match=r"spp=1000000000000: must be 1 to"):
        dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), spp=10**12)
    with pytest.raises(ValueError, match=r"size: width must be a whole number of pixels, got 16.5"):
        dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(16.5, 8))
    with pytest.raises(ValueError, match=r"size=\(8, 9000\): width and height must be 1 to 8192"):
        dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 9000))
    with pytest.raises(ValueError, match=r"spp=0: must be 1 to"):
        r.reference(spp=0)
    with pytest.raises(ValueError, match=r"frame=60: must be 0 to 59"):
        r.reference(frame=60, spp=1)


def test_an_override_of_a_method_that_does_not_run_is_a_warning(monkeypatch):
    monkeypatch.setenv("DVR_OURS", "lag_z=3")
    with pytest.warns(RuntimeWarning, match=r"DVR_OURS is set but no method it applies to runs \(ours, "):
        r = dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), denoisers=["taa"])
    with pytest.warns(RuntimeWarning, match="DVR_OURS"):
        r.denoisers = ["svgf"]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r.denoisers = ["ours"]

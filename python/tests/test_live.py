"""dvr.Renderer as a live view: a still view refines for as long as it is rendered, edits
through the live API render exactly the frames `dvr capture` renders for the same
changes scripted, nested assignments apply or raise, and threads serialise."""

import hashlib
import subprocess
import threading

import numpy as np
import pytest

import dvr
from test_renderer import read_exr

SIZE = (20, 16)


def test_a_still_view_only_gets_better_over_200_frames():
    # A static view of the phantom (one frame, no animation) rendered 200 times: the
    # temporal denoiser keeps refining and never falls back.
    scene = dvr.Scene(dvr.Volume.builtin("phantom", 48), tf="phantom-opaque")
    r = dvr.Renderer(scene, size=(24, 24), denoisers=["ours"], spp=1)
    ref = r.reference(spp=1024)
    psnr = [dvr.metrics.psnr(ref, r.render()["ours"]) for _ in range(200)]
    assert r.frames_rendered == 200 and r.frames == 1
    best = -np.inf
    for f, p in enumerate(psnr):
        if f > 8:
            assert p >= best - 0.5, f"frame {f}: {p:.2f} dB, {best - p:.2f} below the best so far ({best:.2f})"
        best = max(best, p)
    assert np.mean(psnr[100:]) > np.mean(psnr[8:30]) + 0.5, (np.mean(psnr[8:30]), np.mean(psnr[100:]))


# A scene whose changes are keyed on every frame (so each frame's value is a keyframe's
# exactly): the camera moves on frames 1-2, the light on 3, the TF jumps to
# `transfer.b` on 4, and the camera and light change together on 5.
CAMERA = [(0.45, 1.5, 0.35), (0.55, 1.45, 0.36), (0.7, 1.38, 0.4), (0.7, 1.38, 0.4), (0.7, 1.38, 0.4), (0.6, 1.42, 0.3)]
LIGHT = [((-0.9, 1.1, 1.0), 20.0)] * 3 + [((-0.5, 1.2, 0.9), 24.0)] * 2 + [((-0.4, 1.0, 1.1), 18.0)]
TF_B_FROM = 4
# A clip plane switched on at frame 2 and moved on frames 3 and 5.
CLIP = [(0.3, False), (0.3, False), (0.3, True), (0.1, True), (0.1, True), (0.0, True)]


def scripted_scene(path):
    keys = []
    for f, pos in enumerate(CAMERA):
        keys.append(f"[[animation.camera]]\nframe = {f}\nposition = [{pos[0]!r}, {pos[1]!r}, {pos[2]!r}]\n")
    for f, (pos, k) in enumerate(LIGHT):
        keys.append(
            f"[[animation.light]]\nindex = 0\nframe = {f}\nposition = [{pos[0]!r}, {pos[1]!r}, {pos[2]!r}]\n"
            f"intensity = {k!r}\n"
        )
    for f, (z, on) in enumerate(CLIP):
        keys.append(
            f"[[animation.clip]]\nindex = 0\nframe = {f}\npoint = [0.0, 0.0, {z!r}]\n"
            f"enabled = {'true' if on else 'false'}\n"
        )
    keys.append('[[animation.tf]]\nframe = 0\nblend = 0.0\ninterpolation = "step"\n')
    keys.append(f"[[animation.tf]]\nframe = {TF_B_FROM}\nblend = 1.0\n")
    path.write_text(
        'name = "live-vs-scripted"\n[volume]\nbuiltin = "phantom"\nsize = 48\ndensity_scale = 150.0\n'
        '[transfer]\na = "phantom-opaque"\nb = "phantom-layered"\n'
        "[camera]\nposition = [0.45, 1.5, 0.35]\n"
        "[[clip]]\npoint = [0.0, 0.0, 0.3]\nnormal = [0.0, 0.0, -1.0]\nenabled = false\n"
        '[[light]]\nkind = "point"\nposition = [-0.9, 1.1, 1.0]\ncolour = [1.0, 0.95, 0.9]\nintensity = 20.0\n'
        '[[light]]\nkind = "environment"\nmode = "constant"\ncolour = [0.6, 0.7, 0.8]\nintensity = 0.2\n'
        f"[animation]\nframes = {len(CAMERA)}\n" + "".join(keys)
    )


@pytest.mark.parametrize("method", ["ours", "svgf"])
def test_live_edits_render_the_frames_of_the_same_changes_scripted(method, dvr_bin, tmp_path):
    path = tmp_path / "scripted.toml"
    scripted_scene(path)
    out = tmp_path / "capture"
    subprocess.run(
        [dvr_bin, "capture", "--quiet", "--scene", str(path), "--size", f"{SIZE[0]}x{SIZE[1]}",
         "--denoiser", f"none,{method}", "--out", str(out)],
        check=True,
    )
    r = dvr.Renderer(dvr.Scene.load(path), size=SIZE, denoisers=[method])
    for f in range(len(CAMERA)):
        # Each change through the live API, as a user in a notebook would make it.
        r.camera.position = CAMERA[f]
        pos, k = LIGHT[f]
        if r.lights[0].position != pos:
            r.lights[0].update(position=pos, intensity=k)
        if f == TF_B_FROM:
            r.tf = "phantom-layered"
        z, on = CLIP[f]
        if (r.clip[0].point[2], r.clip[0].enabled) != (z, on):
            r.clip[0].update(point=(0.0, 0.0, z), enabled=on)
        got = r.render()
        for name, key in (("none", "noisy"), (method, method)):
            want = read_exr(out / name / f"{f:04d}.exr")
            assert np.array_equal(got[key], want), f"{name} frame {f}: differs by {np.abs(got[key] - want).max()}"


def test_clip_planes_and_the_crop_box_are_live_state():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(16, 16), denoisers=["taa"])
    plain = r.render()["noisy"]
    assert len(r.clip) == 0 and r.crop is None
    r.clip.append(dvr.ClipPlane((0.0, 0.0, 0.0), (0.0, 0.0, -1.0)))  # removes the top half
    assert r.clip[0].normal == (0.0, 0.0, -1.0) and r.clip[0].enabled
    cut = r.render()["noisy"]
    assert np.abs(cut - plain).mean() > 0.01
    r.clip[0].flip()
    assert r.clip[0].normal == (0.0, 0.0, 1.0)
    r.clip[0].enabled = False
    r.crop = dvr.CropBox(min=(-0.5, -0.5, -0.5), max=(0.5, 0.0, 0.5))
    assert r.crop.max == (0.5, 0.0, 0.5) and r.crop.units == "box"
    r.crop.enabled = False
    assert not r.crop.enabled
    r.crop = None
    assert r.crop is None
    with pytest.raises(TypeError):
        r.clip[0].point[0] = 1.0
    # Bad cuts name the field and change nothing.
    before = (r.clip.to_list(), r.crop)
    for edit, needle in [
        (lambda: setattr(r.clip[0], "normal", (0, 0, 0)), r"clip\[0\].normal"),
        (lambda: setattr(r.clip[0], "point", (np.nan, 0, 0)), r"clip\[0\].point"),
        (lambda: setattr(r, "crop", dvr.CropBox(min=(0.2, 0, 0), max=(0.1, 0.3, 0.3))), "crop.min"),
        (lambda: setattr(r, "clip", [dvr.ClipPlane((0, 0, 0), (0, 0, 1))] * 7), "at most 6"),
    ]:
        with pytest.raises(ValueError, match=needle):
            edit()
    assert (r.clip.to_list(), r.crop) == before
    # A scene's cut: the same live views over its dict.
    scene = dvr.Scene.builtin("phantom/orbit")
    scene.clip = [dvr.ClipPlane((0.0, 0.0, 0.1), (0.0, 0.0, 1.0))]
    scene.clip[0].point = (0.0, 0.0, 0.2)
    scene.crop = dvr.CropBox(max=(0.5, 0.5, 0.3))
    assert scene.check()["clip"][0]["point"] == [0.0, 0.0, 0.2] and scene.check()["crop"]["max"][2] == 0.3


def test_render_frame_k_plays_the_animation_and_leaves_its_view():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(8, 8), denoisers=["taa"])
    start = r.camera.position
    r.render(frame=10)
    at10 = r.camera.position
    assert at10 != start
    r.render()  # the view stays where frame 10 put it
    assert r.camera.position == at10
    with pytest.raises(ValueError, match=r"frame=60: must be 0 to 59"):
        r.render(frame=60)
    with pytest.raises(ValueError, match=r"frame=-1: must be 0 to 59"):
        r.render(frame=-1)


def test_nested_assignments_apply_or_raise():
    scene = dvr.Scene.builtin("phantom/orbit")
    r = dvr.Renderer(scene, size=(8, 8), denoisers=["taa"])
    # The camera: a field applies, a component of a returned tuple raises.
    r.camera.position = (0.0, 2.0, 0.5)
    assert r.camera.position == (0.0, 2.0, 0.5)
    r.camera.fov_y_degrees = 30
    assert r.camera.fov_y_degrees == 30.0 and r.camera.position == (0.0, 2.0, 0.5)
    with pytest.raises(TypeError):
        r.camera.position[0] = 1.0
    cam = r.camera
    cam.target = (0.1, 0.0, 0.0)  # a view handed out earlier stays live
    assert r.camera.target == (0.1, 0.0, 0.0)
    with pytest.raises(AttributeError, match="no field 'positon'"):
        r.camera.positon = (0, 0, 0)
    # The lights: a field of one applies, replacing one applies, a tuple raises.
    r.lights[0].intensity = 33.0
    assert r.lights[0].intensity == 33.0
    r.lights[0].colour = (1.0, 0.5, 0.25)
    assert r.lights[0].color == (1.0, 0.5, 0.25)
    with pytest.raises(TypeError):
        r.lights[0].position[1] = 0.0
    n = len(r.lights)
    r.lights.append(dvr.PointLight((1.0, 1.0, 1.0), intensity=5.0))
    assert len(r.lights) == n + 1 and r.lights[n].kind == "point"
    del r.lights[n]
    assert len(r.lights) == n
    r.lights[0] = dvr.PointLight((0.5, 0.5, 1.0), intensity=12.0)
    assert r.lights[0].position == (0.5, 0.5, 1.0)
    # The TF: immutable as handed out; assignment is the way to change it.
    tf = r.tf
    with pytest.raises(TypeError):
        tf.points[0]["opacity"] = 0.5
    with pytest.raises(AttributeError, match="immutable"):
        tf.points = []
    edited = tf.copy()
    edited.points[-1]["opacity"] = 0.25
    r.tf = edited
    assert r.tf.points[-1]["opacity"] == 0.25
    r.tf = np.array([[0.0, 1, 1, 1, 0.0], [1.0, 1, 0.8, 0.6, 0.9]])
    assert len(r.tf.points) == 2
    r.tf = "phantom-layered"
    assert r.tf.name == "phantom-layered"
    # Settings: attribute and item access apply; a bad value raises and changes nothing.
    r.settings.spp = 1
    r.settings["max_bounces"] = 2
    assert r.spp == 1 and r.settings.max_bounces == 2
    with pytest.raises(ValueError, match="spp"):
        r.settings.spp = 0
    assert r.spp == 1
    r.denoisers = ["svgf", "taa"]
    assert r.denoisers == ("svgf", "taa")
    with pytest.raises(TypeError):
        r.denoisers[0] = "ours"
    assert set(r.render()) == {"noisy", "svgf", "taa"}
    # The same semantics on a scene (edits of its dict).
    scene.camera.position = (0.0, 1.8, 0.2)
    assert scene.data["camera"]["position"] == [0.0, 1.8, 0.2]
    scene.lights[0].intensity = 7.0
    assert scene.data["light"][0]["intensity"] == 7.0
    with pytest.raises(TypeError):
        scene.camera.position[2] = 0.0


def test_bad_edits_raise_naming_the_field_and_change_nothing():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(8, 8), denoisers=["taa"])
    before = (r.camera.to_dict(), r.lights.to_list(), r.settings.to_dict())
    for edit, needle in [
        (lambda: setattr(r.camera, "position", (np.nan, 0, 0)), "camera.position"),
        (lambda: setattr(r.camera, "up", (0, 0, 0)), "camera.up"),
        (lambda: setattr(r.camera, "position", (100.0, 0, 0)), "camera.position"),
        (lambda: setattr(r.lights[0], "intensity", -1.0), r"light\[0\].intensity"),
        (lambda: setattr(r.settings, "max_bounces", 10**6), "max_bounces"),
        (lambda: setattr(r.settings, "no_such", 1), "no_such"),
        (lambda: setattr(r, "tf", "no-such-preset"), "no-such-preset"),
        (lambda: setattr(r, "denoisers", ["no-such"]), "no-such"),
        (lambda: r.orbit(float("nan"), 0.0), "camera.position"),
    ]:
        with pytest.raises(ValueError, match=needle):
            edit()
    assert (r.camera.to_dict(), r.lights.to_list(), r.settings.to_dict()) == before
    assert np.isfinite(r.render()["taa"]).all()


def test_orbit_pan_and_zoom_move_the_camera_as_the_explorers_mouse_does():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(32, 32), denoisers=["taa"])
    p0, t0 = np.array(r.camera.position), np.array(r.camera.target)
    d0 = np.linalg.norm(p0 - t0)
    r.orbit_pixels(40, 0)  # the explorer's drag: 0.4 rad about +z, target and distance kept
    p1 = np.array(r.camera.position)
    assert np.allclose(r.camera.target, t0) and np.isclose(np.linalg.norm(p1 - t0), d0)
    a0, a1 = np.arctan2(*(p0 - t0)[1::-1]), np.arctan2(*(p1 - t0)[1::-1])
    assert np.isclose((a0 - a1 + np.pi) % (2 * np.pi) - np.pi, 0.4)
    r.orbit(np.degrees(0.4))  # degrees, as the scene's orbit turns: back to the start
    assert np.allclose(r.camera.position, p0)
    r.zoom(2)
    assert np.isclose(np.linalg.norm(np.array(r.camera.position) - t0), d0 / 1.21)
    r.pan(0, 32)  # a full view height: the target moves by the view's height at its depth
    moved = np.linalg.norm(np.array(r.camera.target) - t0)
    assert np.isclose(moved, 2 * d0 / 1.21 * np.tan(np.radians(r.camera.fov_y_degrees) / 2))
    r.reset_camera()
    assert np.allclose(r.camera.position, p0) and np.allclose(r.camera.target, t0)


def test_view_from_puts_the_camera_on_that_side_of_the_patient():
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=(16, 16), denoisers=["taa"])
    t0 = np.array(r.camera.target)
    d0 = np.linalg.norm(np.array(r.camera.position) - t0)
    sides = {"anterior": (0, 1, 0), "posterior": (0, -1, 0), "left": (-1, 0, 0),
             "right": (1, 0, 0), "superior": (0, 0, 1), "inferior": (0, 0, -1)}
    for side, towards in sides.items():
        r.view_from(side)
        offset = np.array(r.camera.position) - np.array(r.camera.target)
        assert np.isclose(np.linalg.norm(offset), d0), side
        assert np.dot(offset / d0, towards) > 0.999, (side, offset)
    with pytest.raises(ValueError, match="anterior, posterior"):
        r.view_from("front")


def _digest(out):
    return hashlib.sha256(b"".join(np.ascontiguousarray(out[k]).tobytes() for k in sorted(out))).hexdigest()


def test_four_threads_render_on_one_renderer_as_a_serial_run_does():
    def make():
        return dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(12, 12), denoisers=["ours"])

    serial = make()
    want = sorted(_digest(serial.render()) for _ in range(200))
    shared = make()
    got, errors = [], []

    def work():
        try:
            for _ in range(50):
                out = shared.render()
                got.append(_digest(out))
                shared.timings()
                _ = shared.camera.position
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert sorted(got) == want


def test_a_closed_renderer_is_freed_and_says_so():
    r = dvr.Renderer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), denoisers=["taa"])
    with r:
        r.render()
    assert r.closed
    with pytest.raises(RuntimeError, match="closed"):
        r.render()

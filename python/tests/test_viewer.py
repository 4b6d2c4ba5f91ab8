"""dvr.Viewer's kernel side, without a browser: frames go out only as the page shows
them (a lagging page drops frames, nothing queues), messages from the page are checked
(sizes, NaN, unknown fields, floods), and closing stops the thread and frees the
renderer. The browser side is test_notebook.py."""

import gc
import math
import threading
import time

import numpy as np
import pytest

import dvr
from conftest import LABELLED_PHANTOM
from dvr import viewer as viewer_module


class Recorder:
    """Stands in for the page: records what the viewer sends."""

    def __init__(self):
        self.frames = []
        self.lock = threading.Lock()

    def __call__(self, content, buffers=None):
        with self.lock:
            self.frames.append((content, buffers))


@pytest.fixture
def viewer(monkeypatch):
    sent = Recorder()
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: sent(content, buffers))
    v = dvr.Viewer("cloud/orbit", size=(16, 16), denoisers=["ours"])
    yield v, sent
    v.close()


def wait_for(what, predicate, timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.02)
    raise TimeoutError(what)


def test_frames_wait_for_the_page_and_are_dropped_not_queued(viewer):
    v, sent = viewer
    wait_for("a first frame", lambda: sent.frames)
    rendered = v.renderer.frames_rendered
    wait_for("more frames rendered", lambda: v.renderer.frames_rendered >= rendered + 5)
    # No acknowledgement yet: one frame went out however many were rendered.
    assert len(sent.frames) == 1
    content, buffers = sent.frames[0]
    assert content["type"] == "frame" and content["mime"] == "image/jpeg" and content["names"] == ["ours"]
    assert buffers[0][:2] == b"\xff\xd8", "a JPEG"
    assert content["width"] == 16 and content["height"] == 16 and content["timings"]
    for _ in range(3):
        n = len(sent.frames)
        v._on_message(v, {"type": "ack"}, [])
        wait_for("the next frame after an ack", lambda: len(sent.frames) > n)
    frames = [c["frame"] for c, _ in sent.frames]
    assert frames == sorted(frames) and frames[-1] - frames[0] >= 3, frames


def test_messages_from_the_page_are_checked_and_never_queue(viewer):
    v, sent = viewer
    wait_for("a first frame", lambda: sent.frames)
    start = v.renderer.camera.position
    # Refused without a word: not numbers, NaN, infinite, absurd, unknown.
    for msg in [
        {"type": "orbit", "dx": float("nan"), "dy": 0},
        {"type": "orbit", "dx": math.inf, "dy": 0},
        {"type": "orbit", "dx": 1e12, "dy": 0},
        {"type": "orbit", "dx": "10", "dy": 0},
        {"type": "orbit", "dx": True, "dy": 0},
        {"type": "pan", "dx": [1], "dy": 2},
        {"type": "zoom", "steps": 1e9},
        {"type": "zoom"},
        {"type": "launch"},
        {"no": "type"},
        ["orbit", 1, 2],
        "orbit",
        None,
    ]:
        v._on_message(v, msg, [])
    time.sleep(0.5)
    assert v.renderer.camera.position == start
    # A flood: 10,000 small drags are summed into one edit, applied once.
    for _ in range(10_000):
        v._on_message(v, {"type": "orbit", "dx": 0.01, "dy": 0.0, "seq": 1}, [])
    assert len(v._pending._edits) <= 1

    def turned():
        """The camera's turn about the up axis since `start`, radians."""
        moved = np.array(v.renderer.camera.position)
        target = np.array(v.renderer.camera.target)
        p0 = np.array(start) - target
        a = np.arctan2(p0[1], p0[0]) - np.arctan2(*(moved - target)[1::-1])
        return (a + np.pi) % (2 * np.pi) - np.pi

    # 100 pixels of orbit in all: 1 radian about the up axis (the render thread may take
    # the sum in more than one part while the flood arrives; the parts add up).
    wait_for("the flood's orbit, 1 radian", lambda: np.isclose(turned(), 1.0, atol=1e-6))
    # State from the page: a bad TF or denoiser is refused with a status line.
    v.tf_points = [{"density": "x", "opacity": 1}]
    assert "refused" in v.status
    v.tf_points = [{"density": float("nan"), "opacity": 1}]
    assert "refused" in v.status
    v.tf_points = [{"density": 0.0, "opacity": 0.0, "diffuse": [1, 1, 1]}] * 300
    assert "refused" in v.status
    v.denoiser = "no-such"
    assert "unknown denoiser" in v.status
    # A good edit of the curve applies.
    v.tf_points = [
        {"density": 0.0, "opacity": 0.0, "diffuse": [1.0, 0.9, 0.8]},
        {"density": 0.6, "opacity": 0.9, "diffuse": [1.0, 0.9, 0.8]},
    ]
    wait_for("the edited TF", lambda: len(v.renderer.tf.points) == 2)
    # Values the engine refuses (opacity out of range) come back as a status line.
    v.tf_points = [{"density": 0.0, "opacity": 7.0}, {"density": 1.0, "opacity": 0.0}]
    wait_for("the engine's refusal", lambda: "opacity" in v.status)
    assert v.running


def test_closing_stops_the_thread_and_frees_the_renderer(monkeypatch):
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: None)
    v = dvr.Viewer(dvr.Scene.builtin("cloud/orbit"), size=(8, 8), denoisers=["taa"], split="ours")
    r = v.renderer
    wait_for("frames", lambda: r.frames_rendered > 2)
    assert r.denoisers == ("taa", "ours")
    v.close()
    assert not v.running and r.closed and v.renderer is None
    assert not [t for t in threading.enumerate() if t.name == "dvr-viewer" and t.is_alive()]
    # A renderer handed in stays the caller's.
    own = dvr.Renderer("cloud/orbit", size=(8, 8), denoisers=["taa"])
    w = dvr.Viewer(own)
    wait_for("frames", lambda: own.frames_rendered > 1)
    w.close()
    assert not w.running and not own.closed
    own.close()


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_bad_viewer_arguments_are_errors():
    with pytest.raises(ValueError, match="format"):
        dvr.Viewer("cloud/orbit", format="gif")
    with pytest.raises(ValueError, match="quality"):
        dvr.Viewer("cloud/orbit", quality=0)
    with pytest.raises(ValueError, match="denoisers"):
        dvr.Viewer("cloud/orbit", denoisers=[])
    assert viewer_module.panel.tf_points("no") is None
    # The half-made widgets' finalisers (close) run without an error of their own.
    gc.collect()


# The panel shows the renderer's state, whoever changes it, and keeps every field.


def frames_after(sent, v, n):
    """Acknowledges frames until one more than `n` were sent; returns the newest."""
    def newer():
        v._on_message(v, {"type": "ack"}, [])
        return len(sent.frames) > n
    wait_for(f"frame {n + 1}", newer)
    return sent.frames[-1]


def test_the_tf_editor_follows_the_renderers_tf_by_any_road_and_keeps_every_field(viewer):
    v, sent = viewer
    # Another cell assigns a preset: the panel's curve and dropdown follow.
    v.renderer.tf = "phantom-opaque"
    preset = dvr.TransferFunction.preset("phantom-opaque").points
    wait_for("the preset in the panel", lambda: v.tf_points == preset and v.preset == "phantom-opaque")
    # A point with specular, emission and roughness, edited in the page (its opacity):
    # the renderer's TF keeps every field of every point.
    points = [dict(p) for p in v.tf_points]
    points[-1] = dict(points[-1], specular=[0.5, 0.4, 0.3], emissive=[0.2, 0.0, 0.1], roughness=0.25)
    points[-1]["opacity"] = 0.5
    v.tf_points = points
    wait_for("the page's edit in the renderer", lambda: v.renderer.tf.name == "edited")
    got = [dict(p) for p in v.renderer.tf.points]
    assert got[-1]["specular"] == pytest.approx([0.5, 0.4, 0.3]) and got[-1]["emissive"] == pytest.approx([0.2, 0.0, 0.1])
    assert got[-1]["roughness"] == pytest.approx(0.25) and got[-1]["opacity"] == pytest.approx(0.5)
    assert [p["density"] for p in got] == pytest.approx([p["density"] for p in preset])
    # The dropdown no longer names the preset; the panel shows the renderer's TF.
    wait_for("the edited TF in the panel", lambda: v.preset == "" and v.tf_points == got)
    # A preset picked in the page, then an assignment from Python: each shows.
    v.preset = "phantom-vessels"
    wait_for("the page's preset applied", lambda: v.renderer.tf.name == "phantom-vessels")
    v.renderer.tf = dvr.TransferFunction.from_array([[0.0, 1, 1, 1, 0.0], [1.0, 1, 1, 1, 0.3]], "mine")
    wait_for("Python's TF in the panel", lambda: len(v.tf_points) == 2 and v.preset == "")
    # A TF the engine refuses leaves the panel showing the renderer's, not the refused.
    v.tf_points = [{"density": 0.0, "opacity": 7.0}, {"density": 1.0, "opacity": 0.0}]
    wait_for("the refusal", lambda: "opacity" in v.status)
    wait_for("the renderer's TF back in the panel", lambda: v.tf_points[0]["opacity"] == 0.0 and v.tf_points[1]["opacity"] == 0.3)
    # Unknown fields are refused, not passed on or dropped.
    assert viewer_module.panel.tf_points([{"density": 0, "opacity": 0, "glow": 1}]) is None


def test_noisy_is_offered_as_a_denoiser_and_in_the_split(viewer, monkeypatch):
    v, sent = viewer
    # Every change of the renderer's denoisers, counted (each restarts the histories).
    changes = []
    prop = dvr.Renderer.denoisers
    monkeypatch.setattr(dvr.Renderer, "denoisers", property(prop.fget, lambda r, names: (changes.append(list(names)), prop.fset(r, names))))
    assert v.methods[0] == "noisy" and "ours" in v.methods and "none" not in v.methods
    v.denoiser, v.split = "noisy", "ours"
    wait_for("the split of noisy and ours", lambda: frames_after(sent, v, len(sent.frames))[0]["names"] == ["noisy", "ours"])
    assert v.renderer.denoisers == ("ours",), "noisy needs no denoiser run"
    v.split = ""
    wait_for("noisy alone: no denoiser runs", lambda: v.renderer.denoisers == ())
    # Asked once, not again each frame (that would restart the histories each frame).
    n = v.renderer.frames_rendered
    wait_for("frames", lambda: v.renderer.frames_rendered > n + 3)
    assert changes == [["none"]], changes
    content, _ = frames_after(sent, v, len(sent.frames))
    assert content["names"] == ["noisy"]
    # Shown alone, the frame is the renderer's raw input.
    out = v.renderer.render()
    image, names = viewer_module._compose(out, "noisy", "", 0.5)
    assert names == ["noisy"] and image is out["noisy"]


def test_the_spp_box_takes_the_engines_limit(viewer):
    v, sent = viewer
    limit = v.max_spp
    # The limit is the engine's: it takes `limit` and refuses one more.
    r = v.renderer
    assert 1 <= limit <= 64
    if "llvmpipe" in r.device:
        assert limit == 4, "lavapipe takes 4 samples per pixel per frame"
    v.spp = limit
    wait_for("spp at the limit", lambda: r.spp == limit)
    with pytest.raises(ValueError, match="samples per pixel"):
        r.settings.spp = limit + 1
    # 99 in the box is refused with the limit named, and the box shows the renderer's.
    v.spp = 99
    assert f"1 to {limit}" in v.status
    wait_for("the box back at the renderer's spp", lambda: v.spp == limit)
    # From Python the panel follows too.
    r.settings.spp = 1
    wait_for("Python's spp in the box", lambda: v.spp == 1)


@pytest.mark.parametrize(
    "side, direction, up, edges",
    [
        ("anterior", (0, 1, 0), (0, 0, 1), ("R", "L", "S", "I")),
        ("posterior", (0, -1, 0), (0, 0, 1), ("L", "R", "S", "I")),
        ("left", (-1, 0, 0), (0, 0, 1), ("A", "P", "S", "I")),
        ("right", (1, 0, 0), (0, 0, 1), ("P", "A", "S", "I")),
        ("superior", (0, 0, 1), (0, -1, 0), ("R", "L", "P", "A")),
        ("inferior", (0, 0, -1), (0, 1, 0), ("R", "L", "A", "P")),
    ],
)
def test_view_from_a_patient_side_keeps_target_and_distance(side, direction, up, edges):
    with dvr.Renderer("phantom/orbit", size=(8, 8), denoisers=["none"]) as r:
        r.camera.target = (0.1, -0.05, 0.02)
        cam = r.camera.to_dict()
        distance = np.linalg.norm(np.subtract(cam["position"], cam["target"]))
        r.view_from(side)
        now = r.camera.to_dict()
        assert now["target"] == pytest.approx(cam["target"])
        offset = np.subtract(now["position"], now["target"])
        assert np.linalg.norm(offset) == pytest.approx(distance)
        assert offset / distance == pytest.approx(direction, abs=1e-9)
        assert now["up"] == pytest.approx(up)
        # The letters at the view's left, right, top and bottom edges.
        o = viewer_module.panel.orientation(now)
        assert (o["left"], o["right"], o["top"], o["bottom"]) == edges
        # Azimuth and elevation in degrees: 90° of azimuth from anterior is the left
        # or right side; elevation 30° lifts the camera by sin(30°).
        r.view_from(side, elevation=30)
        lifted = np.subtract(r.camera.position, r.camera.target) / distance
        assert np.dot(lifted, up) == pytest.approx(0.5)
        with pytest.raises(ValueError, match="side"):
            r.view_from("north")
        with pytest.raises(ValueError, match="elevation"):
            r.view_from(side, elevation=90)
        # Azimuth turns about the view's up: 90° from the front is the patient's left.
        if side == "anterior":
            r.view_from("anterior", azimuth=90)
            assert np.subtract(r.camera.position, r.camera.target) / distance == pytest.approx((-1, 0, 0), abs=1e-9)


def test_reset_fit_and_side_buttons_move_the_camera(viewer):
    v, sent = viewer
    wait_for("a first frame", lambda: sent.frames)
    start = v.renderer.camera.to_dict()
    v._on_message(v, {"type": "view", "side": "superior", "seq": 3}, [])
    wait_for("the superior view", lambda: v.renderer.camera.up == pytest.approx((0, -1, 0)))
    content, _ = frames_after(sent, v, len(sent.frames))
    assert content["orientation"]["top"] == "P" and content["orientation"]["left"] == "R"
    v._on_message(v, {"type": "reset"}, [])
    # Back to the start, up vector and all (the engine's own reset keeps the current up).
    wait_for("the camera reset", lambda: v.renderer.camera.position == pytest.approx(start["position"]) and v.renderer.camera.up == pytest.approx(start["up"]))
    v._on_message(v, {"type": "zoom", "steps": 5}, [])
    wait_for("zoomed", lambda: v.renderer.camera.position != start["position"])
    zoomed = v.renderer.camera.to_dict()
    v._on_message(v, {"type": "fit"}, [])
    wait_for("fitted", lambda: v.renderer.camera.position != zoomed["position"])
    # Fit keeps the viewing direction.
    unit = lambda c: np.subtract(c["position"], c["target"]) / np.linalg.norm(np.subtract(c["position"], c["target"]))  # noqa: E731
    assert unit(v.renderer.camera.to_dict()) == pytest.approx(unit(zoomed), abs=1e-6)
    v._on_message(v, {"type": "view", "side": "<script>"}, [])
    assert "side" in v.status and v.running


def test_frames_carry_the_orientation_and_a_scale_bar_in_mm(viewer):
    v, sent = viewer
    content, _ = frames_after(sent, v, 0)
    # The volume's physical size, read from the engine's Volume (the builtin cloud).
    vol = dvr.Volume.builtin("cloud")
    extent = max(n * s for n, s in zip(vol.shape, vol.spacing))
    assert v.volume["physical"] == pytest.approx(extent) and v.volume["window"] == list(vol.window)
    cam = v.renderer.camera.to_dict()
    visible_mm = 2 * np.linalg.norm(np.subtract(cam["position"], cam["target"])) * np.tan(np.radians(cam["fov_y_degrees"]) / 2) * extent
    scale = content["scale"]
    # The bar's length in mm over the view's width in mm (square pixels) is its share.
    # (The view is square: its width in mm is its height's.)
    assert scale["fraction"] == pytest.approx(scale["mm"] / visible_mm, rel=1e-3)
    assert 0.1 < scale["fraction"] <= 0.25 and str(scale["mm"])[0] in "125"
    o = content["orientation"]
    assert {o["left"], o["right"]} in ({"R", "L"}, {"A", "P"}, {"S", "I"})


def test_a_volumes_window_and_physical_size_reach_the_panel(monkeypatch):
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: None)
    # [z, y, x] with spacing in that order: extents z 20 mm, y 20 mm, x 15 mm.
    data = (np.arange(10 * 20 * 30).reshape(10, 20, 30) % 1000).astype(np.int16)
    volume = dvr.Volume(data, spacing=(2.0, 1.0, 0.5))
    v = dvr.Viewer(volume, size=(8, 8), denoisers=["none"])
    try:
        assert v.volume["shape"] == [30, 20, 10] and v.volume["spacing"] == [0.5, 1.0, 2.0]
        assert v.volume["physical"] == pytest.approx(20.0)
        # The TF axis is labelled in the data's values: the window the engine chose.
        assert v.volume["window"] == pytest.approx(list(volume.window)) and volume.window[1] > 1
    finally:
        v.close()


def test_screenshot_is_a_lossless_png_at_render_size(viewer, tmp_path):
    from lab import decode_png

    v, sent = viewer
    frames_after(sent, v, 0)
    # The render thread stopped, so the shown frame stays the one compared with.
    v._stop.set()
    v._thread.join()
    path = v.screenshot(tmp_path / "shot.png")
    w, h, rows = decode_png(path.read_bytes())
    assert (w, h) == (16, 16) and len(rows) == 16
    # Exactly the shown frame, tone-mapped as the eval's PNGs (the last frame composed).
    assert path.read_bytes() == dvr._native.encode_image(v._last[1], "png")
    assert v.captures[-1] == {"kind": "screenshot", "path": str(path.resolve())}
    content, buffers = next((c, b) for c, b in reversed(sent.frames) if c["type"] == "capture")
    assert content["mime"] == "image/png" and bytes(buffers[0]) == path.read_bytes()
    # A second screenshot without a path goes to the captures folder.
    v._capture_dir = tmp_path / "captures"
    default = v.screenshot()
    assert default.parent == tmp_path / "captures" and default.read_bytes() == path.read_bytes()


def test_movie_is_an_orbit_mp4_and_the_camera_comes_back(viewer, tmp_path):
    from lab import ffprobe_frames

    v, sent = viewer
    start = v.renderer.camera.to_dict()
    path = v.movie(tmp_path / "orbit.mp4", frames=6, degrees=90, fps=12)
    assert ffprobe_frames(path) == (6, 16, 16)
    assert v.renderer.camera.position == pytest.approx(start["position"])
    assert not list(tmp_path.glob("*.partial*")) and v.captures[-1]["kind"] == "movie"
    with pytest.raises(ValueError, match="frames"):
        v.movie(tmp_path / "x.mp4", frames=1)
    # From the page's button: a file in the captures folder, said in the status line.
    v._capture_dir = tmp_path / "captures"
    v._on_message(v, {"type": "screenshot"}, [])
    wait_for("the page's screenshot", lambda: "screenshot saved" in v.status)
    assert len(list((tmp_path / "captures").glob("*.png"))) == 1


def test_a_movie_pads_odd_sizes_and_leaves_no_file_when_it_fails(tmp_path):
    from lab import ffprobe_frames

    capture = viewer_module.capture
    movie = capture.Movie(tmp_path / "odd.mp4", fps=10)
    rng = np.random.default_rng(1)
    for _ in range(3):
        movie.add(rng.random((11, 15, 3), dtype=np.float32))
    # yuv420p takes even sizes only: one black column and row are added.
    assert ffprobe_frames(movie.finish()) == (3, 16, 12)
    # A frame of another size, and a movie of no frames, are errors that leave nothing.
    bad = capture.Movie(tmp_path / "bad.mp4")
    bad.add(np.zeros((8, 8, 3), np.float32))
    with pytest.raises(ValueError, match="a frame is 4x4"):
        bad.add(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(RuntimeError, match="no frames"):
        capture.Movie(tmp_path / "empty.mp4").finish()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["odd.mp4"]
    with pytest.raises(ValueError, match="fps"):
        capture.Movie(tmp_path / "x.mp4", fps=0)


def test_cuts_from_the_page_clip_and_crop(viewer):
    v, sent = viewer
    plane = {"point": [0.0, 0.0, 0.1], "normal": [0.0, 0.0, 1.0], "enabled": True}
    v.clip_planes = [plane]
    wait_for("the clip plane", lambda: len(v.renderer.clip) == 1)
    assert v.renderer.clip[0].point == pytest.approx((0, 0, 0.1))
    # Dragged (its offset) from the page.
    v.clip_planes = [dict(plane, point=[0.0, 0.0, -0.2])]
    wait_for("the plane moved", lambda: v.renderer.clip[0].point == pytest.approx((0, 0, -0.2)))
    v.crop_box = {"min": [-0.3, -0.5, -0.5], "max": [0.3, 0.5, 0.5], "enabled": True}
    wait_for("the crop box", lambda: v.renderer.crop is not None and v.renderer.crop.min == pytest.approx((-0.3, -0.5, -0.5)))
    # Refused with a reason: a zero normal, seven planes, min past max.
    v.clip_planes = [dict(plane, normal=[0, 0, 0])]
    assert "refused clip planes" in v.status
    v.clip_planes = [plane] * 7
    assert "refused clip planes" in v.status
    v.crop_box = {"min": [0.3, 0, 0], "max": [0.1, 0.5, 0.5]}
    assert "refused a crop box" in v.status
    # The panel goes back to the renderer's planes, and follows Python's edits.
    wait_for("the renderer's plane in the panel", lambda: len(v.clip_planes) == 1)
    v.renderer.clip = []
    v.renderer.crop = None
    wait_for("Python's edits in the panel", lambda: v.clip_planes == [] and v.crop_box == {})


def test_a_closed_viewer_leaves_its_last_frame_in_the_output(monkeypatch):
    from lab import decode_png
    import base64
    import IPython.display

    shown, updated = [], []
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: None)
    monkeypatch.setattr(IPython.display, "display", lambda *a, **k: shown.append((a, k)))
    monkeypatch.setattr(IPython.display, "update_display", lambda *a, **k: updated.append((a, k)))
    v = dvr.Viewer("cloud/orbit", size=(12, 10), denoisers=["ours"])
    v._ipython_display_()
    (bundle,), kw = shown[-1]
    assert "application/vnd.jupyter.widget-view+json" in bundle and kw["display_id"]
    wait_for("a frame", lambda: v._last is not None)
    v.close()
    (out,), kw2 = updated[0]
    assert kw2["display_id"] == kw["display_id"] and kw2["raw"]
    assert decode_png(base64.b64decode(out["image/png"]))[:2] == (12, 10)
    assert "closed" in out["text/plain"]


# Channels and time points: the channels panel and the time slider.


@pytest.fixture
def series_viewer(monkeypatch, series_file):
    sent, resent = Recorder(), []
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: sent(content, buffers))
    monkeypatch.setattr(dvr.Viewer, "send_state", lambda self, key=None: resent.append(key))
    v = dvr.Viewer(dvr.Scene(str(series_file), tf="phantom-opaque"), size=(16, 16), denoisers=["ours"])
    yield v, sent, resent
    v.close()


def test_channel_and_time_messages_are_checked_then_applied_by_the_render_thread(series_viewer):
    v, sent, _ = series_viewer
    r = v.renderer
    assert [c["name"] for c in v.channels] == ["core", "shell"] and v.times == 4 and v.tf_channel == 0
    assert frames_after(sent, v, 0)[0]["time"] == 0.0
    # Refused with a reason, and nothing reaches the renderer: indices out of range or
    # not whole numbers, colours outside [0, 1] or not three numbers, visible not a bool,
    # unknown fields, times outside the series, speeds of none or too many.
    for msg, reason in [
        ({"type": "channel", "index": 2, "visible": False}, "not a channel"),
        ({"type": "channel", "index": -1, "visible": False}, "not a channel"),
        ({"type": "channel", "index": True, "visible": False}, "not a channel"),
        ({"type": "channel", "index": "0", "visible": False}, "not a channel"),
        ({"type": "channel", "index": 0, "colour": [1, 0, 1.5]}, "colour"),
        ({"type": "channel", "index": 0, "colour": [-0.1, 0, 0]}, "colour"),
        ({"type": "channel", "index": 0, "colour": [float("nan"), 0, 0]}, "colour"),
        ({"type": "channel", "index": 0, "colour": [1, 0]}, "colour"),
        ({"type": "channel", "index": 0, "colour": "#ff0000"}, "colour"),
        ({"type": "channel", "index": 0, "visible": 0}, "visible"),
        ({"type": "channel", "index": 0, "visible": "false"}, "visible"),
        ({"type": "channel", "index": 0, "window": [0, 1]}, "unknown field"),
        ({"type": "channel", "index": 0}, "nothing to edit"),
        ({"type": "channel", "index": 0, "preset": "no-such"}, "preset"),
        ({"type": "channel", "index": 0, "tf": "no"}, "tf"),
        ({"type": "time", "time": 3.5}, "from 0 to 3"),
        ({"type": "time", "time": -0.01}, "from 0 to 3"),
        ({"type": "time", "time": float("nan")}, "from 0 to 3"),
        ({"type": "time", "time": "1"}, "from 0 to 3"),
        ({"type": "play", "speed": 0}, "speed"),
        ({"type": "play", "speed": 1e6}, "speed"),
        ({"type": "play", "playing": 1}, "playing"),
    ]:
        v._on_message(v, msg, [])
        assert reason in v.status, (msg, v.status)
    time.sleep(0.3)
    assert [(c.visible, c.colour) for c in r.channels] == [(True, (1.0, 1.0, 1.0))] * 2
    assert r.time == 0.0 and not v.playing and v.speed == 4.0 and v.running
    # A flood of colours for one channel is one pending edit, its newest colour.
    for i in range(1000):
        v._on_message(v, {"type": "channel", "index": 0, "colour": [i / 999, 0.5, 0.25], "seq": 1}, [])
    assert len(v._pending._edits.get("channels", {})) <= 1
    before = v._last[1].copy()
    v._on_message(v, {"type": "channel", "index": 1, "visible": False}, [])
    v._on_message(v, {"type": "time", "time": 2.5, "seq": 2}, [])
    wait_for("the edits in the renderer", lambda: r.time == 2.5 and not r.channels[1].visible)
    assert r.channels[0].colour == pytest.approx((1.0, 0.5, 0.25))
    # The panel shows them, the frames carry the time, and the view changed.
    wait_for("the rows", lambda: [(c["visible"], c["colour"]) for c in v.channels] == [(True, pytest.approx([1.0, 0.5, 0.25])), (False, [1.0, 1.0, 1.0])])
    content, _ = frames_after(sent, v, len(sent.frames))
    assert content["time"] == 2.5 and content["seq"] >= 2
    assert np.abs(v._last[1] - before).mean() > 1e-3
    # A TF preset for the second channel from the page.
    v._on_message(v, {"type": "channel", "index": 1, "preset": "phantom-vessels"}, [])
    wait_for("the preset on channel 1", lambda: r.channels[1].tf.name == "phantom-vessels")
    assert r.channels[0].tf.name == "phantom-opaque"


def test_playback_moves_the_time_on_from_the_render_thread_and_loops(series_viewer):
    v, sent, _ = series_viewer
    r = v.renderer
    v._on_message(v, {"type": "play", "playing": True, "speed": 2.0}, [])
    assert v.playing and v.speed == 2.0
    # Sampled as it plays: it moves on by the wall clock (2 time points a second), a
    # little each frame, and loops after the last time point (3).
    seen, start = [r.time], time.monotonic()
    while time.monotonic() - start < 20 and not (len(seen) > 1 and seen[-1] < seen[-2]):
        seen.append(r.time)
        time.sleep(0.01)
    elapsed = time.monotonic() - start
    steps = np.diff(seen)
    assert (steps[:-1] > 0).sum() > 5 and (steps[:-1] >= 0).all(), "small steps forward, one per frame"
    assert (steps[:-1] <= 2.0 * 0.25 + 1e-6).all() and steps[-1] < -2.0, "then a loop back to the start"
    # About 2 time points a second of wall clock: less where a frame was slower than
    # the step's cap of a quarter second; more by up to one step, the first, which
    # counts from the frame before playback began (before the sampling did).
    moved = steps.sum() + 3.0
    assert 0.5 * 2.0 * elapsed < moved <= 2.0 * (elapsed + 0.25), (moved, elapsed)
    # A time from the page while playing: playback goes on from there.
    v.speed = 0.5
    v._on_message(v, {"type": "time", "time": 0.5}, [])
    wait_for("the page's time", lambda: 0.5 <= r.time < 1.0)
    # Paused: the time stays.
    v._on_message(v, {"type": "play", "playing": False}, [])
    n = r.frames_rendered
    wait_for("frames", lambda: r.frames_rendered > n + 2)
    paused = r.time
    wait_for("more frames", lambda: r.frames_rendered > n + 6)
    assert r.time == paused
    # A speed set from Python that the page could not ask for plays nothing (the render
    # thread goes on).
    v.speed, v.playing = float("nan"), True
    n = r.frames_rendered
    wait_for("frames", lambda: r.frames_rendered > n + 4)
    assert r.time == paused and v.running


def test_the_channels_panel_and_tf_editor_follow_the_renderer(series_viewer):
    v, sent, resent = series_viewer
    r = v.renderer
    # Edits from another cell show in the panel, and the time in the frames.
    r.channels[1].visible = False
    r.channels[0].colour = (0.2, 0.4, 0.6)
    r.time = 1.25
    wait_for("the cell's edits in the rows", lambda: [c["visible"] for c in v.channels] == [True, False] and v.channels[0]["colour"] == pytest.approx([0.2, 0.4, 0.6]))
    wait_for("the cell's time in a frame", lambda: frames_after(sent, v, len(sent.frames))[0]["time"] == 1.25)
    # A TF in data units on channel 0: the editor shows it over the channel's window
    # (0 to 1000 here), and says which channel it edits.
    r.channels[0].tf = "stat-zscore"
    zscore = [p["density"] for p in dvr.TransferFunction.preset("stat-zscore").points]
    lo, hi = r.channels[0].window
    wait_for("channel 0's TF in the editor", lambda: v.preset == "stat-zscore")
    assert v.tf_channel == 0 and [p["density"] for p in v.tf_points] == pytest.approx([(d - lo) / (hi - lo) for d in zscore])
    # Edited in the page (an opacity): it stays in data units, its densities as they
    # were, and the editor shows the same numbers again.
    shown = [dict(p) for p in v.tf_points]
    shown[0]["opacity"] = 0.5
    v._on_message(v, {"type": "channel", "index": 0, "tf": shown}, [])
    wait_for("the edit in the renderer", lambda: r.channels[0].tf.name == "edited")
    tf = r.channels[0].tf
    assert tf.units == "data" and [p["density"] for p in tf.points] == pytest.approx(zscore, abs=1e-3)
    assert tf.points[0]["opacity"] == pytest.approx(0.5)
    wait_for("the edited TF in the editor", lambda: v.preset == "" and v.tf_points[0]["opacity"] == pytest.approx(0.5))
    assert [p["density"] for p in v.tf_points] == [p["density"] for p in shown]
    # A TF the engine refuses: said, and the editor's points sent to the page again
    # (the page shows its refused edit; the kernel's trait never changed).
    resent.clear()
    v._on_message(v, {"type": "channel", "index": 0, "tf": [dict(shown[0], opacity=7.0), shown[-1]]}, [])
    wait_for("the refusal", lambda: "opacity" in v.status)
    wait_for("the editor's points sent again", lambda: "tf_points" in resent)
    # The page picks channel 1: the editor shows its TF; Python's tf_points and
    # preset go to the channel shown.
    v.channel = 1
    wait_for("channel 1's TF in the editor", lambda: v.tf_channel == 1 and v.preset == "phantom-opaque")
    v.preset = "phantom-vessels"
    wait_for("the preset on channel 1", lambda: r.channels[1].tf.name == "phantom-vessels")
    assert r.channels[0].tf.name == "edited"
    v.channel = 2
    assert "channel 2 refused" in v.status and v.channel == 1


def test_a_volume_of_one_field_shows_neither_panel(viewer):
    v, sent = viewer
    content, _ = frames_after(sent, v, 0)
    assert v.channels == [] and v.times == 1 and v.tf_channel == -1 and content["time"] is None
    v._on_message(v, {"type": "time", "time": 0.0}, [])
    assert "one time point" in v.status
    v._on_message(v, {"type": "channel", "index": 0, "visible": False}, [])
    assert "not a channel" in v.status and v.running


# Label maps: the labels panel and picking.



@pytest.fixture
def label_viewer(monkeypatch, tmp_path):
    """The phantom with its built-in labels (scalp, skull, brain, ventricles, vessels)
    shown as solid tissue."""
    sent, resent = Recorder(), []
    monkeypatch.setattr(dvr.Viewer, "send", lambda self, content, buffers=None: sent(content, buffers))
    monkeypatch.setattr(dvr.Viewer, "send_state", lambda self, key=None: resent.append(key))
    path = tmp_path / "labelled.toml"
    path.write_text(LABELLED_PHANTOM.format(mode="solid"))
    v = dvr.Viewer(dvr.Scene.load(path), size=(33, 33), denoisers=["ours"])
    yield v, sent, resent
    v.close()


def panel_rows(r):
    """The labels panel's rows as the renderer's label API reads them."""
    return [{"value": l.value, "name": l.name, "colour": list(l.colour), "opacity": l.opacity, "visible": l.visible} for l in r.labels]


def test_the_labels_panel_shows_the_renderers_labels_and_edits_them(label_viewer):
    v, sent, _ = label_viewer
    r = v.renderer
    assert v.label_mode == "solid"
    assert [(l["value"], l["name"]) for l in v.labels] == [(1, "scalp"), (2, "skull"), (3, "brain"), (4, "ventricles"), (5, "vessels")]
    assert v.labels == panel_rows(r)
    # Refused with a reason, and nothing reaches the renderer.
    for msg, reason in [
        ({"type": "label", "value": 9, "visible": False}, "not a label"),
        ({"type": "label", "value": 0, "visible": False}, "not a label"),
        ({"type": "label", "value": True, "visible": False}, "not a label"),
        ({"type": "label", "value": "2", "visible": False}, "not a label"),
        ({"type": "label", "value": 2, "visible": "no"}, "visible"),
        ({"type": "label", "value": 2, "colour": [1, 0, 2]}, "colour"),
        ({"type": "label", "value": 2, "colour": [float("nan"), 0, 0]}, "colour"),
        ({"type": "label", "value": 2, "opacity": 1.5}, "opacity"),
        ({"type": "label", "value": 2, "opacity": -0.1}, "opacity"),
        ({"type": "label", "value": 2, "name": "bone"}, "unknown field"),
        ({"type": "label", "value": 2}, "nothing to edit"),
        ({"type": "labels", "visible": 1}, "visible"),
        ({"type": "labels", "visible": True, "value": 2}, "visible"),
        ({"type": "pick", "x": 33, "y": 0}, "outside the 33x33 image"),
        ({"type": "pick", "x": -1, "y": 0}, "outside"),
        ({"type": "pick", "x": 1.5, "y": 0}, "whole numbers"),
        ({"type": "pick", "x": True, "y": 0}, "whole numbers"),
    ]:
        v._on_message(v, msg, [])
        assert reason in v.status, (msg, v.status)
    time.sleep(0.3)
    assert all(l.visible and l.opacity == 1.0 for l in r.labels) and v.picked == {}
    # Edits from the page, through the label API: a label hidden, a colour, an opacity
    # (a flood of opacities is one pending edit, the newest).
    for i in range(500):
        v._on_message(v, {"type": "label", "value": 3, "opacity": i / 499, "seq": 1}, [])
    assert len(v._pending._edits.get("labels", {})) <= 1
    before = v._last[1].copy()
    v._on_message(v, {"type": "label", "value": 2, "visible": False}, [])
    v._on_message(v, {"type": "label", "value": 3, "colour": [1.0, 0.0, 0.5], "opacity": 0.25}, [])
    wait_for("the edits in the renderer", lambda: not r.labels[2].visible and r.labels[3].opacity == 0.25)
    assert r.labels[3].colour == pytest.approx((1.0, 0.0, 0.5))
    wait_for("the rows", lambda: v.labels == panel_rows(r))
    assert [l["visible"] for l in v.labels] == [True, False, True, True, True]
    frames_after(sent, v, len(sent.frames))
    assert np.abs(v._last[1] - before).mean() > 1e-3, "the view changed"
    # Hide all, then one shown again, in one frame's edits: the order holds.
    v._on_message(v, {"type": "label", "value": 1, "visible": True}, [])
    v._on_message(v, {"type": "labels", "visible": False}, [])
    v._on_message(v, {"type": "label", "value": 4, "visible": True}, [])
    wait_for("only the ventricles shown", lambda: [l.visible for l in r.labels] == [False, False, False, True, False])
    v._on_message(v, {"type": "labels", "visible": True}, [])
    wait_for("all shown", lambda: all(l.visible for l in r.labels))
    wait_for("the rows", lambda: v.labels == panel_rows(r))
    assert v.running


def test_the_labels_panel_follows_edits_from_another_cell(label_viewer):
    v, _, _ = label_viewer
    r = v.renderer
    r.labels.hide_all()
    r.labels[5].visible = True
    r.labels[5].colour = (0.1, 0.2, 0.3)
    wait_for("the cell's edits in the rows", lambda: [l["visible"] for l in v.labels] == [False] * 4 + [True])
    wait_for("the colour", lambda: v.labels[4]["colour"] == pytest.approx([0.1, 0.2, 0.3]))


def test_a_click_picks_the_label_and_intensity_under_it(label_viewer):
    v, _, _ = label_viewer
    r = v.renderer
    # A front view of the phantom with only the skull shown: the image's centre is skull.
    v._on_message(v, {"type": "view", "side": "anterior"}, [])
    v._on_message(v, {"type": "labels", "visible": False}, [])
    v._on_message(v, {"type": "label", "value": 2, "visible": True}, [])
    wait_for("only the skull shown", lambda: [l.visible for l in r.labels] == [False, True, False, False, False])
    v._on_message(v, {"type": "pick", "x": 16, "y": 16, "seq": 7}, [])
    wait_for("the pick", lambda: v.picked)
    p = v.picked
    assert p["hit"] and (p["x"], p["y"], p["seq"]) == (16, 16, 7)
    assert (p["label"], p["label_name"]) == (2, "skull"), p
    assert p["intensity"] is not None and p["intensity"] > 0 and len(p["voxel"]) == 3
    # What the renderer's own pick says at the same pixel of the same view.
    assert r.pick(16, 16)["label"] == 2
    # The brain alone: the centre is brain, its intensity another.
    v._on_message(v, {"type": "labels", "visible": False}, [])
    v._on_message(v, {"type": "label", "value": 3, "visible": True}, [])
    v._on_message(v, {"type": "pick", "x": 16, "y": 16, "seq": 8}, [])
    wait_for("the second pick", lambda: v.picked.get("seq") == 8)
    assert (v.picked["label"], v.picked["label_name"]) == (3, "brain"), v.picked
    # A corner ray meets nothing.
    v._on_message(v, {"type": "pick", "x": 0, "y": 0, "seq": 9}, [])
    wait_for("the corner's pick", lambda: v.picked.get("seq") == 9)
    assert v.picked == {"x": 0, "y": 0, "seq": 9, "hit": False}


def test_a_renderer_without_labels_has_no_labels_panel(viewer):
    v, _ = viewer
    assert v.labels == [] and v.label_mode == ""
    v._on_message(v, {"type": "label", "value": 1, "visible": False}, [])
    assert "not a label" in v.status
    v._on_message(v, {"type": "labels", "visible": False}, [])
    assert "no label map" in v.status
    # A pick still says the intensity there, with no label.
    v._on_message(v, {"type": "pick", "x": 8, "y": 8, "seq": 1}, [])
    wait_for("the pick", lambda: v.picked)
    assert v.picked["hit"] is False or (v.picked["label"] == 0 and v.picked["label_name"] is None), v.picked
    assert v.running

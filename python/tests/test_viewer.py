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
    assert viewer_module._tf_points("no") is None
    # The half-made widgets' finalisers (close) run without an error of their own.
    gc.collect()

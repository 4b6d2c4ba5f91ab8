"""dvr.Viewer in a real JupyterLab, driven by headless Chromium: frames stream into the
cell, a drag moves the camera and reset brings it back, the TF editor follows a TF set
from another cell and a preset picked in the page, a point added to a preset reaches the
kernel with the preset's points intact, the raw input shows in the split view, a clip
plane is added from the cuts panel, a screenshot and a movie are written, an interrupted
kernel stops the render loop, and a closed viewer leaves no thread and no renderer and
its last frame in the saved notebook; a series' channels panel and time slider edit
the view; a label map's panel edits its labels, and a click picks the label under it.
The example notebooks run through nbclient."""

import base64
import json
import pathlib
import re
import time

import nbformat
import numpy as np
import pytest
from nbclient import NotebookClient

from conftest import LABELLED_PHANTOM
from lab import Notebook, decode_png, ffprobe_frames, image_stats, write_notebook

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def wait_for(what, predicate, timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.2)
    raise TimeoutError(f"waited {timeout} s for {what}")


def shown_after(page, frame):
    """The viewer's image stats once it shows a frame after `frame`."""
    return wait_for(
        f"a frame after {frame}",
        lambda: (s := image_stats(page, ".dvr-frame")) and s[0] > frame and s,
    )


def numbers(text):
    return [float(x) for x in re.findall(r"-?\d+\.\d*(?:e-?\d+)?", text)]


def difference(a, b):
    return sum(abs(x - y) for x, y in zip(a[4], b[4])) / len(a[4])


def test_the_viewer_streams_takes_edits_and_stops(lab, browser):
    write_notebook(
        lab.root / "viewer.ipynb",
        [
            "import dvr, gc, json, threading, weakref\n"
            "v = dvr.Viewer('phantom/orbit', size=(48, 48), denoisers=['ours'])\n"
            "renderer = weakref.ref(v.renderer)\n"
            "v",
            "print('camera', v.renderer.camera.position)",
            "print('state', v.renderer.tf.name, v.renderer.denoisers, v.running)",
            "v.close()\ngc.collect()\n"
            "print('threads', [t.name for t in threading.enumerate() if t.name == 'dvr-viewer'], 'renderer', renderer())",
            "print('tf', json.dumps([dict(p) for p in v.renderer.tf.points]))",
            "v.renderer.tf = 'phantom-vessels'",
            "print('clip', json.dumps(v.renderer.clip.to_list()))",
            "print('spp', v.renderer.spp)",
        ],
    )
    page = browser.new_page(viewport={"width": 1400, "height": 1200})
    nb = Notebook(page, lab, "viewer.ipynb")
    nb.run(0)
    # The image appears and the frame counter grows.
    first = wait_for("the first frame", lambda: image_stats(page, ".dvr-frame"))
    later = shown_after(page, first[0] + 2)
    counter = int(page.locator(".dvr-frame-counter").inner_text())
    assert counter >= later[0] > first[0]
    # The spp box shows the device's limit and holds only what the renderer takes.
    limit = page.locator(".dvr-spp").get_attribute("max")
    assert limit == page.locator(".dvr-spp-range").inner_text().strip("()").split("–")[1]
    page.fill(".dvr-spp", "99")
    page.locator(".dvr-spp").blur()  # the box's change event: its value committed
    wait_for("the box clamped to the limit", lambda: page.locator(".dvr-spp").input_value() == limit)
    assert "99" in page.locator(".dvr-status").inner_text()
    wait_for("the limit's spp in the kernel", lambda: nb.run(7).strip() == f"spp {limit}")

    # A left drag orbits the camera (the kernel's camera moves), and the page says how
    # many frames the drag took to show.
    before = nb.run(1)
    page.locator(".dvr-stage").scroll_into_view_if_needed()  # running a cell scrolls
    box = page.locator(".dvr-stage").bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 80, y + 10, steps=8)
    page.mouse.up()
    latency = page.locator(".dvr-latency")
    wait_for("the drag's latency", lambda: latency.get_attribute("data-frames") is not None)
    after = nb.run(1)
    assert before != after and after.startswith("camera"), (before, after)
    assert float(latency.get_attribute("data-ms")) > 0, latency.inner_text()
    # Reset puts the camera back where it started.
    page.click(".dvr-reset")
    wait_for("the camera reset", lambda: numbers(nb.run(1)) == pytest.approx(numbers(before), abs=1e-9))

    # A TF set from another cell shows in the editor and the dropdown.
    nb.run(5)
    vessels = dvr_tf("phantom-vessels")
    wait_for("the other cell's TF in the editor", lambda: page.locator(".dvr-tf .dvr-point").count() == len(vessels))
    assert page.locator(".dvr-preset").input_value() == "phantom-vessels"

    # A TF preset shows in the next frames.
    still = shown_after(page, int(page.locator(".dvr-frame-counter").inner_text()))
    page.select_option(".dvr-preset", "phantom-opaque")
    wait_for("the preset in the kernel", lambda: "phantom-opaque" in nb.run(2))
    changed = shown_after(page, int(page.locator(".dvr-frame-counter").inner_text()) + 1)
    assert difference(still, changed) > 5.0, difference(still, changed)
    # The editor shows the preset; a double-click adds a point to it: the kernel's TF
    # is the preset (every field of every point) plus that point.
    opaque = dvr_tf("phantom-opaque")
    wait_for("the preset in the editor", lambda: page.locator(".dvr-tf .dvr-point").count() == len(opaque))
    # (Running cells scrolls the notebook: the editor is brought into view first.)
    page.locator(".dvr-tf").scroll_into_view_if_needed()
    plot = page.locator(".dvr-tf .dvr-plot").bounding_box()
    page.mouse.dblclick(plot["x"] + 0.78 * plot["width"], plot["y"] + 0.4 * plot["height"])
    wait_for("the edited TF in the kernel", lambda: "edited" in nb.run(2))
    points = json.loads(nb.run(4).split("tf ", 1)[1])
    added = [p for p in points if p not in opaque]
    assert len(points) == len(opaque) + 1 and len(added) == 1, points
    assert abs(added[0]["density"] - 0.78) < 0.02 and abs(added[0]["opacity"] - 0.6) < 0.03, added
    # It took the colour, specular and roughness of its nearest neighbour (0.86).
    near = next(p for p in opaque if p["density"] == 0.86)
    assert {k: v for k, v in added[0].items() if k not in ("density", "opacity")} == {k: v for k, v in near.items() if k not in ("density", "opacity")}
    wait_for("the dropdown saying edited", lambda: page.locator(".dvr-preset").input_value() == "")

    # The split view shows the denoiser beside the raw path-traced input, labelled.
    page.select_option(".dvr-split", "noisy")
    wait_for("two labels", lambda: page.locator(".dvr-labels span").count() == 2)
    assert page.locator(".dvr-labels span").all_inner_texts() == ["ours", "noisy"]
    assert "('ours',)" in nb.run(2)
    # The orientation letters and the scale bar are drawn (each frame message carries
    # them; the page draws them as it shows the frame).
    letters = wait_for("the orientation letters",
                       lambda: [t for t in page.locator(".dvr-orient").all_inner_texts() if t])
    assert len(letters) == 4 and all(t in "RLAPSI" for t in letters), letters
    wait_for("the scale bar", lambda: float(page.locator(".dvr-scale").get_attribute("data-mm") or 0) > 0)

    # The cuts panel adds a clip plane in the kernel.
    page.click(".dvr-cuts summary")
    page.click(".dvr-add-clip")
    wait_for("the clip plane in the kernel", lambda: json.loads(nb.run(6).split("clip ", 1)[1]))

    # Screenshot: a PNG of the shown frame at the render size; movie: an MP4 of an orbit.
    page.click(".dvr-screenshot")
    shot = page.locator(".dvr-capture-screenshot")
    shot.wait_for(timeout=60_000)
    png = pathlib.Path(shot.get_attribute("data-path"))
    assert decode_png(png.read_bytes())[:2] == (48, 48)
    # The download link holds the file's bytes.
    href = shot.locator("a[download]").get_attribute("href", timeout=30_000)
    assert page.evaluate("async (u) => (await (await fetch(u)).arrayBuffer()).byteLength", href) == png.stat().st_size
    page.click(".dvr-movie")
    movie = page.locator(".dvr-capture-movie")
    movie.wait_for(timeout=300_000)
    mp4 = pathlib.Path(movie.get_attribute("data-path"))
    assert mp4.stat().st_size > 0
    frames, w, h = ffprobe_frames(mp4)
    assert frames > 1 and (w, h) == (48, 48), (frames, w, h)

    # An interrupted kernel stops the render loop.
    page.locator(".jp-Notebook").click()
    page.keyboard.press("Escape")
    page.keyboard.press("i")
    page.keyboard.press("i")
    wait_for("the loop to stop", lambda: nb.run(2).strip().endswith("False"))

    # Closed: no render thread, the renderer freed; the cell keeps the last frame as an
    # image, in the page and in the saved notebook.
    out = nb.run(3)
    assert re.search(r"threads \[\] renderer None", out), out
    nb.cell(0).locator(".jp-OutputArea img").wait_for(timeout=30_000)
    page.keyboard.press("Control+s")

    def saved_image():
        cell = json.loads((lab.root / "viewer.ipynb").read_text())["cells"][0]
        return next((o["data"]["image/png"] for o in cell["outputs"] if "image/png" in o.get("data", {})), None)

    image = wait_for("the last frame in the saved notebook", saved_image)
    assert decode_png(base64.b64decode(image))[:2] == (48, 48)
    page.close()


def test_the_channels_panel_and_the_time_slider(lab, browser, series_file):
    """A series of 2 channels × 4 time points: a channel switched off, a channel's
    colour and TF edited and the time scrubbed and played from the page, each changing
    the view; edits from another cell shown in the panel; no error in the page or the
    status line. (The same server as the test above: one JupyterLab per session.)"""
    write_notebook(
        lab.root / "channels.ipynb",
        [
            "import dvr, json\n"
            f"v = dvr.Viewer(dvr.Scene({str(series_file)!r}, tf='phantom-opaque'), size=(48, 48), denoisers=['ours'])\n"
            "v",
            "r = v.renderer\n"
            "print('state', json.dumps({'visible': [c.visible for c in r.channels], 'colour': [c.colour for c in r.channels],"
            " 'tf': [c.tf.name for c in r.channels], 'time': r.time, 'playing': v.playing, 'status': v.status}))",
            "v.renderer.channels[0].colour = (1.0, 0.2, 0.2)\nv.renderer.time = 2.0",
            "v.close()",
        ],
    )
    page = browser.new_page(viewport={"width": 1400, "height": 1200})
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    nb = Notebook(page, lab, "channels.ipynb")
    nb.run(0)

    def state():
        return json.loads(nb.run(1).split("state ", 1)[1])

    def frame():
        return int(page.locator(".dvr-frame-counter").inner_text())

    first = wait_for("the first frame", lambda: image_stats(page, ".dvr-frame"))
    rows = page.locator(".dvr-channel")
    assert page.locator(".dvr-channel-name").all_inner_texts() == ["core", "shell"]
    assert page.locator(".dvr-time").get_attribute("max") == "3"
    page.locator(".dvr-channels").scroll_into_view_if_needed()

    # The shell switched off: the ball inside shows, and the view changes.
    before = shown_after(page, max(first[0], frame()))
    rows.nth(1).locator(".dvr-channel-visible").uncheck()
    wait_for("the shell hidden in the kernel", lambda: state()["visible"] == [True, False])
    hidden = shown_after(page, frame() + 1)
    assert difference(before, hidden) > 5.0, difference(before, hidden)

    # The ball's colour picked: red in the kernel and in the view.
    rows.nth(0).locator(".dvr-channel-colour").fill("#ff0000")
    wait_for("the colour in the kernel", lambda: state()["colour"][0] == [1.0, 0.0, 0.0])
    red = shown_after(page, frame() + 1)
    assert (red[1] - red[3]) - (hidden[1] - hidden[3]) > 5.0, (hidden[:4], red[:4])  # redder than blue

    # The editor edits the ball's TF: a preset picked for it reaches channel 0 only.
    assert rows.nth(0).locator(".dvr-channel-tf").is_checked()
    page.select_option(".dvr-preset", "phantom-vessels")
    wait_for("the ball's new TF", lambda: state()["tf"] == ["phantom-vessels", "phantom-opaque"])
    assert page.locator(".dvr-tf .dvr-point").count() == len(dvr_tf("phantom-vessels"))
    # Channel 1 picked in the panel: the editor shows its TF.
    rows.nth(1).locator(".dvr-channel-tf").check()
    wait_for("channel 1's TF in the editor", lambda: page.locator(".dvr-preset").input_value() == "phantom-opaque")
    assert page.locator(".dvr-tf .dvr-point").count() == len(dvr_tf("phantom-opaque"))

    # The time slider scrubbed (a click at 80% of it): the kernel's time and the view.
    rows.nth(1).locator(".dvr-channel-visible").check()
    wait_for("the shell back", lambda: state()["visible"] == [True, True])
    still = shown_after(page, frame() + 1)
    page.locator(".dvr-time").scroll_into_view_if_needed()
    box = page.locator(".dvr-time").bounding_box()
    page.mouse.click(box["x"] + 0.8 * box["width"], box["y"] + box["height"] / 2)
    t = wait_for("the scrubbed time in the kernel", lambda: (t := state()["time"]) > 1.5 and t)
    assert 2.0 < t < 2.9, t
    later = shown_after(page, frame() + 1)
    assert difference(still, later) > 2.0, difference(still, later)
    # Played: the slider moves with the frames; paused, it stays.
    page.click(".dvr-play")
    wait_for("playing", lambda: state()["playing"])
    shown_time = lambda: float(page.locator(".dvr-time").input_value())  # noqa: E731
    start = shown_time()
    wait_for("the slider following playback", lambda: shown_time() != start)
    page.click(".dvr-play")
    wait_for("paused", lambda: not state()["playing"])

    # Edits from another cell: the panel shows them.
    nb.run(2)
    wait_for("the cell's colour in the panel", lambda: rows.nth(0).locator(".dvr-channel-colour").input_value() == "#ff3333")
    wait_for("the cell's time on the slider", lambda: shown_time() == 2.0)
    assert page.locator(".dvr-time-value").inner_text().startswith("2.00")

    # No error anywhere.
    assert state()["status"] == "" and page.locator(".dvr-status").inner_text() == "", page.locator(".dvr-status").inner_text()
    assert errors == []
    nb.run(3)
    page.close()




def test_the_labels_panel_and_picking(lab, browser):
    """The phantom with its built-in labels as solid tissue, on a page drawn at twice
    the CSS pixel density: a label hidden, a colour picked, the list searched, hide all
    and one shown again from the panel, each reaching the kernel's renderer; a click in
    the image picks the label under it (the page pixel mapped to the rendered pixel), a
    drag still orbits without picking. (The same server as the tests above.)"""
    (lab.root / "labelled.toml").write_text(LABELLED_PHANTOM.format(mode="solid"))
    write_notebook(
        lab.root / "labels.ipynb",
        [
            "import dvr, json\n"
            "v = dvr.Viewer(dvr.Scene.load('labelled.toml'), size=(33, 33), denoisers=['ours'])\n"
            "v",
            "r = v.renderer\n"
            "print('state', json.dumps({'visible': [l.visible for l in r.labels], 'colour': [l.colour for l in r.labels],"
            " 'picked': v.picked, 'camera': r.camera.position, 'status': v.status}))",
            "v.close()",
        ],
    )
    page = browser.new_page(viewport={"width": 1400, "height": 1200}, device_scale_factor=2)
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    nb = Notebook(page, lab, "labels.ipynb")
    nb.run(0)

    def state():
        return json.loads(nb.run(1).split("state ", 1)[1])

    def frame():
        return int(page.locator(".dvr-frame-counter").inner_text())

    first = wait_for("the first frame", lambda: image_stats(page, ".dvr-frame"))
    rows = page.locator(".dvr-label")
    assert page.locator(".dvr-label-name").all_inner_texts() == ["1 scalp", "2 skull", "3 brain", "4 ventricles", "5 vessels"]
    page.locator(".dvr-labels-panel").scroll_into_view_if_needed()

    # The scalp hidden: the skull shows, the view changes by more than twice what two
    # frames of the still view differ by (the scalp is a ring of edge pixels at 33²),
    # measured once ours has had 30 frames to settle.
    before = shown_after(page, max(first[0], frame(), 30))
    floor = difference(before, shown_after(page, before[0] + 8))
    rows.nth(0).locator(".dvr-label-visible").uncheck()
    wait_for("the scalp hidden in the kernel", lambda: state()["visible"] == [False, True, True, True, True])
    hidden = shown_after(page, frame() + 1)
    assert difference(before, hidden) > 2 * floor, (difference(before, hidden), floor)
    # The skull's colour picked: in the kernel and in the view.
    rows.nth(1).locator(".dvr-label-colour").fill("#ff0000")
    wait_for("the colour in the kernel", lambda: state()["colour"][1] == [1.0, 0.0, 0.0])
    red = shown_after(page, frame() + 1)
    assert (red[1] - red[3]) - (hidden[1] - hidden[3]) > 5.0, (hidden[:4], red[:4])
    # The search filters the rows (in the page only).
    page.fill(".dvr-label-search", "VENT")
    assert [rows.nth(i).is_visible() for i in range(5)] == [False, False, False, True, False]
    page.fill(".dvr-label-search", "")
    # Hide all, then the skull shown again.
    page.click(".dvr-labels-hide")
    wait_for("all hidden in the kernel", lambda: state()["visible"] == [False] * 5)
    rows.nth(1).locator(".dvr-label-visible").check()
    wait_for("the skull alone in the kernel", lambda: state()["visible"] == [False, True, False, False, False])

    # A click in the image, from the front: the pixel under the cursor is picked.
    page.click(".dvr-view-anterior")
    shown_after(page, frame() + 2)

    def at(px, py):
        """Where the centre of rendered pixel (px, py) is on the page (running a cell
        scrolls the notebook: the image is brought into view and measured again)."""
        page.locator(".dvr-stage").scroll_into_view_if_needed()
        box = page.locator(".dvr-frame").bounding_box()
        return box["x"] + (px + 0.5) / 33 * box["width"], box["y"] + (py + 0.5) / 33 * box["height"]

    page.mouse.click(*at(20, 12))
    wait_for("the off-centre pick in the kernel", lambda: (p := state()["picked"]) and (p["x"], p["y"]) == (20, 12))
    page.mouse.click(*at(16, 16))
    picked = wait_for("the centre's pick", lambda: (p := state()["picked"]) and (p["x"], p["y"]) == (16, 16) and p)
    assert (picked["label"], picked["label_name"]) == (2, "skull"), picked
    readout = page.locator(".dvr-pick")
    wait_for("the readout", lambda: "skull" in readout.inner_text())
    assert readout.get_attribute("data-label") == "2" and "intensity" in readout.inner_text()
    # A drag orbits and picks nothing.
    camera = state()["camera"]
    x, y = at(16, 16)
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 60, y, steps=6)
    page.mouse.up()
    wait_for("the orbit", lambda: state()["camera"] != camera)
    assert state()["picked"] == picked

    assert state()["status"] == "" and page.locator(".dvr-status").inner_text() == "", page.locator(".dvr-status").inner_text()
    assert errors == []
    nb.run(2)
    page.close()


def dvr_tf(name):
    """A preset's points as the kernel prints them (plain dicts)."""
    import dvr

    return [dict(p) for p in dvr.TransferFunction.preset(name).points]


def test_the_example_notebooks_run():
    """Every example notebook runs from top to bottom: each code cell executed in order,
    none with an error, each that prints printing; and live.ipynb's results are what it
    says they are (scores in dB, the renderer moved, the viewer rendered frames while it
    was open, and its cell kept the last frame once it was closed)."""
    notebooks = sorted(EXAMPLES.glob("*.ipynb"))
    assert [p.name for p in notebooks] == ["live.ipynb"], f"examples changed: {notebooks}; check each here"
    for path in notebooks:
        nb = nbformat.read(path, as_version=4)
        NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}).execute()
        code = [c for c in nb.cells if c.cell_type == "code"]
        assert [c.execution_count for c in code] == list(range(1, len(code) + 1)), path.name
        for c in code:
            assert not [o for o in c.outputs if o.output_type == "error"], (path.name, c.source)
            if "print(" in c.source:
                assert any(o.output_type == "stream" and o.text.strip() for o in c.outputs), (path.name, c.source)
        text = ["".join(o.text for o in c.outputs if o.output_type == "stream") for c in code]
        scores = re.fullmatch(r"ours (\d+\.\d) dB, svgf (\d+\.\d) dB after 8 frames\s*", text[0])
        assert scores and all(10 < float(x) < 80 for x in scores.groups()), text[0]
        # The 40-pixel orbit moved the camera from the scene's, at the same distance.
        import dvr

        start = np.array(dvr.Scene.builtin("phantom/orbit").camera.position)
        moved = np.array(numbers(text[1].split("position=", 1)[1])[:3])
        assert np.linalg.norm(moved - start) > 0.1 and np.linalg.norm(moved) == pytest.approx(np.linalg.norm(start)), text[1]
        frames = re.search(r"(\d+) frames rendered", text[3])
        assert frames and int(frames.group(1)) > 9, text[3]  # 9: the cells before the viewer's
        # The viewer's cell: the widget, replaced by its last frame when it closed.
        assert any("image/png" in o.get("data", {}) for o in code[2].outputs), code[2].outputs

"""dvr.Viewer in a real JupyterLab, driven by headless Chromium: frames stream into the
cell, a drag moves the camera, a TF preset and a split view show, an interrupted kernel
stops the render loop, and a closed viewer leaves no thread and no renderer. The example
notebooks run through nbclient."""

import pathlib
import re
import time

import nbformat
from nbclient import NotebookClient

from lab import Notebook, image_stats, write_notebook

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


def difference(a, b):
    return sum(abs(x - y) for x, y in zip(a[4], b[4])) / len(a[4])


def test_the_viewer_streams_takes_edits_and_stops(lab, browser):
    write_notebook(
        lab.root / "viewer.ipynb",
        [
            "import dvr, gc, threading, weakref\n"
            "v = dvr.Viewer('phantom/orbit', size=(48, 48), denoisers=['ours'])\n"
            "renderer = weakref.ref(v.renderer)\n"
            "v",
            "print('camera', v.renderer.camera.position)",
            "print('state', v.renderer.tf.name, v.renderer.denoisers, v.running)",
            "v.close()\ngc.collect()\n"
            "print('threads', [t.name for t in threading.enumerate() if t.name == 'dvr-viewer'], 'renderer', renderer())",
        ],
    )
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    nb = Notebook(page, lab, "viewer.ipynb")
    nb.run(0)
    # The image appears and the frame counter grows.
    first = wait_for("the first frame", lambda: image_stats(page, ".dvr-frame"))
    later = shown_after(page, first[0] + 2)
    counter = int(page.locator(".dvr-frame-counter").inner_text())
    assert counter >= later[0] > first[0]

    # A left drag orbits the camera (the kernel's camera moves), and the page says how
    # many frames the drag took to show.
    before = nb.run(1)
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

    # A TF preset shows in the next frames.
    still = shown_after(page, int(page.locator(".dvr-frame-counter").inner_text()))
    page.select_option(".dvr-preset", "phantom-opaque")
    wait_for("the preset in the kernel", lambda: "phantom-opaque" in nb.run(2))
    changed = shown_after(page, int(page.locator(".dvr-frame-counter").inner_text()) + 1)
    assert difference(still, changed) > 5.0, difference(still, changed)

    # The split view shows two methods, labelled.
    page.select_option(".dvr-split", "svgf")
    wait_for("two labels", lambda: page.locator(".dvr-labels span").count() == 2)
    assert page.locator(".dvr-labels span").all_inner_texts() == ["ours", "svgf"]
    assert "('ours', 'svgf')" in nb.run(2)

    # An interrupted kernel stops the render loop.
    page.locator(".jp-Notebook").click()
    page.keyboard.press("Escape")
    page.keyboard.press("i")
    page.keyboard.press("i")
    wait_for("the loop to stop", lambda: nb.run(2).strip().endswith("False"))

    # Closed: no render thread, the renderer freed.
    out = nb.run(3)
    assert re.search(r"threads \[\] renderer None", out), out
    page.close()


def test_the_example_notebooks_run():
    notebooks = sorted(EXAMPLES.glob("*.ipynb"))
    assert notebooks, f"no notebooks in {EXAMPLES}"
    for path in notebooks:
        nb = nbformat.read(path, as_version=4)
        NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}).execute()

"""A real JupyterLab server on loopback, driven by Debian's Chromium through Playwright:
what the notebook tests and ``tools/viewer_bench.py`` share. Nothing is downloaded (the
browser is the system's; JupyterLab serves its own files)."""

import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Lab:
    """``jupyter lab`` serving ``root`` on 127.0.0.1 with a token of its own; the kernel
    is this Python (the one dvr is installed in)."""

    def __init__(self, root, log_path):
        self.root, self.port, self.token = root, free_port(), secrets.token_hex(16)
        self.log = open(log_path, "w")
        env = dict(os.environ, JUPYTER_PLATFORM_DIRS="1")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "jupyterlab", "--allow-root", "--no-browser", "--ip=127.0.0.1",
             f"--port={self.port}", f"--IdentityProvider.token={self.token}",
             f"--ServerApp.root_dir={root}", "--ServerApp.open_browser=False",
             "--LabApp.news_url=", "--LabServerApp.announcements_url="],
            stdout=self.log, stderr=subprocess.STDOUT, env=env, start_new_session=True,
        )
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"jupyter lab exited with {self.proc.returncode}; see {log_path}")
            try:
                urllib.request.urlopen(self.api("status"), timeout=2).read()
                return
            except OSError:
                time.sleep(0.5)
        self.stop()
        raise RuntimeError(f"jupyter lab did not answer on port {self.port}; see {log_path}")

    def api(self, path):
        return f"http://127.0.0.1:{self.port}/api/{path}?token={self.token}"

    def url(self, notebook):
        # `reset`: a fresh workspace, so the notebooks an earlier page opened are not
        # restored beside this one.
        return f"http://127.0.0.1:{self.port}/lab/tree/{notebook}?reset&token={self.token}"

    def kernels(self):
        """The server's running kernels. jupyter_server lists a kernel it is still
        launching before that kernel has a `last_activity`, and answers the listing with a
        500 (a TraitError: `last_activity` is None) until it has one: that answer is
        retried for 10 s."""
        deadline = time.monotonic() + 10
        while True:
            try:
                return json.loads(urllib.request.urlopen(self.api("kernels"), timeout=5).read())
            except urllib.error.HTTPError as e:
                if e.code != 500 or time.monotonic() > deadline:
                    raise RuntimeError(f"GET /api/kernels answered {e.code}; see {self.log.name}") from e
                time.sleep(0.1)

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.log.close()


def write_notebook(path, cells):
    """A notebook of code cells (sources as strings)."""
    nb = {
        "cells": [
            {"cell_type": "code", "execution_count": None, "id": f"c{i}", "metadata": {}, "outputs": [], "source": src}
            for i, src in enumerate(cells)
        ],
        "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}},
        "nbformat": 4,
        "nbformat_minor": 5,
    }
    path.write_text(json.dumps(nb))


class Notebook:
    """A notebook open in the browser: run its cells one by one, read their output."""

    def __init__(self, page, lab, name):
        self.page = page
        page.goto(lab.url(name))
        page.wait_for_selector(".jp-Notebook", timeout=120_000)
        # The kernel takes cells once the page's websocket is connected to it and it
        # is idle (the page's own indicator says idle earlier than that).
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            ready = [k for k in lab.kernels() if k.get("connections", 0) > 0 and k.get("execution_state") == "idle"]
            if ready:
                break
            time.sleep(0.25)
        else:
            raise TimeoutError("the notebook's kernel did not become ready in 120 s")
        page.wait_for_selector(".jp-Notebook-ExecutionIndicator[data-status='idle']", timeout=120_000)

    def cell(self, i):
        return self.page.locator(".jp-Notebook .jp-Cell").nth(i)

    def run(self, i, timeout=120):
        """Runs cell i (Shift+Enter) and waits until it has finished; returns its
        output's text. The key goes to the cell once its editor has focus; a press
        the page did not take (JupyterLab still settling) is repeated."""
        cell = self.cell(i)
        prompt = cell.locator(".jp-InputArea-prompt")
        before = prompt.inner_text().strip()
        deadline = time.monotonic() + timeout
        started = False
        while not started and time.monotonic() < deadline:
            cell.locator(".jp-InputArea-editor").click()
            self.page.keyboard.press("Shift+Enter")
            retry = time.monotonic() + 5
            while time.monotonic() < retry:
                text = prompt.inner_text().strip()
                if text != before or "*" in text:
                    started = True
                    break
                time.sleep(0.1)
        while time.monotonic() < deadline:
            text = prompt.inner_text().strip()
            if started and "*" not in text and text not in ("[ ]:", before):
                return self.output(i)
            time.sleep(0.2)
        raise TimeoutError(f"cell {i} did not finish in {timeout} s (prompt {prompt.inner_text()!r})")

    def output(self, i):
        return self.cell(i).locator(".jp-OutputArea").inner_text()


def image_stats(page, selector):
    """(frame number, mean R, G, B) of the image the viewer shows, read from the
    decoded image in the page."""
    return page.evaluate(
        """(sel) => {
            const img = document.querySelector(sel);
            if (!img || !img.complete || !img.naturalWidth) return null;
            const c = document.createElement('canvas');
            c.width = img.naturalWidth; c.height = img.naturalHeight;
            const g = c.getContext('2d');
            g.drawImage(img, 0, 0);
            const d = g.getImageData(0, 0, c.width, c.height).data;
            const m = [0, 0, 0];
            for (let i = 0; i < d.length; i += 4) { m[0] += d[i]; m[1] += d[i + 1]; m[2] += d[i + 2]; }
            const n = d.length / 4;
            return [parseInt(img.dataset.frame || '0', 10), m[0] / n, m[1] / n, m[2] / n,
                    Array.from(d.filter((_, i) => i % 4 === 0))];
        }""",
        selector,
    )


def decode_png(data):
    """(width, height, rows) of an 8-bit RGB or RGBA PNG, decoded with the standard
    library only (chunk CRCs checked, IDAT inflated, every row's filter undone), so a
    test sees the pixels a viewer would, not just a header."""
    import struct
    import zlib

    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG (signature)")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if zlib.crc32(kind + body) != struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]:
            raise ValueError(f"bad CRC in chunk {kind!r}")
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
        pos += 12 + n
    w, h, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"unsupported PNG: depth {depth}, colour type {colour}, interlace {interlace}")
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(idat), w * bpp
    if len(raw) != h * (stride + 1):
        raise ValueError(f"PNG data is {len(raw)} bytes, {w}x{h} needs {h * (stride + 1)}")
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            elif f != 0:
                raise ValueError(f"bad PNG filter {f}")
        rows.append(bytes(line))
        prev = line
    return w, h, rows


def ffprobe_frames(path):
    """The number of video frames ffprobe counts in `path` (decoding them all)."""
    out = subprocess.run(
        ["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
         "-show_entries", "stream=nb_read_frames,width,height", "-of", "json", str(path)],
        capture_output=True, text=True, check=True,
    )
    stream = json.loads(out.stdout)["streams"][0]
    return int(stream["nb_read_frames"]), int(stream["width"]), int(stream["height"])

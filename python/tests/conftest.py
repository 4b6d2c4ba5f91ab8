"""Shared fixtures: the repository's paths, the CLI binary the package is compared with
(``DVR_BIN``, else the workspace's debug or release build), a small series of channels
and time points, and the notebook tests' JupyterLab and browser."""

import os
import pathlib
import shutil

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The phantom at 48³ with its own segmentation (scalp, skull, brain, ventricles,
# vessels): the label tests' scene, in `mode` ("tint" or "solid").
LABELLED_PHANTOM = """
name = "labelled"
[volume]
builtin = "phantom"
size = 48
[transfer]
a = "ct-bone"
[labels]
builtin = "phantom"
mode = "{mode}"
[[light]]
kind = "environment"
intensity = 1.0
"""


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def dvr_bin():
    for candidate in (os.environ.get("DVR_BIN"), ROOT / "target/debug/dvr", ROOT / "target/release/dvr", shutil.which("dvr")):
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    pytest.fail("no dvr binary: build it (cargo build) or set DVR_BIN")


@pytest.fixture(scope="session")
def series_file(tmp_path_factory):
    """A small series as an OME-TIFF written by tifffile: 2 channels ("core", a ball;
    "shell", a shell around it that grows) × 4 time points, 16³ voxels."""
    tifffile = pytest.importorskip("tifffile")
    n = 16
    z, y, x = np.mgrid[:n, :n, :n] / (n - 1) - 0.5
    r = np.sqrt(x**2 + y**2 + z**2)
    data = np.zeros((4, 2, n, n, n), np.uint16)
    for t in range(4):
        data[t, 0] = (r < 0.2) * 1000
        data[t, 1] = (np.abs(r - (0.25 + 0.05 * t)) < 0.05) * 1000
    path = tmp_path_factory.mktemp("series") / "series.ome.tif"
    tifffile.imwrite(path, data, ome=True, metadata={"axes": "TCZYX", "Channel": {"Name": ["core", "shell"]}})
    return path


@pytest.fixture(autouse=True)
def no_validation_messages():
    """With DVR_VALIDATION=1 (as tools/test.sh runs), any message from the Vulkan
    validation layer fails the test that caused it."""
    import dvr

    before = dvr._native.validation_messages()
    yield
    after = dvr._native.validation_messages()
    assert after == before, f"the Vulkan validation layer reported {after - before} message(s)"


@pytest.fixture(scope="session")
def lab(tmp_path_factory):
    """A JupyterLab server on loopback for the notebook tests (one for the session: it
    takes seconds to start)."""
    from lab import Lab

    root = tmp_path_factory.mktemp("lab")
    server = Lab(root, root / "jupyter.log")
    yield server
    server.stop()


@pytest.fixture(scope="session")
def browser():
    """Debian's Chromium, headless, driven by Playwright (no browser is downloaded)."""
    from lab import CHROMIUM
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        yield b
        b.close()

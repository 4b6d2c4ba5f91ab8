"""Shared fixtures: the repository's paths and the CLI binary the package is compared
with (``DVR_BIN``, else the workspace's debug or release build)."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def dvr_bin():
    for candidate in (os.environ.get("DVR_BIN"), ROOT / "target/debug/dvr", ROOT / "target/release/dvr", shutil.which("dvr")):
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    pytest.fail("no dvr binary: build it (cargo build) or set DVR_BIN")


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

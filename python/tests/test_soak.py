"""Short soaks of live sessions (soak.py): a Python renderer, a 4D series played, the
explorer under Xvfb and the notebook viewer, each with random edits, hold resident memory within 5 % after
the warm-up and device memory flat, with no validation message. `tools/soak.py` runs
the long ones (10,000 frames, 30 minutes) and records them."""

import soak


def check(row):
    print(row)
    assert soak.passed(row), row


def test_a_python_renderer_soaks():
    check(soak.python_session(renders=300))


def test_a_series_plays_for_long():
    check(soak.series_session(renders=300))


def test_the_explorer_soaks(dvr_bin):
    check(soak.explorer_session(dvr_bin, frames=300))


def test_the_notebook_viewer_soaks(lab, browser):
    check(soak.notebook_session(lab, browser, seconds=60))

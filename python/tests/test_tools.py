"""The Python tools that make and check the book: `tools/results_io.py`'s formatting and
tables, `tools/check_docs.py`'s anchors and its rule that OVERVIEW.md names each source
file by a path that resolves to it alone, and `tools/ct_views.py`'s CT in Hounsfield
units. Imported from the checkout's tools/ folder; no GPU. And the validation set's
README: one row per frozen scene file with the day it was frozen."""

import importlib
import re
import sys

import numpy as np
import pytest


@pytest.fixture(scope="module")
def tools(root):
    sys.path.insert(0, str(root / "tools"))
    try:
        yield {name: importlib.import_module(name) for name in ("results_io", "check_docs")}
    finally:
        sys.path.remove(str(root / "tools"))


def test_numbers_are_formatted_and_missing_ones_are_blank(tools):
    r = tools["results_io"]
    assert r.fmt(33.4704, 2) == "33.47"
    assert r.fmt(None, 2) == ""
    assert r.num("1.5") == 1.5
    assert r.best({"a": 1.0, "b": 3.0}, True) == 3.0
    assert r.best({"a": 1.0, "b": 3.0}, False) == 1.0


def test_tables_are_markdown_with_one_row_per_entry(tools):
    r = tools["results_io"]
    text = r.table(["method", "dB"], [["ours", "33.47"], ["svgf", "27.66"]])
    lines = text.splitlines()
    assert lines[0] == "| method | dB |"
    assert lines[1] == "| --- | --- |"
    assert lines[2:] == ["| ours | 33.47 |", "| svgf | 27.66 |"]


def test_a_missing_run_file_is_a_named_error(tools):
    r = tools["results_io"]
    with pytest.raises(r.Missing, match="no-such-set"):
        r.read_csv("no-such-set", "summary.csv")


def test_headings_become_the_anchors_mdbook_makes(tools):
    c = tools["check_docs"]
    assert c.slug("Orientation and units") == "orientation-and-units"
    assert c.slug("A view in a notebook") == "a-view-in-a-notebook"


def test_overview_must_name_a_file_by_a_path_that_resolves_to_it_alone(tools):
    c = tools["check_docs"]
    overview = "\n".join([
        "## tests",
        "| `cut.rs` | cuts |",
        "| `common/` | `harness.rs`, `eval.rs` |",
        "## engine/volume",
        "| `src/` | loaders (`nifti/tests.rs`), `nifti.rs` |",
        "## Top level",
        "| `src/` | `profile/` (`mod.rs`), `bench/` (`mod.rs`), `eval/`: `plan/` (`plan/mod.rs`) |",
        "Start with `engine/src/renderer/mod.rs`.",
    ])
    # By its path from the section's folder, the row's, or one the row names below them.
    assert c.names(overview, "tests/cut.rs")
    assert c.names(overview, "tests/common/harness.rs")
    assert c.names(overview, "engine/volume/src/nifti.rs")
    assert c.names(overview, "engine/volume/src/nifti/tests.rs")
    assert c.names(overview, "src/eval/plan/mod.rs")
    # By its full path anywhere.
    assert c.names(overview, "engine/src/renderer/mod.rs")
    # A path that resolves to two files names neither: `eval.rs` in tests/common's row
    # is tests/eval.rs or tests/common/eval.rs; `mod.rs` in src's row is profile's or bench's.
    assert not c.names(overview, "tests/common/eval.rs")
    assert not c.names(overview, "tests/eval.rs")
    assert not c.names(overview, "src/profile/mod.rs")
    assert not c.names(overview, "src/bench/mod.rs")
    # A bare name does not name a file in a folder its line does not stand in.
    assert not c.names(overview, "engine/volume/src/dicom/tests.rs")
    assert not c.names(overview, "src/eval/cut.rs")


def test_the_checkout_passes_its_own_overview_check(tools):
    assert tools["check_docs"].check_overview() == []


def test_the_ct_is_written_in_hounsfield_units_with_a_marker_on_the_right(root, tmp_path):
    sys.path.insert(0, str(root / "tools"))
    try:
        ct_views = importlib.import_module("ct_views")
    finally:
        sys.path.remove(str(root / "tools"))
    hu = ct_views.ct_volume(48)
    assert hu.dtype == np.int16
    assert hu.min() == -1000 and hu.max() == 1400
    # The knob on the patient's right (+x) has no twin on the left.
    z, y = int(0.55 * 48), int(0.5 * 48)
    right, left = hu[z, y, int(0.92 * 48)], hu[z, y, int(0.08 * 48)]
    assert right == 1400 and left < 1000
    nib = pytest.importorskip("nibabel")
    path = tmp_path / "ct.nii.gz"
    ct_views.write_nifti(hu, path)
    img = nib.load(str(path))
    assert np.allclose(img.affine, np.diag([1.5, 1.5, 1.5, 1.0]))
    assert np.array_equal(np.asarray(img.dataobj).transpose(2, 1, 0), hu)


def test_the_validation_sets_readme_lists_each_scene_file_with_the_day_it_was_frozen(root):
    folder = root / "assets/scenes/validation"
    readme = (folder / "README.md").read_text()
    rows = re.findall(r"^\| `([^`]+\.toml)` \| (\d{4}-\d{2}-\d{2}) \|", readme, re.M)
    listed = [name for name, _ in rows]
    assert sorted(listed) == sorted(p.name for p in folder.glob("*.toml"))
    assert len(set(listed)) == len(listed)
    # Rows in the order the scenes were frozen, so a new scene adds the last row.
    dates = [date for _, date in rows]
    assert dates == sorted(dates)

"""The Python tools that make and check the book: `tools/results_io.py`'s formatting and
tables, `tools/check_docs.py`'s anchors, its rule that OVERVIEW.md names each source
file by a path that resolves to it alone and its rule that a built book's images are in
it, `tools/book_images.py`'s images linked into the book, and `tools/ct_views.py`'s CT
in Hounsfield units. Imported from the checkout's tools/ folder; no GPU. And the validation set's
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
        yield {name: importlib.import_module(name) for name in ("results_io", "check_docs", "book_images")}
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


def test_the_books_images_point_into_the_book(tools, tmp_path):
    b = tools["book_images"]
    repo = tmp_path / "repo"
    src = repo / "docs" / "src"
    page = (
        "![a](../../assets/gallery/x.png) ![b](pictures/y.png) "
        '<img src="../../assets/screenshots/z.png"> ![c](https://example.org/w.png) '
        "[a link, not an image](../../assets/results/r.csv)"
    )
    out, shown = b.rewrite(page, str(src), str(src), str(repo))
    assert shown == {"assets/gallery/x.png", "assets/screenshots/z.png"}
    assert "![a](assets/gallery/x.png)" in out and 'src="assets/screenshots/z.png"' in out
    assert "![b](pictures/y.png)" in out and "https://example.org/w.png" in out
    assert "(../../assets/results/r.csv)" in out
    # The links are made relative to the repository's files; a stale one goes.
    (repo / "assets" / "gallery").mkdir(parents=True)
    (repo / "assets" / "gallery" / "x.png").write_bytes(b"png")
    (src / "assets" / "old").mkdir(parents=True)
    (src / "assets" / "old" / "gone.png").symlink_to("../../../../assets/gallery/x.png")
    b.link_shown(str(src), str(repo), {"assets/gallery/x.png"})
    assert (src / "assets" / "gallery" / "x.png").read_bytes() == b"png"
    assert not (src / "assets" / "old").exists()
    with pytest.raises(SystemExit, match="missing.png"):
        b.link_shown(str(src), str(repo), {"assets/gallery/missing.png"})


def test_a_built_books_image_outside_the_book_is_an_error(tools, tmp_path):
    c = tools["check_docs"]
    book = tmp_path / "book"
    book.mkdir()
    (tmp_path / "outside.png").write_bytes(b"png")
    (book / "in.png").write_bytes(b"png")
    (book / "page.html").write_text('<img src="in.png"><img src="../outside.png">')
    errors = c.check_images(str(book))
    assert len(errors) == 1 and "../outside.png" in errors[0], errors


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

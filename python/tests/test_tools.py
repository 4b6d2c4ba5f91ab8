"""The Python tools that make and check the book: `tools/results_io.py`'s formatting and
tables, `tools/results_sets.py`'s table of setup times with each command's totals, `tools/check_docs.py`'s anchors, its rule that OVERVIEW.md names each source
file by a path that resolves to it alone and its rule that a built book's images are in
it, `tools/book_images.py`'s images linked into the book, `tools/ct_views.py`'s CT
in Hounsfield units, `tools/strip.py`'s strip of one frame per scene and method, and
`tools/oidn_eval.py`'s OIDN rows in an eval folder (with a stand-in for OIDN). Imported
from the checkout's tools/ folder; no GPU. And the validation set's README: one row per
frozen scene file with the day it was frozen."""

import csv
import importlib
import json
import re
import shutil
import sys

import numpy as np
import pytest


@pytest.fixture(scope="module")
def tools(root):
    sys.path.insert(0, str(root / "tools"))
    try:
        yield {name: importlib.import_module(name) for name in ("results_io", "results_sets", "check_docs", "book_images")}
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


def test_the_setup_times_have_a_total_per_command_and_name_a_failed_step(tools, tmp_path, monkeypatch):
    r, sets = tools["results_io"], tools["results_sets"]
    assert [sets.duration(s) for s in (4.4, 59.6, 65, 3600)] == ["4 s", "1 min 00 s", "1 min 05 s", "60 min 00 s"]
    folder = tmp_path / "setup-times"
    folder.mkdir()
    header = "command,step,what,wall_s,cpu_s,user_s,sys_s,load_start,load_end,waited_s,exit,note"
    lines = [header,
             'tools/run.sh,"bash tools/setup.sh","Debian packages",40.4,12,10,2,0.1,0.9,0,0,""',
             'tools/run.sh,"cargo build --release","the build",100,190,180,10,1.5,1.9,0,0,""',
             'tools/test.sh,"cargo fmt --check, cargo clippy","lints",30,50,45,5,0.7,1.2,0,1,"failed (exit 1)"']
    (folder / "steps.csv").write_text("\n".join(lines) + "\n")
    (folder / "meta.json").write_text(json.dumps({
        "command": "tools/setup_times.sh", "commit": "abc1234", "date": "2026-12-07",
        "machine": "2 cores", "nproc": 2, "rustc": "rustc 1.95.0"}))
    monkeypatch.setattr(r, "RESULTS", str(tmp_path))
    text = sets.b_setup_times()
    rows = [line for line in text.splitlines() if line.startswith("| ")][2:]
    assert rows[0] == "| `bash tools/setup.sh` | Debian packages | 40 s | 12 s | 0.10 → 0.90 |"
    assert rows[2] == "| **`tools/run.sh`, in all** |  | **2 min 20 s** | **3 min 22 s** |  |"
    assert rows[3].startswith("| `cargo fmt --check`, `cargo clippy` | lints | 30 s | 50 s |")
    assert rows[4] == "| **`tools/test.sh`, in all** |  | **30 s** | **50 s** |  |"
    assert "`cargo fmt --check`, `cargo clippy` (lints): failed (exit 1)." in text
    assert "Source: `assets/results/setup-times/steps.csv`" in text
    # Only the step that started on a busy machine is named as slowed.
    assert "`cargo build --release` (the build) started at 1 or more" in text
    assert "(Debian packages) started" not in text


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


def _tool(root, name):
    sys.path.insert(0, str(root / "tools"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(root / "tools"))


# tools/strip.py: the results page's strip of one frame per scene and method.

STRIP_COLOURS = {
    ("brain", "reference"): (200, 0, 0),
    ("brain", "ours"): (0, 200, 0),
    ("brain", "svgf"): (0, 0, 200),
    ("head", "reference"): (200, 200, 0),
    ("head", "ours"): (0, 200, 200),
    ("head", "svgf"): (200, 0, 200),
}


def _fake_eval_for_strip(folder, frame, size=(20, 6)):
    """A `dvr eval` folder as strip.py reads it: per scene `reference/` and one folder a
    method of NNNN.png frames (one solid colour each, a grey decoy one frame earlier)
    and `plots/psnr.png`; plus a folder that is no scene."""
    from PIL import Image

    for (scene, method), colour in STRIP_COLOURS.items():
        d = folder / scene / method
        d.mkdir(parents=True, exist_ok=True)
        Image.new("RGB", size, colour).save(d / f"{frame:04d}.png")
        Image.new("RGB", size, (128, 128, 128)).save(d / f"{frame - 1:04d}.png")
    for scene in ("brain", "head"):
        (folder / scene / "plots").mkdir()
        (folder / scene / "plots" / "psnr.png").write_bytes(f"chart of {scene}".encode())
    (folder / "plots").mkdir()


def test_the_strip_has_a_labelled_tile_per_scene_and_method_holding_that_frame(root, tmp_path):
    from PIL import Image

    strip = _tool(root, "strip")
    _fake_eval_for_strip(tmp_path / "eval", 7)
    out = tmp_path / "gallery" / "strip.png"
    strip.main([str(tmp_path / "eval"), "--frame", "7", "--methods", "ours,svgf", "--strip", str(out), "--scale", "2"])
    img = np.asarray(Image.open(out).convert("RGB"))
    w, h, label = 20 * 2, 6 * 2, strip.LABEL
    # Columns: the reference then the methods; rows: the scenes by name.
    assert img.shape == (2 * (h + label), 3 * w, 3)
    for r, scene in enumerate(("brain", "head")):
        for c, method in enumerate(("reference", "ours", "svgf")):
            x, y = c * w, r * (h + label)
            tile = img[y + label : y + label + h, x : x + w]
            assert (tile == STRIP_COLOURS[scene, method]).all(), (scene, method)
            # A label above each tile: text on the background.
            band = img[y : y + label, x : x + w]
            assert (band != strip.BACKGROUND).any(axis=-1).sum() > 5, (scene, method)
            assert ((band == strip.BACKGROUND).all(axis=-1)).mean() > 0.3, (scene, method)


def test_the_strip_takes_the_named_scenes_of_two_evals_in_the_order_named(root, tmp_path):
    from PIL import Image

    strip = _tool(root, "strip")
    # Two evals: "head" in one, "brain" in the other; named head first.
    _fake_eval_for_strip(tmp_path / "a", 4)
    _fake_eval_for_strip(tmp_path / "b", 4)
    shutil.rmtree(tmp_path / "a" / "brain")
    shutil.rmtree(tmp_path / "b" / "head")
    out = tmp_path / "strip.png"
    strip.main([str(tmp_path / "a"), str(tmp_path / "b"), "--scenes", "head,brain", "--frame", "4",
                "--methods", "ours", "--strip", str(out), "--scale", "1"])
    img = np.asarray(Image.open(out).convert("RGB"))
    w, h, label = 20, 6, strip.LABEL
    assert img.shape == (2 * (h + label), 2 * w, 3)
    for r, scene in enumerate(("head", "brain")):
        tile = img[r * (h + label) + label : (r + 1) * (h + label), w : 2 * w]
        assert (tile == STRIP_COLOURS[scene, "ours"]).all(), scene
    # A scene no eval holds, or one both hold, is named.
    with pytest.raises(SystemExit, match="scene lung is in 0 of the evals"):
        strip.strip([tmp_path / "a", tmp_path / "b"], 4, ["ours"], names=["lung"])
    _fake_eval_for_strip(tmp_path / "c", 4)
    with pytest.raises(SystemExit, match="scene head is in 2 of the evals"):
        strip.strip([tmp_path / "a", tmp_path / "c"], 4, ["ours"], names=["head"])


def test_a_missing_method_frame_is_an_error_naming_it(root, tmp_path):
    strip = _tool(root, "strip")
    _fake_eval_for_strip(tmp_path, 3)
    (tmp_path / "head" / "svgf" / "0003.png").unlink()
    with pytest.raises(SystemExit, match=r"head/svgf/0003\.png"):
        strip.strip(tmp_path, 3, ["ours", "svgf"])
    with pytest.raises(SystemExit, match=r"brain/taa/0003\.png"):
        strip.strip(tmp_path, 3, ["taa"])
    with pytest.raises(SystemExit, match="no scene folders"):
        strip.strip(tmp_path / "plots", 3, ["ours"])


def test_the_psnr_charts_are_copied_per_scene_and_a_missing_one_is_named(root, tmp_path):
    strip = _tool(root, "strip")
    _fake_eval_for_strip(tmp_path / "eval", 1)
    written = strip.copy_plots(tmp_path / "eval", tmp_path / "cuts")
    assert [p.name for p in written] == ["cuts-brain-psnr.png", "cuts-head-psnr.png"]
    assert (tmp_path / "cuts-head-psnr.png").read_bytes() == b"chart of head"
    (tmp_path / "eval" / "head" / "plots" / "psnr.png").unlink()
    with pytest.raises(SystemExit, match=r"head/plots/psnr\.png"):
        strip.copy_plots(tmp_path / "eval", tmp_path / "cuts")


# tools/oidn_eval.py: OIDN's rows in an eval folder. OIDN itself (pyoidn) is replaced by
# a stand-in that records its arguments and returns the noisy frame.


def test_frames_to_recover_counts_frames_after_the_event_until_psnr_stays_within_1db(root):
    o = _tool(root, "oidn_eval")
    before = [30.0, 31.0, 30.0, 29.0, 30.0]  # mean 30: recovered at >= 29
    assert o.frames_to_recover(before + [20.0, 25.0, 29.5, 30.0], 5, 1.0) == 2
    assert o.frames_to_recover(before + [29.0, 30.0], 5, 1.0) == 0
    # A dip after a recovery counts; one that lasts to the end is `never` (None).
    assert o.frames_to_recover(before + [20.0, 30.0, 28.0, 30.0], 5, 1.0) == 3
    assert o.frames_to_recover(before + [20.0, 30.0, 20.0], 5, 1.0) is None
    # Only the 5 frames before the event are the baseline; PSNR is capped at 100 dB.
    assert o.frames_to_recover([0.0] + before + [29.0], 6, 1.0) == 0
    assert o.frames_to_recover([float("inf")] * 2 + [98.0, 99.5], 2, 1.0) == 1
    # No event inside the series: no count.
    assert o.frames_to_recover(before, 0, 1.0) is None
    assert o.frames_to_recover(before, 5, 1.0) is None


def test_the_event_frame_is_read_from_index_html_else_the_middle_of_a_jump_scene(root, tmp_path):
    o = _tool(root, "oidn_eval")
    assert o.event_frames(str(tmp_path)) == {}
    data = {"scenes": [{"name": "head/tf-jump", "event_frame": 12}, {"name": "head/orbit"}]}
    (tmp_path / "index.html").write_text(
        f'<html><script type="application/json" id="data">\n{json.dumps(data)}\n</script></html>'
    )
    events = o.event_frames(str(tmp_path))
    assert events == {"head/tf-jump": 12, "head/orbit": None}
    assert o.event_frame("head/tf-jump", events, 40) == 12
    assert o.event_frame("head/orbit", events, 40) is None
    assert o.event_frame("brain/light-jump", events, 40) == 20
    (tmp_path / "index.html").write_text('<script type="application/json" id="data">{not json</script>')
    assert o.event_frames(str(tmp_path)) == {}


def test_scene_names_become_dvrs_folder_names(root):
    o = _tool(root, "oidn_eval")
    assert o.dir_name("head/tf-jump") == "head_tf-jump"
    assert o.dir_name("ct.v2 scan") == "ct.v2_scan"
    assert o.dir_name("..x..") == "x"
    assert o.dir_name("é") == "_"
    assert o.dir_name("..") == "scene"


def test_metrics_csv_gives_the_scenes_and_frames_of_the_none_method(root, tmp_path):
    o = _tool(root, "oidn_eval")
    path = tmp_path / "metrics.csv"
    path.write_text(
        o.METRICS_HEADER + "\n"
        "b,none,1,30,0.9,0.1,,\nb,none,0,30,0.9,0.1,,\na,ours,0,31,0.9,0.1,,\na,none,0,30,0.9,0.1,,\n"
    )
    rows, scenes, frames = o.read_metrics(str(path))
    assert len(rows) == 4
    assert scenes == ["b", "a"]
    assert frames == {"b": [0, 1], "a": [0]}
    path.write_text(o.METRICS_HEADER + "\na,ours,0,31,0.9,0.1,,\n")
    with pytest.raises(SystemExit, match="no `none` rows"):
        o.read_metrics(str(path))
    path.write_text("scene,method,frame\n")
    with pytest.raises(SystemExit, match="does not start with"):
        o.read_metrics(str(path))


def test_rewriting_a_csv_replaces_earlier_oidn_rows_and_keeps_the_others(root, tmp_path):
    o = _tool(root, "oidn_eval")
    path = tmp_path / "summary.csv"
    path.write_text(
        "old,header\n"
        "a,ours,31\na,oidn,1\na,oidn-aux,2\nb,none,20\n\n"
    )
    o.rewrite(str(path), "scene,method,psnr", [["a", "oidn", "29"]])
    assert path.read_text() == "scene,method,psnr\na,ours,31\nb,none,20\na,oidn,29\n"
    assert not (tmp_path / "summary.csv.partial").exists()


def test_a_summary_row_holds_the_means_and_frames_to_recover(root):
    o = _tool(root, "oidn_eval")
    psnr = [30.0] * 5 + [20.0, 29.5, 30.0]
    scored = [
        {"frame": i, "psnr": p, "ssim": 0.5 + 0.01 * i, "flip": 0.1, "temporal_error": None if i == 0 else 0.2}
        for i, p in enumerate(psnr)
    ]
    row = o.summary_row("s", "oidn", scored, 5)
    assert row == ["s", "oidn", f"{sum(psnr) / 8:.4f}", f"{0.535:.6f}", "0.100000", "0.200000", "", "1"]
    assert o.summary_row("s", "oidn", scored, None)[7] == ""
    assert o.summary_row("s", "oidn", scored[:6], 5)[7] == "never"
    assert o.metric_row("s", "oidn", scored[0]) == ["s", "oidn", "0", "30.000000", "0.500000", "0.100000", "", ""]


def _write_exr(path, image):
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(image, dtype=np.float32)}).write(str(path))


def test_oidn_rows_replace_earlier_ones_with_the_evals_metrics_of_each_frame(root, tmp_path, monkeypatch, capsys):
    import types

    import dvr
    from PIL import Image

    o = _tool(root, "oidn_eval")
    rng = np.random.default_rng(1)
    out = tmp_path / "eval"
    scenes = {"head/tf-jump": "head_tf-jump", "brain": "brain"}
    refs, noisy, lines = {}, {}, [o.METRICS_HEADER]
    for scene, folder in scenes.items():
        for sub in ("reference", "none", "aux"):
            (out / folder / sub).mkdir(parents=True)
        prev = None
        for f in range(2):
            ref = rng.uniform(0.0, 2.0, (8, 8, 3)).astype(np.float32)
            test = (ref + rng.normal(0.0, 0.3, ref.shape)).clip(0.0).astype(np.float32)
            refs[scene, f], noisy[scene, f] = ref, test
            _write_exr(out / folder / "reference" / f"{f:04d}.exr", ref)
            _write_exr(out / folder / "none" / f"{f:04d}.exr", test)
            te = "" if prev is None else f"{dvr.metrics.temporal_error(prev[0], test, prev[1], ref):.6f}"
            lines.append(
                f"{scene},none,{f},{dvr.metrics.psnr(ref, test):.6f},{dvr.metrics.ssim(ref, test):.6f},"
                f"{dvr.metrics.flip(ref, test):.6f},{te},1.5"
            )
            prev = (test, ref)
            if scene == "brain":  # only brain's eval ran with --aux
                _write_exr(out / folder / "aux" / f"{f:04d}_albedo.exr", np.full((8, 8, 3), 1.5))
                _write_exr(out / folder / "aux" / f"{f:04d}_normal.exr", np.full((8, 8, 3), -2.0))
    lines.append("brain,oidn,0,1.0,0.1,0.9,,")  # from an earlier run: replaced
    # brain's GPU passes per frame: shared 10 + 1 ms, the guide march 3 ms, a method's own 5.
    passes = [
        {"pass": "path_trace", "owner": "shared", "ms": 10.0},
        {"pass": "motion", "owner": "shared", "ms": 1.0},
        {"pass": "aux_features", "owner": {"methods": ["svgf"]}, "ms": 3.0},
        {"pass": "svgf.temporal", "owner": {"method": "svgf"}, "ms": 5.0},
    ]
    (out / "brain" / "timings.json").write_text(json.dumps({"frames": [passes, passes]}))
    (out / "metrics.csv").write_text("\n".join(lines) + "\n")
    (out / "summary.csv").write_text(o.SUMMARY_HEADER + "\nbrain,none,20,0.5,0.2,0.1,1.5,\nbrain,oidn-aux,1,0.1,0.9,,,\n")

    calls = []

    def denoise(image, **kw):
        calls.append((image.copy(), kw))
        return image

    monkeypatch.setitem(sys.modules, "pyoidn", types.SimpleNamespace(denoise=denoise))
    o.main([str(out), "--quality", "fast", "--check"])

    # --check: the Python metrics of the `none` frames are metrics.csv's to its rounding.
    check = re.search(r"largest \|python - dvr\| on `none`: (.*)", capsys.readouterr().out).group(1)
    assert all(float(v) <= 1e-6 for v in re.findall(r"\d\.\d+e[-+]\d+", check)), check
    # OIDN gets each noisy frame as HDR at the quality asked; brain's also its clean guides, clipped.
    assert len(calls) == 2 * 2 + 2
    for image, kw in calls:
        assert kw["hdr"] is True and kw["quality"] == "fast"
    aux = [kw for _, kw in calls if "albedo" in kw]
    assert len(aux) == 2
    for kw in aux:
        assert kw["clean_aux"] is True
        assert (kw["albedo"] == 1.0).all() and (kw["normal"] == -1.0).all()
    assert any(np.array_equal(image, noisy["brain", 1]) for image, _ in calls)

    rows = list(csv.DictReader((out / "metrics.csv").open()))
    assert [r["method"] for r in rows[:4]] == ["none"] * 4
    new = {(r["scene"], r["method"], int(r["frame"])): r for r in rows[4:]}
    assert sorted(new) == sorted(
        [(s, "oidn", f) for s in scenes for f in range(2)] + [("brain", "oidn-aux", f) for f in range(2)]
    )
    for (scene, method, f), r in new.items():
        psnr = float(r["psnr"])
        assert np.isfinite(psnr) and abs(psnr - dvr.metrics.psnr(refs[scene, f], noisy[scene, f])) < 1e-5
        assert (r["temporal_error"] == "") == (f == 0) and r["gpu_ms"] == ""
        png = np.asarray(Image.open(out / scenes[scene] / method / f"{f:04d}.png"))
        want = (np.clip(dvr.metrics.tonemap(noisy[scene, f]), 0, 1) * 255 + 0.5).astype(np.uint8)
        assert np.array_equal(png, want)

    summary = list(csv.DictReader((out / "summary.csv").open()))
    assert [(r["scene"], r["method"]) for r in summary] == [
        ("brain", "none"), ("head/tf-jump", "oidn"), ("brain", "oidn"), ("brain", "oidn-aux")
    ]
    # head/tf-jump has no index.html event, so its event is the middle frame (1): recovered
    # at once if frame 1 is within 1 dB of frame 0, else never. brain has no event.
    p0, p1 = (float(new["head/tf-jump", "oidn", f]["psnr"]) for f in range(2))
    assert summary[1]["frames_to_recover"] == ("0" if p1 >= p0 - 1.0 else "never")
    assert summary[2]["frames_to_recover"] == ""
    assert float(summary[3]["psnr"]) == pytest.approx(np.mean([float(new["brain", "oidn-aux", f]["psnr"]) for f in range(2)]), abs=1e-4)

    # The whole frame's ms, where the eval kept timings (brain only): the shared passes,
    # for oidn-aux the guide march, and OIDN's own CPU ms.
    ms = list(csv.DictReader((out / "oidn_ms.csv").open()))
    assert sorted((r["method"], int(r["frame"])) for r in ms) == [("oidn", 0), ("oidn", 1), ("oidn-aux", 0), ("oidn-aux", 1)]
    for r in ms:
        assert r["scene"] == "brain" and float(r["oidn_cpu_ms"]) >= 0.0
        passes_ms = 11.0 + (3.0 if r["method"] == "oidn-aux" else 0.0)
        assert float(r["frame_ms"]) == pytest.approx(passes_ms + float(r["oidn_cpu_ms"]), abs=1e-3)


# tools/results_figures.py: the charts drawn from the runs' CSVs.


def test_each_budget_names_the_most_accurate_point_within_it(root):
    f = _tool(root, "results_figures")
    points = {
        "ours": [(1, 50.0, 30.0), (2, 80.0, 32.0)],
        "none": [(1, 30.0, 20.0)],  # cheaper than any point of ours
        "svgf": [(1, 60.0, 31.0)],  # within 60 ms ours has 30 dB only
        "oidn": [(1, 100.0, 31.5)],  # ours has 32 dB within 100 ms: never the best
    }
    assert f.budget_leaders(points) == [
        (30.0, 50.0, "none", 1, 20.0),
        (50.0, 60.0, "ours", 1, 30.0),
        (60.0, 80.0, "svgf", 1, 31.0),
        (80.0, None, "ours", 2, 32.0),
    ]
    text = f._front_sentence(points)
    assert "60.0–80.0 ms: `svgf` at 1 spp (31.00 dB)" in text and "from 80.0 ms: **`ours` at 2 spp" in text
    assert "not on the front" in text
    assert "leads within every budget" in f._front_sentence({"ours": points["ours"], "oidn": points["oidn"]})


def test_the_speed_chart_reads_each_spp_run_and_counts_oidns_cpu_time(root, tmp_path, monkeypatch):
    import xml.etree.ElementTree as ET

    f = _tool(root, "results_figures")
    io = _tool(root, "results_io")
    monkeypatch.setattr(io, "RESULTS", str(tmp_path))
    for spp, folder in f.SPP_FOLDERS.items():
        d = tmp_path / "validation" / folder
        d.mkdir(parents=True, exist_ok=True)
        (d / "summary.csv").write_text(
            "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover\n"
            f"a,ours,{30 + spp},,,,{10 * spp + 1},\nb,ours,{32 + spp},,,,{10 * spp + 1},\n"
            f"a,none,20,,,,{5 * spp},\nb,none,20,,,,{5 * spp},\nb,oidn,25,,,,,\nb,oidn-aux,26,,,,,\n"
        )
        # The frame's shared passes (none's GPU ms) are what OIDN's whole frame has beyond
        # its CPU time and, for oidn-aux, the guide march (3 ms here).
        (d / "metrics.csv").write_text(
            "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms\n"
            f"b,none,0,1,,,,{5 * spp + 1}\nb,oidn,0,1,,,,\n"
        )
        (d / "oidn_ms.csv").write_text(
            "scene,method,frame,oidn_cpu_ms,frame_ms\n"
            f"b,oidn,0,40,{41 + 5 * spp}\nb,oidn-aux,0,40,{44 + 5 * spp}\n"
        )
    points = f.speed_points()
    assert points["ours"] == [(1, 11.0, 32.0), (2, 21.0, 33.0), (4, 41.0, 35.0)]
    assert [p[1] for p in points["none"]] == [5.0, 10.0, 20.0]
    assert points["oidn"] == [(1, 45.0, 25.0), (2, 50.0, 25.0), (4, 60.0, 25.0)]
    assert [p[1] for p in points["oidn-aux"]] == [48.0, 53.0, 63.0]
    svg = f.speed_accuracy_svg()
    root_el = ET.fromstring(svg)
    assert root_el.tag.endswith("svg")
    texts = {t.text for t in root_el.iter() if t.tag.endswith("text")}
    assert {"ours", "oidn", "none"} <= texts
    # Without a run's OIDN times the chart is not drawn: the file is named.
    (tmp_path / "validation" / "spp4" / "oidn_ms.csv").unlink()
    with pytest.raises(io.Missing, match=r"spp4/oidn_ms\.csv"):
        f.speed_points()

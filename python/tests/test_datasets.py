"""The datasets under assets/volumes/ that tools/datasets.py writes: the committed files
hold what the tool writes now (voxels and metadata read back with nibabel, tifffile and
zarr; the statistical map's bytes are nilearn's), `dvr info --json` reads their channels,
names, colours and time points, the microscopy stack's two formats hold the same voxels,
and the shell beats: its size swings over the 24 time points and comes back."""

import importlib.util
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

nib = pytest.importorskip("nibabel")
tifffile = pytest.importorskip("tifffile")
zarr = pytest.importorskip("zarr")

ROOT = pathlib.Path(__file__).resolve().parents[2]
VOLUMES = ROOT / "assets/volumes"
TOOL = ROOT / "tools/datasets.py"
CHANNELS = [("nuclei", "0000FF"), ("membranes", "00FF00"), ("marker", "FF00FF")]


def info(dvr_bin, path):
    r = subprocess.run([str(dvr_bin), "info", str(path), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def write(dataset, out):
    r = subprocess.run([sys.executable, str(TOOL), dataset, "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    """The microscopy stack and the shell as the tool writes them now (once per module:
    the stack takes seconds)."""
    out = tmp_path_factory.mktemp("datasets")
    write("microscopy", out)
    write("beating-shell", out)
    return out


def zarr_image(path):
    """(voxels of the one level, the `ome` attributes) of an OME-Zarr 0.5 image."""
    group = zarr.open_group(str(path), mode="r")
    ome = group.attrs.asdict()["ome"]
    (level,) = ome["multiscales"][0]["datasets"]
    return group[level["path"]][:], ome


def shell_counts():
    data = np.asarray(nib.load(VOLUMES / "beating_shell.nii.gz").dataobj)
    return data, np.array([np.count_nonzero(data[..., t]) for t in range(data.shape[-1])])


def test_the_statmap_is_nilearns_file_byte_for_byte(dvr_bin, tmp_path):
    pytest.importorskip("nilearn")
    spec = importlib.util.find_spec("nilearn")
    theirs = pathlib.Path(list(spec.submodule_search_locations)[0]) / "datasets/data/image_10426.nii.gz"
    ours = write("statmap", tmp_path) / "mni152_statmap.nii.gz"
    committed = VOLUMES / "mni152_statmap.nii.gz"
    assert ours.read_bytes() == theirs.read_bytes() == committed.read_bytes()

    img = nib.load(committed)
    assert img.shape == (53, 63, 46) and np.allclose(img.header.get_zooms(), 3.0)
    got = info(dvr_bin, committed)
    assert got["times"] == 1 and tuple(got["dims"]) == (53, 63, 46)
    assert got["spacing"] == pytest.approx([3.0, 3.0, 3.0])
    (ch,) = got["channels"]
    assert ch["dtype"] == "float32"
    # A signed map: both tails (activation and deactivation) are in its window.
    assert ch["window"][0] < -5 and ch["window"][1] > 5


def test_the_committed_microscopy_stack_is_what_the_tool_writes(fresh):
    committed, committed_ome = zarr_image(VOLUMES / "microscopy.ome.zarr")
    now, now_ome = zarr_image(fresh / "microscopy.ome.zarr")
    assert committed.dtype == now.dtype == np.uint16
    assert np.array_equal(committed, now)
    assert committed_ome == now_ome
    assert np.array_equal(tifffile.imread(VOLUMES / "microscopy.ome.tif"), tifffile.imread(fresh / "microscopy.ome.tif"))


def test_the_microscopy_stacks_ome_zarr_and_ome_tiff_hold_the_same_voxels():
    from_zarr, ome = zarr_image(VOLUMES / "microscopy.ome.zarr")
    with tifffile.TiffFile(VOLUMES / "microscopy.ome.tif") as tif:
        from_tiff = tif.asarray()
        assert tif.series[0].axes == "CZYX"
    assert from_zarr.shape == from_tiff.shape == (3, 64, 96, 96)
    assert np.array_equal(from_zarr, from_tiff)
    assert [a["name"] for a in ome["multiscales"][0]["axes"]] == ["c", "z", "y", "x"]
    # It looks like a fluorescence stack: a dim background at the camera offset, and a
    # sparse marker far brighter than the nuclei.
    nuclei, _, marker = from_zarr.astype(float)
    assert 100 <= np.median(nuclei) <= 110
    assert marker.max() > 10 * np.percentile(nuclei, 99.9)
    assert np.mean(marker > 1000) < 1e-3


@pytest.mark.parametrize("name", ["microscopy.ome.zarr", "microscopy.ome.tif"])
def test_dvr_info_reads_the_microscopy_channels_names_and_colours(dvr_bin, name):
    got = info(dvr_bin, VOLUMES / name)
    assert got["times"] == 1
    assert tuple(got["dims"]) == (96, 96, 64)
    # 0.5 µm across, 1 µm along z, in mm.
    assert got["spacing"] == pytest.approx([0.0005, 0.0005, 0.001])
    assert [(ch["name"], ch["colour"]) for ch in got["channels"]] == CHANNELS
    assert all(ch["dtype"] == "uint16" for ch in got["channels"])
    if name.endswith(".zarr"):
        _, ome = zarr_image(VOLUMES / name)
        windows = [(c["window"]["start"], c["window"]["end"]) for c in ome["omero"]["channels"]]
        assert [tuple(ch["display_window"]) for ch in got["channels"]] == windows


def test_the_committed_shell_is_what_the_tool_writes(fresh):
    committed = nib.load(VOLUMES / "beating_shell.nii.gz")
    now = nib.load(fresh / "beating_shell.nii.gz")
    assert committed.get_data_dtype() == now.get_data_dtype() == np.uint8
    assert np.array_equal(np.asarray(committed.dataobj), np.asarray(now.dataobj))
    assert np.array_equal(committed.affine, now.affine)
    assert committed.header.get_zooms() == now.header.get_zooms()


def test_dvr_info_reads_the_shells_24_time_points(dvr_bin):
    got = info(dvr_bin, VOLUMES / "beating_shell.nii.gz")
    assert got["times"] == 24
    assert tuple(got["dims"]) == (96, 96, 96) and got["spacing"] == pytest.approx([1.0, 1.0, 1.0])
    assert got["frame"] == "RAS"
    (ch,) = got["channels"]
    assert ch["dtype"] == "uint8"


def test_the_shell_beats_once_over_its_time_points_and_comes_back():
    data, counts = shell_counts()
    assert data.shape == (96, 96, 96, 24)
    # Its size swings by far more than 10 %: largest a quarter beat in, smallest at
    # three quarters.
    assert (counts.max() - counts.min()) / counts.mean() > 0.1
    assert counts.argmax() == 6 and counts.argmin() == 18
    # One sinusoidal beat: symmetric about its peak and its trough.
    for k in range(1, 6):
        assert counts[6 + k] == pytest.approx(counts[6 - k], rel=0.01)
        assert counts[(18 + k) % 24] == pytest.approx(counts[18 - k], rel=0.01)
    # Periodic: the beat closes on itself, so the series has no jump from t = 23 to t = 0.
    # A jump (a beat cut short) would spread into every harmonic; here all above the
    # second (the size's square: counts go as the wall's area) are under 1 % of the beat.
    harmonics = np.abs(np.fft.rfft(counts))
    assert harmonics[3:].max() < 0.01 * harmonics[1]
    assert counts[0] == pytest.approx(counts[12], rel=0.01), "the mean size at the beat's start and middle"


def test_the_vessels_ride_on_the_wall():
    data, _ = shell_counts()
    # The wall is 0.6 (153), the vessels 0.9 (230), edges anti-aliased in between.
    values, n = np.unique(data[data > 0], return_counts=True)
    assert values[n.argmax()] == 153 and data.max() == 230
    # The vessels' voxels are carried out and in with the wall: their mean distance from
    # the centre swings by the wall's (1.15 / 0.85 between peak and trough).
    c = np.arange(96) + 0.5 - 48
    r = np.sqrt(c[:, None, None] ** 2 + c[None, :, None] ** 2 + c[None, None, :] ** 2)
    vessel_r = [r[data[..., t] >= 220].mean() for t in (6, 18)]
    assert vessel_r[0] / vessel_r[1] == pytest.approx(1.15 / 0.85, rel=0.05)
    assert all(np.count_nonzero(data[..., t] >= 220) > 500 for t in range(24))


def test_the_committed_mni_labels_are_what_the_tool_writes(tmp_path):
    out = write("mni-labels", tmp_path)
    for name in ("mni152_labels.nii.gz",):
        ours, theirs = nib.load(VOLUMES / name), nib.load(out / name)
        assert np.array_equal(ours.get_fdata(), theirs.get_fdata()) and np.allclose(ours.affine, theirs.affine)
    assert (VOLUMES / "mni152_labels.label").read_text() == (out / "mni152_labels.label").read_text()


def test_the_mni_labels_lie_on_the_t1_grid_and_follow_the_tissue_maps():
    labels = nib.load(VOLUMES / "mni152_labels.nii.gz")
    t1 = nib.load(VOLUMES / "mni152_t1.nii.gz")
    assert labels.shape == t1.shape and np.allclose(labels.affine, t1.affine)
    a = np.asarray(labels.dataobj)
    assert a.dtype == np.uint8 and set(np.unique(a)) == {0, 1, 2, 3}
    # White matter is brighter than grey matter in a T1: the labels agree with the image.
    t = t1.get_fdata()
    assert t[a == 1].mean() > t[a == 2].mean() + 20
    assert 0.05 < (a == 1).mean() < 0.2 and 0.05 < (a == 2).mean() < 0.2
    # The rest of the brain is the masked T1's other voxels: every voxel of the brain has
    # a label, and no label lies outside it.
    assert np.array_equal(a > 0, t > 0) and 0.005 < (a == 3).mean() < 0.05

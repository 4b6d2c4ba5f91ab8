"""Channels and time points as files people have hold them, read through `dvr info
--json`: nibabel's own 4D example (oblique, two time points) on the grid nibabel's
resampling builds, an OME-TIFF of 3 channels x 2 time points written by tifffile with
channel names, and an OME-Zarr image with a channel axis and `omero` colours written by
ome-zarr-py."""

import json
import os
import subprocess

import numpy as np
import pytest

nib = pytest.importorskip("nibabel")


def info(dvr_bin, *args):
    r = subprocess.run([str(dvr_bin), "info", *map(str, args), "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_nibabels_example4d_has_two_time_points_on_nibabels_resampled_grid(dvr_bin):
    processing = pytest.importorskip("nibabel.processing")
    from nibabel.testing import data_path

    path = os.path.join(data_path, "example4d.nii.gz")
    got = info(dvr_bin, path)
    assert got["times"] == 2 and len(got["channels"]) == 1
    assert got["channels"][0]["dtype"] == "int16"
    # The file is oblique (tilted about x): it lands on the RAS grid nibabel's
    # resample_to_output builds with the file's voxel sizes.
    img = nib.load(path)
    first = img.slicer[..., 0]
    sizes = np.sqrt((img.affine[:3, :3] ** 2).sum(axis=0))
    theirs = processing.resample_to_output(first, voxel_sizes=tuple(sizes), order=0)
    assert tuple(got["dims"]) == theirs.shape
    assert np.allclose(np.array(got["to_patient"]), theirs.affine, atol=1e-3)


def test_an_ome_tiff_of_three_channels_and_two_time_points_keeps_its_channel_names(dvr_bin, tmp_path):
    tifffile = pytest.importorskip("tifffile")
    t, c, z, y, x = 2, 3, 4, 6, 8
    data = np.arange(t * c * z * y * x, dtype=np.uint16).reshape(t, c, z, y, x)
    path = tmp_path / "cells.ome.tif"
    names = ["nuclei", "membranes", "marker"]
    tifffile.imwrite(path, data, ome=True, metadata={"axes": "TCZYX", "Channel": {"Name": names}})
    got = info(dvr_bin, path)
    assert got["times"] == 2
    assert [ch["name"] for ch in got["channels"]] == names
    assert tuple(got["dims"]) == (x, y, z)
    # A selection picks channels in the order given.
    picked = info(dvr_bin, path, "--channels", "2,0")
    assert [ch["name"] for ch in picked["channels"]] == ["marker", "nuclei"]


def test_an_ome_zarr_channel_axis_with_omero_colours(dvr_bin, tmp_path):
    zarr = pytest.importorskip("zarr")
    from ome_zarr.format import FormatV04
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image

    fmt = FormatV04()
    path = tmp_path / "two.zarr"
    root = zarr.group(store=parse_url(str(path), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
    data = np.arange(2 * 4 * 6 * 8, dtype=np.uint16).reshape(2, 4, 6, 8)
    write_image(image=data, group=root, fmt=fmt, axes="czyx", scale_factors=[])
    root.attrs["omero"] = {
        "channels": [
            {"label": "dapi", "color": "0000FF", "window": {"start": 0, "end": 200, "min": 0, "max": 383}},
            {"label": "gfp", "color": "00FF00", "window": {"start": 0, "end": 300, "min": 0, "max": 383}},
        ]
    }
    got = info(dvr_bin, path)
    assert got["times"] == 1
    assert [(ch["name"], ch["colour"]) for ch in got["channels"]] == [("dapi", "0000FF"), ("gfp", "00FF00")]
    assert tuple(got["dims"]) == (8, 6, 4)


def test_more_than_four_channels_say_how_to_pick_some(dvr_bin, tmp_path):
    tifffile = pytest.importorskip("tifffile")
    path = tmp_path / "five.ome.tif"
    tifffile.imwrite(path, np.zeros((5, 2, 6, 8), np.uint8), ome=True, metadata={"axes": "CZYX"})
    r = subprocess.run([str(dvr_bin), "info", str(path)], capture_output=True, text=True)
    assert r.returncode != 0
    assert "five.ome.tif" in r.stderr and "channels = [0, 2]" in r.stderr

"""What a loader drops reaches Python as a warning: an OME-TIFF or OME-Zarr image with two
channels (and time points) loads channel 0 at time 0, and says so with a
``dvr.DataDroppedWarning`` (a ``UserWarning``), not only a log line."""

import warnings

import numpy as np
import pytest

import dvr


def _two_channels():
    z, y, x = np.mgrid[:6, :7, :8]
    first = (z * 31 + y * 7 + x).astype(np.uint16)
    return np.stack([first, first[::-1] + 5])  # C, Z, Y, X


def _load_warned(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        v = dvr.load_volume(path)
    return v, [w for w in caught if issubclass(w.category, dvr.DataDroppedWarning)]


def test_an_ome_tiffs_extra_channel_is_a_python_warning(tmp_path):
    tifffile = pytest.importorskip("tifffile")
    data = _two_channels()
    path = tmp_path / "two.ome.tif"
    tifffile.imwrite(path, data, ome=True, metadata={"axes": "CZYX"})
    v, dropped = _load_warned(path)
    assert np.array_equal(v.data, dvr.Volume(data[0]).data)
    assert len(dropped) == 1 and issubclass(dvr.DataDroppedWarning, UserWarning)
    message = str(dropped[0].message)
    assert "two.ome.tif" in message and "channel" in message
    # Attributed to the caller's line, not to dvr's own code.
    assert dropped[0].filename == __file__
    # A single-channel stack warns of nothing.
    tifffile.imwrite(tmp_path / "one.ome.tif", data[0], ome=True, metadata={"axes": "ZYX"})
    assert _load_warned(tmp_path / "one.ome.tif")[1] == []


def test_an_ome_zarrs_extra_channel_and_time_point_are_python_warnings(tmp_path):
    zarr = pytest.importorskip("zarr")
    from ome_zarr.format import FormatV04
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image

    data = np.stack([_two_channels(), _two_channels() + 1])  # T, C, Z, Y, X
    fmt = FormatV04()
    path = tmp_path / "tc.zarr"
    root = zarr.group(store=parse_url(str(path), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
    write_image(image=data, group=root, fmt=fmt, axes="tczyx", scale_factors=[])
    v, dropped = _load_warned(path)
    assert np.array_equal(v.data, dvr.Volume(data[0, 0]).data)
    text = " ".join(str(w.message) for w in dropped)
    assert len(dropped) == 2 and "axis c has 2 entries" in text and "axis t has 2 entries" in text, text
    assert all("tc.zarr" in str(w.message) for w in dropped)


def test_dropped_data_shows_under_w_always_and_errors_under_w_error(tmp_path):
    tifffile = pytest.importorskip("tifffile")
    path = tmp_path / "two.ome.tif"
    tifffile.imwrite(path, _two_channels(), ome=True, metadata={"axes": "CZYX"})
    with warnings.catch_warnings():
        warnings.simplefilter("error", dvr.DataDroppedWarning)
        with pytest.raises(dvr.DataDroppedWarning, match="channel"):
            dvr.load_volume(path)

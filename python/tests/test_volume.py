"""dvr.Volume and dvr.load_volume: arrays in, the loaders' normalisation, clear errors."""

import gzip

import nibabel
import numpy as np
import pytest

import dvr


def test_array_axes_and_spacing_follow_the_shape():
    a = np.zeros((4, 5, 6), dtype=np.uint8)
    a[3, 4, 5] = 255
    v = dvr.Volume(a, spacing=(2.0, 1.0, 0.5))
    assert v.shape == (4, 5, 6)
    assert v.spacing == (2.0, 1.0, 0.5)
    assert v.dtype == "uint8"
    d = v.to_numpy()
    assert d.shape == (4, 5, 6) and d.dtype == np.float32
    assert d[3, 4, 5] == 1.0 and d.sum() == 1.0


def test_float_densities_stay_and_other_ranges_are_windowed():
    rng = np.random.default_rng(1)
    unit = rng.random((3, 4, 5), dtype=np.float32)
    assert np.array_equal(dvr.Volume(unit).to_numpy(), unit)
    hu = (unit * 2000.0 - 1000.0).astype(np.float32)  # Hounsfield-like
    v = dvr.Volume(hu)
    assert v.window == pytest.approx((hu.min(), hu.max()))
    assert np.allclose(v.to_numpy(), (hu - hu.min()) / (hu.max() - hu.min()), atol=1e-6)
    assert dvr.Volume(np.arange(60, dtype=np.uint16).reshape(3, 4, 5)).dtype == "uint16"
    signed = dvr.Volume(np.arange(60, dtype=np.int16).reshape(3, 4, 5) - 30)
    # dtype is what the user handed over; the GPU holds int16 shifted into uint16.
    assert (signed.dtype, signed.stored_as) == ("int16", "uint16")


def test_non_contiguous_views_are_read_in_index_order():
    a = np.arange(2 * 3 * 4, dtype=np.float32).reshape(4, 3, 2).transpose(2, 1, 0) / 24.0
    assert not a.flags["C_CONTIGUOUS"]
    assert np.array_equal(dvr.Volume(a).to_numpy(), np.ascontiguousarray(a))


@pytest.mark.parametrize(
    "array, message",
    [
        (np.zeros((4, 4), np.uint8), "got 2 dimension"),
        (np.zeros((0, 4, 4), np.uint8), "empty"),
        (np.zeros((2, 2, 2), np.int64), "int64"),  # float64 loads (test_api.py)
        (np.zeros((2, 2, 2), np.complex64), "complex64"),
        ([[[1, 2]]], "numpy array"),
    ],
)
def test_bad_arrays_are_value_errors(array, message):
    with pytest.raises(ValueError, match=message):
        dvr.Volume(array)


def test_nan_names_the_first_voxel():
    a = np.zeros((2, 3, 4), np.float32)
    a[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"not finite.*\(3, 2, 1\)|\(3, 2, 1\).*not finite|NaN|non-finite") as e:
        dvr.Volume(a, name="ct")
    assert "ct" in str(e.value)


def test_bad_spacing_is_a_value_error():
    with pytest.raises(ValueError, match="spacing"):
        dvr.Volume(np.zeros((2, 2, 2), np.uint8), spacing=(1.0, 0.0, 1.0))


def test_the_bundled_mri_matches_nibabel(root):
    path = root / "assets/volumes/mni152_t1.nii.gz"
    img = nibabel.load(str(path))
    v = dvr.load_volume(path)
    assert v.shape == tuple(reversed(img.shape))
    assert v.spacing == pytest.approx(tuple(reversed(img.header.get_zooms()[:3])))
    data = np.asarray(img.dataobj)
    # Same voxels: density is the data windowed to its type's (or data's) range.
    ours = v.to_numpy().transpose(2, 1, 0)
    nz = data > 0
    assert (ours[nz] > 0).all() and (ours[~nz] == 0).all()
    # An array of the same data gives the same volume as the file.
    same = dvr.Volume(np.ascontiguousarray(data.transpose(2, 1, 0)), spacing=v.spacing)
    assert np.array_equal(same.to_numpy(), v.to_numpy())


def test_truncated_and_missing_files_name_the_file(root, tmp_path):
    whole = gzip.decompress((root / "assets/volumes/mni152_t1.nii.gz").read_bytes())
    cut = tmp_path / "cut.nii"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(ValueError, match="cut.nii"):
        dvr.load_volume(cut)
    with pytest.raises(ValueError, match="nowhere.nii"):
        dvr.load_volume(tmp_path / "nowhere.nii")
    with pytest.raises(ValueError, match="phantom"):
        dvr.Volume.builtin("phantom", size=0)

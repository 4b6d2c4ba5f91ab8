"""The Python surface as one API: numpy arrays wherever a volume goes, one kind of error
for a mistyped field, dtypes as the user's data had them, .npy files, orbit in degrees."""

import numpy as np
import pytest

import dvr


def _blob(n=16, dtype=np.float32):
    z, y, x = np.mgrid[:n, :n, :n] / (n - 1) - 0.5
    return (np.sqrt(x * x + y * y + z * z) < 0.35).astype(dtype)


def test_numpy_arrays_and_volumes_render_wherever_a_scene_goes():
    a = _blob()
    for what in (a, dvr.Volume(a)):
        with dvr.Renderer(what, size=(32, 32), spp=2, denoisers=[]) as r:
            img = r.render()["noisy"]
            assert img.shape == (32, 32, 3) and np.isfinite(img).all() and img.max() > 0
    s = dvr.Scene(a)
    assert isinstance(s.volume, dvr.Volume) and s.volume.shape == a.shape
    with pytest.raises(TypeError, match="Renderer: expected a Scene, a Volume"):
        dvr.Renderer(42)


@pytest.mark.parametrize("make", [dvr.Scene, dvr.Volume, lambda a: dvr.Renderer(a, size=(8, 8))])
def test_a_non_3d_array_is_refused_at_construction_without_its_repr(make):
    flat = np.full((40, 40), 12345.0, dtype=np.float32)
    with pytest.raises(ValueError) as e:
        make(flat)
    assert "expected an array indexed [z, y, x]" in str(e.value) and "shape [40, 40]" in str(e.value)
    assert "12345" not in str(e.value) and "[[" not in str(e.value)


def test_mistyped_fields_raise_one_attribute_error_naming_the_fields():
    r = dvr.Renderer(_blob(), size=(16, 16), spp=1, denoisers=[])
    with pytest.raises(AttributeError, match=r"lights\[0\] \(point light\) has no field 'colr' \(fields: .*colour"):
        r.lights[0].colr = (1, 0, 0)
    with pytest.raises(AttributeError, match=r"has no field 'colr'"):
        r.lights[0].colr
    with pytest.raises(AttributeError, match=r"camera has no field 'fov' \(fields: position, target, up, fov_y_degrees"):
        r.camera.fov = 30
    v = dvr.Volume(_blob())
    with pytest.raises(AttributeError, match=r"Volume has no field 'spacng' \(fields: .*spacing"):
        v.spacng
    with pytest.raises(AttributeError, match="immutable"):
        v.spacing = (2, 2, 2)
    s = dvr.Scene(v)
    with pytest.raises(AttributeError, match=r"Scene has no field 'camra' \(fields: .*camera"):
        s.camra = dvr.Camera()
    with pytest.raises(AttributeError, match=r"Scene has no field 'ligths'"):
        s.ligths
    point = {"density": 0.5, "opacity": 1.0, "diffuse": [1, 1, 1], "opactiy": 0.2}
    with pytest.raises(AttributeError, match=r"point 0 has no field 'opactiy' \(fields: density, opacity"):
        dvr.TransferFunction([point])
    # The same error type for all of them, and a ValueError too where a dict was the input.
    with pytest.raises(ValueError):
        dvr.TransferFunction([point])
    # Nothing was applied by the failed edits.
    assert "colr" not in r.lights[0].to_dict() and np.isfinite(r.render()["noisy"]).all()
    r.close()


def test_dtype_is_the_users_int16_from_arrays_and_nifti(tmp_path):
    nib = pytest.importorskip("nibabel")
    a = (np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6) - 50) * 7
    assert dvr.Volume(a).dtype == "int16" and "dtype=int16" in repr(dvr.Volume(a))
    nib.save(nib.Nifti1Image(a.T.copy(), np.eye(4)), tmp_path / "ct.nii.gz")
    v = dvr.load_volume(tmp_path / "ct.nii.gz")
    assert v.dtype == "int16" and v.window == pytest.approx((a.min(), a.max()))


def test_float64_arrays_and_nifti_load_as_float32(tmp_path):
    nib = pytest.importorskip("nibabel")
    a = np.random.default_rng(1).random((4, 5, 6)) * 300.0 - 100.0
    v = dvr.Volume(a)
    assert v.dtype == "float64" and v.stored_as == "float32"
    assert np.allclose(v.data, (a - a.min()) / (a.max() - a.min()), atol=1e-5)
    nib.save(nib.Nifti1Image(a.T.copy(), np.eye(4)), tmp_path / "f64.nii")
    f = dvr.load_volume(tmp_path / "f64.nii")
    # The NIfTI loader narrows float64 as it reads (its dtype says float32).
    assert f.shape == v.shape and np.allclose(f.data, v.data, atol=1e-6)


def test_npy_files_load_with_1mm_voxels(tmp_path):
    a = (_blob(12) * 200).astype(np.uint8)
    np.save(tmp_path / "blob.npy", a)
    v = dvr.load_volume(tmp_path / "blob.npy")
    assert (v.name, v.shape, v.spacing, v.dtype) == ("blob", a.shape, (1.0, 1.0, 1.0), "uint8")
    assert np.array_equal(v.data, dvr.Volume(a).data)
    assert dvr.Volume.load(str(tmp_path / "blob.npy")).shape == a.shape
    np.save(tmp_path / "flat.npy", np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"expected an array indexed \[z, y, x\]"):
        dvr.load_volume(tmp_path / "flat.npy")


def test_volume_exposes_window_to_patient_and_data():
    a = np.arange(2 * 3 * 4, dtype=np.uint16).reshape(2, 3, 4) * 100
    v = dvr.Volume(a, spacing=(3.0, 2.0, 0.5))
    assert v.window == pytest.approx((0.0, float(a.max())))
    m = v.to_patient
    assert m.shape == (4, 4) and m.dtype == np.float64
    # Array index (z, y, x) to RAS mm: the spacings, in the array's axis order.
    assert np.allclose(m @ [1, 0, 0, 1] - m @ [0, 0, 0, 1], [0, 0, 3.0, 0])
    assert np.allclose(m @ [0, 0, 1, 1] - m @ [0, 0, 0, 1], [0.5, 0, 0, 0])
    assert v.data.shape == a.shape and np.allclose(v.data * a.max(), a, atol=0.1)


def _azimuth(r):
    p, t = np.array(r.camera.position), np.array(r.camera.target)
    return np.degrees(np.arctan2(*(p - t)[1::-1]))


def test_orbit_takes_degrees_in_the_renderer_as_in_the_scene():
    scene = dvr.Scene(_blob(), frames=2).orbit(degrees_per_frame=25.0)
    animated = dvr.Renderer(scene, size=(16, 16), spp=1, denoisers=[])
    animated.render(frame=0)
    start = _azimuth(animated)
    animated.render(frame=1)
    by_scene = (_azimuth(animated) - start + 180) % 360 - 180
    still = dvr.Renderer(dvr.Scene(_blob()), size=(16, 16), spp=1, denoisers=[])
    before = _azimuth(still)
    still.orbit(25.0)
    by_renderer = (_azimuth(still) - before + 180) % 360 - 180
    assert abs(by_scene) == pytest.approx(25.0, abs=1e-6)
    assert by_renderer == pytest.approx(by_scene, abs=1e-6)

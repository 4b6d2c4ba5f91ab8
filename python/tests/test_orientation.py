"""Patient space end to end, with files written by the packages people write them with:
every loader puts the voxels in RAS order (x +Right, y +Anterior, z +Superior), so a
flipped affine renders mirrored and LPS files (NRRD, DICOM) load as the RAS NIfTI does;
oblique grids are resampled as nibabel resamples them; CT values stay in Hounsfield units
and the CT presets are written in them."""

import numpy as np
import pytest

import dvr

nib = pytest.importorskip("nibabel")

# (x, y, z) sizes, all different, and a phantom with no symmetry: a ramp along each axis
# and a bright block on the +x, +y, +z corner.
NX, NY, NZ = 10, 12, 14


def _phantom_xyz():
    x, y, z = np.mgrid[:NX, :NY, :NZ]
    d = (100 * x + 10 * y + z).astype(np.uint16)
    d[NX // 2 + 1 :, NY // 2 + 1 :, NZ // 2 + 1 :] = 4000
    d[0, 0, 0] = 0
    return d


def _as_dvr(xyz):
    """nibabel's [x, y, z] as dvr's [z, y, x]."""
    return np.ascontiguousarray(xyz.T)


def _render(vol):
    # From +y looking at the centre, +z up: image columns run along x.
    cam = dvr.Camera(position=(0.0, 2.2, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), fov_y_degrees=35.0)
    # The sample stream is fixed by the frame index: the same volume renders the same.
    with dvr.Renderer(dvr.Scene(vol, camera=cam), size=(32, 32), spp=4, denoisers=[]) as r:
        return r.render()["noisy"]


def test_a_flipped_nifti_affine_loads_and_renders_mirrored(tmp_path):
    d = _phantom_xyz()
    flip = np.diag([-1.0, 1.0, 1.0, 1.0])
    flip[0, 3] = NX - 1  # the same box in patient space, indexed from the other side
    nib.save(nib.Nifti1Image(d, np.eye(4)), tmp_path / "ras.nii.gz")
    nib.save(nib.Nifti1Image(d, flip), tmp_path / "flipped.nii.gz")
    nib.save(nib.Nifti1Image(d[::-1].copy(), flip), tmp_path / "same.nii.gz")
    ras, flipped, same = (dvr.load_volume(tmp_path / f"{n}.nii.gz") for n in ("ras", "flipped", "same"))
    assert np.array_equal(ras.data, dvr.Volume(_as_dvr(d)).data)
    # Stored reversed along x with an affine that says so: the same patient, same voxels.
    assert np.array_equal(same.data, ras.data)
    # The same array under the flipping affine: mirrored along x (the array's last axis).
    assert np.array_equal(flipped.data, ras.data[:, :, ::-1])
    # The affine's offset keeps the box where it was: the first RAS voxel is the same point.
    assert np.allclose(flipped.to_patient, ras.to_patient)

    a, b, c = _render(ras), _render(same), _render(flipped)
    assert np.array_equal(a, b)
    # The bright block sits on one side of the image in a and on the other in c.
    cols = np.arange(32) - 15.5

    def centroid(img):
        w = img.mean(axis=(0, 2))
        return float((w * cols).sum() / w.sum())

    # (The light is not mirrored, so the images are not exact mirrors of each other.)
    assert abs(centroid(a)) > 0.5 and np.sign(centroid(a)) == -np.sign(centroid(c))


def _write_nrrd_lps(path, d):
    """The phantom as LPS NRRD: index i runs toward Left, j toward Posterior, so the file
    holds d reversed along x and y."""
    f = d[::-1, ::-1, :]
    header = (
        "NRRD0004\ntype: float\ndimension: 3\nspace: left-posterior-superior\n"
        f"sizes: {NX} {NY} {NZ}\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
        "kinds: domain domain domain\nendian: little\nencoding: raw\nspace origin: (0,0,0)\n\n"
    )
    path.write_bytes(header.encode() + f.astype("<f4").ravel(order="F").tobytes())


def _write_dicom_lps(folder, d, slope=1.0, intercept=0.0):
    """The phantom as a DICOM series (LPS): rows along Left, columns along Posterior,
    one slice per z, written by pydicom."""
    pydicom = pytest.importorskip("pydicom")
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, generate_uid

    folder.mkdir()
    series, study, frame = generate_uid(), generate_uid(), generate_uid()
    nx, ny, nz = d.shape
    for k in range(nz):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, meta.MediaStorageSOPInstanceUID
        ds.Modality, ds.PatientName, ds.PatientID = "CT", "Phantom^Test", "0"
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.FrameOfReferenceUID = study, series, frame
        ds.InstanceNumber = k + 1
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.ImagePositionPatient = [0.0, 0.0, float(k)]
        ds.PixelSpacing, ds.SliceThickness = [1.0, 1.0], 1.0
        ds.Rows, ds.Columns = ny, nx
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.RescaleSlope, ds.RescaleIntercept = slope, intercept
        # pixel[r, c]: column c toward Left (x = nx-1-c), row r toward Posterior (y = ny-1-r).
        ds.PixelData = np.ascontiguousarray(d[::-1, ::-1, k].T).astype("<u2").tobytes()
        pydicom.dcmwrite(folder / f"slice{k:03d}.dcm", ds, enforce_file_format=True)


def test_lps_nrrd_and_dicom_load_as_the_ras_nifti_does(tmp_path):
    d = _phantom_xyz()
    nib.save(nib.Nifti1Image(d, np.eye(4)), tmp_path / "ras.nii.gz")
    ras = dvr.load_volume(tmp_path / "ras.nii.gz")
    _write_nrrd_lps(tmp_path / "lps.nrrd", d)
    _write_dicom_lps(tmp_path / "series", d)
    nrrd, dicom = dvr.load_volume(tmp_path / "lps.nrrd"), dvr.load_volume(tmp_path / "series")
    assert nrrd.shape == dicom.shape == ras.shape
    # The NRRD holds float32 and the NIfTI uint16 (stored as unorm16): equal to 1e-4.
    assert np.allclose(nrrd.data, ras.data, atol=1e-4)
    assert np.array_equal(dicom.data, ras.data)
    # LPS origin (0, 0, 0) is RAS (0, 0, 0); the first RAS voxel is the file's last
    # along i and j: at R = -(nx - 1), A = -(ny - 1).
    assert np.allclose(nrrd.to_patient[:3, 3], [-(NX - 1), -(NY - 1), 0])
    assert np.allclose(dicom.to_patient[:3, 3], nrrd.to_patient[:3, 3])


def test_an_oblique_nifti_loads_onto_nibabels_resampled_grid(tmp_path):
    processing = pytest.importorskip("nibabel.processing")
    rng = np.random.default_rng(3)
    d = rng.random((NX, NY, NZ)).astype(np.float32)
    d[0, 0, 0], d[-1, -1, -1] = 0.0, 1.0  # min 0: the outside fill (0) agrees
    t = np.radians(20.0)
    rot = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])
    sizes = np.array([1.2, 0.9, 1.5])
    affine = np.eye(4)
    affine[:3, :3] = rot @ np.diag(sizes)
    affine[:3, 3] = [-4.0, 3.0, 10.0]
    img = nib.Nifti1Image(d, affine)
    nib.save(img, tmp_path / "oblique.nii.gz")
    ours = dvr.load_volume(tmp_path / "oblique.nii.gz")
    theirs = processing.resample_to_output(img, voxel_sizes=tuple(sizes), order=1)
    expect = theirs.get_fdata().T
    assert ours.shape == expect.shape
    assert np.allclose(ours.to_patient[:3, 3], theirs.affine[:3, 3], atol=1e-4)
    # Array axes (z, y, x) step along S, A, R by nibabel's output voxel sizes.
    assert np.allclose(ours.to_patient[:3, :3], np.fliplr(np.diag(sizes)))
    # Where nibabel's grid lies inside the input's box (the rest is fill).
    idx = np.stack(np.meshgrid(*[np.arange(n) for n in theirs.shape], indexing="ij"), -1).reshape(-1, 3)
    src = (np.linalg.inv(affine) @ theirs.affine @ np.c_[idx, np.ones(len(idx))].T)[:3].T
    inside = np.all((src >= 0) & (src <= np.array(d.shape) - 1), axis=1).reshape(theirs.shape).T
    assert inside.sum() > 0.3 * inside.size
    assert np.abs(ours.data[inside] - expect[inside]).max() < 1e-3


def test_a_dicom_ct_keeps_its_hounsfield_window(tmp_path):
    stored = np.linspace(0, 3000, NX * NY * NZ).reshape(NX, NY, NZ).astype(np.uint16)
    _write_dicom_lps(tmp_path / "ct", stored, slope=1.0, intercept=-1024.0)
    v = dvr.load_volume(tmp_path / "ct")
    assert v.window == pytest.approx((-1024.0, 1976.0))


def _ct(background, top):
    """A CT in HU: a soft-tissue ball (40 HU) around a bone core (1000 HU), in air or fat
    (``background``); ``top`` sets the maximum (one voxel inside the core)."""
    n = 24
    z, y, x = np.mgrid[:n, :n, :n] / (n - 1) - 0.5
    r = np.sqrt(x * x + y * y + z * z)
    hu = np.full((n, n, n), background, dtype=np.int16)
    hu[r < 0.42] = 40
    hu[r < 0.2] = 1000
    hu[n // 2, n // 2, n // 2] = top
    return dvr.Volume(hu)


def test_the_ct_bone_preset_shows_bone_whatever_the_cts_range():
    wide, narrow = _ct(-1024, 3071), _ct(-120, 1500)
    assert wide.window != narrow.window
    cam = dvr.Camera(position=(0.0, 2.0, 0.0), fov_y_degrees=35.0)

    def render(vol, tf):
        with dvr.Renderer(dvr.Scene(vol, tf=tf, camera=cam, ), size=(32, 32), spp=4, denoisers=[]) as r:
            return r.render()["noisy"].mean(axis=2)

    centre = (slice(13, 19), slice(13, 19))  # the bone core's pixels
    rim = (slice(15, 17), slice(3, 6))  # soft tissue only, beside the core
    corner = (slice(0, 3), slice(0, 3))  # the environment only
    for vol in (wide, narrow):
        img = render(vol, "ct-bone")
        assert img[centre].mean() > img[corner].mean() + 0.15, vol.window
        # Soft tissue is transparent under ct-bone: its pixels are the background's.
        assert abs(img[rim].mean() - img[corner].mean()) < 0.03, vol.window
    bone_wide, bone_narrow = render(wide, "ct-bone"), render(narrow, "ct-bone")
    dens_wide, dens_narrow = render(wide, "phantom-opaque"), render(narrow, "phantom-opaque")
    # In HU the two CTs look alike; in normalised density they do not.
    assert np.abs(bone_wide - bone_narrow).mean() < 0.25 * np.abs(dens_wide - dens_narrow).mean()

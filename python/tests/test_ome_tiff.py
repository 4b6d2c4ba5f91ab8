"""OME-TIFF input: z-stacks written by tifffile load with the shape, spacing and voxels
tifffile reports; channels past the first are left out with a warning; plain page stacks
load with 1 mm voxels; bad files get clear errors."""

import numpy as np
import pytest
import tifffile

import dvr


def stack(shape=(12, 20, 28), dtype=np.uint16) -> np.ndarray:
    z, y, x = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    return (z * 97 + y * 13 + x * 3 + (x * y) % 7).astype(dtype)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.float32])
@pytest.mark.parametrize("compression", [None, "zlib"])
def test_a_stack_loads_as_tifffile_reads_it(tmp_path, dtype, compression):
    path = tmp_path / "cells.ome.tif"
    meta = {"axes": "ZYX", "PhysicalSizeX": 0.25, "PhysicalSizeY": 0.5, "PhysicalSizeZ": 2.0}
    tifffile.imwrite(path, stack(dtype=dtype), ome=True, metadata=meta, compression=compression)
    with tifffile.TiffFile(path) as tif:
        array = tif.series[0].asarray()
        pixels = tifffile.xml2dict(tif.ome_metadata)["OME"]["Image"]["Pixels"]
    spacing_mm = tuple(pixels[f"PhysicalSize{a}"] * 1e-3 for a in "ZYX")  # µm by default
    v = dvr.load_volume(path)
    assert v.shape == array.shape
    assert v.spacing == pytest.approx(spacing_mm, rel=1e-6)
    assert np.array_equal(v.to_numpy(), dvr.Volume(array, spacing=spacing_mm).to_numpy())
    assert v.name == "cells"


def test_channel_zero_is_read_whatever_the_page_order(tmp_path):
    data = np.stack([stack(), stack()[::-1] + 1])  # C, Z, Y, X
    path = tmp_path / "two.ome.tif"
    tifffile.imwrite(path, data, ome=True, metadata={"axes": "CZYX", "PhysicalSizeZ": 3.0, "PhysicalSizeZUnit": "mm"})
    v = dvr.load_volume(path)
    assert v.shape == data.shape[1:]
    assert v.spacing[0] == pytest.approx(3.0)
    assert np.array_equal(v.to_numpy(), dvr.Volume(data[0]).to_numpy())
    zc = tmp_path / "zc.ome.tif"  # channels run faster than z: XYCZT
    tifffile.imwrite(zc, np.moveaxis(data, 0, 1), ome=True, metadata={"axes": "ZCYX"})
    assert np.array_equal(dvr.load_volume(zc).to_numpy(), dvr.Volume(data[0]).to_numpy())


def test_a_plain_page_stack_loads_with_millimetre_voxels(tmp_path):
    path = tmp_path / "plain.tif"
    for z in stack():
        tifffile.imwrite(path, z, append=True)
    v = dvr.load_volume(path)
    assert v.shape == (12, 20, 28) and v.spacing == (1.0, 1.0, 1.0)
    assert np.array_equal(v.to_numpy(), dvr.Volume(stack()).to_numpy())


def test_bad_tiffs_are_named(tmp_path):
    rgb = tmp_path / "rgb.tif"
    tifffile.imwrite(rgb, np.zeros((4, 5, 3), np.uint8), photometric="rgb")
    with pytest.raises(ValueError, match=r"rgb\.tif.*RGB"):
        dvr.load_volume(rgb)
    cut = tmp_path / "cut.ome.tif"
    tifffile.imwrite(cut, stack(), ome=True, metadata={"axes": "ZYX"})
    cut.write_bytes(cut.read_bytes()[: cut.stat().st_size // 2])
    with pytest.raises(ValueError, match=r"cut\.ome\.tif"):
        dvr.load_volume(cut)
    mixed = tmp_path / "mixed.tif"
    tifffile.imwrite(mixed, np.zeros((4, 5), np.uint8))
    tifffile.imwrite(mixed, np.zeros((6, 5), np.uint8), append=True)
    with pytest.raises(ValueError, match=r"mixed\.tif.*page 1 is not 5x4"):
        dvr.load_volume(mixed)
    wide = tmp_path / "wide.tif"
    tifffile.imwrite(wide, np.zeros((2, 4200), np.uint8))
    with pytest.raises(ValueError, match=r"wide\.tif.*4200 exceeds 4096"):
        dvr.load_volume(wide)

"""OME-Zarr input: images written by the ome-zarr and zarr packages (OME-Zarr 0.5 on Zarr
v3, OME-NGFF 0.4 on Zarr v2) load at each resolution level with the shape, spacing and
voxels those packages report; bad metadata, missing chunks and unknown codecs get clear
messages; an image's `labels/` group is a scene's label map."""

import json
import pathlib
import shutil
import subprocess

import numpy as np
import pytest
import zarr
from ome_zarr.format import FormatV04, FormatV05
from ome_zarr.io import parse_url
from ome_zarr.reader import Multiscales, Reader
from ome_zarr.writer import write_image, write_labels

import dvr

MM_PER = {"micrometer": 1e-3, "millimeter": 1.0, "nanometer": 1e-6}
FORMATS = {"0.5": FormatV05(), "0.4": FormatV04()}


def image(shape=(20, 24, 32)) -> np.ndarray:
    """A uint16 volume with structure along every axis (a wrong axis order shows)."""
    z, y, x = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    return (z * 97 + y * 13 + x * 3 + (x * y) % 7).astype(np.uint16)


def write(path: pathlib.Path, version: str, data: np.ndarray) -> pathlib.Path:
    fmt = FORMATS[version]
    root = zarr.group(store=parse_url(str(path), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
    write_image(
        image=data, group=root, fmt=fmt, axes="zyx",
        scale_factors=[{"z": 2, "y": 2, "x": 2}, {"z": 4, "y": 4, "x": 4}],
        scale={"z": 2.0, "y": 0.5, "x": 0.25}, axes_units={a: "micrometer" for a in "zyx"},
    )  # fmt: skip
    return path


def levels_as_ome_zarr_reads_them(path: pathlib.Path):
    """(level path, array, spacing in mm (z, y, x)) per level, from ome-zarr's reader."""
    (node,) = [n for n in Reader(parse_url(str(path)))() if n.load(Multiscales)]
    meta = node.metadata
    units = [MM_PER[a["unit"]] for a in meta["axes"]]
    out = []
    for i, ds in enumerate(meta["coordinateTransformations"]):
        (scale,) = [t["scale"] for t in ds if t["type"] == "scale"]
        level_path = node.zarr.root_attrs.get("ome", node.zarr.root_attrs)["multiscales"][0]["datasets"][i]["path"]
        out.append((level_path, np.asarray(node.data[i]), tuple(s * u for s, u in zip(scale, units))))
    return out


@pytest.mark.parametrize("version", ["0.5", "0.4"])
def test_every_level_loads_as_the_ome_zarr_package_reads_it(tmp_path, version):
    path = write(tmp_path / "img.zarr", version, image())
    levels = levels_as_ome_zarr_reads_them(path)
    assert [a.shape for _, a, _ in levels] == [(20, 24, 32), (10, 12, 16), (5, 6, 8)]
    for level_path, array, spacing in levels:
        v = dvr.load_volume(path / level_path)
        assert v.shape == array.shape, level_path
        assert v.spacing == pytest.approx(spacing, rel=1e-6), level_path
        # The voxels, in the same order, normalised as an array of the same values is.
        assert np.array_equal(v.to_numpy(), dvr.Volume(array, spacing=spacing).to_numpy()), level_path
    whole = dvr.load_volume(path)
    assert whole.shape == levels[0][1].shape, "the finest level fits: it is the one read"
    assert whole.name == "img"


def test_the_finest_level_that_fits_one_texture_is_read(tmp_path):
    """A level wider than 4096 voxels cannot be one 3D texture: the next one is read, and
    the log says so."""
    root = zarr.open_group(str(tmp_path / "wide.zarr"), mode="w", zarr_format=3)
    big = root.create_array("0", shape=(2, 4, 5000), chunks=(2, 4, 1000), dtype="uint8")
    big[:] = 1
    small = root.create_array("1", shape=(1, 2, 2500), chunks=(1, 2, 2500), dtype="uint8")
    small[:] = np.arange(5000, dtype=np.uint8).reshape(1, 2, 2500)
    root.attrs["ome"] = {
        "version": "0.5",
        "multiscales": [{
            "axes": [{"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"],
            "datasets": [
                {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0, 1.0]}]},
                {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [2.0, 2.0, 2.0]}]},
            ],
        }],
    }  # fmt: skip
    v = dvr.load_volume(tmp_path / "wide.zarr")
    assert v.shape == (1, 2, 2500) and v.spacing == (2.0, 2.0, 2.0)
    with pytest.raises(ValueError, match="5000 exceeds 4096"):
        dvr.load_volume(tmp_path / "wide.zarr" / "0")


def edit_json(path: pathlib.Path, edit) -> None:
    meta = json.loads(path.read_text())
    edit(meta)
    path.write_text(json.dumps(meta))


def test_bad_metadata_missing_chunks_and_unknown_codecs_are_named(tmp_path):
    good = write(tmp_path / "good.zarr", "0.5", image((8, 8, 8)))

    def variant(name, edit_file, edit):
        p = tmp_path / name
        shutil.copytree(good, p)
        edit_json(p / edit_file, edit)
        return p

    no_multiscales = variant("plain.zarr", "zarr.json", lambda m: m["attributes"].pop("ome"))
    with pytest.raises(ValueError, match=r"plain\.zarr.*multiscales"):
        dvr.load_volume(no_multiscales)
    two_d = variant("flat.zarr", "zarr.json", lambda m: m["attributes"]["ome"]["multiscales"][0].update(
        axes=[{"name": "y", "type": "space"}, {"name": "x", "type": "space"}]))  # fmt: skip
    with pytest.raises(ValueError, match=r"flat\.zarr.*axes \[y, x\].*3D"):
        dvr.load_volume(two_d)
    bad_scale = variant("scale.zarr", "zarr.json", lambda m: m["attributes"]["ome"]["multiscales"][0]["datasets"][0]
                        .update(coordinateTransformations=[{"type": "scale", "scale": [1.0, -1.0, 1.0]}]))  # fmt: skip
    with pytest.raises(ValueError, match=r"scale\.zarr.*not positive"):
        dvr.load_volume(bad_scale)
    with pytest.raises(ValueError, match=r"s7 is not one of the image's levels \(s0, s1, s2\)"):
        shutil.copytree(good / "s0", good / "s7")
        dvr.load_volume(good / "s7")
    codec = variant("codec.zarr", "s0/zarr.json", lambda m: m["codecs"].append({"name": "lzma9000"}))
    with pytest.raises(ValueError, match=r"codec\.zarr.*lzma9000"):
        dvr.load_volume(codec / "s0")
    # A chunk file gone reads as the fill value (Zarr's rule: writers skip chunks that
    # hold only it), with a warning counting them; a chunk cut short is an error.
    gone = tmp_path / "gone.zarr"
    shutil.copytree(good, gone)
    (chunk,) = [p for p in (gone / "s0").rglob("*") if p.is_file() and p.name != "zarr.json"]
    chunk.unlink()
    assert dvr.load_volume(gone / "s0").to_numpy().max() == 0.0
    cut = tmp_path / "cut.zarr"
    shutil.copytree(good, cut)
    (chunk,) = [p for p in (cut / "s0").rglob("*") if p.is_file() and p.name != "zarr.json"]
    chunk.write_bytes(chunk.read_bytes()[:5])
    with pytest.raises(ValueError, match=r"cut\.zarr"):
        dvr.load_volume(cut / "s0")


def test_the_finest_level_within_the_memory_budget_is_read(tmp_path):
    """With a budget (the renderer's --gpu-memory), the finest level whose voxels fit it
    is read; with none fitting, the coarsest (the renderer pages it)."""
    data = image((64, 128, 128))  # uint16: 2 MiB, then 256 KiB and 32 KiB
    path = write(tmp_path / "img.zarr", "0.5", data)
    assert dvr.load_volume(path).shape == (64, 128, 128)
    assert dvr.load_volume(path, gpu_memory="2M").shape == (64, 128, 128)
    assert dvr.load_volume(path, gpu_memory="1M").shape == (32, 64, 64)
    assert dvr.load_volume(path, gpu_memory="64K").shape == (16, 32, 32)
    with pytest.raises(ValueError, match="gpu_memory"):
        dvr.load_volume(path, gpu_memory="lots")


@pytest.mark.parametrize("version", ["0.5", "0.4"])
def test_a_labels_group_written_by_ome_zarr_is_the_scenes_label_map(tmp_path, version, dvr_bin):
    """An image with a `labels/` group (ome-zarr-py's `write_labels`, its `image-label`
    colours and names): `[labels] file` naming the image takes its first label image,
    with the table its metadata holds; the labels render, hide and pick."""
    fmt = FORMATS[version]
    data = image()
    seg = np.zeros(data.shape, np.uint8)
    seg[4:10, 5:12, 6:14] = 1
    seg[10:16, 5:12, 6:14] = 7
    path = tmp_path / "img.zarr"
    root = zarr.group(store=parse_url(str(path), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
    write_image(image=data, group=root, fmt=fmt, axes="zyx")
    write_labels(
        seg, root, "seg", fmt=fmt, axes="zyx",
        label_metadata={
            "colors": [{"label-value": 1, "rgba": [255, 0, 0, 255]}, {"label-value": 7, "rgba": [0, 128, 255, 128]}],
            "properties": [{"label-value": 1, "name": "tumour"}, {"label-value": 7, "name": "oedema"}],
        },
    )  # fmt: skip
    scene = tmp_path / "s.toml"
    scene.write_text(
        f'[volume]\nfile = "{path}"\n[transfer]\na = "ct-bone"\n[labels]\nfile = "{path}"\nmode = "solid"\n'
        '[[light]]\nkind = "environment"\nintensity = 1.0\n'
    )
    r = dvr.Renderer(dvr.Scene.load(str(scene)), size=(24, 24), denoisers=[])
    assert [(lab.value, lab.name) for lab in r.labels] == [(1, "tumour"), (7, "oedema")]
    assert r.labels[1].colour == pytest.approx((1.0, 0.0, 0.0))
    assert r.labels[7].opacity == pytest.approx(128 / 255)
    shown = r.render()["noisy"]
    r.labels.hide_all()
    hidden = r.render(reset=True)["noisy"]
    assert np.abs(shown - hidden).mean() > 1e-3
    out = subprocess.run([str(dvr_bin), "info", str(path), "--labels"], capture_output=True, text=True, check=True).stdout
    assert "1: tumour (colour FF0000" in out and "7: oedema (colour 0080FF" in out, out

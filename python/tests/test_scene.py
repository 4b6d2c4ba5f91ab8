"""Scenes and transfer functions from Python: the CLI's scenes, defaults, edits, and the
engine's messages for bad input."""

import numpy as np
import pytest

import dvr


def test_builtin_and_file_scenes_open(root):
    names = dvr.builtin_scenes()
    assert "phantom/orbit" in names and "mri/point-light" in names
    s = dvr.Scene.builtin("phantom/orbit")
    assert s.name == "phantom/orbit" and s.frames >= 48
    assert s.data["volume"]["builtin"] == "phantom"
    v = dvr.Scene.load(root / "assets/scenes/validation/mri-layered-orbit.toml")
    assert v.name == "val/mri-layered-orbit" and v.frames == 48


def test_a_numpy_scene_has_defaults_and_checks():
    vol = dvr.Volume(np.zeros((8, 8, 8), np.uint8))
    s = dvr.Scene(vol)
    checked = s.check()
    assert checked["camera"]["fov_y_degrees"] == 40.0
    assert any(l["kind"] == "point" for l in checked["light"])
    s.frames = 12
    s.orbit(degrees_per_frame=3.0)
    assert s.check()["animation"]["frames"] == 12
    s.camera = dvr.Camera(position=(0.0, 2.0, 0.0), fov_y_degrees=30.0)
    assert s.camera.fov_y_degrees == 30.0


def test_bad_scene_values_carry_the_engines_message():
    s = dvr.Scene.builtin("phantom/orbit")
    s.data["render"]["spp"] = 0
    with pytest.raises(ValueError, match="spp"):
        s.check()
    s = dvr.Scene.builtin("phantom/orbit")
    s.data["camera"]["posiiton"] = [0, 1, 0]
    with pytest.raises(ValueError, match="posiiton"):
        s.check()
    s = dvr.Scene.builtin("phantom/orbit")
    s.data["camera"]["position"] = [0.0, float("nan"), 0.0]
    with pytest.raises(ValueError, match="position"):
        s.check()
    with pytest.raises(ValueError, match="no-such"):
        dvr.Scene.builtin("no-such/scene")
    with pytest.raises(TypeError, match="camera"):
        s.data["camera"]["position"] = [0.0, object(), 0.0]
        s.check()


def test_transfer_functions():
    assert "phantom-opaque" in dvr.TransferFunction.presets()
    tf = dvr.TransferFunction.preset("mri-opaque")
    assert len(tf.points) >= 3
    arr = np.array([[0.0, 1, 1, 1, 0.0], [0.5, 1, 0.5, 0.2, 1.0], [1.0, 1, 1, 1, 1.0]])
    tf = dvr.TransferFunction.from_array(arr)
    assert tf.points[1]["diffuse"] == [1.0, 0.5, 0.2]
    with pytest.raises(ValueError, match=r"\(N, 5\)"):
        dvr.TransferFunction.from_array(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="opacity"):
        dvr.TransferFunction.from_array([[0.0, 1, 1, 1, 0.0], [1.0, 1, 1, 1, 2.0]])
    with pytest.raises(ValueError, match="no-such-tf"):
        dvr.TransferFunction.preset("no-such-tf")


def test_transfer_function_files(root, tmp_path):
    preset = dvr.TransferFunction.preset("mri-opaque")
    loaded = dvr.TransferFunction.load(root / "assets/transfer/mri-opaque.toml")
    assert loaded.points == preset.points
    (tmp_path / "bad.toml").write_text('name = "x"\n[[point]]\ndensity = 0.5\nopacity = 2.0\ndiffuse = [1, 1, 1]\n')
    with pytest.raises(ValueError, match="bad.toml"):
        dvr.TransferFunction.load(tmp_path / "bad.toml")

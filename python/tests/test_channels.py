"""Channels and time points live from Python: ``r.channels[i]`` fields and ``r.time``
are edits, a time set by hand renders what the scene's time keyframes render, and bad
values are errors naming the field."""

import os

import numpy as np
import pytest

import dvr

SCENES = os.path.join(os.path.dirname(__file__), "..", "..", "assets", "scenes", "development")


def scene(name):
    return dvr.Scene.load(os.path.join(SCENES, name))


def test_time_set_by_hand_renders_what_the_keyframes_render():
    s = scene("shell-beat-still.toml")
    keyed = dvr.Renderer(s, size=(24, 24), denoisers=["ours"])
    by_hand = dvr.Renderer(s, size=(24, 24), denoisers=["ours"])
    assert keyed.times == 24 and keyed.time == 0.0
    for f in range(6):
        a = keyed.render(frame=f)
        by_hand.time = keyed.time
        b = by_hand.render()
        assert keyed.time == pytest.approx(f * 23 / 47)
        for method in ("noisy", "ours"):
            assert np.array_equal(a[method], b[method]), (f, method)
    with pytest.raises(ValueError, match="outside the time points 0 to 23"):
        by_hand.time = 24.5


def test_a_channel_switched_off_leaves_the_other_alone():
    r = dvr.Renderer(scene("mri-statmap-light.toml"), size=(32, 32), denoisers=[])
    names = [c.name for c in r.channels]
    assert names == ["mni152_t1", "mni152_statmap"]
    both = r.render()["noisy"]
    r.channels[1].visible = False
    assert r.channels[1].visible is False
    t1_only = r.render(reset=True)["noisy"]
    assert np.abs(both - t1_only).mean() > 1e-3, "the map's clusters show"
    r.channels[1].visible = True
    r.channels[0].colour = (1.0, 0.5, 0.25)
    assert r.channels[0].colour == (1.0, 0.5, 0.25)
    tinted = r.render(reset=True)["noisy"]
    red, blue = tinted[..., 0].mean(), tinted[..., 2].mean()
    assert red > blue, "the T1 tinted orange"
    with pytest.raises(ValueError, match=r"channel\[1\].window"):
        r.channels[1].window = (5.0, 1.0)
    with pytest.raises(ValueError, match="channel 2 does not exist"):
        dvr.channels.Channel(r._r, 2).visible = False
    with pytest.raises(dvr.FieldError):
        r.channels[0].name = "t2"


def test_a_volume_of_one_field_has_no_channels_and_one_time_point():
    r = dvr.Renderer("phantom/orbit", size=(16, 16), denoisers=[])
    assert r.channels == [] and r.times == 1 and r.time == 0.0
    with pytest.raises(ValueError, match="outside the time points 0 to 0"):
        r.time = 1


def test_an_array_of_channels_renders_their_sum():
    # Two channels each holding 0.4 of a cube render like one channel holding 0.8 under a
    # TF whose opacity is the density (extinction adds).
    n = 16
    ramp = dvr.TransferFunction.from_array([(0.0, 0.8, 0.8, 0.8, 0.0), (1.0, 0.8, 0.8, 0.8, 1.0)], "ramp")
    whole = np.full((n, n, n), 0.8, np.float32)
    halves = np.stack([np.full((n, n, n), 0.4, np.float32)] * 2)
    vol = dvr.Volume(halves)
    assert vol.channels == 2 and vol.times == 1 and vol.channel_names == ["channel 0", "channel 1"]
    assert np.allclose(vol.channel(1).data, 0.4)

    def mean(volume):
        r = dvr.Renderer(dvr.Scene(volume, tf=ramp), size=(24, 24), denoisers=[])
        if r.channels:
            for c in r.channels:
                c.tf = ramp
        return r.reference(spp=256).mean()

    a, b = mean(whole), mean(vol)
    assert abs(a - b) < 0.02 * a, (a, b)


def test_an_array_of_time_points_plays():
    n = 12
    frames = np.zeros((3, 1, n, n, n), np.uint8)
    for t in range(3):
        frames[t, 0, : 4 * (t + 1)] = 200  # a slab that grows
    r = dvr.Renderer(dvr.Volume(frames), size=(16, 16), denoisers=[])
    assert r.times == 3 and r.channels == []
    first = r.reference(spp=64)
    r.time = 2
    last = r.reference(spp=64)
    assert np.abs(first - last).mean() > 1e-3
    with pytest.raises(ValueError, match="5 channels"):
        dvr.Volume(np.zeros((5, 4, 4, 4), np.uint8))
    assert dvr.Volume(np.zeros((5, 4, 4, 4), np.uint8), channels=[0, 3]).channels == 2
    with pytest.raises(ValueError, match="dimension"):
        dvr.Volume(np.zeros((2, 2, 2, 2, 2, 2), np.uint8))


def test_a_statistical_map_lands_where_nilearn_resamples_it():
    image = pytest.importorskip("nilearn.image")
    nib = pytest.importorskip("nibabel")
    volumes = os.path.join(os.path.dirname(__file__), "..", "..", "assets", "volumes")
    t1, zmap = (os.path.join(volumes, f) for f in ("mni152_t1.nii.gz", "mni152_statmap.nii.gz"))
    series = dvr.Volume.load_series([t1, zmap])
    assert series.channels == 2 and series.channel_names == ["mni152_t1", "mni152_statmap"]
    ours = series.channel(1)
    lo, hi = ours.window
    ours_data = lo + ours.data * (hi - lo)  # density back to z
    theirs = image.resample_to_img(zmap, t1, interpolation="linear", force_resample=True, copy_header=True)
    theirs_data = np.asarray(theirs.get_fdata(), np.float64).T  # [i, j, k] -> [z, y, x]
    assert ours_data.shape == theirs_data.shape
    span = float(np.ptp(nib.load(zmap).get_fdata()))
    err = np.abs(ours_data - theirs_data)
    assert err.max() <= 1e-3 * span, (err.max(), span, np.unravel_index(err.argmax(), err.shape))

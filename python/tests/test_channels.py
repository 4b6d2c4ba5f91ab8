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

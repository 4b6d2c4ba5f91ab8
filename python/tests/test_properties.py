"""Property tests of the Python surface (Hypothesis): arrays of any dtype, shape, stride
and value, random scene dicts and TF arrays, random sizes, spp and frame numbers. Every
outcome is a result or a ValueError/TypeError that names what was wrong: never a crash,
a hang, a validation message or a silent wrong image.

Examples per property: the "ci" profile (a few thousand in all, cheap properties get
more); `DVR_HYPOTHESIS=nightly` runs ten times as many. Counterexamples found are kept
as named regression tests in test_regressions.py.
"""

import copy
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import dvr

SCALE = 10 if os.environ.get("DVR_HYPOTHESIS") == "nightly" else 1
FAST = settings(max_examples=600 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SLOW = settings(max_examples=40 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])

DTYPES = [
    "bool", "int8", "uint8", "int16", "uint16", ">u2", "<i2", "int32", "int64", "uint64",
    "float16", "float32", ">f4", "float64", "complex64", "object",
]


def refused(e, *words):
    """A refusal must say what it refuses: one of `words` in the message."""
    msg = str(e)
    assert msg and any(w in msg for w in words), f"{type(e).__name__}: {msg!r} names none of {words}"


@st.composite
def arrays(draw):
    dtype = np.dtype(draw(st.sampled_from(DTYPES)))
    ndim = draw(st.integers(1, 4))
    shape = tuple(draw(st.lists(st.integers(0, 5), min_size=ndim, max_size=ndim)))
    if dtype.kind == "O":
        a = np.empty(shape, dtype=object)
        a[...] = draw(st.sampled_from([None, 1, "x", 1.5]))
    else:
        a = draw(hnp.arrays(dtype, shape, elements=hnp.from_dtype(dtype, allow_nan=True, allow_infinity=True)
                            if dtype.kind in "fc" else None))
    view = draw(st.sampled_from(["plain", "reversed", "strided", "transposed", "broadcast"]))
    if a.ndim >= 1 and a.size:
        if view == "reversed":
            a = a[::-1]
        elif view == "strided":
            a = a[..., ::2]
        elif view == "transposed":
            a = a.T
        elif view == "broadcast" and a.ndim == 3:
            # A huge axis without the memory: a zero-stride view past 4096 voxels.
            a = np.broadcast_to(a[:1], (5000,) + a.shape[1:])
    return a


spacings = st.tuples(*[st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-3, 3))] * 3)


@FAST
@given(arrays(), spacings)
def test_any_array_is_a_volume_or_a_named_refusal(a, spacing):
    try:
        v = dvr.Volume(a, spacing=spacing)
    except (ValueError, TypeError) as e:
        refused(e, "array", "spacing", "dtype", "shape", "voxels")
        return
    # Accepted: a 3-D array (or [c, z, y, x] channels, at most 4) of a volume type,
    # densities in [0, 1] and finite (float64 arrays are volumes too).
    assert a.ndim in (3, 4) and a.dtype in (np.uint8, np.uint16, np.int16, np.float32, np.float64)
    if a.ndim == 4:
        assert v.channels == a.shape[0] <= 4 and v.times == 1
    d = v.to_numpy()
    assert d.shape == a.shape[-3:] and np.isfinite(d).all() and d.min() >= 0 and d.max() <= 1
    assert all(math.isfinite(s) and s > 0 for s in v.spacing)


tf_rows = hnp.arrays(
    np.float64,
    st.tuples(st.integers(0, 6), st.integers(3, 6)),
    elements=st.floats(-2, 2) | st.sampled_from([math.nan, math.inf, -math.inf]),
)


@FAST
@given(tf_rows)
def test_any_tf_array_is_a_transfer_function_or_a_named_refusal(rows):
    try:
        tf = dvr.TransferFunction.from_array(rows)
    except (ValueError, TypeError) as e:
        refused(e, "transfer function", "point", "density", "opacity", "diffuse")
        return
    a = np.asarray(rows)
    assert a.shape[1] == 5 and np.isfinite(a).all()
    assert all(0 <= p["opacity"] <= 1 for p in tf.points)


def junk():
    return st.one_of(
        st.none(), st.booleans(), st.integers(-10**12, 10**12), st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=5), st.lists(st.floats(-5, 5), max_size=4), st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    )


BASE = dvr.Scene.builtin("cloud/point-light").data


def leaves(d, path=()):
    if isinstance(d, dict):
        for k, v in d.items():
            yield from leaves(v, path + (k,))
    elif isinstance(d, list) and d and isinstance(d[0], dict):
        for i, v in enumerate(d):
            yield from leaves(v, path + (i,))
    else:
        yield path


LEAVES = list(leaves(BASE))


@FAST
@given(st.lists(st.tuples(st.sampled_from(LEAVES), junk()), min_size=1, max_size=3))
def test_any_edited_scene_dict_checks_or_is_a_named_refusal(edits):
    data = copy.deepcopy(BASE)
    for path, value in edits:
        d = data
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value
    s = dvr.Scene.builtin("cloud/point-light")
    s.data = data
    try:
        checked = s.check()
    except (ValueError, TypeError) as e:
        names = {str(k) for path, _ in edits for k in path if isinstance(k, str)}
        refused(e, "scene", *names)
        return
    assert isinstance(checked, dict) and checked["animation"]["frames"] >= 1


@st.composite
def images(draw):
    dtype = draw(st.sampled_from([np.float32, np.float64, np.int32, np.uint8]))
    shape = draw(st.tuples(st.integers(0, 6), st.integers(0, 6), st.integers(1, 4)))
    if np.dtype(dtype).kind == "f":
        elements = st.floats(-1, 10, width=32) | st.sampled_from([0.5, math.nan, math.inf])
    else:
        elements = st.integers(0, 200)
    return draw(hnp.arrays(dtype, shape, elements=elements))


@FAST
@given(images(), images())
def test_any_image_pair_scores_or_is_a_named_refusal(a, b):
    # Each score is finite and in its metric's range: PSNR is capped for identical
    # images (as the eval caps it), SSIM lies in [-1, 1] and FLIP in [0, 1].
    ranges = {dvr.metrics.psnr: (0.0, 100.0), dvr.metrics.ssim: (-1.0, 1.0), dvr.metrics.flip: (0.0, 1.0)}
    for f, (lo, hi) in ranges.items():
        try:
            score = f(a, b)
        except (ValueError, TypeError) as e:
            refused(e, "reference", "test", "image", "dtype", "shape", "size")
            continue
        assert math.isfinite(score) and lo <= score <= hi, (f.__name__, score)


@pytest.fixture(scope="module")
def volume():
    return dvr.Volume.builtin("cloud", 16)


@SLOW
@given(
    size=st.tuples(st.one_of(st.integers(-2, 40), st.floats(-1, 40), st.just(10**6)), st.integers(-2, 40)),
    spp=st.one_of(st.none(), st.integers(-2, 10), st.just(10**12)),
    frames=st.lists(st.one_of(st.none(), st.integers(-3, 12), st.just(2**40)), min_size=1, max_size=3),
)
def test_any_size_spp_and_frame_renders_or_is_a_named_refusal(volume, size, spp, frames):
    scene = dvr.Scene(volume, frames=8)
    try:
        r = dvr.Renderer(scene, size=size, spp=spp, denoisers=["taa"])
    except (ValueError, TypeError) as e:
        refused(e, "size", "width", "height", "spp")
        return
    with r:
        for f in frames:
            try:
                out = r.render(frame=f)
            except (ValueError, TypeError) as e:
                refused(e, "frame")
                assume(True)
                continue
            assert out["taa"].shape == (r.size[1], r.size[0], 3) and np.isfinite(out["taa"]).all()

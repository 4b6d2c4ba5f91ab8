"""Counterexamples the property tests (test_properties.py) found, each kept as a named
test so it stays fixed."""

import pytest

import dvr


def test_a_whole_number_past_64_bits_in_a_scene_is_a_value_error_naming_it():
    # Was OverflowError ("Python int too large to convert to C long"), naming nothing.
    s = dvr.Scene.builtin("cloud/point-light")
    s.data["animation"]["frames"] = {"": 2**63}
    with pytest.raises(ValueError, match=r"scene\[\"animation\"\]\[\"frames\"\]\[\"\"\]: 9223372036854775808 is out of range"):
        s.check()

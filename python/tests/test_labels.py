"""Label edits live from Python: ``r.labels[v]`` fields are edits that render what the
scene's ``[[animation.label]]`` keys render (the viewer's labels panel makes the same
edits)."""

import numpy as np

import dvr

SCENE = """
name = "labelled"
[volume]
builtin = "phantom"
size = 48
[transfer]
a = "ct-bone"
[labels]
builtin = "phantom"
mode = "{mode}"
[[light]]
kind = "environment"
intensity = 1.0
[animation]
frames = 3
"""


def test_a_label_edited_by_hand_renders_what_the_keyframes_render(tmp_path):
    for mode in ("tint", "solid"):
        plain = tmp_path / f"plain-{mode}.toml"
        plain.write_text(SCENE.format(mode=mode))
        keyed = tmp_path / f"keyed-{mode}.toml"
        keyed.write_text(SCENE.format(mode=mode) + "[[animation.label]]\nvalue = 2\nframe = 1\nvisible = false\n")
        a, b, c = (dvr.Renderer(dvr.Scene.load(p), size=(24, 24), denoisers=["ours"]) for p in (keyed, plain, plain))
        shown = []
        for f in range(3):
            x = a.render(frame=f)
            if f == 1:
                b.labels[2].visible = False
            y = b.render()
            shown.append(b.labels[2].visible)
            for method in ("noisy", "ours"):
                assert np.array_equal(x[method], y[method]), (mode, f, method)
            # Beside a renderer left alone: the edit changed what was drawn.
            z = c.render()
            assert np.array_equal(y["noisy"], z["noisy"]) == (f == 0), (mode, f)
        assert shown == [True, False, False]
        for r in (a, b, c):
            r.close()

"""What :class:`dvr.Viewer`'s labels panel and picking take and show, kept apart from
the widget: the page's label edits checked (a label the map has, a colour and an
opacity in [0, 1], a bool), kept as pending edits whose newest value wins, applied by
the render thread through the Python label API (:class:`dvr.labels.Labels`: the same
edits a cell makes, which the denoisers follow); the renderer's labels read as the
panel lists them; and a pick (a pixel of the rendered image) answered from
:meth:`dvr.Renderer.pick` as the readout shows it."""

import math

from . import viewer_panel as panel

_LABEL_FIELDS = {"colour", "opacity", "visible"}
# The key of a show-all or hide-all among the pending label edits (label values are
# ints, so it is never a label's).
ALL = "all"


def label_edit(msg, values):
    """``(value, fields)`` from a ``{"type": "label", "value", ...}`` message, its
    fields among ``colour`` (three numbers in [0, 1]), ``opacity`` (a number in [0, 1])
    and ``visible`` (a bool); else the reason it is refused. ``values``: the map's
    label values."""
    value = msg.get("value")
    if isinstance(value, bool) or not isinstance(value, int) or value not in values:
        return f"value {value!r} is not a label of the map"
    unknown = set(msg) - _LABEL_FIELDS - {"type", "value", "seq"}
    if unknown:
        return f"unknown field(s) {', '.join(sorted(map(str, unknown)))}"
    fields = {}
    if "visible" in msg:
        if not isinstance(msg["visible"], bool):
            return f"visible {msg['visible']!r} is not true or false"
        fields["visible"] = msg["visible"]
    if "colour" in msg:
        c = msg["colour"]
        rgb = [panel.number(x, 1.0) for x in c] if isinstance(c, list) and len(c) == 3 else [None]
        if any(x is None or x < 0.0 for x in rgb):
            return f"colour {c!r} is not three numbers in [0, 1]"
        fields["colour"] = tuple(rgb)
    if "opacity" in msg:
        o = panel.number(msg["opacity"], 1.0)
        if o is None or o < 0.0:
            return f"opacity {msg['opacity']!r} is not a number in [0, 1]"
        fields["opacity"] = o
    if not fields:
        return f"nothing to edit (fields: {', '.join(sorted(_LABEL_FIELDS))})"
    return value, fields


def pick_pixel(msg, width, height):
    """``(x, y)`` of a ``{"type": "pick", "x", "y"}`` message: whole numbers within the
    rendered image (row 0 at the top); else the reason it is refused."""
    x, y = msg.get("x"), msg.get("y")
    for v in (x, y):
        if isinstance(v, bool) or not isinstance(v, int):
            return f"pixel ({x!r}, {y!r}) is not two whole numbers"
    if not (0 <= x < width and 0 <= y < height):
        return f"pixel ({x}, {y}) is outside the {width}x{height} image"
    return x, y


def read(renderer, has_labels):
    """``{"labels": the renderer's label rows}`` where the viewer shows a labels panel
    (else nothing). The render thread reads it under its lock, with the frame."""
    return {"labels": rows(renderer._r.labels()[1])} if has_labels else {}


def rows(labels):
    """The labels panel's rows: each label's value, name, colour, opacity, visible."""
    return [
        {
            "value": int(d["value"]),
            "name": d["name"],
            "colour": [float(x) for x in d["colour"]],
            "opacity": float(d["opacity"]),
            "visible": bool(d["visible"]),
        }
        for d in labels
    ]


def apply(renderer, edits):
    """Applies the page's label edits (the render thread, before a frame): a show-all
    or hide-all first (it came before every per-label visibility still pending, see
    :func:`on_message`), then each label's fields. Raises ``ValueError`` as the label
    API does."""
    pending = edits.get("labels")
    if not pending:
        return
    labels = renderer.labels
    if ALL in pending:
        if pending[ALL]["visible"]:
            labels.show_all()
        else:
            labels.hide_all()
    for value, fields in sorted((v, f) for v, f in pending.items() if v != ALL):
        try:
            label = labels[value]
        except KeyError as e:
            raise ValueError(str(e)) from None
        for name in ("colour", "opacity", "visible"):
            if name in fields:
                setattr(label, name, fields[name])


def picked(result, x, y, seq):
    """The readout of :meth:`dvr.Renderer.pick`'s ``result`` at pixel ``(x, y)``: the
    label's value and name, the intensity (data units; ``None`` where the volume has
    none there), the voxel and the world position; ``hit`` false where the ray met
    nothing. ``seq``: the page's message it answers."""
    out = {"x": x, "y": y, "seq": seq, "hit": result is not None}
    if result is None:
        return out
    intensity = float(result["intensity"])
    out.update(
        label=int(result["label"]),
        label_name=result["label_name"],
        # (NaN is no JSON: the page's readout says "–".)
        intensity=intensity if math.isfinite(intensity) else None,
        voxel=[int(v) for v in result["voxel"]],
        position=[round(float(p), 5) for p in result["position"]],
    )
    return out


def on_message(viewer, kind, msg, seq):
    """A ``label``, ``labels`` (show or hide all) or ``pick`` message from the page (the
    kernel's message thread): checked here, then kept for the render thread. A refusal
    is said in the status line."""
    if kind == "label":
        got = label_edit(msg, viewer._label_values)
        if isinstance(got, str):
            viewer.status = f"refused a label edit from the page: {got}"
            return
        viewer._pending.merge("labels", *got, seq)
    elif kind == "labels":
        if not viewer._label_values:
            viewer.status = "refused a label edit from the page: the renderer has no label map"
            return
        if not isinstance(msg.get("visible"), bool) or set(msg) - {"type", "visible", "seq"}:
            viewer.status = "refused a label edit from the page: show or hide all takes visible (true or false) only"
            return

        def every(pending):
            # Shown or hidden all: every per-label visibility before it is superseded;
            # colours and opacities still go.
            for value, fields in list(pending.items()):
                fields.pop("visible", None)
                if not fields:
                    del pending[value]
            pending[ALL] = {"visible": msg["visible"]}

        viewer._pending.edit("labels", every, seq)
    else:
        got = pick_pixel(msg, viewer.width, viewer.height)
        if isinstance(got, str):
            viewer.status = f"refused a pick from the page: {got}"
            return
        viewer._pending.set("pick", (*got, seq), seq)


def pick(renderer, request):
    """The readout of a pick at ``request`` (``(x, y, seq)``, checked by
    :func:`pick_pixel`), or the reason it failed (the renderer's size changed since
    the page's frame, say)."""
    x, y, seq = request
    try:
        return picked(renderer.pick(x, y), x, y, seq)
    except (ValueError, RuntimeError) as e:
        return f"pick at ({x}, {y}) failed: {e}"

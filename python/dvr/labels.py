"""The labels of a renderer's label map as it shows them: a mapping from label value to
a live view whose fields are edits (``r.labels[3].visible = False``)."""

from .live import _Item, _rgb, item_field

__all__ = ["Label", "Labels"]


class Label(_Item):
    """Label ``value`` of a renderer's label map: its ``name``, ``colour`` (RGB in [0, 1]:
    the tint of the intensity TF inside it, or its colour as solid tissue), ``opacity``
    (in [0, 1], scaling the medium's extinction inside it) and ``visible`` (a hidden
    label is empty medium). Reading a field reads the renderer's current view; assigning
    one is an edit the next render re-traces, as a TF edit (``ValueError`` names a bad
    value)."""

    _FIELDS = ("value", "name", "colour", "opacity", "visible")
    _SETTABLE = ("colour", "opacity", "visible")

    def __init__(self, native, value):
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "_value", value)

    def _get(self):
        for d in self._native.labels()[1]:
            if d["value"] == self._value:
                return d
        raise KeyError(self._value)

    def _edit(self, **change):
        self._native.edit_label(self._value, **change)

    def _what(self):
        return f"label {self._value}"

    @property
    def value(self) -> int:
        return self._value

    name = item_field("name")
    colour = item_field("colour", _rgb, tuple)
    color = colour
    opacity = item_field("opacity", float)
    visible = item_field("visible", bool)

    def __repr__(self):
        d = self._get()
        return (
            f"Label({d['value']}, {d['name']!r}, colour={tuple(round(c, 3) for c in d['colour'])}, "
            f"opacity={d['opacity']:.3g}, visible={d['visible']})"
        )


class Labels:
    """The labels of a renderer's label map by value (empty without one): ``r.labels[3]``
    is a live :class:`Label`; ``len``, ``in``, iteration (over :class:`Label` s in value
    order), :meth:`values`, :meth:`find` (by name), :meth:`show_all` and
    :meth:`hide_all`. ``mode`` is ``"tint"`` or ``"solid"`` (``None`` without a map)."""

    def __init__(self, native):
        self._native = native

    def _values(self):
        return [d["value"] for d in self._native.labels()[1]]

    @property
    def mode(self):
        return self._native.labels()[0]

    def values(self) -> list:
        """The label values, ascending."""
        return self._values()

    def __len__(self):
        return len(self._values())

    def __contains__(self, value):
        return value in self._values()

    def __iter__(self):
        return iter([Label(self._native, v) for v in self._values()])

    def __getitem__(self, value):
        if not isinstance(value, int) or isinstance(value, bool):
            raise TypeError(f"labels[{value!r}]: a label value is an int")
        values = self._values()
        if value not in values:
            raise KeyError(f"label {value} is not in the map (it has {values})")
        return Label(self._native, value)

    def find(self, text) -> list:
        """The labels whose name contains ``text`` (case-insensitive)."""
        t = str(text).lower()
        return [Label(self._native, d["value"]) for d in self._native.labels()[1] if t in d["name"].lower()]

    def show_all(self):
        """Shows every label (one edit)."""
        self._native.edit_label(None, visible=True)

    def hide_all(self):
        """Hides every label (one edit)."""
        self._native.edit_label(None, visible=False)

    def __repr__(self):
        return f"Labels(mode={self.mode!r}, {len(self)} labels)"

"""Live views of view state: the camera, the lights and the render settings of a
:class:`dvr.Renderer` (edits of its session) or of a :class:`dvr.Scene` (edits of its
dict).

Every object handed out is either a live view or immutable. Assigning an attribute of a
view applies at once (``r.camera.position = (0, 2, 0)`` is an edit the next render
reprojects); the values a view returns are tuples and numbers, so assigning into one
(``r.camera.position[0] = 1``) raises ``TypeError`` instead of being silently lost.
"""

from collections.abc import Sequence

import numpy as np

__all__ = ["FieldError", "CameraView", "ClipView", "ClipsView", "CropView", "LightView", "LightsView", "SettingsView"]


class FieldError(AttributeError, ValueError):
    """A field that does not exist (a mistyped attribute of a volume, scene, camera or
    light, or key of a TF point): an ``AttributeError`` that names the fields there
    are, also a ``ValueError`` where a dict's key was the bad input."""


# The keys each kind of [[light]] takes (engine/scene/src/light.rs, LightFile).
LIGHT_FIELDS = {
    "point": ("kind", "position", "colour", "intensity"),
    "area": ("kind", "position", "target", "normal", "size", "colour", "intensity"),
    "environment": ("kind", "mode", "colour", "top", "bottom", "map", "intensity"),
}


def _frozen(value):
    """A section value as returned to the user: lists become tuples, recursively."""
    if isinstance(value, list):
        return tuple(_frozen(v) for v in value)
    if isinstance(value, dict):
        return {k: _frozen(v) for k, v in value.items()}
    return value


def _plain(value):
    """A value as the engine takes it: arrays and tuples become lists of floats."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _as_dict(obj, what):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if hasattr(obj, "to_dict"):
        return obj.to_dict()
    raise TypeError(f"{what}: expected a {what} object or a dict, got {type(obj).__name__}")


def _rgb(c):
    r, g, b = (float(x) for x in c)
    return (r, g, b)


class _Item:
    """A live view of one item a renderer lists (a channel, a label): fields read from
    ``self._get()`` (the item's dict in the renderer's current view) and assigned through
    ``self._edit(field=value)`` (one edit). Subclasses name their settable ``_SETTABLE``
    and all their ``_FIELDS``; ``color`` is ``colour``."""

    _FIELDS: tuple = ()
    _SETTABLE: tuple = ()

    def _get(self) -> dict:
        raise NotImplementedError

    def _edit(self, **change):
        raise NotImplementedError

    def __setattr__(self, name, value):
        if name == "color":
            name = "colour"
        if name not in self._SETTABLE:
            fixed = [f for f in self._FIELDS if f not in self._SETTABLE]
            raise FieldError(
                f"{self._what()} has no settable field {name!r} (fields: {', '.join(self._FIELDS)}; "
                f"{' and '.join(fixed)} {'is' if len(fixed) == 1 else 'are'} read-only)"
            )
        object.__setattr__(self, name, value)

    def _what(self) -> str:
        raise NotImplementedError


def item_field(name, coerce=None, read=None, doc=None):
    """A field of an :class:`_Item`: read from its dict (through ``read``), assigned as an
    edit of ``coerce(value)``; read-only without ``coerce``."""

    def get(self):
        v = self._get()[name]
        return read(v) if read else v

    def put(self, value):
        self._edit(**{name: coerce(value)})

    return property(get, put if coerce else None, doc=doc)


class _Section:
    """A dict-valued section behind a getter and a setter; attribute writes replace one
    key and hand the whole section to the setter (which checks it)."""

    _fields: tuple = ()

    def __init__(self, get, put, what):
        object.__setattr__(self, "_get", get)
        object.__setattr__(self, "_put", put)
        object.__setattr__(self, "_what", what)

    def to_dict(self) -> dict:
        """A copy of the section as a plain dict."""
        return dict(self._get())

    def update(self, **fields):
        """Sets several fields in one edit."""
        d = dict(self._get())
        for k, v in fields.items():
            self._check_field(k)
            d[k] = _plain(v)
        self._put(d)

    def _check_field(self, name):
        if self._fields and name not in self._fields:
            raise FieldError(f"{self._what} has no field {name!r} (fields: {', '.join(self._fields)})")

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        d = self._get()
        if name in d:
            return _frozen(d[name])
        if name in self._fields:
            return None
        fields = self._fields or tuple(d)
        raise FieldError(f"{self._what} has no field {name!r} (fields: {', '.join(fields)})")

    def __setattr__(self, name, value):
        self.update(**{name: value})

    def __eq__(self, other):
        if isinstance(other, _Section):
            return self._get() == other._get()
        if isinstance(other, dict):
            return self._get() == other
        return NotImplemented

    def __repr__(self):
        fields = ", ".join(f"{k}={_frozen(v)!r}" for k, v in self._get().items())
        return f"{type(self).__name__}({fields})"


class CameraView(_Section):
    """The camera, live: ``position``, ``target``, ``up`` (world units; the volume's
    longest side spans 1, centred on the origin) and ``fov_y_degrees``."""

    _fields = ("position", "target", "up", "fov_y_degrees")


class SettingsView(_Section):
    """The render settings (a scene file's ``[render]``), live: ``spp``,
    ``max_bounces``, ``estimator``, ``phase``, ``hg_g``, ``russian_roulette_depth``,
    ``step_size``, ``emission``, ``seed``, ``filter_sigma``, ``feature_threshold``;
    also as items (``settings["spp"] = 2``). A change restarts every history;
    ``estimator``, ``phase`` and ``emission`` build a new renderer."""

    def __getitem__(self, key):
        return self.__getattr__(key)

    def __setitem__(self, key, value):
        self.update(**{key: value})

    def keys(self):
        """The section's field names (as a dict's ``keys()``)."""
        return self._get().keys()


class LightView(_Section):
    """One light, live (``kind`` and that kind's fields: ``position``, ``colour``,
    ``intensity``; an area light's ``target``, ``normal``, ``size``; an environment's
    ``mode``, ``top``, ``bottom``, ``map``)."""

    @property
    def _fields(self):
        # A light's fields depend on its kind: a point light has no `size`.
        return LIGHT_FIELDS.get(self._get().get("kind"), ())

    def update(self, **fields):
        """Sets several of the light's fields in one edit (``color`` is read as
        ``colour``)."""
        if "color" in fields:
            fields["colour"] = fields.pop("color")
        d = dict(self._get())
        allowed = LIGHT_FIELDS.get(fields.get("kind", d.get("kind")), ())
        for k in fields:
            if allowed and k not in allowed:
                raise FieldError(f"{self._what} ({d.get('kind')} light) has no field {k!r} (fields: {', '.join(allowed)})")
        d.update({k: _plain(v) for k, v in fields.items()})
        self._put(d)

    def __getattr__(self, name):
        if name == "color":
            name = "colour"
        return super().__getattr__(name)


class ClipView(_Section):
    """One clip plane, live: ``point`` (world units), ``normal`` (the half-space behind
    it is removed) and ``enabled``."""

    _fields = ("point", "normal", "enabled")

    def __getattr__(self, name):
        if name == "enabled":
            return self._get().get("enabled", True)
        return super().__getattr__(name)

    def flip(self):
        """Keeps what was removed and removes what was kept."""
        self.normal = tuple(-x for x in self.normal)


class CropView(_Section):
    """The crop box, live: ``min`` and ``max`` corners (in the volume's frame, -0.5 to
    0.5 per axis, or voxel indices with ``units = "voxels"``) and ``enabled``."""

    _fields = ("min", "max", "units", "enabled")

    def __getattr__(self, name):
        if name == "enabled":
            return self._get().get("enabled", True)
        if name == "units":
            return self._get().get("units", "box")
        return super().__getattr__(name)


class _ListView(Sequence):
    """A live list of dict-valued items: ``view[i]`` is a live item view;
    ``view[i] = item`` replaces one, ``append`` adds one, ``del view[i]`` removes
    one."""

    _item = None
    _noun = "item"

    def __init__(self, get, put, what):
        self._get, self._put, self._what = get, put, what

    def __len__(self):
        return len(self._get())

    def __getitem__(self, i):
        n = len(self)
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(n))]
        if not isinstance(i, (int, np.integer)) or not -n <= i < n:
            raise IndexError(f"{self._what}[{i!r}]: there are {n} {self._noun}(s)")
        i = int(i) % n

        def get():
            return self._get()[i]

        def put(d):
            items = [dict(x) for x in self._get()]
            items[i] = d
            self._put(items)

        return self._item(get, put, f"{self._what}[{i}]")

    def __setitem__(self, i, item):
        items = [dict(x) for x in self._get()]
        items[i] = _as_dict(item, self._noun)
        self._put(items)

    def __delitem__(self, i):
        items = [dict(x) for x in self._get()]
        del items[i]
        self._put(items)

    def append(self, item):
        self._put([dict(x) for x in self._get()] + [_as_dict(item, self._noun)])

    def clear(self):
        self._put([])

    def to_list(self) -> list:
        """A copy as plain dicts."""
        return [dict(x) for x in self._get()]

    def __eq__(self, other):
        if isinstance(other, _ListView):
            return self._get() == other._get()
        if isinstance(other, list):
            return self._get() == other
        return NotImplemented

    def __repr__(self):
        return f"{type(self).__name__}({self._get()!r})"


class LightsView(_ListView):
    """The lights, live: ``lights[i]`` is a :class:`LightView`; ``lights[i] = light``
    replaces one, ``append`` adds one, ``del lights[i]`` removes one."""

    _item = LightView
    _noun = "light"

    def __init__(self, get, put, what="lights"):
        super().__init__(get, put, what)


class ClipsView(_ListView):
    """The clip planes, live (at most 6): ``clip[i]`` is a :class:`ClipView`;
    ``clip.append(dvr.ClipPlane(point, normal))`` adds one, ``del clip[i]`` removes
    one."""

    _item = ClipView
    _noun = "clip plane"

    def __init__(self, get, put, what="clip"):
        super().__init__(get, put, what)

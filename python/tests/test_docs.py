"""Every public name of the package has a docstring: the book's Python API reference is
generated from them (pdoc, in tools/test.sh), so an undocumented name is a hole in it."""

import inspect

import dvr


def _public_members(obj):
    for name, member in vars(obj).items():
        if name.startswith("_"):
            continue
        yield name, member


def _undocumented():
    missing = []
    for name in dvr.__all__:
        obj = getattr(dvr, name)
        if not inspect.getdoc(obj):
            missing.append(f"dvr.{name}")
        if inspect.isclass(obj):
            for member_name, member in _public_members(obj):
                target = member.fget if isinstance(member, property) else member
                if callable(target) or isinstance(member, property):
                    if not (getattr(target, "__doc__", None) or "").strip():
                        missing.append(f"dvr.{name}.{member_name}")
        elif inspect.ismodule(obj):
            for member_name in getattr(obj, "__all__", []):
                if not inspect.getdoc(getattr(obj, member_name)):
                    missing.append(f"dvr.{name}.{member_name}")
    return missing


def test_every_public_name_has_a_docstring():
    assert _undocumented() == []


def test_the_check_sees_an_undocumented_name(monkeypatch):
    def undocumented():
        pass

    monkeypatch.setattr(dvr, "undocumented", undocumented, raising=False)
    monkeypatch.setattr(dvr, "__all__", [*dvr.__all__, "undocumented"])
    assert "dvr.undocumented" in _undocumented()

"""The installed package describes itself: `pip show dvr` has the summary, and the long
description (PyPI's page) is python/README.md, the same file the book's Python page
includes."""

import importlib.metadata
import re


def test_metadata_has_the_summary_and_the_readme(root):
    meta = importlib.metadata.metadata("dvr")
    pyproject = (root / "python/pyproject.toml").read_text()
    summary = re.search(r'^description = "(.*)"$', pyproject, re.M).group(1)
    assert meta["Summary"] == summary
    readme = (root / "python/README.md").read_text()
    body = meta.get_payload() or meta.get("Description", "")
    assert body.strip() == readme.strip()
    assert meta["Description-Content-Type"].startswith("text/markdown")


def test_the_book_includes_the_package_readme(root):
    page = (root / "docs/src/python.md").read_text()
    assert "{{#include ../../python/README.md}}" in page

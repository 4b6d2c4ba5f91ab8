"""The installed package describes itself: `pip show dvr` has the summary, and the long
description (PyPI's page) is python/README.md, the same file the book's Python page
includes."""

import importlib.metadata
import re

import pytest


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
    # The built book (tools/test.sh builds it before these tests) shows every section
    # of the guide on its Python page.
    built = root / "docs/book/python.html"
    if not built.is_file():
        pytest.skip("the book is not built (mdbook build docs)")
    html = built.read_text()
    headings = re.findall(r"^## (.+)$", (root / "python/README.md").read_text(), re.M)
    assert len(headings) >= 5
    for h in headings:
        assert h.replace("&", "&amp;") in html, f"the book's Python page lacks the section {h!r}"


def _copy_docs(root, dest):
    import shutil

    for rel in ("tools/results.py", "tools/results_io.py", "README.md"):
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(root / rel, dest / rel)
    for rel in ("docs/src", "assets/results", "assets/rae", "assets/scenes/validation"):
        shutil.copytree(root / rel, dest / rel, ignore=shutil.ignore_patterns("*.bin"))


def test_results_pages_are_current_and_a_changed_csv_makes_them_stale(root, tmp_path):
    """tools/results.py --check passes on the checkout, and fails once a CSV changes."""
    import subprocess
    import sys

    _copy_docs(root, tmp_path)
    script = tmp_path / "tools/results.py"
    ok = subprocess.run([sys.executable, str(script), "--check"], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    csv = tmp_path / "assets/results/validation/summary.csv"  # README's headline
    rows = csv.read_text().splitlines()
    ours = next(i for i, r in enumerate(rows) if ",ours," in r)
    cells = rows[ours].split(",")
    cells[2] = f"{float(cells[2]) + 1.0:.4f}"
    rows[ours] = ",".join(cells)
    csv.write_text("\n".join(rows) + "\n")
    stale = subprocess.run([sys.executable, str(script), "--check"], capture_output=True, text=True)
    assert stale.returncode == 1
    assert "stale" in stale.stderr and "README.md" in stale.stderr

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


def _expand_includes(page, seen=()):
    """A book page with mdBook's `{{#include path}}` directives replaced by the files they
    name (paths relative to the page), as mdBook renders it."""
    def sub(m):
        target = (page.parent / m.group(1)).resolve()
        assert target.is_file(), f"{page.name} includes {m.group(1)}, which does not exist"
        assert target not in seen, f"{page.name} includes {m.group(1)} recursively"
        return _expand_includes(target, seen + (target,))

    return re.sub(r"\{\{#include ([^}\s]+)\}\}", sub, page.read_text())


def _slug(heading):
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip()).lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def test_the_book_includes_the_package_readme(root):
    page = root / "docs/src/python.md"
    readme = (root / "python/README.md").read_text()
    expanded = _expand_includes(page)
    # The whole guide is on the book's Python page, once.
    assert expanded.count(readme.strip()) == 1
    # Its links work in both places it is read: the README's own anchors and relative
    # paths from python/ (GitHub), and the same text on the book's page from docs/src/.
    text = re.sub(r"```.*?```", "", expanded, flags=re.S)
    anchors = {_slug(h) for h in re.findall(r"^#{1,6}\s+(.+?)\s*$", text, re.M)}
    own = {_slug(h) for h in re.findall(r"^#{1,6}\s+(.+?)\s*$",
                                       re.sub(r"```.*?```", "", readme, flags=re.S), re.M)}
    for link in re.findall(r"\]\(([^)\s]+)\)", re.sub(r"```.*?```", "", readme, flags=re.S)):
        if re.match(r"^[a-z][a-z0-9+.-]*:", link):
            continue
        target, _, frag = link.partition("#")
        if not target:
            assert frag in own, f"python/README.md links to #{frag}, no heading of its own"
            assert frag in anchors, f"#{frag} has no heading on the book's Python page"
        else:
            assert (root / "python" / target).exists(), f"python/README.md: broken link {link}"
            assert (page.parent / target).exists(), f"the book's Python page: broken link {link}"


def test_the_built_book_shows_every_section_of_the_package_readme(root):
    # tools/test.sh builds the book before these tests.
    readme = (root / "python/README.md").read_text()
    built = root / "docs/book/python.html"
    if not built.is_file():
        pytest.skip("the book is not built (mdbook build docs)")
    html = built.read_text()
    headings = re.findall(r"^## (.+)$", readme, re.M)
    assert len(headings) >= 5
    for h in headings:
        assert h.replace("&", "&amp;") in html, f"the book's Python page lacks the section {h!r}"


def _copy_docs(root, dest):
    import shutil

    for rel in [str(p.relative_to(root)) for p in sorted(root.glob("tools/results*.py"))] + ["README.md"]:
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

    def stale_after(rel, key, column, delta):
        """--check after adding `delta` to `column` of the first row of `rel` holding `key`."""
        csv = tmp_path / "assets/results" / rel
        rows = csv.read_text().splitlines()
        i = next(i for i, r in enumerate(rows) if key in r)
        cells = rows[i].split(",")
        cells[column] = f"{float(cells[column]) + delta:.6f}"
        rows[i] = ",".join(cells)
        csv.write_text("\n".join(rows) + "\n")
        return subprocess.run([sys.executable, str(script), "--check"], capture_output=True, text=True)

    stale = stale_after("validation/summary.csv", ",ours,", 2, 1.0)  # README's headline
    assert stale.returncode == 1
    assert "stale" in stale.stderr and "README.md" in stale.stderr
    # A chart is checked as a page is: a changed frame makes the interaction curves stale.
    stale = stale_after("interaction/metrics.csv", ",ours,3,", 3, -3.0)
    assert "interaction/curves.svg is stale" in stale.stderr

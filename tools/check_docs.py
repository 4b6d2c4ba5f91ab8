#!/usr/bin/env python3
"""Offline checks of the documentation (Python standard library only; tools/test.sh runs it).

1. The built book (docs/book, from `mdbook build docs`): every relative link and image in
   every page points at a file that exists, and every #anchor at an id in that file.
   Pages link to the repository's files as ../../<path>, which resolves from both
   docs/src/ (where the Markdown is read) and docs/book/ (where the HTML is). Images
   are the book's own: every image resolves inside the built book, checked in docs/book
   and in a book built into a temporary folder (`mdbook build docs -d <tmp>`), where a
   path out of the book finds nothing (tools/book_images.py links them in).
2. The Markdown outside the book (README.md, OVERVIEW.md, CHANGELOG.md, python/README.md):
   the same for their relative links, anchors by GitHub's heading slugs.
3. OVERVIEW.md names every tracked source file by a path that resolves to it alone
   (its full path, or its path from the folder its section or table row stands in; see
   `named_files`), so the walk through the code stays whole.
4. README.md stays the front door: at most 200 lines.
5. The code stays in pieces one can read whole: no tracked source file (`*.rs`, `*.py`,
   `*.sh`, `*.glsl`) over 800 lines, and no cell of an OVERVIEW.md table over 600
   characters (a longer one becomes rows of its own).

    tools/check_docs.py [--book docs/book] [--no-book]

Exits 1 naming every broken link, missing anchor, unnamed file, long file and long cell.
"""

import argparse
import html.parser
import os
import posixpath
import re
import subprocess
import sys
import tempfile
import urllib.parse

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
MARKDOWN = ["README.md", "OVERVIEW.md", "CHANGELOG.md", "python/README.md"]
# Tracked files OVERVIEW.md must name: source, shaders, tests, tools, the Python package.
SOURCE_DIRS = ["src", "engine/src", "engine/volume/src", "engine/scene/src", "engine/scene/tests", "engine/metrics/src", "engine/glsl-build", "engine/tests",
               "shaders", "tests", "tools", "python/src", "python/dvr", "python/tests",
               "python/examples", "fuzz/src"]
SOURCE_EXCLUDE = ["tests/fixtures/"]
README_LINES = 200
SOURCE_SUFFIXES = (".rs", ".py", ".sh", ".glsl")
SOURCE_LINES = 800
CELL_CHARS = 600


class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links = []
        self.images = []
        self.ids = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name"):
            if a.get(key):
                self.ids.add(a[key])
        for key in ("href", "src"):
            if a.get(key) is not None and tag in ("a", "img", "link", "script", "source"):
                self.links.append(a[key])
        if tag in ("img", "source") and a.get("src"):
            self.images.append(a["src"])


def parse_html(path, cache={}):
    if path not in cache:
        p = Links()
        with open(path, encoding="utf-8") as f:
            p.feed(f.read())
        cache[path] = p
    return cache[path]


def external(link):
    return bool(re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", link)) or link.startswith("//")


def book_pages(book):
    """The book's HTML pages; the API reference (cargo doc, pdoc) is generated with its
    own links: the book's links into it are checked, its own pages are not walked."""
    pages = []
    for d, dirs, files in os.walk(book):
        if os.path.relpath(d, book) == ".":
            dirs[:] = [x for x in dirs if x != "api"]
        pages += [os.path.join(d, f) for f in files if f.endswith(".html")]
    return sorted(pages)


def check_images(book):
    """Every image of the book's pages is a file inside the book: a built book is a
    folder that stands alone, wherever it was built."""
    errors = []
    book = os.path.realpath(book)
    for page in book_pages(book):
        for src in parse_html(page).images:
            if external(src) or src.startswith("data:"):
                continue
            target = urllib.parse.unquote(src.partition("#")[0])
            path = os.path.normpath(os.path.join(os.path.dirname(page), target))
            if os.path.relpath(path, book).startswith("..") or not os.path.isfile(path):
                errors.append(f"{os.path.relpath(page, book)}: image {src} is not in the "
                              f"built book ({book})")
    return errors


def check_book_elsewhere():
    """The book built into a temporary folder (`mdbook build docs -d <tmp>`, from the
    repository's root as its preprocessor needs): every image is there."""
    with tempfile.TemporaryDirectory(prefix="dvr-book-") as tmp:
        out = os.path.join(tmp, "book")
        try:
            subprocess.run(["mdbook", "build", "docs", "-d", out], cwd=ROOT, check=True,
                           capture_output=True, text=True)
        except FileNotFoundError:
            return ["mdbook is not installed (tools/setup.sh --tests installs it); "
                    "--no-book skips the book"]
        except subprocess.CalledProcessError as e:
            return [f"mdbook build docs -d {out} failed: {e.stderr.strip()}"]
        return [f"book built elsewhere: {e}" for e in check_images(out)]


def check_book(book):
    if not os.path.isdir(book):
        return [f"{os.path.relpath(book, ROOT)}: not built (mdbook build docs)"]
    errors = check_images(book)
    for page in book_pages(book):
        rel = os.path.relpath(page, ROOT)
        for link in parse_html(page).links:
            if not link or external(link):
                continue
            target, _, frag = link.partition("#")
            target = urllib.parse.unquote(target)
            path = page if not target else os.path.normpath(os.path.join(os.path.dirname(page), target))
            if os.path.isdir(path):
                path = os.path.join(path, "index.html")
            if not os.path.exists(path):
                errors.append(f"{rel}: broken link {link}")
                continue
            if frag and path.endswith(".html"):
                if urllib.parse.unquote(frag) not in parse_html(path).ids:
                    errors.append(f"{rel}: no anchor #{frag} in {os.path.relpath(path, ROOT)}")
    return errors


def slug(heading):
    """GitHub's anchor for a Markdown heading."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip()).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def md_anchors(path, cache={}):
    if path not in cache:
        anchors, seen, fence = set(), {}, False
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("```"):
                    fence = not fence
                m = None if fence else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
                if m:
                    s = slug(m.group(1))
                    n = seen.get(s, 0)
                    seen[s] = n + 1
                    anchors.add(s if n == 0 else f"{s}-{n}")
        cache[path] = anchors
    return cache[path]


def check_markdown(rel):
    errors = []
    path = os.path.join(ROOT, rel)
    if not os.path.exists(path):
        return [f"{rel}: missing"]
    with open(path, encoding="utf-8") as f:
        text = f.read()
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    links = re.findall(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", text)
    links += re.findall(r"(?:href|src)=\"([^\"]+)\"", text)
    for link in links:
        if external(link):
            continue
        target, _, frag = link.partition("#")
        tpath = path if not target else os.path.normpath(os.path.join(os.path.dirname(path), target))
        if not os.path.exists(tpath):
            errors.append(f"{rel}: broken link {link}")
            continue
        if frag and tpath.endswith(".md") and frag not in md_anchors(tpath):
            errors.append(f"{rel}: no heading for #{frag} in {os.path.relpath(tpath, ROOT)}")
    return errors


TOKEN = re.compile(r"`([^`\n]+)`")


def tracked_files():
    """Every file git tracks, repository-relative; None outside a git checkout."""
    try:
        return set(subprocess.run(["git", "ls-files"], cwd=ROOT, check=True,
                                  capture_output=True, text=True).stdout.split())
    except (OSError, subprocess.CalledProcessError):
        return None


def _join(folder, rel):
    return posixpath.normpath(posixpath.join(folder, rel)) if folder else posixpath.normpath(rel)


def named_files(overview, tracked):
    """The tracked files OVERVIEW.md names, each by a path that resolves to it alone.

    A backticked path names a file when it resolves to exactly one tracked file against
    the folders its line stands in: the section's folder (a heading that starts with a
    folder, `## engine/volume — …`, else the repository root), the folder a table row's
    first cell names in it (`src/` there), and every folder the line names below those
    (`eval/`, then `plan/`); a full repository path names its file wherever it resolves
    against none of them. A path that resolves to several files (`mod.rs` in a row
    naming `profile/` and `bench/`) names none of them: write `profile/mod.rs`."""
    dirs = {"/".join(f.split("/")[:i]) for f in tracked for i in range(1, f.count("/") + 1)}
    named, heading = set(), ""
    for line in overview.splitlines():
        if line.startswith("#"):
            heading = line
            continue
        m = re.match(r"^#+\s+(\S+)", heading)
        section = m.group(1).strip("/") if m and m.group(1).strip("/") in dirs else ""
        folders = {section}
        cells = re.split(r"(?<!\\)\|", line) if line.startswith("|") else []
        if len(cells) > 2:
            for t in TOKEN.findall(cells[1]):
                if t.endswith("/") and _join(section, t) in dirs:
                    folders.add(_join(section, t))
                    break
        tokens = [t for t in TOKEN.findall(line) if " " not in t]
        grown = True
        while grown:
            grown = False
            for t in (t for t in tokens if t.endswith("/")):
                for g in list(folders) + [""]:
                    p = _join(g, t)
                    if p in dirs and p not in folders:
                        folders.add(p)
                        grown = True
        for t in (t for t in tokens if not t.endswith("/")):
            found = {_join(g, t) for g in folders} & tracked
            if not found and t in tracked:
                found = {t}
            if len(found) == 1:
                named |= found
    return named


def names(overview, path, tracked=None):
    """Whether OVERVIEW.md names `path` by a path that resolves to it alone (see
    `named_files`)."""
    tracked = tracked_files() if tracked is None else tracked
    return path in named_files(overview, tracked or {path})


def check_overview():
    tracked = tracked_files()
    if tracked is None:
        print("check_docs: not a git checkout; OVERVIEW.md's coverage not checked", file=sys.stderr)
        return []
    files = sorted(f for f in tracked if any(f.startswith(d + "/") for d in SOURCE_DIRS))
    with open(os.path.join(ROOT, "OVERVIEW.md"), encoding="utf-8") as f:
        named = named_files(f.read(), tracked)
    missing = [f for f in files
               if not any(f.startswith(x) for x in SOURCE_EXCLUDE)
               # Links (python/dvr/assets/ into assets/) are named by the files they reach.
               and not os.path.islink(os.path.join(ROOT, f))
               and f not in named]
    return [f"OVERVIEW.md: does not name {f}" for f in missing]


def check_sizes(tracked):
    """Every tracked source file within SOURCE_LINES lines, every OVERVIEW.md table cell
    within CELL_CHARS characters."""
    errors = []
    for f in sorted(tracked or ()):
        full = os.path.join(ROOT, f)
        if not f.endswith(SOURCE_SUFFIXES) or os.path.islink(full) or not os.path.isfile(full):
            continue
        with open(full, encoding="utf-8", errors="replace") as fh:
            lines = len(fh.read().splitlines())
        if lines > SOURCE_LINES:
            errors.append(f"{f}: {lines} lines, over {SOURCE_LINES}: split it into modules "
                          "named for what they hold")
    with open(os.path.join(ROOT, "OVERVIEW.md"), encoding="utf-8") as fh:
        for n, line in enumerate(fh.read().splitlines(), 1):
            if not line.startswith("|"):
                continue
            for i, cell in enumerate(re.split(r"(?<!\\)\|", line)[1:-1], 1):
                if len(cell.strip()) > CELL_CHARS:
                    errors.append(f"OVERVIEW.md:{n}: column {i} is {len(cell.strip())} characters, "
                                  f"over {CELL_CHARS}: give its parts rows of their own")
    return errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--book", default=os.path.join(ROOT, "docs", "book"))
    ap.add_argument("--no-book", action="store_true", help="skip the built book")
    args = ap.parse_args()
    errors = [] if args.no_book else check_book(args.book) + check_book_elsewhere()
    for rel in MARKDOWN:
        errors += check_markdown(rel)
    errors += check_overview()
    errors += check_sizes(tracked_files())
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        lines = len(f.read().splitlines())
    if lines > README_LINES:
        errors.append(f"README.md: {lines} lines, over {README_LINES}: move the detail into the book")
    for e in errors:
        print(f"check_docs: {e}", file=sys.stderr)
    if errors:
        return 1
    print("check_docs: links, anchors, OVERVIEW.md's file list, README's length and the "
          "sizes of source files and OVERVIEW.md's cells are fine")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""mdBook preprocessor (docs/book.toml): every image of the book resolves inside the built book.

Pages show the repository's images as `../../assets/<path>`, which resolves from docs/src/
(where the Markdown is read, on GitHub too) but points out of a built book: a book built
into another folder (`mdbook build docs -d /elsewhere`) would lose them. For each such
image this links `docs/src/assets/<path>` to the repository's file (a generated folder
git ignores; every build makes it again and drops links no page uses) and rewrites the
reference to that link. mdBook copies what a link points at, so the built book holds its
images and each file keeps its one home in the repository.

mdBook runs it as `book_images.py supports <renderer>`, then with `[context, book]` as
JSON on stdin and the book expected on stdout. No dependencies beyond the standard
library.
"""

import json
import os
import re
import sys

# A Markdown image `![alt](target)` or an HTML `src="target"`: group 1 is what comes
# before the target, group 2 the target.
IMAGE = re.compile(r"(!\[[^\]]*\]\(\s*|\bsrc=\")([^)\s\"]+)")
# The folder of the repository whose files pages may show, and its generated twin in src.
SHOWN = "assets"


def rewrite(content, chapter_dir, src, repo):
    """`content` with every image that resolves into the repository's `assets/` from
    `chapter_dir` (a folder under `src`) pointed at its twin under `src/assets/`; returns
    the new content and the set of repository-relative paths it shows."""
    shown = set()

    def one(m):
        target = m.group(2)
        if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:|^/|^#", target):
            return m.group(0)
        path = os.path.normpath(os.path.join(chapter_dir, target))
        rel = os.path.relpath(path, repo)
        inside_src = not os.path.relpath(path, src).startswith("..")
        if inside_src or rel.split(os.sep)[0] != SHOWN:
            return m.group(0)
        shown.add(rel)
        twin = os.path.relpath(os.path.join(src, rel), chapter_dir)
        return m.group(1) + twin.replace(os.sep, "/")

    return IMAGE.sub(one, content), shown


def link_shown(src, repo, shown):
    """Makes `src/assets/<p>` a relative link to the repository's `<p>` for each `p` in
    `shown`, and removes links under `src/assets/` that no page shows."""
    for rel in sorted(shown):
        source = os.path.join(repo, rel)
        if not os.path.isfile(source):
            raise SystemExit(f"book_images: {rel}: a page shows it, but it does not exist")
        link = os.path.join(src, rel)
        os.makedirs(os.path.dirname(link), exist_ok=True)
        target = os.path.relpath(source, os.path.dirname(link))
        if os.path.islink(link) and os.readlink(link) == target:
            continue
        tmp = f"{link}.{os.getpid()}.tmp"
        os.symlink(target, tmp)
        os.replace(tmp, link)
    twins = os.path.join(src, SHOWN)
    for d, _, files in os.walk(twins, topdown=False):
        for f in files:
            full = os.path.join(d, f)
            if os.path.relpath(full, src) not in shown and os.path.islink(full):
                os.remove(full)
        if d != twins and not os.listdir(d):
            os.rmdir(d)


def chapters(items):
    """Every chapter of a book's items, sub-chapters included."""
    for item in items:
        if isinstance(item, dict) and "Chapter" in item:
            yield item["Chapter"]
            yield from chapters(item["Chapter"].get("sub_items", []))


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "supports":
        return 0
    context, book = json.load(sys.stdin)
    root = context["root"]
    src = os.path.normpath(os.path.join(root, context["config"]["book"].get("src", "src")))
    repo = os.path.normpath(os.path.join(root, ".."))
    shown = set()
    # mdBook 0.4 calls the book's items `sections`; later versions `items`.
    for chapter in chapters(book.get("sections", book.get("items", []))):
        if chapter.get("path") is None:
            continue
        chapter_dir = os.path.dirname(os.path.join(src, chapter["path"]))
        chapter["content"], found = rewrite(chapter["content"], chapter_dir, src, repo)
        shown |= found
    link_shown(src, repo, shown)
    json.dump(book, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())

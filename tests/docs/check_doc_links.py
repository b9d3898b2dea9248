#!/usr/bin/python3
"""Checks the documentation's links: every relative link in README.md and docs/**/*.md (and the
Markdown files they reach) names a file that exists, and a '#anchor' names a heading of that
file; and every page a user needs is linked from the README.

usage: check_doc_links.py SOURCE_DIR
Exit code 0 when every link resolves, 1 with one line per broken link otherwise.
"""
import re
import sys
from pathlib import Path

# The pages a user starts from: each must exist and be linked from the README.
USER_PAGES = [
    "docs/getting-started.md",
    "docs/flashing.md",
    "docs/install.md",
    "docs/configuration.md",
    "docs/tuning.md",
    "docs/troubleshooting.md",
    "tools/python/README.md",
]

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~)")


def anchors(path: Path) -> set:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces as hyphens."""
    found = set()
    in_fence = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            in_fence = not in_fence
        if in_fence or not line.startswith("#"):
            continue
        title = line.lstrip("#").strip().lower()
        slug = re.sub(r"[^\w\- ]", "", title).replace(" ", "-")
        base, n = slug, 1
        while slug in found:
            slug, n = f"{base}-{n}", n + 1
        found.add(slug)
    return found


def links(path: Path):
    in_fence = False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        line = re.sub(r"`[^`]*`", "", line)  # code spans are not links
        for target in LINK.findall(line):
            yield number, target


def main() -> int:
    root = Path(sys.argv[1]).resolve()
    errors = []
    readme = root / "README.md"
    readme_targets = {(readme.parent / t.split("#")[0]).resolve() for _, t in links(readme)}
    for page in USER_PAGES:
        if not (root / page).is_file():
            errors.append(f"{page}: missing (a page every user needs)")
        elif (root / page).resolve() not in readme_targets:
            errors.append(f"README.md: does not link {page}")

    pages = [readme] + sorted((root / "docs").rglob("*.md"))
    seen = set()
    while pages:
        page = pages.pop()
        if page in seen:
            continue
        seen.add(page)
        for number, target in links(page):
            if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition("#")
            dest = (page.parent / file_part).resolve() if file_part else page
            where = f"{page.relative_to(root)}:{number}"
            if not dest.exists():
                errors.append(f"{where}: link to {target}: no such file")
                continue
            if anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                errors.append(f"{where}: link to {target}: no heading '{anchor}' there")
            if dest.suffix == ".md" and root in dest.parents:
                pages.append(dest)
    for error in errors:
        print(error)
    print(f"check_doc_links: {len(seen)} pages, {len(errors)} broken links")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())

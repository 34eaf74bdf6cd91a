"""The documentation's links: every relative link in README.md,
BENCHMARKS.md, docs/*.md and bench/README.md names a file of the
repository, and a link's #anchor a heading of the file it names."""

import glob
import os
import re

_root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _slug(heading: str) -> str:
    """GitHub's anchor for a Markdown heading."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _pages() -> list[str]:
    names = ["README.md", "BENCHMARKS.md", "bench/README.md"]
    names += sorted(os.path.relpath(p, _root) for p in glob.glob(os.path.join(_root, "docs", "*.md")))
    return [n for n in names if os.path.exists(os.path.join(_root, n))]


def test_relative_links_name_files_and_headings():
    pages = _pages()
    assert "README.md" in pages and any(p.startswith("docs") for p in pages)
    broken = []
    for page in pages:
        path = os.path.join(_root, page)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for link in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", link):
                continue
            target, _, anchor = link.partition("#")
            file = os.path.normpath(os.path.join(os.path.dirname(path), target)) if target else path
            if not os.path.exists(file):
                broken.append(f"{page}: {link} (no such file)")
            elif anchor and file.endswith(".md"):
                with open(file, encoding="utf-8") as f:
                    heads = [_slug(h) for h in re.findall(r"^#+ (.*)$", f.read(), re.M)]
                if anchor not in heads:
                    broken.append(f"{page}: {link} (no such heading)")
    assert not broken, "\n".join(broken)

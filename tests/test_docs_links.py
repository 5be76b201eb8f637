"""Every relative link and image of README.md, docs/**/*.md and benchmarks/**/*.md points to a
file of the repository (the site build, ``mkdocs build --strict``, checks the links inside docs/
only)."""

import re
import unicodedata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [
    ROOT / "README.md",
    *sorted((ROOT / "docs").rglob("*.md")),
    *sorted((ROOT / "benchmarks").rglob("*.md")),
]
LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(page):
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    targets = [t for t in LINK.findall(text) if not re.match(r"[a-z]+:|#", t)]
    missing = [t for t in targets if not (page.parent / t.split("#")[0]).exists()]
    assert not missing, f"{page.name}: links to missing files {missing}"


def _slug(heading: str) -> str:
    """The anchor mkdocs (Python-Markdown's toc) gives a heading."""
    text = unicodedata.normalize("NFKD", heading).encode("ascii", "ignore").decode()
    return re.sub(r"[-\s]+", "-", re.sub(r"[^\w\s-]", "", text).strip().lower())


def test_decisions_anchors_cited_by_the_code_exist():
    """Every ``docs/decisions.md#…`` link a module, test, benchmark or example cites names a
    heading of docs/decisions.md (the site build checks links inside docs/ only)."""
    page = (ROOT / "docs" / "decisions.md").read_text(encoding="utf-8")
    anchors = {_slug(h) for h in re.findall(r"^#+\s+(.+)$", page, flags=re.M)}
    cited = {
        (str(path.relative_to(ROOT)), anchor)
        for folder in ("gdnplan", "tests", "benchmarks", "examples")
        for path in (ROOT / folder).rglob("*.py")
        for anchor in re.findall(r"decisions\.md#([\w-]+)", path.read_text(encoding="utf-8"))
    }
    assert cited, "no module cites docs/decisions.md#…"
    missing = sorted((path, anchor) for path, anchor in cited if anchor not in anchors)
    assert not missing, f"anchors missing from docs/decisions.md: {missing}"

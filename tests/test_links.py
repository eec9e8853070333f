"""Every relative link and image in README.md, docs/*.md and docs/results/**/*.md points
at a file that exists (issue 47: the front page showed a broken headline figure)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted([ROOT / "README.md", *(ROOT / "docs").glob("*.md"),
                *(ROOT / "docs" / "results").rglob("*.md")])
# [text](target) and ![alt](target), optionally with a "title"; <img src="target">
MARKDOWN_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_LINK = re.compile(r"<(?:img|a)\b[^>]*?\b(?:src|href)=\"([^\"]+)\"", re.I)
FENCE = re.compile(r"^(```|~~~).*?^\1", re.M | re.S)


def relative_links(page):
    """The relative targets of ``page``'s links and images (code blocks and spans
    skipped), each with its line number."""
    text = FENCE.sub(lambda m: "\n" * m.group(0).count("\n"), page.read_text("utf-8"))
    for number, line in enumerate(text.splitlines(), 1):
        line = re.sub(r"`[^`]*`", "", line)
        for match in [*MARKDOWN_LINK.finditer(line), *HTML_LINK.finditer(line)]:
            target = match.group(1)
            if re.match(r"^([a-z][a-z0-9+.-]*:|#|//)", target, re.I):
                continue  # a URL, a mail address or an anchor on the same page
            yield number, target.split("#")[0]


def test_the_pages_are_found():
    assert ROOT / "README.md" in PAGES and len(PAGES) > 20


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_and_image_resolves(page):
    broken = [f"line {n}: {target}" for n, target in relative_links(page)
              if target and not (page.parent / target).exists()]
    assert not broken, f"{page.relative_to(ROOT)}: broken links\n" + "\n".join(broken)


def test_every_results_page_is_in_the_sites_toctree():
    # the documentation site (sphinx -W) refuses a page outside every toctree
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    pages = sorted(p.stem for p in (ROOT / "docs" / "results").glob("*.md"))
    missing = [p for p in pages if f"results/{p}\n" not in index]
    assert not missing, f"docs/index.md's toctree lacks {missing}"

"""The theory page renders its equations as math: built with the site's MyST settings (dollarmath,
MathJax), every LaTeX command and ``$`` delimiter of the page ends up inside a math element
for MathJax, none as raw text in a paragraph."""

from __future__ import annotations

import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

from sphinx.cmd.build import build_main

DOCS = Path(__file__).resolve().parents[2] / "docs"

#: Text that shows LaTeX was not rendered: a command such as \frac or \mathbf, or a $ delimiter.
RAW_LATEX = re.compile(r"\\[a-zA-Z]+|\$")


class _TextOutsideMath(HTMLParser):
    """The page's text outside math elements (class ``math``), scripts and code; and how many
    math elements it has."""

    def __init__(self):
        super().__init__()
        self.depth_skipped = 0
        self.stack: list[bool] = []
        self.text: list[str] = []
        self.math = 0

    def handle_starttag(self, tag, attrs):
        classes = (dict(attrs).get("class") or "").split()
        skip = "math" in classes or tag in ("script", "style", "code", "pre")
        self.math += "math" in classes
        self.stack.append(skip)
        self.depth_skipped += skip

    def handle_endtag(self, tag):
        if self.stack:
            self.depth_skipped -= self.stack.pop()

    def handle_data(self, data):
        if not self.depth_skipped:
            self.text.append(data)


def test_theory_page_renders_its_equations_as_math(tmp_path):
    assert '"dollarmath"' in (DOCS / "conf.py").read_text()  # the site's setting, used below
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(DOCS / "theory.md", src / "index.md")
    (src / "conf.py").write_text(
        'extensions = ["myst_parser", "sphinx.ext.mathjax"]\nmyst_enable_extensions = ["dollarmath"]\n'
        'suppress_warnings = ["myst.xref_missing", "myst.header"]\n'
    )
    assert build_main(["-q", "-b", "html", str(src), str(tmp_path / "html")]) == 0
    page = _TextOutsideMath()
    page.feed((tmp_path / "html" / "index.html").read_text())
    assert page.math >= 20  # the models, the stable step, the tangent, Newmark, damage
    outside = "".join(page.text)
    assert not RAW_LATEX.findall(outside), RAW_LATEX.findall(outside)[:10]

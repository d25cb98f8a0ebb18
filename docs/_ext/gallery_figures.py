"""sphinx-gallery image scraper for the figures peridyn's jobs save as PNG files.

The gallery's examples run with ``examples/`` as working folder and write their runs under
``examples/peridyn-out/``; a job saves its figures there instead of leaving them open in pyplot,
so the matplotlib scraper alone would show none of them.
"""

from __future__ import annotations

from pathlib import Path


class SavedFigures:
    """sphinx-gallery image scraper: the PNG figures a code block of an example wrote under
    ``runs`` (peridyn's jobs save their figures rather than leave them open in pyplot)."""

    def __init__(self, runs: Path):
        self.runs = runs
        self.seen = self._versions()  # figures of an earlier build count only once rewritten

    def _versions(self) -> set:
        """(path, modification time) of every PNG under ``runs``."""
        return {(p, p.stat().st_mtime_ns) for p in self.runs.rglob("*.png")}

    def __repr__(self) -> str:  # sphinx-gallery compares configurations by their repr
        return "SavedFigures()"

    def __call__(self, block, block_vars, gallery_conf):
        import shutil

        from sphinx_gallery.scrapers import figure_rst

        versions = self._versions()
        new = sorted(path for path, _ in versions - self.seen)
        self.seen = versions
        targets = []
        for png, target in zip(new, block_vars["image_path_iterator"], strict=False):
            shutil.copyfile(png, target)
            targets.append(target)
        return figure_rst(targets, gallery_conf["src_dir"])

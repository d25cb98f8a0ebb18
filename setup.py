"""Build hook: the wheel carries the shipped examples (cases, sweeps, the gallery's scripts and
inputs) as package data in ``peridyn/examples_data/``, copied from the repository at build time
so that the repository keeps one copy of each (the list: ``src/peridyn/data/examples.py``)."""

import runpy
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


class BuildWithExamples(build_py):
    """``build_py`` that also copies the examples into the built package."""

    def run(self):
        super().run()
        if self.editable_mode:  # an editable install finds them in the checkout
            return
        examples = runpy.run_path(str(HERE / "src" / "peridyn" / "data" / "examples.py"))
        target = Path(self.build_lib) / "peridyn" / "examples_data"
        for name, source in examples["example_files"](HERE):
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target / name)


setup(cmdclass={"build_py": BuildWithExamples})

"""The package layout that docs/architecture.md promises (issue 16): few top-level modules and
every numba kernel in ``peridyn.kernels``. The import layering itself is checked by
import-linter (``lint-imports``, contracts in pyproject.toml)."""

import ast
from pathlib import Path

import peridyn

PACKAGE = Path(peridyn.__file__).parent


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_at_most_four_top_level_modules():
    top = [p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")]
    assert len(top) <= 4, f"top-level modules {top}: move them into a layer (docs/architecture.md)"


def _jit_functions(path: Path) -> list[str]:
    """Names of the functions of ``path`` decorated with numba.njit / numba.jit (any form)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.FunctionDef):
            continue
        for deco in node.decorator_list:
            target = deco.func if isinstance(deco, ast.Call) else deco
            name = ast.unparse(target)
            if name.split(".")[-1] in ("njit", "jit", "vectorize", "guvectorize", "stencil"):
                found.append(node.name)
    return found


def test_every_numba_kernel_lives_in_kernels():
    outside = {
        str(p.relative_to(PACKAGE)): names
        for p in _modules()
        if p.relative_to(PACKAGE).parts[0] != "kernels" and (names := _jit_functions(p))
    }
    assert not outside, f"numba kernels outside peridyn/kernels: {outside}"


def test_the_check_sees_a_kernel(tmp_path):
    # the scan above would pass vacuously if it missed the decorator forms in use
    src = tmp_path / "k.py"
    src.write_text("import numba\n@numba.njit(cache=True)\ndef f(x):\n    return x\n")
    assert _jit_functions(src) == ["f"]
    assert _jit_functions(PACKAGE / "kernels" / "pmb.py")


def test_every_module_says_what_it_holds():
    bare = [
        str(p.relative_to(PACKAGE))
        for p in _modules()
        if p.stat().st_size and ast.get_docstring(ast.parse(p.read_text())) is None
    ]
    assert not bare, f"modules without a docstring: {bare}"

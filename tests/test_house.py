"""Files a person can hold in their head (issue #12): no package source file over ~800 lines,
no function over ~120 lines. numba kernels are exempt: splitting one costs a call inside the
hot loop (or a recompile of its callers), so they stay whole."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("semexplore_gym", "policies")
MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 120
_JIT_DECORATORS = {"njit", "jit"}


def _sources(root: Path) -> list[Path]:
    return [f for pkg in PACKAGES for f in sorted((root / pkg).rglob("*.py"))]


def _is_jitted(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    """Decorated with numba's ``njit``/``jit``, bare or called (``@njit(cache=True)``)."""
    for dec in fn.decorator_list:
        target = dec.func if isinstance(dec, ast.Call) else dec
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in _JIT_DECORATORS:
            return True
    return False


def long_functions(path: Path, limit: int = MAX_FUNCTION_LINES) -> list[tuple[str, int, int]]:
    """``(qualified name, first line, n lines)`` of every non-jitted function over ``limit``
    lines (decorators left out, docstring and nested functions counted)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    out = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = (child.end_lineno or child.lineno) - child.lineno + 1
                if n > limit and not _is_jitted(child):
                    out.append((prefix + child.name, child.lineno, n))
                visit(child, f"{prefix}{child.name}.")
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")
            else:
                visit(child, prefix)

    visit(tree, "")
    return out


def test_no_source_file_is_too_long() -> None:
    long_files = []
    for f in _sources(ROOT):
        n = len(f.read_text().splitlines())
        if n > MAX_FILE_LINES:
            long_files.append(f"{f.relative_to(ROOT)}: {n} lines")
    assert not long_files, f"over {MAX_FILE_LINES} lines, split by concept:\n" + "\n".join(
        long_files
    )


def test_no_function_is_too_long() -> None:
    long = [
        f"{f.relative_to(ROOT)}:{line} {name}: {n} lines"
        for f in _sources(ROOT)
        for name, line, n in long_functions(f)
    ]
    assert not long, f"over {MAX_FUNCTION_LINES} lines, split into steps:\n" + "\n".join(long)


def test_checker_finds_a_long_function_and_skips_kernels(tmp_path: Path) -> None:
    body = "".join(f"    x{i} = {i}\n" for i in range(6))
    f = tmp_path / "m.py"
    f.write_text(
        "import numba\nfrom numba import njit\n\n"
        f"def long():\n{body}\n"  # lines 4-10
        f"@njit(cache=True)\ndef kernel():\n{body}\n"
        f"@numba.njit\ndef kernel2():\n{body}\n"
        "class C:\n    def method(self):\n" + body.replace("    ", "        ") + "\n"
        "def short():\n    pass\n"
    )
    assert long_functions(f, limit=6) == [("long", 4, 7), ("C.method", 31, 7)]

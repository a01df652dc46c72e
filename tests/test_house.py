"""Files a person can hold in their head: no package source file over 600 lines, no function
over 80 lines, no public function with more than 8 parameters.

numba kernels are exempt from both function limits: splitting one costs a call inside the hot
loop (or a recompile of its callers), and a jitted function takes arrays, not the config objects
a long argument list would otherwise be folded into.

Parameters are counted as a caller sees them: every positional, positional-only and keyword-only
parameter counts one, ``*args`` and ``**kwargs`` one each (a bare ``*`` counts nothing), a
method's ``self``/``cls`` nothing. A function is public when no part of its dotted path (module,
class, function) starts with ``_``; ``__init__`` and ``__call__`` of a public class are public
(they are the class's call signature). Dataclass constructors are generated, so they never count.
Every offender is printed, not only the first."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("semexplore_gym", "policies")
MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 80
MAX_PUBLIC_PARAMETERS = 8
_PUBLIC_DUNDERS = {"__init__", "__call__"}
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


def parameter_count(fn: ast.FunctionDef | ast.AsyncFunctionDef, is_method: bool) -> int:
    """The parameters a caller can pass (see the module docstring for what counts)."""
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args]
    is_static = any(getattr(d, "id", "") == "staticmethod" for d in fn.decorator_list)
    if is_method and not is_static and names and names[0] in ("self", "cls"):
        names = names[1:]
    return len(names) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)


def _is_public(name: str) -> bool:
    return not name.startswith("_") or name in _PUBLIC_DUNDERS


def many_parameter_functions(
    path: Path, module_is_public: bool = True, limit: int = MAX_PUBLIC_PARAMETERS
) -> list[tuple[str, int, int]]:
    """``(qualified name, line, n parameters)`` of every public, non-jitted function with more
    than ``limit`` parameters."""
    tree = ast.parse(path.read_text(), filename=str(path))
    out = []

    def visit(node: ast.AST, prefix: str, public: bool, in_class: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = parameter_count(child, in_class)
                if public and _is_public(child.name) and n > limit and not _is_jitted(child):
                    out.append((prefix + child.name, child.lineno, n))
                # a nested function is nobody's API
                visit(child, f"{prefix}{child.name}.", False, False)
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.", public and _is_public(child.name), True)
            else:
                visit(child, prefix, public, in_class)

    visit(tree, "", module_is_public, False)
    return out


def _module_is_public(root: Path, f: Path) -> bool:
    parts = f.relative_to(root).with_suffix("").parts
    return not any(p.startswith("_") and p != "__init__" for p in parts)


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


def test_no_public_function_takes_too_many_parameters() -> None:
    many = [
        f"{f.relative_to(ROOT)}:{line} {name}: {n} parameters"
        for f in _sources(ROOT)
        for name, line, n in many_parameter_functions(f, _module_is_public(ROOT, f))
    ]
    assert not many, (
        f"public functions with over {MAX_PUBLIC_PARAMETERS} parameters, pass a config object"
        " or a record:\n" + "\n".join(many)
    )


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


def test_checker_counts_parameters_of_public_functions_only(tmp_path: Path) -> None:
    f = tmp_path / "m.py"
    f.write_text(
        "from numba import njit\n"
        "def wide(a, b, /, c, *args, d, **kw):\n    pass\n"  # 6
        "def _private(a, b, c, d, e, f, g):\n    pass\n"
        "@njit(cache=True)\ndef kernel(a, b, c, d, e, f, g):\n    pass\n"
        "class C:\n"
        "    def __init__(self, a, b, c, d, e):\n        pass\n"  # 5
        "    def method(self, a, *, b):\n        pass\n"  # 2
        "    @staticmethod\n    def static(self, a):\n        pass\n"  # 2
        "    def __repr__(self, a, b, c, d, e, f):\n        pass\n"
        "class _Hidden:\n    def method(self, a, b, c, d, e, f):\n        pass\n"
        "def outer(a):\n    def inner(a, b, c, d, e, f):\n        pass\n"
    )
    assert many_parameter_functions(f, limit=1) == [
        ("wide", 2, 6),
        ("C.__init__", 10, 5),
        ("C.method", 12, 2),
        ("C.static", 15, 2),
    ]
    assert many_parameter_functions(f, module_is_public=False, limit=1) == []
    assert _module_is_public(tmp_path, tmp_path / "pkg" / "__init__.py")
    assert not _module_is_public(tmp_path, tmp_path / "pkg" / "_flags.py")

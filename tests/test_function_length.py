"""No function or method longer than 80 lines in hdl/, sim/, golden/ and stereodepth/ (the developers' guide): a
longer one is split into named steps. Nested functions count towards the function that holds them."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("hdl", "sim", "golden", "stereodepth")
LIMIT = 80


def function_lengths(root=ROOT):
    """``(lines, "file:line name")`` of every module-level function and every method, longest first."""
    out = []
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            tree = ast.parse(path.read_text(), filename=str(path))
            nodes = [n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
            for cls in (n for n in tree.body if isinstance(n, ast.ClassDef)):
                nodes += [n for n in cls.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
            out += [(n.end_lineno - n.lineno + 1, f"{path.relative_to(root)}:{n.lineno} {n.name}") for n in nodes]
    return sorted(out, reverse=True)


def test_no_function_over_80_lines():
    long = [f"{where} ({lines} lines)" for lines, where in function_lengths() if lines > LIMIT]
    assert not long, "functions over 80 lines:\n" + "\n".join(long)


def test_the_check_counts_lines(tmp_path):
    (tmp_path / "hdl").mkdir()
    body = "\n".join(f"        x = {i}" for i in range(LIMIT))
    (tmp_path / "hdl" / "block.py").write_text(f"def short():\n    pass\n\n\nclass C:\n    def long(self):\n{body}\n")
    assert function_lengths(tmp_path)[0] == (LIMIT + 1, "hdl/block.py:6 long")

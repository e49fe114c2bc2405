"""The layering docs/architecture.md promises, read from the source: every import of every module (module level and
inside functions) is checked against what its package may import.

* ``hdl/`` (gateware) imports nothing from ``sim/``, ``golden/``, ``stereodepth/``, ``bench/``;
* ``golden/`` (the specification in NumPy) imports ``hdl.params`` (constants) and nothing else of ``hdl/``, and
  nothing from ``sim/``, ``stereodepth/``, ``bench/``;
* ``sim/`` (models and harnesses) imports nothing from ``stereodepth/`` or ``bench/``;
* ``bench/`` imports nothing from ``stereodepth/`` (it sits on ``sim/`` and ``golden/``).

A violation is reported as ``file:line: <module> imports <name>``.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("hdl", "sim", "golden", "stereodepth", "bench")

#: package -> the project packages it must not import (a name or a dotted prefix).
FORBIDDEN = {
    "hdl": ("sim", "golden", "stereodepth", "bench"),
    "golden": ("hdl", "sim", "stereodepth", "bench"),
    "sim": ("stereodepth", "bench"),
    "bench": ("stereodepth",),
}
#: package -> imports allowed although they fall under a forbidden prefix.
ALLOWED = {"golden": ("hdl.params",)}


def _module_name(path, root):
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_names(path, root=ROOT):
    """``(line, imported module)`` for every import statement in ``path``, relative imports resolved.
    ``from x import y`` yields ``x.y`` (``y`` may be a module)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    module = _module_name(path, root)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            out += [(node.lineno, ".".join(p for p in (base, alias.name) if p and p != "*")) for alias in node.names]
    return out


def _matches(name, prefix):
    return name == prefix or name.startswith(prefix + ".")


def violations(root=ROOT):
    """Every forbidden import under ``root``, as ``file:line: <module> imports <name>`` lines."""
    found = []
    for package, forbidden in FORBIDDEN.items():
        for path in sorted((root / package).rglob("*.py")):
            module = _module_name(path, root)
            for line, name in imported_names(path, root):
                if any(_matches(name, a) for a in ALLOWED.get(package, ())):
                    continue
                if any(_matches(name, f) for f in forbidden):
                    found.append(f"{path.relative_to(root)}:{line}: {module} imports {name}")
    return found


def test_every_package_imports_only_what_its_layer_may():
    found = violations()
    assert not found, "layering violations:\n" + "\n".join(found)


def test_the_check_sees_function_local_and_relative_imports(tmp_path):
    """The checker itself: a function-local import, a relative import and a ``from golden import x`` are found;
    ``hdl.params`` stays allowed for golden/."""
    (tmp_path / "hdl").mkdir()
    (tmp_path / "golden").mkdir()
    (tmp_path / "hdl" / "__init__.py").write_text("")
    (tmp_path / "hdl" / "block.py").write_text("def f():\n    from sim.mt9d112 import MT9D112\n")
    (tmp_path / "golden" / "__init__.py").write_text("")
    (tmp_path / "golden" / "model.py").write_text(
        "from hdl.params import SENSOR\nfrom hdl import params\nfrom hdl.capture import CameraCapture\n"
        "from .. import sim\n")
    found = violations(tmp_path)
    assert found == [
        "hdl/block.py:2: hdl.block imports sim.mt9d112.MT9D112",
        "golden/model.py:3: golden.model imports hdl.capture.CameraCapture",
        "golden/model.py:4: golden.model imports sim",
    ]

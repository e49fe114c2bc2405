"""The layering docs/architecture.md promises, read from the source: every import of every module (module level and
inside functions) is checked against what its layer may import, no two packages import each other (directly or
round a longer cycle), and product code names no module under tests/.

A module's layer is the longest entry of :data:`MAY_IMPORT` its name starts with (``sim.models.i2c.bus`` is in
``sim.models``; ``stereodepth.cmd_timing`` in ``stereodepth.cmd_timing``). An import is allowed when the imported
name starts with one of the layer's entries, or with the layer itself. A violation is reported as
``file:line: <module> imports <name>``. The packages are the project's top-level ones (:data:`PROJECT`); a cycle
between them is reported as ``cycle: a -> b -> a`` with the import behind each step.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PRODUCT = ("spec", "hdl", "golden", "board", "sim", "stereodepth", "bench")
PROJECT = PRODUCT + ("tests",)

#: layer -> the project modules it may import (a name or a dotted prefix), beside its own.
MAY_IMPORT = {
    "spec": (),
    "hdl": ("spec",),
    "golden": ("spec",),
    "board": ("spec", "hdl"),
    "sim": ("spec", "hdl", "golden"),                       # the package itself: its exceptions
    "sim.waves": ("spec", "hdl", "sim.__init__"),
    "sim.models": ("spec", "hdl", "golden", "sim.__init__", "sim.waves"),
    "sim.replay": ("spec", "hdl", "sim.__init__", "sim.models"),
    "sim.runners": ("spec", "hdl", "board", "sim.__init__", "sim.waves"),
    # the Verilator route's C++ testbench is the whole system's: its build makes the system testbench
    "sim.runners.verilator": ("spec", "hdl", "board", "sim.__init__", "sim.waves", "sim.runners",
                              "sim.models", "sim.replay", "sim.testbench.system"),
    "sim.testbench": ("spec", "hdl", "golden", "board", "sim.__init__", "sim.models", "sim.replay", "sim.runners",
                    "sim.waves"),
    "sim.formal": ("spec", "hdl", "sim.__init__", "sim.runners"),
    "sim.analysis": ("spec", "golden", "sim.__init__", "sim.models", "sim.testbed"),
    "sim.testbed": ("spec", "hdl", "golden", "sim.__init__", "sim.runners", "sim.testbench"),
    # the board top's simulation: the DDR2 build's MIG core is the MIG model behind MIG's port names
    "sim.board": ("spec", "hdl", "board", "sim.__init__", "sim.models", "sim.testbench"),
    # the whole-system run: the drivers, and the analysis and sequences its verdict needs
    "sim.system": ("spec", "hdl", "golden", "board", "sim.__init__", "sim.models", "sim.replay", "sim.runners",
                   "sim.waves", "sim.testbench", "sim.testbed", "sim.analysis"),
    "bench": ("spec", "hdl", "golden", "board", "sim"),
    "stereodepth": ("spec", "hdl", "golden", "board", "sim"),
    # the board commands build the board's design (hdl.config): no simulation
    "stereodepth.cmd_verilog": ("spec", "hdl", "board", "stereodepth.errors"),
    "stereodepth.cmd_resources": ("spec", "hdl", "board", "stereodepth.errors", "stereodepth.design_args"),
    "stereodepth.cmd_timing": ("spec", "hdl", "board", "stereodepth.errors", "stereodepth.design_args"),
    "stereodepth.design_args": ("spec", "hdl", "stereodepth.errors"),
    "bench.bench_resources": ("spec", "hdl", "board"),
    "bench.bench_timing": ("spec", "hdl", "board"),
    "tests": PRODUCT,
}


def _module_name(path, root):
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def layer_of(module):
    """The layer of ``module``: the longest :data:`MAY_IMPORT` key it starts with."""
    keys = [k for k in MAY_IMPORT if module == k or module.startswith(k + ".")]
    return max(keys, key=len) if keys else None


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
    if prefix.endswith(".__init__"):            # the package's own names only (``from sim import UserError``)
        package = prefix[:-len(".__init__")]
        return name == package or (name.startswith(package + ".") and name.count(".") == package.count(".") + 1
                                   and name.rpartition(".")[2][:1].isupper())
    return name == prefix or name.startswith(prefix + ".")


def violations(root=ROOT):
    """Every import under ``root`` its layer does not allow, as ``file:line: <module> imports <name>`` lines."""
    found = []
    for top in PROJECT:
        for path in sorted((root / top).rglob("*.py")):
            module = _module_name(path, root)
            layer = layer_of(module)
            allowed = (layer,) + MAY_IMPORT[layer]
            for line, name in imported_names(path, root):
                if name.split(".")[0] not in PROJECT:
                    continue
                if not any(_matches(name, a) for a in allowed):
                    found.append(f"{path.relative_to(root)}:{line}: {module} imports {name}")
    return found


def package_graph(root=ROOT):
    """The import graph between the project's top-level packages, from the same scan as :func:`violations`:
    ``{package: {imported package: "file:line" of its first such import}}``."""
    graph = {}
    for top in PROJECT:
        for path in sorted((root / top).rglob("*.py")):
            for line, name in imported_names(path, root):
                other = name.split(".")[0]
                if other in PROJECT and other != top:
                    graph.setdefault(top, {}).setdefault(other, f"{path.relative_to(root)}:{line}")
    return graph


def package_cycles(root=ROOT):
    """Every cycle of :func:`package_graph`, once each, starting at its first package in :data:`PROJECT`'s
    order, as ``cycle: a -> b -> a (file:line imports ...; ...)`` with the import behind each step."""
    graph = package_graph(root)
    order = {p: i for i, p in enumerate(PROJECT)}
    found = []

    def walk(start, path):
        for nxt in sorted(graph.get(path[-1], {}), key=order.get):
            if nxt == start:
                steps = path + [start]
                where = "; ".join(graph[a][b] for a, b in zip(steps, steps[1:]))
                found.append(f"cycle: {' -> '.join(steps)} ({where})")
            elif order[nxt] > order[start] and nxt not in path:
                walk(start, path + [nxt])

    for start in sorted(graph, key=order.get):
        walk(start, [start])
    return found


def _docstring_nodes(tree):
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                yield body[0].value


def names_of_tests(root=ROOT):
    """Product code that names a module under tests/ in a string it uses (not a docstring): ``"tests/..."``,
    ``"tests.x"``, a ``cocotb_*`` test module of tests/cocotb, as ``file:line: "<string>"``."""
    cocotb_tests = {p.stem for p in (root / "tests" / "cocotb").glob("*.py")}
    found = []
    for top in PRODUCT:
        for path in sorted((root / top).rglob("*.py")):
            tree = ast.parse(path.read_text(), filename=str(path))
            docs = {id(n) for n in _docstring_nodes(tree)}
            for node in ast.walk(tree):
                if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
                    text = node.value
                    if ("tests/" in text or text.startswith("tests.") or text in cocotb_tests) and "\n" not in text:
                        found.append(f"{path.relative_to(root)}:{node.lineno}: {text!r}")
    return found


def test_every_package_imports_only_what_its_layer_may():
    found = violations()
    assert not found, "layering violations:\n" + "\n".join(found)


def test_no_cycle_between_packages():
    found = package_cycles()
    assert not found, "import cycles between packages:\n" + "\n".join(found)


def test_the_check_sees_a_cycle_between_packages(tmp_path):
    """A cycle through two packages and one through three are each reported once; a one-way import is not."""
    for d in ("hdl", "board", "sim", "golden"):
        (tmp_path / d).mkdir()
    (tmp_path / "board" / "top.py").write_text("from spec.sensor import SENSOR\n\ndef f():\n    from sim.runner import run\n")
    (tmp_path / "sim" / "runner.py").write_text("from board.top import f\nfrom golden.model import g\n")
    (tmp_path / "golden" / "model.py").write_text("import hdl.block\n")
    (tmp_path / "hdl" / "block.py").write_text("from sim.runner import run\n")
    assert package_cycles(tmp_path) == [
        "cycle: hdl -> sim -> golden -> hdl (hdl/block.py:1; sim/runner.py:2; golden/model.py:1)",
        "cycle: board -> sim -> board (board/top.py:4; sim/runner.py:1)",
    ]


def test_product_code_names_no_module_under_tests():
    found = names_of_tests()
    assert not found, "product code naming tests/:\n" + "\n".join(found)


def test_every_product_module_has_a_layer():
    for top in PRODUCT:
        for path in (ROOT / top).rglob("*.py"):
            assert layer_of(_module_name(path, ROOT)) is not None, path


def test_the_check_sees_function_local_and_relative_imports(tmp_path):
    """The checker itself: a function-local import, a relative import, ``from golden import x``, a model importing
    a testbench and a board module importing the simulation are found; spec stays allowed for golden/."""
    for d in ("hdl", "golden", "sim/models", "board"):
        (tmp_path / d).mkdir(parents=True)
        (tmp_path / d / "__init__.py").write_text("")
    (tmp_path / "hdl" / "block.py").write_text("def f():\n    from sim.models.mt9d112.sensor import MT9D112\n")
    (tmp_path / "golden" / "model.py").write_text(
        "from spec.sensor import SENSOR\nfrom spec import sensor\nfrom hdl.capture import CameraCapture\n"
        "from .. import sim\n")
    (tmp_path / "sim" / "models" / "part.py").write_text("from sim.testbench.display import run\nfrom sim import UserError\n")
    (tmp_path / "board" / "flow.py").write_text("from sim.runners.cocotb import run_cocotb\nfrom hdl.system import X\n")
    found = violations(tmp_path)
    assert found == [
        "hdl/block.py:2: hdl.block imports sim.models.mt9d112.sensor.MT9D112",
        "golden/model.py:3: golden.model imports hdl.capture.CameraCapture",
        "golden/model.py:4: golden.model imports sim",
        "board/flow.py:1: board.flow imports sim.runners.cocotb.run_cocotb",
        "sim/models/part.py:1: sim.models.part imports sim.testbench.display.run",
    ]


def test_the_check_sees_a_product_string_naming_tests(tmp_path):
    (tmp_path / "tests" / "cocotb").mkdir(parents=True)
    (tmp_path / "tests" / "cocotb" / "cocotb_i2c.py").write_text("")
    (tmp_path / "sim").mkdir()
    (tmp_path / "sim" / "runner.py").write_text(
        '"""Docstrings may cite tests/test_x.py."""\nTESTS = "tests/cocotb"\nMODULE = "cocotb_i2c"\n')
    assert names_of_tests(tmp_path) == ["sim/runner.py:2: 'tests/cocotb'", "sim/runner.py:3: 'cocotb_i2c'"]

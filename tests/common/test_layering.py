"""The layering rule, checked on the source tree.

- `kernels` imports no Blender module: every module under it (recursively) is imported with them blocked.
- Imports go one way: operators -> addon -> gpu_shaders -> kernels; nothing imports `operators` (only the
  registration in ``__init__.py`` names them).
- No import cycles between modules, counting imports inside functions too (a cycle hidden in an ``update=``
  callback is still a cycle).
- Capability packages (``kernels/tubes``, ``addon/terrain``, ...) do not import each other; each may use the
  shared modules of its layer (``kernels/common``, the top-level modules of ``addon`` and ``gpu_shaders``).
"""

import ast
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("kernels", "gpu_shaders", "addon", "operators")  # lowest first
CAPABILITIES = ("tessellation", "tubes", "terrain", "displacement", "subdivision", "surfaces", "impostors",
                "vector_field")

BLOCKER = r"""
import importlib, importlib.abc, pkgutil, sys
BLOCKED = {"bpy", "gpu", "mathutils", "bmesh", "gpu_extras", "bpy_extras", "bl_math"}

class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"kernels must not import {name}")
        return None

sys.meta_path.insert(0, Block())
import tessera.kernels as k
names = [m.name for m in pkgutil.walk_packages(k.__path__, "tessera.kernels.")]
for name in names:
    importlib.import_module(name)
print(len(names))
"""


def package_modules(root=ROOT):
    """Every module of the four layers: dotted name (``kernels.tubes.builder``) -> (path, is_package)."""
    out = {}
    for layer in LAYERS:
        for path in (root / layer).rglob("*.py"):
            parts = list(path.relative_to(root).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts = parts[:-1]
            out[".".join(parts)] = (path, is_package)
    return out


def import_graph(modules):
    """Edges module -> modules it imports (relative imports anywhere in the file, functions included)."""
    graph = {}
    for name, (path, is_package) in modules.items():
        base = name.split(".") if is_package else name.split(".")[:-1]
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level == 0:
                assert not (node.module or "").startswith("tessera"), f"{name}: absolute import of {node.module}"
                continue
            anchor = base[: len(base) - (node.level - 1)]
            target = ".".join(anchor + ([node.module] if node.module else []))
            for alias in node.names:
                sub = f"{target}.{alias.name}" if target else alias.name
                targets.add(sub if sub in modules else target)
        graph[name] = sorted(t for t in targets if t in modules and t != name)
    return graph


def cycles(graph):
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


#: The operator modules every operator may use: not a capability's, the plumbing operators share (what they select
#: and place; the skeleton of the operators that render in a worker).
SHARED_OPERATOR_MODULES = {"operators.selection", "operators.render_job"}


def capability(name):
    """The capability package a module belongs to (``addon.tubes.preview`` -> ``tubes``), or None if shared."""
    parts = name.split(".")
    return parts[1] if len(parts) > 2 and parts[1] in CAPABILITIES else None


def violations(graph):
    """Imports that break the layering rule, as readable lines."""
    out = []
    for source, targets in graph.items():
        for target in targets:
            s_layer, t_layer = source.split(".")[0], target.split(".")[0]
            if LAYERS.index(t_layer) > LAYERS.index(s_layer):
                out.append(f"{source} imports {target}: upward ({s_layer} -> {t_layer})")
            elif t_layer == "operators" and s_layer == "operators" and target not in SHARED_OPERATOR_MODULES:
                out.append(f"{source} imports the operator module {target}")
            s_cap, t_cap = capability(source), capability(target)
            if t_cap is not None and s_cap is not None and s_cap != t_cap:
                out.append(f"{source} imports {target}: capability {s_cap} -> {t_cap}")
            if s_layer == t_layer == "kernels" and s_cap is None and t_cap is not None:
                out.append(f"{source} imports {target}: kernels.common -> capability {t_cap}")
            if s_layer == t_layer == "gpu_shaders" and s_cap is None and t_cap is not None:
                out.append(f"{source} imports {target}: shared shader code -> capability {t_cap}")
    return out


def test_kernels_import_without_blender(tmp_root):
    env = dict(os.environ, PYTHONPATH=str(tmp_root / "repo"))
    proc = subprocess.run([sys.executable, "-c", BLOCKER], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    modules = [m for m in package_modules() if m.startswith("kernels.")]
    assert int(proc.stdout.strip()) == len(modules)
    assert len(modules) > 40 and "kernels.tubes.builder" in modules


def test_blocker_catches_a_violation(tmp_root):
    env = dict(os.environ, PYTHONPATH=str(tmp_root / "repo"))
    proc = subprocess.run([sys.executable, "-c", BLOCKER.replace("import tessera.kernels as k", "import bpy")],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode != 0 and "must not import bpy" in proc.stderr


def test_no_import_cycles():
    graph = import_graph(package_modules())
    assert "addon.tubes.preview" in graph and graph["addon.tubes.preview"], "the graph was not read"
    assert cycles(graph) == []


def test_imports_follow_the_layers():
    assert violations(import_graph(package_modules())) == []


def test_registration_names_only_existing_modules():
    tree = ast.parse((ROOT / "__init__.py").read_text(encoding="utf-8"))
    names = next(ast.literal_eval(node.value) for node in ast.walk(tree)
                 if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "_modules")
    modules = package_modules()
    assert [n for n in names if n not in modules] == []
    assert len(names) == len(set(names))


def _write(root, files):
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")


def test_the_checks_catch_cycles_and_upward_imports(tmp_path):
    """The same checks on a small tree with a hidden cycle (an import inside a function), an upward import and
    a capability importing another one: each is found."""
    _write(tmp_path, {
        "kernels/__init__.py": "", "kernels/common/__init__.py": "", "kernels/common/errors.py": "",
        "kernels/tubes/__init__.py": "", "kernels/tubes/a.py": "from ..terrain import b\n",
        "kernels/terrain/__init__.py": "", "kernels/terrain/b.py": "def f():\n    from ..tubes.a import x\n",
        "gpu_shaders/__init__.py": "", "gpu_shaders/loader.py": "from ..addon import bridge\n",
        "addon/__init__.py": "", "addon/bridge.py": "from ..kernels.common.errors import E\n",
        "operators/__init__.py": "",
    })
    graph = import_graph(package_modules(tmp_path))
    assert cycles(graph) == [["kernels.terrain.b", "kernels.tubes.a"]]
    found = violations(graph)
    assert any("gpu_shaders.loader imports addon.bridge: upward" in v for v in found)
    assert any("capability tubes -> terrain" in v for v in found)

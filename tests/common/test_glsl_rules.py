"""The shaders' sources follow the rules that keep them portable to Vulkan and Metal (no Blender needed): no NaN
self-comparison (Metal compiles with fast math, which may fold it away), no array parameters (Blender's Metal
translation does not rewrite them), ``gl_FragDepth`` only where the create-info declares ``depth_write``, and every
shader compiled through the loader named in the catalogue the self-test compiles."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2] / "gpu_shaders"
GLSL = sorted(ROOT.rglob("*.glsl"))


def _code(path):
    """The source without comments."""
    text = path.read_text(encoding="utf-8")
    return re.sub(r"//[^\n]*", "", re.sub(r"/\*.*?\*/", "", text, flags=re.DOTALL))


def test_no_nan_self_comparison():
    same = re.compile(r"([A-Za-z_][\w.]*)\s*(==|!=)\s*\1(?![\w.])")
    bad = [(p.name, m.group(0)) for p in GLSL for m in same.finditer(_code(p))]
    assert GLSL and not bad, bad


def test_no_array_parameters():
    signature = re.compile(r"^\s*\w+\s+\w+\s*\(([^)]*)\)\s*\{", re.MULTILINE)
    bad = [(p.name, m.group(0).strip()) for p in GLSL for m in signature.finditer(_code(p)) if "[" in m.group(1)]
    assert not bad, bad


def test_frag_depth_only_where_depth_write_is_declared():
    writers = [p for p in GLSL if "gl_FragDepth" in _code(p)]
    for path in writers:
        name = str(path.relative_to(ROOT)).replace("\\\\", "/")
        declaring = [py for py in ROOT.rglob("*.py") if name in py.read_text(encoding="utf-8")]
        assert declaring and all("depth_write" in py.read_text(encoding="utf-8") for py in declaring), name


def test_every_compiled_shader_is_in_the_catalogue():
    names = set()
    for py in ROOT.rglob("*.py"):
        names |= set(re.findall(r"loader\.shader\(\s*\"(\w+)\"", py.read_text(encoding="utf-8")))
    text = (ROOT / "catalogue.py").read_text(encoding="utf-8")
    listed = set(re.findall(r"\(\"(\w+)\", \"[\w.]+\", \"\w+\"\)", text))
    assert names and names == listed, (names - listed, listed - names)

"""A .blend holding every stored Tessera setting at a value other than its default, and the values it holds: the fixture
of ``tests/common/test_blender_saved_settings.py``, which opens the file with the add-on of the working tree and checks
that every setting comes back (a renamed stored identifier would lose the artist's value silently).

Run with a Python that has the ``bpy`` module, from the tree whose add-on should write the file (an older commit's
tree with ``--tree``, so the file is what that version saved):

    .venv/bin/python tools/saved_settings.py OUT_FOLDER [--tree PATH]

It writes ``OUT_FOLDER/saved_settings.blend`` (compressed) and ``OUT_FOLDER/saved_settings.json`` ({"Object.tessera
.tubes.sides": value, ...}, values as Blender reads them back: sets of enum flags as sorted lists).
"""

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from source_tree import as_package, enable_extension  # noqa: E402


def _other_value(prop, current):
    """A valid value of the RNA property ``prop`` other than ``current``, or None where there is none to choose."""
    kind = prop.type
    if kind in ("POINTER", "COLLECTION"):
        return None
    if getattr(prop, "is_array", False):
        values = [_other_number(prop, v) for v in current]
        return None if None in values else values
    if kind == "BOOLEAN":
        return not current
    if kind == "STRING":
        return f"saved {prop.identifier}"
    if kind == "ENUM":
        items = [i.identifier for i in prop.enum_items]
        if prop.is_enum_flag:
            choice = {items[0]} if set(current) != {items[0]} else set(items[:2]) if len(items) > 1 else set()
            return choice if choice != set(current) else None
        others = [i for i in items if i != current]
        return others[-1] if others else None
    return _other_number(prop, current)


def _other_number(prop, current):
    kind = prop.type
    lo, hi = prop.hard_min, prop.hard_max
    soft_lo, soft_hi = prop.soft_min, prop.soft_max
    step = 1 if kind == "INT" else 0.5
    for v in (current + step, current - step, (soft_lo + soft_hi) / 2, soft_lo, soft_hi):
        v = int(v) if kind == "INT" else float(v)
        if lo <= v <= hi and v != current:
            return v
    return None


def _plain(value):
    if isinstance(value, set):
        return sorted(value)
    return list(value) if hasattr(value, "__len__") and not isinstance(value, str) else value


def _set_all(group, path, record, data):
    """Set every setting of the property group ``group`` to another value; record what Blender reads back. data:
    {ID type name: a data-block of that type} for the settings that point at one (recorded by its name)."""
    for prop in group.bl_rna.properties:
        name = prop.identifier
        if name in ("rna_type", "name") or (prop.is_readonly and prop.type != "POINTER"):
            continue
        if prop.type == "POINTER":
            base = prop.fixed_type.base
            if base is not None and base.identifier == "PropertyGroup":  # a group inside the group: its settings
                _set_all(getattr(group, name), f"{path}.{name}", record, data)
            elif prop.fixed_type.identifier in data:  # a data-block (an object, an image): kept by its name
                setattr(group, name, data[prop.fixed_type.identifier])
                record[f"{path}.{name}.name"] = getattr(group, name).name
            continue
        value = _other_value(prop, getattr(group, name))
        if value is None:
            continue
        try:
            setattr(group, name, value)
        except (TypeError, ValueError, AttributeError):
            continue  # an enum whose items come from the data (a UV map), a value its setter refuses
        record[f"{path}.{name}"] = _plain(getattr(group, name))


def write(out, tree=None):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    folder = as_package() if tree is None else as_package(root=tree)
    enable_extension(folder, "saved_settings")
    mesh = bpy.data.meshes.new("Settings")
    ob = bpy.data.objects.new("Settings", mesh)
    bpy.context.scene.collection.objects.link(ob)
    image = bpy.data.images.new("Settings", 4, 4)
    image.use_fake_user = True
    text = bpy.data.texts.new("Settings")
    text.use_fake_user = True
    data = {"Object": ob, "Image": image, "Text": text}
    record = {}
    for label, root in (("Object", ob.tessera), ("Scene", bpy.context.scene.tessera), ("Image", image.tessera)):
        _set_all(root, f"{label}.tessera", record, data)
    out.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "saved_settings.blend"), compress=True)
    (out / "saved_settings.json").write_text(json.dumps(record, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"saved_settings: {len(record)} settings in {out / 'saved_settings.blend'}")


def read(path):
    """Open ``path`` and read back every setting its JSON names: {key: value, or the string "missing"}."""
    import bpy

    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    roots = {"Object": bpy.data.objects["Settings"], "Scene": bpy.data.scenes[0], "Image": bpy.data.images["Settings"]}
    want = json.loads(Path(path).with_suffix(".json").read_text(encoding="utf-8"))
    got = {}
    for key in want:
        holder, *names = key.split(".")
        value = roots[holder]
        for name in names:
            value = getattr(value, name, "missing")
            if value == "missing":
                break
        got[key] = _plain(value)
    return want, got


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder to write saved_settings.blend and .json into")
    parser.add_argument("--tree", type=Path, default=None, help="the source tree whose add-on writes the file")
    args = parser.parse_args()
    write(args.out.resolve(), args.tree.resolve() if args.tree else None)

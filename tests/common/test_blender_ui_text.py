"""Every setting Tessera registers explains itself, walked in the RNA of the enabled add-on (so a new property cannot
slip in without it):

- every visible property has a tooltip, every enum item a description;
- lengths are DISTANCE, screen and texel sizes PIXEL; every other float has a subtype or unit, or is one of the
  plain numbers listed in `UNITLESS` with what it counts;
- no soft range reaches 1e9, so dragging a number means something;
- no label, tooltip or enum item uses research jargon (`ui_rules.JARGON`);
- no label names two kinds of setting (a length and a pixel count, a count and a choice);
- every operator has a one-sentence description;
- the menus hold what Blender users look for where they look (creators under Add, exporters under File › Export,
  tools on the active object under Object › Tessera), and every menu path named in the source or the docs exists;
- the sidebar tab is always there: a start panel shows when no other Tessera panel does.
"""

import ast
import importlib
import re
from pathlib import Path

import pytest
from conftest import ADDON_MODULE
from ui_rules import MENU_PATH, description_problems, jargon

pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[2]

#: Floats that are plain numbers, with what they are (everything else needs a subtype or a unit).
UNITLESS = {
    "level": "segments per edge",
    "max_level": "segments per edge",
    "curvature_gain": "segments per unit of curvature",
    "ham_scale": "a multiplier of the terrain's roughness",
    "exaggeration": "a multiplier of a GeoTIFF's true heights",
    "mid_level": "a value of the map",
    "strength": "map values or scene units per map value",
    "low": "a value of the map",
    "high": "a value of the map",
    "speed": "a multiplier of the field's vectors",
    "step": "a fraction of the texture's width",
    "superellipsoid_e1": "an exponent",
    "superellipsoid_e2": "an exponent",
}
#: Words in a float's identifier or label that make it a length: DISTANCE (scene units) or PIXEL (screen pixels, map
#: texels); ANGLE where the "length" is an angle (an angle tolerance).
LENGTH = re.compile(r"\b(radius|distance|near|far|size|width|height|offset|length|tolerance)\b", re.IGNORECASE)
LENGTH_SUBTYPES = ("DISTANCE", "PIXEL", "DISTANCE_CAMERA", "ANGLE")
#: Words in a number's identifier or label that make it a count of screen pixels: PIXEL.
PIXELS = re.compile(r"\b(pixels?|px)\b", re.IGNORECASE)
#: Properties whose names read like a length but are not one (a colour tolerance).
NOT_A_LENGTH = {"tolerance": {"TESSERA_OT_bake_lighting_hce"}}


def _words(prop):
    return f"{prop.identifier.replace('_', ' ')} {prop.name}"


def _owner_properties(bpy, prefs):
    """(owner, property) of every property Tessera registers: the groups under the ``tessera`` pointers, the
    preferences and every operator's own properties."""
    out, seen = [], set()

    def walk(rna, owner):
        for p in rna.properties:
            if p.identifier == "rna_type":
                continue
            fixed = getattr(p, "fixed_type", None)
            if p.type == "POINTER" and fixed is not None and fixed.identifier.startswith("TESSERA_PG_"):
                if fixed.identifier not in seen:
                    seen.add(fixed.identifier)
                    walk(fixed, fixed.identifier)
                continue
            if (p.identifier == "name" and owner.startswith("TESSERA_PG_")) or p.identifier == "bl_idname":
                continue  # built into every PropertyGroup and AddonPreferences
            out.append((owner, p))

    for id_type in (bpy.types.Object, bpy.types.Scene, bpy.types.Image):
        walk(id_type.bl_rna.properties["tessera"].fixed_type, id_type.__name__)
    walk(prefs.bl_rna, "TESSERA_AddonPreferences")
    base = set(bpy.types.Operator.bl_rna.properties.keys())
    for name in dir(bpy.ops.tessera):
        rna = getattr(bpy.ops.tessera, name).get_rna_type()
        out += [(rna.identifier, p) for p in rna.properties if p.identifier not in base]
    return out


@pytest.fixture(scope="module")
def properties(bpy_module, addon):
    prefs = bpy_module.context.preferences.addons[ADDON_MODULE].preferences
    props = _owner_properties(bpy_module, prefs)
    assert len(props) > 200  # the walk reached the groups and the operators
    return [(owner, p) for owner, p in props if not p.is_hidden]


def test_every_property_and_enum_item_has_a_tooltip(properties):
    missing = [f"{owner}.{p.identifier}" for owner, p in properties if not p.description.strip()]
    items = [f"{owner}.{p.identifier}:{item.identifier}" for owner, p in properties if p.type == "ENUM"
             for item in p.enum_items if not item.description.strip()]
    assert not missing, f"{len(missing)} properties without a tooltip: {missing}"
    assert not items, f"{len(items)} enum items without a description: {items}"


def test_lengths_and_pixel_values_carry_their_subtype(properties):
    bad = []
    for owner, p in properties:
        if p.type not in ("FLOAT", "INT") or getattr(p, "is_array", False):
            continue
        words = _words(p)
        if PIXELS.search(words):
            if p.subtype != "PIXEL":
                bad.append(f"{owner}.{p.identifier}: a pixel value with subtype {p.subtype}")
        elif p.type == "FLOAT" and LENGTH.search(words) and owner not in NOT_A_LENGTH.get(p.identifier, ()):
            if p.subtype not in LENGTH_SUBTYPES:
                bad.append(f"{owner}.{p.identifier}: a length with subtype {p.subtype}")
        elif (p.type == "FLOAT" and p.subtype == "NONE" and getattr(p, "unit", "NONE") == "NONE"
              and p.identifier not in UNITLESS):
            bad.append(f"{owner}.{p.identifier}: no subtype or unit (add one, or list it in UNITLESS with why)")
    assert not bad, "\n".join(bad)


def test_soft_ranges_make_a_usable_slider(properties):
    bad = [f"{owner}.{p.identifier}: soft range {p.soft_min:g} .. {p.soft_max:g}" for owner, p in properties
           if p.type in ("FLOAT", "INT") and (p.soft_max >= 1e9 or p.soft_min <= -1e9)]
    assert not bad, "\n".join(bad)


def _ui_texts(bpy, properties):
    """(where, text) of every label, tooltip and enum item of the registered classes."""
    out = []
    for owner, p in properties:
        out += [(f"{owner}.{p.identifier}", p.name), (f"{owner}.{p.identifier}", p.description)]
        if p.type == "ENUM":
            out += [(f"{owner}.{p.identifier}:{i.identifier}", t)
                    for i in p.enum_items for t in (i.name, i.description)]
    for name in dir(bpy.ops.tessera):
        rna = getattr(bpy.ops.tessera, name).get_rna_type()
        out += [(f"tessera.{name}", rna.name), (f"tessera.{name}", rna.description)]
    for name in dir(bpy.types):
        cls = getattr(bpy.types, name)
        if name.startswith("TESSERA_") and hasattr(cls, "bl_label"):
            out.append((name, cls.bl_label))
    return out


def test_no_research_jargon_in_labels_tooltips_and_items(bpy_module, properties):
    texts = _ui_texts(bpy_module, properties)
    assert len(texts) > 500
    bad = [f"{where}: {found} in {text!r}" for where, text in texts if (found := jargon(text))]
    assert not bad, "\n".join(bad)


#: Labels that name two kinds of setting on purpose, with why: Blender's own words.
SHARED_LABELS = {"Radius": "a tube's radius in scene units; the brush's in pixels, as Blender labels its brushes'"}


def _kind(prop):
    """What a setting is, for `test_no_label_names_two_kinds_of_setting`: numbers by their subtype and unit (a length,
    a pixel count, a plain number: integer or not), enums by their items' labels, the rest by their type."""
    if prop.type in ("INT", "FLOAT"):
        return ("NUMBER", prop.subtype, prop.unit)
    if prop.type == "ENUM":
        return ("ENUM", "FLAG" if prop.is_enum_flag else "ONE")
    return (prop.type,)


def test_no_label_names_two_kinds_of_setting(properties):
    """One word, one meaning: the settings that share a label are the same kind of thing (Tolerance a distance
    everywhere, Screen Error pixels everywhere); enums that share a label offer some of the same choices (Evaluate On:
    CPU and GPU). Stored identifiers may differ (they stay as files hold them); the label is what the artist reads."""
    by_label = {}
    for owner, p in properties:
        by_label.setdefault(p.name, []).append((owner, p))
    assert len(by_label) > 100
    bad = []
    for label, entries in sorted(by_label.items()):
        if label in SHARED_LABELS:
            continue
        kinds = {_kind(p) for _, p in entries}
        enums = [p for _, p in entries if p.type == "ENUM"]
        items = [{i.name for i in p.enum_items} for p in enums]
        disjoint = any(not (a & b) for k, a in enumerate(items) for b in items[k + 1:])
        if len(kinds) > 1 or disjoint:
            bad.append(f"{label!r}: " + ", ".join(sorted({f"{o}.{p.identifier} {_kind(p)}" for o, p in entries})))
    assert not bad, "\n".join(bad)


def test_every_operator_has_a_one_sentence_description(bpy_module, addon):
    bad = []
    for name in dir(bpy_module.ops.tessera):
        rna = getattr(bpy_module.ops.tessera, name).get_rna_type()
        if problems := description_problems(rna.description):
            bad.append(f"tessera.{name}: {problems}: {rna.description!r}")
    assert not bad, "\n".join(bad)


# Menus


def _menus():
    return importlib.import_module(f"{ADDON_MODULE}.addon.menus")


def _label(bpy, entry):
    idname, text = entry if isinstance(entry, tuple) else (entry, None)
    module, name = idname.split(".")
    return text or getattr(getattr(bpy.ops, module), name).get_rna_type().name


def test_menus_are_hooked_where_blender_users_look(bpy_module, addon):
    bpy, menus = bpy_module, _menus()
    hooks = {bpy.types.VIEW3D_MT_add: menus.draw_add_menu, bpy.types.VIEW3D_MT_object: menus.draw_object_menu,
             bpy.types.TOPBAR_MT_file_export: menus.draw_export_menu}
    for menu, hook in hooks.items():
        assert hook in menu._dyn_ui_initialize(), f"{hook.__name__} is not in {menu.__name__}"
    for entry in menus.ADD_MENU + menus.OBJECT_MENU + menus.EXPORT_MENU:
        assert _label(bpy, entry)  # every entry is a registered operator
    # every operator that makes a new object from nothing is a creator: under Add, not under Object
    creators = {"tessera.parametric_surface_add", "tessera.terrain_add", "tessera.vector_field_texture"}
    assert creators <= set(menus.ADD_MENU) and not creators & set(menus.OBJECT_MENU)
    # the operators that write files are exporters: under File › Export
    exporters = {"tessera.impostor_export", "tessera.displacement_export"}
    assert exporters <= {e[0] for e in menus.EXPORT_MENU}


def _named_menu_paths():
    """(where, menu, item text) of every menu path in the product's strings, the README and docs/."""
    out = []
    sources = [p for layer in ("addon", "operators", "kernels") for p in (ROOT / layer).rglob("*.py")]
    for path in sources:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                out += [(f"{path.relative_to(ROOT)}:{node.lineno}", m.group(1), m.group(3))
                        for m in MENU_PATH.finditer(node.value)]
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            out += [(f"{path.relative_to(ROOT)}:{n}", m.group(1), m.group(3)) for m in MENU_PATH.finditer(line)]
    return out


def test_every_menu_path_named_in_messages_and_docs_exists(bpy_module, addon):
    bpy, menus = bpy_module, _menus()
    items = {"Add": menus.ADD_MENU, "Object": menus.OBJECT_MENU}
    items = {k: [_label(bpy, e) for e in v] for k, v in items.items()}
    items["File › Export"] = [_label(bpy, e) for e in menus.EXPORT_MENU]
    panels = [getattr(bpy.types, n).bl_label for n in dir(bpy.types) if n.startswith("TESSERA_PT_")]
    named = _named_menu_paths()
    assert len(named) >= 10  # the docs and messages do name paths: the check has something to check
    bad = []
    for where, menu, rest in named:
        key = re.sub(r"\s*[›>]\s*", " › ", menu)
        choices = panels if "Sidebar" in key else items.get(key, [])
        if not any(rest.startswith(label) for label in choices):
            bad.append(f"{where}: {menu} › Tessera › {rest!r} names no item of that menu ({choices})")
    assert not bad, "\n".join(bad)


def test_the_sidebar_tab_is_always_there(bpy_module, addon, clean_scene):
    """With nothing selected only the start panel shows; with a mesh active it steps aside for the mesh's panels."""
    bpy = bpy_module
    panels = [getattr(bpy.types, n) for n in dir(bpy.types) if n.startswith("TESSERA_PT_")]
    start = bpy.types.TESSERA_PT_start

    def shown():
        return {p.__name__ for p in panels if p.poll(bpy.context)}

    bpy.context.view_layer.objects.active = None
    assert shown() == {"TESSERA_PT_start"}
    bpy.ops.mesh.primitive_monkey_add()
    assert "TESSERA_PT_tessellation" in shown() and start.__name__ not in shown()
    bpy.ops.object.camera_add()  # an object no Tessera panel is for: the tab stays, with the start panel
    assert shown() == {"TESSERA_PT_start"}


def _documented_settings():
    """(page, name, name without a parenthesis) of every setting the manual's option tables name (first column of a
    table headed "option" or "setting"; "A, B" names two)."""
    out = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        in_table = False
        for line in page.read_text(encoding="utf-8").splitlines():
            if re.match(r"\| (option|setting) \|", line):
                in_table = True
                continue
            if not line.startswith("|"):
                in_table = False
            elif in_table and not line.startswith("|---"):
                for part in re.split(r",| and ", line.split("|")[1]):
                    name = part.strip().strip("*").strip()
                    if name:  # "Levels (0–6)": the label, or the label with its unit ("Memory Budget (MiB)")
                        out.append((page.name, name, re.sub(r"\s*\([^)]*\)", "", name)))
    return out


def test_every_setting_the_manual_names_exists(properties):
    """A page's option table names settings by their labels; each is the label of a setting Tessera registers (a
    renamed label fails here until the page follows)."""
    labels = {p.name for _, p in properties}
    named = _documented_settings()
    assert len(named) > 60
    missing = sorted({f"{page}: {name}" for page, name, bare in named if name not in labels and bare not in labels})
    assert not missing, missing


def test_the_readme_names_exactly_the_tools_the_command_line_runs(bpy_module, addon):
    """The README's command-line quick start lists the tools that are verbs; the list is the registry's, by the
    labels the menus show (no claim that every tool is one)."""
    verbs = importlib.import_module(f"{ADDON_MODULE}.addon.command_line.verbs").VERBS
    labels = {getattr(bpy_module.types, getattr(bpy_module.ops.tessera, v.operator.split(".")[1]).idname()).bl_label
              for v in verbs.values()}
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    sentence = re.search(r"The tools that turn files into files are also verbs of.*?Files in", text, re.DOTALL).group(0)
    assert set(re.findall(r"\*([^*]+)\*", sentence)) == labels

"""Command-line options made from an operator's own properties: one ``--name`` per setting, with its panel label and
tooltip as its help, the enum items as its choices and the property's hard range checked, so the command line always
offers exactly what the redo panel offers.

- booleans: ``--culling`` / ``--no-culling``;
- numbers: ``--level 4``; vectors: ``--block 0,1,2,2``;
- enums: ``--method phong`` (any case); sets of flags: ``--metrics projected,silhouette``;
- text: ``--filepath dem.tif``.

Only options given on the command line are passed to the operator; the rest keep the operator's defaults.
"""

import argparse

import bpy

_CONVERT = {"INT": int, "FLOAT": float}


def operator_rna(idname):
    """The RNA type of operator ``idname`` (``"tessera.tessellate"``)."""
    module, name = idname.split(".")
    return getattr(getattr(bpy.ops, module), name).get_rna_type()


def settable(idname, skip=()):
    """The properties of operator ``idname`` a command line may set: `bpy.types.Property` list, in the operator's
    order, without hidden ones and those named in ``skip``."""
    props = []
    for p in operator_rna(idname).properties:
        if p.identifier == "rna_type" or p.identifier in skip or p.is_hidden or p.is_readonly:
            continue
        if p.type in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING"):
            props.append(p)
    return props


def flag(identifier):
    """``edge_pixels`` -> ``--edge-pixels``."""
    return "--" + identifier.replace("_", "-")


def _number(p):
    """A converter for one value of number property ``p`` that refuses values outside its hard range."""
    convert = _CONVERT[p.type]

    def parse(text):
        try:
            value = convert(text)
        except ValueError:
            kind = "an integer" if p.type == "INT" else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        if not (p.hard_min <= value <= p.hard_max):  # NaN fails both
            raise argparse.ArgumentTypeError(f"{text} is outside {_range(p)}")
        return value

    return parse


def _range(p):
    return f"{p.hard_min:g} to {p.hard_max:g}"


def _vector(p):
    one = _number(p) if p.type in _CONVERT else _boolean

    def parse(text):
        parts = [t.strip() for t in text.split(",")]
        if len(parts) != p.array_length:
            raise argparse.ArgumentTypeError(f"{text!r}: give {p.array_length} values separated by commas")
        return tuple(one(t) for t in parts)

    return parse


def _boolean(text):
    low = text.strip().lower()
    if low in ("1", "true", "yes", "on"):
        return True
    if low in ("0", "false", "no", "off"):
        return False
    raise argparse.ArgumentTypeError(f"{text!r} is not true or false")


def _enum(p):
    names = [item.identifier for item in p.enum_items]

    def parse(text):
        chosen = [t.strip().upper() for t in text.split(",")] if p.is_enum_flag else [text.strip().upper()]
        for value in chosen:
            if value not in names:
                allowed = ", ".join(n.lower() for n in names)
                raise argparse.ArgumentTypeError(f"{value.lower()!r} is not one of {allowed}")
        return set(chosen) if p.is_enum_flag else chosen[0]

    return parse


def _help(p):
    """The option's help: the setting's label as the panels show it, its tooltip, its choices or range, its default."""
    text = f"{p.name}: {p.description}".rstrip(".") if p.description else p.name
    if p.type == "ENUM":
        items = "; ".join(f"{i.identifier.lower()}: {i.description or i.name}" for i in p.enum_items)
        default = ",".join(sorted(p.default_flag)).lower() if p.is_enum_flag else p.default.lower()
        text += f". {'One or more of' if p.is_enum_flag else 'One of'}: {items} (default: {default or 'none'})"
    elif p.type in _CONVERT:
        default = tuple(p.default_array) if getattr(p, "array_length", 0) else p.default
        unit = "" if p.unit == "NONE" else f" {p.unit.lower()}"
        shown = ",".join(f"{v:g}" for v in default) if isinstance(default, tuple) else f"{default:g}"
        text += f" ({_range(p)}{unit}; default {shown})"
    elif p.type == "BOOLEAN":
        text += f" (default {'on' if p.default else 'off'})"
    return text.replace("%", "%%")


def add_options(parser, props):
    """Add an option per property of ``props`` (from `settable`) to ``parser`` (argparse)."""
    group = parser.add_argument_group("settings (as in the redo panel)")
    for p in props:
        kw = dict(dest=p.identifier, default=None, help=_help(p))
        vector = getattr(p, "array_length", 0) > 0
        if p.type == "BOOLEAN" and not vector:
            group.add_argument(flag(p.identifier), action=argparse.BooleanOptionalAction, **kw)
            continue
        if vector:
            kw.update(type=_vector(p), metavar=",".join(["V"] * p.array_length))
        elif p.type in _CONVERT:
            kw.update(type=_number(p), metavar="N")
        elif p.type == "ENUM":
            kw.update(type=_enum(p), metavar="A,B" if p.is_enum_flag else "CHOICE")
        else:
            kw.update(metavar="FILE" if p.subtype == "FILE_PATH" else "TEXT")
        group.add_argument(flag(p.identifier), **kw)


def chosen(args, props):
    """The operator keyword arguments given on the command line: dict."""
    return {p.identifier: getattr(args, p.identifier) for p in props if getattr(args, p.identifier) is not None}

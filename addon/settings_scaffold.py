"""One scaffold for every capability's settings.

A capability's options class (``TubeOptions``, ``TerrainOptions``, ...) is a plain class whose annotations are Blender
properties without ``update=``: an operator inherits it, so its redo panel shows them. `stored_options` makes the
annotations of the property group that keeps the same settings on an object (``Object.tessera.tubes``, ...), each
with the preview's invalidation added; `option_names` lists them; `copy_options` moves every value from one holder to
another (an operator's to the object after a run, so a batch script can re-run it; the object's to an operator that a
panel starts). The stored identifiers are the annotations' names: they are what saved files hold."""


def option_names(options):
    """The settings of the options class ``options``, in its order: a tuple of property identifiers."""
    return tuple(options.__annotations__)


def copy_options(options, source, target):
    """Set every setting of ``options`` on ``target`` (an operator or a property group) to ``source``'s value."""
    for name in option_names(options):
        setattr(target, name, getattr(source, name))


def stored_options(options, update, **extra):
    """The annotations of a property group that stores ``options``: each definition with ``update=`` added (the
    preview's invalidation), then ``extra`` (the group's own properties, such as its preview switch). The options
    class keeps its update-free definitions for operators: an operator's properties are set while panels draw, where
    an update that redraws would loop."""
    with_update = {name: prop.function(**{**prop.keywords, "update": update})
                   for name, prop in options.__annotations__.items()}
    return {**with_update, **extra}

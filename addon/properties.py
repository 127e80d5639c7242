"""The one ``tessera`` pointer on each ID type that Tessera stores settings on.

- ``Object.tessera``: ``tessellate``, ``tubes``, ``displacement``, ``terrain``, ``loop``, ``surface``,
  ``nailboard`` (each capability's settings);
- ``Scene.tessera``: ``brush`` (the displacement brush shared by the tool and stroke replays);
- ``Image.tessera``: ``serial`` (strokes applied to a map image, for undo).

The stored names (``tessellate``, ``loop``, ``surface``, ``nailboard``) are older than the capability names
(tessellation, subdivision, surfaces, impostors) and stay: saved files hold the settings under them
(docs/architecture.md, "Capabilities and their names").

`register` registers the capabilities' property groups first (a pointer needs its type registered), then the
roots, then the pointers, so the order is written here and nowhere else.
"""

import bpy

from .displacement import settings as displacement_settings
from .impostors import settings as impostors_settings
from .subdivision import settings as subdivision_settings
from .surfaces import settings as surfaces_settings
from .terrain import settings as terrain_settings
from .tessellation import settings as tessellation_settings
from .tubes import settings as tubes_settings

_SETTINGS = (tessellation_settings, tubes_settings, displacement_settings, terrain_settings, subdivision_settings,
             surfaces_settings, impostors_settings)


class TESSERA_PG_object(bpy.types.PropertyGroup):
    tessellate: bpy.props.PointerProperty(type=tessellation_settings.TESSERA_PG_tessellation,
                                          description="Tessellation settings of this object")
    tubes: bpy.props.PointerProperty(type=tubes_settings.TESSERA_PG_tubes, description="Tube settings of this object")
    displacement: bpy.props.PointerProperty(type=displacement_settings.TESSERA_PG_displacement,
                                            description="This object's displacement map and how it is applied")
    terrain: bpy.props.PointerProperty(type=terrain_settings.TESSERA_PG_terrain,
                                       description="Terrain settings of this object")
    loop: bpy.props.PointerProperty(type=subdivision_settings.TESSERA_PG_subdivision,
                                    description="Loop subdivision settings of this object")
    surface: bpy.props.PointerProperty(type=surfaces_settings.TESSERA_PG_surfaces,
                                       description="Live parametric surface settings of this object")
    nailboard: bpy.props.PointerProperty(type=impostors_settings.TESSERA_PG_impostors,
                                         description="Live nailboard settings of this object")


class TESSERA_PG_scene(bpy.types.PropertyGroup):
    brush: bpy.props.PointerProperty(type=displacement_settings.TESSERA_PG_brush,
                                     description="The displacement brush (shared by the tool and stroke replays)")


classes = (TESSERA_PG_object, TESSERA_PG_scene)
_ROOTS = ((bpy.types.Object, TESSERA_PG_object), (bpy.types.Scene, TESSERA_PG_scene),
          (bpy.types.Image, displacement_settings.TESSERA_PG_image))


def register():
    for module in _SETTINGS:
        module.register()
    for cls in classes:
        bpy.utils.register_class(cls)
    for id_type, group in _ROOTS:
        id_type.tessera = bpy.props.PointerProperty(type=group, description="Tessera's settings")


def unregister():
    for id_type, _ in reversed(_ROOTS):
        del id_type.tessera
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    for module in reversed(_SETTINGS):
        module.unregister()

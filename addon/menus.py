"""Menu entries: Object > Tessera and Add > Tessera."""

import bpy


class TESSERA_MT_object(bpy.types.Menu):
    bl_idname = "TESSERA_MT_object"
    bl_label = "Tessera"

    def draw(self, context):
        self.layout.operator("tessera.tessellate", icon="MOD_SUBSURF")
        self.layout.operator("tessera.loop_subdivide", icon="MOD_SUBSURF")
        self.layout.operator("tessera.bake_lighting_hce", icon="LIGHT_SUN")
        self.layout.operator("tessera.tubes", icon="MESH_CYLINDER")
        self.layout.operator("tessera.displacement_add", icon="IMAGE_DATA")
        self.layout.operator("tessera.terrain_add", icon="RNDCURVE")
        self.layout.operator("tessera.terrain_bake", icon="VIEW_CAMERA")
        self.layout.operator("tessera.curve_adaptive", icon="CURVE_BEZCURVE")
        self.layout.operator("tessera.surface_tessellate", icon="SURFACE_NSURFACE")
        self.layout.operator("tessera.impostor_bake", icon="IMAGE_PLANE")
        self.layout.operator("tessera.impostor_export", icon="EXPORT")


class TESSERA_MT_add(bpy.types.Menu):
    bl_idname = "TESSERA_MT_add"
    bl_label = "Tessera"

    def draw(self, context):
        self.layout.operator_context = "INVOKE_REGION_WIN"
        self.layout.operator("tessera.parametric_surface_add", icon="SURFACE_NSURFACE")
        self.layout.operator("tessera.vector_field_texture", icon="FORCE_VORTEX")


def _draw_add_menu(self, context):
    self.layout.separator()
    self.layout.menu(TESSERA_MT_add.bl_idname)


def _draw_object_menu(self, context):
    self.layout.separator()
    self.layout.menu(TESSERA_MT_object.bl_idname)


classes = (TESSERA_MT_object, TESSERA_MT_add)
_register, _unregister = bpy.utils.register_classes_factory(classes)


def register():
    _register()
    bpy.types.VIEW3D_MT_object.append(_draw_object_menu)
    bpy.types.VIEW3D_MT_add.append(_draw_add_menu)


def unregister():
    bpy.types.VIEW3D_MT_add.remove(_draw_add_menu)
    bpy.types.VIEW3D_MT_object.remove(_draw_object_menu)
    _unregister()

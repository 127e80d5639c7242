"""Sidebar panel Tessera > Loop Subdivision: what the mesh brings (creases, n-gons) and the operator buttons."""

import bpy

from ..sidebar import Sidebar


class TESSERA_PT_loop_subdivision(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_loop_subdivision"
    bl_label = "Loop Subdivision"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        me = context.active_object.data
        n_tris = sum(len(p.vertices) - 2 for p in me.polygons) if len(me.polygons) < 100_000 else None
        col = layout.column(align=True)
        if n_tris is not None:
            col.label(text=f"{n_tris:,} triangles -> {n_tris * 16:,} at level 2", icon="MESH_DATA")
        creases = [a.name for a in me.attributes if a.name in ("crease_edge", "sharp_edge", "crease_vert")]
        col.label(text="Creases: " + (", ".join(creases) if creases else "none"), icon="MOD_EDGESPLIT")
        baked = "tessera_hce" in me
        col.label(text="Baked lighting: " + ("stored (Loop Subdivide writes BakedLight)" if baked else "none"),
                  icon="LIGHT_SUN")
        layout.operator("tessera.bake_lighting_hce", icon="LIGHT_SUN", text="Bake Lighting" if not baked
                        else "Bake Lighting Again")
        row = layout.row(align=True)
        row.scale_y = 1.4
        for level in (1, 2, 3):
            op = row.operator("tessera.loop_subdivide", text=f"Level {level}", icon="MOD_SUBSURF" if level == 1
                              else "NONE")
            op.levels = level


classes = (TESSERA_PT_loop_subdivision,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""``tessera.parametric_surface_add``: a one-point parametric surface (seed 000 §2.3) baked into a mesh at the 3D
cursor: welded where it closes, with its domain coordinates as UVs."""

import bpy

from ..addon import bridge
from ..addon.guarded import guarded
from ..addon.surfaces.settings import SURFACE_ITEMS, SurfaceOptions, draw_surface_options, surface_from
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.surfaces.domain_mesh import surface_mesh
from .selection import select_only


class TESSERA_OT_parametric_surface_add(SurfaceOptions, bpy.types.Operator):
    """Add a parametric surface (sphere, cone, torus, Steiner's surface, Klein bottle, Möbius band, trefoil tube,
    superellipsoid) as a mesh, welded where it closes, with UVs"""

    bl_idname = "tessera.parametric_surface_add"
    bl_label = "Parametric Surface"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to add a surface")
            return False
        return True

    def draw(self, context):
        draw_surface_options(self.layout, self)

    @guarded
    def execute(self, context, tx):
        mesh = surface_mesh(surface_from(self), self.factor)
        label = dict((k, name) for k, name, _ in SURFACE_ITEMS)[self.surface]
        arrays = MeshArrays(positions=mesh.positions, triangles=mesh.triangles,
                            corner_attributes={"UVMap": mesh.uvs}, attribute_types={"UVMap": "FLOAT2"})
        data = tx.track(bridge.write_mesh(label, arrays))
        data.shade_smooth()
        ob = tx.new_object(label, data)
        ob.location = context.scene.cursor.location
        context.collection.objects.link(ob)
        select_only(context, [ob])
        self.report({"INFO"}, f"{label}: {len(mesh.positions):,} vertices, {len(mesh.triangles):,} triangles")
        return {"FINISHED"}


classes = (TESSERA_OT_parametric_surface_add,)
register, unregister = bpy.utils.register_classes_factory(classes)

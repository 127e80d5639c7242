"""``tessera.loop_subdivide``: Loop subdivision of the active mesh (seed 002 §A.3), creases kept."""

import bpy
import numpy as np

from ..addon import bridge
from ..addon.guarded import guarded
from ..addon.preferences import get_preferences
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.subdivision.loop import MAX_LEVELS, loop_subdivide
from ..kernels.subdivision.loop_rules import SHARPNESS_INFINITE, crease_to_sharpness
from .selection import place_mesh, read_source

BOUNDARY_ITEMS = (
    ("EDGE_ONLY", "Smooth", "Open borders follow Loop's boundary rules: a uniform cubic B-spline along the border"),
    ("EDGE_AND_CORNER", "Keep Corners",
     "As Smooth, and border vertices with a single face (the corners of a plane) stay where they are"),
)


class TESSERA_OT_loop_subdivide(bpy.types.Operator):
    """Subdivide the active mesh with Loop's scheme for triangles; sharp and creased edges stay creased"""

    bl_idname = "tessera.loop_subdivide"
    bl_label = "Loop Subdivide"
    bl_options = {"REGISTER", "UNDO"}

    levels: bpy.props.IntProperty(
        name="Levels", description="Times every triangle is split in four (faces grow by 4^levels)",
        default=2, min=1, max=MAX_LEVELS, soft_max=4)
    boundary: bpy.props.EnumProperty(name="Boundary", items=BOUNDARY_ITEMS, default="EDGE_ONLY")
    use_creases: bpy.props.BoolProperty(
        name="Creases", default=True,
        description="Edges marked sharp and edges with crease 1 stay sharp; smaller creases soften over the "
                    "levels, as in OpenSubdiv and Blender's Subdivision Surface; vertex creases make corners")
    output: bpy.props.EnumProperty(
        name="Output", default="NEW_OBJECT",
        items=(("NEW_OBJECT", "New Object", "Add a new object beside the source (its modifiers applied first)"),
               ("REPLACE", "Replace", "Replace the object's mesh (one undo step brings it back)")))

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if ob is None or ob.type != "MESH":
            cls.poll_message_set("Select a mesh object to subdivide (make it active)")
            return False
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to subdivide")
            return False
        return True

    @guarded
    def execute(self, context, tx):
        ob = context.active_object
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            arrays, info, marks = read_source(context, ob, self.output)
            arrays.point_attributes.pop("crease_vert", None)  # a crease, not data to smooth
            result = loop_subdivide(
                arrays.positions, arrays.triangles, self.levels,
                creases=(marks.pairs, crease_to_sharpness(marks.crease)) if self.use_creases else None,
                vertex_sharpness=None if marks.vertex_crease is None or not self.use_creases
                else crease_to_sharpness(marks.vertex_crease),
                boundary=self.boundary, point_data=arrays.point_attributes, corner_data=arrays.corner_attributes,
                budget_bytes=get_preferences(context).memory_budget_bytes,
                progress=lambda done, total: wm.progress_update(int(90 * done / max(total, 1))),
            )
            coarse = result.coarse_face()
            out = MeshArrays(
                positions=result.positions, triangles=result.triangles,
                point_attributes=result.point_attributes, corner_attributes=result.corner_attributes,
                face_attributes={k: v[coarse] for k, v in arrays.face_attributes.items()},
                attribute_types=arrays.attribute_types,
            )
            mesh = tx.track(bridge.write_mesh(f"{ob.data.name}.loop", out, info,
                                              edges=(result.edges, result.corner_edges)))
            self._carry_marks(mesh, result, marks)
        finally:
            wm.progress_end()
        place_mesh(context, tx, ob, mesh, self.output, "loop")
        if marks.n_gons:
            self.report({"INFO"}, f"{marks.n_gons:,} face(s) with more than three corners were triangulated first "
                                  f"(Loop subdivides triangles)")
        if marks.loose_edges:
            self.report({"WARNING"}, f"{marks.loose_edges:,} loose edge(s) (in no face) were left out")
        return {"FINISHED"}

    def _carry_marks(self, mesh, result, marks):
        """Edges on marked input edges keep Mark Sharp, and what is left of their crease (sharpness drops by
        one per level), so the result shades and subdivides on as the source would."""
        if not len(marks.pairs):
            return
        if marks.sharp.any():
            bridge.write_edge_attribute(mesh, "sharp_edge", result.edge_values(marks.pairs, marks.sharp, False))
        soft = marks.crease * ~marks.sharp
        if soft.any() and self.use_creases:
            left = np.maximum(crease_to_sharpness(soft) - self.levels, 0.0) / SHARPNESS_INFINITE
            remaining = np.where(soft >= 1.0, 1.0, np.sqrt(left)).astype(np.float32)
            bridge.write_edge_attribute(mesh, "crease_edge", result.edge_values(marks.pairs, remaining, 0.0))


classes = (TESSERA_OT_loop_subdivide,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""``tessera.tessellate``: tessellate the active mesh object into a new object or in place."""

import bpy

from ..addon import bridge
from ..addon.preferences import get_preferences
from ..kernels.errors import TesseraError
from ..kernels.partition import MAX_LEVEL
from ..kernels.tessellate import check_budget, estimate, tessellate, uniform_levels

_METHODS = (("LINEAR", "Linear", "New vertices on the flat triangles: same shape, more vertices"),)
_SPACINGS = (
    ("EQUAL", "Equal", "Level rounded up to a whole number of equal segments"),
    ("FRACTIONAL_EVEN", "Fractional Even", "Even segment counts; vertices slide continuously as the level changes"),
)
_OUTPUTS = (
    ("NEW_OBJECT", "New Object", "Create a new object beside the source (from the evaluated mesh, with modifiers)"),
    ("REPLACE", "Replace Mesh", "Replace the object's own mesh data (modifiers stay and apply on top)"),
)


class TESSERA_OT_tessellate(bpy.types.Operator):
    """Tessellate the active mesh with the hardware tessellator's refinement pattern"""

    bl_idname = "tessera.tessellate"
    bl_label = "Tessellate"
    bl_options = {"REGISTER", "UNDO"}

    method: bpy.props.EnumProperty(name="Method", items=_METHODS, default="LINEAR")
    level: bpy.props.FloatProperty(
        name="Level",
        description="Segments per edge (and inner level) for every triangle",
        default=3.0, min=1.0, max=float(MAX_LEVEL), soft_max=16.0, step=100, precision=2,
    )
    spacing: bpy.props.EnumProperty(name="Spacing", items=_SPACINGS, default="EQUAL")
    output: bpy.props.EnumProperty(name="Output", items=_OUTPUTS, default="NEW_OBJECT")

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if ob is None or ob.type != "MESH":
            cls.poll_message_set("Select a mesh object to tessellate (make it active)")
            return False
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to tessellate")
            return False
        return True

    def execute(self, context):
        ob = context.active_object
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            new_mesh, skipped = self._build_mesh(context, ob, lambda f: wm.progress_update(int(100 * f)))
        except TesseraError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        if skipped:
            self.report({"INFO"}, f"Not carried over (no interpolation for these types): {', '.join(skipped)}")
        self._place(context, ob, new_mesh)
        return {"FINISHED"}

    def _build_mesh(self, context, ob, progress):
        """Read, tessellate and write; returns ``(mesh, skipped)``. Creates nothing on failure."""
        if self.output == "NEW_OBJECT":
            evaluated = ob.evaluated_get(context.evaluated_depsgraph_get())
            source = evaluated.to_mesh()
        else:
            evaluated, source = None, ob.data
        try:
            arrays, info = bridge.read_mesh(source)
        finally:
            if evaluated is not None:
                evaluated.to_mesh_clear()
        progress(0.1)
        levels = uniform_levels(arrays, self.level)
        check_budget(estimate(arrays, levels, spacing=self.spacing), get_preferences(context).memory_budget_bytes)
        result = tessellate(
            arrays, levels, spacing=self.spacing, method=self.method, progress=lambda f: progress(0.1 + 0.7 * f)
        )
        mesh = bridge.write_mesh(f"{ob.data.name}.tessellated", result, info)
        for material in ob.data.materials:
            mesh.materials.append(material)
        progress(1.0)
        return mesh, info.skipped

    def _place(self, context, ob, mesh):
        if self.output == "REPLACE":
            old = ob.data
            ob.data = mesh
            if old.users == 0:
                old_name = old.name
                bpy.data.meshes.remove(old)
                mesh.name = old_name
            return
        new = bpy.data.objects.new(f"{ob.name}.tessellated", mesh)
        for collection in ob.users_collection:
            collection.objects.link(new)
        new.matrix_world = ob.matrix_world.copy()
        for src_slot, dst_slot in zip(ob.material_slots, new.material_slots, strict=False):
            if src_slot.link == "OBJECT":
                dst_slot.link = "OBJECT"
                dst_slot.material = src_slot.material
        for other in context.selected_objects:
            other.select_set(False)
        new.select_set(True)
        context.view_layer.objects.active = new


classes = (TESSERA_OT_tessellate,)
register, unregister = bpy.utils.register_classes_factory(classes)

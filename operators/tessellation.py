"""``tessera.tessellate``: PN, Phong or linear tessellation of the active mesh, uniform or adaptive levels."""

import bpy
import numpy as np

from ..addon import bridge
from ..addon.cameras import camera_for
from ..addon.gpu_context import ensure_gpu_context
from ..addon.guarded import check_numbers, each_selected, guarded
from ..addon.preferences import get_preferences
from ..addon.settings_scaffold import copy_options
from ..addon.tessellation.settings import (
    TessellateOptions,
    adaptive_settings,
    draw_settings,
    needs_camera,
    surface_options,
)
from ..kernels.common.budget import check_budget
from ..kernels.common.errors import GPUContextError, GPUShaderError
from ..kernels.common.topology import mesh_topology
from ..kernels.tessellation.adaptive import adaptive_levels
from ..kernels.tessellation.mesh_levels import mesh_levels
from ..kernels.tessellation.tessellate import estimate, tessellate, uniform_levels
from .selection import HIDE_SOURCE, is_mesh, mesh_poll, place_mesh, read_source


def _world_positions(positions, matrix):
    m = np.array(matrix, dtype=np.float64)
    return positions @ m[:3, :3].T + m[:3, 3]


class TESSERA_OT_tessellate(TessellateOptions, bpy.types.Operator):
    """Add detail to the active mesh: smooth it with PN triangles or Phong, uniformly or where the camera needs it"""

    bl_idname = "tessera.tessellate"
    bl_label = "Tessellate"
    bl_options = {"REGISTER", "UNDO"}

    # the options: TessellateOptions (addon/tessellation/settings.py), shared with Object.tessera.tessellate
    use_object_settings: bpy.props.BoolProperty(
        name="Use Object Settings", description="Take every setting from the object (Sidebar › Tessera › Tessellate)",
        default=False, options={"SKIP_SAVE"})
    hide_source: HIDE_SOURCE

    @classmethod
    def poll(cls, context):
        return mesh_poll(cls, context, "tessellate")

    def invoke(self, context, event):
        stored = context.active_object.tessera.tessellate
        if stored.stored and not self.use_object_settings:
            copy_options(TessellateOptions, stored, self)  # start from what was used last time on this object
        return self.execute(context)

    def draw(self, context):
        draw_settings(self.layout, self)
        if self.output == "NEW_OBJECT":
            self.layout.prop(self, "hide_source")

    @guarded
    @each_selected(is_mesh)
    def execute(self, context, tx):
        ob = context.active_object
        if self.use_object_settings:
            copy_options(TessellateOptions, ob.tessera.tessellate, self)
            check_numbers(self)  # the object's settings, as the operator's own were checked
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            new_mesh, skipped, notes = self._build_mesh(context, ob, lambda f: wm.progress_update(int(100 * f)))
        finally:
            wm.progress_end()
        tx.track(new_mesh)
        if skipped:
            self.report({"INFO"}, f"Not carried over (no interpolation for these types): {', '.join(skipped)}")
        for note in notes:
            self.report({"WARNING"}, note)
        target = place_mesh(context, tx, ob, new_mesh, self.output, "tessellated", self.hide_source)
        for holder in {ob, target}:
            copy_options(TessellateOptions, self, holder.tessera.tessellate)
            holder.tessera.tessellate.stored = True
        return {"FINISHED"}

    def _levels(self, context, ob, arrays):
        """The mesh's `MeshLevels`: its edge table built once, the levels chosen on it, clamped and counted once,
        then carried through the estimate to the refinement."""
        topology = mesh_topology(arrays.triangles, len(arrays.positions))
        if self.level_mode == "UNIFORM":
            return mesh_levels(topology, uniform_levels(arrays, self.level, topology), None, self.spacing)
        camera = camera_for(context, self.camera_source) if needs_camera(self) else None
        world = _world_positions(arrays.positions.astype(np.float64), ob.matrix_world)
        edge, inner = adaptive_levels(world, arrays.triangles, adaptive_settings(self), camera, arrays.corner_normals,
                                      topology)
        return mesh_levels(topology, edge, inner, self.spacing)

    def _build_mesh(self, context, ob, progress):
        """Read, tessellate and write; returns ``(mesh, skipped, notes)``. Creates nothing on failure."""
        arrays, info, _ = read_source(context, ob, self.output)
        progress(0.1)
        levels = self._levels(context, ob, arrays)
        budget = get_preferences(context).memory_budget_bytes
        check_budget(estimate(arrays, levels), budget)
        notes = []
        result = tessellate(
            arrays, levels, method=self.method,
            options=surface_options(self), progress=lambda f: progress(0.1 + 0.7 * f),
            surface=self._gpu_surface(notes),
        )
        mesh = bridge.write_mesh(f"{ob.data.name}.tessellated", result.mesh, info,
                                 edges=result.refinement.output_edges())
        progress(1.0)
        return mesh, info.skipped, notes + result.notes

    def _gpu_surface(self, notes):
        """The compute-shader evaluator when asked for and a GPU context can be had, else None (numpy)."""
        if self.evaluate_on != "GPU" or self.method == "LINEAR":
            return None
        try:
            ensure_gpu_context()
            from ..gpu_shaders.tessellation.draw import compute_shader, evaluate_on_gpu

            compute_shader()
        except (GPUContextError, GPUShaderError) as err:
            notes.append(f"No GPU for the compute path ({err}); evaluated on the CPU with numpy")
            return None

        method, alpha, quadratic = self.method, self.alpha, self.pn_normals == "QUADRATIC"
        return lambda ref, inputs: evaluate_on_gpu(ref, inputs, method, alpha, quadratic)


classes = (TESSERA_OT_tessellate,)
register, unregister = bpy.utils.register_classes_factory(classes)

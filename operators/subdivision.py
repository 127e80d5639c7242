"""``tessera.loop_subdivide``: Loop subdivision of the active mesh ([Concheiro et al.]), creases kept, baked lighting
carried as a colour attribute; ``tessera.bake_lighting_hce``: the light on the mesh, baked by Cycles and stored
per coarse triangle as an HCE ([Concheiro et al.])."""

import time

import bpy
import numpy as np

from ..addon import bridge
from ..addon.guarded import check_editable, check_numbers, each_selected, guarded
from ..addon.preferences import get_preferences
from ..addon.render_jobs import render_key
from ..addon.subdivision.bake import read_bake, start_bake
from ..addon.subdivision.build import HCE_PROPERTY, subdivide
from ..addon.subdivision.settings import BAKED_COLOUR, LoopOptions
from ..kernels.common.errors import TesseraError
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.common.normals import face_unit_normals
from ..kernels.subdivision import hce
from ..kernels.subdivision.loop import loop_subdivide
from ..kernels.subdivision.loop_rules import SHARPNESS_INFINITE, crease_to_sharpness
from .render_job import RenderJobOperator
from .selection import HIDE_SOURCE, is_mesh, mesh_poll, place_mesh, read_source


class TESSERA_OT_loop_subdivide(LoopOptions, bpy.types.Operator):
    """Smooth the active mesh with Loop subdivision, made for triangles; sharp and creased edges stay creased"""

    bl_idname = "tessera.loop_subdivide"
    bl_label = "Loop Subdivide"
    bl_options = {"REGISTER", "UNDO"}

    # levels, boundary, use_creases, use_baked_lighting: LoopOptions (addon/subdivision/settings.py)
    output: bpy.props.EnumProperty(
        name="Output", default="NEW_OBJECT", description="Make a new object, or replace this object's mesh",
        items=(("NEW_OBJECT", "New Object", "Add a new object beside the source (its modifiers applied first)"),
               ("REPLACE", "Replace Mesh", "Replace the object's mesh (one undo step brings it back)")))
    hide_source: HIDE_SOURCE

    @classmethod
    def poll(cls, context):
        return mesh_poll(cls, context, "subdivide")

    @guarded
    @each_selected(is_mesh)
    def execute(self, context, tx):
        ob = context.active_object
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            arrays, info, marks = read_source(context, ob, self.output)
            build = subdivide(arrays, marks, self, ob.data.get(HCE_PROPERTY),
                              get_preferences(context).memory_budget_bytes,
                              lambda done, total: wm.progress_update(int(90 * done / max(total, 1))))
            result, baked = build.result, build.baked
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
            if baked is not None:
                bridge.write_point_colours(mesh, BAKED_COLOUR, baked)
        finally:
            wm.progress_end()
        place_mesh(context, tx, ob, mesh, self.output, "loop", self.hide_source)
        for note in build.notes:
            self.report({"WARNING"}, note)
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


#: The last lighting bake's colours, by what its render depended on: the redo panel re-encodes them.
_last = {"key": None, "colours": None, "device": "", "what": None}
#: Bakes at most this large are kept for the redo panel.
_KEEP_BYTES = 256 * 2**20


def _encode(colours, what, depth, normals, tolerance):
    """The HCE of baked ``colours`` (N·4^depth, 4): ``(trees, packed bytes)``; numpy only (runs on a worker thread)."""
    _, arrays, sub = what
    n_f, leaves = len(arrays.triangles), 4**depth
    sub_normals = face_unit_normals(sub.positions, sub.triangles).reshape(n_f, leaves, 3)
    trees = hce.encode_samples(colours.reshape(n_f, leaves, 4), sub_normals,
                               face_unit_normals(arrays.positions, arrays.triangles), m=normals, tolerance=tolerance)
    return trees, hce.pack_container(trees, arrays.triangles, 4)


#: The last bake's colours, by what their render depended on: the redo panel's Normals and Colour Tolerance reuse them.
_last = {"key": None, "rendered": None, "what": None, "device": ""}


class TESSERA_OT_bake_lighting_hce(RenderJobOperator, bpy.types.Operator):
    """Bake each selected mesh's light with Cycles and store it on the mesh, so Loop Subdivide shows it at any level"""

    bl_idname = "tessera.bake_lighting_hce"
    bl_label = "Bake Lighting"
    bl_options = {"REGISTER", "UNDO"}

    depth: bpy.props.IntProperty(
        name="Depth", description="Loop level the light is baked at (finer levels share the colours of the "
        "triangles they come from)", default=2, min=0, max=4)
    samples: bpy.props.IntProperty(name="Samples", description="Cycles samples per texel", default=32, min=1,
                                   max=4096, soft_max=512)
    normals: bpy.props.IntProperty(
        name="Normals", description="Extra directions stored per triangle, each with its own colours (for light "
        "that changes with the surface's direction, e.g. across a bend)", default=4, min=0, max=8)
    tolerance: bpy.props.FloatProperty(
        name="Colour Tolerance", description="Colours closer than this are stored once (0: every triangle at "
        "Depth keeps its own colour)", default=1.0 / 255, min=0.0, max=1.0, precision=4, subtype="FACTOR")
    albedo: bpy.props.BoolProperty(name="Surface Colour", default=True,
                                   description="Multiply by the surface colour (off: the light alone)")

    job_label = "Baking lighting with Cycles"
    cancelled = "Lighting bake cancelled: nothing was changed"
    _last = _last

    @classmethod
    def poll(cls, context):
        return mesh_poll(cls, context, "bake")

    def _check(self, context):
        check_numbers(self)
        check_editable(context.active_object.data, "baked lighting stored on its mesh",
                       "Make the object and its mesh local (Object › Relations › Make Local) first")

    def _render_key(self, context):
        """What the bake's render depends on (the object, everything around it that renders, the world, the device:
        `render_jobs.render_key`) and the settings that change the render."""
        return render_key(context, context.active_object, surroundings=True), self.depth, self.samples, self.albedo

    def _start(self, context):
        """Subdivide to Depth and start the worker: ``(BakeJob, (name, arrays, subdivision))``; refusals raise."""
        ob = context.active_object
        self._check(context)
        budget = get_preferences(context).memory_budget_bytes
        arrays, _ = bridge.read_mesh(ob.data)
        marks = bridge.read_edge_marks(ob.data)
        sub = loop_subdivide(arrays.positions, arrays.triangles, self.depth,
                             creases=(marks.pairs, crease_to_sharpness(marks.crease)), budget_bytes=budget)
        material = arrays.face_attributes.get("material_index")
        material = np.zeros(len(arrays.triangles), np.int32) if material is None else material.reshape(-1)
        bj = start_bake(context, ob, sub.positions, sub.triangles, material[sub.coarse_face()], self.samples,
                        self.albedo, budget)
        return bj, (ob.name, arrays, sub)

    @staticmethod
    def _read(handle, what):
        return read_bake(handle)

    def _settings(self):
        return self.depth, self.normals, self.tolerance

    @staticmethod
    def _prepare(colours, what, depth, normals, tolerance):
        return _encode(colours, what, depth, normals, tolerance)

    def _make_steps(self, context, tx, encoded, what, device):
        """Store the encoded HCE on the mesh (undone if anything fails after): one step."""
        name, arrays, _ = what
        trees, blob = encoded
        ob = bpy.data.objects.get(name)
        if ob is None or len(ob.data.polygons) == 0:
            raise TesseraError(f"{name!r} was deleted while its light was baked: nothing was changed")
        current, _ = bridge.read_mesh(ob.data)
        if not np.array_equal(current.triangles, arrays.triangles):
            raise TesseraError(f"{name!r} was edited while its light was baked: nothing was changed; bake again")
        n_f = len(arrays.triangles)
        old = ob.data.get(HCE_PROPERTY)
        old = bytes(old) if isinstance(old, bytes | bytearray) else old
        bridge.set_bytes_property(ob.data, HCE_PROPERTY, blob)
        tx.on_rollback(lambda: bridge.set_bytes_property(ob.data, HCE_PROPERTY, old))
        nodes = sum(len(t.subdivided) for t in trees)
        on = device or "the CPU"
        self.report({"INFO"}, f"Baked lighting on {on}: {n_f:,} triangles, {nodes / n_f:.1f} nodes and "
                              f"{np.mean([len(t.normals) for t in trees]):.1f} extra normals each, "
                              f"{len(blob) / 1024:,.0f} KiB, {time.perf_counter() - self._t0:.1f} s")
        return {"FINISHED"}
        yield  # a generator of one step


classes = (TESSERA_OT_loop_subdivide, TESSERA_OT_bake_lighting_hce)
register, unregister = bpy.utils.register_classes_factory(classes)

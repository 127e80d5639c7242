"""``tessera.parametric_surface_add``: a one-point parametric surface (seed 000 §2.3) baked into a mesh at the 3D
cursor: welded where it closes, with its domain coordinates as UVs. ``tessera.curve_adaptive``: a curve's Bézier
splines as polylines sampled where they bend (digest 001 §5.5.2)."""

import bpy
import numpy as np

from ..addon import bridge
from ..addon.cameras import camera_for, object_camera
from ..addon.guarded import guarded
from ..addon.surfaces.settings import (
    SURFACE_ITEMS,
    CurveOptions,
    SurfaceOptions,
    curve_sampling,
    draw_curve_options,
    draw_surface_options,
    surface_from,
)
from ..kernels.common.errors import InvalidInputError
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.surfaces.adaptive_curves import adaptive_spline
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


class TESSERA_OT_curve_adaptive(CurveOptions, bpy.types.Operator):
    """Turn the active curve's Bézier splines into polylines with segments where they bend (by curvature, a
    tolerance, or pixels for the camera), optionally as several offset copies"""

    bl_idname = "tessera.curve_adaptive"
    bl_label = "Curve to Adaptive Polyline"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if context.mode != "OBJECT" or ob is None or ob.type != "CURVE":
            cls.poll_message_set("Select a curve object in Object Mode")
            return False
        return True

    def draw(self, context):
        draw_curve_options(self.layout, self)

    @guarded
    def execute(self, context, tx):
        ob = context.active_object
        settings = curve_sampling(self)
        camera = None
        if self.mode == "SCREEN":
            camera = object_camera(camera_for(context, self.camera_source, "Sampling for the screen"),
                                   ob.matrix_world)
        out, skipped, counts = [], 0, []
        for sp in bridge.read_splines(ob.data):
            if sp.kind == "BEZIER" and len(sp.co) >= 2:
                for a in adaptive_spline(sp.co, sp.handle_left, sp.handle_right, sp.radius, sp.tilt, sp.cyclic,
                                         settings, camera):
                    out.append(bridge.SplineArrays("POLY", a.points, None, None, a.radius, a.tilt, a.cyclic,
                                                   sp.material_index))
                counts.append(a.counts)
            elif sp.kind == "POLY":
                offset = np.asarray(settings.offset, np.float64)
                for k in range(settings.copies):
                    out.append(bridge.SplineArrays("POLY", sp.co + offset * k / settings.copies, None, None,
                                                   sp.radius, sp.tilt, sp.cyclic, sp.material_index))
            else:
                skipped += 1
        if not out:
            raise InvalidInputError(f"Curve {ob.name!r} has no Bézier or poly spline to sample"
                                    + (f" ({skipped} NURBS spline(s): convert them to Bézier first)" if skipped
                                       else ""))
        data = tx.track(bridge.write_poly_curve(f"{ob.data.name}.adaptive", out, ob.data.dimensions))
        for mat in ob.data.materials:
            data.materials.append(mat)
        new = tx.new_object(f"{ob.name}.adaptive", data)
        new.matrix_world = ob.matrix_world.copy()
        context.collection.objects.link(new)
        select_only(context, [new])
        seg = np.concatenate(counts) if counts else np.zeros(0, np.int64)
        words = (f"{len(seg):,} Bézier segments -> {int(seg.sum()):,} ({int(seg.min())}-{int(seg.max())} each)"
                 if len(seg) else "no Bézier segment")
        note = f"; {skipped} NURBS spline(s) left out (convert them to Bézier)" if skipped else ""
        self.report({"WARNING" if skipped else "INFO"}, f"{len(out):,} polylines: {words}{note}")
        return {"FINISHED"}


classes = (TESSERA_OT_parametric_surface_add, TESSERA_OT_curve_adaptive)
register, unregister = bpy.utils.register_classes_factory(classes)

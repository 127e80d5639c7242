"""``tessera.parametric_surface_add``: a one-point parametric surface ([Nunes 2011, §2.3]) baked into a mesh at the 3D
cursor: welded where it closes, with its domain coordinates as UVs. ``tessera.curve_adaptive``: a curve's Bézier
splines as polylines sampled where they bend ([Nellmedin 2014, §5.5.2])."""

import dataclasses

import bpy
import numpy as np

from ..addon import bridge, curve_bridge
from ..addon.cameras import camera_for, object_camera
from ..addon.guarded import check_numbers, each_selected, guarded
from ..addon.preferences import get_preferences
from ..addon.settings_scaffold import copy_options
from ..addon.surfaces.settings import (
    SURFACE_ITEMS,
    CurveOptions,
    ParametricOptions,
    PatchOptions,
    curve_sampling,
    draw_curve_options,
    draw_patch_options,
    draw_surface_options,
    patch_lod,
    surface_from,
)
from ..addon.surfaces.sources import control_points
from ..kernels.common.budget import check_bytes
from ..kernels.common.curves import nurbs
from ..kernels.common.curves.bezier_curves import (
    MAX_TOLERANCE_SEGMENTS,
    CurveSampling,
    adaptive_nurbs,
    adaptive_spline,
    offset_copies,
)
from ..kernels.common.errors import InvalidInputError
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.surfaces import bezier_patches as bp
from ..kernels.surfaces.domain_mesh import surface_mesh
from .selection import object_poll, place_mesh, select_only

#: Memory per point of an adaptive polyline: Blender's curve point (position and weight, radius, tilt, flags) and the
#: float64 arrays it is written from.
_BYTES_PER_CURVE_POINT = 96


class TESSERA_OT_parametric_surface_add(ParametricOptions, bpy.types.Operator):
    """Add a mathematical surface (torus, Klein bottle, Möbius band and more) as a mesh or as a live GPU object"""

    bl_idname = "tessera.parametric_surface_add"
    bl_label = "Parametric Surface"
    bl_options = {"REGISTER", "UNDO"}

    output: bpy.props.EnumProperty(name="Make", default="MESH", description="A mesh, or a live object", items=(
        ("MESH", "Mesh", "Bake the surface into a mesh"),
        ("LIVE", "Live", "An empty drawn as the surface by the GPU (no mesh; Bake Surface makes one on demand)")))

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to add a surface")
            return False
        return True

    def draw(self, context):
        self.layout.prop(self, "output")
        draw_surface_options(self.layout, self)

    @guarded
    def execute(self, context, tx):
        label = dict((k, name) for k, name, _ in SURFACE_ITEMS)[self.surface]
        if self.output == "LIVE":
            surface_from(self).point(np.zeros(1), np.zeros(1))  # refuse bad parameters now, not in the viewport
            ob = tx.new_object(label, None)
            copy_options(ParametricOptions, self, ob.tessera.surface)
            ob.tessera.surface.is_surface = True
            ob.empty_display_size = 0.25
            words = "drawn live from one point"
        else:
            mesh = surface_mesh(surface_from(self), self.factor)
            data = tx.track(bridge.write_mesh(label, _surface_arrays(mesh)))
            data.shade_smooth()
            ob = tx.new_object(label, data)
            words = f"{len(mesh.positions):,} vertices, {len(mesh.triangles):,} triangles"
        ob.location = context.scene.cursor.location
        context.collection.objects.link(ob)
        select_only(context, [ob])
        self.report({"INFO"}, f"{label}: {words}")
        return {"FINISHED"}


def _surface_arrays(mesh, offsets=None):
    """`MeshArrays` of a baked `DomainMesh`, or of one copy of it at each of ``offsets`` (N, 3)."""
    pos, tris, uvs = mesh.positions, mesh.triangles, mesh.uvs
    if offsets is not None:
        n = len(pos)
        pos = (pos[None] + np.asarray(offsets, np.float32)[:, None]).reshape(-1, 3)
        tris = (tris[None] + (np.arange(len(offsets)) * n)[:, None, None]).reshape(-1, 3)
        uvs = np.broadcast_to(uvs, (len(offsets),) + uvs.shape).reshape(-1, 3, 2)
    return MeshArrays(positions=pos, triangles=tris.astype(np.int32), corner_attributes={"UVMap": uvs},
                      attribute_types={"UVMap": "FLOAT2"})


class TESSERA_OT_parametric_surface_bake(bpy.types.Operator):
    """Make a mesh of the active live surface: one copy at each of its control points, at its Factor"""

    bl_idname = "tessera.parametric_surface_bake"
    bl_label = "Bake Surface"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if context.mode != "OBJECT" or ob is None or not ob.tessera.surface.is_surface:
            cls.poll_message_set("Select a live parametric surface (Add > Tessera > Parametric Surface, Live)")
            return False
        return True

    @guarded
    @each_selected(lambda ob: ob.tessera.surface.is_surface)
    def execute(self, context, tx):
        ob = context.active_object
        s = ob.tessera.surface
        check_numbers(s)
        points = control_points(ob)
        budget = get_preferences(context).memory_budget_bytes
        per = surface_mesh(surface_from(s), s.factor)
        size = len(points) * (per.positions.nbytes + per.triangles.nbytes + per.uvs.nbytes) * 4
        check_bytes(size, budget, f"{len(points):,} surfaces at factor {s.factor} would be made", "a lower Factor")
        data = tx.track(bridge.write_mesh(f"{ob.name}.baked", _surface_arrays(per, points)))
        data.shade_smooth()
        new = tx.new_object(f"{ob.name}.baked", data)
        new.matrix_world = ob.matrix_world.copy()
        context.collection.objects.link(new)
        select_only(context, [new])
        self.report({"INFO"}, f"{len(points):,} surface(s), {len(data.polygons):,} triangles")
        return {"FINISHED"}


class TESSERA_OT_curve_adaptive(CurveOptions, bpy.types.Operator):
    """Turn the active curve's Bézier and NURBS splines into polylines with more points where they bend"""

    bl_idname = "tessera.curve_adaptive"
    bl_label = "Curve to Adaptive Polyline"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return object_poll(cls, context, {"CURVE"}, "Select a curve object in Object Mode")

    def draw(self, context):
        draw_curve_options(self.layout, self)

    @guarded
    @each_selected(lambda ob: ob.type == "CURVE")
    def execute(self, context, tx):
        ob = context.active_object
        settings = curve_sampling(self)
        if settings.mode == "TOLERANCE":  # the tolerance is in scene units; the splines are in the object's
            settings = dataclasses.replace(settings, tolerance=settings.tolerance / _largest_scale(ob))
        camera = None
        if self.mode == "SCREEN":
            camera = object_camera(camera_for(context, self.camera_source, "Sampling for the screen"),
                                   ob.matrix_world)
        once = dataclasses.replace(settings, copies=1)  # sampled once; the copies only after the budget allows them
        sampled, counts, over, worst = [], [], 0, (0.0, 0)
        for k, sp in enumerate(curve_bridge.read_splines(ob.data, ob.name)):
            if sp.kind in ("BEZIER", "NURBS") and len(sp.co) < 2:
                raise InvalidInputError(f"Spline {k} of {ob.name!r} has a single point: delete it or add points")
            if sp.kind == "BEZIER":
                a = adaptive_spline(sp.co, sp.handle_left, sp.handle_right, sp.radius, sp.tilt, sp.cyclic, once,
                                    camera)[0]
            elif sp.kind == "NURBS":
                a = adaptive_nurbs(sp.co, sp.weight, nurbs.Direction(sp.order, sp.knot_mode, sp.cyclic), sp.radius,
                                   sp.tilt, once, camera, what=f"NURBS spline {k}")[0]
            else:
                sampled.append((sp.co, sp.radius, sp.tilt, sp.cyclic, sp.material_index))
                continue
            sampled.append((a.points, a.radius, a.tilt, a.cyclic, sp.material_index))
            counts.append(a.counts)
            if a.deviation is not None and settings.mode == "TOLERANCE":
                over += int((a.deviation > settings.tolerance).sum())
                worst = max(worst, (float(a.deviation.max(initial=0.0)) / settings.tolerance, k))
        if not sampled:
            raise InvalidInputError(f"Curve {ob.name!r} has no spline to sample: add one, or select another curve")
        n_points = sum(len(s[0]) for s in sampled) * settings.copies
        check_bytes(n_points * _BYTES_PER_CURVE_POINT, get_preferences(context).memory_budget_bytes,
                    f"The polylines would have {n_points:,} points", "fewer Copies, fewer Max Segments or a larger "
                    "Tolerance")
        out = [curve_bridge.SplineArrays("POLY", p, None, None, radius, tilt, cyclic, material)
               for points, radius, tilt, cyclic, material in sampled
               for p in offset_copies(points, settings.copies, settings.offset)]
        data = tx.track(curve_bridge.write_poly_curve(f"{ob.data.name}.adaptive", out, ob.data.dimensions))
        place_mesh(context, tx, ob, data, "NEW_OBJECT", "adaptive")
        seg = np.concatenate(counts) if counts else np.zeros(0, np.int64)
        words = (f"{len(seg):,} curve segments -> {int(seg.sum()):,} ({int(seg.min())}-{int(seg.max())} each)"
                 if len(seg) else "no curve segment")
        note = (f"; {over} segment(s) stay over the tolerance at Max Segments {settings.max_segments}, the worst "
                f"{worst[0]:,.1f} times over in spline {worst[1]}: raise Max Segments or the Tolerance") if over else ""
        self.report({"WARNING" if over else "INFO"}, f"{len(out):,} polylines: {words}{note}")
        return {"FINISHED"}


class TESSERA_OT_surface_tessellate(PatchOptions, bpy.types.Operator):
    """Turn the active surface object into a mesh with detail where it bends or near the camera, without cracks"""

    bl_idname = "tessera.surface_tessellate"
    bl_label = "Tessellate Surface"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return object_poll(cls, context, {"SURFACE"}, "Select a surface object (Add > Surface) in Object Mode")

    def draw(self, context):
        draw_patch_options(self.layout, self)

    @guarded
    @each_selected(lambda ob: ob.type == "SURFACE")
    def execute(self, context, tx):
        ob = context.active_object
        surfaces, rows = curve_bridge.read_surface_splines(ob.data, ob.name)
        if not surfaces and not rows:
            raise InvalidInputError(f"Surface {ob.name!r} has no spline: add one in Edit Mode, or select another")
        lod = patch_lod(self)
        scale = _largest_scale(ob)
        lod = dataclasses.replace(lod, tolerance=lod.tolerance / scale)  # scene units -> the object's
        cam = None
        if set(lod.metrics) & {"DISTANCE", "EDGE_LENGTH"}:
            cam = object_camera(camera_for(context, self.camera_source, "Camera levels"), ob.matrix_world)
        budget = get_preferences(context).memory_budget_bytes
        words, warn = [], False
        if surfaces:
            patch_set = nurbs.patches_of([s for _, s in surfaces], [k for k, _ in surfaces])
            result = bp.tessellate_surface(patch_set.patches, lod, cam, budget)
            mesh = result.mesh
            corner_uv = result.patch_uv(patch_set.box)  # each spline's own (u, v)
            arrays = MeshArrays(positions=mesh.positions, triangles=mesh.triangles, point_normals=mesh.normals,
                                corner_attributes={"UVMap": corner_uv}, attribute_types={"UVMap": "FLOAT2"})
            words.append(f"{len(patch_set.patches):,} patches in {len(result.parent):,} parts, sides "
                         f"{int(result.edge_levels.min())}-"
                         f"{int(result.edge_levels.max())} segments, {len(mesh.triangles):,} triangles")
            if "TOLERANCE" in lod.metrics:
                worst = float(np.nanmax(result.deviation)) * scale  # in scene units
                if len(result.unmet):
                    warn = True
                    splines = sorted({surfaces[int(patch_set.spline[result.parent[q]])][0] for q in result.unmet})
                    words.append(f"{len(result.unmet)} part(s) of spline(s) {', '.join(map(str, splines))} stay "
                                 f"over the tolerance at Max Level {lod.max_level} (up to {worst:.3g}): raise Max "
                                 "Level or the Tolerance")
                else:
                    words.append(f"within {self.tolerance:g} of the surface (largest measured {worst:.3g})")
        line_points, line_edges = _row_lines(rows, lod.tolerance)
        name = f"{ob.data.name}.tessellated"
        data = tx.track(bridge.write_mesh(name, arrays) if surfaces else bpy.data.meshes.new(name))
        if len(line_points):
            bridge.append_loose_edges(data, line_points, line_edges)
            words.append(f"{len(rows)} curve(s) as {len(line_edges):,} edges")
        if surfaces:
            data.shade_smooth()
        place_mesh(context, tx, ob, data, "NEW_OBJECT", "tessellated")
        self.report({"WARNING" if warn else "INFO"}, "; ".join(words))
        return {"FINISHED"}


def _largest_scale(ob):
    """How much the object's transform stretches a length at most (its largest singular value; 1 if degenerate)."""
    m = np.array(ob.matrix_world, np.float64)[:3, :3]
    s = float(np.linalg.svd(m, compute_uv=False).max()) if np.all(np.isfinite(m)) else 0.0
    return s if s > 0 else 1.0


def _row_lines(rows, tolerance):
    """The single-row splines (curves in a surface object) as polylines within ``tolerance``: (points (N, 3),
    edges (K, 2) int32)."""
    points, edges, base = [], [], 0
    sampling = CurveSampling(mode="TOLERANCE", tolerance=tolerance, max_segments=MAX_TOLERANCE_SEGMENTS)
    for k, co, direction in rows:
        n = len(co)
        [a] = adaptive_nurbs(co[:, :3], co[:, 3], direction, np.ones(n), np.zeros(n), sampling,
                             what=f"surface spline {k}")
        m = len(a.points)
        idx = base + np.arange(m)
        pairs = np.stack([idx[:-1], idx[1:]], 1)
        if a.cyclic:
            pairs = np.concatenate([pairs, [[idx[-1], idx[0]]]])
        points.append(a.points)
        edges.append(pairs)
        base += m
    if not points:
        return np.zeros((0, 3)), np.zeros((0, 2), np.int32)
    return np.concatenate(points), np.concatenate(edges).astype(np.int32)


classes = (TESSERA_OT_parametric_surface_add, TESSERA_OT_parametric_surface_bake, TESSERA_OT_curve_adaptive,
           TESSERA_OT_surface_tessellate)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Objects made in Blender for the tests, the benches and the demo (not shipped): Bézier control nets as a surface
object, as an artist would have them to tessellate."""

import numpy as np


def write_surface_patches(nets):
    """A new SURFACE object in the active collection holding ``nets`` (P, 4, 4, 3) (row, column, xyz) as P 4 x 4
    NURBS splines with endpoint knots (Bézier patches, u along a row), at the origin, selected and active.

    Uses Blender's own operators (the Python API cannot size a surface spline's v direction); the caller is in
    Object Mode with a 3D context. Returns the object; raises ValueError for no net.
    """
    import bpy

    nets = np.asarray(nets, np.float64)
    if nets.ndim != 4 or nets.shape[1:] != (4, 4, 3) or len(nets) == 0:
        raise ValueError(f"Surface patches must be (P, 4, 4, 3) with P > 0, got {nets.shape}")
    made = []
    for net in nets:
        bpy.ops.surface.primitive_nurbs_surface_surface_add()
        ob = bpy.context.active_object
        spline = ob.data.splines[0]
        co = np.c_[net.transpose(1, 0, 2).reshape(16, 3), np.ones(16)]  # u fastest
        spline.points.foreach_set("co", co.astype(np.float32).ravel())
        spline.use_endpoint_u = spline.use_endpoint_v = True
        ob.location = (0.0, 0.0, 0.0)
        made.append(ob)
    for ob in bpy.context.selected_objects:
        ob.select_set(False)
    for ob in made:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = made[0]
    if len(made) > 1:
        bpy.ops.object.join()
    return bpy.context.active_object

"""Every other preview as an artist meets it, each against its applied result drawn by Blender (the oracle of
`common`): Loop on a smooth Suzanne, tubes on a Bézier circle, a terrain from an image, a live parametric surface.
Each is recorded as ``<name>_vs_applied``; ``<name>_source_hidden_pixels`` counts what is still drawn where the
source is hidden with its preview on."""

import bpy
import numpy as np
from common import clean_scene, frame, operate, oracle, shot, silhouette, tube_circle

SETTLE = 0.3


def setter(ob, group, name="preview"):
    """``preview(on)`` for the oracle: sets ``ob.tessera.<group>.<name>``."""

    def preview(on):
        setattr(getattr(ob.tessera, group), name, on)

    return preview


def hidden_pixels(w, ob, group, empty, name):
    """With the preview on and ``ob`` hidden, the pixels still differing from the empty scene (none expected)."""
    setter(ob, group)(True)
    ob.hide_set(True)
    w.results[f"{name}_source_hidden_pixels"] = int(silhouette(shot(w, f"{name}_hidden"), empty).sum())
    ob.hide_set(False)
    setter(ob, group)(False)


def staged(w, ob, name, view="FRONT"):
    """Frame ``ob`` along ``view`` and shoot the empty scene (``ob`` hidden)."""
    frame(w, [ob], view)
    ob.hide_set(True)
    empty = shot(w, f"{name}_empty")
    ob.hide_set(False)
    return empty


def height_image(size=129):
    """Smooth hills as a float image in this file (the terrain's Image source)."""
    y, x = np.mgrid[0:size, 0:size] / (size - 1)
    h = 0.5 + 0.25 * np.sin(6.0 * x) * np.cos(5.0 * y) + 0.2 * np.exp(-((x - 0.6) ** 2 + (y - 0.4) ** 2) / 0.02)
    image = bpy.data.images.new("Hills", size, size, float_buffer=True, is_data=True)
    pixels = np.ones((size, size, 4), np.float32)
    pixels[..., :3] = h[..., None]
    image.pixels.foreach_set(pixels.ravel())
    return image


def lit_both_ways(w, name, empty, preview, applied, source=None):
    """The oracle in Solid mode's studio lighting (``name``), then in its MatCap lighting (``name_matcap``)."""
    oracle(w, name, empty, preview, applied, source)
    w.space.shading.light = "MATCAP"
    w.results["matcap"] = w.space.shading.studio_light
    preview(True)  # the first MatCap frame asks a timer to read the MatCap
    yield SETTLE
    preview(False)
    oracle(w, f"{name}_matcap", empty, preview, applied, source)
    w.space.shading.light = "STUDIO"
    yield SETTLE


def run(w):
    # Loop: a smooth Suzanne, two levels
    clean_scene(w)
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ob.tessera.loop.levels = 2
    empty = staged(w, ob, "loop")
    yield SETTLE
    yield from lit_both_ways(w, "loop", empty, setter(ob, "loop"),
                             lambda: operate(w, bpy.ops.tessera.loop_subdivide, ob, levels=2), source=ob)
    hidden_pixels(w, ob, "loop", empty, "loop")

    # Tubes on a Bézier circle
    clean_scene(w)
    ob, tubes = tube_circle(w)
    empty = staged(w, ob, "tubes", (0.9, 0.0, 0.5))
    yield SETTLE
    yield from lit_both_ways(w, "tubes", empty, setter(ob, "tubes"),
                             lambda: operate(w, bpy.ops.tessera.tubes, ob, **tubes), source=ob)
    hidden_pixels(w, ob, "tubes", empty, "tubes")

    # A terrain from an image, seen from above at an angle
    clean_scene(w)
    image = height_image()
    ob = operate(w, bpy.ops.tessera.terrain_add, source="IMAGE", image_name=image.name)
    w.results["terrain_triangles"] = len(ob.data.polygons)
    empty = staged(w, ob, "terrain", (1.0, 0.0, 0.6))
    yield SETTLE
    yield from lit_both_ways(w, "terrain", empty, setter(ob, "terrain"), lambda: _copy_of(ob), source=ob)
    hidden_pixels(w, ob, "terrain", empty, "terrain")

    # A displacement map on a grid: the tessellation preview sampling it (linear, level 1: the mesh's own vertices)
    # against Blender drawing the grid its map's modifier displaces
    clean_scene(w)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=64, y_subdivisions=64, size=4.0)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    operate(w, bpy.ops.tessera.displacement_add, ob, width=128, height=128)
    v, u = (np.mgrid[0:128, 0:128] + 0.5) / 128
    rgba = np.ones((128, 128, 4), np.float32)
    rgba[..., :3] = (0.5 + 0.5 * np.sin(9.0 * u) * np.cos(7.0 * v))[..., None]
    d = ob.tessera.displacement
    d.image.pixels.foreach_set(rgba.ravel())
    d.image.update()
    d.mid_level, d.strength = 0.5, 0.6
    t = ob.tessera.tessellate
    t.method, t.level_mode, t.level = "LINEAR", "UNIFORM", 1
    empty = staged(w, ob, "displacement", (1.0, 0.0, 0.6))
    yield SETTLE

    def displaced_preview(on):
        t.preview = on

    def displaced_mesh():  # the object itself, displaced by its map's modifier, drawn by Blender
        copy = bpy.data.objects.new(f"{ob.name} displaced", ob.data)
        copy.matrix_world = ob.matrix_world.copy()
        bpy.context.collection.objects.link(copy)
        copy.tessera.displacement.mode = d.mode
        copy.tessera.displacement.uv_map = d.uv_map
        copy.tessera.displacement.mid_level, copy.tessera.displacement.strength = d.mid_level, d.strength
        copy.tessera.displacement.image = d.image
        return copy

    ob.hide_set(False)
    yield from lit_both_ways(w, "displacement", empty, displaced_preview, displaced_mesh, source=ob)

    # A live parametric surface against the same surface made as a mesh
    clean_scene(w)
    live = operate(w, bpy.ops.tessera.parametric_surface_add, output="LIVE")
    live.empty_display_size = 0.0  # the empty's axes are not the surface
    mesh = operate(w, bpy.ops.tessera.parametric_surface_add, output="MESH")  # to frame: an empty has no size
    frame(w, [mesh], (1.0, 0.0, 0.6))
    bpy.data.objects.remove(mesh)
    live.hide_set(True)
    empty = shot(w, "surface_empty")
    yield SETTLE

    def preview(on):
        live.hide_set(not on)

    s = live.tessera.surface
    yield from lit_both_ways(w, "surface", empty, preview, lambda: operate(
        w, bpy.ops.tessera.parametric_surface_add, output="MESH", factor=s.factor, surface=s.surface))


def _copy_of(ob):
    """The terrain's baked mesh as an object of its own (what *Terrain from Height Map* drew), in the same place."""
    copy = bpy.data.objects.new(f"{ob.name} baked", ob.data)
    copy.matrix_world = ob.matrix_world.copy()
    bpy.context.collection.objects.link(copy)
    return copy

"""Tessera demo, headless: PN and Phong on Suzanne, adaptive levels for a camera, export, pictures.

Run with ``make demo`` (or ``.venv/bin/python samples/demo.py`` after ``make setup``; also works as
``blender --background --python samples/demo.py``). Writes:

- ``out/demo.png``: original / Phong / PN Suzanne (uniform level 4), each with its wireframe;
- ``out/demo_adaptive.png``: four Suzannes receding from the camera, PN with adaptive levels for that
  camera (projected edge length, 18 px): the far ones get fewer triangles;
- ``out/demo_tubes.png``: streamlines of an ABC flow (a wire mesh) turned into tubes with sides per tube
  from the camera (level of detail: near tubes round, far ones triangular) and the pixel clamp;
- ``out/demo_brushes.png``: a flat plane (left) turned into a landscape (right) by a scripted set of
  displacement-brush strokes (ridges, a valley, a plateau, noise, smoothing) replayed through
  ``tessera.displacement_stroke``; the map is also written as ``out/demo_map.exr`` (32-bit float);
- ``out/demo_terrain.png``: a synthetic ridged terrain (1025², written as a 16-bit PNG height map) added with
  ``tessera.terrain_add`` and meshed adaptively for the scene camera, wireframe on top;
- ``out/demo_geotiff.png``: a DEM written as two adjacent GeoTIFF tiles (metres, 30 m samples, a lake of no-data),
  picked together and added as one terrain at true scale with the lake cut out (No-Data: Holes);
- ``out/demo_loop.png``: Suzanne as Add > Monkey gives it, Loop subdivision level 2 of it, and a cube with its top
  edges marked sharp at Loop level 3 (``tessera.loop_subdivide``);
- ``out/demo_loop_hce.png``: a Cornell-like box; Suzanne's light baked by Cycles into its HCE, shown on the coarse
  mesh (left) and carried to Loop level 3 (right) as vertex colours (``tessera.bake_lighting_hce``);
- ``out/demo_node_groups.png``: four objects made by Tessera's node groups alone, each captioned with its modifier
  stack: Suzanne under PN Triangles, a sharp-rimmed cylinder under Phong (Split), a trefoil curve
  under Tubes, a height-map image under Terrain (levels for the camera);
- ``out/demo_surfaces.png``: the one-point parametric surfaces (``tessera.parametric_surface_add``), wireframe;
- ``out/demo_teapot.png``: the Utah teapot's body of revolution (24 bicubic patches) by ``tessera.surface_tessellate``,
  curvature levels and distance levels for the camera, wireframe;
- ``out/demo_lic.png``: line-integral-convolution textures of the ABC flow and a vortex
  (``tessera.vector_field_texture``);
- ``out/demo_nailboard.png``: a Cycles-rendered Suzanne drawn by the GPU from its nailboard (rendered by the
  background worker, pre-warped, per-texel depth) among GPU-drawn geometry: the floor cuts through it;
- ``out/demo_gpu_preview.png``: the live preview's renderer, offscreen: adaptive PN Suzannes drawn from instanced
  refinement patterns, lit / with the output wireframe / displaced by a map sampled in the vertex shader;
- ``out/demo.glb``, ``out/demo.obj`` (+ .mtl): the PN result through Blender's own exporters.
"""

import os
import sys
import time
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = Path(os.environ.get("TESSERA_DEMO_OUT", ROOT / "out"))  # where the pictures and files go
LEVEL = 4


def enable_addon():
    """Enable the source tree as an extension (a dev repo holding a link named after the package id)."""
    sys.path.insert(0, str(ROOT / "tools"))
    from source_tree import as_package, enable_extension

    try:
        enable_extension(as_package("tessera-demo-repo-"), "tessera_demo")
    except RuntimeError as err:
        sys.exit(f"demo: {err}")


def material(name, rgba):
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = rgba
    return mat


def wire_overlay(ob, mat, thickness=0.006):
    """A copy of ``ob`` drawn as thin wires (Wireframe modifier) so the triangles show in a render."""
    wire = bpy.data.objects.new(f"{ob.name}.wire", ob.data)
    bpy.context.scene.collection.objects.link(wire)
    wire.matrix_basis = ob.matrix_basis.copy()  # matrix_world is stale until the depsgraph updates
    mod = wire.modifiers.new("Wire", "WIREFRAME")
    mod.thickness = thickness
    mod.use_replace = True
    mod.use_even_offset = False
    mod.material_offset = 0
    wire.material_slots[0].link = "OBJECT"
    wire.material_slots[0].material = mat
    return wire


def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)


def add_suzanne(location, mat):
    bpy.ops.mesh.primitive_monkey_add(location=location)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ob.data.materials.append(mat)
    return ob


def add_camera(location, rotation, lens=50):
    scene = bpy.context.scene
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = location, rotation
    cam.data.lens = lens
    scene.camera = cam
    return cam


def tessellate(source, **settings):
    bpy.context.view_layer.objects.active = source
    t0 = time.perf_counter()
    result = bpy.ops.tessera.tessellate(output="NEW_OBJECT", hide_source=False, **settings)  # sources shown beside
    elapsed = time.perf_counter() - t0
    if result != {"FINISHED"}:
        sys.exit(f"demo: tessellate returned {result}")
    return bpy.context.active_object, elapsed


def build_methods_scene():
    """Original, Phong and PN side by side; returns (source, {method: (object, seconds)})."""
    clear_scene()
    clay, wire_mat = material("Clay", (0.8, 0.55, 0.35, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    source = add_suzanne((-2.6, 0.0, 0.0), clay)
    source.name = "Suzanne"
    results = {}
    for method, x in (("PHONG", 0.0), ("PN", 2.6)):
        ob, elapsed = tessellate(source, method=method, level=LEVEL)
        ob.location.x = x
        results[method] = (ob, elapsed)
    for ob in (source, *(o for o, _ in results.values())):
        wire_overlay(ob, wire_mat)
    add_camera((0.0, -10.5, 0.55), (1.5, 0.0, 0.0), lens=42)
    return source, results


def build_adaptive_scene():
    """Four Suzannes receding from the camera, PN with adaptive levels for it; returns the triangle counts."""
    clear_scene()
    clay, wire_mat = material("Clay", (0.8, 0.55, 0.35, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    add_camera((0.0, -4.2, 0.5), (1.5, 0.0, 0.0), lens=35)
    bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = 1280, 620
    counts = []
    for k in range(4):
        source = add_suzanne((-2.1 + 1.9 * k, 4.0 * k, 0.0), clay)
        ob, _ = tessellate(source, method="PN", level_mode="ADAPTIVE", metrics={"PROJECTED"},
                           max_level=10, edge_pixels=18)
        ob.location = source.location
        bpy.data.objects.remove(source)
        wire_overlay(ob, wire_mat)
        counts.append(len(ob.data.polygons))
    return counts


def abc_streamlines(lines=220, steps=260, dt=0.05, seed=4):
    """Streamlines of the Arnold-Beltrami-Childress flow (RK4) as (lines * steps, 3) points, in a 2π box."""
    a, b, c = 1.0, np.sqrt(2 / 3), np.sqrt(1 / 3)

    def field(p):
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        return np.stack((a * np.sin(z) + c * np.cos(y), b * np.sin(x) + a * np.cos(z), c * np.sin(y) + b * np.cos(x)),
                        axis=1)

    p = np.random.default_rng(seed).uniform(0, 2 * np.pi, (lines, 3))
    out = np.empty((steps, lines, 3))
    for k in range(steps):
        out[k] = p
        k1 = field(p)
        k2 = field(p + 0.5 * dt * k1)
        k3 = field(p + 0.5 * dt * k2)
        k4 = field(p + dt * k3)
        p = p + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    inside = np.all((out >= 0) & (out <= 2 * np.pi), axis=2)
    inside = np.cumprod(inside, axis=0).astype(bool)  # cut each line where it first leaves the box
    return out.transpose(1, 0, 2), inside.T


def build_tubes_scene():
    """Streamlines as a wire mesh, then tubes with camera LOD; returns (faces, sides range, seconds)."""
    clear_scene()
    points, inside = abc_streamlines()
    verts, edges, base = [], [], 0
    for line, keep in zip(points, inside, strict=True):
        line = line[keep]
        if len(line) < 2:
            continue
        verts.append(line)
        edges.append(np.stack((np.arange(len(line) - 1), np.arange(1, len(line))), axis=1) + base)
        base += len(line)
    verts, edges = np.concatenate(verts).astype(np.float32), np.concatenate(edges).astype(np.int32)
    me = bpy.data.meshes.new("ABC streamlines")
    me.vertices.add(len(verts))
    me.edges.add(len(edges))
    me.vertices.foreach_set("co", verts.ravel())
    me.edges.foreach_set("vertices", edges.ravel())
    me.update()
    lines = bpy.data.objects.new("ABC streamlines", me)
    bpy.context.scene.collection.objects.link(lines)
    lines.location = (-np.pi, -np.pi, -np.pi)
    lines.data.materials.append(material("Tube", (0.25, 0.5, 0.85, 1.0)))
    add_camera((0.0, -5.2, 0.9), (1.42, 0.0, 0.0), lens=18)
    bpy.context.view_layer.update()
    for ob in bpy.context.scene.objects:
        ob.select_set(ob is lines)
    bpy.context.view_layer.objects.active = lines
    t0 = time.perf_counter()
    result = bpy.ops.tessera.tubes(radius=0.045, sides_mode="CAMERA", min_sides=3, max_sides=16, edge_pixels=9,
                                   aa_clamp=True, caps="ROUND", camera_source="SCENE", select_angle=np.radians(6))
    elapsed = time.perf_counter() - t0
    if result != {"FINISHED"}:
        sys.exit(f"demo: tubes returned {result}")
    tubes = bpy.context.active_object
    bpy.data.objects.remove(lines)
    wire_overlay(tubes, material("Wire", (0.02, 0.03, 0.08, 1.0)))
    return len(tubes.data.polygons), elapsed


def stroke(points, **brush):
    """Replay one stroke in map texels ((x, y, pressure) rows) with the given brush settings."""
    b = bpy.context.scene.tessera.brush
    for key, value in brush.items():
        setattr(b, key, value)
    import importlib

    element = importlib.import_module("bl_ext.tessera_demo.tessera.addon.compat").stroke_element
    elements = [element((x, y, 0.0), p, first=i == 0) for i, (x, y, p) in enumerate(points)]
    if bpy.ops.tessera.displacement_stroke(stroke=elements, map_space=True) != {"FINISHED"}:
        sys.exit("demo: a displacement stroke failed")
    return 1


def curve(xs, ys, pressure=1.0, n=60):
    """A smooth path through control points (map texels), sampled n times."""
    t = np.linspace(0, 1, len(xs))
    u = np.linspace(0, 1, n)
    return np.column_stack([np.interp(u, t, xs), np.interp(u, t, ys), np.full(n, pressure)])


def build_brushes_scene(size=1024):
    """A flat plane and a painted copy side by side; returns (strokes, seconds)."""
    clear_scene()
    ground = material("Ground", (0.55, 0.5, 0.38, 1.0))
    wire_mat = material("Wire", (0.1, 0.1, 0.1, 1.0))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=48, y_subdivisions=48, size=4, location=(-2.3, 0, 0))
    flat = bpy.context.active_object
    flat.data.materials.append(ground)
    wire_overlay(flat, wire_mat, thickness=0.008)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=320, y_subdivisions=320, size=4, location=(2.3, 0, 0))
    land = bpy.context.active_object
    land.data.materials.append(ground)
    bpy.ops.object.shade_smooth()
    bpy.ops.tessera.displacement_add(width=size, height=size, mode="HEIGHT")
    land.tessera.displacement.strength = 1.0
    t0 = time.perf_counter()
    s = size / 1024
    ridge = curve(np.array([120, 300, 520, 760, 930]) * s, np.array([820, 700, 780, 640, 720]) * s, n=80)
    count = 0
    for _ in range(6):
        count += stroke(ridge, kind="DRAW", radius=150 * s, strength=0.008, falloff="SMOOTH", spacing=0.1)
    peaks = [(260, 300), (700, 420), (480, 560)]
    for x, y in peaks:
        count += stroke([(x * s, y * s, 1.0)] * 2, kind="DRAW", radius=120 * s, strength=0.2, falloff="SPHERE")
    count += stroke(curve(np.array([0, 200, 420, 600, 1023]) * s, np.array([180, 260, 200, 330, 250]) * s, n=80),
                    kind="DRAW", radius=60 * s, strength=-0.012, falloff="SMOOTH", spacing=0.1)
    count += stroke([(860 * s, 220 * s, 1.0)], kind="FLATTEN", radius=110 * s, strength=1.0, falloff="SHARP")
    count += stroke([(512 * s, 512 * s, 1.0)], kind="NOISE", radius=800 * s, strength=0.08, falloff="CONSTANT",
           noise_cell=64 * s, noise_seed=3)
    count += stroke([(512 * s, 512 * s, 1.0)], kind="NOISE", radius=800 * s, strength=0.012, falloff="CONSTANT",
           noise_cell=12 * s, noise_seed=9)
    count += stroke(curve(np.array([0, 200, 420, 600, 1023]) * s, np.array([180, 260, 200, 330, 250]) * s, n=80),
                    kind="SMOOTH", radius=40 * s, strength=1.0, falloff="SMOOTH", spacing=0.1)
    elapsed = time.perf_counter() - t0
    bpy.ops.tessera.displacement_export(filepath=str(OUT / "demo_map.exr"))
    add_camera((0.0, -7.0, 3.6), (np.radians(62), 0.0, 0.0), lens=30)
    return count, elapsed


def build_terrain_scene(size=1025):
    """A synthetic ridged terrain written as a 16-bit PNG, added with ``tessera.terrain_add`` and meshed for the
    scene camera (adaptive, crack-free, frustum-culled); wireframe on top. Returns (triangles, full grid)."""
    import OpenImageIO as oiio

    clear_scene()
    heights = np.asarray(_synth().ridged_terrain(size, seed=7))
    path = str(OUT / "demo_heightmap.png")
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(size, size, 1, "uint16"))
    out.write_image(np.ascontiguousarray(np.round(heights[::-1] * 65535).astype(np.uint16))[..., None])
    out.close()
    add_camera((0.0, -640.0, 260.0), (1.2, 0.0, 0.0), lens=30)
    bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = 1280, 620
    ob = _terrain(bpy.ops.tessera.terrain_add(filepath=path, texel_size=1.0, height_scale=180.0, tile_size=32,
                                              epsilon=2.0), "Rock", (0.55, 0.5, 0.42, 1.0), 0.25)
    return len(ob.data.polygons), 2 * (size - 1) ** 2


def _terrain(result, name, rgba, wire):
    """The terrain ``tessera.terrain_add`` just made (its ``result`` checked), with a material and a wireframe."""
    if result != {"FINISHED"}:
        sys.exit(f"demo: terrain_add returned {result}")
    ob = bpy.context.active_object
    ob.data.materials.append(material(name, rgba))
    wire_overlay(ob, material("Wire", (0.05, 0.05, 0.08, 1.0)), thickness=wire)
    return ob


def build_geotiff_scene(size=513):
    """A DEM as two adjacent GeoTIFF tiles (int16 metres, 30 m samples, -32768 where a lake has no data), picked
    together and added as one terrain with the lake cut out; wireframe on top. Returns (triangles, void samples)."""
    import importlib

    tools = importlib.import_module("bl_ext.tessera_demo.tessera.tools.geotiff_files")
    clear_scene()
    bpy.context.scene.pop("tessera_geo_origin", None)
    heights = np.asarray(_synth().ridged_terrain(size, seed=11)) * 1400.0 + 300.0
    y, x = np.mgrid[0:size, 0:size] / (size - 1)
    lake = np.hypot((x - 0.42) * 1.4, y - 0.55) < 0.13
    top = np.where(lake, -32768, np.round(heights)).astype(np.int16)
    half = size // 2
    names = []
    for name, c0, c1 in (("dem_west.tif", 0, half + 1), ("dem_east.tif", half, size)):  # one shared column
        tools.write_geotiff(str(OUT / name), top[:, c0:c1], spacing=(30.0, 30.0), nodata=-32768,
                            corner=(400000.0 + 30.0 * c0, 5100000.0), tile=(128, 128))
        names.append(name)
    add_camera((0.0, -14500.0, 9000.0), (0.98, 0.0, 0.0), lens=30).data.clip_end = 60000.0  # a 15 km terrain
    ob = _terrain(bpy.ops.tessera.terrain_add(filepath=str(OUT / names[0]), directory=str(OUT),
                                              files=[{"name": n} for n in names], voids="HOLES", tile_size=32,
                                              epsilon=1.5), "Ground", (0.5, 0.55, 0.4, 1.0), 4.0)
    return len(ob.data.polygons), int(lake.sum())


def _synth():
    import importlib

    return importlib.import_module("tessera.tools.ridged_terrain")


def build_gpu_preview_picture(name="demo_gpu_preview.png", size=(1280, 620)):
    """The live preview's renderer, offscreen: adaptive PN Suzannes drawn from instanced patterns (left: lit,
    middle: with the output wireframe, right: a height map sampled in the vertex shader). Returns triangles."""
    import gpu

    package = "bl_ext.tessera_demo.tessera"
    mods = {n: __import__(f"{package}.{n}", fromlist=["x"]) for n in (
        "addon.gpu_context", "addon.bridge", "kernels.tessellation.adaptive", "kernels.common.camera",
        "kernels.tessellation.tessellate", "gpu_shaders.tessellation.draw", "gpu_shaders.offscreen")}
    mods["addon.gpu_context"].ensure_gpu_context()
    clear_scene()
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    for poly in ob.data.polygons:
        poly.use_smooth = True
    arrays, _ = mods["addon.bridge"].read_mesh(ob.data)
    tess, adaptive = mods["kernels.tessellation.tessellate"], mods["kernels.tessellation.adaptive"]
    preview = mods["gpu_shaders.tessellation.draw"]
    cam = mods["kernels.common.camera"].Camera.looking_at((0.0, -6.4, 0.7), (0.0, 0.0, 0.0), fov_deg=40,
                                                          width=size[0], height=size[1], far=100)
    settings = adaptive.AdaptiveSettings(metrics=("PROJECTED",), max_level=10, edge_pixels=16.0)
    v, u = np.mgrid[0:512, 0:512] / 512.0
    bumps = np.zeros((512, 512, 4), np.float32)
    bumps[..., :3] = (0.5 + 0.5 * np.sin(40 * u) * np.sin(40 * v))[..., None]
    bumps[..., 3] = 1.0
    texture = gpu.types.GPUTexture((512, 512), format="RGBA32F", data=gpu.types.Buffer("FLOAT", bumps.size,
                                                                                        bumps.ravel()))
    draws, total = [], 0
    for x, mode in ((-2.9, "LIT"), (0.0, "WIRE"), (2.9, "DISPLACED")):
        model = np.eye(4)
        model[0, 3] = x
        world = arrays.positions.astype(np.float64) + (x, 0.0, 0.0)
        edge, inner = adaptive.adaptive_levels(world, arrays.triangles, settings, cam)
        inputs = tess.surface_inputs(arrays, edge, "PN", tess.SurfaceOptions())
        data = preview.PatchDrawData(inputs, "PN", uvs=arrays.corner_attributes.get("UVMap"))
        data.set_levels(inputs.edge_levels, inner, "FRACTIONAL_EVEN")
        total += data.triangle_count
        draws.append((data, cam.projection @ cam.view @ model, mode))

    def draw():
        for data, vp, mode in draws:
            disp = preview.Displacement(texture, "HEIGHT", 0.5, 0.1) if mode == "DISPLACED" else None
            data.draw(vp, color=(0.8, 0.55, 0.35, 1.0), displacement=disp)
            if mode == "WIRE":
                data.draw(vp, color=(0.05, 0.05, 0.08, 1.0), lit=False, wireframe=True)

    pixels = mods["gpu_shaders.offscreen"].render(draw, size, background=(0.9, 0.9, 0.92, 1.0))
    image = bpy.data.images.new("demo_gpu_preview", size[0], size[1], alpha=True)
    image.pixels.foreach_set((pixels.astype(np.float32) / 255.0).ravel())
    image.filepath_raw = str(OUT / name)
    image.file_format = "PNG"
    image.save()
    bpy.data.objects.remove(ob)
    return total


def build_nailboard_picture(name="demo_nailboard.png", size=(1280, 620)):
    """A glossy Suzanne rendered by Cycles in the nailboard worker (a separate process), drawn by the GPU from its
    board, pre-warped for the eye, with per-texel depth: the GPU-drawn floor cuts through it and a GPU-drawn cube
    stands in front of it. Returns (board texels a side, seconds the worker took)."""
    mods = {n: __import__(f"bl_ext.tessera_demo.tessera.{n}", fromlist=["x"]) for n in (
        "addon.gpu_context", "addon.impostors.worker", "kernels.impostors.prewarp", "kernels.common.camera",
        "gpu_shaders.impostors.draw", "gpu_shaders.offscreen")}
    mods["addon.gpu_context"].ensure_gpu_context()
    clear_scene()
    bpy.ops.mesh.primitive_monkey_add(location=(0.0, 0.0, 0.35))
    monkey = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    mat = bpy.data.materials.new("Gloss")
    _addon_module("addon.compat").use_material_nodes(mat)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.12, 0.05, 1.0)
    bsdf.inputs["Metallic"].default_value = 0.6
    bsdf.inputs["Roughness"].default_value = 0.25
    monkey.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.rotation_euler = (0.7, 0.2, 0.5)
    sun.data.energy = 4.0
    bpy.context.scene.collection.objects.link(sun)
    eye = np.array([1.8, -5.2, 2.3])
    t0 = time.perf_counter()
    images = mods["addon.impostors.worker"].request_board(monkey, eye, res_screen=size[1], fov=0.75,
                                                          samples=32).result(timeout=600)
    seconds = time.perf_counter() - t0
    pw = mods["kernels.impostors.prewarp"]
    frame = images.setup.frame
    splat = pw.fill_holes(pw.forward_splat(images.displacement, frame, eye, images.present), 4)
    colours = images.colours.copy()
    colours[..., :3] = np.clip(colours[..., :3], 0, 1) ** (1 / 2.2)  # linear render -> display
    board = mods["gpu_shaders.impostors.draw"].BoardDrawData(frame, colours, images.displacement, splat)
    camera = mods["kernels.common.camera"]
    cam = camera.Camera(camera.look_at_view(eye, (0.0, 0.0, 0.2)), camera.perspective(0.75, size[0] / size[1],
                                                                                      0.5, 60.0), *size)
    vp = cam.projection @ cam.view
    offscreen = mods["gpu_shaders.offscreen"]
    floor = np.array([[-4, -4, 0.0], [4, -4, 0.0], [4, 4, 0.0], [-4, 4, 0.0]], np.float32)
    floor_tris = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    cube = np.array([[x, y, z] for z in (0, 0.7) for y in (-1.9, -1.2) for x in (0.3, 1.0)], np.float32)
    cube_tris = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                          [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.int32)
    def draw():
        offscreen.draw_triangles(floor, floor_tris, vp, (0.55, 0.6, 0.65, 1.0))
        offscreen.draw_triangles(cube, cube_tris, vp, (0.3, 0.55, 0.8, 1.0))
        board.draw(vp)

    pixels = offscreen.render(draw, size, background=(0.9, 0.9, 0.92, 1.0))
    image = bpy.data.images.new("demo_nailboard", size[0], size[1], alpha=True)
    image.pixels.foreach_set((pixels.astype(np.float32) / 255.0).ravel())
    image.filepath_raw = str(OUT / name)
    image.file_format = "PNG"
    image.save()
    return images.setup.resolution, seconds


def build_loop_scene():
    """Suzanne as Add > Monkey gives it, Loop level 2 of it, and a cube whose top edges are marked sharp at Loop
    level 3 (the crease stays a crisp curve); returns [(name, triangles, seconds)]."""
    clear_scene()
    clay, wire_mat = material("Clay", (0.55, 0.65, 0.8, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    bpy.ops.mesh.primitive_monkey_add(location=(-2.6, 0.0, 0.0))
    coarse = bpy.context.active_object
    coarse.data.materials.append(clay)
    rows = []
    bpy.ops.mesh.primitive_cube_add(size=1.5, location=(2.7, 0.0, 0.0), rotation=(0.0, 0.0, 0.6))
    cube = bpy.context.active_object
    cube.data.materials.append(clay)
    top = [e for e in cube.data.edges if all(cube.data.vertices[i].co.z > 0 for i in e.vertices)]
    sharp = cube.data.attributes.new("sharp_edge", "BOOLEAN", "EDGE")
    for e in top:
        sharp.data[e.index].value = True
    for source, levels in ((coarse, 2), (cube, 3)):
        bpy.context.view_layer.objects.active = source
        t0 = time.perf_counter()
        if bpy.ops.tessera.loop_subdivide(levels=levels, hide_source=False) != {"FINISHED"}:
            sys.exit("demo: loop_subdivide failed")
        out = bpy.context.active_object
        rows.append((source.name, len(out.data.polygons), time.perf_counter() - t0))
        bpy.ops.object.shade_smooth()
        if source is coarse:
            out.location.x = 0.0
        else:
            bpy.data.objects.remove(source)
        wire_overlay(out, wire_mat, thickness=0.004)
    wire_overlay(coarse, wire_mat)
    add_camera((0.0, -10.0, 3.4), (1.26, 0.0, 0.0), lens=42)
    return rows


def build_hce_scene():
    """A Cornell-like box (red and green walls, an area light): Suzanne's lighting baked by Cycles at Loop depth 2
    into its HCE, then the coarse Suzanne (left, 968 triangles) and Loop level 3 carrying the baked colours
    (right). Returns (seconds to bake, triangles at level 3)."""
    clear_scene()

    def node_material(name, rgba):
        mat = material(name, rgba)
        if mat.node_tree is None:  # 4.x (5.0+ materials always have nodes)
            mat.use_nodes = True
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = rgba
        return mat

    white, red = node_material("White", (0.8, 0.8, 0.8, 1)), node_material("Red", (0.8, 0.08, 0.06, 1))
    green = node_material("Green", (0.1, 0.65, 0.12, 1))
    walls = (((0, 0, 0), (0, 0, 0), white), ((0, 0, 4), (3.1416, 0, 0), white), ((0, 2, 2), (1.5708, 0, 0), white),
             ((-2, 0, 2), (0, 1.5708, 0), red), ((2, 0, 2), (0, -1.5708, 0), green))
    for loc, rot, mat in walls:
        bpy.ops.mesh.primitive_plane_add(size=4, location=loc, rotation=rot)
        bpy.context.active_object.data.materials.append(mat)
    bpy.ops.object.light_add(type="AREA", location=(0, 0, 3.95))
    bpy.context.active_object.data.energy, bpy.context.active_object.data.size = 120, 1.2
    bpy.ops.mesh.primitive_monkey_add(location=(-0.85, 0.2, 1.3), rotation=(0.35, 0, 0.25), size=1.3)
    source = bpy.context.active_object
    source.data.materials.append(white)
    t0 = time.perf_counter()
    if bpy.ops.tessera.bake_lighting_hce(depth=2, samples=64) != {"FINISHED"}:
        sys.exit("demo: bake_lighting_hce failed")
    seconds = time.perf_counter() - t0
    if bpy.ops.tessera.loop_subdivide(levels=3, hide_source=False) != {"FINISHED"}:
        sys.exit("demo: loop_subdivide failed")
    out = bpy.context.active_object
    out.location.x += 1.7
    bpy.ops.object.shade_smooth()
    bpy.context.view_layer.objects.active = source
    if bpy.ops.tessera.loop_subdivide(levels=0) != {"FINISHED"}:  # the coarse mesh with its root colours
        sys.exit("demo: loop_subdivide failed")
    bpy.data.objects.remove(source)
    add_camera((0.0, -7.6, 2.0), (1.5708, 0.0, 0.0), lens=30)
    return seconds, len(out.data.polygons)


def build_node_groups_scene():
    """Four objects whose geometry comes from Tessera's node groups alone, each captioned with its modifier stack:
    Suzanne under PN Triangles, a cylinder with sharp rims under Phong with Split sharp edges,
    a trefoil curve under Tubes, a height-map image under Terrain (levels for the camera). Returns each object's
    evaluated face count."""
    clear_scene()
    ng = _addon_module("addon.node_groups")
    clay, wire_mat = material("Clay", (0.8, 0.55, 0.35, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    ink = material("Ink", (0.08, 0.08, 0.1, 1.0))
    add_camera((0.0, -12.0, 0.7), (1.5, 0.0, 0.0), lens=34)  # first: the terrain's levels follow it

    monkey = add_suzanne((-4.6, 0.0, 0.0), clay)
    bpy.ops.mesh.primitive_cylinder_add(vertices=10, radius=0.75, depth=1.3, location=(-1.5, 0.0, 0.0))
    cylinder = bpy.context.active_object
    bpy.ops.object.shade_smooth_by_angle(angle=0.7)  # smooth sides, sharp rims
    trefoil = _trefoil_curve((1.5, 0.0, 0.0))
    terrain = bpy.data.objects.new("Terrain", bpy.data.meshes.new("Terrain"))
    bpy.context.scene.collection.objects.link(terrain)
    terrain.location, terrain.rotation_euler = (4.5, 1.5, -0.5), (0.5, 0.0, 0.0)  # tilted to show its tiles
    heights = np.asarray(_synth().ridged_terrain(129, seed=3), np.float32)
    image = bpy.data.images.new("Ridges", 129, 129, float_buffer=True, is_data=True)
    image.pixels.foreach_set(np.repeat(heights.ravel(), 4).astype(np.float32))
    stacks = [
        (monkey, "Suzanne, smooth", [("Tessera PN Triangles", {"Subdivisions": 2})]),
        (cylinder, "Cylinder, sharp rims", [("Tessera Phong", {"Subdivisions": 3, "Shape Factor": 1.0,
                                                               "Sharp Edges": "Split"})]),
        (trefoil, "Trefoil curve", [("Tessera Tubes", {"Radius": 0.12, "Sides": 12, "Caps": "Round"})]),
        (terrain, "Height-map image", [("Tessera Terrain", {"Image": image, "Texel Size": 0.017,
                                                            "Height Scale": 0.9, "Tile Size": 16,
                                                            "Detail Distance": 9.0, "Material": clay})]),
    ]
    counts = []
    for ob, source, stack in stacks:
        if ob is not monkey:
            ob.data.materials.append(clay)
        for name, inputs in stack:
            mod = ob.modifiers.new(name, "NODES")
            mod.node_group = ng.ensure_group(ng.GROUPS[name])
            ng.set_inputs(mod, inputs)
        if ob.type == "MESH":
            wire = wire_overlay(ob, wire_mat, thickness=0.003)
            for mod in ob.modifiers:  # the wire copy shows the group's triangles too
                copy = wire.modifiers.new(mod.name, "NODES")
                copy.node_group = mod.node_group
                ng.set_inputs(copy, {**dict(stack)[mod.name], "Material": wire_mat})
                wire.modifiers.move(len(wire.modifiers) - 1, 0)
        lines = [source] + [f"+ {name}" + "".join(f"\n    {k}: {_caption(v)}" for k, v in inputs.items()
                                                  if k != "Material")
                            for name, inputs in stack]
        _caption_text(ob.location.x - 1.3, "\n".join(lines), ink)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        counts.append(len(ob.evaluated_get(depsgraph).to_mesh().polygons))
        ob.evaluated_get(depsgraph).to_mesh_clear()
    return counts


def _caption(value):
    return value.name if hasattr(value, "name") else (f"{value:g}" if isinstance(value, float) else str(value))


def _caption_text(x, text, mat):
    """A text object at the foot of a panel (rendered like geometry)."""
    curve = bpy.data.curves.new("Caption", "FONT")
    curve.body, curve.size = text, 0.2
    ob = bpy.data.objects.new("Caption", curve)
    bpy.context.scene.collection.objects.link(ob)
    ob.location, ob.rotation_euler = (x, 0.0, -1.6), (1.5708, 0.0, 0.0)
    ob.data.materials.append(mat)
    return ob


def _trefoil_curve(location, points=90):
    """A closed poly curve along a trefoil knot."""
    t = np.linspace(0.0, 2.0 * np.pi, points, endpoint=False)
    xyz = 0.33 * np.stack([np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t)], 1)
    data = bpy.data.curves.new("Trefoil", "CURVE")
    data.dimensions = "3D"
    spline = data.splines.new("POLY")
    spline.points.add(points - 1)
    spline.points.foreach_set("co", np.c_[xyz, np.ones(points)].ravel())
    spline.use_cyclic_u = True
    ob = bpy.data.objects.new("Trefoil", data)
    bpy.context.scene.collection.objects.link(ob)
    ob.location = location
    return ob


def _addon_module(name):
    import importlib

    return importlib.import_module(f"bl_ext.tessera_demo.tessera.{name}")


def build_surfaces_scene():
    """The one-point parametric surfaces, baked by ``tessera.parametric_surface_add`` (factor 24, the long trefoil
    tube 48) with their wireframes: sphere, cone, torus, Steiner's Roman surface, Klein bottle, Möbius band, trefoil
    tube, superellipsoid. Returns the triangle counts."""
    clear_scene()
    clay, wire_mat = material("Clay", (0.8, 0.55, 0.35, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    counts = []
    kinds = ("SPHERE", "CONE", "TORUS", "STEINER", "KLEIN", "MOBIUS", "TREFOIL", "SUPERELLIPSOID")
    scale = {"KLEIN": 0.42, "STEINER": 2.4, "TORUS": 0.8, "MOBIUS": 1.0, "TREFOIL": 1.5}
    for i, kind in enumerate(kinds):
        x, z = -5.4 + 3.6 * (i % 4), 1.4 - 3.0 * (i // 4)
        bpy.context.scene.cursor.location = (x, 0.0, z)
        factor = 48 if kind == "TREFOIL" else 24
        if bpy.ops.tessera.parametric_surface_add(surface=kind, factor=factor) != {"FINISHED"}:
            sys.exit(f"demo: parametric_surface_add {kind} failed")
        ob = bpy.context.active_object
        ob.scale = (scale.get(kind, 1.0),) * 3
        ob.rotation_euler = (0.5, 0.0, 0.4)
        ob.data.materials.append(clay)
        wire_overlay(ob, wire_mat, thickness=0.01)
        counts.append(len(ob.data.polygons))
    bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)
    add_camera((0.0, -17.0, 0.0), (1.5708, 0.0, 0.0), lens=38)
    return counts


def build_teapot_scene():
    """Newell's full teapot (32 bicubic patches as a surface object) and Blender's own NURBS torus (order 3, rational,
    cyclic both ways) tessellated by ``tessera.surface_tessellate`` to a tolerance of 0.005 (left: detail where they
    bend most), and the teapot by distance for the scene camera (right: the near side finer), wireframe on top.
    Returns the three triangle counts."""
    clear_scene()
    clay, wire_mat = material("Clay", (0.8, 0.55, 0.35, 1.0)), material("Wire", (0.05, 0.05, 0.08, 1.0))
    from tessera.tools.surface_objects import write_surface_patches
    from tessera.tools.utah_teapot import teapot_patches

    nets, _ = teapot_patches()
    surface = write_surface_patches(nets)
    bpy.ops.surface.primitive_nurbs_surface_torus_add(location=(0.0, -3.0, -0.2))
    torus = bpy.context.active_object
    torus.rotation_euler = (0.35, 0.0, 0.0)
    add_camera((0.0, -15.0, 5.5), (1.27, 0.0, 0.0), lens=35)
    counts = []
    cases = ((surface, -3.4, {"metrics": {"TOLERANCE"}, "tolerance": 0.005, "max_level": 64}),
             (torus, None, {"metrics": {"TOLERANCE"}, "tolerance": 0.005, "max_level": 64}),
             (surface, 3.4, {"metrics": {"DISTANCE"}, "near": 13.0, "far": 19.0, "max_level": 24}))
    for source, x, kw in cases:
        if x is not None:
            source.location = (x, 0.0, 0.0)
        bpy.context.view_layer.objects.active = source
        bpy.context.view_layer.update()
        if bpy.ops.tessera.surface_tessellate(**kw) != {"FINISHED"}:
            sys.exit("demo: surface_tessellate failed")
        ob = bpy.context.active_object
        ob.data.materials.append(clay)
        wire_overlay(ob, wire_mat, thickness=0.008)
        counts.append(len(ob.data.polygons))
    bpy.data.objects.remove(surface)
    bpy.data.objects.remove(torus)
    return counts


def build_lic_picture(name="demo_lic.png"):
    """``tessera.vector_field_texture`` for the ABC flow and a vortex (512², GPU where a context can be made), side
    by side in one PNG. Returns (seconds, backend report)."""
    import OpenImageIO as oiio

    halves = []
    t0 = time.perf_counter()
    for field in ("ABC", "VORTEX"):
        before = set(bpy.data.images)
        if bpy.ops.tessera.vector_field_texture(field=field, width=512, height=512, seeds=160, steps=60,
                                                step=0.0015, slice_z=0.6) != {"FINISHED"}:
            sys.exit(f"demo: vector_field_texture {field} failed")
        [image] = set(bpy.data.images) - before
        px = np.empty(512 * 512 * 4, np.float32)
        image.pixels.foreach_get(px)
        halves.append(px.reshape(512, 512, 4)[::-1, :, 0])
    seconds = time.perf_counter() - t0
    both = np.concatenate([halves[0], np.ones((512, 8)), halves[1]], axis=1)
    out = oiio.ImageOutput.create(str(OUT / name))
    out.open(str(OUT / name), oiio.ImageSpec(both.shape[1], 512, 1, "uint8"))
    out.write_image(np.ascontiguousarray(np.round(np.clip(both, 0, 1) * 255).astype(np.uint8))[..., None])
    out.close()
    return seconds


def export(tess):
    for ob in bpy.context.scene.objects:
        ob.select_set(ob is tess)
    bpy.context.view_layer.objects.active = tess
    bpy.ops.export_scene.gltf(filepath=str(OUT / "demo.glb"), export_format="GLB", use_selection=True)
    bpy.ops.wm.obj_export(filepath=str(OUT / "demo.obj"), export_selected_objects=True)


def render(name, color_type="MATERIAL", light="STUDIO"):
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = light
    scene.display.shading.color_type = color_type
    scene.display.shading.show_specular_highlight = False
    scene.render.resolution_x, scene.render.resolution_y = 1280, 620
    scene.render.film_transparent = False
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.color = (0.9, 0.9, 0.92)
    scene.render.filepath = str(OUT / name)
    bpy.ops.render.render(write_still=True)


def caption_figures():
    """The figures the manual's captions of these pictures give, from the scenes built as `main` builds them, without
    rendering (``tests/common/test_blender_demo_figures.py`` holds the captions to them)."""
    source, results = build_methods_scene()
    figures = {"methods_triangles": {method: len(ob.data.polygons) for method, (ob, _) in results.items()},
               "adaptive_triangles": build_adaptive_scene()}
    figures["terrain_triangles"], figures["terrain_full_grid"] = build_terrain_scene()
    rows = build_loop_scene()
    figures["loop_triangles"] = {name: tris for name, tris, _ in rows}
    figures["node_groups_faces"] = build_node_groups_scene()
    return figures


def main():
    OUT.mkdir(exist_ok=True)
    os.environ.setdefault("TESSERA_OPENCL", "1")
    enable_addon()
    source, results = build_methods_scene()
    export(results["PN"][0])
    render("demo.png")
    n_in = len(source.data.polygons)
    for method, (ob, elapsed) in results.items():
        print(f"demo: {method} Suzanne {n_in} faces -> {len(ob.data.polygons)} triangles at level {LEVEL} "
              f"in {elapsed:.2f} s")
    counts = build_adaptive_scene()
    render("demo_adaptive.png")
    print(f"demo: adaptive PN for the camera, near to far: {counts} triangles")
    faces, elapsed = build_tubes_scene()
    render("demo_tubes.png")
    print(f"demo: tubes around ABC-flow streamlines: {faces:,} faces in {elapsed:.2f} s")
    strokes, elapsed = build_brushes_scene()
    render("demo_brushes.png")
    print(f"demo: landscape painted by {strokes} scripted strokes in {elapsed:.2f} s")
    tris, full = build_terrain_scene()
    render("demo_terrain.png")
    print(f"demo: terrain for the camera: {tris:,} triangles ({100 * tris / full:.2f}% of the {full:,}-triangle grid)")
    tris, voids = build_geotiff_scene()
    render("demo_geotiff.png")
    print(f"demo: GeoTIFF terrain from two tiles, {voids:,} no-data samples cut out: {tris:,} triangles")
    for name, tris, elapsed in build_loop_scene():
        print(f"demo: Loop subdivision of {name}: {tris:,} triangles in {elapsed:.2f} s")
    render("demo_loop.png")
    seconds, tris = build_hce_scene()
    render("demo_loop_hce.png", color_type="VERTEX", light="FLAT")
    print(f"demo: lighting baked to HCE in {seconds:.1f} s, carried to Loop level 3 ({tris:,} triangles)")
    counts = build_node_groups_scene()
    render("demo_node_groups.png")
    print(f"demo: node groups as modifiers (PN, Phong Split, Tubes, Terrain): {counts} faces")
    counts = build_surfaces_scene()
    render("demo_surfaces.png")
    print(f"demo: one-point parametric surfaces: {counts} triangles")
    counts = build_teapot_scene()
    render("demo_teapot.png")
    print(f"demo: Tessellate Surface, teapot and NURBS torus to a tolerance, teapot by distance: {counts} triangles")
    seconds = build_lic_picture()
    print(f"demo: vector-field textures (ABC flow, vortex) in {seconds:.1f} s")
    texels, seconds = build_nailboard_picture()
    print(f"demo: a Cycles-rendered Suzanne as a {texels}² nailboard among GPU geometry (worker: {seconds:.1f} s)")
    tris = build_gpu_preview_picture()
    print(f"demo: GPU preview (instanced patterns, adaptive PN, one displaced): {tris:,} triangles drawn")
    for name in ("demo.glb", "demo.obj", "demo.png", "demo_adaptive.png", "demo_tubes.png", "demo_brushes.png",
                 "demo_map.exr", "demo_terrain.png", "demo_geotiff.png", "demo_gpu_preview.png", "demo_loop.png",
                 "demo_loop_hce.png", "demo_node_groups.png", "demo_surfaces.png", "demo_lic.png", "demo_teapot.png",
                 "demo_nailboard.png"):
        path = OUT / name
        if not path.is_file() or path.stat().st_size == 0:
            sys.exit(f"demo: {path} was not written")
        print(f"demo: wrote {path.relative_to(ROOT)} ({path.stat().st_size:,} bytes)")


if __name__ == "__main__":
    main()

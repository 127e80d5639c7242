"""Offscreen rendering of triangle arrays to RGBA images, for checks and pictures.

`render_triangles` draws world-space triangles with a view-projection matrix into a new offscreen
buffer and returns the pixels as numpy; with ``lit=False`` every pixel of the mesh gets exactly
``color``, which makes silhouette and crack comparisons exact.
"""

from dataclasses import dataclass

import numpy as np

from ..kernels.common.tolerances import FLOAT32_TINY
from . import loader

#: The view and shading constants every drawing shader shares, as the uniform buffer ``shading`` (std140, every member
#: a whole vec4 or mat4): the push constants stay within the 128 bytes Vulkan and Metal guarantee. GLSL reads
#: ``shading.view_projection``, ``shading.color``, ``shading.light_dir.xyz``, ``shading.lit_range`` (x, y: the check
#: shade; z: 1 studio lighting, 2 MatCap lighting; w: orthographic view), ``light_dir.w`` (1: the base colour is the
#: vertex colour, in shaders made with ``vertex_color``) and, for studio lighting (`ViewLighting`), ``model_view`` and
#: ``normal_matrix`` (object to view space), ``material`` (roughness, metallic), ``ambient`` (rgb; a: specular on) and
#: the four lights' ``light_direction``, ``light_diffuse`` (rgb; a: wrap) and ``light_specular``.
VIEW_STRUCT = ("struct TesseraView {\n  mat4 view_projection;\n  vec4 color;\n  vec4 light_dir;\n  vec4 lit_range;\n"
               "  mat4 model_view;\n  mat4 normal_matrix;\n  vec4 material;\n  vec4 ambient;\n"
               "  vec4 light_direction[4];\n  vec4 light_diffuse[4];\n  vec4 light_specular[4];\n};\n")
_BLOCK_FLOATS = 16 + 4 * 3 + 16 * 2 + 4 * 2 + 4 * 12


@dataclass(frozen=True)
class ViewLighting:
    """How the viewport lights objects, for a preview drawn instead of one (`addon.viewport_lighting` reads it from
    the 3D view): model_view (4, 4) row-major, object to view space; lights: up to four ``(direction (3,) toward the
    light in view space, diffuse rgb, specular rgb, wrap)``; ambient rgb; roughness (as Solid mode takes it: the
    square root of the material's) and metallic of the object's surface; specular: the highlights are on;
    orthographic: the view is; matcap: a `gpu.types.GPUTexture` of the MatCap to light by instead of the lights (as
    Solid mode's MatCap lighting does: its diffuse and specular passes side by side), or None."""

    model_view: tuple
    lights: tuple
    ambient: tuple = (0.0, 0.0, 0.0)
    roughness: float = 0.6325  # the square root of Blender's default 0.4
    metallic: float = 0.0
    specular: bool = True
    orthographic: bool = False
    matcap: object = None


HEADLIGHT = (0.3, -0.5, 0.81)


def add_view_block(info):
    """Declare the shared `VIEW_STRUCT` uniform buffer ``shading`` (binding 0) on a create-info."""
    info.typedef_source(VIEW_STRUCT)
    info.uniform_buf(0, "TesseraView", "shading")


def view_block(view_projection, color=(1.0, 1.0, 1.0, 1.0), light_dir=HEADLIGHT, lit_range=(1.0, 0.0),
               lighting=None, vertex_colors=False):
    """The ``shading`` uniform buffer for these values; view_projection (4, 4) row-major; lighting: a
    `ViewLighting` (studio lighting as the viewport's, in place of the check shade) or None; vertex_colors: the
    base colour is the vertex colour (shaders made with ``vertex_color``) instead of ``color``."""
    data = np.zeros(_BLOCK_FLOATS, np.float32)
    data[:16] = np.asarray(view_projection, np.float32).T.ravel()  # GLSL's matrices are column-major
    data[16:20] = color
    data[20:23] = light_dir
    data[23] = 1.0 if vertex_colors else 0.0
    data[24:26] = lit_range
    if lighting is not None:
        model_view = np.asarray(lighting.model_view, np.float64)
        normal = np.eye(4)
        det = np.linalg.det(model_view[:3, :3])
        normal[:3, :3] = np.linalg.inv(model_view[:3, :3]).T if abs(det) > 1e-30 else model_view[:3, :3]
        data[26:28] = (2.0 if lighting.matcap is not None else 1.0, 1.0 if lighting.orthographic else 0.0)
        data[28:44] = model_view.astype(np.float32).T.ravel()
        data[44:60] = normal.astype(np.float32).T.ravel()
        data[60:62] = (lighting.roughness, lighting.metallic)
        data[64:67] = lighting.ambient
        data[67] = 1.0 if lighting.specular else 0.0
        for i, (direction, diffuse, specular, wrap) in enumerate(lighting.lights[:4]):
            data[68 + 4 * i:71 + 4 * i] = direction
            data[84 + 4 * i:87 + 4 * i] = diffuse
            data[87 + 4 * i] = wrap
            data[100 + 4 * i:103 + 4 * i] = specular
    return loader.block(data)


def shaded_create_info(name, *vertex_files, vertex_color=False):
    """A create-info with the shading every Tessera check shader shares: ``shade``, ``view_normal`` and
    ``view_position`` varyings (the vertex stage writes all three), the ``shading`` uniform buffer (`add_view_block`)
    and ``flat_mesh_frag.glsl`` with ``solid_light.glsl``. The vertex stage is ``vertex_files`` joined in order.
    vertex_color: a fourth varying ``vertex_color`` (vec4, the vertex stage writes it) is the base colour where the
    block says so (`view_block`'s ``vertex_colors``). Sampler slot 4 is ``matcap`` (`set_shading` binds it). The
    caller adds its vertex inputs, push constants and samplers (slots 0 to 3)."""
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo(f"tessera_{name}_iface")
    iface.smooth("FLOAT", "shade")
    iface.smooth("VEC3", "view_normal")
    iface.smooth("VEC3", "view_position")
    if vertex_color:
        iface.smooth("VEC4", "vertex_color")
    info = gpu.types.GPUShaderCreateInfo()
    add_view_block(info)
    info.sampler(4, "FLOAT_2D", "matcap")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_color")
    info.vertex_source(loader.sources(*vertex_files))
    # a define in the source, not the create-info: the same text on every supported Blender
    prelude = "#define TESSERA_VERTEX_COLOR\n" if vertex_color else ""
    info.fragment_source(prelude + loader.sources("solid_light.glsl", "flat_mesh_frag.glsl"))
    return info


def set_shading(shader, view_projection, color, lit, lighting=None, vertex_colors=False):
    """Bind ``shader`` and its shared ``shading`` block; view_projection: (4, 4) row-major; lighting: a
    `ViewLighting` to light as the viewport does (when ``lit``), or None for the check shade; vertex_colors: the
    vertex colour is the base colour (`view_block`)."""
    shader.bind()
    shader.uniform_block("shading", view_block(view_projection, tuple(color), HEADLIGHT,
                                               (0.25, 0.75) if lit else (1.0, 0.0), lighting if lit else None,
                                               vertex_colors))
    matcap = lighting.matcap if lit and lighting is not None else None
    shader.uniform_sampler("matcap", matcap if matcap is not None else loader.blank_texture())


def _describe_flat_mesh():
    info = shaded_create_info("flat_mesh", "flat_mesh_vert.glsl")
    info.vertex_in(0, "VEC3", "pos")
    info.vertex_in(1, "VEC3", "nor")
    return info


def triangle_batch(positions, triangles, normals=None):
    """The flat-mesh shader and a batch of unshared corners: ``(shader, batch)``.

    positions: (V, 3) float32 world space; triangles: (T, 3) int32; normals: None (flat shading), (V, 3) per
    vertex or (T, 3, 3) per corner. Needs a GPU context.
    """
    from gpu_extras.batch import batch_for_shader

    tris = np.ascontiguousarray(triangles, dtype=np.int32)
    corners = np.ascontiguousarray(positions, dtype=np.float32)[tris]  # (T, 3, 3) unshared
    if normals is None:
        flat = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        flat /= np.maximum(np.linalg.norm(flat, axis=1, keepdims=True), FLOAT32_TINY)
        nor = np.repeat(flat, 3, axis=0).astype(np.float32)
    else:
        normals = np.asarray(normals, np.float32)
        nor = np.ascontiguousarray((normals if normals.ndim == 3 else normals[tris]).reshape(-1, 3))
    shader = loader.shader("flat_mesh", _describe_flat_mesh)
    return shader, batch_for_shader(shader, "TRIS", {"pos": corners.reshape(-1, 3), "nor": nor})


def draw_triangles(positions, triangles, view_projection, color=(0.8, 0.8, 0.8, 1.0), lit=True, normals=None):
    """Draw triangles (as `triangle_batch` takes them) with the flat-mesh shader into the bound framebuffer, depth
    state as the caller set it; view_projection: (4, 4) row-major. Needs a GPU context."""
    shader, batch = triangle_batch(positions, triangles, normals)
    set_shading(shader, view_projection, color, lit)
    batch.draw(shader)


def render_triangles(positions, triangles, view_projection, size=(256, 256), color=(0.8, 0.8, 0.8, 1.0),
                     background=(0.0, 0.0, 0.0, 1.0), lit=True, normals=None):
    """Draw triangles offscreen (as `draw_triangles` does) and return the image: (height, width, 4) uint8, row 0
    at the bottom. Needs a GPU context."""
    shader, batch = triangle_batch(positions, triangles, normals)

    def draw():
        set_shading(shader, view_projection, color, lit)
        batch.draw(shader)

    return render(draw, size, background)


def render(draw, size=(256, 256), background=(0.0, 0.0, 0.0, 1.0)):
    """Call ``draw()`` into a new offscreen buffer with depth test; return (height, width, 4) uint8, row 0 at
    the bottom. Needs a GPU context."""
    import gpu

    width, height = size
    offscreen = gpu.types.GPUOffScreen(width, height)
    try:
        with offscreen.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=background, depth=1.0)
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            draw()
            buf = fb.read_color(0, 0, width, height, 4, 0, "UBYTE")
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)
    finally:
        offscreen.free()
    buf.dimensions = width * height * 4  # multi-dimensional Buffers export wrong strides
    return np.asarray(memoryview(buf), dtype=np.uint8).reshape(height, width, 4).copy()

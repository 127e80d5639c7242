"""How the 3D viewport lights and colours an object in Solid mode, for a preview drawn instead of it: the user's
studio light (its four lights and ambient, in view space or turned with the world) or MatCap, the specular toggle,
and the object's colour as the viewport's Color setting takes it (material, object, single colour). The GPU side is
`gpu_shaders.offscreen.ViewLighting` and ``solid_light.glsl``."""

import math

import bpy
import numpy as np

from ..gpu_shaders import loader
from ..gpu_shaders.offscreen import ViewLighting
from .viewport import outline, preview_style

#: Blender's default surface when an object has no material (grey 0.8, roughness 0.4, not metallic).
DEFAULT_SURFACE = ((0.8, 0.8, 0.8, 1.0), 0.4, 0.0)


def _studio_light(context, name):
    for light in context.preferences.studio_lights:
        if light.type == "STUDIO" and light.name == name:
            return light
    return next((light for light in context.preferences.studio_lights if light.type == "STUDIO"), None)


def surface(shading, ob):
    """``(rgba, roughness, metallic)`` of ``ob`` as Solid mode colours it."""
    color, roughness, metallic = DEFAULT_SURFACE
    material = ob.active_material if ob.material_slots else None
    if material is not None:
        color, roughness, metallic = tuple(material.diffuse_color), material.roughness, material.metallic
    if shading.color_type == "OBJECT":
        color = tuple(ob.color)
    elif shading.color_type == "SINGLE":
        color = (*shading.single_color, 1.0)
    return color, roughness, metallic


_matcaps = {}  # MatCap name -> (its (H, 2W, 4) float32 pixels (diffuse | specular), it has a specular pass), or
#                (None, False) when unreadable


def matcap_pixels(name):
    """The MatCap ``name`` as Solid mode lights with it: ``(pixels, specular)``, its diffuse and specular passes side
    by side, (H, 2W, 4) float32, row 0 at the bottom (read once from Blender's multilayer EXR; a few milliseconds),
    and whether Blender counts its specular pass. Pixels None when it cannot be read (told once; previews then
    light with the studio lights)."""
    if name not in _matcaps:
        from ..kernels.common.errors import TesseraError
        from ..kernels.common.image_io import read_channels

        light = next((sl for sl in bpy.context.preferences.studio_lights
                      if sl.type == "MATCAP" and sl.name == name), None)
        _matcaps[name] = (None, False)
        if light is not None:
            try:
                passes = read_channels(light.path, "MatCap", [f"{p}.{c}" for p in ("diffuse", "specular")
                                                              for c in "RGB"])
            except TesseraError as err:
                print(f"Tessera: the MatCap {name!r} could not be read ({err}); previews light with the studio "
                      "lights")
            else:
                h, w = passes[0].shape
                pixels = np.ones((h, 2 * w, 4), np.float32)
                pixels[:, :w, :3] = np.stack(passes[:3], axis=-1)
                pixels[:, w:, :3] = np.stack(passes[3:], axis=-1)
                _matcaps[name] = (pixels, bool(light.has_specular_highlight_pass))
    return _matcaps[name]


def matcap_texture(name):
    """The GPU texture of `matcap_pixels` ``name`` (uploaded once per GPU context), or None."""
    pixels = matcap_pixels(name)[0]
    if pixels is None:
        return None

    def upload():
        import gpu

        h, w = pixels.shape[:2]
        return gpu.types.GPUTexture((w, h), format="RGBA16F", data=gpu.types.Buffer("FLOAT", pixels.size,
                                                                                   pixels.ravel()))

    return loader.batch(("matcap", name), upload)


def view_lighting(context, ob, view):
    """``(rgba, ViewLighting or None)`` for drawing ``ob`` in the current 3D view; view: (4, 4) world to view.
    None for Flat lighting (the colour as it is)."""
    shading = context.space_data.shading
    color, roughness, metallic = surface(shading, ob)
    if shading.light == "FLAT":
        return color, None
    model_view = np.asarray(view, np.float64) @ np.array(ob.matrix_world)
    rv3d = context.region_data
    if shading.light == "MATCAP":
        matcap = matcap_texture(shading.studio_light)
        if matcap is not None:
            specular = shading.show_specular_highlight and matcap_pixels(shading.studio_light)[1]
            return color, ViewLighting(model_view=tuple(map(tuple, model_view)), lights=(), matcap=matcap,
                                       specular=specular, orthographic=not rv3d.is_perspective)
    light = _studio_light(context, shading.studio_light)
    lights = []
    if light is not None:
        turn = np.eye(3)
        if shading.use_world_space_lighting:
            a = shading.studiolight_rotate_z
            turn = np.asarray(view, np.float64)[:3, :3] @ np.array(
                [[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        for solid in light.solid_lights:
            if solid.use:
                direction = turn @ np.asarray(solid.direction, np.float64)
                direction /= max(np.linalg.norm(direction), 1e-12)
                lights.append((tuple(direction), tuple(solid.diffuse_color), tuple(solid.specular_color),
                               float(solid.smooth)))
    ambient = tuple(light.light_ambient) if light is not None else (0.0, 0.0, 0.0)
    # Solid mode remaps the material's roughness to its square root before it lights with it
    return color, ViewLighting(model_view=tuple(map(tuple, model_view)), lights=tuple(lights), ambient=ambient,
                               roughness=math.sqrt(max(float(roughness), 0.0)), metallic=float(metallic),
                               specular=bool(shading.show_specular_highlight),
                               orthographic=not rv3d.is_perspective)


def draw_as_object(context, ob, view, draw, *args, wire=False, **kwargs):
    """Draw ``ob``'s preview as the viewport draws the object (`viewport.preview_style`): its surface by
    ``draw(*args, color=, lit=, lighting=, **kwargs)`` unless the shading is Wireframe (``lighting`` a
    `ViewLighting`, or None and unlit for Flat lighting), then, where the viewport draws the object's wire and the
    preview has one (``wire``), the wire by ``draw(*args, color=, lit=False, wireframe=True, **kwargs)``.

    In X-ray the surface is see-through as Blender's objects are: its nearest layer only (a depth pass first, then
    the colour blended where the depth is equal), so overlapping layers never blotch; its wire shows through. A
    selected object gets Blender's outline (`viewport.outline`)."""
    import gpu

    style = preview_style(context, ob)
    if context.space_data.shading.type != "WIREFRAME":
        color, lighting = view_lighting(context, ob, view)
        color = style.surface_color(color)
        if style.xray:
            gpu.state.color_mask_set(False, False, False, False)
            draw(*args, color=color, lit=False, **kwargs)
            gpu.state.color_mask_set(True, True, True, True)
            gpu.state.blend_set("ALPHA")
            gpu.state.depth_mask_set(False)
        try:
            draw(*args, color=color, lit=lighting is not None, lighting=lighting, **kwargs)
        finally:
            gpu.state.blend_set("NONE")
            gpu.state.depth_mask_set(True)
        outline(context, ob, lambda mask_color: draw(*args, color=mask_color, lit=False, **kwargs))
    if style.wire_color is not None and wire:
        if style.xray:
            gpu.state.depth_test_set("ALWAYS")
        try:
            draw(*args, color=style.wire_color, lit=False, wireframe=True, **kwargs)
        finally:
            gpu.state.depth_test_set("LESS_EQUAL")

"""How the 3D viewport lights and colours an object in Solid mode, for a preview drawn instead of it: the user's
studio light (its four lights and ambient, in view space or turned with the world), the specular toggle, and the
object's colour as the viewport's Color setting takes it (material, object, single colour). The GPU side is
`gpu_shaders.offscreen.ViewLighting` and ``solid_light.glsl``."""

import math

import numpy as np

from ..gpu_shaders.offscreen import ViewLighting

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


def view_lighting(context, ob, view):
    """``(rgba, ViewLighting or None)`` for drawing ``ob`` in the current 3D view; view: (4, 4) world to view.
    None for Flat lighting (the colour as it is)."""
    shading = context.space_data.shading
    color, roughness, metallic = surface(shading, ob)
    if shading.light == "FLAT":
        return color, None
    model_view = np.asarray(view, np.float64) @ np.array(ob.matrix_world)
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
    rv3d = context.region_data
    # Solid mode remaps the material's roughness to its square root before it lights with it
    return color, ViewLighting(model_view=tuple(map(tuple, model_view)), lights=tuple(lights), ambient=ambient,
                               roughness=math.sqrt(max(float(roughness), 0.0)), metallic=float(metallic),
                               specular=bool(shading.show_specular_highlight),
                               orthographic=not rv3d.is_perspective)


def draw_as_object(context, ob, view, surface, wire=None):
    """Draw ``ob``'s preview as the viewport draws the object (`viewport.preview_state`): ``surface(rgba,
    lighting)`` unless the shading is Wireframe (``lighting`` a `ViewLighting`, or None for Flat lighting), then
    ``wire(rgba)`` where the viewport draws the object's wire (a preview without ``wire`` draws none)."""
    from .viewport import preview_state

    with preview_state(context, ob) as style:
        if context.space_data.shading.type != "WIREFRAME":
            color, lighting = view_lighting(context, ob, view)
            surface(style.surface_color(color), lighting)
        if style.wire_color is not None and wire is not None:
            wire(style.wire_color)

"""Displacement maps at run time: the map of each image as a float32 array (and on the OpenCL device), the
image pixels and the Displace modifier that show it, stroke sessions with tile undo, and the file handlers.

The array is the truth while painting; the image is written after strokes (all RGBA pixels, one
``foreach_set``). Height maps store the height in R, G and B with alpha 1 (the Displace modifier reads the mean
of RGB, divided by alpha). Maps are keyed by the image's ``session_uid``, which survives undo steps.

Undo: each stroke increments ``Image.tessera.serial`` and keeps a `TileUndo` under that serial. After Blender
undoes or redoes (global undo restores the serial), `_on_undo_redo` rolls the map back or forward tile by tile
to the serial Blender now shows. Save: maps are written to their images and packed as float EXR (exact).
Load: all map state is dropped; nothing is compiled or run.
"""

import bpy
import numpy as np

from ...kernels.common.errors import InvalidInputError, TesseraError
from ...kernels.common.opencl_runtime import get_runtime
from ...kernels.displacement.map_buffer import MapBuffer
from ...kernels.displacement.map_strokes import TileUndo, run_stroke, stroke_dabs, union_region
from .. import bridge
from ..compat import has_uv_tangent_node
from ..node_groups import set_inputs
from . import nodes as displace_nodes

MODIFIER_NAME = "Tessera Displacement"
NOTHING = (0, 0, 0, 0)  # an empty region
_states = {}


class MapState:
    """A map being edited: ``host`` (H, W, C) float32 with row 0 = the image's bottom row."""

    def __init__(self, image, channels):
        w, h = image.size
        if w == 0 or h == 0:
            raise TesseraError(f"Image {image.name!r} has no pixels (is its file missing?)")
        rgba = bridge.read_image_pixels(image, 4)
        if not np.isfinite(rgba).all():
            raise InvalidInputError(f"Image {image.name!r} has NaN or infinite pixels")
        self.host = np.ascontiguousarray(rgba[..., :1] if channels == 1 else rgba[..., :channels])
        self.rgba = rgba
        self.serial = image.tessera.serial
        self.steps = {}  # serial -> TileUndo of the stroke that produced it
        runtime = get_runtime()
        self.device = MapBuffer(runtime, self.host) if runtime is not None else None
        self.backend = "auto" if self.device is not None else "numpy"  # with a device: per stroke, by measured time

    def to_image(self, image, region=None):
        """Write the map into the image pixels and tag its users. ``region`` (x0, y0, x1, y1): only that part of the
        map changed since the last write, so only that part of the RGBA mirror is refreshed (the mirror is most of a
        write's cost; Blender takes the whole image either way)."""
        x0, y0, x1, y1 = region or (0, 0, self.host.shape[1], self.host.shape[0])
        tile = self.host[y0:y1, x0:x1]
        if tile.shape[2] == 1:
            self.rgba[y0:y1, x0:x1, :3] = tile
            self.rgba[y0:y1, x0:x1, 3] = 1.0
        else:
            self.rgba[y0:y1, x0:x1, :tile.shape[2]] = tile
            if tile.shape[2] == 3:
                self.rgba[y0:y1, x0:x1, 3] = 1.0
        bridge.write_image_pixels(image, self.rgba)
        for ob in bpy.data.objects:
            if ob.type == "MESH" and ob.tessera.displacement.image == image:
                ob.update_tag()

    def rewind(self, image, serial):
        """Undo or redo strokes until the map is at ``serial``; returns True when anything changed."""
        changed = False
        while self.serial > serial and self.serial in self.steps:
            self.steps[self.serial].undo(self.host)
            self.serial -= 1
            changed = True
        while self.serial < serial and self.serial + 1 in self.steps:
            self.serial += 1
            self.steps[self.serial].redo(self.host)
            changed = True
        if changed:
            if self.device is not None:
                self.device.push()
            self.to_image(image)
        return changed


def channels_for(settings):
    return 1 if settings.mode == "HEIGHT" else 3


def map_state(image, channels):
    """The `MapState` of ``image`` (created from its pixels on first use)."""
    state = _states.get(image.session_uid)
    if state is None or state.host.shape[2] != channels or state.host.shape[:2] != tuple(image.size)[::-1]:
        state = _states[image.session_uid] = MapState(image, channels)
    return state


def forget(image=None):
    """Drop the state of one image (after its pixels were replaced) or of all."""
    if image is None:
        _states.clear()
    else:
        _states.pop(image.session_uid, None)


class StrokeSession:
    """One stroke on one map: dabs are applied as samples arrive, in the same order a replay uses."""

    def __init__(self, image, settings, brush):
        self.image = image
        self.state = map_state(image, channels_for(settings))
        self.brush = brush
        self.samples = []
        self.undo = TileUndo(self.state.host)
        self.done = 0
        self.region = None

    def add(self, x, y, pressure):
        """Add a sample (map texels) and apply the dabs it completes; returns the changed region or None."""
        self.samples.append((x, y, pressure))
        dabs = stroke_dabs(self.samples, self.brush.spacing * self.brush.radius)
        new = dabs[self.done:]
        self.done = len(dabs)
        if not len(new):
            return None
        region = run_stroke(self.state.host, self.brush, new, backend=self.state.backend, device=self.state.device,
                            undo=self.undo, spaced=False)
        self.region = union_region(self.region, region)
        return region

    def cancel(self):
        """Put back every tile this stroke changed."""
        self.undo.undo(self.state.host)
        if self.state.device is not None:
            self.state.device.push()

    def write_image(self):
        """Write what the stroke changed so far into the image (the live view while painting)."""
        self.state.to_image(self.image, self.undo.region() or NOTHING)

    def finish(self):
        """Close the undo step under a new serial and write the image."""
        commit(self.state, self.image, self.undo)
        return self.region


def commit(state, image, undo):
    """Record a finished edit: ``undo`` (a `TileUndo`) becomes the step of a new serial; the image is written."""
    undo.close(state.host)
    for serial in [s for s in state.steps if s > state.serial]:  # a new edit drops the redo branch
        del state.steps[serial]
    state.serial += 1
    state.steps[state.serial] = undo
    image.tessera.serial = state.serial
    state.to_image(image, undo.region() or NOTHING)  # the edit's tiles: the rest of the mirror is current


def modifier_kind(settings):
    """NODES (the tangent-space group) for tangent-space vector maps, else DISPLACE."""
    return "NODES" if settings.mode == "VECTOR" and settings.space == "TANGENT" else "DISPLACE"


def sync_modifier(ob):
    """Create or update the modifier that shows the object's map: a Displace modifier (and its image
    texture), or for tangent-space vector maps the `displace_nodes` group. Returns it, or None when hidden (no
    map, or tangent space on a Blender without the UV Tangent node)."""
    settings = ob.tessera.displacement
    mod = ob.modifiers.get(MODIFIER_NAME)
    kind = modifier_kind(settings)
    if settings.image is None or (kind == "NODES" and not has_uv_tangent_node()):
        if mod is not None:
            mod.show_viewport = mod.show_render = False
        return None
    if mod is not None and mod.type != kind:  # replaced in place, keeping its position in the stack
        position = ob.modifiers.find(MODIFIER_NAME)
        ob.modifiers.remove(mod)
        mod = ob.modifiers.new(MODIFIER_NAME, kind)
        ob.modifiers.move(len(ob.modifiers) - 1, position)
    elif mod is None:
        mod = ob.modifiers.new(MODIFIER_NAME, kind)
    mod.show_viewport = mod.show_render = True
    if kind == "NODES":
        mod.node_group = displace_nodes.node_group()
        uv_map = settings.uv_map or getattr(ob.data.uv_layers.active, "name", "")
        set_inputs(mod, {"Map": "Tangent", "Image": settings.image, "UV Map": uv_map,
                                        "Mid-Level": settings.mid_level, "Strength": settings.strength})
        ob.update_tag()
        return mod
    if mod.texture is None:
        mod.texture = bpy.data.textures.new(f"{settings.image.name} Texture", "IMAGE")
    tex = mod.texture
    tex.image = settings.image
    tex.extension = "EXTEND"
    mod.texture_coords = "UV"
    mod.uv_layer = settings.uv_map
    mod.mid_level = settings.mid_level
    mod.strength = settings.strength
    if settings.mode == "HEIGHT":
        mod.direction = "NORMAL"
    else:
        mod.direction = "RGB_TO_XYZ"
        mod.space = settings.space
    return mod


def _maps_in_use():
    """(image, state) of every map being edited and bound to an object, each image once."""
    images = {ob.tessera.displacement.image for ob in bpy.data.objects
              if ob.type == "MESH" and ob.tessera.displacement.image is not None}
    return [(image, _states[image.session_uid]) for image in images if image.session_uid in _states]


@bpy.app.handlers.persistent
def _on_undo_redo(*_args):
    for image, state in _maps_in_use():
        state.rewind(image, image.tessera.serial)


@bpy.app.handlers.persistent
def _on_save_pre(*_args):
    for image, state in _maps_in_use():
        state.to_image(image)
        image.file_format = "OPEN_EXR"
        image.pack()


@bpy.app.handlers.persistent
def _on_load_pre(*_args):
    forget()


_HANDLERS = (("undo_post", _on_undo_redo), ("redo_post", _on_undo_redo), ("save_pre", _on_save_pre),
             ("load_pre", _on_load_pre))


def register():
    for name, fn in _HANDLERS:
        getattr(bpy.app.handlers, name).append(fn)


def unregister():
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn in handlers:
            handlers.remove(fn)
    forget()

"""Displacement-map operators: add a map to a mesh, export it, and paint it with strokes.

``tessera.displacement_stroke`` is both the interactive brush (invoke: raycast the mouse onto the displaced
surface, dabs along the stroke, a brush circle while painting) and the headless replay (execute: the recorded
``stroke`` elements, with ``location`` a point on the surface in object space, or map texels when
``map_space`` is set). Both go through one `StrokeSession`, so a replay reproduces the stroke.
"""

import time

import bpy
import mathutils
import numpy as np

from ..addon import bridge
from ..addon.compat import UV_TANGENT_MESSAGE, has_uv_tangent_node
from ..addon.displacement.brush_cursor import draw_ring, mouse_hit, stroke_ended, stroke_started, texel
from ..addon.displacement.maps import StrokeSession, channels_for, map_state, sync_modifier
from ..addon.displacement.settings import MODE_ITEMS, SPACE_ITEMS, map_value_property
from ..addon.guarded import check_numbers, each_selected, guarded
from ..addon.preferences import get_preferences
from ..kernels.common.errors import InvalidInputError, TesseraError
from ..kernels.common.image_io import image_size
from ..kernels.displacement.map_edit import check_map_budget
from ..kernels.displacement.map_io import read_map, write_map
from ..kernels.displacement.map_strokes import Brush

_LIVE_INTERVAL = 0.05  # seconds between image updates while painting, at least
#: ... and at least this many times the last update's own time: writing a large map's pixels (tens of milliseconds
#: for a 4096² map; Blender has no partial write) then takes at most a quarter of a stroke
_LIVE_WAIT_PER_WRITE = 3.0


def live_write_due(now, last_write_end, last_write_seconds):
    """Whether a painting stroke writes its map into the image now (`_LIVE_INTERVAL`, `_LIVE_WAIT_PER_WRITE`)."""
    return now - last_write_end > max(_LIVE_INTERVAL, _LIVE_WAIT_PER_WRITE * last_write_seconds)


def _map_object(context):
    ob = context.active_object
    if ob is None or ob.type != "MESH" or ob.tessera.displacement.image is None:
        return None
    return ob


def kernel_brush(b, channels):
    """`kernels.displacement.map_strokes.Brush` from ``Scene.tessera.brush``."""
    check_numbers(b)
    vector = (*b.direction, 0.0) if channels > 1 else (0.0, 0.0, 1.0, 0.0)
    params = {"falloff": b.falloff, "vector": vector, "cell": b.noise_cell, "seed": b.noise_seed}
    if b.kind == "TEST":
        params["arg2"] = tuple(v * b.strength for v in vector)
    return Brush(kind=b.kind, radius=b.radius, strength=b.strength, spacing=b.spacing,
                 pressure_radius=b.use_pressure_radius, pressure_strength=b.use_pressure_strength,
                 mirror_x=b.mirror_x, params=params).validate()


def new_map_image(name, width, height, data=None):
    """A float, non-colour image of ``width`` x ``height`` (zero height, alpha 1), optionally filled."""
    image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    rgba = np.zeros((height, width, 4), np.float32)
    rgba[..., 3] = 1.0
    if data is not None:
        rgba[..., :3] = data if data.shape[2] != 1 else np.repeat(data, 3, axis=2)
    bridge.write_image_pixels(image, rgba)
    return image


class TESSERA_OT_displacement_add(bpy.types.Operator):
    """Give the active mesh a displacement map to paint, new or read from a file, shown by a Displace modifier"""

    bl_idname = "tessera.displacement_add"
    bl_label = "Add Displacement Map"
    bl_options = {"REGISTER", "UNDO"}

    width: bpy.props.IntProperty(name="Width", default=1024, min=8, max=32768, soft_max=8192, subtype="PIXEL",
                                 description="Width of a new map")
    height: bpy.props.IntProperty(name="Height", default=1024, min=8, max=32768, soft_max=8192, subtype="PIXEL",
                                  description="Height of a new map")
    mode: bpy.props.EnumProperty(name="Mode", items=MODE_ITEMS, default="HEIGHT",
                                 description="One height per texel, or an XYZ offset per texel")
    space: bpy.props.EnumProperty(name="Space", items=SPACE_ITEMS, default="LOCAL",
                                  description="The axes a vector map's X, Y and Z follow")
    filepath: bpy.props.StringProperty(name="From File", subtype="FILE_PATH",
                                       description="Read the map from this file instead (EXR, PNG, TIFF)")
    low: map_value_property("16-bit Low", 0.0, "Map value of a black texel in 8- or 16-bit files")
    high: map_value_property("16-bit High", 1.0, "Map value of a white texel in 8- or 16-bit files")

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if ob is None or ob.type != "MESH":
            cls.poll_message_set("Select a mesh")
            return False
        if not ob.data.uv_layers:
            cls.poll_message_set("The mesh needs a UV map to place the displacement map")
            return False
        return True

    @guarded
    @each_selected(lambda ob: ob.type == "MESH" and bool(ob.data.uv_layers))
    def execute(self, context, tx):
        ob = context.active_object
        channels = 1 if self.mode == "HEIGHT" else 3
        if self.mode == "VECTOR" and self.space == "TANGENT" and not has_uv_tangent_node():
            raise InvalidInputError(UV_TANGENT_MESSAGE)
        budget = get_preferences(context).memory_budget_bytes
        data = None
        if self.filepath:
            path = bpy.path.abspath(self.filepath)
            w, h, _ = image_size(path, "map")  # the header: checked before anything is read
            check_map_budget(w, h, channels, budget)
            data = read_map(path, channels=channels, low=self.low, high=self.high)
            h, w = data.shape[:2]
        else:
            w, h = self.width, self.height
            check_map_budget(w, h, channels, budget)
        image = tx.track(new_map_image(f"{ob.name} Displacement", w, h, data))
        settings = ob.tessera.displacement
        previous = {name: getattr(settings, name) for name in ("mode", "space", "uv_map", "image")}

        def restore():
            for name, value in previous.items():
                setattr(settings, name, value)
            sync_modifier(ob)

        tx.on_rollback(restore)
        settings.mode, settings.space = self.mode, self.space
        settings.uv_map = ob.data.uv_layers.active.name
        settings.image = image  # creates the modifier through the update callback
        sync_modifier(ob)
        self.report({"INFO"}, f"Displacement map {w} x {h} ({self.mode.lower()}) on {ob.name}")
        return {"FINISHED"}


class TESSERA_OT_displacement_export(bpy.types.Operator):
    """Write the active object's displacement map to a 32-bit EXR (exact) or a 16-bit PNG or TIFF file"""

    bl_idname = "tessera.displacement_export"
    bl_label = "Export Displacement Map"

    filepath: bpy.props.StringProperty(name="File", subtype="FILE_PATH",
                                       description="The file to write: .exr, .png or .tif")
    low: map_value_property("16-bit Low", 0.0, "Map value written as black in a 16-bit file (lower values are "
                            "clipped)")
    high: map_value_property("16-bit High", 1.0, "Map value written as white in a 16-bit file (higher values are "
                             "clipped)")

    @classmethod
    def poll(cls, context):
        return _map_object(context) is not None

    def invoke(self, context, event):
        if not self.filepath:
            self.filepath = "displacement.exr"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    @guarded
    def execute(self, context, tx):
        settings = context.active_object.tessera.displacement
        state = map_state(settings.image, channels_for(settings))
        clipped = write_map(bpy.path.abspath(self.filepath), state.host, low=self.low, high=self.high)
        if clipped:
            self.report({"WARNING"}, f"{clipped} values lay outside [{self.low:g}, {self.high:g}] and were clipped")
        return {"FINISHED"}


def _new_session(context):
    """A stroke on the active object's map with the scene's brush."""
    settings = context.active_object.tessera.displacement
    return StrokeSession(settings.image, settings, kernel_brush(context.scene.tessera.brush, channels_for(settings)))


class TESSERA_OT_displacement_stroke(bpy.types.Operator):
    """Paint the displacement map of the active object (drag), or replay a recorded stroke"""

    bl_idname = "tessera.displacement_stroke"
    bl_label = "Displacement Stroke"
    bl_options = {"REGISTER", "UNDO", "BLOCKING"}

    stroke: bpy.props.CollectionProperty(type=bpy.types.OperatorStrokeElement, options={"SKIP_SAVE"},
                                         description="The stroke's points (recorded while painting, or given by a "
                                                     "script)")
    map_space: bpy.props.BoolProperty(name="Map Space", default=False, options={"SKIP_SAVE"},
                                      description="Stroke locations are map texels (x, y) instead of surface points")

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Paint displacement maps in Object Mode")
            return False
        if _map_object(context) is None:
            cls.poll_message_set("The active mesh has no displacement map (Add Displacement Map)")
            return False
        return True

    # -- replay -------------------------------------------------------------------------------------------
    @guarded
    def execute(self, context, tx):
        ob = context.active_object
        session = _new_session(context)
        samples = self._replay_samples(context, ob, session.state.host.shape)
        wm = context.window_manager
        wm.progress_begin(0, len(samples))
        try:
            for i, sample in enumerate(samples):
                session.add(*sample)
                wm.progress_update(i)
        except Exception:
            session.cancel()  # every tile the stroke changed goes back (host and device)
            raise
        finally:
            wm.progress_end()
        session.finish()
        return {"FINISHED"}

    def _replay_samples(self, context, ob, shape):
        if self.map_space:
            return [(e.location.x, e.location.y, e.pressure) for e in self.stroke]
        settings = ob.tessera.displacement
        depsgraph = context.evaluated_depsgraph_get()
        ob_eval = ob.evaluated_get(depsgraph)
        tree = mathutils.bvhtree.BVHTree.FromObject(ob_eval, depsgraph)
        mesh = ob_eval.data
        out = []
        for e in self.stroke:
            co, _normal, index, _dist = tree.find_nearest(e.location)
            if index is None:
                raise TesseraError("A stroke location found no surface")
            out.append((*texel(mesh, index, co, settings.uv_map, (shape[1], shape[0])), e.pressure))
        return out

    # -- interactive --------------------------------------------------------------------------------------
    def invoke(self, context, event):
        if context.area is None or context.area.type != "VIEW_3D":
            self.report({"ERROR"}, "Paint in a 3D Viewport")
            return {"CANCELLED"}
        try:
            self._session = _new_session(context)
        except TesseraError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self._last_write, self._write_seconds = 0.0, 0.0
        self._cursor = None
        self._draw = bpy.types.SpaceView3D.draw_handler_add(self._draw_cursor, (), "WINDOW", "POST_VIEW")
        stroke_started()
        self.stroke.clear()
        self._sample(context, event, first=True)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type in {"MOUSEMOVE", "INBETWEEN_MOUSEMOVE"}:
            self._sample(context, event)
            return {"RUNNING_MODAL"}
        if event.type == "LEFTMOUSE" and event.value == "RELEASE":
            self._end(context)
            self._session.finish()
            return {"FINISHED"}
        if event.type in {"ESC", "RIGHTMOUSE"}:
            self._end(context)
            self._session.cancel()
            self._session.state.to_image(self._session.image)
            return {"CANCELLED"}
        return {"RUNNING_MODAL"}

    def _end(self, context):
        bpy.types.SpaceView3D.draw_handler_remove(self._draw, "WINDOW")
        stroke_ended()
        context.area.tag_redraw()

    def _sample(self, context, event, first=False):
        ob = context.active_object
        mouse = (event.mouse_region_x, event.mouse_region_y)
        hit = mouse_hit(context, ob, mouse)
        if hit is None:
            self._cursor = None
            context.area.tag_redraw()
            return
        co, index = hit.co, hit.index
        settings = ob.tessera.displacement
        shape = self._session.state.host.shape
        size = (shape[1], shape[0])
        x, y = texel(hit.evaluated.data, index, co, settings.uv_map, size)
        pressure = event.pressure if event.pressure > 0 else 1.0
        try:
            self._session.add(x, y, pressure)
        except TesseraError as err:
            self.report({"WARNING"}, str(err))
            return
        element = self.stroke.add()
        element.location, element.mouse, element.pressure = co, mouse, pressure
        element.is_start, element.time = first, time.monotonic()
        self._cursor = hit.ring(self._session.brush.radius, size, settings.uv_map)
        if live_write_due(time.monotonic(), self._last_write, self._write_seconds):
            start = time.monotonic()
            self._session.write_image()
            self._last_write = time.monotonic()
            self._write_seconds = self._last_write - start
        context.area.tag_redraw()

    def _draw_cursor(self):
        if self._cursor is not None:
            draw_ring(self._cursor)


classes = (TESSERA_OT_displacement_add, TESSERA_OT_displacement_export, TESSERA_OT_displacement_stroke)
register, unregister = bpy.utils.register_classes_factory(classes)

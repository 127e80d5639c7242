"""``tessera.impostor_bake``: the active object baked into an octahedral impostor (colour, normal and depth atlases
rendered by Cycles in a worker process) on a card that faces the camera, for EEVEE and Cycles renders;
``tessera.impostor_export``: such a card written to glTF (`addon.impostors.export`).

The bake runs in a background worker through the skeleton every render job shares (`render_job.RenderJobOperator`):
in the UI the status bar shows the views done and Esc leaves nothing; the views are read and dilated on a worker
thread, and the main thread only makes the images and the card; the redo panel renders again only when a setting
that changes the render changed (Blend Views and Dilation reuse the last views)."""

import bpy

from ..addon.guarded import check_numbers, guarded
from ..addon.impostors.bake import (
    atlas_pixels,
    check_atlas_size,
    dilated,
    make_card_steps,
    packed_float_image_steps,
    read_atlas,
    start_atlas,
)
from ..addon.impostors.export import export_card, impostor_info
from ..addon.preferences import get_preferences
from ..addon.render_jobs import render_device, render_key
from ..kernels.common.errors import TesseraError
from .render_job import RenderJobOperator
from .selection import object_poll, select_only

#: The object types a card can be baked of (what Cycles renders as geometry).
_BAKEABLE = {"MESH", "CURVE", "SURFACE", "META", "FONT"}
#: The last views rendered (before dilation), by what their render depended on: the redo panel reuses them.
_last = {"key": None, "rendered": None, "what": None, "device": ""}


def _object(what):
    """The object a bake started on (``what`` = (session_uid, name)), wherever it is now."""
    uid, name = what
    ob = next((o for o in bpy.data.objects if o.session_uid == uid), None)
    if ob is None:
        raise TesseraError(f"{name!r} was deleted while its views were rendered: nothing was made")
    return ob


class TESSERA_OT_impostor_bake(RenderJobOperator, bpy.types.Operator):
    """Render each selected object from many directions with Cycles onto a camera-facing card that stands in for it"""

    bl_idname = "tessera.impostor_bake"
    bl_label = "Bake Impostor"
    bl_options = {"REGISTER", "UNDO"}

    grid: bpy.props.IntProperty(name="Views", default=8, min=1, max=32,
                                description="Views along each side of the atlas (Views × Views directions)")
    tile: bpy.props.IntProperty(name="View Size", default=128, min=8, max=2048, soft_max=1024, subtype="PIXEL",
                                description="Width and height of each view")
    samples: bpy.props.IntProperty(name="Samples", default=16, min=1, max=4096, soft_max=1024,
                                   description="Cycles samples per view")
    dilation: bpy.props.IntProperty(name="Dilation", default=4, min=0, max=64, subtype="PIXEL",
                                    description="Texels each view's colours and normals spread into the empty texels "
                                                "around it (alpha stays 0), so engines that filter the atlas show no "
                                                "dark halo at the outline")
    blend: bpy.props.BoolProperty(name="Blend Views", default=True,
                                  description="Mix the four views nearest the view direction, so the card changes "
                                              "smoothly as it turns; off: the nearest view alone")
    hemi: bpy.props.BoolProperty(name="Upper Hemisphere", default=False,
                                 description="Views only from above: more detail for objects that stand on the "
                                             "ground")

    job_label = "Baking impostor views"
    cancelled = "Impostor bake cancelled: nothing was made"
    _last = _last

    @classmethod
    def poll(cls, context):
        return object_poll(cls, context, _BAKEABLE, "Select an object with geometry in Object Mode")

    @staticmethod
    def _wanted(ob):
        return ob.type in _BAKEABLE

    def _render_key(self, context):
        """What the views depend on (`render_jobs.render_key`) and the settings that change the render (Blend Views
        and Dilation reuse the last views)."""
        return render_key(context, context.active_object), self.grid, self.tile, self.samples, self.hemi

    def _start(self, context):
        """Check the size, then start the worker: the `AtlasJob` and the object baked."""
        check_numbers(self)
        check_atlas_size(self.grid, self.tile, get_preferences(context).memory_budget_bytes)
        ob = context.active_object
        return (start_atlas(ob, self.grid, self.tile, self.samples, self.hemi, render_device(context)),
                (ob.session_uid, ob.name))

    @staticmethod
    def _read(handle, what):
        return read_atlas(handle)

    def _settings(self):
        return (self.dilation,)

    @staticmethod
    def _prepare(atlas, what, dilation):
        return dilated(atlas, dilation)

    @staticmethod
    def _render_bytes(atlas):
        return atlas.colour.nbytes * 3  # colour, normal and depth

    def _make_steps(self, context, tx, atlas, what, device):
        """The card and its images from a dilated atlas, one step at a time (each image, the parts of the card's
        material, the card), so that a timer tick never holds the UI long; returns the operator's result."""
        ob = _object(what)
        name = f"{ob.name} impostor"
        images = {}
        for key, pixels in atlas_pixels(atlas).items():
            images[key] = tx.track((yield from packed_float_image_steps(f"{name} {key}", pixels)))
            yield
        card = yield from make_card_steps(name, atlas, images, context.scene.camera, self.blend)
        tx.track(card.data)
        tx.track(card.data.materials[0])
        tx.track(card)
        context.collection.objects.link(card)
        select_only(context, [card])
        note = "" if context.scene.camera else " (no scene camera: add a Track To constraint to the camera)"
        on = f", rendered on {device}" if device else ""
        self.report({"INFO"}, f"{name}: {self.grid}x{self.grid} views of {self.tile}px{on}{note}")
        return {"FINISHED"}


class TESSERA_OT_impostor_export(bpy.types.Operator):
    """Write the active impostor card and its atlas to a glTF binary (.glb) file for game engines"""

    bl_idname = "tessera.impostor_export"
    bl_label = "Tessera Impostor (.glb)"
    bl_options = {"REGISTER"}

    filepath: bpy.props.StringProperty(name="File", subtype="FILE_PATH", description="The .glb file to write")
    filter_glob: bpy.props.StringProperty(default="*.glb", options={"HIDDEN"}, description="Files listed")

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT" or impostor_info(context.active_object) is None:
            cls.poll_message_set("Select a card made by Bake Impostor, in Object Mode")
            return False
        return True

    def invoke(self, context, event):
        if not self.filepath:
            self.filepath = bpy.path.clean_name(context.active_object.name) + ".glb"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    @guarded
    def execute(self, context, tx):
        path = bpy.path.abspath(self.filepath)
        if not path.lower().endswith(".glb"):
            path += ".glb"
        export_card(context.active_object, path)
        self.report({"INFO"}, f"Wrote {path}")
        return {"FINISHED"}


classes = (TESSERA_OT_impostor_bake, TESSERA_OT_impostor_export)
register, unregister = bpy.utils.register_classes_factory(classes)

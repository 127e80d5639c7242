"""``tessera.impostor_bake``: the active object baked into an octahedral impostor (colour, normal and depth atlases
rendered by Cycles in a worker process) on a card that faces the camera, for EEVEE and Cycles renders;
``tessera.impostor_export``: such a card written to glTF (`addon.impostors.export`).

In the UI the bake runs in the background (`addon.render_jobs`): the operator returns at once, a timer follows the
worker, the status bar shows the views done, Esc stops it and leaves nothing. Scripts, ``blender -b`` and the redo
panel run it to the end with progress lines. Once the views are in, they are read and dilated on a worker thread; the
main thread only makes the images and the card; the redo panel renders again only when a setting that changes the
render changed (Blend Views and Dilation reuse the last views)."""

import bpy

from ..addon.guarded import Transaction, check_numbers, guarded, guarded_step
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
from ..kernels.common import workers
from ..kernels.common.errors import TesseraError
from .selection import object_poll, select_only


def _read_dilated(aj, dilation):
    """(the atlas as rendered, the atlas dilated) of a finished job: on a worker thread (numpy and file reads only)."""
    atlas = read_atlas(aj)
    return atlas, dilated(atlas, dilation)


#: The last atlas rendered (before dilation), by what its render depended on: the redo panel reuses it.
_last = {"key": None, "atlas": None, "device": ""}
#: Atlases at most this large are kept for the redo panel.
_KEEP_BYTES = 256 * 2**20


def _render_key(context, ob, op):
    """What a bake's views depend on (`render_jobs.render_key`) and the settings that change the render."""
    return render_key(context, ob), op.grid, op.tile, op.samples, op.hemi


class TESSERA_OT_impostor_bake(bpy.types.Operator):
    """Render the active object from many directions with Cycles onto a camera-facing card that stands in for it"""

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

    @classmethod
    def poll(cls, context):
        return object_poll(cls, context, {"MESH", "CURVE", "SURFACE", "META", "FONT"},
                           "Select an object with geometry in Object Mode")

    def _start(self, context):
        """Check the size, then start the worker: the `AtlasJob`, or a `TesseraError`."""
        check_numbers(self)
        check_atlas_size(self.grid, self.tile, get_preferences(context).memory_budget_bytes)
        return start_atlas(context.active_object, self.grid, self.tile, self.samples, self.hemi,
                           render_device(context))

    def invoke(self, context, event):
        """In the UI: start the bake and follow it from a timer (the UI never waits); elsewhere: `execute`."""
        if bpy.app.background or context.window is None:
            return self.execute(context)
        started = self._begin(context)
        if started is not None:
            return started
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, self._job.job.total)
        self._status(context)
        return {"RUNNING_MODAL"}

    @guarded
    def _begin_guarded(self, context, tx):
        self._name = context.active_object.name  # the object baked, whatever is active when the views are in
        self._key = _render_key(context, context.active_object, self)
        self._job = self._start(context)
        return {"FINISHED"}

    def _begin(self, context):
        """Start the job; None when it started, else the operator's result (the refusal is reported)."""
        self._job, self._reading, self._making = None, None, None
        result = self._begin_guarded(context)
        return None if self._job is not None else result

    def _status(self, context):
        job = self._job.job
        done = job.fraction()
        context.window_manager.progress_update(done)
        device = job.device()
        on = f" on {device}" if device else ""
        view = min(int(done) + 1, job.total)
        context.workspace.status_text_set(f"Baking impostor: view {view} of {job.total} "
                                          f"({100.0 * done / max(job.total, 1):.0f}%){on} — Esc to cancel")

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == "ESC":
            self._job.job.cancel()
            if self._making is not None:
                self._tx.rollback()  # the images made so far
            self._end(context)
            self.report({"WARNING"}, "Impostor bake cancelled: nothing was made")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if self._job.job.running():
            self._status(context)
            return {"RUNNING_MODAL"}
        if self._reading is None:  # the views are in: read and dilate them on a worker thread, the UI keeps going
            self._device = self._job.job.device()
            dilation = self.dilation
            self._reading = workers.submit(lambda: _read_dilated(self._job, dilation))
            context.workspace.status_text_set("Baking impostor: reading the views — Esc to cancel")
            return {"RUNNING_MODAL"}
        if not self._reading.done():
            return {"RUNNING_MODAL"}
        if self._making is None:  # then the images and the card, one per tick
            self._tx = Transaction()
            self._making = self._finish_steps(context)
        result = guarded_step(self, self._tx, self._making)
        if result is None:
            return {"RUNNING_MODAL"}
        self._end(context)
        return result

    def _finish_steps(self, context):
        atlas, ready = self._reading.result()
        _last.update(key=self._key if atlas.colour.nbytes * 3 <= _KEEP_BYTES else None, atlas=atlas,
                     device=self._device)
        ob = bpy.data.objects.get(self._name)
        if ob is None:
            raise TesseraError(f"{self._name!r} was deleted while its views were rendered: nothing was made")
        return (yield from self._make_steps(context, self._tx, atlas, _last["device"], ob, ready))

    @guarded
    def execute(self, context, tx):
        """Scripts, ``blender -b`` and the redo panel: to the end, with progress lines; the last views are reused
        when nothing the render depends on changed."""
        ob = context.active_object
        key = _render_key(context, ob, self)
        if _last["key"] == key and _last["atlas"] is not None:
            atlas, device = _last["atlas"], _last["device"]
        else:
            aj = self._start(context)
            try:
                aj.job.wait(None, "Baking impostor views")
            except BaseException:
                aj.job.cancel()
                raise
            atlas, device = read_atlas(aj), aj.job.device()
            _last.update(key=key if atlas.colour.nbytes * 3 <= _KEEP_BYTES else None, atlas=atlas, device=device)
        return self._make(context, tx, atlas, device, ob)

    def _make(self, context, tx, atlas, device, ob, ready=None):
        """``ob``'s card and its images from a rendered atlas (dilated here unless ``ready`` is: the kept atlas stays
        as rendered)."""
        steps = self._make_steps(context, tx, atlas, device, ob, ready)
        while True:
            try:
                next(steps)
            except StopIteration as done:
                return done.value

    def _make_steps(self, context, tx, atlas, device, ob, ready=None):
        """`_make` one step at a time (a generator: each image, the parts of the card's material, the card), so that a
        timer tick never holds the UI long; returns the operator's result."""
        atlas = ready if ready is not None else dilated(atlas, self.dilation)
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

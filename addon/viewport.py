"""The mechanism every viewport preview shares: draw handlers, per-object caches, and invalidation.

- `Preview` is one preview (tessellation, tubes, terrain): its draw callback, the data-block types whose edits
  drop its uploads, and its `PreviewCache`, keyed by the object's ``session_uid`` (stable across renames and
  undo steps, unlike names).
- Settings never import previews. A property's ``update=`` is `invalidator(topic)`; a preview subscribes to its
  topic with a callback that forgets what the change makes stale. `invalidate` runs the subscribers and asks
  the 3D viewports to redraw.
- `clear_previews` forgets every preview's uploads, the compiled shaders and the pattern batches (one place;
  the add-on calls it when it is disabled).
"""

from dataclasses import dataclass, field

import bpy

from ..gpu_shaders import loader
from ..kernels.common.errors import GPUShaderError, TesseraError

_previews = []  # every registered Preview
_subscribers = {}  # topic -> [callback(owner)]


def tag_view3d_redraw():
    """Ask every 3D viewport to redraw (after a preview's data or settings changed)."""
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


# --- invalidation --------------------------------------------------------------------------------------------

def subscribe(topic, callback):
    """Call ``callback(owner)`` whenever settings of ``topic`` change on ``owner`` (an ID, usually an Object)."""
    callbacks = _subscribers.setdefault(topic, [])
    if callback not in callbacks:
        callbacks.append(callback)


def unsubscribe(topic, callback):
    callbacks = _subscribers.get(topic, [])
    if callback in callbacks:
        callbacks.remove(callback)


def invalidate(topic, owner):
    """Settings of ``topic`` changed on ``owner``: tell the subscribers, then redraw."""
    for callback in tuple(_subscribers.get(topic, ())):
        callback(owner)
    tag_view3d_redraw()


def invalidator(topic):
    """An ``update=`` callback for properties of ``topic``: ``invalidate(topic, the property's owner ID)``."""

    def update(self, context):
        invalidate(topic, self.id_data)

    return update


def with_update(options, update):
    """The property definitions of the options class ``options`` (its annotations), each with ``update=`` added:
    for a property group whose changes must reach the previews. The class itself keeps its update-free
    definitions for operators (an operator's properties are set while panels draw, where an update that
    redraws would loop)."""
    return {name: prop.function(**{**prop.keywords, "update": update})
            for name, prop in options.__annotations__.items()}


# --- caches --------------------------------------------------------------------------------------------------

@dataclass
class PreviewEntry:
    """What a preview keeps for one object.

    draw: the GPU draw data (`gpu_shaders.<capability>.draw`); data_uid: ``session_uid`` of the data block it was
    read from (an edit of that block drops the entry); source: what the upload depends on (settings, UV map...):
    a change rebuilds it; view: the key of the view or levels the draw data is set up for (None: set it up).
    """

    draw: object
    data_uid: int | None = None
    source: tuple = ()
    view: object = None


@dataclass
class PreviewCache:
    """Entries of one preview by object ``session_uid``, and the errors that stopped an object from being built
    (kept so that a broken object is not retried every frame; any change of it clears the error)."""

    entries: dict = field(default_factory=dict)
    errors: dict = field(default_factory=dict)

    def __contains__(self, ob):
        return ob.session_uid in self.entries

    def get(self, ob):
        return self.entries.get(ob.session_uid)

    def put(self, ob, entry):
        self.entries[ob.session_uid] = entry
        self.errors.pop(ob.session_uid, None)
        return entry

    def fail(self, ob, message):
        self.errors[ob.session_uid] = message

    def failed(self, ob):
        return ob.session_uid in self.errors

    def forget(self, ob):
        """Drop ``ob``'s entry and error (it is rebuilt on the next draw)."""
        self._drop(ob.session_uid)

    def forget_error(self, ob):
        """Let a failed ``ob`` be tried again on the next draw (its settings changed)."""
        self.errors.pop(ob.session_uid, None)

    def _drop(self, uid):
        self.entries.pop(uid, None)
        self.errors.pop(uid, None)

    def clear(self):
        self.entries.clear()
        self.errors.clear()

    def drop_stale(self, depsgraph, data_types):
        """Forget objects whose geometry changed, or whose data block (one of ``data_types``) changed."""
        if not self.entries:
            return
        for update in depsgraph.updates:
            block = update.id.original if hasattr(update.id, "original") else update.id
            if isinstance(block, bpy.types.Object) and block.session_uid in self.entries:
                if update.is_updated_geometry:
                    self._drop(block.session_uid)
            elif isinstance(block, data_types):
                for uid in [uid for uid, entry in self.entries.items() if entry.data_uid == block.session_uid]:
                    self._drop(uid)


# --- previews ------------------------------------------------------------------------------------------------

def _view_draw(preview):
    """A POST_VIEW handler calling the preview's ``draw(context, region, view, projection)`` (numpy 4x4s) with depth
    test on; nothing once the preview has stopped on a shader that does not compile (`Preview.stop`)."""

    def handler():
        import gpu
        import numpy as np

        context = bpy.context
        region, rv3d = context.region, context.region_data
        if region is None or rv3d is None or preview.stopped:
            return
        gpu.state.depth_test_set("LESS_EQUAL")
        gpu.state.depth_mask_set(True)
        try:
            preview.run(context, region, np.array(rv3d.view_matrix), np.array(rv3d.window_matrix))
        finally:
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)

    return handler


@bpy.app.handlers.persistent  # survive file loads
def _on_depsgraph(scene, depsgraph):
    for preview in _previews:
        if preview.data_types:
            preview.cache.drop_stale(depsgraph, preview.data_types)


class Preview:
    """One viewport preview.

    draw(context, region, view, projection): draws every object it previews; data_types: data-block types whose
    edits drop an object's upload (depsgraph); topic: the settings topic whose changes call ``on_settings(ob)``
    (default: forget ``ob``'s upload).
    """

    def __init__(self, draw, data_types=(), topic=None, on_settings=None):
        self.draw, self.data_types, self.topic = draw, tuple(data_types), topic
        self.on_settings = on_settings or self.forget
        self.cache = PreviewCache()
        self._handler = None
        self.stopped = ""  # why the preview stopped drawing (a shader that does not compile here), or ""

    def stop(self, err):
        """Stop drawing for the session, telling why once (the sidebar's GPU notice shows it)."""
        if not self.stopped:
            self.stopped = str(err)
            print(f"Tessera: the {self.topic or 'viewport'} preview stopped: {err}. The operators compute on the CPU.")
            tag_view3d_redraw()

    def run(self, context, region, view, projection):
        """Draw once; a shader that does not compile stops the preview (told once), never raises per frame."""
        try:
            self.draw(context, region, view, projection)
        except GPUShaderError as err:
            self.stop(err)

    def forget(self, ob):
        if isinstance(ob, bpy.types.Object):
            self.cache.forget(ob)

    def entry(self, ob, build):
        """``ob``'s entry, built by ``build()`` (a `PreviewEntry`) on first use; None when building raised a
        `TesseraError` (remembered until ``ob`` or its settings change)."""
        entry = self.cache.get(ob)
        if entry is None and not self.cache.failed(ob):
            try:
                entry = self.cache.put(ob, build())
            except GPUShaderError as err:  # not this object's fault: the whole preview stops
                self.cache.fail(ob, str(err))
                self.stop(err)
            except TesseraError as err:
                self.cache.fail(ob, str(err))
        return entry

    def register(self):
        """Install the handlers (no draw handler in background mode) and subscribe to the settings topic."""
        if self not in _previews:
            _previews.append(self)
        if _on_depsgraph not in bpy.app.handlers.depsgraph_update_post:
            bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph)
        if self.topic is not None:
            subscribe(self.topic, self.on_settings)
        if not bpy.app.background and self._handler is None:
            self._handler = bpy.types.SpaceView3D.draw_handler_add(_view_draw(self), (), "WINDOW", "POST_VIEW")

    def unregister(self):
        """Undo `register` and forget every upload."""
        if self._handler is not None:
            bpy.types.SpaceView3D.draw_handler_remove(self._handler, "WINDOW")
            self._handler = None
        if self.topic is not None:
            unsubscribe(self.topic, self.on_settings)
        self.cache.clear()
        if self in _previews:
            _previews.remove(self)
        if not _previews and _on_depsgraph in bpy.app.handlers.depsgraph_update_post:
            bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph)


def stopped_previews():
    """Why previews stopped drawing: {topic: message} (empty when all draw)."""
    return {preview.topic or "viewport": preview.stopped for preview in _previews if preview.stopped}


def clear_previews():
    """Forget every preview's uploads, compiled shaders and pattern batches (rebuilt on the next draw)."""
    for preview in _previews:
        preview.cache.clear()
    loader.clear()


def register():
    pass


def unregister():
    clear_previews()
    _subscribers.clear()

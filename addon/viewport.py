"""The mechanism every viewport preview shares: draw handlers, per-object caches, and invalidation.

- `Preview` is one preview (tessellation, tubes, terrain): its draw callback, the data-block types whose edits
  drop its uploads, and its `PreviewCache`, keyed by the object's ``session_uid`` (stable across renames and
  undo steps, unlike names).
- Settings never import previews. A property's ``update=`` is `invalidator(topic)`; a preview subscribes to its
  topic with a callback that forgets what the change makes stale. `invalidate` runs the subscribers and asks
  the 3D viewports to redraw.
- `clear_previews` forgets every preview's uploads, the compiled shaders and the pattern batches (one place;
  the add-on calls it when it is disabled).
- A preview that stands for its object's surface (tessellation, Loop, terrain, the live board) is drawn *instead
  of* the object, as a modifier's result is: while it is on, `sync_source` gives the object a last, viewport-only
  modifier (`SOURCE_MODIFIER`) that hands Blender the evaluated geometry as instances of zero size (two, at the
  far corners of its bounding box, so the object keeps its bounds), so Blender draws none of the
  object's faces or wires, while its edit cage (the modifier is off in Edit Mode), its modifier stack and renders
  stay as they were. `source_mesh` reads the evaluated mesh back from that instance. The modifier is added
  and removed only by `sync_source` (from the preview switches, file loads and saves: saved files never hold it).
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
    """Settings of ``topic`` changed on ``owner``: tell the subscribers, give or take the object's
    `SOURCE_MODIFIER` (a preview switched on or off), then redraw."""
    for callback in tuple(_subscribers.get(topic, ())):
        callback(owner)
    if isinstance(owner, bpy.types.Object):
        sync_source(owner)
    tag_view3d_redraw()


def invalidator(topic):
    """An ``update=`` callback for properties of ``topic``: ``invalidate(topic, the property's owner ID)``."""

    def update(self, context):
        invalidate(topic, self.id_data)

    return update


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


# --- the source a preview stands for -------------------------------------------------------------------------

#: The modifier that keeps Blender from drawing an object while a preview stands for it, and its node group.
SOURCE_MODIFIER = "Tessera Preview"
SOURCE_GROUP = ".Tessera Preview Source"
_GROUP_TAG = "tessera_preview_source"
_GROUP_VERSION = 3  # 3: two zero-size instances, at the box's corners, so the object keeps its bounds


def _source_group():
    """The node group of `SOURCE_MODIFIER` (made once per file): the geometry as two instances scaled to zero, one
    at each far corner of its bounding box. Blender draws neither, while the object keeps its bounds: Frame
    Selected, the view's clipping and a board's framing see the object's size. (Loose vertices would keep the bounds
    too, but Blender draws them as dots.)"""
    group = bpy.data.node_groups.get(SOURCE_GROUP)
    if group is not None and group.get(_GROUP_TAG) == _GROUP_VERSION:
        return group
    group = bpy.data.node_groups.new(SOURCE_GROUP, "GeometryNodeTree")
    group[_GROUP_TAG] = _GROUP_VERSION
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    source, result = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    instance = nodes.new("GeometryNodeGeometryToInstance")
    box = nodes.new("GeometryNodeBoundBox")
    join = nodes.new("GeometryNodeJoinGeometry")
    links.new(source.outputs[0], instance.inputs[0])
    links.new(source.outputs[0], box.inputs[0])
    for corner in ("Min", "Max"):
        scale = nodes.new("GeometryNodeScaleInstances")
        scale.inputs["Scale"].default_value = (0.0, 0.0, 0.0)
        links.new(instance.outputs[0], scale.inputs[0])
        links.new(box.outputs[corner], scale.inputs["Center"])
        links.new(scale.outputs[0], join.inputs[0])
    links.new(join.outputs[0], result.inputs[0])
    return group


def stands_for(ob):
    """True when a preview that stands for ``ob``'s surface is on for it."""
    return any(p.replaces is not None and p.replaces(ob) for p in _previews)


def sync_source(ob):
    """Give ``ob`` the `SOURCE_MODIFIER` exactly while a preview stands for it (last in its stack, viewport only,
    off in Edit Mode); remove it otherwise. Returns True when something changed."""
    if getattr(ob, "type", None) != "MESH" or ob.library is not None:
        return False
    mod = ob.modifiers.get(SOURCE_MODIFIER)
    want = stands_for(ob) and not bpy.app.background
    if want and mod is None:
        mod = ob.modifiers.new(SOURCE_MODIFIER, "NODES")
        mod.node_group = _source_group()
        mod.show_render = False
        mod.show_in_editmode = False
        mod.show_expanded = False
        return True
    if want and ob.modifiers[-1] != mod:  # the user added a modifier after it: it stays last
        ob.modifiers.move(list(ob.modifiers).index(mod), len(ob.modifiers) - 1)
        return True
    if not want and mod is not None:
        ob.modifiers.remove(mod)
        return True
    return False


def source_mesh(ob, depsgraph):
    """The mesh a preview of ``ob`` reads: its evaluated mesh with its modifiers (as the operators read it), from
    the first zero-size instance of `SOURCE_MODIFIER` when that is on. Returns ``(mesh, release)``; call ``release()``
    when done reading."""
    evaluated = ob.evaluated_get(depsgraph)
    if ob.modifiers.get(SOURCE_MODIFIER) is not None:
        for instance in depsgraph.object_instances:
            if instance.is_instance and instance.parent is not None and instance.parent.original == ob \
                    and instance.object.type == "MESH":
                return instance.object.data, lambda: None
    return evaluated.to_mesh(), evaluated.to_mesh_clear


def previewed_objects(context, wanted):
    """The objects of this viewport a preview draws: visible here (not hidden, in Local View when it is on), in
    Object Mode, and ``wanted(ob)``."""
    space = context.space_data
    for ob in context.view_layer.objects:
        if ob.mode == "EDIT" or not wanted(ob):
            continue
        if ob.visible_get(view_layer=context.view_layer, viewport=space):
            yield ob


@dataclass
class PreviewStyle:
    """How one object's preview is drawn in this view (`preview_style`): ``alpha`` of its surface (below 1 in
    X-ray), ``wire_color`` (rgba, linear) of its wire or None when no wire is drawn, and ``xray``: X-ray is on."""

    alpha: float = 1.0
    wire_color: tuple | None = None
    xray: bool = False

    def surface_color(self, rgba):
        return (*rgba[:3], rgba[3] * self.alpha)


def _linear(rgb):
    """The theme's sRGB colour in the viewport's linear space."""
    c = [float(v) for v in rgb[:3]]
    return tuple(v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4 for v in c)


def preview_style(context, ob):
    """The `PreviewStyle` of ``ob``'s preview as the viewport draws objects: see-through in X-ray (its alpha), its
    wire in Wireframe shading, with the Wireframe overlay or the object's own Wireframe display, in the theme's wire
    colour (selected and active as Blender draws them)."""
    space = context.space_data
    shading = space.shading
    wireframe = shading.type == "WIREFRAME"
    xray = shading.show_xray_wireframe if wireframe else shading.show_xray
    style = PreviewStyle(alpha=(shading.xray_alpha_wireframe if wireframe else shading.xray_alpha) if xray else 1.0,
                         xray=xray)
    overlay = space.overlay
    if wireframe or (overlay.show_overlays and (overlay.show_wireframes or ob.show_wire)):
        theme = context.preferences.themes[0].view_3d
        if ob.select_get():
            rgb = theme.object_active if ob == context.view_layer.objects.active else theme.object_selected
        else:
            rgb = theme.wire
        style.wire_color = (*_linear(rgb), 1.0)
    return style


_outlined = []  # (draw(color), outline id) of the previews the current draw handler drew for selected objects


def outline(context, ob, draw):
    """Outline ``ob``'s preview as Blender outlines a selected object (its overlay outlines the object's own
    geometry, which the preview hides): when ``ob`` is selected and the viewport draws outlines (overlays on, Outline
    Selected on, not Wireframe shading), ``draw(color)`` (the preview drawn flat, unlit, in ``color``) is kept for
    the outline the draw handler adds once its preview has drawn (`gpu_shaders.outline`)."""
    space = context.space_data
    if space is None or not ob.select_get() or space.shading.type == "WIREFRAME" \
            or not space.overlay.show_overlays or not space.overlay.show_outline_selected:
        return  # no 3D view (an offscreen drawing), or no outline to draw
    from ..gpu_shaders.outline import ACTIVE_ID, SELECTED_ID

    _outlined.append((draw, ACTIVE_ID if ob == context.view_layer.objects.active else SELECTED_ID))


def thick_outline(preferences):
    """Whether Blender draws its selection outline two pixels a side (instead of one): at a resolution scale above 1,
    or with the theme's Outline Width above 2."""
    return preferences.system.pixel_size > 1.0 or preferences.themes[0].view_3d.outline_width > 2


def _draw_outlines(context, region):
    """The outline of what `outline` kept, over the viewport: in the theme's selected and active colours, two pixels
    a side where Blender's is (a resolution scale above 1, or the theme's Outline Width above 2), as bright behind
    other objects as in front in X-ray."""
    from ..gpu_shaders import outline as gpu_outline

    try:
        shader = gpu_outline.shader()
    except GPUShaderError:
        return  # told once by the loader: previews draw on, without outlines
    theme = context.preferences.themes[0].view_3d
    mask = gpu_outline.mask_for((region.width, region.height))
    mask.draw(_outlined)
    gpu_outline.resolve(shader, mask, (*_linear(theme.object_selected), 1.0), (*_linear(theme.object_active), 1.0),
                        thick=thick_outline(context.preferences), xray=context.space_data.shading.show_xray)


@bpy.app.handlers.persistent
def _sync_all(*_args):
    """After a file loads: the modifier where previews are on. Before a save: none (a file never holds one)."""
    for ob in bpy.data.objects:
        sync_source(ob)


@bpy.app.handlers.persistent
def _strip_all(*_args):
    for ob in bpy.data.objects:
        mod = ob.modifiers.get(SOURCE_MODIFIER) if ob.type == "MESH" and ob.library is None else None
        if mod is not None:
            ob.modifiers.remove(mod)


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
            if _outlined:
                _draw_outlines(context, region)
        finally:
            _outlined.clear()
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
    (default: forget ``ob``'s upload); replaces(ob): the preview is on for ``ob`` and is drawn instead of it
    (`sync_source`).
    """

    def __init__(self, draw, data_types=(), topic=None, on_settings=None, replaces=None):
        self.draw, self.data_types, self.topic = draw, tuple(data_types), topic
        self.replaces = replaces  # replaces(ob): True when the preview stands for ob's surface (`sync_source`)
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
        for handlers, handler in _FILE_HANDLERS:
            if handler not in handlers:
                handlers.append(handler)
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
        if not _previews:
            for handlers, handler in _FILE_HANDLERS:
                if handler in handlers:
                    handlers.remove(handler)


_FILE_HANDLERS = ((bpy.app.handlers.load_post, _sync_all), (bpy.app.handlers.save_pre, _strip_all),
                  (bpy.app.handlers.save_post, _sync_all))


def stopped_previews():
    """Why previews stopped drawing: {topic: message} (empty when all draw)."""
    return {preview.topic or "viewport": preview.stopped for preview in _previews if preview.stopped}


def clear_previews():
    """Forget every preview's uploads, compiled shaders and pattern batches (rebuilt on the next draw)."""
    from ..gpu_shaders import outline as gpu_outline

    for preview in _previews:
        preview.cache.clear()
    loader.clear()
    gpu_outline.clear()


def register():
    pass


def unregister():
    if not bpy.app.background:
        _strip_all()
    clear_previews()
    _subscribers.clear()

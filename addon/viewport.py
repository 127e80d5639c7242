"""Small helpers shared by the viewport previews."""

import bpy


def tag_view3d_redraw():
    """Ask every 3D viewport to redraw (after a preview's data or settings changed)."""
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def new_state():
    """The state a preview module keeps: its draw handler, and per object name the uploaded data and errors."""
    return {"handler": None, "cache": {}, "errors": {}}


def drop_stale(state, depsgraph, data_types):
    """Forget the cached objects whose geometry changed, or whose data block (one of ``data_types``, matched by
    the entry's ``"data"`` name) changed; they are rebuilt on the next draw."""
    cache = state["cache"]
    if not cache:
        return
    for update in depsgraph.updates:
        obj = update.id.original if hasattr(update.id, "original") else update.id
        if isinstance(obj, bpy.types.Object) and obj.name in cache and update.is_updated_geometry:
            names = [obj.name]
        elif isinstance(obj, data_types):
            names = [name for name, entry in cache.items() if entry["data"] == obj.name]
        else:
            continue
        for name in names:
            cache.pop(name, None)
            state["errors"].pop(name, None)


def _view_draw(draw):
    """A POST_VIEW handler calling ``draw(context, region, view, projection)`` (numpy 4x4s) with depth test on."""

    def handler():
        import gpu
        import numpy as np

        context = bpy.context
        region, rv3d = context.region, context.region_data
        if region is None or rv3d is None:
            return
        gpu.state.depth_test_set("LESS_EQUAL")
        gpu.state.depth_mask_set(True)
        try:
            draw(context, region, np.array(rv3d.view_matrix), np.array(rv3d.window_matrix))
        finally:
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)

    return handler


def add_handlers(state, draw, on_depsgraph=None):
    """Install a preview: its depsgraph handler (if any), and its draw handler unless in background mode."""
    if on_depsgraph is not None:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph)
    if not bpy.app.background:
        state["handler"] = bpy.types.SpaceView3D.draw_handler_add(_view_draw(draw), (), "WINDOW", "POST_VIEW")


def remove_handlers(state, on_depsgraph=None):
    """Undo `add_handlers` and forget every upload."""
    if on_depsgraph is not None and on_depsgraph in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph)
    if state["handler"] is not None:
        bpy.types.SpaceView3D.draw_handler_remove(state["handler"], "WINDOW")
        state["handler"] = None
    state["cache"].clear()
    state["errors"].clear()

"""Small helpers shared by the viewport previews."""

import bpy


def tag_view3d_redraw():
    """Ask every 3D viewport to redraw (after a preview's data or settings changed)."""
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()

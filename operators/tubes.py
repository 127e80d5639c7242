"""``tessera.tubes``: tube meshes around curves, hair curves and mesh edges (one new object per source)."""

import bpy

from ..addon import bridge
from ..addon.cameras import camera_for, object_camera
from ..addon.guarded import guarded
from ..addon.preferences import get_preferences
from ..addon.settings_scaffold import copy_options
from ..addon.tubes.settings import TubeOptions, draw_tubes_settings, kernel_settings
from ..addon.tubes.sources import SOURCE_TYPES, read_lines
from ..kernels.common.budget import check_bytes
from ..kernels.common.errors import EmptyResultError
from ..kernels.tubes.builder import build_tubes
from .selection import select_only

# output bytes per vertex (position, normal) and per corner (vertex, edge, UV) plus per edge, for the memory guard
_BYTES_PER_VERTEX, _BYTES_PER_CORNER, _BYTES_PER_EDGE = 24, 16, 8


class TESSERA_OT_tubes(TubeOptions, bpy.types.Operator):
    """Build tube meshes around the selected curves, hair curves or mesh edges"""

    bl_idname = "tessera.tubes"
    bl_label = "Tubes"
    bl_options = {"REGISTER", "UNDO"}

    # the options: TubeOptions (addon/tubes/settings.py), shared with Object.tessera.tubes

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to build tubes")
            return False
        if not any(ob.type in SOURCE_TYPES for ob in context.selected_objects):
            cls.poll_message_set("Select curves, hair curves or meshes with edges")
            return False
        return True

    def draw(self, context):
        draw_tubes_settings(self.layout, self)

    def settings(self):
        return kernel_settings(self)

    @guarded
    def execute(self, context, tx):
        sources = [ob for ob in context.selected_objects if ob.type in SOURCE_TYPES]
        settings = self.settings()
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            camera = None
            if settings.sides_mode == "CAMERA" or settings.aa_clamp:
                camera = camera_for(context, self.camera_source, "Camera sides and the pixel clamp")
            results, empty = [], []
            for i, ob in enumerate(sources):
                def progress(f, i=i):
                    wm.progress_update(int(100 * (i + f) / len(sources)))

                cam = object_camera(camera, ob.matrix_world) if camera is not None else None
                # the kernel writes into the new mesh's own arrays (bridge.PolygonWriter.allocate)
                writer = bridge.PolygonWriter(f"{ob.data.name}.tubes", track=tx.track)
                try:
                    lines, notes = read_lines(ob, self)
                    self._check_budget(context, lines, settings)
                    poly = build_tubes(lines, settings, cam, progress, allocate=writer.allocate)
                except EmptyResultError as err:  # this source has nothing to build; the others may
                    empty.append(f"{ob.name}: {err}")
                    continue
                results.append((ob, writer.finish(poly), notes + poly.notes))
        finally:
            wm.progress_end()
        if not results:
            raise EmptyResultError(empty[0] if len(empty) == 1 else f"No tubes from {len(empty)} sources. {empty[0]}")
        made = [self._place(tx, ob, mesh) for ob, mesh, _ in results]  # every source built before any is placed
        for ob, _, notes in results:
            copy_options(TubeOptions, self, ob.tessera.tubes)  # a batch script can re-run them
            for note in notes:
                self.report({"WARNING"}, note)
        for note in empty:
            self.report({"WARNING"}, f"No tubes from {note}")
        select_only(context, made)
        return {"FINISHED"}

    def _check_budget(self, context, lines, settings):
        budget = get_preferences(context).memory_budget_bytes
        sides = settings.sides if settings.sides_mode == "FIXED" else settings.max_sides
        verts = len(lines.points) * sides * max(1, settings.refine)
        need = verts * (_BYTES_PER_VERTEX + 4 * _BYTES_PER_CORNER + 2 * _BYTES_PER_EDGE)
        check_bytes(need, budget, f"The tubes would have about {verts:,} vertices", "fewer sides")

    def _place(self, tx, ob, mesh):
        for material in getattr(ob.data, "materials", ()):
            mesh.materials.append(material)
        new = tx.new_object(f"{ob.name}.tubes", mesh)
        for collection in ob.users_collection:
            collection.objects.link(new)
        new.matrix_world = ob.matrix_world.copy()
        return new


classes = (TESSERA_OT_tubes,)
register, unregister = bpy.utils.register_classes_factory(classes)

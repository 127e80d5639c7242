"""``tessera.terrain_add`` (a terrain object from a height map) and ``tessera.terrain_bake`` (its crack-free
adaptive mesh for a camera, for render and export)."""

import os
import time

import bpy

from ..addon.cameras import camera_for, object_camera
from ..addon.guarded import check_numbers, each_selected, guarded
from ..addon.preferences import get_preferences
from ..addon.settings_scaffold import copy_options
from ..addon.terrain import data as terrain_data
from ..addon.terrain.settings import TerrainOptions, draw_terrain_settings, lod_settings
from ..kernels.common.budget import check_bytes
from ..kernels.common.errors import EmptyResultError, InvalidInputError
from ..kernels.terrain.lod import box_distance, select
from ..kernels.terrain.mesh import bake, triangle_count
from .selection import select_only

#: Blender memory per output triangle (vertex share, 3 corners, edges, face, UVs), for the memory guard.
_BYTES_PER_TRIANGLE = 80


def _camera_or_none(context, source):
    """The chosen camera, or None (view-independent levels) when there is none to use."""
    try:
        return camera_for(context, source)
    except InvalidInputError:
        return None


def _nothing_seen(hm, table, camera):
    """Why ``camera`` (terrain-local) sees no tile, and what to change."""
    distance, clip = box_distance(hm, table, camera), camera.clip_end
    if distance > clip:
        return (f"The camera sees no tile of this terrain: the terrain is {distance:,.0f} away, beyond the "
                f"camera's clip end (about {clip:,.4g}). Raise the camera's Clip End past {distance:,.0f}, move "
                "the camera closer, or turn off Frustum Culling")
    return ("The camera sees no tile of this terrain: it is within the clip end, but the camera looks away from "
            "it or sits under its surface. Aim the camera at the terrain (or raise it above the heights), or turn "
            "off Frustum Culling")


#: A terrain's whole tile grid as a `block` (column, row, columns, rows of an even split).
WHOLE = (0, 0, 1, 1)



def _block_property():
    return bpy.props.IntVectorProperty(
        name="Block", size=4, default=WHOLE, min=0, max=4096, options={"SKIP_SAVE"},
        description="Mesh one block of an even split of the terrain's tiles: column, row, columns, rows (0, 0, 2, 2 "
                    "is the lower-left quarter). Blocks of one split meet without cracks, so render-farm tasks can "
                    "each mesh one, reading only their part of the elevation data; 0, 0, 1, 1 meshes the whole "
                    "terrain")


def _void_index_property():
    return bpy.props.StringProperty(
        name="Void Index", subtype="FILE_PATH", options={"SKIP_SAVE"},
        description="The no-data voids of the elevation files, found and filled once for every block of a farm "
                    "split (the farm plan writes it), so a block task reads only its part of the data. Empty: the "
                    "voids are found by scanning the whole data")


def _bake_into(context, ob, camera, report, tx, block=WHOLE, void_index=""):
    """Select levels for ``camera``, check the budget, bake and write the mesh (its new mesh tracked by the
    `Transaction` ``tx``). Returns the selection. Raises `EmptyResultError` when the camera sees no tile.

    ``block`` (column, row, columns, rows) meshes only that block's tiles of an even split, reading and analysing
    only the block and the ring of tiles around it: every level is the one the whole terrain gives, so the blocks of
    one split weld into exactly the whole terrain's mesh. A block the camera does not see gets an empty mesh.
    ``void_index``: the voids of elevation files from a farm plan (`terrain_data.read_source`)."""
    s = ob.tessera.terrain
    wm = context.window_manager
    whole = tuple(block) == WHOLE
    part = None if whole else tuple(block)
    hm, table = terrain_data.analysis(ob, progress=lambda done, total: wm.progress_update(int(80 * done / total)),
                                      block=part, void_index=void_index)
    t0 = time.perf_counter()
    local_camera = object_camera(camera, ob.matrix_world) if camera else None
    sel = select(hm, table, local_camera, lod_settings(s), block=part)
    t_select = time.perf_counter() - t0
    n_tris = triangle_count(sel)
    if n_tris == 0 and whole:  # every tile culled: say which of the camera's settings keeps the terrain out
        raise EmptyResultError(_nothing_seen(hm, table, local_camera))
    check_bytes(n_tris * _BYTES_PER_TRIANGLE, get_preferences(context).memory_budget_bytes,
                f"The terrain mesh would have {n_tris:,} triangles", "a larger Screen Error or Adaptive levels")
    wm.progress_update(85)
    mesh = bake(hm, table, sel)
    tx.track(terrain_data.write_terrain_mesh(ob, f"{ob.name}.terrain", mesh))
    full = 2 * (hm.width - 1) * (hm.height - 1)
    view = "for the camera" if camera is not None else "view-independent (no camera)"
    if not whole:
        view += f", block {block[0]}, {block[1]} of {block[2]} x {block[3]}"
    report({"INFO"}, f"Terrain {view}: {len(mesh.triangles):,} triangles, {100 * len(mesh.triangles) / full:.2f}% "
                     f"of the full grid; {int(sel.culled.sum())} of {sel.culled.size} tiles culled; "
                     f"levels selected in {t_select * 1e3:.1f} ms")
    return sel


def _place(context, ob, geo, report):
    """Put a georeferenced terrain where its data lies: the first in a scene at the world origin (its centre
    becomes the scene's geographic origin), later ones beside it; a terrain in another CRS stays at the cursor."""
    scene = context.scene
    at = terrain_data.geo_location(scene, geo)
    if at is None and scene.get(terrain_data.GEO_ORIGIN) is not None:
        report({"WARNING"}, "This terrain's coordinate system differs from the one the scene's first georeferenced "
                            "terrain set; it is placed at the 3D cursor, not beside the others")
    else:
        ob.location = (*(at or (0.0, 0.0)), 0.0)
        terrain_data.set_geo_origin(scene, geo)
    hm = terrain_data.height_map(ob)  # read by the bake
    voids = hm.samples.void_count
    what = "none" if not voids else f"{voids:,} samples {'cut out' if hm.samples.cut else 'filled'}"
    (tx, ty), files = geo.texel, len(geo.files)
    notes = sorted({note for info in geo.files for note in info.notes})
    report({"INFO"}, f"Elevation data: {files} file{'s' if files > 1 else ''}, {geo.grid.shape[1]:,} x "
                     f"{geo.grid.shape[0]:,} samples, {tx:.4g} x {ty:.4g} m apart; no-data: {what}"
                     + "".join(f"; {note}" for note in notes))


class TESSERA_OT_terrain_add(TerrainOptions, bpy.types.Operator):
    """Add a terrain object from a height map, meshed adaptively for the scene camera"""

    bl_idname = "tessera.terrain_add"
    bl_label = "Terrain from Height Map"
    bl_options = {"REGISTER", "UNDO"}

    # the options: TerrainOptions (addon/terrain/settings.py), shared with Object.tessera.terrain
    filter_glob: bpy.props.StringProperty(default="*.png;*.tif;*.tiff;*.exr;*.r16;*.r32;*.raw;*.hgt;*.asc;*.img;"
                                                  "*.vrt;*.dem;*.bil;*.flt;*.dt0;*.dt1;*.dt2", options={"HIDDEN"},
                                          description="Files listed")
    # several files picked at once (the adjacent tiles of one elevation model) become one terrain
    files: bpy.props.CollectionProperty(type=bpy.types.OperatorFileListElement, options={"HIDDEN", "SKIP_SAVE"})
    directory: bpy.props.StringProperty(subtype="DIR_PATH", options={"HIDDEN", "SKIP_SAVE"})
    block: _block_property()
    void_index: _void_index_property()

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to add a terrain")
            return False
        return True

    def invoke(self, context, event):
        if self.source == "FILE" and not self.filepath:
            context.window_manager.fileselect_add(self)
            return {"RUNNING_MODAL"}
        return self.execute(context)

    def draw(self, context):
        draw_terrain_settings(self.layout, self)

    @guarded
    def execute(self, context, tx):
        names = [f.name for f in self.files if f.name]
        if len(names) > 1 and self.directory:  # picked together: the first is the height map, the rest its tiles
            self.filepath = os.path.join(self.directory, names[0])
            self.tile_files = ";".join(names[1:])
        mesh = tx.new_mesh("Terrain")
        ob = tx.new_object("Terrain", mesh)
        tx.on_rollback(lambda: terrain_data.forget(ob))
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            copy_options(TerrainOptions, self, ob.tessera.terrain)
            ob.tessera.terrain.is_terrain = True
            ob.location = context.scene.cursor.location
            context.collection.objects.link(ob)
            _bake_into(context, ob, _camera_or_none(context, self.camera_source), self.report, tx, self.block,
                       bpy.path.abspath(self.void_index) if self.void_index else "")
            geo = terrain_data.georeference(ob)
            if geo is not None:
                _place(context, ob, geo, self.report)
        finally:
            wm.progress_end()
        select_only(context, [ob])
        return {"FINISHED"}


class TESSERA_OT_terrain_bake(bpy.types.Operator):
    """Re-mesh the active terrain for its camera (the scene camera or the viewport), for render and export"""

    bl_idname = "tessera.terrain_bake"
    bl_label = "Bake Terrain for Camera"
    bl_options = {"REGISTER", "UNDO"}

    block: _block_property()
    void_index: _void_index_property()

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        if ob is None or ob.type != "MESH" or not ob.tessera.terrain.is_terrain:
            cls.poll_message_set("Select a terrain object (Add > Tessera > Terrain from Height Map)")
            return False
        return True

    @guarded
    @each_selected(lambda ob: ob.type == "MESH" and ob.tessera.terrain.is_terrain)
    def execute(self, context, tx):
        ob = context.active_object
        check_numbers(ob.tessera.terrain)  # the settings the bake reads, as an operator's own are checked
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            camera = camera_for(context, ob.tessera.terrain.camera_source, "Baking a terrain for a camera")
            _bake_into(context, ob, camera, self.report, tx, self.block,
                       bpy.path.abspath(self.void_index) if self.void_index else "")
        finally:
            wm.progress_end()
        return {"FINISHED"}


classes = (TESSERA_OT_terrain_add, TESSERA_OT_terrain_bake)
register, unregister = bpy.utils.register_classes_factory(classes)

"""The only module where mesh data crosses between Blender and numpy.

Reading uses Blender's loop triangles (quads and n-gons are triangulated the way Blender draws them)
and typed ``foreach_get``; writing allocates a new mesh's elements once and fills its arrays with
`mesh_memory.write_items` (a bulk copy where the layout allows, else typed ``foreach_set``; ``from_pydata`` is
many times slower: ``bench/bridge.py``). Arrays are float32 / int32, contiguous.
"""

from contextlib import contextmanager
from dataclasses import dataclass, field

import bpy
import numpy as np

from ..kernels.common.errors import EmptyResultError, InvalidInputError
from ..kernels.common.mesh_arrays import MeshArrays
from ..kernels.common.tolerances import FLAT_FACE_NORMAL_ATOL
from ..kernels.displacement.tangent_space import triangle_tangents
from ..kernels.tubes.builder import MeshSizes, allocate_arrays
from . import compat
from .mesh_memory import face_offsets_match, face_offsets_view, item_view, sample_matches, set_face_offsets, write_items

# Blender attribute data types whose values are floats we can interpolate, with the element field and
# the number of channels.
_FLOAT_TYPES = {
    "FLOAT": ("value", 1),
    "FLOAT2": ("vector", 2),
    "FLOAT_VECTOR": ("vector", 3),
    "FLOAT_COLOR": ("color", 4),
    "BYTE_COLOR": ("color", 4),
}
# Types copied per face (never interpolated): element field, channels, numpy dtype.
_FACE_TYPES = {
    **{k: (f, c, np.float32) for k, (f, c) in _FLOAT_TYPES.items()},
    "INT": ("value", 1, np.int32),
    "BOOLEAN": ("value", 1, bool),
    "INT8": ("value", 1, np.int32),
}
# Handled separately: custom normals (5.0: a "custom_normal" attribute) and sharp edges are carried by
# the corner normals written as custom normals.
_SKIP = {"position", "custom_normal", "sharp_edge"}


@dataclass
class MeshInfo:
    """What `read_mesh` saw that the writer needs, and what it could not carry over."""

    active_color: str | None = None
    default_color: str | None = None
    active_uv: str | None = None
    render_uv: str | None = None
    skipped: list = field(default_factory=list)  # "name (DOMAIN TYPE)" of attributes not carried


def _get(collection, prop, count, dtype, width=1):
    out = np.empty(count * width, dtype=dtype)
    collection.foreach_get(prop, out)
    return out.reshape(count, width) if width > 1 else out


def read_mesh(mesh):
    """Read a `bpy.types.Mesh` into `MeshArrays` (triangulated) and a `MeshInfo`.

    Corner and face attributes are returned per loop triangle: corner attributes (T, 3, C), face
    attributes (T, C) from each triangle's polygon. Raises `InvalidInputError` for a mesh without faces.
    """
    mesh.calc_loop_triangles()
    n_tris = len(mesh.loop_triangles)
    if n_tris == 0:
        raise InvalidInputError(f"Mesh {mesh.name!r} has no faces to work on")
    n_verts = len(mesh.vertices)
    tri_verts = _get(mesh.loop_triangles, "vertices", n_tris, np.int32, 3)
    tri_loops = _get(mesh.loop_triangles, "loops", n_tris, np.int32, 3)
    tri_polys = _get(mesh.loop_triangles, "polygon_index", n_tris, np.int32)
    positions = _get(mesh.attributes["position"].data, "vector", n_verts, np.float32, 3)
    normals = _get(mesh.corner_normals, "vector", len(mesh.loops), np.float32, 3)[tri_loops]

    info = MeshInfo(
        active_color=getattr(mesh.color_attributes.active_color, "name", None),
        default_color=mesh.color_attributes.default_color_name or None,
        active_uv=getattr(mesh.uv_layers.active, "name", None),
        render_uv=next((uv.name for uv in mesh.uv_layers if uv.active_render), None),
    )
    arrays = MeshArrays(positions=positions, triangles=tri_verts, corner_normals=normals)
    for attr in mesh.attributes:
        name, domain, dtype = attr.name, attr.domain, attr.data_type
        if name.startswith(".") or name in _SKIP:
            continue
        if domain == "FACE" and dtype in _FACE_TYPES:
            prop, width, np_type = _FACE_TYPES[dtype]
            values = _get(attr.data, prop, len(mesh.polygons), np_type, width)
            arrays.face_attributes[name] = values[tri_polys]
        elif domain in ("POINT", "CORNER") and dtype in _FLOAT_TYPES:
            prop, width = _FLOAT_TYPES[dtype]
            count = n_verts if domain == "POINT" else len(mesh.loops)
            values = _get(attr.data, prop, count, np.float32, width)
            if domain == "POINT":
                arrays.point_attributes[name] = values
            else:
                arrays.corner_attributes[name] = values[tri_loops]
        else:
            info.skipped.append(f"{name} ({domain} {dtype})")
            continue
        arrays.attribute_types[name] = dtype
    return arrays, info


@dataclass
class EdgeMarks:
    """What a subdivision keeps sharp, as Blender marks it.

    pairs: (K, 2) int32 vertex ids of the marked edges; crease: (K,) float32 in 0..1 (an edge marked sharp
    counts as crease 1); sharp: (K,) bool marked sharp; vertex_crease: (V,) float32 or None; n_gons: faces with
    more than three corners (they are triangulated when read); loose_edges: edges in no face.
    """

    pairs: np.ndarray
    crease: np.ndarray
    sharp: np.ndarray
    vertex_crease: np.ndarray | None
    n_gons: int
    loose_edges: int


def read_edge_marks(mesh):
    """`EdgeMarks` of a `bpy.types.Mesh`: the ``crease_edge`` and ``sharp_edge`` edge attributes, the
    ``crease_vert`` point attribute, the count of n-gons and of loose edges."""
    n_e, n_p = len(mesh.edges), len(mesh.polygons)
    crease = np.zeros(n_e, np.float32)
    sharp = np.zeros(n_e, bool)
    attr = mesh.attributes.get("crease_edge")
    if attr is not None and attr.domain == "EDGE" and attr.data_type == "FLOAT":
        crease = _get(attr.data, "value", n_e, np.float32)
    attr = mesh.attributes.get("sharp_edge")
    if attr is not None and attr.domain == "EDGE" and attr.data_type == "BOOLEAN":
        sharp = _get(attr.data, "value", n_e, bool)
    marked = np.flatnonzero(sharp | (crease > 0))
    pairs = _get(mesh.attributes[".edge_verts"].data, "value", n_e, np.int32, 2)[marked] if n_e else np.zeros((0, 2))
    vertex_crease = None
    attr = mesh.attributes.get("crease_vert")
    if attr is not None and attr.domain == "POINT" and attr.data_type == "FLOAT":
        vertex_crease = _get(attr.data, "value", len(mesh.vertices), np.float32)
    sizes = _get(mesh.polygons, "loop_total", n_p, np.int32)
    corner_edge = _get(mesh.attributes[".corner_edge"].data, "value", len(mesh.loops), np.int32)
    loose = n_e - int(np.count_nonzero(np.bincount(corner_edge, minlength=n_e)))
    crease = np.where(sharp, np.float32(1.0), crease)
    return EdgeMarks(pairs.astype(np.int32), crease[marked], sharp[marked], vertex_crease,
                     int(np.count_nonzero(sizes > 3)), loose)


def write_point_colours(mesh, name, colours):
    """A point colour attribute (FLOAT_COLOR) of ``mesh`` from colours (V, 4), made the active and default one."""
    attr = _new_attribute(mesh, name, "FLOAT_COLOR", "POINT")
    attr.data.foreach_set("color", np.ascontiguousarray(colours, np.float32).ravel())
    mesh.color_attributes.active_color = mesh.color_attributes[name]
    mesh.color_attributes.default_color_name = name


def write_edge_attribute(mesh, name, values):
    """An edge attribute of ``mesh``: values (E,) bool (BOOLEAN) or float (FLOAT), replacing one of that name."""
    values = np.ascontiguousarray(values)
    if values.dtype == bool:
        _new_attribute(mesh, name, "BOOLEAN", "EDGE").data.foreach_set("value", values)
    else:
        _new_attribute(mesh, name, "FLOAT", "EDGE").data.foreach_set("value", values.astype(np.float32))


def corner_tangents(mesh, uv_map):
    """MikkTSpace tangents of UV map ``uv_map`` per loop-triangle corner, as `read_mesh` orders corners:
    (T, 3, 4) float32, the unit tangent (xyz) and bitangent sign (w). Meshes with n-gons, which
    `Mesh.calc_tangents` refuses, get per-triangle tangents from the UVs (`kernels.displacement.tangent_space`)."""
    mesh.calc_loop_triangles()
    n_tris = len(mesh.loop_triangles)
    tri_loops = _get(mesh.loop_triangles, "loops", n_tris, np.int32, 3)
    try:
        mesh.calc_tangents(uvmap=uv_map)
    except RuntimeError:
        positions = _get(mesh.attributes["position"].data, "vector", len(mesh.vertices), np.float32, 3)
        tri_verts = _get(mesh.loop_triangles, "vertices", n_tris, np.int32, 3)
        uv = _get(mesh.uv_layers[uv_map].data, "uv", len(mesh.loops), np.float32, 2)
        return triangle_tangents(positions[tri_verts], uv[tri_loops])
    out = np.empty((len(mesh.loops), 4), np.float32)
    out[:, :3] = _get(mesh.loops, "tangent", len(mesh.loops), np.float32, 3)
    out[:, 3] = _get(mesh.loops, "bitangent_sign", len(mesh.loops), np.float32)
    mesh.free_tangents()
    return out[tri_loops]


def _new_attribute(mesh, name, dtype, domain):
    attr = mesh.attributes.get(name)
    if attr is None or attr.domain != domain or attr.data_type != dtype:
        if attr is not None:
            mesh.attributes.remove(attr)
        attr = mesh.attributes.new(name, dtype, domain)
    return attr


def _set_custom_normals(mesh, normals, domain="CORNER"):
    """Corner (L, 3) or point (V, 3) float32 normals as custom normals, with the fastest API this Blender has."""
    normals = np.ascontiguousarray(normals, dtype=np.float32)
    if compat.FLOAT_CUSTOM_NORMALS:
        write_items(_new_attribute(mesh, "custom_normal", "FLOAT_VECTOR", domain).data, "vector", normals)
    else:
        compat.set_split_custom_normals(mesh, normals, domain)


def _add_geometry(mesh, positions, corner_verts, loop_starts):
    """Allocate and fill vertices (V, 3) float32, corners (L,) int32 and faces (F,) int32 loop starts. An empty mesh
    (V = 0: a block of a terrain the camera does not see) stays empty: Blender has no position attribute then."""
    if len(positions) == 0:
        return
    mesh.vertices.add(len(positions))
    mesh.loops.add(len(corner_verts))
    mesh.polygons.add(len(loop_starts))
    write_items(mesh.attributes["position"].data, "vector", positions)
    write_items(mesh.attributes[".corner_vert"].data, "value", corner_verts)
    set_face_offsets(mesh, loop_starts)


@contextmanager
def _new_mesh(name):
    """A new `bpy.types.Mesh`, removed again if the block raises (nothing half-built is left behind)."""
    mesh = bpy.data.meshes.new(name)
    try:
        yield mesh
    except Exception:
        bpy.data.meshes.remove(mesh)
        raise


def _set_edges(mesh, edges):
    """Edges from ``(edges (K, 2), corner_edges (L,) or (T, 3))`` int32, written as they are; or, for None,
    computed by Blender from the faces."""
    if edges is None:
        mesh.update(calc_edges=True)
        return
    edges, corner_edges = edges
    mesh.edges.add(len(edges))
    write_items(mesh.attributes[".edge_verts"].data, "value", np.ascontiguousarray(edges, np.int32))
    write_items(mesh.attributes[".corner_edge"].data, "value", np.ascontiguousarray(corner_edges, np.int32).ravel())


def write_mesh(name, arrays, info=None, edges=None):
    """Create a new `bpy.types.Mesh` from triangle `MeshArrays` and return it.

    Writes positions, triangles, point / corner / face attributes with the data types recorded in
    ``arrays.attribute_types``, and corner (or else point) normals as custom normals. edges: ``(edges (K, 2),
    corner_edges (T, 3))`` int32 when known (`Refinement.output_edges`): written as they are, so Blender does
    not compute them; else None. If anything fails the half-built mesh is removed before the error propagates.
    """
    positions = np.ascontiguousarray(arrays.positions, dtype=np.float32)
    tris = np.ascontiguousarray(arrays.triangles, dtype=np.int32)
    n_tris = len(tris)
    with _new_mesh(name) as mesh:
        _add_geometry(mesh, positions, tris.ravel(), np.arange(0, 3 * n_tris, 3, dtype=np.int32))
        _set_edges(mesh, edges)

        domains = (
            ("POINT", arrays.point_attributes),
            ("CORNER", arrays.corner_attributes),
            ("FACE", arrays.face_attributes),
        )
        for domain, attrs in domains:
            for attr_name, values in attrs.items():
                dtype = arrays.attribute_types.get(attr_name, "FLOAT")
                prop, _, np_type = _FACE_TYPES[dtype]
                attr = _new_attribute(mesh, attr_name, dtype, domain)
                write_items(attr.data, prop, np.ascontiguousarray(values, dtype=np_type))
        if arrays.corner_normals is not None:
            _set_custom_normals(mesh, arrays.corner_normals.reshape(-1, 3))
        elif arrays.point_normals is not None:
            _set_custom_normals(mesh, arrays.point_normals, "POINT")
        if info is not None:
            _restore_active(mesh, info)
        mesh.update()
    return mesh


def append_loose_edges(mesh, points, edges):
    """Add vertices points (N, 3) and loose edges (K, 2) between them (indices from 0) to ``mesh``."""
    co = _get(mesh.vertices, "co", len(mesh.vertices), np.float32, 3)
    verts = _get(mesh.edges, "vertices", len(mesh.edges), np.int32, 2)
    base = len(co)
    mesh.vertices.add(len(points))
    mesh.edges.add(len(edges))
    mesh.vertices.foreach_set("co", np.concatenate([co, np.asarray(points, np.float32)]).ravel())
    mesh.edges.foreach_set("vertices", np.concatenate([verts, np.asarray(edges, np.int32) + base]).ravel())
    mesh.update()


def _restore_active(mesh, info):
    colors = mesh.color_attributes
    if info.active_color and info.active_color in colors:
        colors.active_color = colors[info.active_color]
    if info.default_color and info.default_color in colors:
        colors.default_color_name = info.default_color
    if info.active_uv and info.active_uv in mesh.uv_layers:
        mesh.uv_layers.active = mesh.uv_layers[info.active_uv]
    if info.render_uv and info.render_uv in mesh.uv_layers:
        mesh.uv_layers[info.render_uv].active_render = True


# ---- polygon meshes (tubes), wire meshes, point attributes (curves: curve_bridge) --------------------------


# The `PolygonMesh` arrays a new mesh keeps as one array each: field -> (attribute, item property, dtype, width).
_POLYGON_ARRAYS = {
    "positions": ("position", "vector", np.float32, 3),
    "corner_verts": (".corner_vert", "value", np.int32, 1),
    "edges": (".edge_verts", "value", np.int32, 2),
    "corner_edges": (".corner_edge", "value", np.int32, 1),
    "corner_uvs": ("UVMap", "vector", np.float32, 2),
    "face_material": ("material_index", "value", np.int32, 1),
}


class PolygonWriter:
    """A new `bpy.types.Mesh` made from a `kernels.tubes.builder.PolygonMesh`.

    `allocate` is an allocator for `build_tubes`: it adds the new mesh's elements and hands the kernel the mesh's own
    arrays (positions, face offsets, corners, edges, UVs, materials) wherever each is one array in memory
    (`mesh_memory.item_view`), so the output is written once, straight into Blender's memory, instead of built and
    then copied. `finish` writes the rest (sharp faces, any array not handed out), reads a sample of what was written
    in place back through RNA, and returns the mesh. ``track(mesh)`` is called with the new mesh as soon as it exists
    (a `guarded.Transaction` removes it if anything fails later); `write_polygons` is the one-shot form.
    """

    def __init__(self, name, track=None):
        self.name = name
        self.mesh = None
        self._track = track or (lambda block: block)
        self._in_place = []

    def allocate(self, sizes, settings):
        """``builder.allocate_arrays(sizes, settings)`` with the new mesh's arrays in place of new ones."""
        poly = allocate_arrays(sizes, settings)
        data = self._new_mesh(sizes, settings.uvs)
        for name, (_, _, dtype, width) in _POLYGON_ARRAYS.items():
            wanted = getattr(poly, name)
            view = item_view(data[name], dtype, width) if wanted is not None and data[name] is not None else None
            if view is not None:
                setattr(poly, name, view.reshape(wanted.shape))
                self._in_place.append(name)
        offsets = face_offsets_view(self.mesh)
        if offsets is not None:
            poly.face_offsets = offsets
            self._in_place.append("face_offsets")
        return poly

    def finish(self, poly):
        """Write what ``poly`` holds outside the mesh and return the mesh. The arrays that were the mesh's own memory
        are set to None in ``poly`` (they belong to Blender from here on)."""
        if self.mesh is None:
            self._new_mesh(polygon_sizes(poly), poly.corner_uvs is not None)
        mesh = self.mesh
        data = self._data()
        sharp = None if poly.corner_normals is None else _sharp_faces(poly)
        for name, (_, prop, dtype, _) in _POLYGON_ARRAYS.items():
            values = getattr(poly, name)
            if values is None or data[name] is None:
                continue
            if name not in self._in_place:
                write_items(data[name], prop, np.ascontiguousarray(values, dtype))
            elif not sample_matches(data[name], prop, values.reshape(len(data[name]), -1)):
                data[name].foreach_set(prop, np.array(values).ravel())  # never seen: the slow way
        if "face_offsets" not in self._in_place or not face_offsets_match(mesh, poly.face_offsets):
            set_face_offsets(mesh, np.array(poly.face_offsets[:-1]))
        if poly.edges is None:
            mesh.update(calc_edges=True)
        if sharp is not None:
            write_items(_new_attribute(mesh, "sharp_face", "BOOLEAN", "FACE").data, "value", sharp)
        for name in self._in_place:
            setattr(poly, name, None)
        self._in_place.clear()
        mesh.update()
        return mesh

    def _new_mesh(self, sizes, uvs):
        if sizes.faces == 0 or sizes.vertices == 0:
            raise EmptyResultError(f"Nothing to write for {self.name!r}: the result has no faces")
        mesh = self.mesh = self._track(bpy.data.meshes.new(self.name))
        mesh.vertices.add(sizes.vertices)
        mesh.loops.add(sizes.corners)
        mesh.polygons.add(sizes.faces)
        mesh.edges.add(sizes.edges)
        if uvs:
            _new_attribute(mesh, "UVMap", "FLOAT2", "CORNER")
        if sizes.materials:
            _new_attribute(mesh, "material_index", "INT", "FACE")
        return self._data()

    def _data(self):
        """The item collections of the arrays in `_POLYGON_ARRAYS` (None for those the mesh lacks)."""
        attrs = self.mesh.attributes
        return {name: (attrs[attr].data if attr in attrs else None)
                for name, (attr, _, _, _) in _POLYGON_ARRAYS.items()}


def _sharp_faces(poly):
    """(F,) bool: the faces whose corner normals all equal their first (flat, so Blender's sharp-face shading is
    theirs)."""
    offsets = np.asarray(poly.face_offsets)
    starts, sizes = offsets[:-1], np.diff(offsets)
    corner_face = np.repeat(np.arange(len(starts)), sizes)
    first = poly.corner_normals[starts]
    flat = np.all(np.abs(poly.corner_normals - first[corner_face]) < FLAT_FACE_NORMAL_ATOL, axis=1)
    return np.logical_and.reduceat(flat, starts)


def polygon_sizes(poly):
    """The `MeshSizes` of a `PolygonMesh` (no edges when it has none: Blender computes them; materials when any face
    has one other than 0)."""
    materials = poly.face_material is not None and bool(np.any(poly.face_material))
    return MeshSizes(vertices=len(poly.positions), faces=len(poly.face_offsets) - 1, corners=len(poly.corner_verts),
                     edges=0 if poly.edges is None else len(poly.edges), materials=materials)


def write_polygons(name, poly):
    """Create a `bpy.types.Mesh` from a `kernels.tubes.builder.PolygonMesh` and return it.

    Writes edges and corner edges directly when the kernel knows them (no edge computation). Faces are
    smooth except where corner normals differ from the point normal field (FLAT caps: those faces are
    marked sharp, so Blender's own normals keep the rim crisp). UVs go to the map "UVMap", materials to
    ``material_index``. Removes the half-built mesh if anything fails. Raises `EmptyResultError` for a mesh
    without faces (Blender's geometry writer needs at least one point). The tube operator writes through a
    `PolygonWriter` instead, whose allocator lets the kernel write into the mesh directly.
    """
    writer = PolygonWriter(name)
    try:
        return writer.finish(poly)
    except Exception:
        if writer.mesh is not None:
            bpy.data.meshes.remove(writer.mesh)
        raise


def point_float_attribute(data, name, count):
    """A float POINT attribute of a mesh or curves data-block as (count,) float64, or a clear error."""
    attr = data.attributes.get(name)
    if attr is None or attr.domain != "POINT" or attr.data_type != "FLOAT":
        raise InvalidInputError(f"{data.name!r} has no float point attribute named {name!r}")
    return _get(attr.data, "value", count, np.float32).astype(np.float64)


def point_vector_attribute(data, name, count):
    """A 3-component float POINT attribute (FLOAT_VECTOR) of a mesh as (count, 3) float64, or a clear error."""
    attr = data.attributes.get(name)
    if attr is None or attr.domain != "POINT" or attr.data_type != "FLOAT_VECTOR":
        raise InvalidInputError(f"{data.name!r} has no vector point attribute named {name!r}")
    return _get(attr.data, "vector", count, np.float32, 3).astype(np.float64)


def read_wire_mesh(mesh):
    """Vertex positions (V, 3) float32 and edges (E, 2) int32 of a mesh (its wire, faces ignored)."""
    n_v = len(mesh.vertices)
    if n_v == 0:  # an empty mesh has no position attribute at all
        return np.zeros((0, 3), np.float32), np.zeros((0, 2), np.int32)
    positions = _get(mesh.attributes["position"].data, "vector", n_v, np.float32, 3)
    edges = _get(mesh.edges, "vertices", len(mesh.edges), np.int32, 2)
    return positions, edges


def read_image_pixels(image, channels=None):
    """An image's pixels as (H, W, C) float32, row 0 at the bottom (Blender's order); C = ``channels`` or the
    image's own channel count. One ``foreach_get``."""
    w, h = image.size
    c = channels or image.channels
    pixels = np.empty(w * h * c, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(h, w, c)


def set_bytes_property(block, name, value):
    """Store ``value`` (bytes; None: remove) as the custom property ``name`` of ``block``. The property is removed
    first: Blender copies new bytes into an existing bytes property only up to their first zero byte."""
    block.pop(name, None)
    if value is not None:
        block[name] = value


def pack_float_image(image):
    """Pack a float image into the .blend as OpenEXR with its channels kept apart (alpha mode Channel Packed: no
    premultiplication on the way in or out), so its values come back bit for bit after save and reload, colours
    under a zero alpha included. Set its pixels first (`write_image_pixels`)."""
    image.alpha_mode = "CHANNEL_PACKED"
    image.file_format = "OPEN_EXR"
    image.pack()


def write_image_pixels(image, pixels):
    """Replace every pixel of ``image`` with ``pixels`` ((H, W, C) float32 as `read_image_pixels` gives) and
    tell Blender the image changed. One ``foreach_set``."""
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.update()

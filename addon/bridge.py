"""The only module where mesh data crosses between Blender and numpy.

Reading uses Blender's loop triangles (quads and n-gons are triangulated the way Blender draws them)
and typed ``foreach_get``; writing allocates elements once and fills attributes with typed
``foreach_set`` (``from_pydata`` is about 10x slower). Arrays are float32 / int32, contiguous.
"""

from dataclasses import dataclass, field

import bpy
import numpy as np

from ..kernels.errors import InvalidInputError
from ..kernels.mesh_arrays import MeshArrays

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
        raise InvalidInputError(f"Mesh {mesh.name!r} has no faces to tessellate")
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
    if bpy.app.version >= (5, 0, 0):
        attr = _new_attribute(mesh, "custom_normal", "FLOAT_VECTOR", domain)
        attr.data.foreach_set("vector", normals.ravel())
    elif domain == "POINT":
        mesh.normals_split_custom_set_from_vertices(normals)
    else:
        mesh.normals_split_custom_set(normals)


def write_mesh(name, arrays, info=None):
    """Create a new `bpy.types.Mesh` from triangle `MeshArrays` and return it.

    Writes positions, triangles, point / corner / face attributes with the data types recorded in
    ``arrays.attribute_types``, and corner (or else point) normals as custom normals. If anything fails the
    half-built mesh is removed before the error propagates.
    """
    positions = np.ascontiguousarray(arrays.positions, dtype=np.float32)
    tris = np.ascontiguousarray(arrays.triangles, dtype=np.int32)
    n_tris = len(tris)
    mesh = bpy.data.meshes.new(name)
    try:
        mesh.vertices.add(len(positions))
        mesh.loops.add(3 * n_tris)
        mesh.polygons.add(n_tris)
        mesh.attributes["position"].data.foreach_set("vector", positions.ravel())
        mesh.attributes[".corner_vert"].data.foreach_set("value", tris.ravel())
        mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * n_tris, 3, dtype=np.int32))
        mesh.update(calc_edges=True)

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
                attr.data.foreach_set(prop, np.ascontiguousarray(values, dtype=np_type).ravel())
        if arrays.corner_normals is not None:
            _set_custom_normals(mesh, arrays.corner_normals.reshape(-1, 3))
        elif arrays.point_normals is not None:
            _set_custom_normals(mesh, arrays.point_normals, "POINT")
        if info is not None:
            _restore_active(mesh, info)
        mesh.update()
    except Exception:
        bpy.data.meshes.remove(mesh)
        raise
    return mesh


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

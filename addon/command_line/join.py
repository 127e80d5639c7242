"""``blender -c tessera join``: the meshes of several files as one object, vertices that coincide exactly welded (the
blocks of a terrain meshed by separate farm tasks give the mesh one process makes)."""

import os

import bpy
import numpy as np

from ...kernels.common.mesh_arrays import MeshArrays
from ...kernels.common.weld import weld_triangles
from .. import bridge
from . import files


def _read_blend(path):
    """Link the mesh objects of the .blend ``path`` into the current scene: the objects."""
    with bpy.data.libraries.load(path, link=False) as (src, dst):
        dst.objects = list(src.objects)
    obs = [ob for ob in dst.objects if ob is not None and ob.type == "MESH"]
    for ob in obs:
        bpy.context.scene.collection.objects.link(ob)
    return obs


def read_meshes(paths):
    """Mesh objects from ``paths`` (.blend files: every mesh object; others: what their importer makes), into an empty
    scene: list of objects."""
    bpy.ops.wm.read_homefile(use_empty=True)
    found = []
    for path in paths:
        path = os.path.abspath(path)
        files.check_input(path, {".blend", *files.IMPORTERS})
        if files.extension(path) == ".blend":
            found += _read_blend(path)
        else:
            found += [ob for ob in files.read_inputs_into_scene([path]) if ob.type == "MESH"]
    return found


def join(objects, name):
    """One new mesh object ``name`` from ``objects`` (world space), welded exactly; UV maps and other attributes that
    every object has are kept, custom normals when any object has them. Objects without faces (a terrain block the
    camera did not see) add nothing. Returns the object."""
    objects = [ob for ob in objects if len(ob.data.polygons)] or objects[:1]
    parts = []
    for ob in objects:
        arrays, _ = bridge.read_mesh(ob.data)
        m = np.array(ob.matrix_world, np.float64)
        world = (arrays.positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
        normals = arrays.corner_normals if ob.data.has_custom_normals else None
        if normals is not None:
            normals = (normals.astype(np.float64) @ np.linalg.inv(m[:3, :3])).astype(np.float32)  # (M^-T n)^T
        parts.append((arrays, world, normals))
    corner_names = set.intersection(*(set(a.corner_attributes) for a, _, _ in parts))
    point_names = set.intersection(*(set(a.point_attributes) for a, _, _ in parts))
    offsets = np.cumsum([0] + [len(w) for _, w, _ in parts])
    positions = np.concatenate([w for _, w, _ in parts])
    triangles = np.concatenate([a.triangles.astype(np.int64) + o
                                for (a, _, _), o in zip(parts, offsets[:-1], strict=True)])
    welded, tris, keep, kept = weld_triangles(positions, triangles)
    out = MeshArrays(positions=welded, triangles=tris)
    for n in sorted(corner_names):
        out.corner_attributes[n] = np.concatenate([a.corner_attributes[n] for a, _, _ in parts])[kept]
        out.attribute_types[n] = parts[0][0].attribute_types[n]
    for n in sorted(point_names):
        out.point_attributes[n] = np.concatenate([a.point_attributes[n] for a, _, _ in parts])[keep]
        out.attribute_types[n] = parts[0][0].attribute_types[n]
    if any(nm is not None for _, _, nm in parts):
        out.corner_normals = np.concatenate([nm if nm is not None else a.corner_normals
                                             for a, _, nm in parts])[kept]
    mesh = bridge.write_mesh(name, out)
    for material in objects[0].data.materials:
        mesh.materials.append(material)
    ob = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    return ob

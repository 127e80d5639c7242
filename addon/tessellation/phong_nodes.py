"""The geometry-nodes group "Tessera Phong": Phong tessellation (Boubekeur & Alexa 2008, [Nellmedin 2014]) in the
modifier stack, with no add-on needed to evaluate it. Numpy reference: `kernels.tessellation.patches.phong_control`.

Subdivide Mesh splits every triangle (linearly: UVs and attributes are interpolated as the kernel does). Each
new point p lies on a coarse triangle with barycentric coordinates b, and Phong's point is
``p* = sum_i b_i (p - ((p - P_i).n_i) n_i) = p - (sum_i b_i n_i n_i^T) p + sum_i b_i (P_i.n_i) n_i``. Both sums
are linear in b: the coarse points carry n n^T (6 numbers) and (P.n) n as attributes, which Subdivide Mesh
(bilinear) interpolates with the same weights as the positions, so every new point holds the sums of the coarse
triangle it lies on (no search, so self-intersecting meshes are fine). The result is
``p + a (p* - p)`` with the shape factor a (a field: per-vertex a works). The normals follow the kernel's sharp-edge
policy (Watertight or Split, `surface_nodes`); the shading normals are the corner normals interpolated linearly and
normalised, as the kernel shades Phong.
"""

from ..node_groups import Graph, GroupSpec, register_group
from .surface_nodes import CORNER_NORMAL, set_shading, surface_interface

GROUP_NAME = "Tessera Phong"
VERSION = 6


def _build(tree):
    g = Graph(tree)
    gi, go, coarse, normal = surface_interface(g, 0.75, "0: flat triangles; 1: fully rounded (0.75 by default); "
                                                        "a field, so it can vary per vertex")
    position = g.node("GeometryNodeInputPosition").outputs[0]
    n = g.split(normal)
    diag = g.vec("MULTIPLY", normal, normal)  # (nx nx, ny ny, nz nz)
    off = g.xyz(g.math("MULTIPLY", n[0], n[1]), g.math("MULTIPLY", n[1], n[2]), g.math("MULTIPLY", n[2], n[0]))
    plane = g.vec("SCALE", normal, g.vec("DOT_PRODUCT", position, normal, out=1))  # (P.n) n

    names = ("tessera_phong_diag", "tessera_phong_off", "tessera_phong_plane")
    geometry = coarse
    for name, field in zip(names, (diag, off, plane), strict=True):
        geometry = g.node("GeometryNodeStoreNamedAttribute", [(0, geometry), ("Name", name), ("Value", field)],
                          data_type="FLOAT_VECTOR", domain="POINT").outputs[0]
    fine = g.node("GeometryNodeSubdivideMesh", [(0, geometry), (1, gi.outputs["Subdivisions"])]).outputs[0]

    def carried(name):  # the point values, interpolated by the subdivision with the same weights as positions
        return g.node("GeometryNodeInputNamedAttribute", [(0, name)], data_type="FLOAT_VECTOR").outputs[0]

    d, o, c = (carried(name) for name in names)
    p = g.split(position)
    oo = g.split(o)
    a = g.vec("MULTIPLY", o, g.xyz(p[1], p[2], p[0]))  # (ox py, oy pz, oz px)
    b = g.vec("MULTIPLY", g.xyz(oo[2], oo[0], oo[1]), g.xyz(p[2], p[0], p[1]))  # (oz pz, ox px, oy py)
    np_ = g.vec("ADD", g.vec("MULTIPLY", d, position), g.vec("ADD", a, b))  # (sum b_i n_i n_i^T) p
    offset = g.vec("SCALE", g.vec("SUBTRACT", c, np_), gi.outputs["Shape Factor"])
    moved = g.node("GeometryNodeSetPosition", [(0, fine), ("Offset", offset)]).outputs[0]
    # shading: the kernel's Phong normals, the corner normals interpolated linearly (as Subdivide Mesh carries them)
    shaded = set_shading(g, moved, g.vec("NORMALIZE", g.named(CORNER_NORMAL, "FLOAT_VECTOR")))
    tree.links.new(g.remove(shaded, (*names, CORNER_NORMAL)), go.inputs[0])


SPEC = register_group(GroupSpec(GROUP_NAME, VERSION, _build, catalog="Tessera/Tessellation",
                                description="Smooth a mesh with Phong tessellation: finer faces that bulge toward "
                                            "the vertex normals"))

"""What the curved-surface groups ("Tessera Phong", "Tessera PN Triangles") share: their sockets and the sharp-edge
policy of `kernels.tessellation.normals` as geometry nodes, so every point gets the one geometry normal the numpy
kernel uses.

The shading follows the kernel too (where geometry nodes can write custom normals, 4.5 and newer; on 4.2 Blender
computes the normals from the faces): each group evaluates its shading-normal field at every corner, from the
coarse face's own corner normals (equal to the shared vertex normals on faces with no sharp corner), and writes it
as the mesh's custom normals (`set_shading`).

The corner normals (Blender's: sharp edges, flat faces and custom normals included) are read before the mesh is
triangulated, as the operator reads them, and carried as a corner attribute. Then, as `kernels.tessellation.
tessellate.surface_inputs` does:

``Watertight``
    one normal per vertex, the corner-angle-weighted mean of its corner normals (`shared_vertex_normals`): shared
    edges stay shared, a closed mesh stays closed.
``Split``
    the mesh is split (Split Edges) along every edge whose two faces' corner normals differ at either end
    (`split_by_normals`, with the same `SAME_NORMAL_DOT`), so each split vertex has one corner normal and the
    surface follows it; the mesh opens along those edges.
"""

from ...kernels.common.tolerances import FLOAT32_TINY, SAME_NORMAL_DOT
from ..compat import NORMAL_NODE_CORNER_NORMALS, has_set_mesh_normal_node
from ..node_groups import socket

#: Corner attribute holding the input's corner normals while the group runs.
CORNER_NORMAL = "tessera_corner_normal"
SHARP_EDGE_MODES = ("Watertight", "Split")


def surface_interface(g, shape_default, shape_description):
    """The sockets the curved-surface groups share (Geometry, Subdivisions, Shape Factor, Sharp Edges -> Geometry).
    Subdivisions counts Subdivide Mesh passes (each splits every edge in two), not the Tessellate operator's Level
    (segments per edge), so the two keep different names.
    Returns ``(group input, group output, mesh, normal)``: the triangulated (and in Split mode split) mesh, and
    the field of each point's geometry normal on it."""
    tree = g.tree
    socket(tree, "Geometry", "NodeSocketGeometry", description="The mesh to tessellate (faces are triangulated)")
    socket(tree, "Subdivisions", "NodeSocketInt", default=2, min_value=0, max_value=6,
           description="Times every face is subdivided: each time splits every edge in two")
    socket(tree, "Shape Factor", "NodeSocketFloat", default=shape_default, min_value=0.0, max_value=1.0,
           subtype="FACTOR",
           description=shape_description)
    socket(tree, "Sharp Edges", "NodeSocketMenu",
           description="Watertight: one averaged normal per vertex, the mesh stays closed (shading stays sharp). "
                       "Split: the surface follows the split normals and opens along sharp edges")
    socket(tree, "Geometry", "NodeSocketGeometry", in_out="OUTPUT", description="The curved, finer mesh")
    gi, go = g.node("NodeGroupInput"), g.node("NodeGroupOutput")
    with_normals = g.store(gi.outputs["Geometry"], CORNER_NORMAL, _corner_normals(g, gi.outputs["Geometry"]),
                           "FLOAT_VECTOR", "CORNER")
    coarse = g.node("GeometryNodeTriangulate", [(0, with_normals)]).outputs[0]
    split = g.node("GeometryNodeSplitEdges", [(0, coarse), ("Selection", _normals_differ(g))]).outputs[0]
    mesh = g.menu("GEOMETRY", gi.outputs["Sharp Edges"], list(zip(SHARP_EDGE_MODES, (coarse, split), strict=True)))
    return gi, go, mesh, _vertex_normal(g)


def _corner_normals(g, mesh):
    """On corners of ``mesh``: Blender's corner normals. Where the Normal node gives them on the corner domain
    (`compat.NORMAL_NODE_CORNER_NORMALS`) that node; before, each corner's smooth fan is made explicit: the mesh
    is split along its sharp edges and the edges of its flat faces, where the point normal (angle-weighted face
    normals) is the fan's normal, and read back by corner index (Split Edges keeps the corners in order). Custom
    normals are out of reach there."""
    normal = g.input("GeometryNodeInputNormal")
    if NORMAL_NODE_CORNER_NORMALS:
        return normal
    edge = g.input("GeometryNodeInputIndex")
    flat = g.math("SUBTRACT", 1.0, g.input("GeometryNodeInputShadeSmooth"))
    sharp = g.math("SUBTRACT", 1.0, g.input("GeometryNodeInputEdgeSmooth"))
    for k in range(2):
        corner = g.node("GeometryNodeCornersOfEdge", [("Edge Index", edge), ("Sort Index", k)]).outputs[0]
        face = g.node("GeometryNodeFaceOfCorner", [(0, corner)]).outputs["Face Index"]
        sharp = g.math("MAXIMUM", sharp, g.at("FACE", "FLOAT", flat, face))
    fans = g.node("GeometryNodeSplitEdges", [(0, mesh), ("Selection", g.math("GREATER_THAN", sharp, 0.5))])
    fan_normal = g.on("POINT", "FLOAT_VECTOR", normal)  # 4.2 gives face normals on corners
    return g.node("GeometryNodeSampleIndex", [("Geometry", fans.outputs[0]), ("Value", fan_normal),
                                              ("Index", g.input("GeometryNodeInputIndex"))],
                  data_type="FLOAT_VECTOR", domain="CORNER").outputs[0]


def _corner_normal_at(g, corner):
    return g.at("CORNER", "FLOAT_VECTOR", g.named(CORNER_NORMAL, "FLOAT_VECTOR"), corner)


def _normals_differ(g):
    """On edges: True where the edge's first two faces have different corner normals at either of its ends."""
    edge = g.input("GeometryNodeInputIndex")
    corners = [g.node("GeometryNodeCornersOfEdge", [("Edge Index", edge), ("Sort Index", k)]) for k in range(2)]
    c0, c1 = (c.outputs["Corner Index"] for c in corners)

    def vertex(corner):
        return g.node("GeometryNodeVertexOfCorner", [(0, corner)]).outputs[0]

    def following(corner):
        return g.node("GeometryNodeOffsetCornerInFace", [("Corner Index", corner), ("Offset", 1)]).outputs[0]

    # c0 sits at one end a, following(c0) at the other end b; in the second face the corner at a is c1 or the one
    # after it (its faces may be oriented either way)
    same_start = g.node("FunctionNodeCompare", [("A", vertex(c0)), ("B", vertex(c1))], data_type="INT",
                        operation="EQUAL").outputs[0]
    c1_at_a = g.switch("INT", same_start, following(c1), c1)
    c1_at_b = g.switch("INT", same_start, c1, following(c1))

    def differ(a, b):
        dot = g.vec("DOT_PRODUCT", _corner_normal_at(g, a), _corner_normal_at(g, b), out=1)
        return g.math("LESS_THAN", dot, SAME_NORMAL_DOT)

    either = g.math("MAXIMUM", differ(c0, c1_at_a), differ(following(c0), c1_at_b))
    two_faces = g.math("GREATER_THAN", corners[0].outputs["Total"], 1.5)
    return g.math("GREATER_THAN", g.math("MULTIPLY", either, two_faces), 0.5)


def _vertex_normal(g):
    """On points: the corner-angle-weighted mean of the point's corner normals, unit length
    (`kernels.common.normals.shared_vertex_normals`; where they cancel, the point's own normal, as the kernel's
    fallback). A point whose corners all share one normal gets it."""
    corner = g.input("GeometryNodeInputIndex")
    here = g.input("GeometryNodeInputPosition")  # on corners: the corner's point

    def side(offset):
        other = g.node("GeometryNodeOffsetCornerInFace", [("Corner Index", corner), ("Offset", offset)]).outputs[0]
        return g.vec("NORMALIZE", g.vec("SUBTRACT", g.at("CORNER", "FLOAT_VECTOR", here, other), here))

    cosine = g.vec("DOT_PRODUCT", side(1), side(-1), out=1)
    angle = g.math("ARCCOSINE", g.math("MINIMUM", g.math("MAXIMUM", cosine, -1.0), 1.0))
    weighted = g.on("CORNER", "FLOAT_VECTOR", g.vec("SCALE", g.named(CORNER_NORMAL, "FLOAT_VECTOR"), angle))
    # normals that cancel: the angle-weighted face normals (Blender's point normal), as the kernel falls back
    cancelled = g.math("LESS_THAN", g.vec("LENGTH", weighted, out=1), FLOAT32_TINY)
    normal = g.switch("VECTOR", cancelled, g.vec("NORMALIZE", weighted), g.input("GeometryNodeInputNormal"))
    return g.on("POINT", "FLOAT_VECTOR", normal)  # a point value, read from corners too


def set_shading(g, mesh, normal):
    """``mesh`` with the corner field ``normal`` as its custom normals (Set Mesh Normal, 4.5+); before, ``mesh``
    as it is (Blender computes its normals from the faces)."""
    if not has_set_mesh_normal_node():
        return mesh
    node = g.node("GeometryNodeSetMeshNormal", [(0, mesh)], mode="FREE", domain="CORNER")
    g.feed(node.inputs["Custom Normal"], normal)
    return node.outputs[0]

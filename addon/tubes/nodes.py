"""The geometry-nodes group "Tessera Tubes": tubes around curves ([Nunes 2011, §4]) in the modifier stack, no add-on
needed to evaluate it. Numpy reference: `kernels.tubes.builder.build_tubes` with
`kernels.tubes.frames.rotation_minimizing_frames` (the double-reflection method, Wang et al. 2008).

Curve to Mesh sweeps a circle of ``Sides`` points along the curves' evaluated points; the group only chooses the
frames, as free curve normals. With the local frame field F_k = `frames.any_perpendicular`(t_k), the kernel's
frames are ``R_k = Rot(t_k, θ_k) F_k`` with R_0 = F_0. One double-reflection step S carries R_{k-1} to point k,
and since S maps the axis t_{k-1} to t_k, ``θ_k = θ_{k-1} + δ_k`` with ``δ_k`` the signed angle from F_k to
S F_{k-1} about t_k, a local quantity: Accumulate Field sums it per curve (no loop). Closed curves spread the
angle left at the seam along their arc length, as the kernel does; the curve's own tilt is applied on top by
Curve to Mesh, as the kernel applies it. Round caps extend open curves past their ends by ``max(1, Sides // 4)``
points on the end's tangent with radius r cos φ (φ up to 90°, where the ring collapses into a pole that Merge by
Distance welds);
flat caps are Curve to Mesh's Fill Caps. The pixel clamp keeps one pixel of radius for the scene's active camera
(perspective; field of view and image width are inputs, since geometry nodes cannot read the render settings).
Corner UVs: u along the curve (arc length fraction), v around (j / Sides), the seams closed at 1.
"""

import math

from ...kernels.common.tolerances import FLOAT32_TINY
from ..compat import set_node_mode
from ..node_groups import Graph, GroupSpec, register_group, socket

GROUP_NAME = "Tessera Tubes"
VERSION = 3
_TEMP = ("tessera_u", "tessera_pole")


def _interface(tree):
    socket(tree, "Curve", "NodeSocketGeometry", description="The curves to sweep (Bezier and NURBS curves are "
                                                             "evaluated at their resolution first)")
    socket(tree, "Radius", "NodeSocketFloat", default=0.05, min_value=0.0, subtype="DISTANCE",
           description="Tube radius, multiplied by each point's curve radius (a field)")
    socket(tree, "Sides", "NodeSocketInt", default=8, min_value=3, max_value=1024,
           description="Vertices around each ring")
    socket(tree, "Caps", "NodeSocketMenu", description="How open tubes end: none, a flat n-gon or a hemisphere")
    socket(tree, "Pixel Clamp", "NodeSocketBool", default=False,
           description="Keep every tube at least one pixel thick for the scene's active camera (anti-aliasing)")
    socket(tree, "Field of View", "NodeSocketFloat", default=math.radians(39.6), min_value=1e-4, subtype="ANGLE",
           max_value=math.pi - 1e-4, description="The camera's horizontal field of view, for the pixel clamp")
    socket(tree, "Image Width", "NodeSocketInt", default=1920, min_value=1, subtype="PIXEL",
           description="Rendered image width in pixels, for the pixel clamp")
    socket(tree, "Max Radius", "NodeSocketFloat", default=0.0, min_value=0.0, subtype="DISTANCE",
           description="Largest radius the pixel clamp may inflate a tube to (0: no limit)")
    socket(tree, "UV Map", "NodeSocketString", default="UVMap",
           description="Name of the corner UVs to write (u along the curve, v around); empty: no UVs (faster)")
    socket(tree, "Mesh", "NodeSocketGeometry", in_out="OUTPUT", description="The tube meshes")


class _Tubes:
    """The builder's state: the graph and the group's inputs."""

    def __init__(self, tree):
        self.g = Graph(tree)
        _interface(tree)
        self.gi, self.go = self.g.node("NodeGroupInput"), self.g.node("NodeGroupOutput")
        self.tree = tree

    def inp(self, name):
        return self.gi.outputs[name]

    # --- small vector helpers ------------------------------------------------------------------------------------
    def dot(self, a, b):
        return self.g.vec("DOT_PRODUCT", a, b, out=1)

    def reflect(self, v, axis):
        """v reflected across the plane with unit normal ``axis``: v - 2 (axis.v) axis."""
        g = self.g
        return g.vec("SUBTRACT", v, g.vec("SCALE", axis, g.math("MULTIPLY", self.dot(axis, v), 2.0)))

    def signed_angle(self, a, b, axis):
        """Angle from ``a`` to ``b`` about ``axis`` (right-handed), in (-π, π]."""
        g = self.g
        return g.math("ARCTAN2", self.dot(g.vec("CROSS_PRODUCT", a, b), axis), self.dot(a, b))

    def any_perpendicular(self, t):
        """`frames.any_perpendicular`: the axis of t's smallest |component| (first on ties), made orthogonal."""
        g = self.g
        ax, ay, az = (g.math("ABSOLUTE", c) for c in g.split(t))
        is_x = g.math("MINIMUM", g.math("SUBTRACT", 1.0, g.math("GREATER_THAN", ax, ay)),
                      g.math("SUBTRACT", 1.0, g.math("GREATER_THAN", ax, az)))
        is_y = g.math("MULTIPLY", g.math("SUBTRACT", 1.0, is_x),
                      g.math("SUBTRACT", 1.0, g.math("GREATER_THAN", ay, az)))
        is_z = g.math("SUBTRACT", g.math("SUBTRACT", 1.0, is_x), is_y)
        e = g.xyz(is_x, is_y, is_z)
        return g.vec("NORMALIZE", g.vec("SUBTRACT", e, g.vec("SCALE", t, self.dot(e, t))))

    def is_first_point(self):
        """True at each curve's first point (a field on points)."""
        index = self.g.node("GeometryNodeCurveOfPoint").outputs["Index in Curve"]
        return self.g.node("FunctionNodeCompare", [("A", index), ("B", 0)], data_type="INT",
                           operation="EQUAL").outputs[0]

    # --- stages --------------------------------------------------------------------------------------------------
    def radius(self):
        """r = Radius x curve radius, or max(r, min(s_pix / cos(π / n), Max Radius)) with the pixel clamp."""
        g = self.g
        r = g.math("MULTIPLY", self.inp("Radius"), g.input("GeometryNodeInputRadius"))
        camera = g.node("GeometryNodeObjectInfo", [(0, g.input("GeometryNodeInputActiveCamera"))],
                        transform_space="RELATIVE")
        forward = g.node("FunctionNodeRotateVector", [("Vector", (0.0, 0.0, -1.0)),
                                                      ("Rotation", camera.outputs["Rotation"])]).outputs[0]
        depth = self.dot(g.vec("SUBTRACT", g.input("GeometryNodeInputPosition"), camera.outputs["Location"]), forward)
        per_depth = g.math("DIVIDE", g.math("MULTIPLY", 2.0, g.math("TANGENT", g.math(
            "MULTIPLY", self.inp("Field of View"), 0.5))), self.inp("Image Width"))
        cos_half = g.math("COSINE", g.math("DIVIDE", math.pi, self.inp("Sides")))
        inflate = g.math("DIVIDE", g.math("MULTIPLY", depth, per_depth), cos_half)
        max_r = self.inp("Max Radius")
        limited = g.switch("FLOAT", g.math("GREATER_THAN", max_r, 0.0), inflate, g.math("MINIMUM", inflate, max_r))
        clamped = g.switch("FLOAT", g.math("GREATER_THAN", depth, 0.0), r, g.math("MAXIMUM", r, limited))
        return g.switch("FLOAT", self.inp("Pixel Clamp"), r, clamped)

    def extend_for_round_caps(self, curve, round_caps):
        """Open curves get ``m = max(1, Sides // 4)`` points past each end (rings of the hemisphere; the last is the
        pole); their positions, radii, u and tilt come from ``curve`` (`Sample Index`)."""
        g = self.g
        m_int = g.math("MAXIMUM", 1.0, g.math("FLOOR", g.math("DIVIDE", self.inp("Sides"), 4.0)))
        m = g.math("MULTIPLY", m_int, g.math("SUBTRACT", 1.0, g.input("GeometryNodeInputSplineCyclic")))
        points = g.node("GeometryNodePointsOfCurve", [("Sort Index", 0)])  # read on the curve domain
        resample = g.node("GeometryNodeResampleCurve", [("Curve", curve), ("Count", g.math(
            "ADD", points.outputs["Total"], g.math("MULTIPLY", m, 2.0)))])
        set_node_mode(resample, "Mode", "COUNT", "Count")
        extended = resample.outputs[0]

        of_point = g.node("GeometryNodeCurveOfPoint")
        index_in_curve, curve_index = of_point.outputs["Index in Curve"], of_point.outputs["Curve Index"]

        def of_curve(value):  # an integer of the source curve with this point's curve index
            return g.node("GeometryNodeSampleIndex", [("Geometry", curve), ("Value", value), ("Index", curve_index)],
                          data_type="INT", domain="CURVE").outputs[0]

        first, n = of_curve(points.outputs["Point Index"]), of_curve(points.outputs["Total"])
        local = g.math("SUBTRACT", index_in_curve, m)  # m read per point: the cyclic flag of the point's curve
        kk = g.math("MINIMUM", g.math("MAXIMUM", local, 0.0), g.math("SUBTRACT", n, 1.0))
        src = g.math("ADD", first, kk)
        ring = g.math("MAXIMUM", g.math("MAXIMUM", g.math("MULTIPLY", local, -1.0),
                                          g.math("SUBTRACT", local, g.math("SUBTRACT", n, 1.0))), 0.0)
        side = g.math("SUBTRACT", 1.0, g.math("MULTIPLY", g.math("LESS_THAN", local, 0.0), 2.0))
        phi = g.math("MULTIPLY", g.math("DIVIDE", ring, g.math("MAXIMUM", m, 1.0)), math.pi / 2)
        pole = g.math("MULTIPLY", g.math("GREATER_THAN", m, 0.0),
                      g.node("FunctionNodeCompare", [("A", ring), ("B", m)], data_type="FLOAT",
                             operation="EQUAL").outputs[0])
        cos_phi = g.switch("FLOAT", pole, g.math("COSINE", phi), 0.0)

        def at_src(value, data_type="FLOAT"):
            return g.node("GeometryNodeSampleIndex", [("Geometry", curve), ("Value", value), ("Index", src)],
                          data_type=data_type, domain="POINT").outputs[0]

        r = at_src(g.input("GeometryNodeInputRadius"))
        along = g.vec("SCALE", at_src(g.input("GeometryNodeInputTangent"), "FLOAT_VECTOR"),
                      g.math("MULTIPLY", g.math("MULTIPLY", side, r), g.math("SINE", phi)))
        position = g.vec("ADD", at_src(g.input("GeometryNodeInputPosition"), "FLOAT_VECTOR"), along)
        extended = g.node("GeometryNodeSetPosition", [(0, extended), ("Position", position)]).outputs[0]
        extended = g.node("GeometryNodeSetCurveRadius", [(0, extended), ("Radius", g.math(
            "MULTIPLY", r, cos_phi))]).outputs[0]
        extended = g.store(extended, "tessera_u", at_src(g.named("tessera_u")))
        extended = g.node("GeometryNodeSetCurveTilt", [(0, extended), ("Tilt", at_src(g.input(
            "GeometryNodeInputCurveTilt")))]).outputs[0]
        extended = g.store(extended, "tessera_pole", g.math("GREATER_THAN", pole, 0.5), "BOOLEAN")
        return g.switch("GEOMETRY", round_caps, curve, extended)

    def frames(self, curve):
        """``curve`` with free normals set to the kernel's rotation-minimising frames (before the tilt, which
        Curve to Mesh applies on top, as the kernel does). The step angles are stored once (the accumulation and
        the seam read them again) and removed after."""
        g = self.g
        index = g.input("GeometryNodeInputIndex")
        prev = g.node("GeometryNodeOffsetPointInCurve", [("Point Index", index), ("Offset", -1)]).outputs["Point Index"]
        x, t = g.input("GeometryNodeInputPosition"), g.input("GeometryNodeInputTangent")
        f = self.any_perpendicular(t)
        xp, tp, fp = (g.at("POINT", "FLOAT_VECTOR", v, prev) for v in (x, t, f))
        a = g.vec("NORMALIZE", g.vec("SUBTRACT", x, xp))
        v1, t_l = self.reflect(fp, a), self.reflect(tp, a)
        d = g.vec("SUBTRACT", t, t_l)
        # reflection 2 undefined when t == reflected t_prev: it then acts as the identity on v1
        b = g.vec("SCALE", g.vec("NORMALIZE", d), g.math("GREATER_THAN", g.vec("LENGTH", d, out=1), 1e-6))
        curve = g.store(curve, "tessera_step", self.signed_angle(f, self.reflect(v1, b), t))
        step = g.named("tessera_step")
        in_curve = g.node("GeometryNodeCurveOfPoint")
        acc = g.node("GeometryNodeAccumulateField", [("Value", g.switch("FLOAT", self.is_first_point(), step, 0.0)),
                                                     ("Group ID", in_curve.outputs["Curve Index"])],
                     data_type="FLOAT", domain="POINT")
        # closed curves: the frame carried round the seam misses the first frame by phi, spread along the arc
        first = g.node("GeometryNodePointsOfCurve", [("Curve Index", in_curve.outputs["Curve Index"]),
                                                     ("Sort Index", 0)]).outputs[0]
        phi = g.math("MULTIPLY", g.math("ADD", acc.outputs["Total"], g.at("POINT", "FLOAT", step, first)), -1.0)
        phi = g.math("ARCTAN2", g.math("SINE", phi), g.math("COSINE", phi))
        length = g.node("GeometryNodeSplineLength")
        closed = g.math("MULTIPLY", g.input("GeometryNodeInputSplineCyclic"),
                        g.math("GREATER_THAN", length.outputs["Point Count"], 2.5))
        fraction = g.math("DIVIDE", g.node("GeometryNodeSplineParameter").outputs["Length"],
                          g.math("MAXIMUM", length.outputs["Length"], FLOAT32_TINY))
        angle = g.math("ADD", acc.outputs["Leading"], g.math("MULTIPLY", closed, g.math("MULTIPLY", phi, fraction)))
        normal = g.vec("ADD", g.vec("SCALE", f, g.math("COSINE", angle)),
                       g.vec("SCALE", g.vec("CROSS_PRODUCT", t, f), g.math("SINE", angle)))
        node = g.node("GeometryNodeSetCurveNormal", [(0, curve)])
        set_node_mode(node, "Mode", "FREE", "Free")
        g.feed(node.inputs["Normal"], normal)
        return g.remove(node.outputs[0], ("tessera_step",))


def _build(tree):
    b = _Tubes(tree)
    g = b.g
    caps = g.menu("INT", b.inp("Caps"), [(name, i) for i, name in enumerate(("None", "Flat", "Round"))])

    resample = g.node("GeometryNodeResampleCurve", [("Curve", b.inp("Curve"))])
    set_node_mode(resample, "Mode", "EVALUATED", "Evaluated")
    curve = resample.outputs[0]
    closed_start = g.math("MULTIPLY", g.input("GeometryNodeInputSplineCyclic"), b.is_first_point())
    u = g.switch("FLOAT", closed_start, g.node("GeometryNodeSplineParameter").outputs["Factor"], -1.0)
    has_uv = g.math("GREATER_THAN", g.node("FunctionNodeStringLength", [(0, b.inp("UV Map"))]).outputs[0], 0.0)
    # -1 marks a closed curve's first point (u 0 there, 1 at the seam)
    curve = g.switch("GEOMETRY", has_uv, curve, g.store(curve, "tessera_u", u))
    curve = g.node("GeometryNodeSetCurveRadius", [(0, curve), ("Radius", b.radius())]).outputs[0]
    is_round = g.node("FunctionNodeCompare", [("A", caps), ("B", 2)], data_type="INT", operation="EQUAL").outputs[0]
    curve = b.extend_for_round_caps(curve, is_round)

    curve = b.frames(curve)

    circle = g.node("GeometryNodeCurvePrimitiveCircle", [("Resolution", b.inp("Sides")), ("Radius", 1.0)],
                    mode="RADIUS").outputs[0]
    fill = g.node("FunctionNodeCompare", [("A", caps), ("B", 1)], data_type="INT", operation="EQUAL").outputs[0]
    to_mesh = g.node("GeometryNodeCurveToMesh", [("Curve", curve), ("Profile Curve", circle), ("Fill Caps", fill)])
    if "Scale" in to_mesh.inputs:  # 4.5+: the radius scales the profile only through this input
        g.feed(to_mesh.inputs["Scale"], g.input("GeometryNodeInputRadius"))
    mesh = to_mesh.outputs[0]
    uv = g.switch("VECTOR", fill, _quad_uv(g, b.inp("Sides")), _uv(g, b.inp("Sides")))
    with_uv = g.node("GeometryNodeStoreNamedAttribute", [(0, mesh), ("Name", b.inp("UV Map")), ("Value", uv)],
                     data_type="FLOAT2", domain="CORNER").outputs[0]
    mesh = g.switch("GEOMETRY", has_uv, mesh, with_uv)
    merge = g.node("GeometryNodeMergeByDistance", [("Geometry", mesh), ("Selection", g.named(
        "tessera_pole", "BOOLEAN")), ("Distance", 0.0)])
    set_node_mode(merge, "Mode", "CONNECTED", "Connected")
    mesh = g.switch("GEOMETRY", is_round, mesh, merge.outputs[0])  # poles exist only with round caps
    tree.links.new(g.remove(mesh, _TEMP), b.go.inputs[0])


def _uv(g, sides):
    """Corner UVs (u along, v around) from Curve to Mesh's layout: ring-major vertices (side j = vertex mod n)
    and quads (ring k side j, ring k side j+1, ring k+1 side j+1, ring k+1 side j), so corners 1 and 2 of a face
    at side n-1 close the seam at v = 1, and corners 2 and 3 of a closed curve's last segment at u = 1 (its first
    point's u is stored as -1 to mark it)."""
    corner = g.input("GeometryNodeInputIndex")
    k = g.node("GeometryNodeFaceOfCorner", [(0, corner)]).outputs["Index in Face"]
    j = g.math("FLOORED_MODULO", g.node("GeometryNodeVertexOfCorner", [(0, corner)]).outputs[0], sides)
    second = g.math("MULTIPLY", g.math("GREATER_THAN", k, 0.5), g.math("LESS_THAN", k, 2.5))  # corners 1, 2
    v = g.switch("FLOAT", g.math("MULTIPLY", second, g.math("LESS_THAN", j, 0.5)), g.math("DIVIDE", j, sides), 1.0)
    u = g.named("tessera_u")
    u = g.switch("FLOAT", g.math("LESS_THAN", u, 0.0), u, g.math("GREATER_THAN", k, 1.5))
    return g.xyz(u, v, 0.0)


def _quad_uv(g, sides):
    """`_uv` where every face is a quad (no flat caps), from the corner index alone: Curve to Mesh writes the faces
    ring-major, four corners each, so corner c has index in face c mod 4 and side (c div 4) mod n. No lookup of the
    face or the vertex per corner (each costs as much as the rest together on millions of corners)."""
    corner = g.input("GeometryNodeInputIndex")
    k = g.math("FLOORED_MODULO", corner, 4.0)
    side = g.math("FLOORED_MODULO", g.math("FLOOR", g.math("DIVIDE", corner, 4.0)), sides)
    second = g.math("LESS_THAN", g.math("FLOORED_MODULO", g.math("ADD", k, 3.0), 4.0), 1.5)  # corners 1, 2: side + 1
    v = g.math("DIVIDE", g.math("ADD", side, second), sides)
    u = g.named("tessera_u")
    u = g.switch("FLOAT", g.math("LESS_THAN", u, 0.0), u, g.math("GREATER_THAN", k, 1.5))
    return g.xyz(u, v, 0.0)


SPEC = register_group(GroupSpec(GROUP_NAME, VERSION, _build, catalog="Tessera/Tubes",
                                description="Sweep curves into tube meshes with twist-free rings, caps and UVs"))

"""PN / Phong / linear tessellation on the GPU, from instanced refinement patterns (no tessellation stage).

`PatchDrawData` holds one mesh's control texture (`kernels.tessellation.patch_instances.control_rows`, uploaded
once per mesh edit) and, per level class, an instance texture of 32 bytes per triangle (uploaded when the levels
change).
Each class's pattern is drawn instanced; ``patch_eval.glsl`` places its vertices on the surface. `evaluate_on_gpu`
is the compute path: the same ``evaluate`` for every welded vertex of a CPU refinement, read back as arrays.
"""


from ...kernels.tessellation import patch_instances as pi
from .. import loader
from ..offscreen import set_shading, shaded_create_info
from ..textures import TEX_WIDTH, read_after_compute, rgba_texture

METHOD_CODES = {"LINEAR": 0, "PHONG": 1, "PN": 2}
DISPLACE_CODES = {"HEIGHT": 1, "VECTOR": 2, "TANGENT": 3}


def _surface_constants(info):
    info.push_constant("INT", "tex_width")
    info.push_constant("INT", "method")
    info.push_constant("INT", "pn_quadratic")
    info.push_constant("INT", "fractional")
    info.sampler(0, "FLOAT_2D", "control")


def _describe_preview():
    info = shaded_create_info("patch", "partition.glsl", "tessellation/patch_eval.glsl", "tessellation/patch_vert.glsl")
    _surface_constants(info)
    info.push_constant("VEC4", "counts")
    info.push_constant("INT", "displace")
    info.push_constant("VEC2", "mid_strength")
    info.sampler(1, "FLOAT_2D", "instances")
    info.sampler(2, "FLOAT_2D", "displacement")
    info.vertex_in(0, "VEC4", "code")
    return info


def _describe_compute():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    _surface_constants(info)
    info.push_constant("INT", "vertex_count")
    info.sampler(1, "FLOAT_2D", "vertices")
    info.image(0, "RGBA32F", "FLOAT_2D", "out_positions", qualifiers={"WRITE"})
    info.image(1, "RGBA32F", "FLOAT_2D", "out_normals", qualifiers={"WRITE"})
    info.local_group_size(64, 1, 1)
    info.compute_source(loader.sources("partition.glsl", "tessellation/patch_eval.glsl",
                                       "tessellation/patch_comp.glsl"))
    return info


def _pattern_batch(shader, key, wireframe=False):
    """The pattern of class ``key`` as triangles, or as its unique edges for a wireframe (cached)."""

    def make():
        codes, tris = pi.pattern(*key)
        return {"code": codes}, tris

    return loader.pattern_batch(("tessellation", key), shader, make, wireframe)


def _set_surface(shader, method, pn_quadratic, fractional, control):
    shader.uniform_int("tex_width", TEX_WIDTH)
    shader.uniform_int("method", METHOD_CODES[method])
    shader.uniform_int("pn_quadratic", 1 if pn_quadratic else 0)
    shader.uniform_int("fractional", 1 if fractional else 0)
    shader.uniform_sampler("control", control)


class Displacement:
    """A displacement map for the preview: ``texture`` (a `gpu.types.GPUTexture`), ``mode`` HEIGHT (along the
    normal, mean of R, G, B), VECTOR (RGB in object space) or TANGENT (RGB in the tangent frame: needs the
    draw data's tangents), ``mid_level``, ``strength``; sampled at the UVs."""

    def __init__(self, texture, mode="HEIGHT", mid_level=0.5, strength=1.0):
        if mode not in DISPLACE_CODES:
            raise ValueError(f"mode must be one of {', '.join(DISPLACE_CODES)}; got {mode!r}")
        self.texture, self.mode, self.mid_level, self.strength = texture, mode, float(mid_level), float(strength)


class PatchDrawData:
    """GPU resources of one tessellated mesh.

    inputs: `kernels.tessellation.tessellate.SurfaceInputs`; method: LINEAR, PHONG or PN; alpha: the constant
    Phong factor;
    pn_quadratic: quadratic PN normals; uvs: (T, 3, 2) corner UVs or None (needed for displacement);
    tangents: (T, 3, 4) corner tangents and bitangent signs or None (needed for tangent-space displacement).
    """

    def __init__(self, inputs, method="PN", alpha=0.75, pn_quadratic=True, uvs=None, tangents=None):
        self.inputs, self.method, self.pn_quadratic = inputs, method, pn_quadratic
        rows = pi.control_rows(inputs, alpha, uvs, tangents)
        self.control = rgba_texture(rows.reshape(-1, 4))
        self.control_bytes = rows.nbytes
        self.buckets, self.instance_bytes, self.fractional, self.classes = {}, 0, False, None

    def set_levels(self, edge_levels, inner_levels=None, spacing="EQUAL"):
        """Upload the instances of each class for new levels ((E,) per edge of ``inputs.mesh``, (T,) or None)."""
        tris = self.inputs.mesh.triangles
        self.classes = pi.patch_classes(tris, len(self.inputs.positions), edge_levels, inner_levels, spacing)
        self.fractional = spacing == "FRACTIONAL_EVEN"
        self.buckets, self.instance_bytes = {}, 0
        for key, ids in self.classes.classes.items():
            rows = pi.instance_rows(self.classes, ids)
            self.buckets[key] = (rgba_texture(rows.reshape(-1, 4)), len(ids))
            self.instance_bytes += rows.nbytes

    @property
    def triangle_count(self):
        """Triangles one draw produces."""
        return sum(len(pi.pattern(*key)[1]) * count for key, (_, count) in self.buckets.items())

    def draw(self, view_projection, color=(0.8, 0.8, 0.8, 1.0), lit=True, displacement=None, wireframe=False,
             lighting=None):
        """Draw into the bound framebuffer. view_projection: (4, 4) row-major, mesh space to clip space;
        displacement: a `Displacement` or None; wireframe: draw the edges of the output triangles instead;
        lighting: an `offscreen.ViewLighting` to light as the viewport does, or None for the check shade."""
        shader = loader.shader("patch_preview", _describe_preview)
        set_shading(shader, view_projection, color, lit, lighting)
        _set_surface(shader, self.method, self.pn_quadratic, self.fractional, self.control)
        if displacement is None:
            shader.uniform_int("displace", 0)
            shader.uniform_sampler("displacement", self.control)  # bound but unread
        else:
            shader.uniform_int("displace", DISPLACE_CODES[displacement.mode])
            shader.uniform_float("mid_strength", (displacement.mid_level, displacement.strength))
            shader.uniform_sampler("displacement", displacement.texture)
        for key, (texture, count) in self.buckets.items():
            shader.uniform_float("counts", tuple(float(c) for c in key))
            shader.uniform_sampler("instances", texture)
            _pattern_batch(shader, key, wireframe).draw_instanced(shader, instance_start=0, instance_count=count)


def compute_shader():
    """The compute shader of `evaluate_on_gpu`, compiled (a `GPUShaderError` when this backend cannot)."""
    return loader.shader("patch_compute", _describe_compute)


def evaluate_on_gpu(ref, inputs, method="PN", alpha=0.75, pn_quadratic=True):
    """Positions and unit point normals of every vertex of ``ref`` by the compute shader.

    ref: the `Refinement` of ``inputs.mesh`` at the levels wanted; returns ``(positions (N, 3) float32,
    normals (N, 3) float32)``, the same surface as the numpy kernels (float32 arithmetic). Needs a GPU context.
    """
    import gpu

    classes = pi.patch_classes(ref.faces, ref.n_corners, ref.edge_level, ref.inner_level, ref.spacing)
    control = rgba_texture(pi.control_rows(inputs, alpha).reshape(-1, 4))
    vertices = rgba_texture(pi.vertex_rows(ref, classes).reshape(-1, 4))
    n = ref.n_vertices
    height = max(1, -(-n // TEX_WIDTH))
    out_p = gpu.types.GPUTexture((TEX_WIDTH, height), format="RGBA32F")
    out_n = gpu.types.GPUTexture((TEX_WIDTH, height), format="RGBA32F")
    shader = compute_shader()
    shader.bind()
    _set_surface(shader, method, pn_quadratic, ref.spacing == "FRACTIONAL_EVEN", control)
    shader.uniform_int("vertex_count", n)
    shader.uniform_sampler("vertices", vertices)
    shader.image("out_positions", out_p)
    shader.image("out_normals", out_n)
    gpu.compute.dispatch(shader, TEX_WIDTH // 64, height, 1)
    return read_after_compute(out_p, n)[:, :3].copy(), read_after_compute(out_n, n)[:, :3].copy()

"""``tessera.vector_field_texture``: an image of streaks that follow a steady 2-D flow (a preset, or vectors on a grid
mesh), by line integral convolution ([Nellmedin 2014, §5.5.4]), on the GPU or with the numpy reference."""

import bpy
import numpy as np

from ..addon import bridge
from ..addon.gpu_context import ensure_gpu_context
from ..addon.guarded import guarded
from ..addon.preferences import get_preferences
from ..addon.vector_field.settings import FieldOptions, draw_field_options
from ..kernels.common.budget import check_bytes
from ..kernels.common.errors import GPUContextError, GPUShaderError, InvalidInputError
from ..kernels.vector_field import fields, streaks

#: Memory per pixel of a vector-field texture: the splat sums and counts (float64), the RGBA pixels written, and
#: Blender's float image with its packed copy.
_BYTES_PER_FIELD_PIXEL = 96


class TESSERA_OT_vector_field_texture(FieldOptions, bpy.types.Operator):
    """Make an image of streaks that follow a flow (a preset, or vectors on a grid mesh), for materials"""

    bl_idname = "tessera.vector_field_texture"
    bl_label = "Vector Field Texture"
    bl_options = {"REGISTER", "UNDO"}

    def draw(self, context):
        draw_field_options(self.layout, self)

    def _field(self, context):
        if self.field != "MESH":
            return fields.AnalyticField(self.field, slice_z=self.slice_z, speed=self.speed)
        if self.field_object and self.field_object not in bpy.data.objects:
            raise InvalidInputError(f"No object named {self.field_object!r} (Grid Object): pick the grid mesh")
        ob = bpy.data.objects.get(self.field_object) if self.field_object else context.active_object
        if ob is None or ob.type != "MESH":
            raise InvalidInputError("Choose a grid mesh object holding the field (Grid Object), or make one active")
        n = len(ob.data.vertices)
        if n == 0:
            raise InvalidInputError(f"The Grid Object {ob.name!r} has no vertices: give it the grid of the field")
        positions, _ = bridge.read_wire_mesh(ob.data)
        vectors = bridge.point_vector_attribute(ob.data, self.attribute, n) * self.speed
        return fields.grid_field_from_points(positions, vectors)

    def _camera_distance(self, context):
        cam, ob = context.scene.camera, context.active_object
        if cam is None:
            return self.far  # no camera: the sparsest lattice
        eye = np.array(cam.matrix_world.translation)
        target = np.array(ob.matrix_world.translation) if ob is not None else np.zeros(3)
        return float(np.linalg.norm(eye - target))

    @guarded
    def execute(self, context, tx):
        if self.near >= self.far:
            raise InvalidInputError(f"Near ({self.near:g}) must be less than Far ({self.far:g})")
        check_bytes(self.width * self.height * _BYTES_PER_FIELD_PIXEL, get_preferences(context).memory_budget_bytes,
                    f"A {self.width} x {self.height} texture would be made", "a smaller Width and Height")
        field = self._field(context)
        per_side = streaks.seeds_per_side(self.seeds, self._camera_distance(context), self.near, self.far)
        points, values = streaks.seed_points(per_side, self.noise_seed)
        backend = self.backend
        if backend != "CPU":
            try:
                ensure_gpu_context()
                from ..gpu_shaders.vector_field.streaks import streak_shaders, streaks_on_gpu

                streak_shaders()
                backend = "GPU"
            except GPUShaderError as err:  # the driver cannot compile it: the numpy reference makes the same image
                self.report({"WARNING"}, f"{err}; computed on the CPU with numpy")
                backend = "CPU"
            except GPUContextError as err:
                if backend == "GPU":
                    raise
                self.report({"INFO"}, f"{err}; using numpy")
                backend = "CPU"
        if backend == "GPU":
            total, count = streaks_on_gpu(field, points, values, self.width, self.height, self.step, self.steps)
        else:
            total, count = streaks.splat(streaks.advect(points, field, self.step, self.steps), values, self.width,
                                    self.height)
        grey = np.where(count > 0, total / np.maximum(count, 1), 0.5).astype(np.float32)
        if not np.all(np.isfinite(grey)):
            raise InvalidInputError("The field gave points that are not finite numbers: lower the Step or Speed")
        image = tx.track(bpy.data.images.new("Vector Field", self.width, self.height, float_buffer=True,
                                             is_data=True))
        rgba = np.ones((self.height, self.width, 4), np.float32)
        rgba[..., :3] = grey[..., None]
        bridge.write_image_pixels(image, rgba)
        bridge.pack_float_image(image)
        image.use_fake_user = True  # made to be used: kept in the file until the user deletes it
        self.report({"INFO"}, f"{image.name}: {per_side}² seeds x {self.steps} steps on the {backend}")
        return {"FINISHED"}


classes = (TESSERA_OT_vector_field_texture,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Add-on preferences: memory budget, compute backend (OpenCL mode and device), and the Manual."""

import bpy

from ..kernels.common import opencl_runtime
from .manifest import manual_url

BASE_PACKAGE = __package__.rpartition(".")[0]

_OPENCL_MODES = (
    ("ENV", "From Environment", "Use TESSERA_OPENCL (default: OpenCL when available, else numpy)"),
    ("0", "Off", "Never use OpenCL; numpy only"),
    ("1", "When Available", "Use OpenCL when a platform is present; fall back to numpy with a warning"),
    ("require", "Required", "Fail with an error when OpenCL is unavailable"),
)


def _cache_dir():
    try:
        return bpy.utils.extension_path_user(BASE_PACKAGE, path="opencl_cache", create=True)
    except (ValueError, AttributeError):  # loaded as a legacy add-on (no extension user path)
        return None


def apply_opencl_settings(prefs):
    """Pass the OpenCL preferences to the kernels' runtime (which then picks the device lazily)."""
    opencl_runtime.configure(
        mode=None if prefs.opencl_mode == "ENV" else prefs.opencl_mode,
        device=prefs.opencl_device or None,
        cache_dir=_cache_dir(),
    )


def _on_opencl_change(self, context):
    apply_opencl_settings(self)


class TESSERA_AddonPreferences(bpy.types.AddonPreferences):
    bl_idname = BASE_PACKAGE

    memory_budget_mb: bpy.props.IntProperty(
        name="Memory Budget (MiB)",
        description="Refuse operations whose estimated peak memory exceeds this many mebibytes (0: no limit)",
        default=4096,
        min=0,
        soft_max=65536,
    )
    opencl_mode: bpy.props.EnumProperty(
        name="OpenCL", items=_OPENCL_MODES, default="ENV", update=_on_opencl_change,
        description="Whether heavy work (tubes, brushes, terrain, Loop subdivision) runs on an OpenCL device",
    )
    opencl_device: bpy.props.StringProperty(
        name="OpenCL Device",
        description="Part of the device or platform name to use (empty: prefer a GPU)",
        default="",
        update=_on_opencl_change,
    )

    @property
    def memory_budget_bytes(self):
        return self.memory_budget_mb * 2**20

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(self, "memory_budget_mb")
        layout.prop(self, "opencl_mode")
        layout.prop(self, "opencl_device")
        runtime = None
        try:
            runtime = opencl_runtime.get_runtime()
        except Exception as err:  # shown, not raised: drawing must never fail
            layout.label(text=str(err), icon="ERROR")
        layout.label(text=f"Compute device: {runtime.description if runtime else 'numpy (CPU)'}")
        if manual_url():
            layout.operator("wm.url_open", text="Manual", icon="HELP").url = manual_url()


def get_preferences(context=None):
    """The add-on's preferences (valid while the add-on is enabled)."""
    context = context or bpy.context
    return context.preferences.addons[BASE_PACKAGE].preferences


classes = (TESSERA_AddonPreferences,)
_register, _unregister = bpy.utils.register_classes_factory(classes)


def register():
    _register()
    apply_opencl_settings(get_preferences())


def unregister():
    _unregister()

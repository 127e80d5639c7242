"""``tessera.impostor_bake``: the active object baked into an octahedral impostor (colour, normal and depth atlases
rendered by Cycles in a worker process) on a card that faces the camera, for EEVEE and Cycles renders;
``tessera.impostor_export``: such a card written to glTF (`addon.impostors.export`)."""

import bpy

from ..addon.guarded import guarded
from ..addon.impostors.bake import atlas_images, bake_atlas, make_card
from ..addon.impostors.export import export_card, impostor_info
from .selection import object_poll, select_only


class TESSERA_OT_impostor_bake(bpy.types.Operator):
    """Render the active object from many directions with Cycles onto a camera-facing card that stands in for it"""

    bl_idname = "tessera.impostor_bake"
    bl_label = "Bake Impostor"
    bl_options = {"REGISTER", "UNDO"}

    grid: bpy.props.IntProperty(name="Views", default=8, min=1, max=32,
                                description="Views along each side of the atlas (Views × Views directions)")
    tile: bpy.props.IntProperty(name="View Size", default=128, min=8, max=2048, soft_max=1024, subtype="PIXEL",
                                description="Width and height of each view")
    samples: bpy.props.IntProperty(name="Samples", default=16, min=1, max=4096, soft_max=1024,
                                   description="Cycles samples per view")
    dilation: bpy.props.IntProperty(name="Dilation", default=4, min=0, max=64, subtype="PIXEL",
                                    description="Texels each view's colours and normals spread into the empty texels "
                                                "around it (alpha stays 0), so engines that filter the atlas show no "
                                                "dark halo at the outline")
    blend: bpy.props.BoolProperty(name="Blend Views", default=True,
                                  description="Mix the four views nearest the view direction, so the card changes "
                                              "smoothly as it turns; off: the nearest view alone")
    hemi: bpy.props.BoolProperty(name="Upper Hemisphere", default=False,
                                 description="Views only from above: more detail for objects that stand on the "
                                             "ground")

    @classmethod
    def poll(cls, context):
        return object_poll(cls, context, {"MESH", "CURVE", "SURFACE", "META", "FONT"},
                           "Select an object with geometry in Object Mode")

    @guarded
    def execute(self, context, tx):
        ob = context.active_object
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            atlas = bake_atlas(ob, self.grid, self.tile, self.samples, self.hemi, dilation=self.dilation)
        finally:
            wm.progress_end()
        name = f"{ob.name} impostor"
        images = {k: tx.track(v) for k, v in atlas_images(name, atlas).items()}
        card = make_card(name, atlas, images, context.scene.camera, self.blend)
        tx.track(card.data)
        tx.track(card.data.materials[0])
        tx.track(card)
        context.collection.objects.link(card)
        select_only(context, [card])
        note = "" if context.scene.camera else " (no scene camera: add a Track To constraint to the camera)"
        self.report({"INFO"}, f"{name}: {self.grid}x{self.grid} views of {self.tile}px{note}")
        return {"FINISHED"}


class TESSERA_OT_impostor_export(bpy.types.Operator):
    """Write the active impostor card and its atlas to a glTF binary (.glb) file for game engines"""

    bl_idname = "tessera.impostor_export"
    bl_label = "Tessera Impostor (.glb)"
    bl_options = {"REGISTER"}

    filepath: bpy.props.StringProperty(name="File", subtype="FILE_PATH", description="The .glb file to write")
    filter_glob: bpy.props.StringProperty(default="*.glb", options={"HIDDEN"}, description="Files listed")

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT" or impostor_info(context.active_object) is None:
            cls.poll_message_set("Select a card made by Bake Impostor, in Object Mode")
            return False
        return True

    def invoke(self, context, event):
        if not self.filepath:
            self.filepath = bpy.path.clean_name(context.active_object.name) + ".glb"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    @guarded
    def execute(self, context, tx):
        path = bpy.path.abspath(self.filepath)
        if not path.lower().endswith(".glb"):
            path += ".glb"
        export_card(context.active_object, path)
        self.report({"INFO"}, f"Wrote {path}")
        return {"FINISHED"}


classes = (TESSERA_OT_impostor_bake, TESSERA_OT_impostor_export)
register, unregister = bpy.utils.register_classes_factory(classes)

"""What the window scenarios share: a clean scene, a framed view, and the preview oracle.

The oracle (issue "Tessera in a real Blender window", item 2): a screenshot with a preview on is compared with a
screenshot of the applied result drawn by Blender (its source hidden). A pixel differs when a channel differs by
more than 16/255; the share of differing pixels is taken over the union of both silhouettes, each silhouette being
where its screenshot differs from the empty scene's.
"""

import bpy
import numpy as np

THRESHOLD = 16


def clean_scene():
    """No objects, no leftover meshes; Solid shading, overlays on."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)


def frame(w, objects, front=True):
    """Look at ``objects`` from the front (numpad 1) and frame them, as an artist would; nothing stays selected."""
    for ob in bpy.data.objects:
        ob.select_set(ob in objects)
    with bpy.context.temp_override(**w.context()):
        if front:
            bpy.ops.view3d.view_axis(type="FRONT")
        bpy.ops.view3d.view_selected()
    for ob in objects:
        ob.select_set(False)


def silhouette(image, empty):
    """Where ``image`` differs from the empty scene's screenshot: (h, w) bool."""
    return (np.abs(image.astype(np.int16) - empty.astype(np.int16)) > THRESHOLD).any(axis=2)


def differing_share(a, b, empty):
    """The share of pixels that differ between ``a`` and ``b`` over the union of their silhouettes, and the
    union's size in pixels."""
    union = silhouette(a, empty) | silhouette(b, empty)
    differ = (np.abs(a.astype(np.int16) - b.astype(np.int16)) > THRESHOLD).any(axis=2) & union
    count = int(union.sum())
    return (float(differ.sum()) / count if count else 0.0), count

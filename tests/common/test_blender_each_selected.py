"""Object › Tessera acts on every selected object, as Blender's own object operators do (`guarded.each_selected`):
one result per selected object, all selected afterwards; one object failing leaves nothing of the others."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def _monkeys(bpy, count):
    obs = []
    for i in range(count):
        bpy.ops.mesh.primitive_monkey_add(location=(3.0 * i, 0.0, 0.0))
        obs.append(bpy.context.active_object)
    for ob in obs:
        ob.select_set(True)
    return obs


def test_tessellate_makes_one_result_per_selected_mesh(clean_scene, bpy_module):
    bpy = bpy_module
    sources = _monkeys(bpy, 3)
    before = set(bpy.data.objects)
    assert bpy.ops.tessera.tessellate(method="PN", level=2) == {"FINISHED"}
    made = set(bpy.data.objects) - before
    assert len(made) == 3
    # each result sits on its own source (the transform and the place are the source's)
    for ob in made:
        source = next(s for s in sources if ob.name == f"{s.name}.tessellated")
        assert np.allclose(np.array(ob.matrix_world), np.array(source.matrix_world))
        assert len(ob.data.polygons) > 4 * len(source.data.polygons)
    assert set(bpy.context.selected_objects) == made
    assert bpy.context.view_layer.objects.active in made


def test_one_failure_leaves_nothing_of_the_others(clean_scene, bpy_module):
    bpy = bpy_module
    sources = _monkeys(bpy, 2)
    empty = bpy.data.objects.new("Empty mesh", bpy.data.meshes.new("Empty mesh"))  # nothing to subdivide
    bpy.context.collection.objects.link(empty)
    empty.select_set(True)
    meshes, objects = set(bpy.data.meshes), set(bpy.data.objects)
    with pytest.raises(RuntimeError):  # the report of the one that failed
        bpy.ops.tessera.loop_subdivide(levels=1)
    assert set(bpy.data.objects) == objects and set(bpy.data.meshes) == meshes
    assert all(ob.name in bpy.data.objects for ob in sources)


def test_only_the_active_object_when_nothing_else_is_selected(clean_scene, bpy_module):
    bpy = bpy_module
    first, second = _monkeys(bpy, 2)
    second.select_set(False)
    bpy.context.view_layer.objects.active = first
    before = set(bpy.data.objects)
    assert bpy.ops.tessera.loop_subdivide(levels=1) == {"FINISHED"}
    assert len(set(bpy.data.objects) - before) == 1

"""What an operator leaves selected: its results, the last one active."""


def select_only(context, objects):
    """Deselect everything, select ``objects`` and make the last of them active (if any)."""
    for other in context.selected_objects:
        other.select_set(False)
    for ob in objects:
        ob.select_set(True)
    if objects:
        context.view_layer.objects.active = objects[-1]

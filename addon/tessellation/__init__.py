"""Tessellation in Blender ([Nellmedin 2014, §5]): the settings shared by the operator and
``Object.tessera.tessellate``, the live GPU preview, the panel and the PN and Phong node groups."""

"""Surfaces and curves generated where they are needed.

[Nunes 2011, §2.3–2.4]: parametric surfaces generated from one control point (a quad domain of factor F
evaluated by a formula: (F + 1)² domain vertices, 2F² triangles). `parametric` holds the surfaces (the coded
equations of [Nunes 2011], Steiner's Roman surface included, and the ones an artist wants) with the way each one's
domain closes; `domain_mesh` the quad-domain pattern, its welded mesh (seams, poles) and the many-instances case.
"""

"""Loop subdivision of triangle meshes ([Concheiro et al.], Part A).

`loop_rules` holds the factored form's weights (correction factor cf(n), Loop's beta) and OpenSubdiv's crease
arithmetic; `loop_topology` the edge structure of one level and its analytic refinement (no sort after the coarse
level); `loop` the entry point: positions and point data through the factored rules (linear subdivision ->
averaging -> correction), corner data on its own face-varying mesh with linear boundaries, faces numbered
``4 * parent + slot`` in [Concheiro et al.]'s T/L/C/R order.
"""

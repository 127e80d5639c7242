"""PN-triangle, Phong and linear tessellation with adaptive, crack-free edge levels.

Seeds: 000 §3 (PN triangles vs Phong tessellation, the tessellator's patterns, §2) and 001 §2, §4, §5 (the
pipeline, the metrics: distance, projected edge length, silhouette, curvature κ⁺). `refine` builds the
hardware tessellator's refinement for a whole mesh (`refine_general` for any mix of levels, `refine_templates`
per pattern class), `patches` and `surface_eval` place the points on the PN or Phong surface, `interpolate`
carries attributes (``gather_weighted.cl``), `metrics` and `adaptive` choose the levels, `tessellate` is the
entry point, `patch_instances` prepares the GPU preview's instanced patterns.
"""

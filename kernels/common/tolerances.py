"""Numeric tolerances used across kernels and tests: one place, so they cannot drift apart."""

#: Relative tolerance when a float32 path (OpenCL, GPU) is compared with the float64-accumulating numpy reference.
FLOAT32_PATH_RTOL = 1e-6
#: Absolute tolerance for the same comparison, for values near zero.
FLOAT32_PATH_ATOL = 1e-6
#: Tolerance for "exact" reproduction of linear attributes (float32 storage of the result).
LINEAR_REPRODUCTION_ATOL = 2e-6
#: Two unit normals whose dot product is at least this are the same normal (not a split / sharp edge).
SAME_NORMAL_DOT = 1.0 - 1e-6
#: A face whose corner normals all lie within this (per component) of its first corner's is flat-shaded.
FLAT_FACE_NORMAL_ATOL = 1e-6
#: Tolerance of the curved-patch identities (linear precision, projections) in float64 tests.
PATCH_IDENTITY_ATOL = 1e-12

# Guards in the kernels' own arithmetic (not test tolerances): named here so the same meaning has one value.

#: A float64 divisor floor: a length, weight or denominator below this counts as zero, so dividing by
#: ``max(x, FLOAT64_TINY)`` gives 0 for a zero numerator instead of NaN.
FLOAT64_TINY = 1e-300
#: The same floor for float32 arithmetic (geometry-node graphs, GPU read-backs), well above float32's smallest normal.
FLOAT32_TINY = 1e-30
#: A float64 vector (or weight) shorter than this has no direction: normalising it would only amplify round-off.
NO_DIRECTION = 1e-12
#: Slack for float64 round-off where a computed value should land exactly on a whole number or an interval's end.
ROUND_OFF_SLACK = 1e-9
#: Alpha below this counts as transparent where premultiplied colours are divided by their alpha.
ALPHA_FLOOR = 1e-6

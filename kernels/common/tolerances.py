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

"""The largest magnitudes Tessera accepts for a setting, by kind: past them float32 carries no precision, or the
value can only be a typing slip. The add-on gives every numeric property a hard range from these, and the
guarded operator path refuses NaN (the one value Blender does not clamp) with the setting's name and range.
"""

#: Distances, sizes and offsets in world units (texel size, height scale, radii, near/far, map values).
MAX_WORLD_VALUE = 1e15
#: Lengths on screen or in map texels (target edge pixels, brush radius, noise size).
MAX_PIXELS = 1e5
#: Gains, strengths and other unit-free factors.
MAX_FACTOR = 1e6

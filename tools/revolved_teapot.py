"""A model of bicubic patches for the tests, benches and demo (not shipped): the body of revolution of Newell's Utah
teapot (rim, body, lid and bottom: 24 of its 32 patches; the handle and the spout are left out), made from his
profile curves, each revolved as four quadrant patches (the around-direction control points at r, 0.56 r as in his
data). The lid's top and the bottom's centre collapse to a point on the axis, as in the original, and the lid's
knob folds back on itself."""

import numpy as np

#: The profile cubics (r, z), bottom to top as Newell ordered each section.
PROFILES = {
    "rim": ((1.4, 2.4), (1.3375, 2.53125), (1.4375, 2.53125), (1.5, 2.4)),
    "body_upper": ((1.5, 2.4), (1.75, 1.875), (2.0, 1.35), (2.0, 0.9)),
    "body_lower": ((2.0, 0.9), (2.0, 0.45), (1.5, 0.225), (1.5, 0.15)),
    "lid_top": ((0.0, 3.15), (0.8, 3.15), (0.0, 2.85), (0.2, 2.7)),
    "lid_bottom": ((0.2, 2.7), (0.4, 2.55), (1.3, 2.55), (1.3, 2.4)),
    "bottom": ((1.5, 0.15), (1.5, 0.075), (1.425, 0.0), (0.0, 0.0)),
}
CIRCLE = 0.56


def revolve(profile):
    """Four quadrant patches (4, 4, 4, 3) of a profile cubic: control[i, j] = profile point i turned to the j-th
    point of the quarter circle (u along the profile, v around)."""
    p = np.asarray(profile, np.float64)
    quarter = np.array([[1.0, 0.0], [1.0, CIRCLE], [CIRCLE, 1.0], [0.0, 1.0]])  # times r, in the quadrant's frame
    out = np.empty((4, 4, 4, 3))
    for q in range(4):
        a = q * np.pi / 2
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        xy = np.round(quarter @ rot.T, 15)  # exact 0 and ±1 on the axes, so quadrants share their seams exactly
        out[q, :, :, :2] = p[:, 0, None, None] * xy[None]
        out[q, :, :, 2] = p[:, 1, None]
    return out


def teapot_patches():
    """(24, 4, 4, 3) float64 control nets, and the section name of each patch (24,)."""
    nets, names = [], []
    for name, profile in PROFILES.items():
        nets.append(revolve(profile))
        names += [name] * 4
    return np.concatenate(nets), np.array(names)

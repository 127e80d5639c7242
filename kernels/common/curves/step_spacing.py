"""Steps spaced where a curve bends, for a tolerance: the chord of a step h at t strays about |C''(t)| h² / 8 from
the curve, so steps of equal ρ h with the density ρ = √|C''| stray equally, and n such steps stray about
(∫ρ)² / 8n² where n equal steps stray max(ρ)² / 8n² ([de Boor 1978, ch. III], the equidistribution of the
interpolation error; references.md). A curve that bends in one part gets its steps there, not everywhere.

A spacing is a cumulative table (S, SAMPLES + 1): the share of ∫ρ up to each of SAMPLES + 1 equal parameters
k / SAMPLES, from 0 to 1, strictly increasing; n steps of it are the parameters where it reaches i / n
(`params`). ρ is measured from second differences of the curve's points, and floored at FLOOR of its largest value,
so no step is more than 1 / FLOOR times another and a straight curve (ρ = 0) gets equal steps.
"""

import numpy as np

#: Equal parts of the parameter on which the density is measured.
SAMPLES = 32
#: The density is at least this share of its largest value: steps differ by 1 / FLOOR at most.
FLOOR = 0.2


def cumulative(density):
    """Cumulative tables (S, M + 1) of densities (S, M) given on M equal parts of [0, 1]: from 0 to exactly 1,
    strictly increasing (the density floored at FLOOR of each row's largest; a row of zeros: equal steps)."""
    rho = np.asarray(density, np.float64)
    top = rho.max(axis=1, keepdims=True)
    rho = np.where(top > 0, np.maximum(rho, FLOOR * top), 1.0)
    cum = np.concatenate([np.zeros((len(rho), 1)), np.cumsum(rho, axis=1)], axis=1)
    cum /= cum[:, -1:]
    cum[:, -1] = 1.0
    return cum


def bend_density(points):
    """√ of the second differences' lengths of points (S, 2M + 1, 3) at equal parameter steps 1 / 2M: the density
    (S, M) on each of M equal parts (the part's midpoint's second difference)."""
    p = np.asarray(points, np.float64)
    m = (p.shape[1] - 1) // 2
    second = p[:, 0:-2:2] - 2.0 * p[:, 1:-1:2] + p[:, 2::2]
    return np.sqrt(np.linalg.norm(second, axis=-1) * (2.0 * m) ** 2)


def params(cum, n):
    """Parameters (S, n + 1) of n steps of each spacing table cum (S, M + 1): from exactly 0 to exactly 1."""
    cum = np.asarray(cum, np.float64)
    return padded_params(cum, np.full(len(cum), int(n)))


def padded_params(cum, counts):
    """Each table's parameters at its own step count: cum (S, M + 1), counts (S,) int -> (S, max count + 1)
    float64, each row from 0 to 1 in counts[s] steps, padded with 1 past its end. All rows at once: the share
    i / n each step reaches, found in its table's cumulative shares, and the parameter interpolated in that
    part."""
    cum = np.asarray(cum, np.float64)
    counts = np.asarray(counts, np.int64)
    top = int(counts.max(initial=1))
    m = cum.shape[1] - 1
    i = np.arange(top + 1)[None]
    y = i / np.maximum(counts, 1)[:, None]  # (S, top + 1): the shares i / n
    idx = np.clip((cum[:, None, :] <= y[:, :, None]).sum(axis=2) - 1, 0, m - 1)
    c0 = np.take_along_axis(cum, idx, axis=1)
    c1 = np.take_along_axis(cum, idx + 1, axis=1)
    t = (idx + (y - c0) / (c1 - c0)) / m
    t[:, 0] = 0.0
    t = np.where(i >= counts[:, None], 1.0, t)  # each row's last point exactly 1, and past it
    return np.clip(t, 0.0, 1.0)

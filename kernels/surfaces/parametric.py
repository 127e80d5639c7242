"""Parametric surfaces over the unit square ([Nunes 2011, §2.3], the coded versions of eqs. 2-1 … 2-4).

Each surface is a frozen dataclass of its shape parameters with ``point(u, v) -> (..., 3) float64`` for domain
coordinates ``u, v`` in [0, 1] (any matching shapes), and a `Closure` saying how its domain's edges meet:
``PERIODIC`` (the u = 0 edge is the u = 1 edge, v for v), ``TWISTED`` (u = 0 at v is u = 1 at 1 - v: Möbius band,
Klein bottle, Steiner's surface), and the edges that collapse to one point (poles, apexes). `domain_mesh` welds
by these rules, never by comparing positions, so self-intersecting surfaces (Klein bottle, Steiner) keep their
sheets apart. ``flip`` is set where the formula's (du, dv) orientation points inward, so closed orientable
surfaces come out with outward normals.

[Nunes 2011]'s debug colour is ``normalize(p) + 0.6`` for the sphere and ``+ 0.4`` for the others (`debug_colour`).
"""

from dataclasses import dataclass, field

import numpy as np

from ..common.errors import InvalidInputError

NONE, PERIODIC, TWISTED = "NONE", "PERIODIC", "TWISTED"
TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Closure:
    """How a surface's domain closes: ``u`` and ``v`` are NONE, PERIODIC or TWISTED (the edge u = 0 meets u = 1,
    v reversed); ``collapse``: the domain edges ("u0", "u1", "v0", "v1") that map to a single point."""

    u: str = NONE
    v: str = NONE
    collapse: tuple = ()
    flip: bool = False


def parameter(default, label, description, unit="LENGTH"):
    """A shape parameter: a dataclass field whose metadata says how settings show it (``label``, ``description``,
    ``unit``: "LENGTH" for a size in scene units, "NONE" for a plain number such as an exponent)."""
    return field(default=default, metadata={"label": label, "description": description, "unit": unit})


def _stack(x, y, z):
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1).astype(np.float64)


def _positive(**values):
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise InvalidInputError(f"The surface's {name} must be a positive number; got {value!r}")


@dataclass(frozen=True)
class Sphere:
    """Eq. 2-1 as coded: φ = π u (from the +z pole), θ = 2π v."""

    radius: float = parameter(1.0, "Radius", "Radius of the sphere")
    closure = Closure(v=PERIODIC, collapse=("u0", "u1"))
    colour_offset = 0.6

    def point(self, u, v):
        _positive(radius=self.radius)
        fi, theta = np.pi * np.asarray(u, np.float64), TWO_PI * np.asarray(v, np.float64)
        r = self.radius
        return _stack(r * np.sin(fi) * np.cos(theta), r * np.sin(fi) * np.sin(theta), r * np.cos(fi))


@dataclass(frozen=True)
class Cone:
    """Eq. 2-2 as coded: θ = 2π u, s = v from the base circle (z = 0, radius R) to the apex (z = H). Open at the
    base."""

    radius: float = parameter(0.5, "Radius", "Radius of the base circle")
    height: float = parameter(1.5, "Cone Height", "Height of the apex above the base")
    closure = Closure(u=PERIODIC, collapse=("v1",))
    colour_offset = 0.4

    def point(self, u, v):
        _positive(radius=self.radius, height=self.height)
        theta, s = TWO_PI * np.asarray(u, np.float64), np.asarray(v, np.float64)
        h, r = self.height, self.radius
        k = (h - s * h) / h * r
        return _stack(k * np.cos(theta), k * np.sin(theta), s * h)


@dataclass(frozen=True)
class Torus:
    """Eq. 2-3 as coded: s = 2π u around z, t = 2π v around the tube; M the ring radius, N the tube radius."""

    major: float = parameter(1.0, "Ring Radius", "Distance from the centre to the middle of the tube")
    minor: float = parameter(0.5, "Tube Radius", "Radius of the tube")
    closure = Closure(u=PERIODIC, v=PERIODIC)
    colour_offset = 0.4

    def point(self, u, v):
        _positive(major=self.major, minor=self.minor)
        s, t = TWO_PI * np.asarray(u, np.float64), TWO_PI * np.asarray(v, np.float64)
        ring = self.major + self.minor * np.cos(t)
        return _stack(ring * np.cos(s), ring * np.sin(s), self.minor * np.sin(t))


@dataclass(frozen=True)
class Steiner:
    """Steiner's Roman surface, eq. 2-4 as coded ([Nunes 2011, correction 1]: y = a² sin u sin 2v / 2, not sin u sin v),
    u = π u, v = π v. Closes as the projective plane: v = 0 meets v = 1, and u = 0 at v meets u = 1 at 1 - v."""

    a: float = parameter(1.0, "Size", "Size of the surface: it reaches half the square of this from its centre")
    closure = Closure(u=TWISTED, v=PERIODIC)
    colour_offset = 0.4
    #: The surface point is (AB, BC, AC) a² of the hemisphere point (A, B, C) = (cos u cos v, sin u cos v, sin v),
    #: which covers the closed upper hemisphere once: the projective plane. The domain's middle row v = 1/2 is the
    #: hemisphere's pole, one point (the origin): welded as such when F is even.
    middle_row = True

    def point(self, u, v):
        _positive(a=self.a)
        uu, vv = np.pi * np.asarray(u, np.float64), np.pi * np.asarray(v, np.float64)
        a2 = self.a * self.a
        return _stack(a2 * np.cos(vv) ** 2 * np.sin(2 * uu) / 2, a2 * np.sin(uu) * np.sin(2 * vv) / 2,
                      a2 * np.cos(uu) * np.sin(2 * vv) / 2)


@dataclass(frozen=True)
class KleinBottle:
    """The figure-8 Klein bottle: θ = 2π u around z, φ = 2π v along the figure 8 of half-width 1 at radius r."""

    radius: float = parameter(2.0, "Radius", "Radius of the circle the figure-8 cross-section sweeps along")
    closure = Closure(u=TWISTED, v=PERIODIC)
    colour_offset = 0.4

    def point(self, u, v):
        _positive(radius=self.radius)
        th, ph = TWO_PI * np.asarray(u, np.float64), TWO_PI * np.asarray(v, np.float64)
        w = self.radius + np.cos(th / 2) * np.sin(ph) - np.sin(th / 2) * np.sin(2 * ph)
        return _stack(w * np.cos(th), w * np.sin(th), np.sin(th / 2) * np.sin(ph) + np.cos(th / 2) * np.sin(2 * ph))


@dataclass(frozen=True)
class MobiusBand:
    """A Möbius band of ring radius 1 (times ``radius``) and the given width: t = 2π u, s = width (v - 1/2)."""

    radius: float = parameter(1.0, "Radius", "Radius of the band's middle circle")
    width: float = parameter(0.8, "Band Width", "Width of the band")
    closure = Closure(u=TWISTED)
    colour_offset = 0.4

    def point(self, u, v):
        _positive(radius=self.radius, width=self.width)
        t, s = TWO_PI * np.asarray(u, np.float64), self.width * (np.asarray(v, np.float64) - 0.5)
        ring = self.radius + s * np.cos(t / 2)
        return _stack(ring * np.cos(t), ring * np.sin(t), s * np.sin(t / 2))


@dataclass(frozen=True)
class TrefoilTube:
    """A tube of radius ``tube`` around the trefoil knot c(t) = (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t) ×
    ``scale``, t = 2π u, on its Frenet frame (periodic: the trefoil's curvature never vanishes), φ = 2π v."""

    scale: float = parameter(0.3, "Knot Size", "Size of the knot's path (its loops reach about three times this)")
    tube: float = parameter(0.12, "Tube Radius", "Radius of the tube around the knot")
    closure = Closure(u=PERIODIC, v=PERIODIC, flip=True)
    colour_offset = 0.4

    def point(self, u, v):
        _positive(scale=self.scale, tube=self.tube)
        t, phi = TWO_PI * np.asarray(u, np.float64), TWO_PI * np.asarray(v, np.float64)
        c = _stack(np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t))
        d1 = _stack(np.cos(t) + 4 * np.cos(2 * t), -np.sin(t) + 4 * np.sin(2 * t), -3 * np.cos(3 * t))
        d2 = _stack(-np.sin(t) - 8 * np.sin(2 * t), -np.cos(t) + 8 * np.cos(2 * t), 9 * np.sin(3 * t))
        tangent = d1 / np.linalg.norm(d1, axis=-1, keepdims=True)
        b = np.cross(d1, d2)
        binormal = b / np.linalg.norm(b, axis=-1, keepdims=True)
        normal = np.cross(binormal, tangent)
        ring = np.cos(phi)[..., None] * normal + np.sin(phi)[..., None] * binormal
        return self.scale * c + self.tube * ring


def cos_sin_turns(t):
    """(cos 2πt, sin 2πt), exact at quarter turns (each is computed on [0, 1/4) and turned by whole quarters), for
    the superellipsoid, whose powers |x|^e turn cos(π/2) ≈ 6e-17 (or -4e-8 in float32) into visible offsets."""
    t = np.asarray(t, np.float64)
    q = np.floor(4.0 * t)
    r = t - q / 4.0
    c, s = np.cos(TWO_PI * r), np.sin(TWO_PI * r)
    k = q.astype(np.int64) % 4
    return np.choose(k, [c, -s, -c, s]), np.choose(k, [s, c, -s, -c])


@dataclass(frozen=True)
class Superellipsoid:
    """x = a cos^e1(η) cos^e2(ω), y = a cos^e1(η) sin^e2(ω), z = a sin^e1(η) (signed powers), η = π (1/2 - u)
    from the +z pole, ω = 2π v. e1 = e2 = 1 is the sphere; small exponents tend to a cube, 2 to an octahedron.
    Angles go through `cos_sin_turns`, so the poles and the four meridians' zeros are exact (GPU likewise)."""

    size: float = parameter(1.0, "Size", "Half the height and width of the shape")
    e1: float = parameter(0.5, "Vertical Shape", "Top to bottom: 1 round, toward 0 square, 2 pointed", "NONE")
    e2: float = parameter(0.5, "Horizontal Shape", "Around the middle: 1 round, toward 0 square, 2 pointed", "NONE")
    closure = Closure(v=PERIODIC, collapse=("u0", "u1"))
    colour_offset = 0.4

    def point(self, u, v):
        _positive(size=self.size, e1=self.e1, e2=self.e2)
        cos_eta, sin_eta = cos_sin_turns(0.25 - 0.5 * np.asarray(u, np.float64))
        cos_om, sin_om = cos_sin_turns(np.asarray(v, np.float64))

        def sp(x, e):
            return np.sign(x) * np.abs(x) ** e

        ce = sp(cos_eta, self.e1)
        return self.size * _stack(ce * sp(cos_om, self.e2), ce * sp(sin_om, self.e2), sp(sin_eta, self.e1))


#: Every surface by the name the operator and the settings use.
SURFACES = {"SPHERE": Sphere, "CONE": Cone, "TORUS": Torus, "STEINER": Steiner, "KLEIN": KleinBottle,
            "MOBIUS": MobiusBand, "TREFOIL": TrefoilTube, "SUPERELLIPSOID": Superellipsoid}


def debug_colour(surface, points):
    """[Nunes 2011]'s debug colour: normalize(p) + 0.6 (sphere) or + 0.4 (the others): (..., 3) float64."""
    p = np.asarray(points, np.float64)
    length = np.linalg.norm(p, axis=-1, keepdims=True)
    unit = np.divide(p, length, out=np.zeros_like(p), where=length > 0)
    return unit + surface.colour_offset

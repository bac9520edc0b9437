// Sampling routines shared by the stages: orthonormal bases, cosine-weighted hemisphere
// directions and uniform points on triangles. Lane-wise (lanes.h).
#ifndef FH_SAMPLING_H
#define FH_SAMPLING_H

#include "lanes.h"

// A right-handed basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017).
FH_INLINE void orthonormal_basis(lvec3 n, lvec3* t, lvec3* b) {
  const lfloat sign = copysign((lfloat)(1.0f), n.z);
  const lfloat a = -1.0f / (sign + n.z);
  const lfloat c = n.x * n.y * a;
  *t = v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = v3(c, sign + n.y * n.y * a, -n.y);
}

// sin and cos on [-pi/4, pi/4] by their Taylor series to degree 9 and 8 (errors below
// 1e-8): PoCL's sin/cos take a third of the shade stage with their general argument
// reduction, and the concentric mapping needs no wider range. (x: sin, y: cos.)
FH_INLINE lvec2 sincos_quarter(lfloat x) {
  const lfloat x2 = x * x;
  const lfloat s = x * (1.0f + x2 * (-1.0f / 6.0f + x2 * (1.0f / 120.0f + x2 * (-1.0f / 5040.0f + x2 / 362880.0f))));
  const lfloat c = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24.0f + x2 * (-1.0f / 720.0f + x2 / 40320.0f)));
  return lv2(s, c);
}

// sin and cos of any moderate angle: reduced by quarter turns to [-pi/4, pi/4].
FH_INLINE lvec2 sincos_reduced(lfloat x) {
  const lfloat k = rint(x * M_2_PI_F);
  const lvec2 sc = sincos_quarter(x - k * M_PI_2_F);
  const lint quarter = lconvert_int(k) & 3;
  // Odd quarter turns swap sin and cos; turns 2 and 3 negate the sine, 1 and 2 the cosine.
  const lmask swap = (quarter & 1) != 0;
  const lfloat s = select(sc.x, sc.y, swap), c = select(sc.y, sc.x, swap);
  return lv2(select(s, -s, quarter >= 2), select(c, -c, quarter == 1 || quarter == 2));
}

// A uniform point on the unit disk from [0,1)^2 by Shirley and Chiu's concentric
// mapping (area-preserving, so stratified inputs stay stratified).
FH_INLINE lvec2 sample_concentric_disk(lfloat u1, lfloat u2) {
  const lfloat a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  const lmask centre = a == 0.0f && b == 0.0f;
  // |a| > |b|: phi = (pi/4)(b/a), the point a (cos phi, sin phi). Otherwise phi =
  // pi/2 - (pi/4)(a/b): cos(phi) = sin(theta), sin(phi) = cos(theta), with theta = (pi/4)(a/b).
  const lmask wide = fabs(a) > fabs(b);
  const lfloat r = select(b, a, wide);
  const lvec2 sc = sincos_quarter(M_PI_4_F * (select(a, b, wide) / select(r, (lfloat)(1.0f), centre)));
  const lfloat x = r * select(sc.x, sc.y, wide), y = r * select(sc.y, sc.x, wide);
  return lv2(select(x, (lfloat)(0.0f), centre), select(y, (lfloat)(0.0f), centre));
}

// Cosine-weighted direction about unit n from (u1, u2) in [0,1)^2 (Malley's method: a
// uniform disk point lifted to the hemisphere); pdf = cos / pi.
FH_INLINE lvec3 sample_cosine_hemisphere(lvec3 n, lfloat u1, lfloat u2) {
  const lvec2 d = sample_concentric_disk(u1, u2);
  lvec3 t, b;
  orthonormal_basis(n, &t, &b);
  const lfloat lift = sqrt(fmax(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return v3_normalize(v3_add(v3_add(v3_scale(t, d.x), v3_scale(b, d.y)), v3_scale(n, lift)));
}

// Per lane, the first of the `count` entries of a CDF starting at cdf[first] that exceeds
// u (the last entry if none does), counted from first. A binary search without branches:
// every lane takes the same steps, a gather and a select each, so the lanes search side by
// side instead of one after another, each step a branch that mispredicts half the time.
// `base` stays at the last entry known <= u (or the first).
FH_INLINE luint search_cdf(__global const float* cdf, luint first, uint count, lfloat u) {
  luint base = (luint)(0u);
  for (uint len = count; len > 1;) {
    const uint step = len / 2;
    base = select(base, base + step, gather_float(cdf, first + base + step) <= u);
    len -= step;
  }
  const luint above = select((luint)(0u), (luint)(1u), gather_float(cdf, first + base) <= u);
  return min(base + above, (luint)(count - 1));
}

// One coordinate of a 2D sample can make a discrete choice (a light) and then, where
// it fell within the chosen option's share [lo, hi), stretched to [0, 1), still serve the
// continuous sample that follows: a stratified set of 2D samples then stays stratified
// over the options taken together, where a choice by a number of its own leaves each
// option a random subset of the points. A share narrower than FH_NARROW_SHARE keeps too
// few of the coordinate's bits (a float has 24) to stretch, so there the caller draws the
// coordinate on its own. A test hook may set FH_NARROW_SHARE to 2, so every share counts
// as narrow (host/base/test_hooks.h).
#ifndef FH_NARROW_SHARE
#define FH_NARROW_SHARE (1.0f / 64.0f)
#endif

FH_INLINE lfloat within_share(lfloat u, lfloat lo, lfloat hi) {
  return clamp((u - lo) / (hi - lo), 0.0f, 0x1.fffffep-1f);
}

// Barycentrics (b1, b2) of a uniform point on a triangle.
FH_INLINE lvec2 sample_triangle(lfloat u1, lfloat u2) {
  const lfloat su = sqrt(u1);
  return lv2(su * u2, 1.0f - su);
}

#endif

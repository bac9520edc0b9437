// Light sampling for next-event estimation: an emissive triangle chosen in proportion
// to its power (a CDF over the light list), then a point on it: uniform in the solid angle
// it subtends where that is well conditioned (Arvo 1995), else uniform in area (the area
// formulation: Le f G V / p_area, with p_area = P(triangle) / area). Solid-angle sampling
// bounds the estimate where area sampling's 1/r^2 is unbounded: a light next to the
// receiver, e.g. across a concave edge of an emitting room, where area sampling's variance
// is infinite. Lane-wise (lanes.h).
#ifndef FH_LIGHTS_H
#define FH_LIGHTS_H

#include "ray.h"
#include "sampling.h"

// The first light whose CDF value exceeds u (the last light if none does), for each lane.
FH_INLINE luint pick_light(__global const float* cdf, uint count, lfloat u) {
  return search_cdf(cdf, (luint)(0u), count, u);
}

// Light sampling picks the light by its 2D sample's second coordinate, which, stretched
// within the light's share of the table (sampling.h, within_share), then places the point.
typedef struct {
  luint light;    // its index in the table
  lfloat within;  // where u fell within its share, in [0, 1)
  lmask narrow;   // the share is too narrow for `within` to be used
} LightPick;

// The table's entries start at `start` (the environment map's share lies below it).
FH_INLINE LightPick pick_light_within(__global const float* cdf, uint count, float start, lfloat u) {
  LightPick p;
  p.light = pick_light(cdf, count, u);
  const lfloat lo = select(gather_float(cdf, max(p.light, (luint)(1u)) - 1u), (lfloat)(start), p.light == 0u);
  const lfloat hi = gather_float(cdf, p.light);
  p.within = within_share(u, lo, hi);
  p.narrow = !(hi - lo >= FH_NARROW_SHARE);
  return p;
}

// Converts an area density at a point seen at distance^2 `dist2` under cosine `cos_light`
// to a solid-angle density at the receiver.
FH_INLINE lfloat area_to_solid_angle(lfloat pdf_area, lfloat dist2, lfloat cos_light) {
  return select((lfloat)(0.0f), pdf_area * dist2 / cos_light, cos_light > 0.0f);
}

// A triangle as seen from a point: unit directions to its corners and its solid angle
// (Van Oosterom and Strackee 1983).
typedef struct {
  lvec3 a, b, c;
  lfloat solid_angle;
} SphericalTriangle;

FH_INLINE SphericalTriangle spherical_triangle(lvec3 o, lvec3 v0, lvec3 v1, lvec3 v2) {
  SphericalTriangle t;
  t.a = v3_normalize(v3_sub(v0, o));
  t.b = v3_normalize(v3_sub(v1, o));
  t.c = v3_normalize(v3_sub(v2, o));
  const lfloat triple = fabs(v3_dot(t.a, v3_cross(t.b, t.c)));
  t.solid_angle = 2.0f * atan2(triple, 1.0f + v3_dot(t.a, t.b) + v3_dot(t.b, t.c) + v3_dot(t.c, t.a));
  return t;
}

// The triangle as light sampling sees it from o: by solid angle (solid_angle > 0) when it
// is large for its distance (area above a quarter of the squared distance to its centroid),
// where area sampling's 1/r^2 makes the estimate spiky, and the spherical triangle is
// neither so small that its angles lose precision in float nor nearly a hemisphere
// (pbrt-v4's bounds); by area (solid_angle 0) otherwise, which costs less and is about as
// good for small or distant lights. Light samples and the MIS weights of BSDF-found
// emission both decide by this.
FH_INLINE SphericalTriangle light_seen_from(lvec3 o, lvec3 v0, lvec3 v1, lvec3 v2, lfloat area) {
  const lvec3 to_centroid = v3_sub(v3_scale(v3_add(v3_add(v0, v1), v2), 1.0f / 3.0f), o);
  const lmask large = area > 0.25f * v3_dot(to_centroid, to_centroid);
  SphericalTriangle t;
  if (lanes_any(large)) {
    t = spherical_triangle(o, v0, v1, v2);
    t.solid_angle = select((lfloat)(0.0f), t.solid_angle, large && t.solid_angle > 3e-4f && t.solid_angle < 6.22f);
  } else {
    t.a = t.b = t.c = v3_splat(0.0f);
    t.solid_angle = (lfloat)(0.0f);
  }
  return t;
}

FH_INLINE lvec3 normalize_or(lvec3 v, lvec3 fallback) {
  const lfloat len2 = v3_dot(v, v);
  return v3_select(len2 > 0.0f, v3_scale(v, rsqrt(len2)), fallback);
}

// A direction uniform in the spherical triangle (Arvo, "Stratified sampling of spherical
// triangles", 1995): u1 picks the sub-triangle with area u1 * solid angle, which fixes its
// third corner on the arc a-c; u2 picks a point on the arc from b to that corner.
FH_INLINE lvec3 sample_spherical_triangle(const SphericalTriangle* t, lfloat u1, lfloat u2) {
  const lvec3 a = t->a, b = t->b, c = t->c;
  // The angle at corner a between the great circles a-b and a-c.
  const lvec3 n_ab = normalize_or(v3_cross(a, b), v3_splat(0.0f)), n_ac = normalize_or(v3_cross(a, c), v3_splat(0.0f));
  const lfloat cos_alpha = clamp(v3_dot(n_ab, n_ac), -1.0f, 1.0f);
  const lfloat sin_alpha = sqrt(fmax(0.0f, 1.0f - cos_alpha * cos_alpha));
  // sin and cos of (u1 * solid angle - alpha), by the angle-difference identities.
  const lvec2 sc = sincos_reduced(u1 * t->solid_angle);
  const lfloat s = sc.x * cos_alpha - sc.y * sin_alpha, tt = sc.y * cos_alpha + sc.x * sin_alpha;
  const lfloat u = tt - cos_alpha, v = s + sin_alpha * v3_dot(a, b);
  const lfloat denominator = (v * s + u * tt) * sin_alpha;
  const lfloat q = select((lfloat)(1.0f), clamp(((v * tt - u * s) * cos_alpha - v) / denominator, -1.0f, 1.0f),
                          denominator != 0.0f);
  const lvec3 c_hat = v3_add(v3_scale(a, q), v3_scale(normalize_or(v3_sub(c, v3_scale(a, v3_dot(c, a))), c),
                                                      sqrt(fmax(0.0f, 1.0f - q * q))));
  const lfloat z = 1.0f - u2 * (1.0f - v3_dot(c_hat, b));
  return v3_normalize(v3_add(v3_scale(b, z), v3_scale(normalize_or(v3_sub(c_hat, v3_scale(b, v3_dot(c_hat, b))), c_hat),
                                                      sqrt(fmax(0.0f, 1.0f - z * z)))));
}

// Barycentrics (b1, b2) of the point where the ray o + s w meets the plane of the triangle
// (Moller-Trumbore), clamped into the triangle: a direction drawn inside the spherical
// triangle hits it up to rounding.
FH_INLINE lvec2 barycentrics_along(lvec3 o, lvec3 w, lvec3 v0, lvec3 v1, lvec3 v2) {
  const lvec3 e1 = v3_sub(v1, v0), e2 = v3_sub(v2, v0), p = v3_cross(w, e2), d = v3_sub(o, v0), q = v3_cross(d, e1);
  const lfloat inv = 1.0f / v3_dot(e1, p);
  const lfloat b1 = clamp(v3_dot(d, p) * inv, 0.0f, 1.0f), b2 = clamp(v3_dot(w, q) * inv, 0.0f, 1.0f);
  const lfloat excess = fmax(b1 + b2 - 1.0f, 0.0f);
  return lv2(b1 - 0.5f * excess, b2 - 0.5f * excess);
}

// A light triangle as light sampling treats it from a receiver's ray origin: its corners,
// area, the chance `pick` that light sampling chooses it, and how it is sampled from there
// (seen.solid_angle > 0: by solid angle). shadow_connect samples with it and shade weighs
// BSDF-found emission with it, so both use one density (light_pdf) for the same point.
typedef struct {
  lvec3 v0, v1, v2;
  lfloat area, pick;
  SphericalTriangle seen;
} LightTriangle;

FH_INLINE LightTriangle light_triangle_from(__global const float4* triangles, lint t, lfloat pdf_area, lvec3 origin) {
  LightTriangle l;
  l.v0 = triangle_corner(triangles, t, 0);
  l.v1 = triangle_corner(triangles, t, 1);
  l.v2 = triangle_corner(triangles, t, 2);
  l.area = 0.5f * v3_length(v3_cross(v3_sub(l.v1, l.v0), v3_sub(l.v2, l.v0)));
  l.pick = pdf_area * l.area;  // pdf_area = P(triangle) / area
  l.seen = light_seen_from(origin, l.v0, l.v1, l.v2, l.area);
  return l;
}

// The density (per solid angle at the receiver) with which light sampling picks a point of
// light triangle l at squared distance dist2, seen under cos_light.
FH_INLINE lfloat light_pdf(const LightTriangle* l, lfloat dist2, lfloat cos_light) {
  return select(area_to_solid_angle(l->pick / l->area, dist2, cos_light), l->pick / l->seen.solid_angle,
                l->seen.solid_angle > 0.0f);
}

// The power heuristic (beta = 2) weight of a sample drawn with density `a` against `b`.
FH_INLINE lfloat power_heuristic(lfloat a, lfloat b) {
  const lfloat a2 = a * a, b2 = b * b;
  return select((lfloat)(0.0f), a2 / (a2 + b2), a2 + b2 > 0.0f);
}

#endif

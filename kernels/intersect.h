// Ray casting against the 8-wide BVH: the watertight ray/triangle test of Woop, Benthin
// and Wald (JCGT 2013), a conservative float8 slab test (Ize 2013), and stack traversal
// with near-to-far child order. Used by intersect.cl and anything else that casts rays.
#ifndef FH_INTERSECT_H
#define FH_INTERSECT_H

#include "types.h"

// Watertightness needs the edge functions of two triangles that share an edge to be
// exact negatives of each other; a fused multiply-add would round one product and not
// the other, opening cracks along shared edges.
#pragma OPENCL FP_CONTRACT OFF

// The host passes the stack depth its BVH needs (7 per wide level + 1) as a build option.
#ifndef FH_TRAVERSAL_STACK
#define FH_TRAVERSAL_STACK 64
#endif

// Per-ray constants of the watertight test: the axis the ray is most aligned with
// (kz) and the shear that maps the ray onto +z.
typedef struct {
  float3 org;
  float3 inv_dir;
  int kx, ky, kz;
  float sx, sy, sz;
} RayPrecomp;

inline float component(float3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

inline RayPrecomp precompute_ray(float3 org, float3 dir) {
  RayPrecomp r;
  r.org = org;
  const float3 a = fabs(dir);
  r.kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  r.kx = r.kz == 2 ? 0 : r.kz + 1;
  r.ky = r.kx == 2 ? 0 : r.kx + 1;
  // Keep the winding of the sheared triangle: swap kx and ky when the ray points down kz.
  if (component(dir, r.kz) < 0.0f) {
    const int t = r.kx;
    r.kx = r.ky;
    r.ky = t;
  }
  const float dz = component(dir, r.kz);
  r.sx = component(dir, r.kx) / dz;
  r.sy = component(dir, r.ky) / dz;
  r.sz = 1.0f / dz;
  // Zero direction components would give 0 * inf = NaN in the slab test; a tiny value
  // keeps the reciprocal finite-signed and the test conservative.
  const float tiny = 1e-30f;
  const float3 safe = (float3)(fabs(dir.x) < tiny ? copysign(tiny, dir.x) : dir.x,
                               fabs(dir.y) < tiny ? copysign(tiny, dir.y) : dir.y,
                               fabs(dir.z) < tiny ? copysign(tiny, dir.z) : dir.z);
  r.inv_dir = 1.0f / safe;
  return r;
}

// Watertight test. On a hit closer than *t_max (and at least t_min), updates *t_max and
// the barycentrics (b1, b2) of v1 and v2, and returns true.
inline bool intersect_triangle(const RayPrecomp* r, float3 v0, float3 v1, float3 v2, float t_min, float* t_max,
                               float* b1, float* b2) {
  const float3 a = v0 - r->org, b = v1 - r->org, c = v2 - r->org;
  const float az = component(a, r->kz), bz = component(b, r->kz), cz = component(c, r->kz);
  const float ax = component(a, r->kx) - r->sx * az, ay = component(a, r->ky) - r->sy * az;
  const float bx = component(b, r->kx) - r->sx * bz, by = component(b, r->ky) - r->sy * bz;
  const float cx = component(c, r->kx) - r->sx * cz, cy = component(c, r->ky) - r->sy * cz;
  const float u = cx * by - cy * bx;
  const float v = ax * cy - ay * cx;
  const float w = bx * ay - by * ax;
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
  const float det = u + v + w;
  if (det == 0.0f) return false;
  const float t_scaled = u * r->sz * az + v * r->sz * bz + w * r->sz * cz;
  // Compare t against the interval without dividing: flip by det's sign.
  const float sign = det < 0.0f ? -1.0f : 1.0f;
  const float abs_det = fabs(det);
  const float ts = t_scaled * sign;
  if (ts < t_min * abs_det || ts >= *t_max * abs_det) return false;
  const float inv_det = 1.0f / det;
  *t_max = t_scaled * inv_det;
  *b1 = v * inv_det;
  *b2 = w * inv_det;
  return true;
}

// 1 + 2 gamma(3): widens the far slab distance so rounding never culls a box that the
// ray touches (Ize, "Robust BVH Ray Traversal", JCGT 2013).
#define FH_SLAB_WIDEN 1.0000003576f

// Near distances of the eight children; lanes the ray misses get +INFINITY.
inline float8 intersect_children(const RayPrecomp* r, __global const Bvh8Node* node, float t_max) {
  const float8 ox = (float8)(r->org.x), oy = (float8)(r->org.y), oz = (float8)(r->org.z);
  const float8 ix = (float8)(r->inv_dir.x), iy = (float8)(r->inv_dir.y), iz = (float8)(r->inv_dir.z);
  const float8 tx0 = (vload8(0, node->lo_x) - ox) * ix, tx1 = (vload8(0, node->hi_x) - ox) * ix;
  const float8 ty0 = (vload8(0, node->lo_y) - oy) * iy, ty1 = (vload8(0, node->hi_y) - oy) * iy;
  const float8 tz0 = (vload8(0, node->lo_z) - oz) * iz, tz1 = (vload8(0, node->hi_z) - oz) * iz;
  const float8 t_near = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), (float8)(0.0f)));
  const float8 t_far = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), (float8)(t_max))) *
                       FH_SLAB_WIDEN;
  const int8 empty = vload8(0, node->child) == (int8)(0);
  const int8 miss = (t_near > t_far) | empty;
  return select(t_near, (float8)(INFINITY), miss);
}

typedef struct {
  float t, b1, b2;
  int triangle;  // index into the ordered triangle array, -1 for a miss
} TraceHit;

// Pushes the children the ray hits, farthest first, so the nearest is popped next.
inline void push_hit_children(float8 t_near, __global const Bvh8Node* node, int* stack_node, float* stack_t,
                              int* sp) {
  float t[8];
  vstore8(t_near, 0, t);
  int order[8];
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    if (t[i] == INFINITY) continue;
    // Insertion sort by decreasing distance.
    int j = n++;
    while (j > 0 && t[order[j - 1]] < t[i]) {
      order[j] = order[j - 1];
      --j;
    }
    order[j] = i;
  }
  for (int k = 0; k < n && *sp < FH_TRAVERSAL_STACK; ++k) {
    stack_node[*sp] = node->child[order[k]];
    stack_t[*sp] = t[order[k]];
    ++*sp;
  }
}

// Closest hit (any_hit == false) or the first hit found (any_hit == true) in [t_min, t_max).
inline TraceHit trace_ray(__global const Bvh8Node* nodes, __global const float4* triangles, float3 org, float3 dir,
                          float t_min, float t_max, bool any_hit) {
  const RayPrecomp r = precompute_ray(org, dir);
  TraceHit hit;
  hit.t = t_max;
  hit.b1 = hit.b2 = 0.0f;
  hit.triangle = -1;
  int stack_node[FH_TRAVERSAL_STACK];
  float stack_t[FH_TRAVERSAL_STACK];
  int sp = 0;
  stack_node[sp] = 0;
  stack_t[sp++] = 0.0f;
  while (sp > 0) {
    --sp;
    const int ref = stack_node[sp];
    if (stack_t[sp] > hit.t) continue;  // a closer hit was found since this was pushed
    if (ref >= 0) {
      __global const Bvh8Node* node = nodes + ref;
      push_hit_children(intersect_children(&r, node, hit.t), node, stack_node, stack_t, &sp);
      continue;
    }
    const uint packed = (uint)(~ref);
    const uint first = packed >> FH_LEAF_BITS, count = packed & ((1u << FH_LEAF_BITS) - 1u);
    for (uint i = first; i < first + count; ++i) {
      const float4 v0 = triangles[3 * i], v1 = triangles[3 * i + 1], v2 = triangles[3 * i + 2];
      if (intersect_triangle(&r, v0.xyz, v1.xyz, v2.xyz, t_min, &hit.t, &hit.b1, &hit.b2)) {
        hit.triangle = (int)i;
        if (any_hit) return hit;
      }
    }
  }
  return hit;
}

#endif

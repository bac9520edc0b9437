// Ray casting against the 8-wide BVH: the watertight ray/triangle test of Woop, Benthin
// and Wald (JCGT 2013), a conservative float8 slab test (Ize 2013), and stack traversal:
// near-to-far child order for closest hits, lane order for shadow rays (find_occluder).
// Used by intersect.cl and anything else that casts rays.
#ifndef FH_INTERSECT_H
#define FH_INTERSECT_H

#include "masks.h"
#include "types.h"

// Watertightness needs the edge functions of two triangles that share an edge to be
// exact negatives of each other; a fused multiply-add would round one product and not
// the other, opening cracks along shared edges.
#pragma OPENCL FP_CONTRACT OFF

// The host passes the stack depth its BVH needs (7 per wide level + 1) as a build option.
#ifndef FH_TRAVERSAL_STACK
#define FH_TRAVERSAL_STACK 64
#endif

// Lane l of x (0 <= l < 8), exact for every value, -0 and NaN included. On x86 one
// permute; elsewhere the other lanes' bits are masked off and the lanes OR-ed together.
FH_INLINE float lane_at(float8 x, int l) {
#ifdef __AVX2__
  return __builtin_ia32_permvarsf256((fh_v8sf)x, (fh_v8si)(int8)(l))[0];
#else
  return as_float(or_lanes(as_int8(x) & ((int8)(l) == (int8)(0, 1, 2, 3, 4, 5, 6, 7))));
#endif
}

// Minimum and maximum by comparisons, which compile to single min/max instructions (fmin
// and fmax must also handle NaNs, which the distances they serve never are: ray
// directions' inverses are finite, so slab distances are never 0 * inf).
FH_INLINE float8 min8(float8 a, float8 b) { return a < b ? a : b; }
FH_INLINE float8 max8(float8 a, float8 b) { return a > b ? a : b; }

FH_INLINE float min_lane(float8 x) {
  const float4 a = x.lo < x.hi ? x.lo : x.hi;
  const float2 b = a.lo < a.hi ? a.lo : a.hi;
  return b.x < b.y ? b.x : b.y;
}

FH_INLINE float max_lane(float8 x) {
  const float4 a = x.lo > x.hi ? x.lo : x.hi;
  const float2 b = a.lo > a.hi ? a.lo : a.hi;
  return b.x > b.y ? b.x : b.y;
}

// The index of the lowest set bit of m (m != 0). clz is OpenCL 1.2; ctz is not.
FH_INLINE int lowest_bit(uint m) { return 31 - (int)clz(m & (0u - m)); }

// Per-ray constants of the watertight test: the axis the ray is most aligned with
// (kz), the shear that maps the ray onto +z, and the origin in that axis order.
typedef struct {
  float3 inv_dir;
  // Per axis, which of a node's two planes the ray enters by (its offset in floats in
  // Bvh8Node: the low plane where the direction is positive); the exit plane is the other
  // (offset ^ 8; kernel_layouts.cpp pins the offsets). Chosen once per ray, so a box test
  // needs no min and max to sort each axis' two distances.
  int near_x, near_y, near_z;
  // The distance to an entry plane is plane * inv_dir + near_offset, to an exit plane
  // plane * inv_dir + far_offset (FH_SLAB_OFFSET).
  float3 near_offset, far_offset;
  int kx, ky, kz;
  float sx, sy, sz;
  float ox, oy, oz;  // origin components along kx, ky, kz
} RayPrecomp;

// The slab test's distance to a plane p along an axis is p * inv + offset, one fused
// multiply-add (p * inv is exact inside it), with offset = -(o * inv), the origin's part.
// That product is rounded, by up to half an ulp, and a rounding of it could move a box's
// entry later or its exit earlier by far more than the distance's own ulp (an origin far
// from the world's, near the box); so the entry's offset is moved down and the exit's up by
// FH_ULP_STEP, and the distances can only widen the slab. The distance itself is then
// rounded once, which FH_SLAB_WIDEN covers. Macros, for float3 and float8 alike (the same
// bits). fma is exact on every device (OpenCL requires it), and fast where the hardware has
// it: GPUs, and x86 CPUs since Haswell; elsewhere it is emulated, slowly.
//
// o * inv, clamped to the finite floats (infinity moved by a step could be NaN; the clamped
// value still errs the right way once stepped).
#define FH_ORIGIN_TERM(o, inv, type) clamp((o) * (inv), (type)(-FLT_MAX), (type)(FLT_MAX))
// At least one ulp of x, for every finite x (checked against nextafter on every binade's
// edges and 20 million random floats), and at most two where x is at least 2^-103: x's
// magnitude scaled by 2^-23 is exact, and the rounded sum cannot fall below it. Never below
// the smallest normal float: an origin at 0 would give a denormal offset, and a
// multiply-add with a denormal operand takes a microcode assist on x86.
#define FH_ULP_STEP(x, type) fma(fabs(x), (type)(0x1p-23f), (type)(FLT_MIN))
// The offset of a plane the ray enters by where `entry` is positive (stepped down), exits by
// where it is negative (stepped up): a constant for one ray, the direction's sign for a
// packet's low planes.
#define FH_SLAB_OFFSET(o, inv, entry, type) \
  (-FH_ORIGIN_TERM(o, inv, type) - copysign(FH_ULP_STEP(FH_ORIGIN_TERM(o, inv, type), type), (type)(entry)))

FH_INLINE float component(float3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

FH_INLINE RayPrecomp precompute_ray(float3 org, float3 dir) {
  RayPrecomp r;
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
  r.ox = component(org, r.kx);
  r.oy = component(org, r.ky);
  r.oz = component(org, r.kz);
  // A zero direction component would give 0 * inf = NaN in the slab test. Such an axis
  // gets a tiny positive direction instead, which alone would exit a box at t = 0 when the
  // origin lies exactly on its high face (a ray along a wall's edge), so for that axis the
  // origin is moved by a few ulps away from each face it is tested against: the slab
  // becomes [lo - eps, hi + eps], conservative. Other axes are untouched.
  const float tiny = 1e-30f;
  const int3 flat = fabs(dir) < (float3)(tiny);
  const float3 eps = fmax(fabs(org), (float3)(1.0f)) * 0x1p-20f;
  r.inv_dir = 1.0f / select(dir, (float3)(tiny), flat);
  const float3 org_lo = select(org, org + eps, flat), org_hi = select(org, org - eps, flat);
  const int3 forward = r.inv_dir >= (float3)(0.0f);
  r.near_x = forward.x ? 0 : 8;
  r.near_y = forward.y ? 16 : 24;
  r.near_z = forward.z ? 32 : 40;
  r.near_offset = FH_SLAB_OFFSET(select(org_hi, org_lo, forward), r.inv_dir, 1.0f, float3);
  r.far_offset = FH_SLAB_OFFSET(select(org_lo, org_hi, forward), r.inv_dir, -1.0f, float3);
  return r;
}

// RayPrecomp's fields as arrays over rays, ray l's at index l, so that a traversal reads its
// ray's constants with plain loads (FH_RAY_AT): X(type, name) for each.
#define FH_RAY_CONSTANTS(X)                                                                       \
  X(float, inv_x) X(float, inv_y) X(float, inv_z) X(int, near_x) X(int, near_y) X(int, near_z)    \
  X(float, near_offset_x) X(float, near_offset_y) X(float, near_offset_z) X(float, far_offset_x) \
  X(float, far_offset_y) X(float, far_offset_z) X(int, kx) X(int, ky) X(int, kz) X(float, sx)     \
  X(float, sy) X(float, sz) X(float, ox) X(float, oy) X(float, oz)
#define FH_EIGHT_OF(type, name) type name[8];

// Eight rays' constants (precompute_rays8).
typedef struct {
  FH_RAY_CONSTANTS(FH_EIGHT_OF)
} RayPrecomp8;

// The same constants in vector lanes, ray l's in lane l, as they are computed.
#define FH_LANES_OF(type, name) type##8 name;
typedef struct {
  FH_RAY_CONSTANTS(FH_LANES_OF)
} RayLanes8;

// Component k (0: x, 1: y, 2: z) of (x, y, z), per lane.
FH_INLINE float8 component8(float8 x, float8 y, float8 z, int8 k) {
  return select(select(z, y, k == (int8)(1)), x, k == (int8)(0));
}

// The watertight test's axis order of eight rays, ray l in lane l, as precompute_ray picks
// it; *along is each ray's direction component along kz.
FH_INLINE void axis_orders8(float8 dx, float8 dy, float8 dz, int8* kx, int8* ky, int8* kz, float8* along) {
  const float8 ax = fabs(dx), ay = fabs(dy), az = fabs(dz);
  const int8 two = (int8)(2), zero = (int8)(0);
  *kz = select(select(two, (int8)(1), ay > az), select(two, zero, ax > az), ax > ay);
  const int8 x = select(*kz + 1, zero, *kz == two);
  const int8 y = select(x + 1, zero, x == two);
  *along = component8(dx, dy, dz, *kz);
  const int8 down = *along < (float8)(0.0f);  // keep the winding: swap kx and ky
  *kx = select(x, y, down);
  *ky = select(y, x, down);
}

// precompute_ray for eight rays, ray l in lane l: the same operations on the same values
// (the same bits), with one vector division where eight rays took a scalar one each.
FH_INLINE RayLanes8 ray_constants8(float8 ox, float8 oy, float8 oz, float8 dx, float8 dy, float8 dz) {
  RayLanes8 lanes;
  const float8 ax = fabs(dx), ay = fabs(dy), az = fabs(dz);
  const int8 zero = (int8)(0);
  int8 kx, ky, kz;
  float8 along;
  axis_orders8(dx, dy, dz, &kx, &ky, &kz, &along);
  lanes.kx = kx;
  lanes.ky = ky;
  lanes.kz = kz;
  lanes.sx = component8(dx, dy, dz, kx) / along;
  lanes.sy = component8(dx, dy, dz, ky) / along;
  lanes.sz = 1.0f / along;
  lanes.ox = component8(ox, oy, oz, kx);
  lanes.oy = component8(ox, oy, oz, ky);
  lanes.oz = component8(ox, oy, oz, kz);
  // Zero direction components as precompute_ray treats them, one axis at a time.
  const float8 tiny = (float8)(1e-30f), one = (float8)(1.0f);
  const int8 flat_x = ax < tiny, flat_y = ay < tiny, flat_z = az < tiny;
  const float8 eps_x = fmax(fabs(ox), one) * 0x1p-20f, eps_y = fmax(fabs(oy), one) * 0x1p-20f,
               eps_z = fmax(fabs(oz), one) * 0x1p-20f;
  const float8 inv_x = 1.0f / select(dx, tiny, flat_x), inv_y = 1.0f / select(dy, tiny, flat_y),
               inv_z = 1.0f / select(dz, tiny, flat_z);
  lanes.inv_x = inv_x;
  lanes.inv_y = inv_y;
  lanes.inv_z = inv_z;
  const float8 lo_x = select(ox, ox + eps_x, flat_x), hi_x = select(ox, ox - eps_x, flat_x);
  const float8 lo_y = select(oy, oy + eps_y, flat_y), hi_y = select(oy, oy - eps_y, flat_y);
  const float8 lo_z = select(oz, oz + eps_z, flat_z), hi_z = select(oz, oz - eps_z, flat_z);
  const int8 fwd_x = inv_x >= (float8)(0.0f), fwd_y = inv_y >= (float8)(0.0f), fwd_z = inv_z >= (float8)(0.0f);
  lanes.near_x = select((int8)(8), zero, fwd_x);
  lanes.near_y = select((int8)(24), (int8)(16), fwd_y);
  lanes.near_z = select((int8)(40), (int8)(32), fwd_z);
  lanes.near_offset_x = FH_SLAB_OFFSET(select(hi_x, lo_x, fwd_x), inv_x, 1.0f, float8);
  lanes.near_offset_y = FH_SLAB_OFFSET(select(hi_y, lo_y, fwd_y), inv_y, 1.0f, float8);
  lanes.near_offset_z = FH_SLAB_OFFSET(select(hi_z, lo_z, fwd_z), inv_z, 1.0f, float8);
  lanes.far_offset_x = FH_SLAB_OFFSET(select(lo_x, hi_x, fwd_x), inv_x, -1.0f, float8);
  lanes.far_offset_y = FH_SLAB_OFFSET(select(lo_y, hi_y, fwd_y), inv_y, -1.0f, float8);
  lanes.far_offset_z = FH_SLAB_OFFSET(select(lo_z, hi_z, fwd_z), inv_z, -1.0f, float8);
  return lanes;
}

// Stores eight rays' constants (RayLanes8 lanes) at index `at` of each of out's arrays.
#define FH_STORE_LANES_OF(type, name) vstore8(lanes.name, 0, out->name + at);

FH_INLINE void store_rays8(RayPrecomp8* out, RayLanes8 lanes) {
  const int at = 0;
  FH_RAY_CONSTANTS(FH_STORE_LANES_OF)
}

FH_INLINE void precompute_rays8(float8 ox, float8 oy, float8 oz, float8 dx, float8 dy, float8 dz, RayPrecomp8* out) {
  store_rays8(out, ray_constants8(ox, oy, oz, dx, dy, dz));
}

// Ray l's constants, into the RayPrecomp r, from arrays laid out by FH_RAY_CONSTANTS.
#define FH_RAY_AT(s, l, r)                                                                   \
  do {                                                                                       \
    (r).inv_dir = (float3)((s)->inv_x[l], (s)->inv_y[l], (s)->inv_z[l]);                     \
    (r).near_x = (s)->near_x[l];                                                             \
    (r).near_y = (s)->near_y[l];                                                             \
    (r).near_z = (s)->near_z[l];                                                             \
    (r).near_offset = (float3)((s)->near_offset_x[l], (s)->near_offset_y[l], (s)->near_offset_z[l]); \
    (r).far_offset = (float3)((s)->far_offset_x[l], (s)->far_offset_y[l], (s)->far_offset_z[l]);     \
    (r).kx = (s)->kx[l];                                                                     \
    (r).ky = (s)->ky[l];                                                                     \
    (r).kz = (s)->kz[l];                                                                     \
    (r).sx = (s)->sx[l];                                                                     \
    (r).sy = (s)->sy[l];                                                                     \
    (r).sz = (s)->sz[l];                                                                     \
    (r).ox = (s)->ox[l];                                                                     \
    (r).oy = (s)->oy[l];                                                                     \
    (r).oz = (s)->oz[l];                                                                     \
  } while (0)

// Ray l's constants from precompute_rays8.
FH_INLINE RayPrecomp ray_of_lane(const RayPrecomp8* s, int l) {
  RayPrecomp r;
  FH_RAY_AT(s, l, r);
  return r;
}

// 1 + 2^-20: widens the division-free interval test below so that it never rejects a lane
// whose quotient (the t a hit keeps) equals the current hit's t: the products round on
// their own, by a few ulps at most.
#define FH_T_WIDEN 1.00000095367f

// Whether a candidate at distance t with BVH-order index id beats the current hit (t_max,
// best; best < 0: none yet). Ties in t go to the lower index, so the closest hit is the
// same whatever order the leaves are visited in (single rays and packets alike); with no
// hit yet, t_max is the ray's own end, which is excluded.
FH_INLINE int8 closer_hit8(float8 t, int8 id, float8 t_max, int8 best) {
  return (t < t_max) | ((t == t_max) & (id < best) & (id >= (int8)(0)));
}

// The watertight test's arithmetic on eight (ray, triangle) pairs, whichever of the two is
// spread over the lanes (a leaf's eight triangles for one ray, or one triangle for a
// packet's eight rays), so both find the same bits. Vertex coordinates come in the ray's
// axis order (x: kx, y: ky, z: kz), as do the origin o and the shear s.
typedef struct {
  float8 v, w, det, t_scaled;  // barycentrics of v1 and v2 are v / det and w / det; t = t_scaled / det
  // Inside the edges, not degenerate, and t in [t_min, t_max] by the division-free test
  // (widened at t_max by FH_T_WIDEN, so a tie with the current hit is never lost to it).
  int8 maybe;
} WatertightLanes;

FH_INLINE WatertightLanes watertight_lanes(float8 x0, float8 y0, float8 z0, float8 x1, float8 y1, float8 z1,
                                           float8 x2, float8 y2, float8 z2, float8 ox, float8 oy, float8 oz,
                                           float8 sx, float8 sy, float8 sz, float8 t_min, float8 t_max) {
  // Each vertex's sheared coordinates depend on that vertex and the ray alone, so they may
  // be fused (a vertex gets the same bits in every triangle); the edge functions below may
  // not (see FP_CONTRACT above).
  const float8 az = z0 - oz, bz = z1 - oz, cz = z2 - oz;
  const float8 ax = fma(-sx, az, x0 - ox), ay = fma(-sy, az, y0 - oy);
  const float8 bx = fma(-sx, bz, x1 - ox), by = fma(-sy, bz, y1 - oy);
  const float8 cx = fma(-sx, cz, x2 - ox), cy = fma(-sy, cz, y2 - oy);
  WatertightLanes e;
  const float8 u = cx * by - cy * bx;
  e.v = ax * cy - ay * cx;
  e.w = bx * ay - by * ax;
  const float8 zero = (float8)(0.0f);
  // Outside where the edge functions differ in sign (a NaN among them fails the t test below).
  const int8 outside = (min8(min8(u, e.v), e.w) < zero) & (max8(max8(u, e.v), e.w) > zero);
  e.det = u + e.v + e.w;
  e.t_scaled = fma(u, sz * az, fma(e.v, sz * bz, e.w * (sz * cz)));
  // Compare t against the interval without dividing: flip by det's sign.
  const float8 abs_det = fabs(e.det);
  const float8 ts = select(e.t_scaled, -e.t_scaled, e.det < zero);
  e.maybe = ~outside & (e.det != zero) & (ts >= t_min * abs_det) & (ts <= (t_max * FH_T_WIDEN) * abs_det);
  return e;
}

// watertight_lanes for one ray and the eight triangles of a leaf, their vertices read in
// the ray's axis order.
FH_INLINE WatertightLanes watertight_block(const RayPrecomp* r, __global const TriangleBlock8* block, float t_min,
                                           float t_max) {
  __global const float* v0 = block->v[0][0];
  __global const float* v1 = block->v[1][0];
  __global const float* v2 = block->v[2][0];
  const int kx = 8 * r->kx, ky = 8 * r->ky, kz = 8 * r->kz;
  return watertight_lanes(vload8(0, v0 + kx), vload8(0, v0 + ky), vload8(0, v0 + kz), vload8(0, v1 + kx),
                          vload8(0, v1 + ky), vload8(0, v1 + kz), vload8(0, v2 + kx), vload8(0, v2 + ky),
                          vload8(0, v2 + kz), (float8)(r->ox), (float8)(r->oy), (float8)(r->oz), (float8)(r->sx),
                          (float8)(r->sy), (float8)(r->sz), (float8)(t_min), (float8)(t_max));
}

// The watertight test on the eight triangles of a leaf at once. Returns the lane of the
// closest hit in [t_min, *t_max) that beats the current one (`best`, see closer_hit8),
// updating *t_max and the barycentrics b1, b2 of v1 and v2, or -1. An any-hit query takes
// the lowest lane hit and updates nothing.
FH_INLINE int intersect_block(const RayPrecomp* r, __global const TriangleBlock8* block, float t_min, float* t_max,
                              int best, float* b1, float* b2, bool any_hit) {
  const WatertightLanes e = watertight_block(r, block, t_min, *t_max);
  const int8 maybe = e.maybe;
  if (!any_lane(maybe)) return -1;
  // The division-free test rounds differently from the quotient below: a lane can pass it
  // and still have t >= t_max (a triangle at the current hit's distance, duplicated or
  // across a shared edge). Accept only on the quotient, the value the hit keeps.
  const float8 quotient = e.t_scaled / e.det;
  int8 valid = maybe & (quotient >= (float8)(t_min)) & (quotient <= (float8)(*t_max));
  if (!any_lane(valid)) return -1;
  const int8 ids = vload8(0, block->id);
  // Rare (a duplicated face, or a shared edge at the current hit's distance): only a lower
  // index beats the current hit at equal t.
  const int8 tied = valid & (quotient == (float8)(*t_max));
  if (any_lane(tied)) {
    valid &= closer_hit8(quotient, ids, (float8)(*t_max), (int8)(best));
    if (!any_lane(valid)) return -1;
  }
  if (any_hit) return lowest_bit(lane_bits(valid));
  uint lanes = lane_bits(valid);
  // Mostly one lane hits; with more, the nearest, and among equals (rare again) the lowest index.
  if (lanes & (lanes - 1)) {
    const float8 t = select((float8)(INFINITY), quotient, valid);
    const int8 at_nearest = valid & (t == (float8)(min_lane(t)));
    lanes = lane_bits(at_nearest);
    if (lanes & (lanes - 1)) {
      const int8 id_at = select((int8)(INT_MAX), ids, at_nearest);
      const int4 i4 = min(id_at.lo, id_at.hi);
      const int2 i2 = min(i4.lo, i4.hi);
      lanes = lane_bits(at_nearest & (ids == (int8)(min(i2.x, i2.y))));
    }
  }
  const int lowest = lowest_bit(lanes);
  *t_max = lane_at(quotient, lowest);
  // The hit lane's quotients alone, as the lane of a vector division would give them (the
  // same bits: a division is correctly rounded either way).
  const float det = lane_at(e.det, lowest);
  *b1 = lane_at(e.v, lowest) / det;
  *b2 = lane_at(e.w, lowest) / det;
  return lowest;
}

// 1 + 2 gamma(3): widens the far slab distance so rounding never culls a box that the
// ray touches (Ize, "Robust BVH Ray Traversal", JCGT 2013).
#define FH_SLAB_WIDEN 1.0000003576f

// The slab test's interval from each axis' entry and exit distances, clipped to [0, t_max]
// and its far end widened; empty where *t_near > *t_far. Single rays (eight children) and
// packets (eight rays) both end their box tests here, so both cull the same boxes.
FH_INLINE void slab_interval(float8 nx, float8 ny, float8 nz, float8 fx, float8 fy, float8 fz, float8 t_max,
                             float8* t_near, float8* t_far) {
  *t_near = max8(max8(nx, ny), max8(nz, (float8)(0.0f)));
  *t_far = min8(min8(fx, fy), min8(fz, t_max)) * FH_SLAB_WIDEN;
}

// The slab test's near distance, +INFINITY where the interval is empty.
FH_INLINE float8 slab_entry(float8 nx, float8 ny, float8 nz, float8 fx, float8 fy, float8 fz, float8 t_max) {
  float8 t_near, t_far;
  slab_interval(nx, ny, nz, fx, fy, fz, t_max, &t_near, &t_far);
  return select(t_near, (float8)(INFINITY), t_near > t_far);
}

// slab_entry from the six slab distances, each axis' two sorted by comparing them (packets,
// whose rays may enter a box by different planes).
FH_INLINE float8 slab_near(float8 tx0, float8 tx1, float8 ty0, float8 ty1, float8 tz0, float8 tz1, float8 t_max) {
  return slab_entry(min8(tx0, tx1), min8(ty0, ty1), min8(tz0, tz1), max8(tx0, tx1), max8(ty0, ty1), max8(tz0, tz1),
                    t_max);
}

// The slab intervals of the eight children. Each axis' entry and exit distances are the
// two the slab test would sort into its min and max (the same bits: a positive inverse
// keeps low before high, a negative one swaps them).
FH_INLINE void child_intervals(const RayPrecomp* r, __global const Bvh8Node* node, float t_max, float8* t_near,
                               float8* t_far) {
  __global const float* planes = (__global const float*)node;
  const float8 ix = (float8)(r->inv_dir.x), iy = (float8)(r->inv_dir.y), iz = (float8)(r->inv_dir.z);
  const float8 nx = fma(vload8(0, planes + r->near_x), ix, (float8)(r->near_offset.x));
  const float8 fx = fma(vload8(0, planes + (r->near_x ^ 8)), ix, (float8)(r->far_offset.x));
  const float8 ny = fma(vload8(0, planes + r->near_y), iy, (float8)(r->near_offset.y));
  const float8 fy = fma(vload8(0, planes + (r->near_y ^ 8)), iy, (float8)(r->far_offset.y));
  const float8 nz = fma(vload8(0, planes + r->near_z), iz, (float8)(r->near_offset.z));
  const float8 fz = fma(vload8(0, planes + (r->near_z ^ 8)), iz, (float8)(r->far_offset.z));
  slab_interval(nx, ny, nz, fx, fy, fz, (float8)(t_max), t_near, t_far);
}

// Near distances of the eight children; lanes the ray misses, and empty slots, get +INFINITY.
FH_INLINE float8 intersect_children(const RayPrecomp* r, __global const Bvh8Node* node, float t_max) {
  float8 t_near, t_far;
  child_intervals(r, node, t_max, &t_near, &t_far);
  const int8 empty = vload8(0, node->child) == (int8)(0);
  return select(t_near, (float8)(INFINITY), (t_near > t_far) | empty);
}

typedef struct {
  float t, b1, b2;
  int triangle;  // index in BVH order, -1 for a miss
} TraceHit;

// A hit as the device stores it: (t, b1, b2, triangle index in BVH order as bits), t =
// INFINITY and index -1 on a miss. Per-triangle data on the device is stored in that order.
FH_INLINE float4 stored_hit(TraceHit h) {
  return (float4)(h.triangle < 0 ? INFINITY : h.t, h.b1, h.b2, as_float(h.triangle));
}

// One step of a sorting network on eight keys: lane i meets lane partner[i] and keeps the
// smaller of the two where keep_min[i] is set, the larger elsewhere.
FH_INLINE int8 sort_step(int8 keys, uint8 partner, int8 keep_min) {
  const int8 other = shuffle(keys, partner);
  return select(max(keys, other), min(keys, other), keep_min);
}

// Eight keys in ascending order: Batcher's bitonic network, six steps of whole-vector
// operations, where an insertion sort would branch on every comparison.
FH_INLINE int8 sort8(int8 k) {
  const uint8 pairs = (uint8)(1, 0, 3, 2, 5, 4, 7, 6), twos = (uint8)(2, 3, 0, 1, 6, 7, 4, 5);
  // Blocks of two, then four, sorted alternately up and down (bitonic), then merged up.
  k = sort_step(k, pairs, (int8)(-1, 0, 0, -1, -1, 0, 0, -1));
  k = sort_step(k, twos, (int8)(-1, -1, 0, 0, 0, 0, -1, -1));
  k = sort_step(k, pairs, (int8)(-1, 0, -1, 0, 0, -1, 0, -1));
  k = sort_step(k, (uint8)(4, 5, 6, 7, 0, 1, 2, 3), (int8)(-1, -1, -1, -1, 0, 0, 0, 0));
  k = sort_step(k, twos, (int8)(-1, -1, 0, 0, -1, -1, 0, 0));
  return sort_step(k, pairs, (int8)(-1, 0, -1, 0, -1, 0, -1, 0));
}

// Visits the children the ray hits nearest first: returns the nearest (0 if none) and
// pushes the others, farthest first, with their distances. One or two children hit, the
// common cases, take no sort. The order never changes the hit found (closer_hit8), only
// how soon the farther boxes are culled. The stack needs eight entries of room past its
// deepest use (vstore8).
FH_INLINE int order_children(float8 t_near, __global const Bvh8Node* node, int* stack_node, float* stack_t,
                             int* sp) {
  const uint hits = lane_bits(t_near != (float8)(INFINITY));
  if (hits == 0) return 0;
  const int first = lowest_bit(hits);
  const uint rest = hits & (hits - 1);
  if (rest == 0) return node->child[first];
  if ((rest & (rest - 1)) == 0) {
    const int second = lowest_bit(rest);
    const float t_first = lane_at(t_near, first), t_second = lane_at(t_near, second);
    const bool swap = t_first < t_second;
    const int far = swap ? second : first, near = swap ? first : second;
    stack_node[*sp] = node->child[far];
    stack_t[*sp] = swap ? t_second : t_first;
    ++*sp;
    return node->child[near];
  }
  // Three or more: sorted as integer keys, a distance's bits with its lane in the low three
  // (non-negative floats order as their bits; misses, +INFINITY, sort last). The stack
  // takes the exact distances, so the truncated bits only reorder near-ties.
  const int8 lanes = (int8)(0, 1, 2, 3, 4, 5, 6, 7);
  const int8 order = sort8((as_int8(t_near) & (int8)(~7)) | lanes) & (int8)(7);  // nearest first
  const int n = (int)popcount(hits);
  // Stack entry *sp + k takes the (n - 1 - k)-th nearest, k < n - 1 (the lanes past them are
  // overwritten by later pushes).
  const uint8 pushed = as_uint8(shuffle(order, as_uint8((int8)(n - 1) - lanes)));
  vstore8(shuffle(vload8(0, node->child), pushed), 0, stack_node + *sp);
  vstore8(shuffle(t_near, pushed), 0, stack_t + *sp);
  *sp += n - 1;
  return node->child[order.s0];
}

// The closest hit in [t_min, t_max) of the ray r was precomputed from.
FH_INLINE TraceHit trace_precomputed(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                     RayPrecomp r, float t_min, float t_max) {
  TraceHit hit;
  hit.t = t_max;
  hit.b1 = hit.b2 = 0.0f;
  hit.triangle = -1;
  int stack_node[FH_TRAVERSAL_STACK + 8];
  float stack_t[FH_TRAVERSAL_STACK + 8];
  int sp = 0;
  int ref = 0;  // the root
  for (;;) {
    if (ref >= 0) {
      __global const Bvh8Node* node = nodes + ref;
      ref = order_children(intersect_children(&r, node, hit.t), node, stack_node, stack_t, &sp);
      if (ref != 0) continue;
    } else {
      __global const TriangleBlock8* block = blocks + ~ref;
      const int lane = intersect_block(&r, block, t_min, &hit.t, hit.triangle, &hit.b1, &hit.b2, false);
      if (lane >= 0) hit.triangle = block->id[lane];
    }
    // Pop the nearest pending child that may still hold a closer hit (or one as close with
    // a lower index: the bound is widened as the box test widens its far distance).
    ref = 0;
    while (sp > 0) {
      --sp;
      if (stack_t[sp] <= hit.t * FH_SLAB_WIDEN) {
        ref = stack_node[sp];
        break;
      }
    }
    if (ref == 0) return hit;
  }
}

// The closest hit in [t_min, t_max).
FH_INLINE TraceHit trace_ray(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, float3 org,
                             float3 dir, float t_min, float t_max) {
  return trace_precomputed(nodes, blocks, precompute_ray(org, dir), t_min, t_max);
}

// A triangle on the segment [t_min, t_max), as its BVH-order index, or -1 if there is none
// (shadow rays). Any occluder ends the query, near or far, and the segment never shortens,
// so no child needs its distance: the children are visited in lane order, and a node's
// pending children are one stack entry, the node and a bit mask of those still to visit
// (one entry per level, none per child).
// Every child the segment touches is still visited until an occluder is found, so whether
// there is one does not depend on the order (which one is found does).
FH_INLINE int find_occluder_precomputed(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                        RayPrecomp r, float t_min, float t_max) {
  int stack_node[FH_TRAVERSAL_STACK];
  uint stack_pending[FH_TRAVERSAL_STACK];
  int sp = 0;
  int ref = 0;  // the root
  float t_end = t_max, b1, b2;
  for (;;) {
    if (ref >= 0) {
      __global const Bvh8Node* node = nodes + ref;
      const uint hits = lane_bits(intersect_children(&r, node, t_max) != (float8)(INFINITY));
      if (hits != 0) {
        const uint rest = hits & (hits - 1);
        if (rest != 0) {
          stack_node[sp] = ref;
          stack_pending[sp] = rest;
          ++sp;
        }
        ref = node->child[lowest_bit(hits)];
        continue;
      }
    } else {
      __global const TriangleBlock8* block = blocks + ~ref;
      const int lane = intersect_block(&r, block, t_min, &t_end, -1, &b1, &b2, true);
      if (lane >= 0) return block->id[lane];
    }
    if (sp == 0) return -1;
    const uint pending = stack_pending[sp - 1];
    ref = nodes[stack_node[sp - 1]].child[lowest_bit(pending)];
    const uint rest = pending & (pending - 1);
    if (rest != 0)
      stack_pending[sp - 1] = rest;
    else
      --sp;
  }
}

// find_occluder_precomputed for the ray from org along dir.
FH_INLINE int find_occluder(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, float3 org,
                            float3 dir, float t_min, float t_max) {
  return find_occluder_precomputed(nodes, blocks, precompute_ray(org, dir), t_min, t_max);
}

#endif

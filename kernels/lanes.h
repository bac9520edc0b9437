// Lanes: the shading code is written once for FH_LANES paths per work-item.
//
// With FH_LANES 1 (GPUs, and every program but the CPU path tracer) an `lfloat` is a float
// and the code is ordinary scalar code: a mask is an int, `lanes_any(m)` is `m`, and a
// branch on it is a branch. With FH_LANES 8 (the CPU strategy) an `lfloat` is a float8:
// each work-item carries eight paths in the lanes of vector registers, branches become
// selects over the lanes (taken when any lane needs them) and loads of per-path or
// per-triangle data are gathers. PoCL does not vectorize divergent shading code across
// work-items on its own: written one path per work-item, shade and shadow_connect compiled
// to scalar code, and eight explicit lanes cut shade's time about in half (see
// docs/architecture.md; measured in bench/history/cpu_render_speed.md), so the lanes are
// explicit.
//
// Masks are what comparisons return: 0 / 1 for scalars, 0 / -1 for vectors; `select`,
// `&&`, `||`, `!`, `&` and `|` treat both alike. Vectors are lvec3 structures of lanes
// (x, y, z), not float3, so that each component is one register.
#ifndef FH_LANES_H
#define FH_LANES_H

#include "masks.h"
#include "types.h"

#ifndef FH_LANES
#define FH_LANES 1
#endif

#if FH_LANES == 1
typedef float lfloat;
typedef int lint;
typedef uint luint;
typedef int lmask;
#define lanes_any(m) ((m) != 0)
// Lane l of v, to read or assign.
#define LANE(v, l) (v)
#define lconvert_float(x) convert_float(x)
#define lconvert_uint(x) convert_uint(x)
#define lconvert_int(x) convert_int(x)
#define las_int(x) as_int(x)
#define las_uint(x) as_uint(x)
#define las_float(x) as_float(x)
#elif FH_LANES == 8
typedef float8 lfloat;
typedef int8 lint;
typedef uint8 luint;
typedef int8 lmask;
#define lanes_any(m) any_lane(m)
#define LANE(v, l) ((v)[l])
#define lconvert_float(x) convert_float8(x)
#define lconvert_uint(x) convert_uint8(x)
#define lconvert_int(x) convert_int8(x)
#define las_int(x) as_int8(x)
#define las_uint(x) as_uint8(x)
#define las_float(x) as_float8(x)
#else
#error "FH_LANES must be 1 or 8"
#endif

// A loop over the lanes, unrolled: each LANE(v, l) then names a fixed lane (a register
// insert or extract) rather than an element of a vector in memory.
#define FH_FOR_LANES(l) _Pragma("unroll") for (int l = 0; l < FH_LANES; ++l)

// ---- Two- and three-component vectors of lanes ----

typedef struct {
  lfloat x, y;
} lvec2;

FH_INLINE lvec2 lv2(lfloat x, lfloat y) {
  lvec2 v;
  v.x = x;
  v.y = y;
  return v;
}

typedef struct {
  lfloat x, y, z;
} lvec3;

FH_INLINE lvec3 v3(lfloat x, lfloat y, lfloat z) {
  lvec3 v;
  v.x = x;
  v.y = y;
  v.z = z;
  return v;
}
FH_INLINE lvec3 v3_splat(lfloat s) { return v3(s, s, s); }
// One value for every lane.
FH_INLINE lvec3 v3_uniform(float3 u) { return v3((lfloat)(u.x), (lfloat)(u.y), (lfloat)(u.z)); }
FH_INLINE lvec3 v3_add(lvec3 a, lvec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
FH_INLINE lvec3 v3_sub(lvec3 a, lvec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
FH_INLINE lvec3 v3_mul(lvec3 a, lvec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
FH_INLINE lvec3 v3_scale(lvec3 a, lfloat s) { return v3(a.x * s, a.y * s, a.z * s); }
FH_INLINE lvec3 v3_neg(lvec3 a) { return v3(-a.x, -a.y, -a.z); }
// a * s + b
FH_INLINE lvec3 v3_madd(lvec3 a, lfloat s, lvec3 b) { return v3(a.x * s + b.x, a.y * s + b.y, a.z * s + b.z); }
FH_INLINE lfloat v3_dot(lvec3 a, lvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FH_INLINE lvec3 v3_cross(lvec3 a, lvec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
FH_INLINE lfloat v3_length(lvec3 a) { return sqrt(v3_dot(a, a)); }
FH_INLINE lvec3 v3_normalize(lvec3 a) { return v3_scale(a, rsqrt(v3_dot(a, a))); }
FH_INLINE lvec3 v3_abs(lvec3 a) { return v3(fabs(a.x), fabs(a.y), fabs(a.z)); }
FH_INLINE lvec3 v3_max(lvec3 a, lvec3 b) { return v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }
FH_INLINE lvec3 v3_clamp01(lvec3 a) { return v3(clamp(a.x, 0.0f, 1.0f), clamp(a.y, 0.0f, 1.0f), clamp(a.z, 0.0f, 1.0f)); }
FH_INLINE lfloat v3_max_component(lvec3 a) { return fmax(fmax(a.x, a.y), a.z); }
// Bit l set where m sets lane l, and the mask of the lanes whose bits are set.
FH_INLINE uint lanes_bits(lmask m) {
#if FH_LANES == 1
  return m ? 1u : 0u;
#else
  return lane_bits(m);
#endif
}
FH_INLINE lmask lanes_of_bits(uint bits) {
#if FH_LANES == 1
  return (bits & 1u) != 0u;
#else
  return ((uint8)(bits) & (uint8)(1, 2, 4, 8, 16, 32, 64, 128)) != (uint8)(0u);
#endif
}

// A mask of every lane (true) or none.
FH_INLINE lmask lanes_mask(bool all) { return (lint)(all ? 1 : 0) != 0; }
// Lanes where any component is positive.
// How many lanes m sets.
FH_INLINE uint lanes_count(lmask m) {
  uint n = 0;
  FH_FOR_LANES(l) n += LANE(m, l) ? 1u : 0u;
  return n;
}

FH_INLINE lmask v3_any_positive(lvec3 a) { return a.x > 0.0f || a.y > 0.0f || a.z > 0.0f; }
// Lanes of `if_true` where m is set, of `if_false` elsewhere.
FH_INLINE lvec3 v3_select(lmask m, lvec3 if_true, lvec3 if_false) {
  return v3(select(if_false.x, if_true.x, m), select(if_false.y, if_true.y, m), select(if_false.z, if_true.z, m));
}

// ---- Gathers and scatters: per-path and per-triangle data by index ----

// With FH_PRIVATE_PATHS (the CPU megakernel, megakernel.cl), the path state is each
// work-item's own vectors rather than global buffers (lanes_of_float4 and the others
// below), so the gathers and scatters come for both (overloaded; the other programs keep
// plain functions).
#if defined(FH_MEGAKERNEL) && FH_LANES > 1
#define FH_PRIVATE_PATHS
#define FH_ACCESS FH_INLINE __attribute__((overloadable))
#else
#define FH_ACCESS FH_INLINE
#endif

// gather_float, gather_uint, gather_int: base[index] for each lane's index, and
// scatter_float, scatter_uint, scatter_int: base[index] = v where m is set.
#define FH_GATHER(space, element, lanes_type)                                     \
  FH_ACCESS lanes_type gather_##element(space const element* base, luint index) { \
    lanes_type r;                                                                 \
    FH_FOR_LANES(l) LANE(r, l) = base[LANE(index, l)];                            \
    return r;                                                                     \
  }
#define FH_SCATTER(space, element, lanes_type)                                                \
  FH_ACCESS void scatter_##element(space element* base, luint index, lanes_type v, lmask m) { \
    FH_FOR_LANES(l)                                                                           \
    if (LANE(m, l)) base[LANE(index, l)] = LANE(v, l);                                        \
  }

// The xyz of float4 elements, and their w into *w: each element read once (gather_xyzw).
#define FH_GATHER_XYZW(space)                                                         \
  FH_ACCESS lvec3 gather_xyzw(space const float4* base, luint index, lfloat* w) {     \
    lvec3 r;                                                                          \
    FH_FOR_LANES(l) {                                                                 \
      const float4 e = base[LANE(index, l)];                                          \
      LANE(r.x, l) = e.x;                                                             \
      LANE(r.y, l) = e.y;                                                             \
      LANE(r.z, l) = e.z;                                                             \
      LANE(*w, l) = e.w;                                                              \
    }                                                                                 \
    return r;                                                                         \
  }
// Their xyz (gather_xyz) or w (gather_w); and where m is set, base[index] = (v, w).
#define FH_FLOAT4_ACCESS(space)                                                                  \
  FH_ACCESS lvec3 gather_xyz(space const float4* base, luint index) {                            \
    lfloat unused;                                                                               \
    return gather_xyzw(base, index, &unused);                                                    \
  }                                                                                              \
  FH_ACCESS lfloat gather_w(space const float4* base, luint index) {                             \
    lfloat r;                                                                                    \
    FH_FOR_LANES(l) LANE(r, l) = base[LANE(index, l)].w;                                         \
    return r;                                                                                    \
  }                                                                                              \
  FH_ACCESS void scatter_xyzw(space float4* base, luint index, lvec3 v, lfloat w, lmask m) {     \
    FH_FOR_LANES(l)                                                                              \
    if (LANE(m, l)) base[LANE(index, l)] = (float4)(LANE(v.x, l), LANE(v.y, l), LANE(v.z, l), LANE(w, l)); \
  }

#define FH_GATHERS(space)                 \
  FH_GATHER(space, float, lfloat)         \
  FH_GATHER(space, uint, luint)           \
  FH_GATHER(space, int, lint)             \
  FH_GATHER_XYZW(space)
#define FH_SCATTERS(space)                \
  FH_SCATTER(space, float, lfloat)        \
  FH_SCATTER(space, uint, luint)          \
  FH_SCATTER(space, int, lint)            \
  FH_FLOAT4_ACCESS(space)

#if FH_LANES == 8 && defined(__AVX2__)
// Eight lanes of global data on x86: the gather instruction, one per eight 32-bit words,
// where the portable form is eight loads and eight inserts into the vector. Its operand is
// a flat address, which OpenCL C has no cast to; a CPU device has one address space, so the
// global pointer goes through an integer. Its word offsets are signed 32-bit: buffers up
// to 8 GiB, which every buffer a CPU device is given here stays under.
FH_INLINE float8 gather_words(__global const void* base, int8 word) {
  const fh_v8sf all = (fh_v8sf)as_float8((int8)(-1));
  union {
    fh_v8sf x86;
    float8 lanes;
  } r;
  r.x86 = __builtin_ia32_gatherd_ps256((fh_v8sf)(float8)(0.0f), (const void*)(ulong)base,
                                       (fh_v8si)word, all, 4);
  return r.lanes;
}
FH_ACCESS lfloat gather_float(__global const float* base, luint index) { return gather_words(base, as_int8(index)); }
FH_ACCESS luint gather_uint(__global const uint* base, luint index) {
  return as_uint8(gather_words(base, as_int8(index)));
}
FH_ACCESS lint gather_int(__global const int* base, luint index) { return as_int8(gather_words(base, as_int8(index))); }
FH_ACCESS lvec3 gather_xyzw(__global const float4* base, luint index, lfloat* w) {
  const int8 word = as_int8(index) * 4;
  *w = gather_words(base, word + 3);
  return v3(gather_words(base, word), gather_words(base, word + 1), gather_words(base, word + 2));
}
#else
FH_GATHERS(__global)
#endif
FH_SCATTERS(__global)
#undef FH_GATHERS
#undef FH_SCATTERS
#undef FH_FLOAT4_ACCESS
#undef FH_GATHER_XYZW
#undef FH_SCATTER
#undef FH_GATHER

// One path-state field of every lane in registers (FH_PRIVATE_PATHS): a float4 field as
// four vectors, a scalar field as one. The megakernel's lanes index their own state by
// their positions, so the accesses below take the index only to match the global ones:
// a gather is the vectors themselves and a scatter a blend, where an array of float4 per
// lane costs a transpose and a branch per lane.
#ifdef FH_PRIVATE_PATHS
typedef struct {
  lfloat x, y, z, w;
} lanes_of_float4;
typedef lfloat lanes_of_float;
typedef luint lanes_of_uint;
typedef lint lanes_of_int;

#define FH_LANES_ACCESS(element, lanes_type)                                                      \
  FH_ACCESS lanes_type gather_##element(__private const lanes_type* base, luint index) { return *base; } \
  FH_ACCESS void scatter_##element(__private lanes_type* base, luint index, lanes_type v, lmask m) { \
    *base = select(*base, v, m);                                                                  \
  }
FH_LANES_ACCESS(float, lfloat)
FH_LANES_ACCESS(uint, luint)
FH_LANES_ACCESS(int, lint)
#undef FH_LANES_ACCESS
FH_ACCESS lvec3 gather_xyzw(__private const lanes_of_float4* base, luint index, lfloat* w) {
  *w = base->w;
  return v3(base->x, base->y, base->z);
}
FH_ACCESS lvec3 gather_xyz(__private const lanes_of_float4* base, luint index) { return v3(base->x, base->y, base->z); }
FH_ACCESS lfloat gather_w(__private const lanes_of_float4* base, luint index) { return base->w; }
FH_ACCESS void scatter_xyzw(__private lanes_of_float4* base, luint index, lvec3 v, lfloat w, lmask m) {
  base->x = select(base->x, v.x, m);
  base->y = select(base->y, v.y, m);
  base->z = select(base->z, v.z, m);
  base->w = select(base->w, w, m);
}
// base[index].xyz += v where m is set.
FH_ACCESS void add_xyz(__private lanes_of_float4* base, luint index, lvec3 v, lmask m) {
  base->x = select(base->x, base->x + v.x, m);
  base->y = select(base->y, base->y + v.y, m);
  base->z = select(base->z, base->z + v.z, m);
}
#endif
FH_ACCESS void add_xyz(__global float4* base, luint index, lvec3 v, lmask m) {
  FH_FOR_LANES(l) {
    if (LANE(m, l)) base[LANE(index, l)].xyz += (float3)(LANE(v.x, l), LANE(v.y, l), LANE(v.z, l));
  }
}

FH_INLINE lvec2 gather_xy(__global const float2* base, luint index) {
  lvec2 r;
  FH_FOR_LANES(l) {
    const float2 e = base[LANE(index, l)];
    LANE(r.x, l) = e.x;
    LANE(r.y, l) = e.y;
  }
  return r;
}

// Lane l of v as a float3 (for scalar code: ray traversal).
FH_INLINE float3 v3_lane(lvec3 v, int l) { return (float3)(LANE(v.x, l), LANE(v.y, l), LANE(v.z, l)); }

// The queue positions this work-item's lanes start at: lane l of the result is
// first + l, the paths a work-item of the CPU strategy carries.
FH_INLINE luint lane_positions(uint first) {
#if FH_LANES == 1
  return first;
#else
  return (luint)(first) + (luint)(0, 1, 2, 3, 4, 5, 6, 7);
#endif
}

#endif

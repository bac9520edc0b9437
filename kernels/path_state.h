// The path state, declared once: each field is one structure-of-arrays buffer indexed by
// path slot. The host (host/render/wavefront.h) expands the same list into named buffers
// and binds them, in this order, to every stage's FH_PATH_PARAMS.
#ifndef FH_PATH_STATE_H
#define FH_PATH_STATE_H

#include "types.h"

// X(type, name, bytes per path): what it holds
#define FH_PATH_FIELDS(X)                                                                         \
  X(float4, ray_org, 16)        /* origin xyz, tmin */                                           \
  X(float4, ray_dir, 16)        /* unit direction xyz, tmax */                                   \
  X(float4, hit, 16)            /* t, b1, b2, triangle (BVH order) bits or -1 */                 \
  X(float4, throughput, 16)     /* rgb (w unused: 16-byte loads) */                              \
  X(float, ray_pdf, 4)          /* pdf with which the BSDF sampled ray_dir (MIS); < 0: delta */ \
  X(float4, radiance, 16)       /* rgb gathered so far */                                        \
  X(uint, pixel_seed, 4)        /* the sample's pixel sampler (sampler.h): its scrambling seed, */ \
  X(uint, point_reversed, 4)    /* and its point in the pixel's sequence, bits reversed */       \
  X(uint, pass_entry, 4)        /* entry in the pass buffers and pass slot: FH_PASS_ENTRY */     \
  X(uint, depth, 4)             /* bounces so far */

// The light-sample requests shade hands to shadow_connect, stored by queue position (so
// they are written and read in order), one buffer per field like the path state.
#define FH_SHADOW_FIELDS(X)                                                                   \
  X(uint, shadow_path, 4)           /* the path slot the contribution goes to */             \
  X(float4, shadow_position, 16)    /* shading point, w: its magnitude (for ray offsets) */  \
  X(float4, shadow_normal, 16)      /* shading normal on the viewer's side */                \
  X(float4, shadow_geometric, 16)   /* geometric normal on the viewer's side */              \
  X(float4, shadow_albedo, 16)      /* diffuse albedo there (textures) */                    \
  X(float4, shadow_throughput, 16)  /* throughput before the BSDF sample */                  \
  X(float4, shadow_wo, 16)          /* direction toward the previous vertex */               \
  X(int, shadow_material, 4)        /* the material there */                                 \
  X(uint, shadow_depth, 4)          /* bounces to the shading point (its random dimensions) */

// The random dimensions of one bounce, shared by shade and shadow_connect so no two uses
// of one sample's numbers overlap: dimension = bounce * FH_DIMS_PER_BOUNCE + FH_DIM_*.
// The pixel sampler (sampler.h) draws U1/U2 pairs together as one 2D point.
#define FH_DIMS_PER_BOUNCE 8
#define FH_DIM_BSDF_U1 0
#define FH_DIM_BSDF_U2 1
#define FH_DIM_ROULETTE 2
// The light sample's U2 also picks the light (lights.h); LIGHT_NARROW replaces U2 for
// the point where the picked light's share of the table is too narrow to stretch.
#define FH_DIM_LIGHT_NARROW 3
#define FH_DIM_LIGHT_U1 4
#define FH_DIM_LIGHT_U2 5
#define FH_DIM_BSDF_LOBE 6
// The sub-pixel position (two dimensions), far above every bounce's.
#define FH_DIM_PIXEL 0x7fff0000u

#ifdef __OPENCL_VERSION__
#include "ray.h"
#include "sampler.h"

// Where the path state lives: global buffers of `type` per slot, or with FH_PRIVATE_PATHS
// (lanes.h) the megakernel's own variables, each one field of all its lanes.
#ifdef FH_PRIVATE_PATHS
#define FH_PATH_SPACE __private
#define FH_PATH_TYPE(type) lanes_of_##type
#else
#define FH_PATH_SPACE __global
#define FH_PATH_TYPE(type) type
#endif
#define FH_PATH_PARAM(type, name, bytes) , FH_PATH_SPACE FH_PATH_TYPE(type)* name
#define FH_PATH_ARG(type, name, bytes) , name
// Appended to a kernel's or a stage function's parameter list:
// `__kernel void k(int a FH_PATH_PARAMS)`, and to a call that passes them on: `f(a FH_PATH_ARGS)`.
#define FH_PATH_PARAMS FH_PATH_FIELDS(FH_PATH_PARAM)
#define FH_PATH_ARGS FH_PATH_FIELDS(FH_PATH_ARG)
#define FH_SHADOW_PARAM(type, name, bytes) , __global type* name
#define FH_SHADOW_PARAMS FH_SHADOW_FIELDS(FH_SHADOW_PARAM)
#define FH_SHADOW_ARGS FH_SHADOW_FIELDS(FH_PATH_ARG)

// The pixel sampler of the paths in slots p, as start_sample kept it.
FH_INLINE PixelSampler path_sampler(luint p FH_PATH_PARAMS) {
  PixelSampler s;
  s.pixel_seed = gather_uint(pixel_seed, p);
  s.index_reversed = gather_uint(point_reversed, p);
  return s;
}

// One light-sample request per lane, as shade makes it and shadow_connect uses it; the
// wavefront stores it in the FH_SHADOW_FIELDS buffers between the two, the megakernel
// hands it over directly.
typedef struct {
  luint path;
  SurfacePoint at;  // at.normal: the geometric normal on the viewer's side
  lvec3 shading_normal, albedo, throughput, wo;
  lint material;
  luint depth;
} ShadowRequest;

// Every field but the path: shadow_path is the request queue itself, which
// queue_append_each fills.
FH_INLINE void store_shadow_request(const ShadowRequest* r, luint index, lmask m FH_SHADOW_PARAMS) {
  scatter_xyzw(shadow_position, index, r->at.position, r->at.magnitude, m);
  scatter_xyzw(shadow_normal, index, r->shading_normal, (lfloat)(0.0f), m);
  scatter_xyzw(shadow_geometric, index, r->at.normal, (lfloat)(0.0f), m);
  scatter_xyzw(shadow_albedo, index, r->albedo, (lfloat)(0.0f), m);
  scatter_xyzw(shadow_throughput, index, r->throughput, (lfloat)(0.0f), m);
  scatter_xyzw(shadow_wo, index, r->wo, (lfloat)(0.0f), m);
  scatter_int(shadow_material, index, r->material, m);
  scatter_uint(shadow_depth, index, r->depth, m);
}

FH_INLINE ShadowRequest load_shadow_request(luint index FH_SHADOW_PARAMS) {
  ShadowRequest r;
  r.path = gather_uint(shadow_path, index);
  r.at.position = gather_xyzw(shadow_position, index, &r.at.magnitude);
  r.at.normal = gather_xyz(shadow_geometric, index);
  r.shading_normal = gather_xyz(shadow_normal, index);
  r.albedo = gather_xyz(shadow_albedo, index);
  r.throughput = gather_xyz(shadow_throughput, index);
  r.wo = gather_xyz(shadow_wo, index);
  r.material = gather_int(shadow_material, index);
  r.depth = gather_uint(shadow_depth, index);
  return r;
}
#endif

#endif

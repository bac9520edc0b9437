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
  X(uint, sample_id, 4)         /* global sample index: pixel = id % pixels, pass = id / pixels */ \
  X(uint, local_pass, 4)        /* this device's pass number for the sample: its pass buffer */    \
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
#define FH_DIM_LIGHT_PICK 3
#define FH_DIM_LIGHT_U1 4
#define FH_DIM_LIGHT_U2 5
#define FH_DIM_BSDF_LOBE 6
// The sub-pixel position (two dimensions), far above every bounce's.
#define FH_DIM_PIXEL 0x7fff0000u

#ifdef __OPENCL_VERSION__
#define FH_PATH_PARAM(type, name, bytes) , __global type* name
// Appended to a kernel's parameter list: `__kernel void k(int a FH_PATH_PARAMS)`.
#define FH_PATH_PARAMS FH_PATH_FIELDS(FH_PATH_PARAM)
#define FH_SHADOW_PARAMS FH_SHADOW_FIELDS(FH_PATH_PARAM)
#endif

// Passes in flight on a device: pass p uses pass-buffer slot p % FH_PASS_SLOTS.
#ifndef FH_PASS_SLOTS
#define FH_PASS_SLOTS FH_MAX_PASS_SLOTS
#endif

#endif

// The scene's device buffers, declared once. The stages that read the scene take all of it
// as one SceneView; their kernels take the buffers as FH_SCENE_PARAMS, and the host
// (host/render/device_scene.h) expands the same list into its buffers and binds them in
// this order, checking every kernel's argument count.
#ifndef FH_SCENE_VIEW_H
#define FH_SCENE_VIEW_H

#include "types.h"

// X(element type, name): what it holds
#define FH_SCENE_FIELDS(X)                                                                         \
  X(Bvh8Node, nodes)             /* the BVH's nodes (intersect.h) */                               \
  X(TriangleBlock8, blocks)      /* its leaves' triangles, eight to a block */                     \
  X(float4, triangles)           /* three corners per triangle, BVH order */                       \
  X(int, triangle_material)      /* material per triangle, BVH order */                            \
  X(GpuMaterial, materials)      /* FH_MATERIAL_WORDS words each */                                \
  X(float, light_cdf)            /* the light pick's CDF over emissive triangles (lights.h) */     \
  X(int, light_triangle)         /* the triangle of each CDF entry */                              \
  X(float, light_pdf_area)       /* per triangle: P(pick) / area, 0 for non-emitters */            \
  X(float4, normals)             /* vertex normals, three per triangle (FH_SHADING_NORMALS) */     \
  X(float2, uvs)                 /* texture coordinates, three per triangle (FH_TEXTURES) */       \
  X(uint, texels)                /* every texture's texels after the sRGB table (surface.h) */     \
  X(uint4, texture_info)         /* per texture: first texel, width, height, format */             \
  X(float, env_map)              /* the environment map and its sampling tables (environment.h) */

#ifdef __OPENCL_VERSION__
#define FH_SCENE_PARAM(type, name) , __global const type* name
#define FH_SCENE_MEMBER(type, name) __global const type* name;
#define FH_SCENE_INIT(type, name) name,
// Appended to a kernel's parameter list: `__kernel void k(int a FH_SCENE_PARAMS)`.
#define FH_SCENE_PARAMS FH_SCENE_FIELDS(FH_SCENE_PARAM)
// The kernel's scene buffers as one value for the stage functions.
#define FH_SCENE_VIEW {FH_SCENE_FIELDS(FH_SCENE_INIT)}

typedef struct {
  FH_SCENE_FIELDS(FH_SCENE_MEMBER)
} SceneView;
#endif

#endif

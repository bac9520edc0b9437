// What shading needs at a hit beyond its geometry, each only when the scene has it (the
// host compiles with FH_SHADING_NORMALS and FH_TEXTURES only then): the interpolated
// shading normal and the diffuse albedo from map_Kd (bilinear, wrapping, stored linear).
#ifndef FH_SURFACE_H
#define FH_SURFACE_H

#include "types.h"

// Texture i covers texels[offset .. offset + width * height) (float4, linear RGB, rows
// from the top); texture_info[i] = (offset, width, height, unused).
FH_INLINE float3 texture_lookup(__global const float4* texels, __global const uint4* texture_info, int texture,
                                float2 uv) {
  const uint4 info = texture_info[texture];
  const float w = (float)info.y, h = (float)info.z;
  // OBJ's v runs up the image; texel rows run down it.
  const float x = (uv.x - floor(uv.x)) * w - 0.5f, y = (1.0f - (uv.y - floor(uv.y))) * h - 0.5f;
  const float fx = floor(x), fy = floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = (int)fx, y0 = (int)fy;
  const int iw = (int)info.y, ih = (int)info.z;
  const int xa = (x0 % iw + iw) % iw, xb = (xa + 1) % iw, ya = (y0 % ih + ih) % ih, yb = (ya + 1) % ih;
  __global const float4* t = texels + info.x;
  const float4 top = mix(t[ya * iw + xa], t[ya * iw + xb], tx), bottom = mix(t[yb * iw + xa], t[yb * iw + xb], tx);
  return mix(top, bottom, ty).xyz;
}

// The shading normal at barycentrics (b1, b2), turned to the side of `ng` (the geometric
// normal on the viewer's side): interpolated normals may disagree with the winding.
FH_INLINE float3 shading_normal(__global const float4* normals, int t, float b1, float b2, float3 ng) {
  const float3 n = (1.0f - b1 - b2) * normals[3 * t].xyz + b1 * normals[3 * t + 1].xyz + b2 * normals[3 * t + 2].xyz;
  const float len = length(n);
  if (!(len > 0.0f)) return ng;
  const float3 ns = n / len;
  return dot(ns, ng) >= 0.0f ? ns : -ns;
}

FH_INLINE float2 surface_uv(__global const float2* uvs, int t, float b1, float b2) {
  return (1.0f - b1 - b2) * uvs[3 * t] + b1 * uvs[3 * t + 1] + b2 * uvs[3 * t + 2];
}

#endif

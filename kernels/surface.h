// What shading needs at a hit beyond its geometry, each only when the scene has it (the
// host compiles with FH_SHADING_NORMALS and FH_TEXTURES only then): the interpolated
// shading normal and the diffuse albedo from map_Kd (bilinear, wrapping, stored linear).
// Lane-wise (lanes.h).
#ifndef FH_SURFACE_H
#define FH_SURFACE_H

#include "ray.h"

// Texture i: texture_info[i] = (offset, width, height, format) into texels, 32-bit words,
// rows from the top (host/render/device_scene.h). Format 1: an 8-bit sRGB image, a word per
// texel (R | G << 8 | B << 16), each code decoded by the table of linear values (float
// bits) in texels[0 .. 256). Format 0: linear float RGBA, four words per texel.
FH_INLINE float3 texel_at(__global const uint* texels, uint4 info, int index) {
  if (info.w == 1u) {
    const uint code = texels[info.x + (uint)index];
    return (float3)(as_float(texels[code & 255u]), as_float(texels[(code >> 8) & 255u]),
                    as_float(texels[(code >> 16) & 255u]));
  }
  return vload3(0, (__global const float*)(texels + info.x + 4u * (uint)index));
}

// One bilinear lookup, wrapping.
FH_INLINE float3 texture_texel(__global const uint* texels, __global const uint4* texture_info, int texture,
                               float2 uv) {
  const uint4 info = texture_info[texture];
  const float w = (float)info.y, h = (float)info.z;
  // OBJ's v runs up the image; texel rows run down it.
  const float x = (uv.x - floor(uv.x)) * w - 0.5f, y = (1.0f - (uv.y - floor(uv.y))) * h - 0.5f;
  const float fx = floor(x), fy = floor(y);
  const float tx = x - fx, ty = y - fy;
  const int iw = (int)info.y, ih = (int)info.z;
  // The wrapped texel columns and rows without integer divisions (which vector units lack):
  // x and y lie in [-0.5, size - 0.5], so fx and fy lie in [-1, size - 1], and only -1
  // wraps. The clamp keeps non-finite coordinates inside the texture.
  const int xa = clamp((int)fx + (fx < 0.0f ? iw : 0), 0, iw - 1);
  const int ya = clamp((int)fy + (fy < 0.0f ? ih : 0), 0, ih - 1);
  const int xb = xa + 1 == iw ? 0 : xa + 1, yb = ya + 1 == ih ? 0 : ya + 1;
  const float3 top = mix(texel_at(texels, info, ya * iw + xa), texel_at(texels, info, ya * iw + xb), tx);
  const float3 bottom = mix(texel_at(texels, info, yb * iw + xa), texel_at(texels, info, yb * iw + xb), tx);
  return mix(top, bottom, ty);
}

// The textured albedo in the lanes with a texture (texture >= 0), `albedo` in the others.
// Texture fetches are gathers whatever the lanes, so each lane looks up its own.
FH_INLINE lvec3 texture_lookup(__global const uint* texels, __global const uint4* texture_info, lint texture,
                               lvec2 uv, lvec3 albedo) {
  FH_FOR_LANES(l) {
    if (LANE(texture, l) < 0) continue;
    const float3 c = texture_texel(texels, texture_info, LANE(texture, l), (float2)(LANE(uv.x, l), LANE(uv.y, l)));
    LANE(albedo.x, l) = c.x;
    LANE(albedo.y, l) = c.y;
    LANE(albedo.z, l) = c.z;
  }
  return albedo;
}

// The shading normal at barycentrics (b1, b2), turned to the side of `ng` (the geometric
// normal on the viewer's side): interpolated normals may disagree with the winding.
// Zero normals (a scene without any, under a kernel compiled with every feature) give ng.
FH_INLINE lvec3 shading_normal(__global const float4* normals, lint t, lfloat b1, lfloat b2, lvec3 ng) {
  const lvec3 n = v3_add(v3_add(v3_scale(triangle_corner(normals, t, 0), 1.0f - b1 - b2),
                                v3_scale(triangle_corner(normals, t, 1), b1)),
                         v3_scale(triangle_corner(normals, t, 2), b2));
  const lvec3 ns = v3_normalize(n);
  return v3_select(!(v3_dot(n, n) > 0.0f), ng, v3_select(v3_dot(ns, ng) >= 0.0f, ns, v3_neg(ns)));
}

FH_INLINE lvec2 surface_uv(__global const float2* uvs, lint t, lfloat b1, lfloat b2) {
  const luint i = las_uint(3 * t);
  const lvec2 a = gather_xy(uvs, i), b = gather_xy(uvs, i + 1), c = gather_xy(uvs, i + 2);
  const lfloat w = 1.0f - b1 - b2;
  return lv2(w * a.x + b1 * b.x + b2 * c.x, w * a.y + b1 * b.y + b2 * c.y);
}

#endif

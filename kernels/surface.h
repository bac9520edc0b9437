// What shading needs at a hit beyond its geometry, each only when the scene has it (the
// host compiles with FH_SHADING_NORMALS and FH_TEXTURES only then): the interpolated
// shading normal and the diffuse albedo from map_Kd (bilinear, wrapping, stored linear).
// Lane-wise (lanes.h).
#ifndef FH_SURFACE_H
#define FH_SURFACE_H

#include "ray.h"

// Texture i: texture_info[i] = (offset, width, height, format) into texels, 32-bit words,
// rows from the top (host/render/device_scene.h). FH_TEXELS_SRGB8: a word per texel
// (R | G << 8 | B << 16), each code decoded by the table of linear values (float bits) in
// texels[0 .. 256). FH_TEXELS_LINEAR_FLOAT: linear float RGBA, four words per texel.
FH_INLINE float3 texel_at(__global const uint* texels, uint offset, uint format, int index) {
  if (format == FH_TEXELS_SRGB8) {
    const uint code = texels[offset + (uint)index];
    return (float3)(as_float(texels[code & 255u]), as_float(texels[(code >> 8) & 255u]),
                    as_float(texels[(code >> 16) & 255u]));
  }
  return vload3(0, (__global const float*)(texels + offset + 4u * (uint)index));
}

// The lanes' texels at (column, row), each from its lane's texture.
FH_INLINE lvec3 gather_texels(__global const uint* texels, luint offset, luint format, lint column, lint row,
                              lint width) {
  const lint index = row * width + column;
  lvec3 c;
  FH_FOR_LANES(l) {
    const float3 t = texel_at(texels, LANE(offset, l), LANE(format, l), LANE(index, l));
    LANE(c.x, l) = t.x;
    LANE(c.y, l) = t.y;
    LANE(c.z, l) = t.z;
  }
  return c;
}

FH_INLINE lvec3 v3_mix(lvec3 a, lvec3 b, lfloat t) { return v3(mix(a.x, b.x, t), mix(a.y, b.y, t), mix(a.z, b.z, t)); }

// The textured albedo in the lanes with a texture (texture >= 0), `albedo` in the others:
// bilinear, wrapping. The coordinates are computed for all lanes at once and the texel
// loads of all lanes issued together, so their cache misses overlap.
FH_INLINE lvec3 texture_lookup(__global const uint* texels, __global const uint4* texture_info, lint texture,
                               lvec2 uv, lvec3 albedo) {
  const lmask textured = texture >= 0;
  if (!lanes_any(textured)) return albedo;
  // Lanes without a texture read texture 0's first texel and are dropped at the end.
  luint offset, format;
  lint iw, ih;
  FH_FOR_LANES(l) {
    const uint4 info = texture_info[LANE(textured, l) ? LANE(texture, l) : 0];
    LANE(offset, l) = info.x;
    LANE(iw, l) = (int)info.y;
    LANE(ih, l) = (int)info.z;
    LANE(format, l) = info.w;
  }
  const lfloat w = lconvert_float(iw), h = lconvert_float(ih);
  const lfloat u = select((lfloat)(0.0f), uv.x, textured), v = select((lfloat)(0.0f), uv.y, textured);
  // OBJ's v runs up the image; texel rows run down it.
  const lfloat x = (u - floor(u)) * w - 0.5f, y = (1.0f - (v - floor(v))) * h - 0.5f;
  const lfloat fx = floor(x), fy = floor(y);
  const lfloat tx = x - fx, ty = y - fy;
  // The wrapped texel columns and rows without integer divisions (which vector units lack):
  // x and y lie in [-0.5, size - 0.5], so fx and fy lie in [-1, size - 1], and only -1
  // wraps. The clamp keeps non-finite coordinates inside the texture.
  const lint xa = clamp(lconvert_int(fx) + select((lint)(0), iw, fx < 0.0f), (lint)(0), iw - 1);
  const lint ya = clamp(lconvert_int(fy) + select((lint)(0), ih, fy < 0.0f), (lint)(0), ih - 1);
  const lint xb = select(xa + 1, (lint)(0), xa + 1 == iw), yb = select(ya + 1, (lint)(0), ya + 1 == ih);
  const lvec3 top = v3_mix(gather_texels(texels, offset, format, xa, ya, iw),
                           gather_texels(texels, offset, format, xb, ya, iw), tx);
  const lvec3 bottom = v3_mix(gather_texels(texels, offset, format, xa, yb, iw),
                              gather_texels(texels, offset, format, xb, yb, iw), tx);
  return v3_select(textured, v3_mix(top, bottom, ty), albedo);
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

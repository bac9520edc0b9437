// The HDR environment light (FH_ENV_MAP): radiance from a latitude-longitude map for rays
// that leave the scene, and directions drawn from the map for next-event estimation, in
// proportion to the map's luminance per solid angle (a piecewise-constant 2D distribution:
// a row by the marginal CDF, then a column by that row's CDF). Both sides compute one
// density for a direction (environment_pdf), so mis weighs them consistently.
// Conventions (host/scene/environment_map.h): +y up, row 0 at theta = 0, u = 0.5 along -z,
// u growing towards +x; params.env_u_shift turns the map about +y. Lane-wise (lanes.h).
//
// The env_map buffer holds, for a width x height map: per texel four floats (rgb radiance,
// density per unit uv area), then each row's CDF over its columns, then the CDF over rows.
#ifndef FH_ENVIRONMENT_H
#define FH_ENVIRONMENT_H

#include "lanes.h"
#include "sampling.h"

// Texels are picked by u, v on [0,1)^2; a direction's solid angle is 2 pi^2 sin(theta) du dv.
#define FH_ENV_SOLID_ANGLE_PER_UV (2.0f * M_PI_F * M_PI_F)

// Texel i's radiance, and its density per unit uv area in *density.
FH_INLINE lvec3 environment_texel(__global const float* env_map, luint i, lfloat* density) {
  const luint word = 4u * i;
  *density = gather_float(env_map + 3, word);
  return v3(gather_float(env_map, word), gather_float(env_map + 1, word), gather_float(env_map + 2, word));
}

// The density per solid angle of a texel's density per uv area, at sin(theta).
FH_INLINE lfloat environment_pdf(lfloat density, lfloat sin_theta) {
  return select((lfloat)(0.0f), density / (FH_ENV_SOLID_ANGLE_PER_UV * sin_theta), sin_theta > 0.0f);
}

// The radiance arriving from direction d (unit), and in *pdf the density per solid angle
// with which environment_sample draws d (before the light pick's probability).
FH_INLINE lvec3 environment_lookup(RenderParams params, __global const float* env_map, lvec3 d, lfloat* pdf) {
  const lfloat v = acos(clamp(d.y, -1.0f, 1.0f)) * M_1_PI_F;
  const lfloat u_unwrapped = atan2(d.x, -d.z) * (0.5f * M_1_PI_F) + 0.5f + params.env_u_shift;
  const lfloat u = u_unwrapped - floor(u_unwrapped);
  const luint column = min(lconvert_uint(u * (float)(params.env_width)), (luint)(params.env_width - 1));
  const luint row = min(lconvert_uint(v * (float)(params.env_height)), (luint)(params.env_height - 1));
  lfloat density;
  const lvec3 radiance = environment_texel(env_map, row * params.env_width + column, &density);
  *pdf = environment_pdf(density, sqrt(d.x * d.x + d.z * d.z));
  return radiance;
}

// Where u lies between the CDF entry before `index` and that one, in [0, 1), for each lane
// (index from search_cdf over the entries from cdf[first]).
FH_INLINE lfloat cdf_fraction(__global const float* cdf, luint first, luint index, lfloat u) {
  const luint before = first + index - min(index, (luint)(1u));  // (first itself for index 0)
  const lfloat below = select((lfloat)(0.0f), gather_float(cdf, before), index > 0u);
  const lfloat width = gather_float(cdf, first + index) - below;
  return select((lfloat)(0.5f), clamp((u - below) / width, 0.0f, 0x1.fffffep-1f), width > 0.0f);
}

// A direction drawn from the map, the radiance arriving from it and its density per solid
// angle (pdf 0: no sample, at a pole).
typedef struct {
  lvec3 wi, radiance;
  lfloat pdf;
} EnvironmentSample;

FH_INLINE EnvironmentSample environment_sample(RenderParams params, __global const float* env_map, lfloat u1,
                                               lfloat u2) {
  const uint width = params.env_width, height = params.env_height;
  __global const float* row_cdf = env_map + 4 * width * height;
  __global const float* marginal_cdf = row_cdf + width * height;
  const luint row = search_cdf(marginal_cdf, (luint)(0u), height, u1);
  const luint row_start = row * width;
  const luint column = search_cdf(row_cdf, row_start, width, u2);
  const luint texel = row_start + column;
  const lfloat v = (lconvert_float(row) + cdf_fraction(marginal_cdf, (luint)(0u), row, u1)) / (float)(height);
  const lfloat u = (lconvert_float(column) + cdf_fraction(row_cdf, row_start, column, u2)) / (float)(width);
  EnvironmentSample s;
  lfloat density;
  s.radiance = environment_texel(env_map, texel, &density);
  const lvec2 theta = sincos_reduced(M_PI_F * v);  // (sin, cos)
  const lvec2 phi = sincos_reduced(2.0f * M_PI_F * (u - 0.5f - params.env_u_shift));
  s.wi = v3(theta.x * phi.x, theta.y, -theta.x * phi.y);
  s.pdf = environment_pdf(density, theta.x);
  return s;
}

#endif

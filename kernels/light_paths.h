// What light paths share (light tracing, kernels/light_trace.cl; bidirectional path tracing,
// kernels/bdpt.cl): contributions added as whole film quanta with integer atomics (splats),
// the pinhole as a point sees it, the surfaces light paths reach and the adjoint weight of
// their BSDF samples, and a light path's bounce with its roulette. Written for FH_LANES
// paths a work-item (lanes.h): a light path's rays and splats go lane by lane, the rest in
// the lanes together.
#ifndef FH_LIGHT_PATHS_H
#define FH_LIGHT_PATHS_H

#include "bsdf.h"
#include "intersect.h"
#include "lane_rays.h"
#include "lights.h"
#include "ray.h"
#include "rng.h"
#include "sampling.h"
#include "scene_view.h"
#include "surface.h"

// A splat's resolution, the film's quantum (host/render/film.h), and its cap: 2^24 quanta
// of radiance in one splat keep 65536 of them per pixel below 2^64.
#define FH_SPLAT_QUANTA 16777216.0f
#define FH_SPLAT_MOST 16777216.0f

// Per pass: the pass's splats, three 64-bit sums (low, high words) per pixel.
#define FH_SPLAT_WORDS 6

// Adds v >= 0, as whole quanta, to the 64-bit integer at sum (low word first): the carry
// out of the low word goes into the high word, so the total is exact in any order.
FH_INLINE void add_quanta(volatile __global uint* sum, float v) {
  const ulong q = convert_ulong_sat_rte(fmin(v, FH_SPLAT_MOST) * FH_SPLAT_QUANTA);
  const uint low = (uint)q, high = (uint)(q >> 32);
  if (low != 0u) {
    const uint before = atomic_add(sum, low);
    if (before + low < before) atomic_inc(sum + 1);
  }
  if (high != 0u) atomic_add(sum + 1, high);
}

// Pixel filter g(d) over one axis (a density: it integrates to one), tabulated over
// [-radius, radius] by the host (render/pixel_filter.h).
FH_INLINE float filter_density(__global const float* table, uint size, float radius, float d) {
  const float x = (d + radius) / (2.0f * radius) * (float)(size - 1);
  if (!(x >= 0.0f && x <= (float)(size - 1))) return 0.0f;
  const uint i = min((uint)x, size - 2);
  return mix(table[i], table[i + 1], x - (float)i);
}

// Adds the radiance c seen at image position p (pixels) to every pixel whose filter covers p,
// weighted by its filter there. The box filter covers one pixel, the one p lies in.
FH_INLINE void splat(RenderParams params, volatile __global uint* splats, __global const float* density, float2 p,
                     float3 c) {
  const int w = params.camera.width, h = params.camera.height;
  const float r = params.filter_radius;
  const bool box = r <= 0.5f;  // weight one in the pixel p lies in, none elsewhere
  const int x0 = box ? (int)floor(p.x) : (int)ceil(p.x - 0.5f - r), x1 = box ? x0 : (int)floor(p.x - 0.5f + r);
  const int y0 = box ? (int)floor(p.y) : (int)ceil(p.y - 0.5f - r), y1 = box ? y0 : (int)floor(p.y - 0.5f + r);
  for (int y = max(y0, 0); y <= min(y1, h - 1); ++y) {
    const float gy = box ? 1.0f : filter_density(density, params.filter_table_size, r, p.y - ((float)y + 0.5f));
    for (int x = max(x0, 0); x <= min(x1, w - 1); ++x) {
      const float g = gy * (box ? 1.0f : filter_density(density, params.filter_table_size, r, p.x - ((float)x + 0.5f)));
      if (g <= 0.0f) continue;
      volatile __global uint* sum = splats + FH_SPLAT_WORDS * ((uint)y * (uint)w + (uint)x);
      add_quanta(sum, c.x * g);
      add_quanta(sum + 2, c.y * g);
      add_quanta(sum + 4, c.z * g);
    }
  }
}

// A point as the pinhole sees it: the unit direction to the camera, from the ray origin
// just off the surface on the camera's side; the image position (pixels, (0, 0) at the
// top-left corner, as camera_ray_direction takes it) and the importance per pixel filter,
// 1 / (A d^2 cos^3 theta). `seen`: in front of the camera and within a filter's reach of
// the image.
typedef struct {
  lvec3 origin, to_camera;
  lfloat distance, importance;
  lvec2 image;
  lmask seen;
} CameraView;

FH_INLINE CameraView camera_view(RenderParams params, const SurfacePoint* at) {
  const CameraParams* cam = &params.camera;
  const lvec3 eye = v3_uniform(vload3(0, cam->origin)), f = v3_uniform(vload3(0, cam->forward)),
              right = v3_uniform(vload3(0, cam->right)), up = v3_uniform(vload3(0, cam->up));
  CameraView v;
  v.origin = offset_ray_origin(at, v3_sub(eye, at->position));
  const lvec3 d = v3_sub(eye, v.origin);
  v.distance = v3_length(d);
  v.to_camera = v3_scale(d, 1.0f / v.distance);
  // Toward the point from the camera, on the image plane one unit ahead.
  const lfloat cos_theta = -v3_dot(v.to_camera, f);
  const lvec3 q = v3_scale(v.to_camera, -1.0f / cos_theta);
  const lfloat sx = v3_dot(q, right) / v3_dot(right, right), sy = v3_dot(q, up) / v3_dot(up, up);
  v.image = lv2(0.5f * (sx + 1.0f) * (float)cam->width, 0.5f * (1.0f - sy) * (float)cam->height);
  const float reach = fmax(params.filter_radius - 0.5f, 0.0f);
  v.seen = cos_theta > 0.0f && v.distance > 0.0f && v.image.x >= -reach && v.image.x < (float)cam->width + reach &&
           v.image.y >= -reach && v.image.y < (float)cam->height + reach;
  const lfloat film_area = 4.0f * v3_length(right) * v3_length(up);
  v.importance = 1.0f / (film_area * v.distance * v.distance * cos_theta * cos_theta * cos_theta);
  return v;
}

// What one light path counts: rays traced and contributions dropped as NaN or infinite.
typedef struct {
  uint bounce_rays, camera_rays, nonfinite;
} LightTally;

// Adds a work-item's tally to the launch's (bounce rays, camera rays, non-finite values).
FH_INLINE void add_tally(__global uint* tallies, const LightTally* tally) {
  atomic_add(tallies, tally->bounce_rays);
  atomic_add(tallies + 1, tally->camera_rays);
  if (tally->nonfinite) atomic_add(tallies + 2, tally->nonfinite);
}

// Of the lanes where `active`, those whose ray from org along dir is clear up to t_max (each
// lane's ray in turn); each ray counts as a camera ray.
FH_INLINE lmask clear_lanes(const SceneView* scene, lvec3 org, lvec3 dir, lfloat t_max, lmask active,
                            LightTally* tally) {
  tally->camera_rays += lanes_count(active);
  LaneRays rays;
  precompute_lane_rays(org, dir, &rays);
  uint clear = 0u;
  for (uint left = lanes_bits(active); left != 0u; left &= left - 1u) {
    const int l = lowest_bit(left);
    if (find_occluder_precomputed(scene->nodes, scene->blocks, lane_ray(&rays, l), 0.0f, LANE(t_max, l)) < 0)
      clear |= 1u << l;
  }
  return lanes_of_bits(clear);
}

// Splats `value` (the contribution before the camera's importance) where the camera sees
// v from, in the lanes where `active` and nothing lies between.
FH_INLINE void connect_to_camera(RenderParams params, const SceneView* scene, const CameraView* v, lvec3 value,
                                 lmask active, volatile __global uint* splats, __global const float* density,
                                 LightTally* tally) {
  const lvec3 c = v3_scale(value, v->importance);
  lmask connects = active && v3_any_positive(c);
  const lmask finite = isfinite(c.x) && isfinite(c.y) && isfinite(c.z);
  tally->nonfinite += lanes_count(connects && !finite);
  connects = connects && finite;
  if (!lanes_any(connects)) return;
  const lmask seen = clear_lanes(scene, v->origin, v->to_camera, v->distance * FH_SHADOW_SHORTEN, connects, tally);
  for (uint left = lanes_bits(seen); left != 0u; left &= left - 1u) {
    const int l = lowest_bit(left);
    splat(params, splats, density, (float2)(LANE(v->image.x, l), LANE(v->image.y, l)), v3_lane(c, l));
  }
}

// The closest hit of each lane's ray where `active` (closest_hits over the whole ray).
FH_INLINE LaneHit trace_lanes(const SceneView* scene, lvec3 org, lvec3 dir, lmask active) {
  return closest_hits(scene->nodes, scene->blocks, org, dir, (lfloat)(0.0f), (lfloat)(INFINITY), active);
}

// The surface a light path reached: point, normals (the shading normal on the geometric
// normal's side, as shade's shading_at gives it) and BSDF, textured.
typedef struct {
  SurfacePoint point;
  lvec3 shading_normal;
  Bsdf bsdf;
} LightVertex;

// Triangle t (a valid index in every lane) at barycentrics (b1, b2).
FH_INLINE LightVertex light_vertex(const SceneView* scene, lint t, lfloat b1, lfloat b2) {
  LightVertex v;
  v.point = surface_point(scene->triangles, t, b1, b2);
  const MaterialLanes m = material_lanes(scene->materials, gather_int(scene->triangle_material, las_uint(t)));
  v.bsdf = material_bsdf(&m);
#if defined(FH_SHADING_NORMALS)
  v.shading_normal = shading_normal(scene->normals, t, b1, b2, v.point.normal);
#else
  v.shading_normal = v.point.normal;
#endif
#if defined(FH_TEXTURES)
  v.bsdf.kd =
      texture_lookup(scene->texels, scene->texture_info, m.texture, surface_uv(scene->uvs, t, b1, b2), v.bsdf.kd);
#endif
  return v;
}

// The adjoint weight of a BSDF sample taken with wo = w_in (toward where the light came
// from): f(w_next <- w_in) |n.w_in| |g.w_next| / (|g.w_in| pdf), the shading normal's cosine
// at the incoming side in place of the geometric one (Veach §5.3). Smooth lobes are
// evaluated the other way round (the diffuse share depends on the outgoing direction); a
// delta lobe's radiance weight is used without the 1/eta^2 of a refraction, which
// radiance has and importance has not.
FH_INLINE lvec3 adjoint_weight(const LightVertex* v, lvec3 n, lvec3 w_in, const BsdfSample* s) {
  const lfloat cos_g_in = fabs(v3_dot(v->point.normal, w_in)), cos_g_next = fabs(v3_dot(v->point.normal, s->wi));
  const lfloat correction = fabs(v3_dot(n, w_in)) * cos_g_next / cos_g_in;
  lvec3 weight = v3_scale(s->weight, correction / fabs(v3_dot(n, s->wi)));
#if defined(FH_GLASS)
  const lmask refracted = v3_dot(v->point.normal, w_in) * v3_dot(v->point.normal, s->wi) < 0.0f;
  const lmask scaled = has_lobe(&v->bsdf, FH_LOBE_GLASS) && refracted;
  if (lanes_any(scaled)) {
    const lfloat eta = select(1.0f / v->bsdf.eta, v->bsdf.eta, v3_dot(v->point.normal, w_in) >= 0.0f);
    weight = v3_select(scaled, v3_scale(weight, eta * eta), weight);
  }
#endif
  const lmask smooth = s->pdf > 0.0f;
  if (lanes_any(smooth))
    weight = v3_select(smooth, v3_scale(bsdf_eval(&v->bsdf, n, s->wi, w_in), correction / s->pdf), weight);
  return weight;
}

// A light path's next bounce from v, in the lanes where `active`: a BSDF sample with the
// light's side as wo, its adjoint weight into alpha and into `carried` (the weights since
// the light, which roulette reads), and Russian roulette from params.rr_depth scatterings
// on. Returns the sample; pdf 0: the path ends there. The lanes draw the same dimensions
// (*dim) at a bounce, so one count serves them all.
FH_INLINE BsdfSample bounce_light_path(RenderParams params, const LightVertex* v, lvec3 n, lvec3 w_in, lmask active,
                                       uint scatterings, luint stream, luint path, uint* dim, lvec3* alpha,
                                       lvec3* carried) {
  const lfloat u0 = random_float(stream, path, (luint)((*dim)++));
  const lfloat u1 = random_float(stream, path, (luint)((*dim)++)), u2 = random_float(stream, path, (luint)((*dim)++));
  BsdfSample s = bsdf_sample(&v->bsdf, v->point.normal, v->shading_normal, w_in, u0, u1, u2);
  lmask goes = active && s.pdf != 0.0f;
  const lvec3 weight = adjoint_weight(v, n, w_in, &s);
  *alpha = v3_select(goes, v3_mul(*alpha, weight), *alpha);
  *carried = v3_select(goes, v3_mul(*carried, weight), *carried);
  if (scatterings >= params.rr_depth) {
    const lfloat survive = fmin(v3_max_component(*carried), 0.95f);
    goes = goes && !(random_float(stream, path, (luint)((*dim)++)) >= survive);
    *alpha = v3_select(goes, v3_scale(*alpha, 1.0f / survive), *alpha);
    *carried = v3_select(goes, v3_scale(*carried, 1.0f / survive), *carried);
  }
  goes = goes && v3_any_positive(*alpha);
  s.pdf = select((lfloat)(0.0f), s.pdf, goes);
  return s;
}

#endif

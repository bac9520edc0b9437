// The shadow-connect stage: next-event estimation for each light-sample request that
// shade queued. Picks a light by the host's light table (device_scene.h): an emissive
// triangle and a point on it (uniform in the solid angle it subtends, or in area:
// lights.h), or with FH_ENV_MAP the environment map and a direction from it
// (environment.h); traces the shadow ray (V(x,y)), and adds the unoccluded contribution,
// weighted against BSDF sampling for mis.
// Each work-item connects FH_LANES consecutive requests (lanes.h); their shadow rays are
// traced one after the other.
// The stage's functions; kernels/shadow_connect.cl holds its kernel, and the megakernel calls them.
#ifndef FH_SHADOW_CONNECT_STAGE_H
#define FH_SHADOW_CONNECT_STAGE_H

#include "bsdf.h"
#include "lane_rays.h"
#include "lights.h"
#include "path_state.h"
#include "ray.h"
#include "sampler.h"
#include "sampling.h"
#include "scene_view.h"
#if defined(FH_ENV_MAP)
#include "environment.h"
#endif

// A light sample as a receiver at `origin` sees it: the direction to it, the radiance
// arriving from there, its density per solid angle (the light's pick included; 0: no
// sample), and the shadow ray that tests V(x, y).
typedef struct {
  lvec3 wi, radiance;
  lfloat pdf;
  lvec3 shadow_direction;
  lfloat shadow_distance;
} LightSample;

// A point on an emissive triangle picked by the light table: uniform in the solid
// angle it subtends where light_seen_from chooses that, else uniform in area.
FH_INLINE LightSample sample_light_triangle(lvec3 origin, luint light, lvec2 u, __global const float4* triangles,
                                            __global const int* triangle_material,
                                            __global const GpuMaterial* materials, __global const int* light_triangle,
                                            __global const float* light_pdf_area) {
  const lint lt = gather_int(light_triangle, light);
  const LightTriangle light_tri = light_triangle_from(triangles, lt, gather_float(light_pdf_area, las_uint(lt)), origin);
  lvec2 b = sample_triangle(u.x, u.y);
  const lmask by_angle = light_tri.seen.solid_angle > 0.0f;
  if (lanes_any(by_angle)) {
    const lvec2 along = barycentrics_along(origin, sample_spherical_triangle(&light_tri.seen, u.x, u.y), light_tri.v0,
                                           light_tri.v1, light_tri.v2);
    b = lv2(select(b.x, along.x, by_angle), select(b.y, along.y, by_angle));
  }
  const SurfacePoint l = surface_point_between(light_tri.v0, light_tri.v1, light_tri.v2, b.x, b.y);
  const lvec3 to_light = v3_sub(l.position, origin);
  const lfloat dist2 = v3_dot(to_light, to_light);
  LightSample ls;
  ls.wi = v3_scale(to_light, rsqrt(dist2));
  const lfloat cos_light = -v3_dot(l.normal, ls.wi);
  // The light's back emits nothing.
  ls.pdf = select((lfloat)(0.0f), light_pdf(&light_tri, dist2, cos_light), dist2 > 0.0f && cos_light > 0.0f);
  ls.radiance = material_lanes(materials, gather_int(triangle_material, las_uint(lt))).ke;
  // V(x, y): the segment from just off the surface to just short of the light point.
  const lvec3 d = v3_sub(offset_ray_origin(&l, v3_neg(ls.wi)), origin);
  ls.shadow_distance = v3_length(d);
  ls.shadow_direction = v3_scale(d, 1.0f / ls.shadow_distance);
  ls.shadow_distance *= FH_SHADOW_SHORTEN;
  return ls;
}

#if defined(FH_ENV_MAP)
// A direction drawn from the environment map; its shadow ray goes to infinity.
FH_INLINE LightSample sample_light_environment(RenderParams params, lvec2 u, __global const float* env_map) {
  const EnvironmentSample e = environment_sample(params, env_map, u.x, u.y);
  LightSample ls;
  ls.wi = ls.shadow_direction = e.wi;
  ls.radiance = e.radiance;
  ls.pdf = params.env_pick * e.pdf;
  ls.shadow_distance = (lfloat)(INFINITY);
  return ls;
}

FH_INLINE LightSample select_light_sample(lmask m, LightSample a, LightSample b) {
  LightSample s;
  s.wi = v3_select(m, a.wi, b.wi);
  s.radiance = v3_select(m, a.radiance, b.radiance);
  s.pdf = select(b.pdf, a.pdf, m);
  s.shadow_direction = v3_select(m, a.shadow_direction, b.shadow_direction);
  s.shadow_distance = select(b.shadow_distance, a.shadow_distance, m);
  return s;
}
#endif

// Connects the requests r where `active`, whose paths' samples are `sampler`: adds each
// unoccluded light sample's contribution to its path's radiance.
FH_INLINE void connect_light(RenderParams params, const ShadowRequest* r, const PixelSampler* sampler, lmask active,
                             const SceneView* scene FH_PATH_PARAMS) {
  const luint p = r->path;
  const SurfacePoint s = r->at;  // its normal: the geometric normal on the viewer's side
  const lvec3 n = r->shading_normal;  // same side
  const luint dim = r->depth * FH_DIMS_PER_BOUNCE;

  // Connect from the point just off the surface that BSDF-sampled rays also start from:
  // both strategies then see the same geometry, and their MIS weights sum to one even
  // where the offset is a visible distance (far from the origin).
  const lvec3 origin = offset_ray_origin(&s, s.normal);
  // The pick, by u.y (lights.h): the environment map below params.env_pick, a triangle by
  // the light CDF (whose entries start at env_pick) above.
  const lvec2 u = sample_2d(sampler, dim + FH_DIM_LIGHT_U1);
  LightPick pick;
  pick.light = (luint)(0u);
  pick.within = (lfloat)(0.0f);
  pick.narrow = lanes_mask(false);
  lmask to_environment = lanes_mask(false);
#if defined(FH_ENV_MAP)
  to_environment = u.y < params.env_pick;
  pick.within = within_share(u.y, 0.0f, params.env_pick);
  pick.narrow = to_environment && params.env_pick < FH_NARROW_SHARE;
#endif
  if (params.light_count > 0 && lanes_any(active && !to_environment)) {
    const LightPick by_table = pick_light_within(scene->light_cdf, params.light_count, params.env_pick, u.y);
    pick.light = by_table.light;
    pick.within = select(by_table.within, pick.within, to_environment);
    pick.narrow = select(by_table.narrow, pick.narrow, to_environment);
  }
  if (lanes_any(active && pick.narrow))
    pick.within = select(pick.within, sample_1d(sampler, dim + FH_DIM_LIGHT_NARROW), pick.narrow);
  const lvec2 u_point = lv2(u.x, pick.within);
  LightSample ls;
  ls.wi = ls.radiance = ls.shadow_direction = v3_splat(0.0f);
  ls.pdf = ls.shadow_distance = (lfloat)(0.0f);
  if (params.light_count > 0 && lanes_any(active && !to_environment))
    ls = sample_light_triangle(origin, pick.light, u_point, scene->triangles, scene->triangle_material,
                               scene->materials, scene->light_triangle, scene->light_pdf_area);
#if defined(FH_ENV_MAP)
  if (lanes_any(active && to_environment))
    ls = select_light_sample(to_environment, sample_light_environment(params, u_point, scene->env_map), ls);
#endif
  const lfloat cos_surface = v3_dot(n, ls.wi);
  // Behind the surface (by either normal: no light leaks through), or no sample.
  lmask connects = active && ls.pdf > 0.0f && cos_surface > 0.0f && v3_dot(s.normal, ls.wi) > 0.0f;
  if (!lanes_any(connects)) return;

  const MaterialLanes m = material_lanes(scene->materials, r->material);
  Bsdf bsdf = material_bsdf(&m);
  bsdf.kd = r->albedo;  // textured or not, as shade found it
  const lvec3 wo = r->wo;
  const lvec3 f = bsdf_eval(&bsdf, n, wo, ls.wi);
#if defined(FH_METHOD_MIS)
  const lfloat weight = power_heuristic(ls.pdf, bsdf_pdf(&bsdf, n, wo, ls.wi));
#else
  const lfloat weight = (lfloat)(1.0f);
#endif
  const lvec3 contribution =
      v3_scale(v3_mul(v3_mul(r->throughput, f), ls.radiance), cos_surface * weight / ls.pdf);
  connects = connects && v3_any_positive(contribution);

  LaneRays rays;
  precompute_lane_rays(origin, ls.shadow_direction, &rays);
  // The lanes' shadow rays one by one, only those that connect; the unoccluded ones add
  // their contributions together at the end.
  uint unoccluded = 0u;
  for (uint left = lanes_bits(connects); left != 0u; left &= left - 1u) {
    const int k = lowest_bit(left);
    if (find_occluder_precomputed(scene->nodes, scene->blocks, lane_ray(&rays, k), 0.0f, LANE(ls.shadow_distance, k)) < 0)
      unoccluded |= 1u << k;
  }
  add_xyz(radiance, p, contribution, lanes_of_bits(unoccluded));
}

#endif

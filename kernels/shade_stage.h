// The shade stage, for every path whose ray was just intersected:
//   escaped       -> add the environment (the map's with the MIS weight for mis), finish;
//   emitter hit   -> add Ke where the method counts it (with the MIS weight for mis);
//   light sample  -> queue a next-event request for shadow_connect (nee, mis);
//   BSDF sample   -> the next direction, throughput update, Russian roulette, requeue.
// Build options choose the method: FH_METHOD_PT, FH_METHOD_NEE or FH_METHOD_MIS. Each
// work-item shades FH_LANES consecutive paths of the queue (lanes.h).
// FH_LIGHT_TRACED_FIRST_VERTEX (--method lt, with FH_METHOD_MIS): light tracing
// (light_trace.cl) counts every path whose first vertex from the camera scatters through a
// smooth lobe or emits; the camera's paths count only those that leave the first vertex by
// a delta lobe (a mirror, glass), which the light tracer cannot connect to the camera.
// The stage's functions; kernels/shade.cl holds its kernel, and the megakernel calls them.
#ifndef FH_SHADE_STAGE_H
#define FH_SHADE_STAGE_H

#include "bsdf.h"
#include "lights.h"
#include "path_state.h"
#include "queues.h"
#include "scene_view.h"
#include "ray.h"
#include "sampler.h"
#include "surface.h"
#if defined(FH_AOVS)
#include "aovs.h"
#endif
#if defined(FH_ENV_MAP)
#include "environment.h"
#endif

#if !defined(FH_METHOD_PT) && !defined(FH_METHOD_NEE) && !defined(FH_METHOD_MIS)
#error "build with -DFH_METHOD_PT, -DFH_METHOD_NEE or -DFH_METHOD_MIS"
#endif

// The weight of emission found by BSDF sampling at a vertex `depth` bounces from the
// camera, on light triangle t reached from `origin` at squared distance dist2 under
// cos_light; bsdf_pdf < 0 marks a delta (mirror, glass) bounce, which light sampling
// cannot reproduce, so its emission always counts.
FH_INLINE lfloat emission_weight(luint depth, lfloat bsdf_pdf, __global const float4* triangles, lint t,
                                 lfloat light_pdf_area, lvec3 origin, lfloat dist2, lfloat cos_light) {
#if defined(FH_METHOD_PT)
  return (lfloat)(1.0f);
#else
  const lmask always = depth == 0 || bsdf_pdf < 0.0f;
#if defined(FH_METHOD_NEE)
  return select((lfloat)(0.0f), (lfloat)(1.0f), always);  // light sampling counted the rest
#else
  // The density light sampling (shadow_connect) would have had for this point.
  const LightTriangle light = light_triangle_from(triangles, t, light_pdf_area, origin);
  return select(power_heuristic(bsdf_pdf, light_pdf(&light, dist2, cos_light)), (lfloat)(1.0f), always);
#endif
#endif
}

#if defined(FH_ENV_MAP)
// The weight of environment-map radiance found by BSDF sampling (density bsdf_pdf, < 0 for a
// delta bounce) where light sampling would have drawn the same direction with density
// light_pdf (0 where it never does: the map not sampled, or a black texel).
FH_INLINE lfloat environment_weight(luint depth, lfloat bsdf_pdf, lfloat light_pdf) {
#if defined(FH_METHOD_PT)
  return (lfloat)(1.0f);
#else
  const lmask always = depth == 0 || bsdf_pdf < 0.0f || light_pdf == 0.0f;
#if defined(FH_METHOD_NEE)
  return select((lfloat)(0.0f), (lfloat)(1.0f), always);
#else
  return select(power_heuristic(bsdf_pdf, light_pdf), (lfloat)(1.0f), always);
#endif
#endif
}
#endif

// What shading decided for FH_LANES paths: which go on to another bounce, which asked for
// a light sample (described by `request`), which are finished.
typedef struct {
  lmask continues, light_sample, finished;
  ShadowRequest request;
  PixelSampler sampler;  // the paths' samples, where light_sample is set (connect_light's too)
} ShadeOutcome;

// The lanes' paths where they are: the hit (t, b1, b2), its triangle (-1: escaped), the
// throughput that reached it and the bounces so far.
typedef struct {
  lvec3 hit, beta;
  lint triangle;
  luint bounce;
} PathAt;

// The surface a path hit, seen from it: the point, its material and BSDF (textured), the
// direction back along the ray, and the geometric and shading normals as the file gives
// them (cos_front > 0: seen from the front, counter-clockwise, side).
typedef struct {
  SurfacePoint point;
  lint triangle, material_id;
  MaterialLanes material;
  Bsdf bsdf;
  lvec3 wo, shading_normal;
  lfloat cos_front;
} Shading;

// Escaped: the constant environment and, with FH_ENV_MAP, the map's radiance weighted
// against light sampling's density for it.
FH_INLINE void add_escaped(RenderParams params, const SceneView* scene, luint p, lmask escaped, const PathAt* at,
                           lvec3* gathered FH_PATH_PARAMS) {
  *gathered = v3_select(escaped, v3_add(*gathered, v3_mul(at->beta, v3_uniform(vload3(0, params.env)))), *gathered);
#if defined(FH_ENV_MAP)
  if (lanes_any(escaped)) {
    lfloat env_pdf;
    const lvec3 le = environment_lookup(params, scene->env_map, gather_xyz(ray_dir, p), &env_pdf);
    const lfloat weight = environment_weight(at->bounce, gather_float(ray_pdf, p), params.env_pick * env_pdf);
    *gathered = v3_select(escaped, v3_add(*gathered, v3_scale(v3_mul(at->beta, le), weight)), *gathered);
  }
#endif
}

FH_INLINE Shading shading_at(const SceneView* scene, luint p, lmask hits, const PathAt* at FH_PATH_PARAMS) {
  Shading sh;
  sh.triangle = select((lint)(0), at->triangle, hits);
  sh.point = surface_point(scene->triangles, sh.triangle, at->hit.y, at->hit.z);
  sh.material_id = gather_int(scene->triangle_material, las_uint(sh.triangle));
  sh.material = material_lanes(scene->materials, sh.material_id);
  sh.wo = v3_neg(gather_xyz(ray_dir, p));
  sh.cos_front = v3_dot(sh.point.normal, sh.wo);
#if defined(FH_SHADING_NORMALS)
  sh.shading_normal = shading_normal(scene->normals, sh.triangle, at->hit.y, at->hit.z, sh.point.normal);
#else
  sh.shading_normal = sh.point.normal;
#endif
  sh.bsdf = material_bsdf(&sh.material);
#if defined(FH_TEXTURES)
  sh.bsdf.kd = texture_lookup(scene->texels, scene->texture_info, select((lint)(-1), sh.material.texture, hits),
                              surface_uv(scene->uvs, sh.triangle, at->hit.y, at->hit.z), sh.bsdf.kd);
#endif
  return sh;
}

// Emission leaves the front (counter-clockwise) side only. The MIS weight measures the
// light's density from the ray's origin, the offset point shadow_connect also connects
// from, so the two strategies weigh the same paths.
FH_INLINE void add_emission(const SceneView* scene, luint p, lmask hits, const PathAt* at, const Shading* sh,
                            lvec3* gathered FH_PATH_PARAMS) {
  const lmask emits = hits && sh->cos_front > 0.0f && v3_any_positive(sh->material.ke);
  if (!lanes_any(emits)) return;
  lfloat weight = emission_weight(at->bounce, gather_float(ray_pdf, p), scene->triangles, sh->triangle,
                                  gather_float(scene->light_pdf_area, las_uint(sh->triangle)),
                                  gather_xyz(ray_org, p), at->hit.x * at->hit.x, sh->cos_front);
#if defined(FH_LIGHT_TRACED_FIRST_VERTEX)
  weight = select(weight, (lfloat)(0.0f), at->bounce == 0);  // the light tracer sees emitters
#endif
  *gathered = v3_select(emits, v3_add(*gathered, v3_scale(v3_mul(at->beta, sh->material.ke), weight)), *gathered);
}

#if !defined(FH_METHOD_PT)
// Next-event estimation at smooth surfaces: what shadow_connect needs, normals turned to the
// viewer's side (opaque surfaces shade both sides).
FH_INLINE void request_light_sample(RenderParams params, lmask may_bounce, const PathAt* at, const Shading* sh,
                                    ShadeOutcome* o) {
  const lmask front = sh->cos_front >= 0.0f;
  ShadowRequest* r = &o->request;
  o->light_sample =
      may_bounce && (params.light_count > 0 || params.env_pick > 0.0f) && bsdf_has_smooth_lobe(&sh->bsdf);
#if defined(FH_LIGHT_TRACED_FIRST_VERTEX)
  o->light_sample = o->light_sample && at->bounce > 0;  // the light tracer connects the first vertex
#endif
  r->at.position = sh->point.position;
  r->at.magnitude = sh->point.magnitude;
  r->at.normal = v3_select(front, sh->point.normal, v3_neg(sh->point.normal));
  r->shading_normal = v3_select(front, sh->shading_normal, v3_neg(sh->shading_normal));
  r->albedo = sh->bsdf.kd;
  r->throughput = at->beta;
  r->wo = sh->wo;
  r->material = sh->material_id;
  r->depth = at->bounce;
}
#endif

// The next direction by BSDF sampling, the throughput through it and Russian roulette:
// survive with a probability from the throughput (capped, so bright paths still end);
// dividing by it keeps the estimator unbiased. Writes the surviving paths' next ray and
// returns which continue.
FH_INLINE lmask bounce_and_roulette(RenderParams params, luint p, lmask may_bounce, const PathAt* at,
                                    const Shading* sh, PixelSampler* sampler_out FH_PATH_PARAMS) {
  const luint dim = at->bounce * FH_DIMS_PER_BOUNCE;
  const PixelSampler sampler = path_sampler(p FH_PATH_ARGS);
  *sampler_out = sampler;
  const lvec2 u = sample_2d(&sampler, dim + FH_DIM_BSDF_U1);
  const BsdfSample b = bsdf_sample(&sh->bsdf, sh->point.normal, sh->shading_normal, sh->wo,
                                   sample_1d(&sampler, dim + FH_DIM_BSDF_LOBE), u.x, u.y);
  lvec3 beta = v3_mul(at->beta, b.weight);
  lmask continues = may_bounce && b.pdf != 0.0f;
#if defined(FH_LIGHT_TRACED_FIRST_VERTEX)
  continues = continues && (at->bounce > 0 || b.pdf < 0.0f);  // smooth lobes at the first vertex: light traced
#endif
  const lmask roulette = continues && at->bounce + 1 >= params.rr_depth;
  if (lanes_any(roulette)) {
    const lfloat survive = fmin(v3_max_component(beta), 0.95f);
    const lmask dies = roulette && sample_1d(&sampler, dim + FH_DIM_ROULETTE) >= survive;
    beta = v3_select(roulette && !dies, v3_scale(beta, 1.0f / survive), beta);
    continues = continues && !dies;
  }
  continues = continues && v3_any_positive(beta);
  scatter_xyzw(ray_org, p, offset_ray_origin(&sh->point, b.wi), (lfloat)(0.0f), continues);
  scatter_xyzw(ray_dir, p, b.wi, (lfloat)(INFINITY), continues);
  scatter_xyzw(throughput, p, beta, (lfloat)(0.0f), continues);
  scatter_float(ray_pdf, p, b.pdf, continues);
  scatter_uint(depth, p, at->bounce + 1, continues);
  return continues;
}

// Shades path slots p where `active`: adds what the paths gathered at their hits to their
// radiance and, for those that go on, writes the next ray, throughput, pdf and depth; with
// FH_AOVS, records the first-surface layers in `aovs` (aovs.h).
FH_INLINE ShadeOutcome shade_paths(RenderParams params, luint p, lmask active, const SceneView* scene,
                                   __global float4* aovs FH_PATH_PARAMS) {
  ShadeOutcome o;
  o.continues = o.light_sample = lanes_mask(false);
  // What a light-sample request needs (zero where none is made).
  ShadowRequest* r = &o.request;
  r->path = p;
  r->at.position = r->at.normal = r->shading_normal = r->albedo = r->throughput = r->wo = v3_splat(0.0f);
  r->at.magnitude = (lfloat)(0.0f);
  r->material = (lint)(0);
  r->depth = (luint)(0);
  o.sampler.pixel_seed = o.sampler.index_reversed = (luint)(0u);
  if (lanes_any(active)) {
    PathAt at;
    at.beta = gather_xyz(throughput, p);
    at.bounce = gather_uint(depth, p);
    lfloat triangle_bits;
    at.hit = gather_xyzw(hit, p, &triangle_bits);  // t, b1, b2
    at.triangle = las_int(triangle_bits);
    lvec3 gathered = gather_xyz(radiance, p);
    const lmask escaped = active && at.triangle < 0, hits = active && at.triangle >= 0;
    add_escaped(params, scene, p, escaped, &at, &gathered FH_PATH_ARGS);
#if defined(FH_AOVS)
    const luint aov = aov_entry(p, pass_entry);
    record_escaped_aovs(aov, escaped && at.bounce == 0, aovs);
#endif
    if (lanes_any(hits)) {
      const Shading sh = shading_at(scene, p, hits, &at FH_PATH_ARGS);
      add_emission(scene, p, hits, &at, &sh, &gathered FH_PATH_ARGS);
      const lmask may_bounce = hits && at.bounce + 1 <= params.max_depth;
#if defined(FH_AOVS)
      const lmask front = sh.cos_front >= 0.0f;
      record_surface_aovs(aov, hits, at.bounce, gather_float(ray_pdf, p), at.hit.x, &sh.bsdf,
                          v3_select(front, sh.shading_normal, v3_neg(sh.shading_normal)), aovs);
#endif
#if !defined(FH_METHOD_PT)
      request_light_sample(params, may_bounce, &at, &sh, &o);
#endif
      if (lanes_any(may_bounce))
        o.continues = bounce_and_roulette(params, p, may_bounce, &at, &sh, &o.sampler FH_PATH_ARGS);
    }
    scatter_xyzw(radiance, p, gathered, (lfloat)(0.0f), active);
  }
  o.finished = active && !o.continues;
  return o;
}

#endif

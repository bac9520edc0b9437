// The shade stage, for every path whose ray was just intersected:
//   escaped       -> add the environment (the map's with the MIS weight for mis), finish;
//   emitter hit   -> add Ke where the method counts it (with the MIS weight for mis);
//   light sample  -> queue a next-event request for shadow_connect (nee, mis);
//   BSDF sample   -> the next direction, throughput update, Russian roulette, requeue.
// Build options choose the method: FH_METHOD_PT, FH_METHOD_NEE or FH_METHOD_MIS. Each
// work-item shades FH_LANES consecutive paths of the queue (lanes.h).
#include "bsdf.h"
#include "lights.h"
#include "path_state.h"
#include "queues.h"
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

// Shades path slots p where `active`: adds what the paths gathered at their hits to their
// radiance and, for those that go on, writes the next ray, throughput, pdf and depth; with
// FH_AOVS, records the first-surface layers in `aovs` (aovs.h).
FH_INLINE ShadeOutcome shade_paths(RenderParams params, luint p, lmask active, __global const float4* triangles,
                                   __global const int* triangle_material, __global const GpuMaterial* materials,
                                   __global const float* light_pdf_area, __global const float4* normals,
                                   __global const float2* uvs, __global const uint* texels,
                                   __global const uint4* texture_info, __global const float* env_map,
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
    const lvec3 beta_in = gather_xyz(throughput, p);
    const luint bounce = gather_uint(depth, p);
    lvec3 gathered = gather_xyz(radiance, p);
    lfloat triangle_bits;
    const lvec3 h = gather_xyzw(hit, p, &triangle_bits);  // t, b1, b2
    const lint hit_triangle = las_int(triangle_bits);
    const lmask escaped = active && hit_triangle < 0, hits = active && hit_triangle >= 0;
    gathered = v3_select(escaped, v3_add(gathered, v3_mul(beta_in, v3_uniform(vload3(0, params.env)))), gathered);
#if defined(FH_ENV_MAP)
    if (lanes_any(escaped)) {
      lfloat env_pdf;
      const lvec3 le = environment_lookup(params, env_map, gather_xyz(ray_dir, p), &env_pdf);
      const lfloat weight = environment_weight(bounce, gather_float(ray_pdf, p), params.env_pick * env_pdf);
      gathered = v3_select(escaped, v3_add(gathered, v3_scale(v3_mul(beta_in, le), weight)), gathered);
    }
#endif
#if defined(FH_AOVS)
    const luint aov = aov_entry(p, pass_entry);
    record_escaped_aovs(aov, escaped && bounce == 0, aovs);
#endif

    if (lanes_any(hits)) {
      const lint t = select((lint)(0), hit_triangle, hits);
      const SurfacePoint s = surface_point(triangles, t, h.y, h.z);
      const lint material_id = gather_int(triangle_material, las_uint(t));
      const MaterialLanes m = material_lanes(materials, material_id);
      const lvec3 wo = v3_neg(gather_xyz(ray_dir, p));
      const lfloat cos_front = v3_dot(s.normal, wo);

      // Emission leaves the front (counter-clockwise) side only. The MIS weight measures
      // the light's density from the ray's origin, the offset point shadow_connect also
      // connects from, so the two strategies weigh the same paths.
      const lmask emits = hits && cos_front > 0.0f && v3_any_positive(m.ke);
      if (lanes_any(emits)) {
        const lfloat weight = emission_weight(bounce, gather_float(ray_pdf, p), triangles, t,
                                              gather_float(light_pdf_area, las_uint(t)), gather_xyz(ray_org, p),
                                              h.x * h.x, cos_front);
        gathered = v3_select(emits, v3_add(gathered, v3_scale(v3_mul(beta_in, m.ke), weight)), gathered);
      }

  #if defined(FH_SHADING_NORMALS)
      const lvec3 ns = shading_normal(normals, t, h.y, h.z, s.normal);
  #else
      const lvec3 ns = s.normal;
  #endif
      const lmask may_bounce = hits && bounce + 1 <= params.max_depth;
      Bsdf bsdf = material_bsdf(&m);
  #if defined(FH_TEXTURES)
      bsdf.kd = texture_lookup(texels, texture_info, select((lint)(-1), m.texture, hits), surface_uv(uvs, t, h.y, h.z),
                               bsdf.kd);
  #endif

  #if !defined(FH_METHOD_PT) || defined(FH_AOVS)
      // Two-sided shading for opaque surfaces: the normals on the viewer's side.
      const lmask front = cos_front >= 0.0f;
  #endif
  #if defined(FH_AOVS)
      record_surface_aovs(aov, hits, bounce, gather_float(ray_pdf, p), h.x, &bsdf, v3_select(front, ns, v3_neg(ns)),
                          aovs);
  #endif
  #if !defined(FH_METHOD_PT)
      o.light_sample =
          may_bounce && (params.light_count > 0 || params.env_pick > 0.0f) && bsdf_has_smooth_lobe(&bsdf);
      r->at.position = s.position;
      r->at.magnitude = s.magnitude;
      r->at.normal = v3_select(front, s.normal, v3_neg(s.normal));
      r->shading_normal = v3_select(front, ns, v3_neg(ns));
      r->albedo = bsdf.kd;
      r->throughput = beta_in;
      r->wo = wo;
      r->material = material_id;
      r->depth = bounce;
  #endif

      if (lanes_any(may_bounce)) {
        const luint dim = bounce * FH_DIMS_PER_BOUNCE;
        const PixelSampler sampler = path_sampler(p FH_PATH_ARGS);
        o.sampler = sampler;
        const lvec2 u = sample_2d(&sampler, dim + FH_DIM_BSDF_U1);
        const BsdfSample b = bsdf_sample(&bsdf, s.normal, ns, wo, sample_1d(&sampler, dim + FH_DIM_BSDF_LOBE), u.x, u.y);
        lvec3 beta = v3_mul(beta_in, b.weight);
        lmask continues = may_bounce && b.pdf != 0.0f;
        // Russian roulette: survive with a probability from the throughput (capped, so
        // bright paths still end); dividing by it keeps the estimator unbiased.
        const lmask roulette = continues && bounce + 1 >= params.rr_depth;
        if (lanes_any(roulette)) {
          const lfloat survive = fmin(v3_max_component(beta), 0.95f);
          const lmask dies = roulette && sample_1d(&sampler, dim + FH_DIM_ROULETTE) >= survive;
          beta = v3_select(roulette && !dies, v3_scale(beta, 1.0f / survive), beta);
          continues = continues && !dies;
        }
        continues = continues && v3_any_positive(beta);
        scatter_xyzw(ray_org, p, offset_ray_origin(&s, b.wi), (lfloat)(0.0f), continues);
        scatter_xyzw(ray_dir, p, b.wi, (lfloat)(INFINITY), continues);
        scatter_xyzw(throughput, p, beta, (lfloat)(0.0f), continues);
        scatter_float(ray_pdf, p, b.pdf, continues);
        scatter_uint(depth, p, bounce + 1, continues);
        o.continues = continues;
      }
    }
    scatter_xyzw(radiance, p, gathered, (lfloat)(0.0f), active);
  }
  o.finished = active && !o.continues;
  return o;
}

#if !defined(FH_MEGAKERNEL)  // the megakernel calls the stage function itself
__kernel void shade(RenderParams params, __global const uint* ray_queue, __global uint* next_queue,
                    __global uint* finished_queue, volatile __global WavefrontCounters* counters, uint parity,
                    __global const float4* triangles, __global const int* triangle_material,
                    __global const GpuMaterial* materials, __global const float* light_pdf_area,
                    __global const float4* normals, __global const float2* uvs, __global const uint* texels,
                    __global const uint4* texture_info, __global const float* env_map,
                    __global float4* aovs FH_PATH_PARAMS FH_SHADOW_PARAMS) {
  volatile __local uint scratch[2 * 3];
  const luint position = lane_positions(get_global_id(0) * FH_LANES);
  const lmask active = position < counters->ray_length[parity];
  // Idle lanes (past the queue's end) read the work-item's first path, which no other
  // work-item writes, and write nothing.
  const luint p =
      lanes_any(active) ? gather_uint(ray_queue, select((luint)(LANE(position, 0)), position, active)) : (luint)(0);
  const ShadeOutcome o = shade_paths(params, p, active, triangles, triangle_material, materials, light_pdf_area,
                                     normals, uvs, texels, texture_info, env_map, aovs FH_PATH_ARGS);

  // Continuing paths to the next ray queue, light-sample requests to shadow_connect's,
  // finished paths to accumulate's.
  const lmask append[3] = {o.continues, o.light_sample, o.finished};
  __global uint* const queues[3] = {next_queue, shadow_path, finished_queue};
  volatile __global uint* const lengths[3] = {&counters->ray_length[1 - parity], &counters->shadow_length,
                                              &counters->finished_length};
  luint positions[3];
  queue_append_each(3, append, p, queues, lengths, scratch, positions);
  if (lanes_any(o.light_sample)) store_shadow_request(&o.request, positions[1], o.light_sample FH_SHADOW_ARGS);
}
#endif

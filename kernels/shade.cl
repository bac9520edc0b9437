// The shade stage, for every path whose ray was just intersected:
//   escaped       -> add the environment, finish;
//   emitter hit   -> add Ke where the method counts it (with the MIS weight for mis);
//   light sample  -> queue a next-event request for shadow_connect (nee, mis);
//   BSDF sample   -> the next direction, throughput update, Russian roulette, requeue.
// Build options choose the method: FH_METHOD_PT, FH_METHOD_NEE or FH_METHOD_MIS.
#include "bsdf.h"
#include "lights.h"
#include "path_state.h"
#include "queues.h"
#include "ray.h"
#include "sampler.h"
#include "surface.h"

#if !defined(FH_METHOD_PT) && !defined(FH_METHOD_NEE) && !defined(FH_METHOD_MIS)
#error "build with -DFH_METHOD_PT, -DFH_METHOD_NEE or -DFH_METHOD_MIS"
#endif

// The weight of emission found by BSDF sampling at a vertex `depth` bounces from the
// camera, on light triangle t reached from `origin` at squared distance dist2 under
// cos_light; bsdf_pdf < 0 marks a delta (mirror, glass) bounce, which light sampling
// cannot reproduce, so its emission always counts.
FH_INLINE float emission_weight(uint depth, float bsdf_pdf, __global const float4* triangles, int t,
                                float light_pdf_area, float3 origin, float dist2, float cos_light) {
#if defined(FH_METHOD_PT)
  return 1.0f;
#elif defined(FH_METHOD_NEE)
  return depth == 0 || bsdf_pdf < 0.0f ? 1.0f : 0.0f;  // light sampling counted the rest
#else
  if (depth == 0 || bsdf_pdf < 0.0f) return 1.0f;
  // The density light sampling (shadow_connect) would have had for this point.
  const LightTriangle light = light_triangle_from(triangles, t, light_pdf_area, origin);
  return power_heuristic(bsdf_pdf, light_pdf(&light, dist2, cos_light));
#endif
}

__kernel void shade(RenderParams params, __global const uint* ray_queue, __global uint* next_queue,
                    __global uint* finished_queue, volatile __global WavefrontCounters* counters, uint parity,
                    __global const float4* triangles, __global const int* triangle_material,
                    __global const GpuMaterial* materials, __global const float* light_pdf_area,
                    __global const float4* normals, __global const float2* uvs, __global const float4* texels,
                    __global const uint4* texture_info FH_PATH_PARAMS FH_SHADOW_PARAMS) {
  volatile __local uint scratch[2];
  const uint i = get_global_id(0), count = counters->ray_length[parity];
  bool continues = false, light_sample = false, finishes = false;
  uint p = 0;
  // What a light-sample request needs, kept until its queue position is known.
  float4 request_position = (float4)(0.0f);
  float3 request_normal = (float3)(0.0f), request_beta = (float3)(0.0f), request_wo = (float3)(0.0f),
         request_geometric = (float3)(0.0f), request_albedo = (float3)(0.0f);
  int request_material = 0;
  uint request_depth = 0;

  if (i < count) {
    p = ray_queue[i];
    const float4 h = hit[p];
    const float3 dir = ray_dir[p].xyz;
    float3 beta = throughput[p].xyz;
    float3 gathered = radiance[p].xyz;
    const uint bounce = depth[p];
    const int t = as_int(h.w);

    if (t < 0) {
      gathered += beta * vload3(0, params.env);
    } else {
      const SurfacePoint s = surface_point(triangles, t, h.y, h.z);
      const int material_id = triangle_material[t];
      __global const GpuMaterial* m = materials + material_id;
      const float3 wo = -dir;
      const float cos_front = dot(s.normal, wo);

      // Emission leaves the front (counter-clockwise) side only. The MIS weight measures
      // the light's density from the ray's origin, the offset point shadow_connect also
      // connects from, so the two strategies weigh the same paths.
      const float3 ke = vload3(0, m->ke);
      if (cos_front > 0.0f && (ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f))
        gathered += beta * ke * emission_weight(bounce, ray_pdf[p], triangles, t, light_pdf_area[t], ray_org[p].xyz,
                                                h.x * h.x, cos_front);

#if defined(FH_SHADING_NORMALS)
      const float3 ns = shading_normal(normals, t, h.y, h.z, s.normal);
#else
      const float3 ns = s.normal;
#endif
      const bool may_bounce = bounce + 1 <= params.max_depth;
      Bsdf bsdf = material_bsdf(m);
#if defined(FH_TEXTURES)
      if (m->texture >= 0) bsdf.kd = texture_lookup(texels, texture_info, m->texture, surface_uv(uvs, t, h.y, h.z));
#endif

#if !defined(FH_METHOD_PT)
      // Two-sided shading for opaque surfaces: the normals on the viewer's side.
      const float3 g = cos_front >= 0.0f ? s.normal : -s.normal;
      const float3 n = cos_front >= 0.0f ? ns : -ns;
      light_sample = may_bounce && params.light_count > 0 && bsdf_has_smooth_lobe(&bsdf);
      request_position = (float4)(s.position, s.magnitude);
      request_normal = n;
      request_geometric = g;
      request_albedo = bsdf.kd;
      request_beta = beta;
      request_wo = wo;
      request_material = material_id;
      request_depth = bounce;
#endif

      if (may_bounce) {
        const uint dim = bounce * FH_DIMS_PER_BOUNCE;
        const PixelSampler sampler = pixel_sampler(params.seed, sample_id[p], params.pixel_count);
        const float2 u = sample_2d(&sampler, dim + FH_DIM_BSDF_U1);
        float3 wi;
        float pdf;
        const float3 weight =
            bsdf_sample(&bsdf, s.normal, ns, wo, sample_1d(&sampler, dim + FH_DIM_BSDF_LOBE), u.x, u.y, &wi, &pdf);
        beta *= weight;
        continues = pdf != 0.0f;
        // Russian roulette: survive with a probability from the throughput (capped, so
        // bright paths still end); dividing by it keeps the estimator unbiased.
        if (continues && bounce + 1 >= params.rr_depth) {
          const float survive = fmin(fmax(fmax(beta.x, beta.y), beta.z), 0.95f);
          if (sample_1d(&sampler, dim + FH_DIM_ROULETTE) >= survive) continues = false;
          else beta /= survive;
        }
        continues = continues && (beta.x > 0.0f || beta.y > 0.0f || beta.z > 0.0f);
        if (continues) {
          ray_org[p] = (float4)(offset_ray_origin(&s, wi), 0.0f);
          ray_dir[p] = (float4)(wi, INFINITY);
          throughput[p] = (float4)(beta, 0.0f);
          ray_pdf[p] = pdf;
          depth[p] = bounce + 1;
        }
      }
    }
    radiance[p] = (float4)(gathered, 0.0f);
    finishes = !continues;
  }

  queue_append(continues, p, next_queue, &counters->ray_length[1 - parity], scratch);
  const uint request = queue_append(light_sample, p, shadow_path, &counters->shadow_length, scratch);
  if (light_sample) {
    shadow_position[request] = request_position;
    shadow_normal[request] = (float4)(request_normal, 0.0f);
    shadow_throughput[request] = (float4)(request_beta, 0.0f);
    shadow_wo[request] = (float4)(request_wo, 0.0f);
    shadow_geometric[request] = (float4)(request_geometric, 0.0f);
    shadow_albedo[request] = (float4)(request_albedo, 0.0f);
    shadow_material[request] = request_material;
    shadow_depth[request] = request_depth;
  }
  queue_append(finishes, p, finished_queue, &counters->finished_length, scratch);
}

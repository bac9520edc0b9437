// The shadow-connect stage: next-event estimation for each light-sample request that
// shade queued. Picks an emissive triangle in proportion to its power and a point on it
// (uniform in the solid angle it subtends, or in area: lights.h), traces the shadow ray
// (V(x,y)), and adds the unoccluded contribution, weighted against BSDF sampling for mis.
#include "bsdf.h"
#include "intersect.h"
#include "lights.h"
#include "path_state.h"
#include "ray.h"
#include "sampler.h"
#include "sampling.h"

__kernel void shadow_connect(RenderParams params, __global const WavefrontCounters* counters,
                             __global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                             __global const float4* triangles, __global const int* triangle_material,
                             __global const GpuMaterial* materials, __global const float* light_cdf,
                             __global const int* light_triangle, __global const float* light_pdf_area
                                 FH_PATH_PARAMS FH_SHADOW_PARAMS) {
  const uint i = get_global_id(0);
  if (i >= counters->shadow_length) return;
  const uint p = shadow_path[i];
  const float4 position = shadow_position[i];
  SurfacePoint s;
  s.position = position.xyz;
  s.magnitude = position.w;
  s.normal = shadow_geometric[i].xyz;  // the geometric normal on the viewer's side
  const float3 n = shadow_normal[i].xyz;  // the shading normal, same side
  const float3 beta = shadow_throughput[i].xyz;
  const PixelSampler sampler = pixel_sampler(params.seed, sample_id[p], params.pixel_count);
  const uint dim = shadow_depth[i] * FH_DIMS_PER_BOUNCE;

  // Connect from the point just off the surface that BSDF-sampled rays also start from:
  // both strategies then see the same geometry, and their MIS weights sum to one even
  // where the offset is a visible distance (far from the origin).
  const float3 origin = offset_ray_origin(&s, s.normal);
  const uint light = pick_light(light_cdf, params.light_count, sample_1d(&sampler, dim + FH_DIM_LIGHT_PICK));
  const int lt = light_triangle[light];
  const LightTriangle light_tri = light_triangle_from(triangles, lt, light_pdf_area[lt], origin);
  const float2 u = sample_2d(&sampler, dim + FH_DIM_LIGHT_U1);
  const float2 b = light_tri.seen.solid_angle > 0.0f
                       ? barycentrics_along(origin, sample_spherical_triangle(&light_tri.seen, u.x, u.y), light_tri.v0,
                                            light_tri.v1, light_tri.v2)
                       : sample_triangle(u.x, u.y);
  const SurfacePoint l = surface_point(triangles, lt, b.x, b.y);
  const float3 to_light = l.position - origin;
  const float dist2 = dot(to_light, to_light);
  if (!(dist2 > 0.0f)) return;
  const float3 wi = to_light * rsqrt(dist2);
  const float cos_surface = dot(n, wi), cos_light = -dot(l.normal, wi);
  // Behind the surface (by either normal: no light leaks through), or the light's back.
  if (cos_surface <= 0.0f || dot(s.normal, wi) <= 0.0f || cos_light <= 0.0f) return;

  Bsdf bsdf = material_bsdf(materials + shadow_material[i]);
  bsdf.kd = shadow_albedo[i].xyz;  // textured or not, as shade found it
  const float3 wo = shadow_wo[i].xyz;
  const float3 f = bsdf_eval(&bsdf, n, wo, wi);
  const float pdf_light = light_pdf(&light_tri, dist2, cos_light);
#if defined(FH_METHOD_MIS)
  const float weight = power_heuristic(pdf_light, bsdf_pdf(&bsdf, n, wo, wi));
#else
  const float weight = 1.0f;
#endif
  const float3 ke = vload3(0, materials[triangle_material[lt]].ke);
  const float3 contribution = beta * f * ke * (cos_surface * weight / pdf_light);
  if (!(contribution.x > 0.0f || contribution.y > 0.0f || contribution.z > 0.0f)) return;

  // V(x, y): the segment from just off the surface to just short of the light point.
  const float3 target = offset_ray_origin(&l, -wi);
  const float3 d = target - origin;
  const float dist = length(d);
  if (trace_ray(nodes, blocks, origin, d / dist, 0.0f, dist * FH_SHADOW_SHORTEN, true).triangle >= 0) return;
  radiance[p] += (float4)(contribution, 0.0f);
}

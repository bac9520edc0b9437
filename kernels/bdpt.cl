// Bidirectional path tracing (--method bdpt; Veach 1997 ch. 10, Veach and Guibas 1995): for
// each pixel, a light subpath from the emitters and a camera subpath through the pixel,
// joined in every way a path of at most max_depth scattering vertices can be made. A
// work-item takes FH_LANES pixels (lanes.h: eight in vector lanes on a CPU), their light
// subpaths bouncing together, then their camera subpaths, each lane joined to its own
// light vertices; one lane or eight, the same bits:
//   s = 0   the camera subpath hits an emitter,
//   s = 1   a camera vertex connected to a point on an emitter (the light table, uniform in area)
//           or, with FH_ENV_MAP, to a direction drawn from the environment map,
//   s >= 2  a camera vertex connected to each stored light vertex,
//   t = 1   each light vertex connected to the pinhole, splatted where the camera sees it
//           (light tracing, kernels/light_paths.h).
// Every contribution is weighted by the power heuristic over all the strategies that could
// have made its path. The weights are computed recursively along the subpaths (Georgiev,
// "Implementing vertex connection and merging", 2012: the quantities d_vcm and d_vc, here
// without merging): each vertex carries two partial sums of squared density ratios, so a
// connection needs only its two end vertices. Densities in the weights are those of the
// unbiased strategies without Russian roulette (the weights still sum to one over the
// strategies, which is all that unbiasedness asks of them), with area conversions by the
// geometric normal. The directly seen emitter is the camera's alone (no s = 1, t = 1).
//
// A pass is one light and one camera subpath per pixel. The camera subpath's sum goes to
// its own pixel (the filter is importance-sampled, as in the path tracer); light tracing's
// splats land anywhere. Both are added as whole film quanta (light_paths.h), so a pass is
// the same bits on any device count, chunking and rank count. The camera's density of a
// direction in the weights is the whole film's, 1 / (A cos^3): N = W H light paths per pass
// against one camera path per pixel.
//
// Light vertices wait in `stored`, FH_BDPT_VERTEX_WORDS float4s each, max_depth per path: a
// launch covers `count` paths from `first`, as many as the buffer holds.
//
// --method vcm (FH_VCM) adds vertex merging (Georgiev et al. 2012, "Light transport simulation
// with vertex connection and merging"; Hachisuka et al. 2012): a launch's light subpaths are
// traced first (vcm_light_subpaths), the host files their vertices in a hash grid of cells
// 2r wide (render/merge_grid.h), and each camera vertex (vcm_camera_subpaths) also takes every
// light vertex within r as if the two were one, a density estimate over the launch's N light
// paths: the one strategy that samples a diffuse vertex seen and lit through delta lobes
// (L S D S E, a caustic seen through glass). Merging is a strategy among the others in the
// power heuristic, its density that of the light subpath times eta = N pi r^2; r shrinks
// with the pass (render/merge_grid.h), so the estimate's bias goes to zero as passes grow.
// `factors` carries mis2(eta) and mis2(1 / eta), both zero under plain bdpt.
//
// The environment map is a light like the triangles (picked with params.env_pick): its light
// subpaths start on a disk as wide as the scene's bounding sphere (`sphere`: centre, radius),
// facing a direction drawn from the map, beyond the sphere (Georgiev's background light), so
// their first hit is at no finite distance from the light. A constant --env is found by
// camera paths alone (as in the path tracer), with weight one.
#include "camera.h"
#include "film.h"
#include "light_paths.h"
#include "path_state.h"
#include "sampler.h"
// After the others: the host inlines each file once, at its first include, whatever the #if.
#if defined(FH_ENV_MAP)
#include "environment.h"
#endif

// A stored light vertex: (triangle bits, b1, b2, d_vcm), (w_in, d_vc), (alpha, scatterings),
// (position, d_vm).
#define FH_BDPT_VERTEX_WORDS 4

// What merging adds to every strategy's weight: mis2(eta) and mis2(1 / eta) for the merging
// radius's eta = N pi r^2 (zero under plain bdpt, which leaves the weights as they were).
typedef struct {
  float vm, vc;
} MergeFactors;

// Where merging is a strategy: at a smooth vertex whose neighbour toward the camera
// scatters by a delta lobe, the one place no connection reaches (L S D S E: the diffuse
// vertex seen through glass). Elsewhere the connections sample every path as merging
// would, and merging there would only cost lookups. The weights count merging where it is
// possible and nowhere else, so they still sum to one: on the camera side that is known at
// the vertex (its last sample), on the light side at the next vertex's sample (the held
// terms of trace_light_subpath); a vertex joined by a connection, or to the camera, has a
// smooth neighbour there. Under FH_VCM_MERGE_ONLY (a test hook) merging is at the first
// camera vertex instead, for every path.
FH_INLINE lmask merging_possible(MergeFactors m, lmask after_delta, uint camera_scatterings) {
#if defined(FH_VCM_MERGE_ONLY)
  (void)after_delta;
  return lanes_mask(m.vm > 0.0f && camera_scatterings == 1u);
#else
  (void)camera_scatterings;
  return m.vm > 0.0f ? after_delta : lanes_mask(false);
#endif
}

// The power heuristic's weight of a density ratio.
FH_INLINE lfloat mis2(lfloat x) { return x * x; }

// The weight a contribution of strategy s (its light vertices) to a path of m scattering
// vertices counts with: the power heuristic's, or under FH_BDPT_ONLY_S (a test hook,
// base/test_hooks.h) one for the one strategy kept for paths of that length (s = ONLY_S, or
// the nearest below it that such a path has; the camera's alone for a directly seen emitter)
// and none for the others, so that each strategy can be tested alone.
FH_INLINE lfloat strategy_weight(lfloat power_heuristic, luint s, luint m) {
#if defined(FH_VCM_MERGE_ONLY)
  return select((lfloat)(0.0f), (lfloat)(1.0f), s == 0u && m == 0u);
#elif defined(FH_BDPT_ONLY_S)
  const luint kept = select(min((luint)(FH_BDPT_ONLY_S), m + 1u), (luint)(0u), m == 0u);
  return select((lfloat)(0.0f), (lfloat)(1.0f), s == kept);
#else
  return power_heuristic;
#endif
}

// The recursive weights' state after a hit at distance d under |cos| = cos_g (the geometric
// normal and the arriving direction): the densities of the new vertex in area measure.
FH_INLINE void weights_at_hit(lfloat* d_vcm, lfloat* d_vc, lfloat* d_vm, lfloat d, lfloat cos_g) {
  *d_vcm *= mis2(d * d) / mis2(cos_g);
  *d_vc /= mis2(cos_g);
  *d_vm /= mis2(cos_g);
}

// ... and after a BSDF sample from there (pdf < 0: a delta lobe, whose choice is as likely
// both ways and whose vertex no connection can use): cos_out at the vertex toward the new
// direction, pdf_rev the density of sampling the way back, merge_here 1 where merging at
// the vertex left is a strategy for this path (see merging_possible), else 0.
FH_INLINE void weights_at_sample(lfloat* d_vcm, lfloat* d_vc, lfloat* d_vm, MergeFactors m, lfloat merge_here,
                                 lfloat pdf, lfloat pdf_rev, lfloat cos_out) {
  const lmask delta = pdf < 0.0f;
  const lfloat vc = mis2(cos_out / pdf) * (*d_vc * mis2(pdf_rev) + *d_vcm + merge_here * m.vm);
  const lfloat vm = mis2(cos_out / pdf) * (*d_vm * mis2(pdf_rev) + *d_vcm * m.vc + merge_here);
  *d_vc = select(vc, *d_vc * mis2(cos_out), delta);
  *d_vm = select(vm, *d_vm * mis2(cos_out), delta);
  *d_vcm = select(mis2(1.0f / pdf), (lfloat)(0.0f), delta);
}

// Where a light subpath starts: its first ray, its weight alpha (Le cos over the emission
// density), the weights' state, and whether it comes from infinitely far (the map).
typedef struct {
  lvec3 org, dir, alpha;
  lfloat d_vcm, d_vc, d_vm;
  lmask valid, infinite;
} LightStart;

// A point uniform in the area of a light triangle, leaving its front cosine-distributed:
// Le cos / (p_A cos / pi), the emission density p_A cos / pi against light sampling's p_A
// (d_vcm) and against the camera hitting the light (d_vc).
FH_INLINE LightStart start_on_triangle(RenderParams params, const SceneView* scene, MergeFactors m, lfloat u_pick,
                                       lfloat u1, lfloat u2, lfloat u3, lfloat u4) {
  const lint light = gather_int(scene->light_triangle, pick_light(scene->light_cdf, params.light_count, u_pick));
  const lvec2 b = sample_triangle(u1, u2);
  const SurfacePoint y = surface_point(scene->triangles, light, b.x, b.y);
  const lfloat pdf_area = gather_float(scene->light_pdf_area, las_uint(light));
  LightStart l;
  l.dir = sample_cosine_hemisphere(y.normal, u3, u4);
  const lfloat cos_light = v3_dot(y.normal, l.dir);
  l.valid = cos_light > 0.0f && pdf_area > 0.0f;
  l.alpha = v3_scale(material_lanes(scene->materials, gather_int(scene->triangle_material, las_uint(light))).ke,
                     M_PI_F / pdf_area);
  l.d_vcm = mis2(M_PI_F / cos_light);
  l.d_vc = mis2(M_PI_F / pdf_area);
  l.d_vm = l.d_vc * m.vc;
  l.org = offset_ray_origin(&y, l.dir);
  l.infinite = lanes_mask(false);
  return l;
}

#if defined(FH_ENV_MAP)
// A direction w drawn from the map (density p_w, the pick's included) and a point uniform on
// the disk of the scene's bounding sphere that faces it, beyond the sphere, the ray toward
// -w: Le / (p_w / (pi R^2)); light sampling's density p_w against the emission density (d_vcm)
// and no cosine at the light (d_vc).
FH_INLINE LightStart start_from_environment(RenderParams params, const SceneView* scene, MergeFactors m, float4 sphere,
                                            lfloat u1, lfloat u2, lfloat u3, lfloat u4) {
  const EnvironmentSample e = environment_sample(params, scene->env_map, u1, u2);
  const lfloat pdf_w = params.env_pick * e.pdf;
  const float disk_area = M_PI_F * sphere.w * sphere.w;
  lvec3 t, b;
  orthonormal_basis(e.wi, &t, &b);
  const lvec2 d = sample_concentric_disk(u3, u4);
  LightStart l;
  l.org = v3_add(v3_uniform(sphere.xyz), v3_scale(v3_add(e.wi, v3_add(v3_scale(t, d.x), v3_scale(b, d.y))), sphere.w));
  l.dir = v3_neg(e.wi);
  l.valid = pdf_w > 0.0f && (lfloat)(disk_area) > 0.0f;
  l.alpha = v3_scale(e.radiance, disk_area / pdf_w);
  l.d_vcm = (lfloat)(disk_area * disk_area);  // mis2(disk_area)
  l.d_vc = mis2(disk_area / pdf_w);
  l.d_vm = l.d_vc * m.vc;
  l.infinite = lanes_mask(true);
  return l;
}

// a where m is set, else b.
FH_INLINE LightStart select_start(lmask m, LightStart a, LightStart b) {
  LightStart s;
  s.org = v3_select(m, a.org, b.org);
  s.dir = v3_select(m, a.dir, b.dir);
  s.alpha = v3_select(m, a.alpha, b.alpha);
  s.d_vcm = select(b.d_vcm, a.d_vcm, m);
  s.d_vc = select(b.d_vc, a.d_vc, m);
  s.d_vm = select(b.d_vm, a.d_vm, m);
  s.valid = select(b.valid, a.valid, m);
  s.infinite = select(b.infinite, a.infinite, m);
  return s;
}
#endif

// Stores light vertex number `count` of each lane where m is set, in its path's slots from
// float4 `own`: (triangle bits, b1, b2, d_vcm), (w_in, d_vc), (alpha, scatterings),
// (position, d_vm).
FH_INLINE void store_light_vertex(__global float4* stored, luint own, luint count, lmask m, LaneHit hit, lfloat d_vcm,
                                  lvec3 w_in, lfloat d_vc, lvec3 alpha, uint scatterings, lvec3 position, lfloat d_vm) {
  FH_FOR_LANES(l) {
    if (LANE(m, l)) {
      __global float4* s = stored + LANE(own, l) + FH_BDPT_VERTEX_WORDS * LANE(count, l);
      s[0] = (float4)(as_float(LANE(hit.triangle, l)), LANE(hit.b1, l), LANE(hit.b2, l), LANE(d_vcm, l));
      s[1] = (float4)(LANE(w_in.x, l), LANE(w_in.y, l), LANE(w_in.z, l), LANE(d_vc, l));
      s[2] = (float4)(LANE(alpha.x, l), LANE(alpha.y, l), LANE(alpha.z, l), (float)scatterings);
      s[3] = (float4)(LANE(position.x, l), LANE(position.y, l), LANE(position.z, l), LANE(d_vm, l));
    }
  }
}

// The light subpaths of the lanes where `alive`: their surface vertices (as light_trace.cl
// reaches them) stored from float4 `own` of `stored` where a smooth lobe can connect them,
// each connected to the camera. Returns how many each lane stored.
FH_INLINE luint trace_light_subpath(RenderParams params, const SceneView* scene, MergeFactors m, float4 sphere,
                                    luint stream, luint path, lmask alive, __global float4* stored, luint own,
                                    volatile __global uint* splats, __global const float* density, LightTally* tally) {
  uint dim = 0u;
  luint count = (luint)(0u);
  const lfloat u_pick = random_float(stream, path, (luint)(dim++));
  const lfloat u1 = random_float(stream, path, (luint)(dim++)), u2 = random_float(stream, path, (luint)(dim++));
  const lfloat u3 = random_float(stream, path, (luint)(dim++)), u4 = random_float(stream, path, (luint)(dim++));
  LightStart start;
  start.org = start.dir = start.alpha = v3_splat(0.0f);
  start.d_vcm = start.d_vc = start.d_vm = (lfloat)(0.0f);
  start.valid = start.infinite = lanes_mask(false);
  (void)sphere;  // read with FH_ENV_MAP only
  if (params.light_count > 0u) start = start_on_triangle(params, scene, m, u_pick, u1, u2, u3, u4);
#if defined(FH_ENV_MAP)
  const lmask from_environment = u_pick < params.env_pick;
  if (lanes_any(alive && from_environment))
    start = select_start(from_environment, start_from_environment(params, scene, m, sphere, u1, u2, u3, u4), start);
#endif
  alive = alive && start.valid;
  lvec3 alpha = start.alpha, dir = start.dir, org = start.org;
  lfloat d_vcm = start.d_vcm, d_vc = start.d_vc, d_vm = start.d_vm;
  // Merging at the vertex before, held back: it is a strategy only where this vertex
  // scatters by a delta lobe (merging_possible), which its sample decides.
  lfloat held_vc = (lfloat)(0.0f), held_vm = (lfloat)(0.0f);
  lvec3 carried = v3_splat(1.0f);

  for (uint scatterings = 1u; scatterings <= params.max_depth && lanes_any(alive); ++scatterings) {
    tally->bounce_rays += lanes_count(alive);
    const LaneHit hit = trace_lanes(scene, org, dir, alive);
    alive = alive && hit.triangle >= 0;
    if (!lanes_any(alive)) break;
    const LightVertex v = light_vertex(scene, select((lint)(0), hit.triangle, alive), hit.b1, hit.b2);
    const lvec3 w_in = v3_neg(dir);
    const lfloat cos_g_in = v3_dot(v.point.normal, w_in);
    alive = alive && cos_g_in != 0.0f;
    // From the map, the first hit is at no distance the light's density knows of.
    weights_at_hit(&d_vcm, &d_vc, &d_vm,
                   select(hit.t, (lfloat)(1.0f), scatterings == 1u ? start.infinite : lanes_mask(false)),
                   fabs(cos_g_in));
    held_vc /= mis2(cos_g_in);
    held_vm /= mis2(cos_g_in);
    const lmask front = cos_g_in > 0.0f;
    const lvec3 g = v3_select(front, v.point.normal, v3_neg(v.point.normal));
    const lvec3 n = v3_select(front, v.shading_normal, v3_neg(v.shading_normal));

    const lmask smooth = alive && bsdf_has_smooth_lobe(&v.bsdf);
    if (lanes_any(smooth)) {
      store_light_vertex(stored, own, count, smooth, hit, d_vcm, w_in, d_vc, alpha, scatterings, v.point.position,
                         d_vm);
      count = select(count, count + 1u, smooth);
      // t = 1: the pinhole, weighed against the camera finding this vertex (the film's
      // density of it, in area) and everything further from the camera.
      const CameraView view = camera_view(params, &v.point);
      const lfloat cos_camera = v3_dot(g, view.to_camera);
      const lmask seen = smooth && view.seen && cos_camera > 0.0f;
      if (lanes_any(seen)) {
        const lvec3 f = bsdf_eval(&v.bsdf, n, view.to_camera, w_in);
        const lfloat pdf_rev = bsdf_pdf(&v.bsdf, n, view.to_camera, w_in);
        const lfloat w_light = mis2(view.importance * cos_camera) * (d_vcm + d_vc * mis2(pdf_rev));
        const lfloat weight = strategy_weight(1.0f / (1.0f + w_light), (luint)(scatterings + 1u), (luint)(scatterings));
        connect_to_camera(params, scene, &view,
                          v3_scale(v3_mul(alpha, f), fabs(v3_dot(n, w_in)) * cos_camera / fabs(cos_g_in) * weight),
                          seen, splats, density, tally);
      }
    }
    if (scatterings == params.max_depth) break;

    const BsdfSample s =
        bounce_light_path(params, &v, n, w_in, alive, scatterings, stream, path, &dim, &alpha, &carried);
    alive = alive && s.pdf != 0.0f;
    const lmask by_smooth_lobe = s.pdf > 0.0f;
    const lfloat pdf_rev = select((lfloat)(0.0f), bsdf_pdf(&v.bsdf, n, s.wi, w_in), by_smooth_lobe);
    const lfloat cos_out = fabs(v3_dot(v.point.normal, s.wi));
    // The merge at the vertex before is a strategy where this vertex took a delta lobe.
    const lmask by_delta_lobe = s.pdf < 0.0f;
    d_vc = select(d_vc, d_vc + held_vc, by_delta_lobe);
    d_vm = select(d_vm, d_vm + held_vm, by_delta_lobe);
    weights_at_sample(&d_vcm, &d_vc, &d_vm, m, (lfloat)(0.0f), s.pdf, pdf_rev, cos_out);
    held_vc = select((lfloat)(0.0f), mis2(cos_out / s.pdf) * m.vm, by_smooth_lobe);
    held_vm = select((lfloat)(0.0f), mis2(cos_out / s.pdf), m.vm > 0.0f ? by_smooth_lobe : lanes_mask(false));
    dir = s.wi;
    org = offset_ray_origin(&v.point, s.wi);
  }
  return count;
}

// A camera vertex as the connections see it: its surface, the normals on the viewer's side
// (g geometric, n shading), the direction back toward the camera, the throughput and the
// recursive weights' state.
typedef struct {
  LightVertex v;
  lvec3 g, n, wo, beta;
  lfloat d_vcm, d_vc, d_vm;
  lfloat merge_here;  // 1 where merging at this vertex is a strategy (merging_possible), else 0
  uint scatterings;   // this vertex's count from the camera, 1 for the first hit (the lanes' alike)
} CameraVertex;

// Of the lanes where `active`, those whose segment from a to b (both points just off their
// surfaces) is clear.
FH_INLINE lmask unoccluded(const SceneView* scene, lvec3 a, lvec3 b, lmask active, LightTally* tally) {
  const lvec3 d = v3_sub(b, a);
  const lfloat distance = v3_length(d);
  const lvec3 w = v3_scale(d, 1.0f / distance);
  return clear_lanes(scene, a, w, distance * FH_SHADOW_SHORTEN, active && distance > 0.0f, tally);
}

// s = 1: a point uniform in the area of a light triangle picked by the light table.
FH_INLINE lvec3 connect_to_triangle(RenderParams params, const SceneView* scene, MergeFactors m, const CameraVertex* c,
                                    luint pick, lfloat u1, lfloat u2, lmask active, LightTally* tally) {
  const lint light = gather_int(scene->light_triangle, pick);
  const lvec2 b = sample_triangle(u1, u2);
  const SurfacePoint y = surface_point(scene->triangles, light, b.x, b.y);
  const lfloat pdf_area = gather_float(scene->light_pdf_area, las_uint(light));
  const lvec3 to_light = v3_sub(y.position, c->v.point.position);
  const lfloat d2 = v3_dot(to_light, to_light);
  const lvec3 wi = v3_scale(to_light, rsqrt(d2));
  const lfloat cos_light = -v3_dot(y.normal, wi), cos_s = v3_dot(c->n, wi), cos_g = v3_dot(c->g, wi);
  lmask connects = active && cos_light > 0.0f && cos_s > 0.0f && cos_g > 0.0f && pdf_area > 0.0f && d2 > 0.0f;
  if (!lanes_any(connects)) return v3_splat(0.0f);
  const lvec3 f = bsdf_eval(&c->v.bsdf, c->n, c->wo, wi);
  const lvec3 le = material_lanes(scene->materials, gather_int(scene->triangle_material, las_uint(light))).ke;
  const lfloat pdf_w = pdf_area * d2 / cos_light;
  // Against BSDF sampling finding the light, and against the light subpaths that leave
  // the light through this vertex (emission density cos_light / pi, times p_A, over p_A).
  const lfloat w_light = mis2(bsdf_pdf(&c->v.bsdf, c->n, c->wo, wi) / pdf_w);
  const lfloat w_camera = mis2(cos_light * cos_g / (M_PI_F * d2)) *
                          (c->merge_here * m.vm + c->d_vcm + c->d_vc * mis2(bsdf_pdf(&c->v.bsdf, c->n, wi, c->wo)));
  const lfloat weight = strategy_weight(1.0f / (w_light + 1.0f + w_camera), (luint)(1u), (luint)(c->scatterings));
  const lvec3 value = v3_scale(v3_mul(v3_mul(c->beta, f), le), cos_s * weight / pdf_w);
  connects = connects && v3_any_positive(value);
  if (!lanes_any(connects)) return v3_splat(0.0f);
  const lvec3 from = offset_ray_origin(&c->v.point, c->g), to = offset_ray_origin(&y, v3_neg(wi));
  return v3_select(unoccluded(scene, from, to, connects, tally), value, v3_splat(0.0f));
}

#if defined(FH_ENV_MAP)
// s = 1 toward the map: a direction drawn from it (density p_w, the pick's included), against
// BSDF sampling escaping that way and against the light subpaths from the map's disk
// through this vertex (emission density p_w / (pi R^2), no cosine at the light).
FH_INLINE lvec3 connect_to_environment(RenderParams params, const SceneView* scene, MergeFactors m, float4 sphere,
                                       const CameraVertex* c, lfloat u1, lfloat u2, lmask active, LightTally* tally) {
  const EnvironmentSample e = environment_sample(params, scene->env_map, u1, u2);
  const lfloat pdf_w = params.env_pick * e.pdf;
  const lfloat cos_s = v3_dot(c->n, e.wi), cos_g = v3_dot(c->g, e.wi);
  lmask connects = active && pdf_w > 0.0f && cos_s > 0.0f && cos_g > 0.0f;
  if (!lanes_any(connects)) return v3_splat(0.0f);
  const lvec3 f = bsdf_eval(&c->v.bsdf, c->n, c->wo, e.wi);
  const lfloat w_light = mis2(bsdf_pdf(&c->v.bsdf, c->n, c->wo, e.wi) / pdf_w);
  const lfloat w_camera = mis2(cos_g / (M_PI_F * sphere.w * sphere.w)) *
                          (c->merge_here * m.vm + c->d_vcm + c->d_vc * mis2(bsdf_pdf(&c->v.bsdf, c->n, e.wi, c->wo)));
  const lfloat weight = strategy_weight(1.0f / (w_light + 1.0f + w_camera), (luint)(1u), (luint)(c->scatterings));
  const lvec3 value = v3_scale(v3_mul(v3_mul(c->beta, f), e.radiance), cos_s * weight / pdf_w);
  connects = connects && v3_any_positive(value);
  if (!lanes_any(connects)) return v3_splat(0.0f);
  const lvec3 from = offset_ray_origin(&c->v.point, c->g);
  return v3_select(clear_lanes(scene, from, e.wi, (lfloat)(INFINITY), connects, tally), value, v3_splat(0.0f));
}
#endif

// s = 1 in the lanes where `active`: the light table's pick decides between the map and a
// triangle.
FH_INLINE lvec3 connect_to_light(RenderParams params, const SceneView* scene, MergeFactors m, float4 sphere,
                                 const CameraVertex* c, lvec2 u, lfloat u_narrow, lmask active, LightTally* tally) {
  (void)sphere;  // read with FH_ENV_MAP only
  lvec3 value = v3_splat(0.0f);
  lmask to_environment = lanes_mask(false);
#if defined(FH_ENV_MAP)
  to_environment = u.y < params.env_pick;
  if (lanes_any(active && to_environment))
    value =
        connect_to_environment(params, scene, m, sphere, c, u.x,
                               params.env_pick < FH_NARROW_SHARE ? u_narrow : within_share(u.y, 0.0f, params.env_pick),
                               active && to_environment, tally);
#endif
  if (params.light_count > 0u && lanes_any(active && !to_environment)) {
    const LightPick pick = pick_light_within(scene->light_cdf, params.light_count, params.env_pick, u.y);
    value =
        v3_select(to_environment, value,
                  connect_to_triangle(params, scene, m, c, pick.light, u.x, select(pick.within, u_narrow, pick.narrow),
                                      active && !to_environment, tally));
  }
  return value;
}

// s >= 2 in the lanes where `active`: the camera vertex joined to the light vertex stored at
// float4 `slot` (read in every lane: a stored vertex of this work-item's in the others).
FH_INLINE lvec3 connect_vertices(const SceneView* scene, MergeFactors m, const CameraVertex* c,
                                 __global const float4* stored, luint slot, lmask active, LightTally* tally) {
  lfloat d_vcm_l, d_vc_l, scatterings_l;
  const lvec3 s0 = gather_xyzw(stored, slot, &d_vcm_l);
  const lvec3 w_in = gather_xyzw(stored, slot + 1u, &d_vc_l);
  const lvec3 alpha = gather_xyzw(stored, slot + 2u, &scatterings_l);
  const LightVertex l = light_vertex(scene, select((lint)(0), las_int(s0.x), active), s0.y, s0.z);
  const lfloat cos_l_in = v3_dot(l.point.normal, w_in);
  const lmask front = cos_l_in > 0.0f;
  const lvec3 g_l = v3_select(front, l.point.normal, v3_neg(l.point.normal));
  const lvec3 n_l = v3_select(front, l.shading_normal, v3_neg(l.shading_normal));
  const lvec3 d = v3_sub(l.point.position, c->v.point.position);
  const lfloat d2 = v3_dot(d, d);
  const lvec3 w = v3_scale(d, rsqrt(d2)), back = v3_neg(w);  // camera to light vertex, and back
  const lfloat cos_c = v3_dot(c->n, w), cos_c_g = v3_dot(c->g, w), cos_l_g = v3_dot(g_l, back);
  lmask joins = active && d2 > 0.0f && cos_c > 0.0f && cos_c_g > 0.0f && cos_l_g > 0.0f;
  if (!lanes_any(joins)) return v3_splat(0.0f);
  const lvec3 f_c = bsdf_eval(&c->v.bsdf, c->n, c->wo, w), f_l = bsdf_eval(&l.bsdf, n_l, back, w_in);
  // The camera side's radiance weights, the light side's as light_trace.cl weighs a bounce
  // toward the camera, and 1/d^2 between them.
  const lvec3 value = v3_scale(v3_mul(v3_mul(c->beta, f_c), v3_mul(f_l, alpha)),
                               cos_c * fabs(v3_dot(n_l, w_in)) * cos_l_g / (fabs(cos_l_in) * d2));
  joins = joins && v3_any_positive(value);
  if (!lanes_any(joins)) return v3_splat(0.0f);
  // Against the strategies with one more light vertex (the camera side's BSDF sampling
  // reaching the light vertex) and one more camera vertex, and all those beyond them.
  const lfloat pdf_camera_a = bsdf_pdf(&c->v.bsdf, c->n, c->wo, w) * cos_l_g / d2;
  const lfloat pdf_light_a = bsdf_pdf(&l.bsdf, n_l, w_in, back) * cos_c_g / d2;
  // (No merging at the light vertex: its neighbour toward the camera is this smooth join.)
  const lfloat w_light = mis2(pdf_camera_a) * (d_vcm_l + d_vc_l * mis2(bsdf_pdf(&l.bsdf, n_l, back, w_in)));
  const lfloat w_camera =
      mis2(pdf_light_a) * (c->merge_here * m.vm + c->d_vcm + c->d_vc * mis2(bsdf_pdf(&c->v.bsdf, c->n, w, c->wo)));
  const luint light_scatterings = lconvert_uint(scatterings_l);
  const lfloat weight =
      strategy_weight(1.0f / (w_light + 1.0f + w_camera), light_scatterings + 1u, light_scatterings + c->scatterings);
  joins = joins && weight > 0.0f;
  if (!lanes_any(joins)) return v3_splat(0.0f);
  const lvec3 from = offset_ray_origin(&c->v.point, c->g), to = offset_ray_origin(&l.point, g_l);
  return v3_select(unoccluded(scene, from, to, joins, tally), v3_scale(value, weight), v3_splat(0.0f));
}

#if defined(FH_VCM)
// The light vertices of a launch filed by cell (render/merge_grid.h): cell (i, j, k) of a
// grid `cell` wide from `lo` is bucket hash & mask, whose entries are
// filed[starts[b]] .. filed[starts[b + 1] - 1], in slot order: each a vertex's position and
// (w) its slot's bits (path index in the launch times max_depth, plus its place in its path),
// side by side so that a lookup reads a bucket's positions from one place.
typedef struct {
  __global const float4* stored;
  __global const uint* starts;
  __global const float4* filed;
  float4 lo;     // xyz: the grid's corner, w: 1 / its cells' width (2 r)
  float radius;  // r
  float scale;   // 1 / (N pi r^2): a merged light vertex's share of the density estimate
  uint mask;     // buckets - 1 (a power of two less one)
} MergeGrid;

// A multiplication, not a division (which OpenCL need not round correctly), so that the
// host files a vertex in the cell the kernel looks in.
FH_INLINE int merge_cell(float x, float lo, float inverse_width) { return (int)floor((x - lo) * inverse_width); }

// The grid's bucket of a cell: the host hashes alike (render/merge_grid.cpp).
FH_INLINE uint merge_bucket(int i, int j, int k, uint mask) {
  return (((uint)i * 73856093u) ^ ((uint)j * 19349663u) ^ ((uint)k * 83492791u)) & mask;
}

// The weight a merge at the camera's vertex number `scatterings` counts with: the power
// heuristic's, or under FH_VCM_MERGE_ONLY (a test hook) one at the first camera vertex and
// none elsewhere, so that merging alone renders every path that scatters.
FH_INLINE lfloat merge_weight(lfloat power_heuristic, uint scatterings) {
#if defined(FH_VCM_MERGE_ONLY)
  return (lfloat)(scatterings == 1u ? 1.0f : 0.0f);
#else
  (void)scatterings;
  return power_heuristic;
#endif
}

// Lane l's BSDF in every lane: one camera vertex's, against light vertices in the lanes.
FH_INLINE Bsdf bsdf_of_lane(const Bsdf* b, int l) {
  Bsdf r;
  r.kd = v3_uniform(v3_lane(b->kd, l));
  r.ks = v3_uniform(v3_lane(b->ks, l));
  r.tf = v3_uniform(v3_lane(b->tf, l));
  r.alpha = (lfloat)(LANE(b->alpha, l));
  r.eta = (lfloat)(LANE(b->eta, l));
  r.p_specular = (lfloat)(LANE(b->p_specular, l));
  r.lobes = (lint)(LANE(b->lobes, l));
  return r;
}

// Every light vertex within r of lane l's camera vertex merged with it: the light's
// throughput there times the camera vertex's BSDF toward where that light came from, over
// the disk's area and N, weighed against the connections that would make the same path
// (Georgiev's eqs. 38-39). A merged path has one scattering vertex fewer than its two
// subpaths together. The candidates of a bucket are taken FH_LANES at a time, each in a lane,
// and added in the bucket's order: the same sum as one at a time.
FH_INLINE float3 merge_at_lane(const MergeGrid* grid, MergeFactors m, const CameraVertex* c, int l, uint max_depth) {
  const float3 x = v3_lane(c->v.point.position, l);
  const lvec3 g = v3_uniform(v3_lane(c->g, l)), n = v3_uniform(v3_lane(c->n, l)), wo = v3_uniform(v3_lane(c->wo, l));
  const Bsdf bsdf = bsdf_of_lane(&c->v.bsdf, l);
  const float d_vcm = LANE(c->d_vcm, l), d_vm = LANE(c->d_vm, l);
  const float r = grid->radius, r2 = r * r;
  const int i0 = merge_cell(x.x - r, grid->lo.x, grid->lo.w), i1 = merge_cell(x.x + r, grid->lo.x, grid->lo.w);
  const int j0 = merge_cell(x.y - r, grid->lo.y, grid->lo.w), j1 = merge_cell(x.y + r, grid->lo.y, grid->lo.w);
  const int k0 = merge_cell(x.z - r, grid->lo.z, grid->lo.w), k1 = merge_cell(x.z + r, grid->lo.z, grid->lo.w);
  float3 sum = (float3)(0.0f);
  // Cells 2r wide: a disk of radius r meets at most two a side.
  for (int k = k0; k <= min(k1, k0 + 1); ++k)
    for (int j = j0; j <= min(j1, j0 + 1); ++j)
      for (int i = i0; i <= min(i1, i0 + 1); ++i) {
        const uint bucket = merge_bucket(i, j, k, grid->mask), end = grid->starts[bucket + 1u];
        for (uint first = grid->starts[bucket]; first < end; first += FH_LANES) {
          const luint e = lane_positions(first);
          lmask take = e < end;
          lfloat slot_bits;
          const lvec3 p = gather_xyzw(grid->filed, select((luint)(first), e, take), &slot_bits);
          const lvec3 d = v3_sub(p, v3_uniform(x));
          take = take && !(v3_dot(d, d) > r2);
          // Another cell's vertex in the same bucket is taken with its own cell (two of the
          // eight cells may share a bucket), as the host filed it.
          take = take && lconvert_int(floor((p.x - grid->lo.x) * grid->lo.w)) == i &&
                 lconvert_int(floor((p.y - grid->lo.y) * grid->lo.w)) == j &&
                 lconvert_int(floor((p.z - grid->lo.z) * grid->lo.w)) == k;
          if (!lanes_any(take)) continue;
          const luint slot = FH_BDPT_VERTEX_WORDS * select((luint)(0u), las_uint(slot_bits), take);
          lfloat d_vcm_l, unused, scatterings_l, d_vm_l;
          (void)gather_xyzw(grid->stored, slot, &d_vcm_l);
          const lvec3 w_in = gather_xyzw(grid->stored, slot + 1u, &unused);
          const lvec3 alpha = gather_xyzw(grid->stored, slot + 2u, &scatterings_l);
          d_vm_l = gather_w(grid->stored, slot + 3u);
          const lfloat cos_g = v3_dot(g, w_in);  // the light arrived on the camera's side
          take = take && !(lconvert_uint(scatterings_l) + c->scatterings - 1u > max_depth) && cos_g > 0.0f;
          if (!lanes_any(take)) continue;
          const lvec3 f = bsdf_eval(&bsdf, n, wo, w_in);
          const lfloat w_light = d_vcm_l * m.vc + d_vm_l * mis2(bsdf_pdf(&bsdf, n, wo, w_in));
          const lfloat w_camera = d_vcm * m.vc + d_vm * mis2(bsdf_pdf(&bsdf, n, w_in, wo));
          const lfloat weight = merge_weight(1.0f / (w_light + 1.0f + w_camera), c->scatterings);
          const lvec3 each = v3_scale(v3_mul(f, alpha), fabs(v3_dot(n, w_in)) / cos_g * weight);
          FH_FOR_LANES(q) {
            if (LANE(take, q)) sum += (float3)(LANE(each.x, q), LANE(each.y, q), LANE(each.z, q));
          }
        }
      }
  return (v3_lane(c->beta, l) * sum) * grid->scale;
}

// Merging at the camera vertices of the lanes where `merging`, lane after lane.
FH_INLINE lvec3 merge_light_vertices(const MergeGrid* grid, MergeFactors m, const CameraVertex* c, lmask merging,
                                     uint max_depth) {
  lvec3 merged = v3_splat(0.0f);
  const luint lanes = lane_positions(0);
  for (uint left = lanes_bits(merging); left != 0u; left &= left - 1u) {
    const int l = lowest_bit(left);
    merged = v3_select(lanes == (luint)(l), v3_uniform(merge_at_lane(grid, m, c, l, max_depth)), merged);
  }
  return merged;
}
#endif

// The camera subpaths through pixels `path` of the lanes where `alive`, their positions
// offset by the filter, joined to the `light_vertices` each stored from float4 `own` (and
// under FH_VCM merged with the grid's): the sum of each one's contributions to its own
// pixel. Its numbers are the pixel's own sequence, point `pass`, in the path tracer's
// dimensions (path_state.h): a pixel's first 2^k passes stratify each decision, as under
// mis. The lanes' subpaths take their bounces together: a vertex's count is the same in
// every lane still going.
#if defined(FH_VCM)
#define FH_MERGE_GRID_PARAM , const MergeGrid* grid
#else
#define FH_MERGE_GRID_PARAM
#endif
FH_INLINE lvec3 trace_camera_subpath(RenderParams params, const SceneView* scene, MergeFactors m, float4 sphere,
                                     uint pass, luint path, lmask alive, __global const float4* stored, luint own,
                                     luint light_vertices, __global const float* filter_table,
                                     LightTally* tally FH_MERGE_GRID_PARAM) {
  const PixelSampler sampler = pixel_sampler_at(params.seed, (luint)(pass), path, params.replicates);
  const CameraParams* cam = &params.camera;
  const uint width = (uint)cam->width;
  const lvec2 u_pixel = sample_2d(&sampler, (luint)(FH_DIM_PIXEL));
  const lfloat px =
      lconvert_float(path % width) + 0.5f + filter_offset(filter_table, params.filter_table_size, u_pixel.x);
  const lfloat py =
      lconvert_float(path / width) + 0.5f + filter_offset(filter_table, params.filter_table_size, u_pixel.y);
  lvec3 dir = camera_ray_direction(cam, px, py);
  lvec3 org = v3_uniform(vload3(0, cam->origin));
  const lfloat cos_camera = v3_dot(dir, v3_uniform(vload3(0, cam->forward)));
  const lfloat film_area =
      4.0f * v3_length(v3_uniform(vload3(0, cam->right))) * v3_length(v3_uniform(vload3(0, cam->up)));
  CameraVertex c;
  c.beta = v3_splat(1.0f);
  c.d_vcm = mis2(film_area * cos_camera * cos_camera * cos_camera);  // 1 / the film's density of dir
  c.d_vc = (lfloat)(0.0f);
  c.d_vm = (lfloat)(0.0f);
  lmask after_delta = lanes_mask(false);  // the camera subpath's last sample took a delta lobe
  lvec3 sum = v3_splat(0.0f);

  for (c.scatterings = 1u; c.scatterings <= params.max_depth + 1u; ++c.scatterings) {
    if (c.scatterings > 1u) tally->bounce_rays += lanes_count(alive);  // camera rays: the host counts one a pixel
    const LaneHit hit = trace_lanes(scene, org, dir, alive);
    const lmask escaped = alive && hit.triangle < 0;
    if (lanes_any(escaped)) {
      // Escaped: --env with weight one (no strategy but this finds it); the map weighed
      // against light sampling (p_w) and the light subpaths from its disk (p_w / (pi R^2)).
      sum = v3_select(escaped, v3_add(sum, v3_mul(c.beta, v3_uniform(vload3(0, params.env)))), sum);
#if defined(FH_ENV_MAP)
      lfloat env_pdf;
      const lvec3 le =
          environment_lookup(params, scene->env_map, v3_select(escaped, dir, v3(0.0f, 1.0f, 0.0f)), &env_pdf);
      const lfloat pdf_w = params.env_pick * env_pdf;
      const lfloat w_camera = c.scatterings == 1u
                                  ? (lfloat)(0.0f)
                                  : mis2(pdf_w) * c.d_vcm + mis2(pdf_w / (M_PI_F * sphere.w * sphere.w)) * c.d_vc;
      sum = v3_select(escaped,
                      v3_add(sum, v3_scale(v3_mul(c.beta, le), strategy_weight(1.0f / (1.0f + w_camera), (luint)(0u),
                                                                               (luint)(c.scatterings - 1u)))),
                      sum);
#endif
      alive = alive && !escaped;
    }
    if (!lanes_any(alive)) break;
    const lint triangle = select((lint)(0), hit.triangle, alive);
    c.v = light_vertex(scene, triangle, hit.b1, hit.b2);
    c.wo = v3_neg(dir);
    const lfloat cos_g = v3_dot(c.v.point.normal, c.wo);
    alive = alive && cos_g != 0.0f;
    weights_at_hit(&c.d_vcm, &c.d_vc, &c.d_vm, hit.t, fabs(cos_g));
    const lmask front = cos_g > 0.0f;
    c.g = v3_select(front, c.v.point.normal, v3_neg(c.v.point.normal));
    c.n = v3_select(front, c.v.shading_normal, v3_neg(c.v.shading_normal));
    c.merge_here = select((lfloat)(0.0f), (lfloat)(1.0f), merging_possible(m, after_delta, c.scatterings));

    // s = 0: emission from the front, weighed against light sampling (p_A) and the light
    // subpaths leaving from this point (p_A cos / pi); seen directly, the camera's alone.
    if (lanes_any(alive && front)) {
      const lvec3 ke = material_lanes(scene->materials, gather_int(scene->triangle_material, las_uint(triangle))).ke;
      const lmask emits = alive && front && v3_any_positive(ke);
      if (lanes_any(emits)) {
        const lfloat pdf_area = gather_float(scene->light_pdf_area, las_uint(triangle));
        const lfloat w_camera = c.scatterings == 1u
                                    ? (lfloat)(0.0f)
                                    : mis2(pdf_area) * c.d_vcm + mis2(pdf_area * cos_g * M_1_PI_F) * c.d_vc;
        sum = v3_select(emits,
                        v3_add(sum, v3_scale(v3_mul(c.beta, ke), strategy_weight(1.0f / (1.0f + w_camera), (luint)(0u),
                                                                                 (luint)(c.scatterings - 1u)))),
                        sum);
      }
    }
    if (c.scatterings > params.max_depth) break;

    const luint dim = (luint)((c.scatterings - 1u) * FH_DIMS_PER_BOUNCE);
    const lmask smooth = alive && bsdf_has_smooth_lobe(&c.v.bsdf);
    if (lanes_any(smooth)) {
      const lvec2 u = sample_2d(&sampler, dim + FH_DIM_LIGHT_U1);
      sum = v3_add(sum, connect_to_light(params, scene, m, sphere, &c, u,
                                         sample_1d(&sampler, dim + FH_DIM_LIGHT_NARROW), smooth, tally));
      // Each lane's light vertices in order of scatterings, until the path would be too long.
      // Lanes not joining read their work-item's first slot instead: lane 0 is a path of the
      // launch, whose slots no other work-item writes (lanes past the launch have none).
      lmask joining = smooth;
      const luint first_slot = (luint)(LANE(own, 0));
      for (uint k = 0u; k < params.max_depth; ++k) {
        joining = joining && k < light_vertices;
        const luint slot = select(first_slot, own + FH_BDPT_VERTEX_WORDS * k, joining);
        joining = joining && !(c.scatterings + lconvert_uint(gather_w(stored, slot + 2u)) > params.max_depth);
        if (!lanes_any(joining)) break;
        sum = v3_add(sum, connect_vertices(scene, m, &c, stored, slot, joining, tally));
      }
#if defined(FH_VCM)
      const lmask merging = smooth && c.merge_here > 0.0f;
      if (lanes_any(merging)) sum = v3_add(sum, merge_light_vertices(grid, m, &c, merging, params.max_depth));
#endif
    }

    const lvec2 u = sample_2d(&sampler, dim + FH_DIM_BSDF_U1);
    const BsdfSample b = bsdf_sample(&c.v.bsdf, c.v.point.normal, c.v.shading_normal, c.wo,
                                     sample_1d(&sampler, dim + FH_DIM_BSDF_LOBE), u.x, u.y);
    alive = alive && b.pdf != 0.0f;
    if (!lanes_any(alive)) break;
    const lfloat pdf_rev = select((lfloat)(0.0f), bsdf_pdf(&c.v.bsdf, c.n, b.wi, c.wo), b.pdf > 0.0f);
    weights_at_sample(&c.d_vcm, &c.d_vc, &c.d_vm, m, c.merge_here, b.pdf, pdf_rev,
                      fabs(v3_dot(c.v.point.normal, b.wi)));
    after_delta = b.pdf < 0.0f;
    c.beta = v3_mul(c.beta, b.weight);
    if (c.scatterings >= params.rr_depth) {
      const lfloat survive = fmin(v3_max_component(c.beta), 0.95f);
      alive = alive && !(sample_1d(&sampler, dim + FH_DIM_ROULETTE) >= survive);
      c.beta = v3_scale(c.beta, 1.0f / survive);
    }
    alive = alive && v3_any_positive(c.beta);
    if (!lanes_any(alive)) break;
    dir = b.wi;
    org = offset_ray_origin(&c.v.point, b.wi);
  }
  return sum;
}

// Adds each valid lane's camera subpath sum to its pixel, and a work-item's tally to the
// launch's.
FH_INLINE void finish_path(luint path, lvec3 sum, lmask valid, __global uint* splats, __global uint* tallies,
                           LightTally* tally) {
  const lmask finite = isfinite(sum.x) && isfinite(sum.y) && isfinite(sum.z);
  FH_FOR_LANES(l) {
    if (LANE(valid, l) && LANE(finite, l)) {
      volatile __global uint* own_pixel = splats + FH_SPLAT_WORDS * LANE(path, l);
      add_quanta(own_pixel, LANE(sum.x, l));
      add_quanta(own_pixel + 2, LANE(sum.y, l));
      add_quanta(own_pixel + 4, LANE(sum.z, l));
    }
  }
  tally->nonfinite += lanes_count(valid && !finite);
  add_tally(tallies, tally);
}

// Where each lane's light vertices go in `stored` (a float4 index): max_depth slots a path,
// by its place in the launch.
FH_INLINE luint own_slots(luint index, uint max_depth) { return index * (max_depth * FH_BDPT_VERTEX_WORDS); }

// A work-item's paths, one a lane: their places in the launch of `count` paths from the
// pass's path `first` (`index`: what the vertex buffer's slots follow) and their numbers in
// the pass (`path`); `in_launch` where the place is in the launch, `valid` where the path
// is also one of the pass's pixels.
typedef struct {
  luint index, path;
  lmask in_launch, valid;
} LaunchLanes;

FH_INLINE LaunchLanes launch_lanes(RenderParams params, uint first, uint count) {
  LaunchLanes w;
  w.index = lane_positions(get_global_id(0) * FH_LANES);
  w.path = first + w.index;
  w.in_launch = w.index < count;
  w.valid = w.in_launch && w.path < params.pixel_count;
  return w;
}

#if !defined(FH_VCM)
// bdpt: a work-item's light subpaths (FH_LANES of them: lanes.h), then its camera subpaths
// joined to them.
__kernel void bdpt(RenderParams params, uint pass, uint first, uint count, float4 sphere, __global float4* stored,
                   __global const float* filter_table, __global uint* splats, __global const float* density,
                   __global uint* tallies FH_SCENE_PARAMS) {
  const LaunchLanes w = launch_lanes(params, first, count);
  if (!lanes_any(w.valid)) return;
  const SceneView scene = FH_SCENE_VIEW;
  const luint stream = hash_combine((luint)(params.seed), (luint)(pass));
  const MergeFactors none = {0.0f, 0.0f};
  LightTally tally = {0u, 0u, 0u};
  const luint own = own_slots(w.index, params.max_depth);
  const luint light_vertices = trace_light_subpath(params, &scene, none, sphere, hash_combine(stream, (luint)(1u)),
                                                   w.path, w.valid, stored, own, splats, density, &tally);
  const lvec3 sum = trace_camera_subpath(params, &scene, none, sphere, pass, w.path, w.valid, stored, own,
                                         light_vertices, filter_table, &tally);
  finish_path(w.path, sum, w.valid, splats, tallies, &tally);
}
#else
// vcm, first: every light subpath of the launch (FH_LANES a work-item), its vertices stored
// and counted.
__kernel void vcm_light_subpaths(RenderParams params, uint pass, uint first, uint count, float4 sphere, float2 factors,
                                 __global float4* stored, __global uint* stored_count, __global uint* splats,
                                 __global const float* density, __global uint* tallies FH_SCENE_PARAMS) {
  const LaunchLanes w = launch_lanes(params, first, count);
  if (!lanes_any(w.in_launch)) return;
  const SceneView scene = FH_SCENE_VIEW;
  const luint stream = hash_combine((luint)(params.seed), (luint)(pass));
  const MergeFactors m = {factors.x, factors.y};
  LightTally tally = {0u, 0u, 0u};
  luint stored_here = (luint)(0u);
  if (lanes_any(w.valid))
    stored_here = trace_light_subpath(params, &scene, m, sphere, hash_combine(stream, (luint)(1u)), w.path, w.valid,
                                      stored, own_slots(w.index, params.max_depth), splats, density, &tally);
  scatter_uint(stored_count, w.index, select((luint)(0u), stored_here, w.valid), w.in_launch);
  add_tally(tallies, &tally);
}

// vcm, next: the stored vertices' positions, path after path (`offsets`: where each path's
// go, from the host's running sum of the counts), for the host to file in the grid.
__kernel void vcm_gather_positions(uint count, uint max_depth, __global const float4* stored,
                                   __global const uint* stored_count, __global const uint* offsets,
                                   __global float4* positions) {
  const uint index = get_global_id(0);
  if (index >= count) return;
  for (uint k = 0u; k < stored_count[index]; ++k)
    positions[offsets[index] + k] = stored[((size_t)index * max_depth + k) * FH_BDPT_VERTEX_WORDS + 3u];
}

// vcm, then: the camera subpaths (FH_LANES a work-item), joined to their own light subpaths
// and merged with all of the launch's.
__kernel void vcm_camera_subpaths(RenderParams params, uint pass, uint first, uint count, float4 sphere, float2 factors,
                                  float4 grid_lo, float4 grid_merge, __global const float4* stored,
                                  __global const uint* stored_count, __global const uint* grid_starts,
                                  __global const float4* grid_filed, __global const float* filter_table,
                                  __global uint* splats, __global uint* tallies FH_SCENE_PARAMS) {
  const LaunchLanes w = launch_lanes(params, first, count);
  if (!lanes_any(w.valid)) return;
  const SceneView scene = FH_SCENE_VIEW;
  const MergeFactors m = {factors.x, factors.y};
  MergeGrid grid;
  grid.stored = stored;
  grid.starts = grid_starts;
  grid.filed = grid_filed;
  grid.lo = grid_lo;
  grid.radius = grid_merge.x;
  grid.scale = grid_merge.y;
  grid.mask = as_uint(grid_merge.z);
  LightTally tally = {0u, 0u, 0u};
  // Lanes past the launch read the first lane's count (lane 0 is always in it).
  const luint light_vertices = gather_uint(stored_count, select((luint)(LANE(w.index, 0)), w.index, w.valid));
  const lvec3 sum =
      trace_camera_subpath(params, &scene, m, sphere, pass, w.path, w.valid, stored,
                           own_slots(w.index, params.max_depth), light_vertices, filter_table, &tally, &grid);
  finish_path(w.path, sum, w.valid, splats, tallies, &tally);
}
#endif

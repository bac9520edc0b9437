// Light tracing (--method lt): paths start on the emitters and each vertex is connected to
// the camera (the t = 1 strategy of bidirectional path tracing, Veach 1997 §10.2), so light
// that reaches a diffuse surface through glass or a mirror (L S+ D E paths, caustics) is
// found from the light's side, where camera paths never find it.
//
// A work-item traces FH_LANES light paths (lanes.h: eight in vector lanes on a CPU), each:
// an emissive triangle picked by the light table and a point uniform on it (density p_A), a
// direction cosine-distributed about its front normal, then BSDF sampling with the adjoint
// weights (importance is carried, not radiance: no 1/eta^2 through a refraction, and the
// shading-normal correction of Veach §5.3). Every vertex with a smooth lobe, and the
// emitter point itself, is connected to the pinhole: the contribution alpha f |cos| W / d^2
// lands on the pixels whose filter covers the point it is seen at. Lanes or not, a path
// draws the same numbers and makes the same splats: the same bits.
//
// A pass traces one light path per pixel of the image (N = W H), so that pixel j's value
// after the pass is sum_i alpha_i f_i |cos_i| g_j(p_i) / (A d_i^2 cos^3 theta_i): W_j, the
// pinhole's importance for pixel j per unit solid angle, is g_j(p) W H / (A cos^3 theta)
// (A: the film's area on the plane one unit in front of the pinhole, g_j: pixel j's filter
// density over image positions), and the W H cancels against 1/N.
//
// Splats are added as whole quanta of the film (2^-24) into 64-bit integers, so a pixel's
// sum does not depend on the order in which work-items or devices add to it: the same bits
// on any device count, chunking and rank count.
#include "light_paths.h"

__kernel void light_trace(RenderParams params, uint pass, __global uint* splats, __global const float* density,
                          __global uint* tallies FH_SCENE_PARAMS) {
  const luint path = lane_positions(get_global_id(0) * FH_LANES);
  lmask alive = path < params.pixel_count;
  if (!lanes_any(alive) || params.light_count == 0u) return;
  const SceneView scene = FH_SCENE_VIEW;
  const luint stream = hash_combine((luint)(params.seed), (luint)(pass));
  uint dim = 0u;
  LightTally tally = {0u, 0u, 0u};

  // The emitter point: a triangle by the light table, then uniform in its area.
  const lfloat u_pick = random_float(stream, path, (luint)(dim++));
  const lint light = gather_int(scene.light_triangle, pick_light(scene.light_cdf, params.light_count, u_pick));
  const lfloat u1 = random_float(stream, path, (luint)(dim++)), u2 = random_float(stream, path, (luint)(dim++));
  const lvec2 b = sample_triangle(u1, u2);
  const SurfacePoint y = surface_point(scene.triangles, light, b.x, b.y);
  const lvec3 le = material_lanes(scene.materials, gather_int(scene.triangle_material, las_uint(light))).ke;
  // alpha: the path's weight per unit area at its last vertex, Le / p_A at the emitter.
  lvec3 alpha = v3_scale(le, 1.0f / gather_float(scene.light_pdf_area, las_uint(light)));

  // The emitter seen directly: Ke leaves the front side only.
  CameraView view = camera_view(params, &y);
  const lfloat cos_light = v3_dot(y.normal, view.to_camera);
  connect_to_camera(params, &scene, &view, v3_scale(alpha, cos_light), alive && view.seen && cos_light > 0.0f, splats,
                    density, &tally);

  // Leave the light cosine-distributed about its front normal: Le cos / (p_A cos / pi).
  const lfloat u3 = random_float(stream, path, (luint)(dim++)), u4 = random_float(stream, path, (luint)(dim++));
  lvec3 dir = sample_cosine_hemisphere(y.normal, u3, u4);
  lvec3 org = offset_ray_origin(&y, dir);
  alpha = v3_scale(alpha, M_PI_F);
  lvec3 carried = v3_splat(1.0f);  // the BSDF weights since the light: what roulette reads

  // The lanes bounce together; a lane whose path has ended waits for the others.
  for (uint scatterings = 1u; scatterings <= params.max_depth; ++scatterings) {
    tally.bounce_rays += lanes_count(alive);
    const LaneHit hit = trace_lanes(&scene, org, dir, alive);
    alive = alive && hit.triangle >= 0;
    if (!lanes_any(alive)) break;
    const LightVertex v = light_vertex(&scene, select((lint)(0), hit.triangle, alive), hit.b1, hit.b2);
    const lvec3 w_in = v3_neg(dir);
    const lfloat cos_g_in = v3_dot(v.point.normal, w_in);
    alive = alive && cos_g_in != 0.0f;
    // The normals on the side the light arrives from.
    const lmask front = cos_g_in > 0.0f;
    const lvec3 g = v3_select(front, v.point.normal, v3_neg(v.point.normal));
    const lvec3 n = v3_select(front, v.shading_normal, v3_neg(v.shading_normal));

    // The camera through the smooth lobes: f(w_camera <- w_in), the shading cosine at the
    // incoming side (Veach §5.3), the geometric one toward the camera.
    const lmask smooth = alive && bsdf_has_smooth_lobe(&v.bsdf);
    if (lanes_any(smooth)) {
      view = camera_view(params, &v.point);
      const lfloat cos_camera = v3_dot(g, view.to_camera);
      const lmask seen = smooth && view.seen && cos_camera > 0.0f;
      if (lanes_any(seen)) {
        const lvec3 f = bsdf_eval(&v.bsdf, n, view.to_camera, w_in);
        connect_to_camera(params, &scene, &view,
                          v3_scale(v3_mul(alpha, f), fabs(v3_dot(n, w_in)) * cos_camera / fabs(cos_g_in)), seen,
                          splats, density, &tally);
      }
    }
    if (scatterings == params.max_depth) break;

    const BsdfSample s =
        bounce_light_path(params, &v, n, w_in, alive, scatterings, stream, path, &dim, &alpha, &carried);
    alive = alive && s.pdf != 0.0f;
    if (!lanes_any(alive)) break;
    dir = s.wi;
    org = offset_ray_origin(&v.point, s.wi);
  }
  add_tally(tallies, &tally);
}

// The first-surface layers a denoiser or compositor wants beside the image (--aovs
// albedo,normal,depth), recorded by shade in the same render as the radiance, built with
// FH_AOVS only. Each sample writes its entry of the pass buffers (pass_entry: one writer
// per entry, as for radiance), two float4s:
//   [0] albedo rgb of the first non-specular surface, w: 1 once found, -1 while pending
//       (only delta bounces so far: mirrors and glass are looked through, as denoisers
//       expect; a path that ends before finding one keeps the last such surface's values)
//   [1] its normal (shading normal on the viewer's side) xyz, w: the camera ray's hit
//       distance (0 where it escaped)
// Every sample writes at its first vertex, so the entries need no clearing between passes.
#ifndef FH_AOVS_H
#define FH_AOVS_H

#include "bsdf.h"
#include "lanes.h"
#include "path_state.h"

#define FH_AOV_FLOAT4S 2

// The entry of path p's sample in the AOV buffers.
FH_INLINE luint aov_entry(luint p, FH_PATH_SPACE const FH_PATH_TYPE(uint)* pass_entry) {
  return FH_AOV_FLOAT4S * FH_PASS_ENTRY_INDEX(gather_uint(pass_entry, p));
}

// What a denoiser takes as a surface's albedo: its diffuse and specular reflectance.
FH_INLINE lvec3 aov_albedo(const Bsdf* b) {
  const lvec3 specular = v3_select(has_lobe(b, FH_LOBE_GLOSSY | FH_LOBE_MIRROR), b->ks, v3_splat(0.0f));
  return v3_clamp01(v3_add(b->kd, specular));
}

// Surfaces a denoiser looks through: glass, and mirrors whose delta lobe is sampled at least
// as often as their diffuse one. The path's next vertex is recorded instead when the bounce
// here took the delta lobe.
FH_INLINE lmask aov_looks_through(const Bsdf* b) {
  return has_lobe(b, FH_LOBE_GLASS) || (has_lobe(b, FH_LOBE_MIRROR) && b->p_specular >= 0.5f);
}

// Camera rays that escaped: nothing seen.
FH_INLINE void record_escaped_aovs(luint entry, lmask escaped_at_camera, __global float4* aovs) {
  scatter_xyzw(aovs, entry, v3_splat(0.0f), (lfloat)(1.0f), escaped_at_camera);
  scatter_xyzw(aovs, entry + 1, v3_splat(0.0f), (lfloat)(0.0f), escaped_at_camera);
}

// Surfaces hit (`hits`) at `bounce`: recorded where the path has had only delta bounces and
// its entry is still pending (every camera hit, then the hits after mirrors and glass).
FH_INLINE void record_surface_aovs(luint entry, lmask hits, luint bounce, lfloat previous_pdf, lfloat distance,
                                   const Bsdf* b, lvec3 viewer_normal, __global float4* aovs) {
  const lmask at_camera = hits && bounce == 0;
  lmask pending = at_camera;
  const lmask after_delta = hits && bounce > 0 && previous_pdf < 0.0f;
  if (lanes_any(after_delta)) pending = pending || (after_delta && gather_w(aovs, entry) < 0.0f);
  if (!lanes_any(pending)) return;
  const lfloat found = select((lfloat)(1.0f), (lfloat)(-1.0f), aov_looks_through(b));
  // The depth is the camera ray's: kept from the first vertex.
  const lfloat depth = select(gather_w(aovs, entry + 1), distance, at_camera);
  scatter_xyzw(aovs, entry, aov_albedo(b), found, pending);
  scatter_xyzw(aovs, entry + 1, viewer_normal, depth, pending);
}

#endif

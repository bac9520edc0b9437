// BSDFs: the scattering kernel of the rendering equation. Each provides eval (f), sample
// and pdf that agree with each other. Today: Lambertian diffuse (Kd); glossy, mirror
// and glass lobes plug in here, selected by the material's illum model.
#ifndef FH_BSDF_H
#define FH_BSDF_H

#include "sampling.h"
#include "types.h"

typedef struct {
  float3 kd;
} Bsdf;

FH_INLINE Bsdf material_bsdf(__global const GpuMaterial* m) {
  Bsdf b;
  b.kd = vload3(0, m->kd);
  return b;
}

// f(wo, wi) for directions on the side of n (the normal on the viewer's side). Light
// from the other side of an opaque surface is not reflected.
FH_INLINE float3 bsdf_eval(const Bsdf* b, float3 n, float3 wi) {
  return dot(n, wi) > 0.0f ? b->kd * M_1_PI_F : (float3)(0.0f);
}

FH_INLINE float bsdf_pdf(float3 n, float3 wi) { return fmax(dot(n, wi), 0.0f) * M_1_PI_F; }

// Samples wi; returns f cos / pdf (the throughput factor) and the pdf in *pdf.
FH_INLINE float3 bsdf_sample(const Bsdf* b, float3 n, float u1, float u2, float3* wi, float* pdf) {
  *wi = sample_cosine_hemisphere(n, u1, u2);
  *pdf = bsdf_pdf(n, *wi);
  return *pdf > 0.0f ? b->kd : (float3)(0.0f);
}

#endif

// BSDFs: the scattering kernel of the rendering equation, mapped from MTL (README):
//   illum 0, 1, 2 with Ks = 0   Lambertian diffuse Kd
//   illum 2 with Ks > 0         diffuse + GGX glossy reflection, roughness from Ns
//   illum 3, 5, 8               diffuse + mirror (delta) if Ns >= 1000, else + glossy
//   illum 4, 6, 7, 9            smooth dielectric: Fresnel reflection / refraction by Ni,
//                               transmission tinted by Tf, total internal reflection
// The specular reflectance is Ks (Schlick's Fresnel rises to 1 at grazing angles), and
// the diffuse part is scaled by 1 - max F(wo), the light the specular lobe leaves over,
// so the sum never reflects more than it receives (tests/test_bsdf.cpp). Every non-delta lobe has eval, sample and
// pdf that agree (tests/test_bsdf.cpp checks sampling against the pdf); delta lobes
// (mirror, glass) are sampled only, and report pdf < 0 so the integrator knows.
#ifndef FH_BSDF_H
#define FH_BSDF_H

#include "sampling.h"
#include "types.h"

#define FH_LOBE_DIFFUSE 1
#define FH_LOBE_GLOSSY 2
#define FH_LOBE_MIRROR 4
#define FH_LOBE_GLASS 8
#define FH_NS_MIRROR 1000.0f  // Ns at or above which an illum 3/5/8 surface is a perfect mirror

typedef struct {
  float3 kd;            // diffuse albedo (scaled per wo by diffuse_scale)
  float3 ks;            // specular reflectance at normal incidence (Schlick's F0)
  float3 tf;            // transmission tint (glass)
  float alpha;          // GGX roughness
  float eta;            // index of refraction (glass)
  float p_specular;     // probability of sampling the specular lobe rather than the diffuse
  int lobes;
} Bsdf;

FH_INLINE float luminance3(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Ns (a Phong exponent) to GGX roughness: alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007).
FH_INLINE float roughness_from_ns(float ns) { return sqrt(2.0f / (fmax(ns, 0.0f) + 2.0f)); }

FH_INLINE Bsdf material_bsdf(__global const GpuMaterial* m) {
  Bsdf b;
  const float3 kd = vload3(0, m->kd), ks = clamp(vload3(0, m->ks), 0.0f, 1.0f);
  const float ns = m->ks[3];
  b.tf = clamp(vload3(0, m->tf), 0.0f, 1.0f);
  b.eta = m->tf[3] > 0.0f ? m->tf[3] : 1.5f;
  b.alpha = fmax(roughness_from_ns(ns), 1e-3f);
  b.ks = ks;
#if defined(FH_GLASS) || defined(FH_GLOSSY)
  const int illum = m->illum;
#endif
#if defined(FH_GLASS)
  if (illum == 4 || illum == 6 || illum == 7 || illum == 9) {
    b.lobes = FH_LOBE_GLASS;
    b.kd = (float3)(0.0f);
    b.p_specular = 1.0f;
    return b;
  }
#endif
  b.kd = kd;
  b.lobes = FH_LOBE_DIFFUSE;
#if defined(FH_GLOSSY)
  const bool has_specular = ks.x > 0.0f || ks.y > 0.0f || ks.z > 0.0f;
  if (has_specular && illum >= 2)
    b.lobes |= (illum == 3 || illum == 5 || illum == 8) && ns >= FH_NS_MIRROR ? FH_LOBE_MIRROR : FH_LOBE_GLOSSY;
#endif
  const float ws = (b.lobes & ~FH_LOBE_DIFFUSE) ? luminance3(ks) : 0.0f;
  const float wd = luminance3(kd) * (1.0f - fmax(fmax(ks.x, ks.y), ks.z));
  b.p_specular = ws + wd > 0.0f ? ws / (ws + wd) : 0.0f;
  return b;
}

FH_INLINE bool bsdf_has_smooth_lobe(const Bsdf* b) { return (b->lobes & (FH_LOBE_DIFFUSE | FH_LOBE_GLOSSY)) != 0; }

// Scenes are compiled with only the lobes they use (host/render/device_scene.cpp): FH_GLOSSY
// for glossy and mirror surfaces, FH_GLASS for dielectrics. Without them the branches
// below are dead code the compiler removes.
#if !defined(FH_GLOSSY)
#define FH_HAS_GLOSSY 0
#else
#define FH_HAS_GLOSSY 1
#endif

// ---- GGX (Trowbridge-Reitz), in the local frame where n = (0, 0, 1) ----

FH_INLINE float ggx_d(float3 h, float a) {
  const float a2 = a * a, c2 = h.z * h.z;
  const float t = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (M_PI_F * t * t);
}

FH_INLINE float ggx_lambda(float3 w, float a) {
  const float c2 = w.z * w.z;
  if (c2 <= 0.0f) return 0.0f;
  const float t2 = fmax(1.0f - c2, 0.0f) / c2;
  return 0.5f * (sqrt(1.0f + a * a * t2) - 1.0f);
}

FH_INLINE float ggx_g1(float3 w, float a) { return 1.0f / (1.0f + ggx_lambda(w, a)); }

// Height-correlated masking-shadowing.
FH_INLINE float ggx_g2(float3 wo, float3 wi, float a) { return 1.0f / (1.0f + ggx_lambda(wo, a) + ggx_lambda(wi, a)); }

FH_INLINE float3 fresnel_schlick(float3 f0, float cos_theta) {
  const float m = 1.0f - clamp(cos_theta, 0.0f, 1.0f);
  const float m5 = m * m * m * m * m;
  return f0 + (1.0f - f0) * m5;
}

// A visible normal for wo (Heitz, "Sampling the GGX Distribution of Visible Normals", 2018).
FH_INLINE float3 ggx_sample_visible_normal(float3 wo, float a, float u1, float u2) {
  const float3 vh = normalize((float3)(a * wo.x, a * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const float3 t1 = len2 > 0.0f ? (float3)(-vh.y, vh.x, 0.0f) * rsqrt(len2) : (float3)(1.0f, 0.0f, 0.0f);
  const float3 t2 = cross(vh, t1);
  const float2 d = sample_concentric_disk(u1, u2);
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - d.x * d.x)) + s * d.y;
  const float p1 = d.x;
  const float3 nh = p1 * t1 + p2 * t2 + sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize((float3)(a * nh.x, a * nh.y, fmax(1e-6f, nh.z)));
}

// Density of wi from visible-normal sampling: D_v(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z).
FH_INLINE float ggx_pdf(float3 wo, float3 wi, float a) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const float3 h = normalize(wo + wi);
  return ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z);
}

FH_INLINE float3 ggx_eval(float3 wo, float3 wi, float3 f0, float a) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
  const float3 h = normalize(wo + wi);
  return fresnel_schlick(f0, dot(wo, h)) * (ggx_d(h, a) * ggx_g2(wo, wi, a) / (4.0f * wo.z * wi.z));
}

// ---- The material as a whole, in world space; n is the normal on the viewer's side ----

typedef struct {
  float3 t, b, n;
} Frame;

FH_INLINE Frame make_frame(float3 n) {
  Frame f;
  f.n = n;
  orthonormal_basis(n, &f.t, &f.b);
  return f;
}
FH_INLINE float3 to_local(const Frame* f, float3 v) { return (float3)(dot(v, f->t), dot(v, f->b), dot(v, f->n)); }
FH_INLINE float3 to_world(const Frame* f, float3 v) { return v.x * f->t + v.y * f->b + v.z * f->n; }

// The share of the diffuse lobe: what the specular lobe's Fresnel term leaves at wo.
FH_INLINE float diffuse_scale(const Bsdf* b, float cos_o) {
  if (!(b->lobes & (FH_LOBE_GLOSSY | FH_LOBE_MIRROR))) return 1.0f;
  const float3 f = fresnel_schlick(b->ks, cos_o);
  return 1.0f - fmax(fmax(f.x, f.y), f.z);
}

// f(wo, wi) of the smooth (non-delta) lobes. Light from behind an opaque surface is not
// reflected.
FH_INLINE float3 bsdf_eval(const Bsdf* b, float3 n, float3 wo, float3 wi) {
  if (dot(n, wi) <= 0.0f || dot(n, wo) <= 0.0f) return (float3)(0.0f);
  float3 f = (b->lobes & FH_LOBE_DIFFUSE) ? b->kd * (M_1_PI_F * diffuse_scale(b, dot(n, wo))) : (float3)(0.0f);
  if (FH_HAS_GLOSSY && (b->lobes & FH_LOBE_GLOSSY)) {
    const Frame fr = make_frame(n);
    f += ggx_eval(to_local(&fr, wo), to_local(&fr, wi), b->ks, b->alpha);
  }
  return f;
}

// The density bsdf_sample gives wi through the smooth lobes (delta lobes excluded).
FH_INLINE float bsdf_pdf(const Bsdf* b, float3 n, float3 wo, float3 wi) {
  if (dot(n, wi) <= 0.0f) return 0.0f;
  float pdf = (b->lobes & FH_LOBE_DIFFUSE) ? (1.0f - b->p_specular) * dot(n, wi) * M_1_PI_F : 0.0f;
  if (FH_HAS_GLOSSY && (b->lobes & FH_LOBE_GLOSSY)) {
    const Frame fr = make_frame(n);
    pdf += b->p_specular * ggx_pdf(to_local(&fr, wo), to_local(&fr, wi), b->alpha);
  }
  return pdf;
}

// Exact Fresnel reflectance of a smooth dielectric for cos_i > 0 and relative index eta
// (transmitted over incident side); 1 under total internal reflection. *cos_t is set.
FH_INLINE float fresnel_dielectric(float cos_i, float eta, float* cos_t) {
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) {
    *cos_t = 0.0f;
    return 1.0f;
  }
  *cos_t = sqrt(1.0f - sin2_t);
  const float rs = (cos_i - eta * *cos_t) / (cos_i + eta * *cos_t);
  const float rp = (eta * cos_i - *cos_t) / (eta * cos_i + *cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

// Samples wi given wo (toward the viewer), ng (the geometric normal, front side) and ns
// (the shading normal, on ng's side). Returns the throughput factor f cos / pdf; *pdf is
// the density for smooth lobes, or -1 for a delta lobe (mirror, glass), which light
// sampling cannot reach. Directions that a shading normal would send through the
// geometric surface the wrong way are rejected (factor 0): no light leaks.
FH_INLINE float3 bsdf_sample(const Bsdf* b, float3 ng, float3 ns, float3 wo, float u0, float u1, float u2,
                             float3* wi, float* pdf) {
  const bool front = dot(ng, wo) >= 0.0f;
  const float3 g = front ? ng : -ng;  // the geometric normal on the viewer's side
  const float3 n = front ? ns : -ns;
  *pdf = 0.0f;
#if defined(FH_GLASS)
  if (b->lobes & FH_LOBE_GLASS) {
    // Entering through the front, leaving through the back: the geometric side decides.
    const float eta = front ? b->eta : 1.0f / b->eta;
    const float cos_i = dot(n, wo);
    if (cos_i <= 0.0f) return (float3)(0.0f);
    float cos_t;
    const float f = fresnel_dielectric(cos_i, eta, &cos_t);
    if (u0 < f) {
      *wi = 2.0f * cos_i * n - wo;
      if (dot(g, *wi) <= 0.0f) return (float3)(0.0f);
      *pdf = -1.0f;
      return (float3)(1.0f);
    }
    *wi = normalize(-wo / eta + (cos_i / eta - cos_t) * n);
    if (dot(g, *wi) >= 0.0f) return (float3)(0.0f);
    *pdf = -1.0f;
    // Radiance is compressed by (eta_i / eta_t)^2 crossing into the denser medium.
    return b->tf / (eta * eta);
  }
#endif
  if (dot(n, wo) <= 0.0f) return (float3)(0.0f);
  if (FH_HAS_GLOSSY && (b->lobes & FH_LOBE_MIRROR) && u0 < b->p_specular) {
    *wi = 2.0f * dot(n, wo) * n - wo;
    if (dot(g, *wi) <= 0.0f) return (float3)(0.0f);
    *pdf = -1.0f;
    return fresnel_schlick(b->ks, dot(n, wo)) / b->p_specular;
  }
  if (FH_HAS_GLOSSY && (b->lobes & FH_LOBE_GLOSSY) && u0 < b->p_specular) {
    const Frame fr = make_frame(n);
    const float3 lo = to_local(&fr, wo);
    const float3 h = ggx_sample_visible_normal(lo, b->alpha, u1, u2);
    *wi = to_world(&fr, 2.0f * dot(lo, h) * h - lo);
  } else {
    *wi = sample_cosine_hemisphere(n, u1, u2);
  }
  if (dot(g, *wi) <= 0.0f) return (float3)(0.0f);
  // (With a mirror lobe, this is its diffuse part, chosen with 1 - p_specular, which
  // bsdf_pdf includes.)
  *pdf = bsdf_pdf(b, n, wo, *wi);
  const float3 f = bsdf_eval(b, n, wo, *wi);
  return *pdf > 0.0f ? f * dot(n, *wi) / *pdf : (float3)(0.0f);
}

#endif

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
// Lane-wise (lanes.h): each lane may have its own material; a lobe is computed when any
// lane has it, and the lanes' results are selected.
#ifndef FH_BSDF_H
#define FH_BSDF_H

#include "sampling.h"

#define FH_LOBE_DIFFUSE 1
#define FH_LOBE_GLOSSY 2
#define FH_LOBE_MIRROR 4
#define FH_LOBE_GLASS 8

typedef struct {
  lvec3 kd;             // diffuse albedo (scaled per wo by diffuse_scale)
  lvec3 ks;             // specular reflectance at normal incidence (Schlick's F0)
  lvec3 tf;             // transmission tint (glass)
  lfloat alpha;         // GGX roughness
  lfloat eta;           // index of refraction (glass)
  lfloat p_specular;    // probability of sampling the specular lobe rather than the diffuse
  lint lobes;
} Bsdf;

// Lanes whose BSDF has any of `lobes`.
FH_INLINE lmask has_lobe(const Bsdf* b, int lobes) { return (b->lobes & lobes) != 0; }

FH_INLINE lfloat luminance3(lvec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Ns (a Phong exponent) to GGX roughness: alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007).
FH_INLINE lfloat roughness_from_ns(lfloat ns) { return sqrt(2.0f / (fmax(ns, 0.0f) + 2.0f)); }

// A material's fields for each lane's material id: gathers.
typedef struct {
  lvec3 kd, ks, tf, ke;
  lfloat ns, ni;
  lint illum, texture;
} MaterialLanes;

// Each lane's material is a run of 32-bit words; field `offset` (in words) of every lane's
// material is one gather (lanes.h), and a field no caller reads is never loaded.
FH_INLINE lfloat material_float(__global const GpuMaterial* materials, luint first_word, int offset) {
  return gather_float((__global const float*)materials + offset, first_word);
}

FH_INLINE lvec3 material_rgb(__global const GpuMaterial* materials, luint first_word, int offset) {
  return v3(material_float(materials, first_word, offset), material_float(materials, first_word, offset + 1),
            material_float(materials, first_word, offset + 2));
}

FH_INLINE MaterialLanes material_lanes(__global const GpuMaterial* materials, lint id) {
  const luint first = las_uint(id) * (uint)(FH_MATERIAL_WORDS);
  MaterialLanes r;
  r.kd = material_rgb(materials, first, FH_MATERIAL_KD);
  r.ke = material_rgb(materials, first, FH_MATERIAL_KE);
  r.ks = material_rgb(materials, first, FH_MATERIAL_KS);
  r.ns = material_float(materials, first, FH_MATERIAL_NS);
  r.tf = material_rgb(materials, first, FH_MATERIAL_TF);
  r.ni = material_float(materials, first, FH_MATERIAL_NI);
  r.illum = gather_int((__global const int*)materials + FH_MATERIAL_ILLUM, first);
  r.texture = gather_int((__global const int*)materials + FH_MATERIAL_TEXTURE, first);
  return r;
}

FH_INLINE Bsdf material_bsdf(const MaterialLanes* m) {
  Bsdf b;
  const lvec3 ks = v3_clamp01(m->ks);
  b.tf = v3_clamp01(m->tf);
  b.eta = select((lfloat)(1.5f), m->ni, m->ni > 0.0f);
  b.alpha = fmax(roughness_from_ns(m->ns), 1e-3f);
  b.ks = ks;
  b.kd = m->kd;
  b.lobes = (lint)(FH_LOBE_DIFFUSE);
#if defined(FH_GLOSSY)
  const lmask has_specular = v3_any_positive(ks) && m->illum >= 2;
  const lmask mirror = (m->illum == 3 || m->illum == 5 || m->illum == 8) && m->ns >= FH_NS_MIRROR;
  b.lobes |= select((lint)(0), select((lint)(FH_LOBE_GLOSSY), (lint)(FH_LOBE_MIRROR), mirror), has_specular);
#endif
  const lfloat ws = select((lfloat)(0.0f), luminance3(ks), (b.lobes & ~FH_LOBE_DIFFUSE) != 0);
  const lfloat wd = luminance3(m->kd) * (1.0f - v3_max_component(ks));
  b.p_specular = select((lfloat)(0.0f), ws / (ws + wd), ws + wd > 0.0f);
#if defined(FH_GLASS)
  const lmask glass = m->illum == 4 || m->illum == 6 || m->illum == 7 || m->illum == 9;
  b.lobes = select(b.lobes, (lint)(FH_LOBE_GLASS), glass);
  b.kd = v3_select(glass, v3_splat(0.0f), b.kd);
  b.p_specular = select(b.p_specular, (lfloat)(1.0f), glass);
#endif
  return b;
}

FH_INLINE lmask bsdf_has_smooth_lobe(const Bsdf* b) { return has_lobe(b, FH_LOBE_DIFFUSE | FH_LOBE_GLOSSY); }

// Scenes are compiled with only the lobes they use (host/render/device_scene.cpp): FH_GLOSSY
// for glossy and mirror surfaces, FH_GLASS for dielectrics. Without them the branches
// below are dead code the compiler removes.
#if !defined(FH_GLOSSY)
#define FH_HAS_GLOSSY 0
#else
#define FH_HAS_GLOSSY 1
#endif

// ---- GGX (Trowbridge-Reitz), in the local frame where n = (0, 0, 1) ----

FH_INLINE lfloat ggx_d(lvec3 h, lfloat a) {
  const lfloat a2 = a * a, c2 = h.z * h.z;
  const lfloat t = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (M_PI_F * t * t);
}

FH_INLINE lfloat ggx_lambda(lvec3 w, lfloat a) {
  const lfloat c2 = w.z * w.z;
  const lfloat t2 = fmax(1.0f - c2, 0.0f) / c2;
  return select(0.5f * (sqrt(1.0f + a * a * t2) - 1.0f), (lfloat)(0.0f), c2 <= 0.0f);
}

FH_INLINE lfloat ggx_g1(lvec3 w, lfloat a) { return 1.0f / (1.0f + ggx_lambda(w, a)); }

// Height-correlated masking-shadowing.
FH_INLINE lfloat ggx_g2(lvec3 wo, lvec3 wi, lfloat a) {
  return 1.0f / (1.0f + ggx_lambda(wo, a) + ggx_lambda(wi, a));
}

FH_INLINE lvec3 fresnel_schlick(lvec3 f0, lfloat cos_theta) {
  const lfloat m = 1.0f - clamp(cos_theta, 0.0f, 1.0f);
  const lfloat m5 = m * m * m * m * m;
  return v3_add(f0, v3_scale(v3_sub(v3_splat(1.0f), f0), m5));
}

// A visible normal for wo (Heitz, "Sampling the GGX Distribution of Visible Normals", 2018).
FH_INLINE lvec3 ggx_sample_visible_normal(lvec3 wo, lfloat a, lfloat u1, lfloat u2) {
  const lvec3 vh = v3_normalize(v3(a * wo.x, a * wo.y, wo.z));
  const lfloat len2 = vh.x * vh.x + vh.y * vh.y;
  const lfloat inv_len = rsqrt(len2);
  const lvec3 t1 = v3_select(len2 > 0.0f, v3(-vh.y * inv_len, vh.x * inv_len, 0.0f), v3(1.0f, 0.0f, 0.0f));
  const lvec3 t2 = v3_cross(vh, t1);
  const lvec2 d = sample_concentric_disk(u1, u2);
  const lfloat s = 0.5f * (1.0f + vh.z);
  const lfloat p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - d.x * d.x)) + s * d.y;
  const lfloat p1 = d.x;
  const lvec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
                          v3_scale(vh, sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2))));
  return v3_normalize(v3(a * nh.x, a * nh.y, fmax(1e-6f, nh.z)));
}

// Density of wi from visible-normal sampling: D_v(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z).
FH_INLINE lfloat ggx_pdf(lvec3 wo, lvec3 wi, lfloat a) {
  const lvec3 h = v3_normalize(v3_add(wo, wi));
  return select(ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z), (lfloat)(0.0f), wo.z <= 0.0f || wi.z <= 0.0f);
}

FH_INLINE lvec3 ggx_eval(lvec3 wo, lvec3 wi, lvec3 f0, lfloat a) {
  const lvec3 h = v3_normalize(v3_add(wo, wi));
  const lvec3 f =
      v3_scale(fresnel_schlick(f0, v3_dot(wo, h)), ggx_d(h, a) * ggx_g2(wo, wi, a) / (4.0f * wo.z * wi.z));
  return v3_select(wo.z <= 0.0f || wi.z <= 0.0f, v3_splat(0.0f), f);
}

// ---- The material as a whole, in world space; n is the normal on the viewer's side ----

typedef struct {
  lvec3 t, b, n;
} Frame;

FH_INLINE Frame make_frame(lvec3 n) {
  Frame f;
  f.n = n;
  orthonormal_basis(n, &f.t, &f.b);
  return f;
}
FH_INLINE lvec3 to_local(const Frame* f, lvec3 v) { return v3(v3_dot(v, f->t), v3_dot(v, f->b), v3_dot(v, f->n)); }
FH_INLINE lvec3 to_world(const Frame* f, lvec3 v) {
  return v3_add(v3_add(v3_scale(f->t, v.x), v3_scale(f->b, v.y)), v3_scale(f->n, v.z));
}

// The share of the diffuse lobe: what the specular lobe's Fresnel term leaves at wo.
FH_INLINE lfloat diffuse_scale(const Bsdf* b, lfloat cos_o) {
  const lfloat left = 1.0f - v3_max_component(fresnel_schlick(b->ks, cos_o));
  return select((lfloat)(1.0f), left, has_lobe(b, FH_LOBE_GLOSSY | FH_LOBE_MIRROR));
}

// f(wo, wi) of the smooth (non-delta) lobes. Light from behind an opaque surface is not
// reflected.
FH_INLINE lvec3 bsdf_eval(const Bsdf* b, lvec3 n, lvec3 wo, lvec3 wi) {
  const lfloat cos_o = v3_dot(n, wo);
  lvec3 f = v3_select(has_lobe(b, FH_LOBE_DIFFUSE), v3_scale(b->kd, M_1_PI_F * diffuse_scale(b, cos_o)),
                      v3_splat(0.0f));
  const lmask glossy = has_lobe(b, FH_LOBE_GLOSSY);
  if (FH_HAS_GLOSSY && lanes_any(glossy)) {
    const Frame fr = make_frame(n);
    f = v3_add(f, v3_select(glossy, ggx_eval(to_local(&fr, wo), to_local(&fr, wi), b->ks, b->alpha), v3_splat(0.0f)));
  }
  return v3_select(v3_dot(n, wi) <= 0.0f || cos_o <= 0.0f, v3_splat(0.0f), f);
}

// The density bsdf_sample gives wi through the smooth lobes (delta lobes excluded).
FH_INLINE lfloat bsdf_pdf(const Bsdf* b, lvec3 n, lvec3 wo, lvec3 wi) {
  const lfloat cos_i = v3_dot(n, wi);
  lfloat pdf = select((lfloat)(0.0f), (1.0f - b->p_specular) * cos_i * M_1_PI_F, has_lobe(b, FH_LOBE_DIFFUSE));
  const lmask glossy = has_lobe(b, FH_LOBE_GLOSSY);
  if (FH_HAS_GLOSSY && lanes_any(glossy)) {
    const Frame fr = make_frame(n);
    pdf += select((lfloat)(0.0f), b->p_specular * ggx_pdf(to_local(&fr, wo), to_local(&fr, wi), b->alpha), glossy);
  }
  return select(pdf, (lfloat)(0.0f), cos_i <= 0.0f);
}

// Exact Fresnel reflectance of a smooth dielectric for cos_i > 0 and relative index eta
// (transmitted over incident side); 1 under total internal reflection. *cos_t is set.
FH_INLINE lfloat fresnel_dielectric(lfloat cos_i, lfloat eta, lfloat* cos_t) {
  const lfloat sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  const lmask total = sin2_t >= 1.0f;
  const lfloat ct = select(sqrt(1.0f - sin2_t), (lfloat)(0.0f), total);
  *cos_t = ct;
  const lfloat rs = (cos_i - eta * ct) / (cos_i + eta * ct);
  const lfloat rp = (eta * cos_i - ct) / (eta * cos_i + ct);
  return select(0.5f * (rs * rs + rp * rp), (lfloat)(1.0f), total);
}

// What bsdf_sample returns: the direction, its density for smooth lobes (-1: a delta lobe,
// which light sampling cannot reach; 0: no sample) and the throughput factor f cos / pdf.
typedef struct {
  lvec3 wi, weight;
  lfloat pdf;
} BsdfSample;

// Sets the lanes m of *r (0 where !ok: a direction through the surface the wrong way).
FH_INLINE void set_sample(BsdfSample* r, lmask m, lmask ok, lvec3 wi, lfloat pdf, lvec3 weight) {
  r->wi = v3_select(m, wi, r->wi);
  r->pdf = select(r->pdf, select((lfloat)(0.0f), pdf, ok), m);
  r->weight = v3_select(m, v3_select(ok, weight, v3_splat(0.0f)), r->weight);
}

// Samples wi given wo (toward the viewer), ng (the geometric normal, front side) and ns
// (the shading normal, on ng's side), with u0 choosing the lobe. Directions that a shading
// normal would send through the geometric surface the wrong way are rejected (factor 0):
// no light leaks.
FH_INLINE BsdfSample bsdf_sample(const Bsdf* b, lvec3 ng, lvec3 ns, lvec3 wo, lfloat u0, lfloat u1, lfloat u2) {
  const lmask front = v3_dot(ng, wo) >= 0.0f;
  const lvec3 g = v3_select(front, ng, v3_neg(ng));  // the geometric normal on the viewer's side
  const lvec3 n = v3_select(front, ns, v3_neg(ns));
  BsdfSample r;
  r.wi = r.weight = v3_splat(0.0f);
  r.pdf = (lfloat)(0.0f);
  lmask opaque = lanes_mask(true);
#if defined(FH_GLASS)
  const lmask glass = has_lobe(b, FH_LOBE_GLASS);
  opaque = !glass;
  if (lanes_any(glass)) {
    // Entering through the front, leaving through the back: the geometric side decides.
    const lfloat eta = select(1.0f / b->eta, b->eta, front);
    const lfloat cos_i = v3_dot(n, wo);
    lfloat cos_t;
    const lfloat f = fresnel_dielectric(cos_i, eta, &cos_t);
    const lmask reflect = u0 < f;
    const lvec3 reflected = v3_sub(v3_scale(n, 2.0f * cos_i), wo);
    const lvec3 refracted = v3_normalize(v3_add(v3_scale(wo, -1.0f / eta), v3_scale(n, cos_i / eta - cos_t)));
    const lvec3 wi = v3_select(reflect, reflected, refracted);
    const lfloat side = v3_dot(g, wi);
    const lmask ok = cos_i > 0.0f && select(side < 0.0f, side > 0.0f, reflect);
    // Radiance is compressed by (eta_i / eta_t)^2 crossing into the denser medium.
    const lvec3 weight = v3_select(reflect, v3_splat(1.0f), v3_scale(b->tf, 1.0f / (eta * eta)));
    set_sample(&r, glass, ok, wi, (lfloat)(-1.0f), weight);
  }
#endif
  const lfloat cos_o = v3_dot(n, wo);
  const lmask reflects = opaque && cos_o > 0.0f;
  lmask mirror = lanes_mask(false);
  if (FH_HAS_GLOSSY) {
    mirror = reflects && has_lobe(b, FH_LOBE_MIRROR) && u0 < b->p_specular;
    if (lanes_any(mirror)) {
      const lvec3 wi = v3_sub(v3_scale(n, 2.0f * cos_o), wo);
      set_sample(&r, mirror, v3_dot(g, wi) > 0.0f, wi, (lfloat)(-1.0f),
                 v3_scale(fresnel_schlick(b->ks, cos_o), 1.0f / b->p_specular));
    }
  }
  const lmask smooth = reflects && !mirror;
  if (!lanes_any(smooth)) return r;
  lvec3 wi = sample_cosine_hemisphere(n, u1, u2);
  const lmask glossy = smooth && has_lobe(b, FH_LOBE_GLOSSY) && u0 < b->p_specular;
  if (FH_HAS_GLOSSY && lanes_any(glossy)) {
    const Frame fr = make_frame(n);
    const lvec3 lo = to_local(&fr, wo);
    const lvec3 h = ggx_sample_visible_normal(lo, b->alpha, u1, u2);
    wi = v3_select(glossy, to_world(&fr, v3_sub(v3_scale(h, 2.0f * v3_dot(lo, h)), lo)), wi);
  }
  // (With a mirror lobe, this is its diffuse part, chosen with 1 - p_specular, which
  // bsdf_pdf includes.)
  const lfloat pdf = bsdf_pdf(b, n, wo, wi);
  const lvec3 f = bsdf_eval(b, n, wo, wi);
  const lvec3 weight = v3_select(pdf > 0.0f, v3_scale(f, v3_dot(n, wi) / pdf), v3_splat(0.0f));
  set_sample(&r, smooth, v3_dot(g, wi) > 0.0f, wi, pdf, weight);
  return r;
}

#endif

// BSDFs on the device: the sampling of every smooth lobe against its pdf (chi-square
// goodness of fit, as Mitsuba's chi2 test), energy (the estimated albedo never exceeds
// one), and white furnaces: a lossless object (white diffuse, perfect mirror, clear glass)
// inside a uniformly emitting, non-reflecting enclosure is invisible. And the model itself
// against independent values: the glossy lobe's value and directional albedo against the
// published formulas, glass's reflectance against Fresnel's equations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <OpenImageIO/imageio.h>

#include <array>

#include "device/kernel_sources.h"
#include "device/program.h"
#include "image/image_io.h"
#include "render/device_scene.h"
#include "render/render.h"
#include "scene_builder.h"
#include "test_support.h"

namespace fh {
namespace {

const char* kTestKernels = R"CL(
// FH_LANES samples per work-item (kernels/lanes.h), as the path tracer's strategies take them.
__kernel void sample_bsdf(__global const GpuMaterial* m, float4 wo, uint seed, __global float4* wi_pdf,
                          __global float4* weight) {
  const luint i = lane_positions(get_global_id(0) * FH_LANES);
  const MaterialLanes material = material_lanes(m, (lint)(0));
  const Bsdf b = material_bsdf(&material);
  const lvec3 n = v3_uniform((float3)(0.0f, 0.0f, 1.0f));
  const BsdfSample s = bsdf_sample(&b, n, n, v3_uniform(wo.xyz), random_float((luint)(seed), i, (luint)(0)),
                                   random_float((luint)(seed), i, (luint)(1)), random_float((luint)(seed), i, (luint)(2)));
  scatter_xyzw(wi_pdf, i, s.wi, s.pdf, lanes_mask(true));
  scatter_xyzw(weight, i, s.weight, (lfloat)(0.0f), lanes_mask(true));
}
// f(wo, wi), its red channel (the test materials are grey).
__kernel void eval_bsdf(__global const GpuMaterial* m, float4 wo, __global const float4* wi, __global float* f) {
  const luint i = lane_positions(get_global_id(0) * FH_LANES);
  const MaterialLanes material = material_lanes(m, (lint)(0));
  const Bsdf b = material_bsdf(&material);
  const lvec3 value = bsdf_eval(&b, v3_uniform((float3)(0.0f, 0.0f, 1.0f)), v3_uniform(wo.xyz), gather_xyz(wi, i));
  scatter_float(f, i, value.x, lanes_mask(true));
}
__kernel void pdf_bsdf(__global const GpuMaterial* m, float4 wo, __global const float4* wi, __global float* pdf) {
  const luint i = lane_positions(get_global_id(0) * FH_LANES);
  const MaterialLanes material = material_lanes(m, (lint)(0));
  const Bsdf b = material_bsdf(&material);
  scatter_float(pdf, i, bsdf_pdf(&b, v3_uniform((float3)(0.0f, 0.0f, 1.0f)), v3_uniform(wo.xyz), gather_xyz(wi, i)),
                lanes_mask(true));
}
)CL";

class BsdfOnDevice : public ::testing::Test {
 protected:
  DeviceContext dc{selectDevices(listDevices(), "").front()};
  // One path per work-item and eight in vector lanes: the two strategies' BSDF code.
  std::array<cl::Program, 2> programs = {program(1), program(8)};
  cl::Program program(int lanes) {
    return buildProgramFromSource(dc.context, dc.info.device,
                                  assembleKernelSources({"bsdf.h", "rng.h"}) + kTestKernels,
                                  "-DFH_GLOSSY -DFH_GLASS -DFH_LANES=" + std::to_string(lanes));
  }

  static gpu::GpuMaterial material(float kd, float ks, float ns, int illum, float ni = 1.5f, float tf = 1.f) {
    Scene s;
    Material m;
    m.kd = {kd, kd, kd};
    m.ks = {ks, ks, ks};
    m.ns = ns;
    m.illum = illum;
    m.ni = ni;
    m.tf = {tf, tf, tf};
    s.materials.push_back(m);
    return toGpuMaterials(s)[0];
  }

  struct Samples {
    std::vector<float> wiPdf, weight;
  };

  // n samples with both strategies' code, which must agree bit for bit.
  Samples sample(const gpu::GpuMaterial& m, const float3& wo, size_t n, unsigned seed = 1) {
    const Samples one = sample(programs[0], 1, m, wo, n, seed), eight = sample(programs[1], 8, m, wo, n, seed);
    EXPECT_EQ(0, std::memcmp(one.wiPdf.data(), eight.wiPdf.data(), n * 16)) << "one lane and eight disagree";
    EXPECT_EQ(0, std::memcmp(one.weight.data(), eight.weight.data(), n * 16)) << "one lane and eight disagree";
    return one;
  }
  Samples sample(const cl::Program& program, size_t lanes, const gpu::GpuMaterial& m, const float3& wo, size_t n,
                 unsigned seed) {
    EXPECT_EQ(0u, n % lanes);
    cl::Buffer mb = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, sizeof m, "material", &m);
    cl::Buffer a = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, n * 16, "wi");
    cl::Buffer b = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, n * 16, "weight");
    cl::Kernel k = createKernel(program, "sample_bsdf");
    const cl_float4 w{{wo[0], wo[1], wo[2], 0.f}};
    FH_CL(k.setArg(0, mb));
    FH_CL(k.setArg(1, w));
    FH_CL(k.setArg(2, seed));
    FH_CL(k.setArg(3, a));
    FH_CL(k.setArg(4, b));
    FH_CL(dc.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n / lanes)));
    Samples s{std::vector<float>(n * 4), std::vector<float>(n * 4)};
    FH_CL(dc.queue.enqueueReadBuffer(a, CL_TRUE, 0, n * 16, s.wiPdf.data()));
    FH_CL(dc.queue.enqueueReadBuffer(b, CL_TRUE, 0, n * 16, s.weight.data()));
    return s;
  }

  // The pdf of sampling each direction (x, y, z, unused) in `dirs`, and f's red channel there:
  // both strategies' code, which must agree bit for bit.
  std::vector<float> pdf(const gpu::GpuMaterial& m, const float3& wo, const std::vector<float>& dirs) {
    return perDirection("pdf_bsdf", m, wo, dirs);
  }
  std::vector<float> eval(const gpu::GpuMaterial& m, const float3& wo, const std::vector<float>& dirs) {
    return perDirection("eval_bsdf", m, wo, dirs);
  }
  std::vector<float> perDirection(const char* kernel, const gpu::GpuMaterial& m, const float3& wo,
                                  const std::vector<float>& dirs) {
    const std::vector<float> one = perDirection(programs[0], 1, kernel, m, wo, dirs),
                             eight = perDirection(programs[1], 8, kernel, m, wo, dirs);
    EXPECT_EQ(one, eight) << kernel << ": one lane and eight disagree";
    return one;
  }
  // `kernel`(material, wo, directions, one float out per direction).
  std::vector<float> perDirection(const cl::Program& program, size_t lanes, const char* kernel,
                                  const gpu::GpuMaterial& m, const float3& wo, const std::vector<float>& dirs) {
    const size_t n = dirs.size() / 4;
    EXPECT_EQ(0u, n % lanes);
    cl::Buffer mb = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, sizeof m, "material", &m);
    cl::Buffer d = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, n * 16, "dirs", dirs.data());
    cl::Buffer out = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, n * 4, kernel);
    cl::Kernel k = createKernel(program, kernel);
    const cl_float4 w{{wo[0], wo[1], wo[2], 0.f}};
    FH_CL(k.setArg(0, mb));
    FH_CL(k.setArg(1, w));
    FH_CL(k.setArg(2, d));
    FH_CL(k.setArg(3, out));
    FH_CL(dc.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n / lanes)));
    std::vector<float> values(n);
    FH_CL(dc.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * 4, values.data()));
    return values;
  }
};

float3 fromAngle(float thetaDeg) {
  const float t = thetaDeg * float(M_PI) / 180.f;
  return {std::sin(t), 0.f, std::cos(t)};
}

// Upper quantile of the chi-square distribution (Wilson-Hilferty), for p close to 1.
double chiSquareQuantile(double k, double z) {
  const double c = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - c + z * std::sqrt(c), 3.0);
}

// z for an upper tail probability q (Acklam-free: a few Newton steps on erfc).
double normalQuantile(double q) {
  double z = 3.0;
  for (int i = 0; i < 50; ++i) {
    const double tail = 0.5 * std::erfc(z / std::sqrt(2.0)), density = std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI);
    z += (tail - q) / density;
  }
  return z;
}

struct LobeCase {
  float kd, ks, ns;
  int illum;
  float thetaDeg;
};

const LobeCase kLobes[] = {
    {0.f, 1.f, 8.f, 2, 10.f},   {0.f, 1.f, 8.f, 2, 60.f},   {0.f, 1.f, 40.f, 2, 30.f},  {0.f, 1.f, 40.f, 2, 80.f},
    {0.f, 1.f, 200.f, 2, 45.f}, {0.5f, 0.3f, 20.f, 2, 40.f}, {0.8f, 0.f, 0.f, 1, 30.f}, {0.4f, 0.5f, 80.f, 2, 70.f},
};

TEST_F(BsdfOnDevice, SamplingMatchesThePdfChiSquare) {
  const int thetaBins = 16, phiBins = 32, sub = 6;
  const size_t n = 1 << 20;
  // Significance 0.01 over all cases (Sidak).
  const double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / (sizeof kLobes / sizeof kLobes[0]));
  for (const LobeCase& c : kLobes) {
    const auto m = material(c.kd, c.ks, c.ns, c.illum);
    const float3 wo = fromAngle(c.thetaDeg);
    const Samples s = sample(m, wo, n);
    // Histogram over (cos theta, phi) of the upper hemisphere: equal solid angle per cell.
    std::vector<double> observed(size_t(thetaBins * phiBins), 0.0);
    for (size_t i = 0; i < n; ++i) {
      const float* w = &s.wiPdf[4 * i];
      if (w[3] <= 0.f) continue;
      const double z = std::clamp(double(w[2]), 0.0, 1.0 - 1e-12), phi = std::atan2(w[1], w[0]) + M_PI;
      const int ti = std::min(thetaBins - 1, int(z * thetaBins)), pi = std::min(phiBins - 1, int(phi / (2 * M_PI) * phiBins));
      observed[size_t(ti * phiBins + pi)] += 1;
    }
    // Expected counts: the pdf integrated over each cell on a sub x sub grid (d omega = dz dphi).
    std::vector<float> dirs;
    for (int ti = 0; ti < thetaBins; ++ti)
      for (int pi = 0; pi < phiBins; ++pi)
        for (int a = 0; a < sub; ++a)
          for (int b = 0; b < sub; ++b) {
            const double z = (ti + (a + 0.5) / sub) / thetaBins, phi = (pi + (b + 0.5) / sub) / phiBins * 2 * M_PI - M_PI;
            const double r = std::sqrt(std::max(0.0, 1 - z * z));
            dirs.insert(dirs.end(), {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z), 0.f});
          }
    const std::vector<float> p = pdf(m, wo, dirs);
    const double cellArea = (1.0 / thetaBins) * (2 * M_PI / phiBins) / (sub * sub);
    std::vector<double> expected(observed.size(), 0.0);
    for (size_t i = 0; i < p.size(); ++i) expected[i / size_t(sub * sub)] += p[i] * cellArea * double(n);
    // Pool cells expecting fewer than 5 samples into one.
    double chi2 = 0, poolObs = 0, poolExp = 0;
    int dof = 0;
    for (size_t i = 0; i < observed.size(); ++i) {
      if (expected[i] < 5) {
        poolObs += observed[i];
        poolExp += expected[i];
        continue;
      }
      chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
      ++dof;
    }
    if (poolExp >= 5) {
      chi2 += (poolObs - poolExp) * (poolObs - poolExp) / poolExp;
      ++dof;
    }
    const double limit = chiSquareQuantile(dof - 1, normalQuantile(alpha));
    EXPECT_LT(chi2, limit) << "kd " << c.kd << " ks " << c.ks << " Ns " << c.ns << " theta " << c.thetaDeg
                           << ": chi2 " << chi2 << " with " << dof - 1 << " degrees of freedom";
  }
}

TEST_F(BsdfOnDevice, AlbedoNeverExceedsOne) {
  const size_t n = 1 << 18;
  for (float kd : {0.f, 0.5f, 1.f})
    for (float ks : {0.f, 0.3f, 1.f})
      for (float ns : {2.f, 40.f, 500.f, 5000.f})
        for (int illum : {2, 5})
          for (float theta : {0.f, 30.f, 60.f, 85.f}) {
            const auto m = material(kd, ks, ns, illum);
            const Samples s = sample(m, fromAngle(theta), n);
            double albedo = 0;
            for (size_t i = 0; i < n; ++i) albedo += s.weight[4 * i];
            albedo /= double(n);
            EXPECT_LE(albedo, 1.01) << "kd " << kd << " ks " << ks << " Ns " << ns << " illum " << illum << " theta "
                                    << theta;
          }
}

TEST_F(BsdfOnDevice, GlassReflectsAndRefractsByFresnel) {
  // At normal incidence on glass of index 1.5, F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
  const auto m = material(0.f, 0.f, 0.f, 7, 1.5f, 1.f);
  const size_t n = 1 << 18;
  const Samples s = sample(m, {0.f, 0.f, 1.f}, n);
  size_t reflected = 0;
  for (size_t i = 0; i < n; ++i) {
    reflected += s.wiPdf[4 * i + 2] > 0.f;
    ASSERT_LT(s.wiPdf[4 * i + 3], 0.f);  // a delta lobe
  }
  EXPECT_NEAR(double(reflected) / n, 0.04, 4 * std::sqrt(0.04 * 0.96 / n));
  // Leaving the glass beyond the critical angle (41.8 degrees): total internal reflection.
  const Samples inside = sample(m, {std::sin(0.9f), 0.f, -std::cos(0.9f)}, 4096);
  for (size_t i = 0; i < 4096; ++i) EXPECT_LT(inside.wiPdf[4 * i + 2], 0.f) << "not reflected back inside";
}

// ---- The model against independent values ----
// Sampling against the pdf cannot see a wrong model that is sampled consistently (a lost
// cosine, a wrong Fresnel exponent), so the lobes are also held to the published formulas,
// written out here again in double precision: GGX's D and the height-correlated Smith
// masking-shadowing (Walter et al. 2007, Heitz 2014), Schlick's Fresnel (1994) with F0 = Ks,
// the diffuse lobe scaled by what Fresnel leaves at wo, roughness alpha = sqrt(2 / (Ns + 2)).
namespace model {

double ggxD(double cosH, double a) {
  const double t = cosH * cosH * (a * a - 1) + 1;
  return a * a / (M_PI * t * t);
}
double smithLambda(double cosW, double a) {
  const double tan2 = (1 - cosW * cosW) / (cosW * cosW);
  return (std::sqrt(1 + a * a * tan2) - 1) / 2;
}
double schlick(double f0, double cosD) { return f0 + (1 - f0) * std::pow(1 - cosD, 5); }
double alphaFromNs(double ns) { return std::max(std::sqrt(2 / (ns + 2)), 1e-3); }

// f(wo, wi) of illum 2 (diffuse Kd + GGX glossy Ks), one channel, n = +z.
double glossyBrdf(double kd, double ks, double ns, const double wo[3], const double wi[3]) {
  if (wo[2] <= 0 || wi[2] <= 0) return 0;
  double h[3] = {wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]};
  const double len = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  for (double& c : h) c /= len;
  const double a = alphaFromNs(ns), cosD = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
  const double g2 = 1 / (1 + smithLambda(wo[2], a) + smithLambda(wi[2], a));
  const double specular = schlick(ks, cosD) * ggxD(h[2], a) * g2 / (4 * wo[2] * wi[2]);
  const double diffuse = kd / M_PI * (ks > 0 ? 1 - schlick(ks, wo[2]) : 1);
  return diffuse + specular;
}

// The directional albedo: the integral of f cos over the hemisphere, by the midpoint rule in
// (theta, phi); wo lies in the xz-plane, so the half phi in [0, pi] is doubled.
double glossyAlbedo(double kd, double ks, double ns, double thetaO) {
  const int nt = 2048, np = 512;
  const double wo[3] = {std::sin(thetaO), 0, std::cos(thetaO)};
  double sum = 0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) / nt * M_PI / 2;
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) / np * M_PI;
      const double wi[3] = {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
      sum += glossyBrdf(kd, ks, ns, wo, wi) * std::cos(t) * std::sin(t);
    }
  }
  return 2 * sum * (M_PI / 2 / nt) * (M_PI / np);
}

// Unpolarized reflectance of a smooth dielectric, in Fresnel's sine and tangent form (a
// different route from the kernel's); 1 beyond the critical angle. eta: transmitted over
// incident index.
double dielectricReflectance(double thetaI, double eta) {
  if (thetaI == 0) return std::pow((eta - 1) / (eta + 1), 2);
  const double sinT = std::sin(thetaI) / eta;
  if (sinT >= 1) return 1;
  const double thetaT = std::asin(sinT);
  const double rs = std::pow(std::sin(thetaI - thetaT) / std::sin(thetaI + thetaT), 2);
  const double rp = std::pow(std::tan(thetaI - thetaT) / std::tan(thetaI + thetaT), 2);
  return (rs + rp) / 2;
}

}  // namespace model

struct GlossyCase {
  float kd, ks, ns;
};
const GlossyCase kGlossy[] = {{0.f, 1.f, 10.f}, {0.f, 0.04f, 10.f}, {0.f, 0.5f, 100.f},
                              {0.5f, 0.04f, 50.f}, {0.3f, 0.9f, 1000.f}};

TEST_F(BsdfOnDevice, GlossyEvaluationMatchesThePublishedFormulas) {
  std::vector<float> dirs;
  std::vector<std::array<double, 3>> wis;
  for (int t = 1; t <= 30; ++t)
    for (int p = 0; p < 24; ++p) {
      const double theta = t * 2.95 * M_PI / 180, phi = p * 15.0 * M_PI / 180;
      wis.push_back({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
      dirs.insert(dirs.end(), {float(wis.back()[0]), float(wis.back()[1]), float(wis.back()[2]), 0.f});
    }
  for (const GlossyCase& c : kGlossy)
    for (float thetaO : {0.f, 30.f, 60.f, 80.f, 88.f}) {
      const float3 wo = fromAngle(thetaO);
      const double wod[3] = {wo[0], wo[1], wo[2]};
      const std::vector<float> f = eval(material(c.kd, c.ks, c.ns, 2), wo, dirs);
      int wrong = 0;
      for (size_t i = 0; i < wis.size(); ++i) {
        double wi[3] = {dirs[4 * i], dirs[4 * i + 1], dirs[4 * i + 2]};
        const double expected = model::glossyBrdf(c.kd, c.ks, c.ns, wod, wi);
        if (std::fabs(f[i] - expected) > 2e-3 * expected + 1e-5 && wrong++ < 3)
          ADD_FAILURE() << "kd " << c.kd << " ks " << c.ks << " Ns " << c.ns << " theta_o " << thetaO << " wi ("
                        << wi[0] << ", " << wi[1] << ", " << wi[2] << "): f " << f[i] << ", the formulas give "
                        << expected;
      }
    }
}

TEST_F(BsdfOnDevice, GlossyAlbedoMatchesQuadratureOfTheFormulas) {
  // The sampled estimate E[f cos / pdf] at wo against the integral of the formulas: what a
  // glossy surface under uniform light of radiance 1 reflects toward wo.
  const size_t n = 1 << 20;
  for (const GlossyCase& c : kGlossy)
    for (float thetaO : {0.f, 45.f, 80.f}) {
      const Samples s = sample(material(c.kd, c.ks, c.ns, 2), fromAngle(thetaO), n);
      double sum = 0, sumSq = 0;
      for (size_t i = 0; i < n; ++i) {
        sum += s.weight[4 * i];
        sumSq += double(s.weight[4 * i]) * s.weight[4 * i];
      }
      const double mean = sum / n, stdErr = std::sqrt(std::max(sumSq / n - mean * mean, 0.0) / n);
      const double exact = model::glossyAlbedo(c.kd, c.ks, c.ns, thetaO * M_PI / 180);
      EXPECT_NEAR(mean, exact, 5 * stdErr + 2e-3 * exact)
          << "kd " << c.kd << " ks " << c.ks << " Ns " << c.ns << " theta_o " << thetaO;
    }
}

TEST_F(BsdfOnDevice, DielectricReflectsAsFresnelsEquationsSay) {
  const size_t n = 1 << 18;
  for (float ni : {1.33f, 1.5f, 2.4f}) {
    const auto glass = material(0.f, 0.f, 0.f, 7, ni, 1.f);
    for (float thetaDeg : {0.f, 30.f, 60.f, 75.f, 85.f}) {
      const Samples s = sample(glass, fromAngle(thetaDeg), n);
      size_t reflected = 0;
      for (size_t i = 0; i < n; ++i) reflected += s.wiPdf[4 * i + 2] > 0.f;
      const double r = model::dielectricReflectance(thetaDeg * M_PI / 180, ni);
      EXPECT_NEAR(double(reflected) / n, r, 4.5 * std::sqrt(r * (1 - r) / n) + 1e-4)
          << "entering index " << ni << " at " << thetaDeg << " degrees";
    }
    // From inside, below the critical angle: the relative index is 1 / Ni.
    const float3 inside = {std::sin(0.3f), 0.f, -std::cos(0.3f)};
    const Samples s = sample(glass, inside, n);
    size_t reflected = 0;
    for (size_t i = 0; i < n; ++i) reflected += s.wiPdf[4 * i + 2] < 0.f;
    const double r = model::dielectricReflectance(0.3, 1.0 / ni);
    EXPECT_NEAR(double(reflected) / n, r, 4.5 * std::sqrt(r * (1 - r) / n) + 1e-4) << "leaving index " << ni;
  }
}

// ---- White furnaces ----

Scene furnaceWith(const Material& object) {
  test::SceneBuilder b;
  b.closedBoxInside({-2, -2, -2}, {2, 2, 2}, b.material(0.f, 1.f));  // emits 1, reflects nothing
  Scene s = b.build();
  // An icosahedron-ish closed object: an octahedron, faces wound outward.
  s.materials.push_back(object);
  const int m = int(s.materials.size() - 1);
  const float3 v[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& f : faces) {
    const unsigned base = unsigned(s.vertexCount());
    for (int k = 0; k < 3; ++k) s.positions.insert(s.positions.end(), v[f[k]].begin(), v[f[k]].end());
    s.indices.insert(s.indices.end(), {base, base + 1, base + 2});
    s.triangleMaterial.push_back(m);
  }
  return s;
}

TEST(WhiteFurnace, LosslessObjectsVanishInAUniformEnclosure) {
  DeviceContext dc(selectDevices(listDevices(), "").front());
  Material white, mirror, glass;
  white.kd = {1, 1, 1};
  white.illum = 1;
  mirror.kd = {0, 0, 0};
  mirror.ks = {1, 1, 1};
  mirror.ns = 10000;
  mirror.illum = 5;
  glass.kd = {0, 0, 0};
  glass.illum = 7;
  glass.ni = 1.5f;
  glass.tf = {1, 1, 1};
  Camera camera;
  camera.eye = {0.3f, 0.4f, 1.9f};
  camera.target = {0, 0, 0};
  camera.fovYDeg = 50.f;
  for (const auto& [name, object] : {std::pair{"white diffuse", white}, {"mirror", mirror}, {"glass", glass}}) {
    const Scene scene = furnaceWith(object);
    const Bvh bvh = buildBvh(scene);
    for (Method method : {Method::PT, Method::NEE, Method::MIS}) {
      RenderSettings s = test::renderSettings();
      s.width = s.height = 16;
      s.spp = 64;
      s.method = method;
      const RenderResult r = render(dc, scene, bvh, camera, s);
      const Film& film = r.film;
      EXPECT_EQ(r.stats.nonfinite, 0u);
      double mean = 0, var = 0;
      for (size_t p = 0; p < 256; ++p) {
        mean += film.sum[4 * p] / film.count(p) / 256;
        var += film.varianceOfMean(p)[0] / (256.0 * 256.0);
      }
      // Lossless: exactly 1, up to noise (a mirror or glass object in a uniform field has
      // zero variance except through numerics).
      EXPECT_LT(std::fabs(mean - 1.0), 4 * std::sqrt(var) + 2e-3) << name << " " << methodName(method);
    }
  }
}

// A textured plane under a constant environment: L = rho(uv) * L_env, with rho read from
// an 8-bit sRGB image (decoded to linear), and v pointing up the image.
// texture_lookup against the analytic bilinear interpolation of a periodic ramp: texel
// column x holds red = f(x), row y green = f(y), so between texel centres red and green are
// linear in u and v, and across the seam at u, v = 0 and 1 they wrap from the last texel to
// the first. A nearest-texel lookup (a planted bug once: it passed the test below, which reads texels
// far from any boundary) is off by up to half a step. Both texel formats: linear floats
// (f(x) = x), and 8-bit sRGB codes decoded through the table (f(x) = the linear value of
// code 50 x), which a lookup that skipped or misindexed the table would miss.
TEST(Textures, LookupIsBilinearAndWrapsAtTheSeams) {
  const char* kernel = R"CL(
__kernel void lookup(__global const uint* texels, __global const uint4* info, __global const float2* uv,
                     __global float4* out) {
  const uint i = get_global_id(0);
  const lvec3 c = texture_lookup(texels, info, 0, lv2(uv[i].x, uv[i].y), v3_splat(-1.0f));
  out[i] = (float4)(c.x, c.y, c.z, 0.0f);
}
)CL";
  DeviceContext dc(selectDevices(listDevices(), "").front());
  const cl::Program program =
      buildProgramFromSource(dc.context, dc.info.device, assembleKernelSources({"surface.h"}) + kernel, "");
  const int w = 5, h = 4;
  const std::vector<uint32_t> table = srgbDecodeTable();
  auto decoded = [&](int code) {
    float v;
    std::memcpy(&v, &table[size_t(code)], 4);
    return double(v);
  };
  std::vector<float> uv;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j) uv.insert(uv.end(), {-0.02f + 1.04f * float(i) / 40.f, -0.02f + 1.04f * float(j) / 40.f});
  const size_t n = uv.size() / 2;
  auto buffer = [&](size_t bytes, const void* data) {
    return allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, bytes, "test", data);
  };
  for (const auto format : {TextureData::kLinearFloat, TextureData::kSrgb8}) {
    const bool srgb8 = format == TextureData::kSrgb8;
    auto value = [&](int k) { return srgb8 ? decoded(50 * k) : double(k); };
    std::vector<uint32_t> words = table;  // the table always leads the buffer
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (srgb8) {
          words.push_back(uint32_t(50 * x) | uint32_t(50 * y) << 8);
          continue;
        }
        for (float c : {float(x), float(y), 0.f, 1.f}) {
          uint32_t bits;
          std::memcpy(&bits, &c, 4);
          words.push_back(bits);
        }
      }
    const std::vector<uint32_t> info = {uint32_t(table.size()), uint32_t(w), uint32_t(h), uint32_t(format)};
    cl::Buffer texelBuffer = buffer(words.size() * 4, words.data()), infoBuffer = buffer(16, info.data()),
               uvBuffer = buffer(uv.size() * 4, uv.data()), out = buffer(n * 16, nullptr);
    cl::Kernel k = createKernel(program, "lookup");
    setKernelArgs(k, texelBuffer, infoBuffer, uvBuffer, out);
    FH_CL(dc.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n)));
    std::vector<float> result(n * 4);
    FH_CL(dc.queue.enqueueReadBuffer(out, CL_TRUE, 0, result.size() * 4, result.data()));
    // The periodic ramp f(k mod size), interpolated linearly at texel coordinate x (texel
    // centres at integers).
    auto ramp = [&](double x, int size) {
      const double f = std::floor(x);
      const int k0 = ((int(f) % size) + size) % size, k1 = (k0 + 1) % size;
      return value(k0) * (1.0 - (x - f)) + value(k1) * (x - f);
    };
    for (size_t i = 0; i < n; ++i) {
      const double u = uv[2 * i] - std::floor(uv[2 * i]), v = uv[2 * i + 1] - std::floor(uv[2 * i + 1]);
      const double red = ramp(u * w - 0.5, w), green = ramp((1.0 - v) * h - 0.5, h);  // rows run down the image
      EXPECT_NEAR(result[4 * i], red, 1e-4) << (srgb8 ? "sRGB8 " : "float ") << "u " << uv[2 * i];
      EXPECT_NEAR(result[4 * i + 1], green, 1e-4) << (srgb8 ? "sRGB8 " : "float ") << "v " << uv[2 * i + 1];
    }
  }
}

TEST(Textures, AlbedoComesFromTheImageDecodedToLinear) {
  const std::string dir = test::tempDir("tex");
  // 8x8 texels: the top half (v > 0.5) one colour, the bottom half another.
  const unsigned char top[3] = {200, 60, 20}, bottom[3] = {40, 120, 220};
  std::vector<unsigned char> pixels;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const unsigned char* c = y < 4 ? top : bottom;
      pixels.insert(pixels.end(), c, c + 3);
    }
  {
    auto out = OIIO::ImageOutput::create(dir + "/t.png");
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(dir + "/t.png", OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
  }
  test::SceneBuilder b;
  const int m = b.material(0.5f);
  b.quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, m);  // faces +y
  Scene scene = b.build();
  scene.materials[size_t(m)].kdTexture = 0;
  scene.textures.push_back({dir + "/t.png"});
  // Corners in quad order: (-1,-1) (-1,1) (1,1) (1,-1) in (x, z); v runs toward -z.
  const float uv[4][2] = {{0.05f, 0.95f}, {0.05f, 0.05f}, {0.95f, 0.05f}, {0.95f, 0.95f}};
  for (int tri : {0, 1})
    for (int k : tri == 0 ? std::array<int, 3>{0, 1, 2} : std::array<int, 3>{0, 2, 3})
      scene.cornerUVs.insert(scene.cornerUVs.end(), {uv[k][0], uv[k][1]});
  Camera camera;
  camera.eye = {0, 3, 0.001f};
  camera.target = {0, 0, 0};
  camera.up = {0, 0, -1};  // image up = -z = toward v = 1
  camera.fovYDeg = 20.f;
  DeviceContext dc(selectDevices(listDevices(), "").front());
  const Bvh bvh = buildBvh(scene);
  RenderSettings s = test::renderSettings();
  s.width = s.height = 8;
  s.spp = 16;
  s.method = Method::PT;
  s.env = {1.f, 1.f, 1.f};
  const Image img = render(dc, scene, bvh, camera, s).film.image();
  // The camera sees only the plane; rows 0-2 lie in the texture's top half, 5-7 in the bottom.
  for (int y : {0, 1, 2, 5, 6, 7})
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) {
        const float expected = srgbToLinear((y < 4 ? top : bottom)[c] / 255.f);
        EXPECT_NEAR(img.rgb[size_t(3 * (y * 8 + x) + c)], expected, 0.02f + 0.05f * expected)
            << "pixel " << x << "," << y << " channel " << c;
      }
}

}  // namespace
}  // namespace fh

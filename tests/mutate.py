#!/usr/bin/python3
"""How strong is the suite? Plants one-line bugs, one at a time, and runs the tests that should catch each.

  tests/mutate.py [--build build] [--only NAME ...] [--all-tests]   plant, rebuild, test, restore
  tests/mutate.py --list                                            each mutation and the bug it models
  tests/mutate.py --check [--root DIR]                              every original text occurs once

Each mutation replaces one exact piece of source text, which must occur exactly once in its
file, rebuilds, and runs the CTest regex of the tests that should catch it (the whole suite
with --all-tests: minutes per mutation). It prints one line per mutation: caught, MISSED (a
gap in the suite), does not build, no tests (its regex matches none) or stale (its text is
no longer in the source exactly once), then "N of M mutations caught". The source is
restored after each, also on Ctrl-C, and the build rebuilt at the end. --check (CTest
Mutations.EveryTextOccursOnce) keeps the texts from going stale unnoticed.
"""
import argparse, collections, os, re, signal, subprocess, sys

Mutation = collections.namedtuple("Mutation", "name path original mutated models tests")

# (name, file, original text, mutated text, the bug it models, CTest regex of the tests that should catch it).
# Regexes are anchored (^) so the strategy reruns (scalar/..., simd8/..., megakernel/...) are left out.
MUTATIONS = [Mutation(*m) for m in [
    # Geometry, texture, filter and sampler.
    ("crack", "kernels/intersect.h",
     "const int8 outside = (min8(min8(u, e.v), e.w) < zero) & (max8(max8(u, e.v), e.w) > zero);",
     "const int8 outside = ((min8(min8(u, e.v), e.w) < zero) | (u == zero)) & (max8(max8(u, e.v), e.w) > zero);",
     "a one-sided crack in the watertight test (a hit on one edge counts as outside)", r"^Watertight\."),
    ("nearest-texel", "kernels/surface.h", "const lfloat tx = x - fx, ty = y - fy;",
     "const lfloat tx = round(x - fx), ty = round(y - fy);", "nearest instead of bilinear texture lookup",
     r"^Textures\."),
    ("texture-v-down", "kernels/surface.h", "y = (1.0f - (v - floor(v))) * h - 0.5f;", "y = (v - floor(v)) * h - 0.5f;",
     "texture v running down the image (OBJ's runs up)", r"^Textures\."),
    ("shading-normal-unturned", "kernels/surface.h",
     "return v3_select(!(v3_dot(n, n) > 0.0f), ng, v3_select(v3_dot(ns, ng) >= 0.0f, ns, v3_neg(ns)));",
     "return v3_select(!(v3_dot(n, n) > 0.0f), ng, ns);",
     "shading normals not turned to the geometric normal's side",
     r"^PathTracer/EveryMethod\.VertexNormalsAgainstTheWinding"),
    ("camera-aspect", "host/scene/camera.cpp", "p.right[k] = f.right[size_t(k)] * f.tanHalfFovY * f.aspect;",
     "p.right[k] = f.right[size_t(k)] * f.tanHalfFovY;", "the device camera without the aspect ratio (wide images squeezed)",
     r"^AovRender\."),
    ("gaussian-as-box", "host/render/pixel_filter.cpp",
     "return std::max(0.0, std::exp(-x * x / (2 * sigma * sigma)) - std::exp(-radius * radius / (2 * sigma * sigma)));",
     "return 1.0 + 0.0 * sigma;", "the Gaussian filter sampled as a box", r"^PixelFilters\."),
    ("no-owen-values", "kernels/sampler.h",
     "return u32_to_unit_float(reverse_bits_u32(owen_hash(digits_reversed, seed)));",
     "return u32_to_unit_float(reverse_bits_u32(digits_reversed + 0u * seed));",
     "sample values not Owen-scrambled (index shuffle kept)", r"^PixelSamplerOnDevice\."),
    ("world-scale-kept", "host/scene/scene_loader.cpp", "  return std::ldexp(1.f, exponent);\n}",
     "  return 1.f + 0.f * std::ldexp(1.f, exponent);\n}",
     "a scene far from unit size rendered in its units (only its positions scaled)",
     r"^(SceneLoader\.ScenesFarFromUnitSize|RenderCli\.ASceneInAnyUnits)"),
    ("camera-up-unscaled", "host/scene/camera.cpp",
     "f.right = normalize(cross(f.forward, atUnitScale(c.up[0], c.up[1], c.up[2])));",
     "f.right = normalize(cross(f.forward, c.up));", "the camera's basis from an up vector whose square overflows",
     r"^Camera\.TheFrameIsTheSameInAnyUnits"),
    ("depth-in-world-units", "host/render/film.cpp", "out[6] += quantized(in[7]) * depthUnit;",
     "out[6] += quantized(in[7]);", "the depth layer in the renderer's units, not the scene file's",
     r"^RenderCli\.ASceneInAnyUnits"),
    ("radiance-unit-dropped", "host/render/film.cpp",
     "const double v = quantized(samples[4 * i + c]) * (c == 3 ? 1.0 : radianceUnit);",
     "const double v = quantized(samples[4 * i + c]);",
     "a scene lit far from unit brightness left in the renderer's unit (its image off by a power of two)",
     r"^RenderCli\.EmittersOfAnyBrightness"),
    ("radiance-unit-never", "host/render/radiance_unit.cpp", "exponentTowardOne(brightest(scene, s), kRadianceBand)",
     "exponentTowardOne(brightest(scene, s), 1000)",
     "emission never scaled to the unit (dim scenes below the film's quantum, bright splats capped)",
     r"^RenderCli\.EmittersOfAnyBrightness"),
    ("texels-unmended", "host/render/device_scene.cpp", "    mendReflectance(rgb, t);\n", "",
     "float texture texels taken as they are (NaN, negative or above-one reflectance)",
     r"^RenderCli\.TexelsNoReflectanceCanBe"),
    # Materials.
    ("ggx-pdf", "kernels/bsdf.h", "return select(ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z),",
     "return select(1.1f * ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z),", "a 10 % GGX pdf error",
     r"^BsdfOnDevice\."),
    ("ggx-no-cos-wi", "kernels/bsdf.h", "/ (4.0f * wo.z * wi.z)", "/ (4.0f * wo.z)",
     "GGX evaluated without wi.z in the microfacet denominator", r"^BsdfOnDevice\.Glossy"),
    ("schlick-power-4", "kernels/bsdf.h", "const lfloat m5 = m * m * m * m * m;", "const lfloat m5 = m * m * m * m;",
     "Schlick's Fresnel with exponent 4 instead of 5", r"^BsdfOnDevice\.Glossy"),
    ("ns-roughness-no-sqrt", "kernels/bsdf.h", "return sqrt(2.0f / (fmax(ns, 0.0f) + 2.0f));",
     "return 2.0f / (fmax(ns, 0.0f) + 2.0f);", "Ns mapped to alpha squared, not alpha = sqrt(2 / (Ns + 2))",
     r"^BsdfOnDevice\.Glossy"),
    ("fresnel-p-as-s", "kernels/bsdf.h", "const lfloat rp = (eta * cos_i - ct) / (eta * cos_i + ct);",
     "const lfloat rp = (cos_i - eta * ct) / (cos_i + eta * ct);",
     "the dielectric's p-polarised reflectance written like the s one", r"^BsdfOnDevice\.(Dielectric|Glass)"),
    # Light transport.
    ("mis-half", "kernels/lights.h", "return select((lfloat)(0.0f), a2 / (a2 + b2), a2 + b2 > 0.0f);",
     "return select((lfloat)(0.0f), (lfloat)(0.5f), a2 + b2 > 0.0f);", "a constant one-half MIS weight",
     r"^PathTracer\.MethodsAgreeOnTheCornellBox|^WhereMethodsFail\.TinyBrightLight"),
    ("light-pdf", "kernels/lights.h", "l->pick / l->seen.solid_angle,", "2.0f * l->pick / l->seen.solid_angle,",
     "a doubled light pdf (solid-angle sampling)",
     r"^PathTracer/EveryMethod\.ClosedFurnaceBox|^WhereMethodsFail\.(ExtremeScales|DegenerateTriangles)"),
    ("light-pick-density-by-power", "host/render/device_scene.cpp",
     "table.pdfArea[size_t(table.triangle[i])] = float(pick / l.area);",
     "table.pdfArea[size_t(table.triangle[i])] = float(trianglesPick * power[i] / trianglePower / l.area);",
     "lights picked by the defensive mixture, but their density still the power share's",
     r"^LightPicking\."),
    ("light-pick-own-number", "kernels/shadow_connect_stage.h",
     "pick_light_within(scene->light_cdf, params.light_count, params.env_pick, u.y);",
     "pick_light_within(scene->light_cdf, params.light_count, params.env_pick,\n"
     "                                                        sample_1d(sampler, dim + FH_DIM_BSDF_LOBE));",
     "the light picked by a number of its own: its points a random subset of the light sample's",
     r"^LightPicking\.OneSample"),
    ("light-narrow-share-ignored", "kernels/lights.h", "p.narrow = !(hi - lo >= FH_NARROW_SHARE);",
     "p.narrow = lanes_mask(false);", "every light's point placed by the stretched pick, however narrow its share",
     r"^LightPicking\.OneSample"),
    ("lt-refraction-as-radiance", "kernels/light_paths.h",
     "weight = v3_select(scaled, v3_scale(weight, eta * eta), weight);", "weight = v3_select(scaled, weight, weight);", "light paths scaled by radiance's 1/eta^2 through a refraction",
     r"^Methods/LightTracing\."),
    ("lt-no-shading-correction", "kernels/light_paths.h",
     "const lfloat correction = fabs(v3_dot(n, w_in)) * cos_g_next / cos_g_in;",
     "const lfloat correction = cos_g_next;", "light paths' bounces weighed by the geometric cosine",
     r"^Methods/LightTracing\."),
    ("lt-cos4-importance", "kernels/light_paths.h", "cos_theta * cos_theta * cos_theta);",
     "cos_theta * cos_theta * cos_theta * cos_theta);", "the pinhole's importance with cos^4 (a film-plane density)",
     r"^Methods/LightTracing\."),
    ("lt-adjoint-f-forward", "kernels/light_paths.h", "bsdf_eval(&v->bsdf, n, s->wi, w_in), correction / s->pdf)",
     "bsdf_eval(&v->bsdf, n, w_in, s->wi), correction / s->pdf)",
     "a light path's bounce evaluating the BSDF as a camera path does (the diffuse share at the light's side)",
     r"^Methods/LightTracing\."),
    ("lanes-hits-crossed", "kernels/lane_rays.h", "const lmask here = lanes == (luint)(l);",
     "const lmask here = lanes == (luint)(0);", "every lane of eight paths given lane 0's hit",
     r"^PathTracer\.EveryStrategyRendersTheSameBits$"),
    ("bdpt-lanes-share-slots", "kernels/bdpt.cl",
     "__global float4* s = stored + LANE(own, l) + FH_BDPT_VERTEX_WORDS * LANE(count, l);",
     "__global float4* s = stored + LANE(own, 0) + FH_BDPT_VERTEX_WORDS * LANE(count, l);",
     "eight bdpt light subpaths storing their vertices in the first lane's slots",
     r"^PathTracer\.EveryStrategyRendersTheSameBits$"),
    ("bdpt-lanes-read-past-launch", "kernels/bdpt.cl",
     "const luint slot = select(first_slot, own + FH_BDPT_VERTEX_WORDS * k, joining);",
     "const luint slot = own + FH_BDPT_VERTEX_WORDS * k;",
     "lanes past the launch's paths reading light vertices beyond the buffer",
     r"^Runs/UnderOclgrind\.RunsWithoutReports/bdpt_lanes "),
    ("vcm-lanes-same-candidate", "kernels/bdpt.cl", "const luint e = lane_positions(first);",
     "const luint e = (luint)(first);", "every lane of a merge taking the bucket's same light vertex",
     r"^PathTracer\.EveryStrategyRendersTheSameBits$"),
    ("typical-relmse-is-the-worst-set", "host/render/film.cpp",
     "return means.size() % 2 ? means[mid] : (means[mid - 1] + means[mid]) / 2;", "return means.back();",
     "the typical noise estimate taken from the pixel set with the most error, a firefly's",
     r"^NoiseEstimate\."),
    ("lt-splat-carry-lost", "kernels/light_paths.h", "if (before + low < before) atomic_inc(sum + 1);",
     "if (before + low < before) atomic_inc(sum);", "a splat's carry out of the low word dropped",
     r"^Methods/LightTracing\.|^TwoDevices\.LightTracing"),
    ("bdpt-vc-no-reverse-pdf", "kernels/bdpt.cl",
     "const lfloat vc = mis2(cos_out / pdf) * (*d_vc * mis2(pdf_rev) + *d_vcm + merge_here * m.vm);",
     "const lfloat vc = mis2(cos_out / pdf) * (*d_vc + *d_vcm + merge_here * m.vm);",
     "bdpt's recursive weights without the reverse density (the weights no longer sum to one)",
     r"^Methods/LightTracing\..*/bdpt|^Bidirectional\."),
    ("bdpt-emission-density-no-cosine", "kernels/bdpt.cl", "mis2(pdf_area * cos_g * M_1_PI_F) * c.d_vc;",
     "mis2(pdf_area * M_1_PI_F) * c.d_vc;",
     "bdpt weighing emission found by the camera against light paths without the emitter's cosine",
     r"^Methods/LightTracing\..*/bdpt|^Bidirectional\."),
    ("vcm-merge-without-pi", "host/render/light_tracer.cpp",
     "const cl_float4 merge{{radius, float(1.0 / eta), maskBits, 0.f}};",
     "const cl_float4 merge{{radius, float(M_PI / eta), maskBits, 0.f}};",
     "vcm's density estimate over r^2 N, not pi r^2 N", r"^Bidirectional\.Merging"),
    ("vcm-merges-everywhere", "kernels/bdpt.cl", "  return m.vm > 0.0f ? after_delta : lanes_mask(false);",
     "  return m.vm > 0.0f ? lanes_mask(true) : lanes_mask(false);",
     "vcm's camera side merging where its light side counts no merge (the weights no longer sum to one)",
     r"^Methods/LightTracing\..*/vcm|^Bidirectional\."),
    ("bdpt-env-disk-per-area", "kernels/bdpt.cl", "l.alpha = v3_scale(e.radiance, disk_area / pdf_w);",
     "l.alpha = v3_scale(e.radiance, 1.0f / pdf_w);",
     "bdpt's light paths from the environment map without the disk's area in their weight",
     r"^EnvironmentMap\.Bidirectional|^Environment/EveryMethod\..*/bdpt"),
    ("auto-error-only", "host/render/method_choice.h", "double cost() const { return relMse * seconds; }",
     "double cost() const { return relMse; }", "--method auto comparing the pilots' errors without their times",
     r"^MethodChoice"),
    ("auto-no-margin", "host/render/method_choice.cpp", "best->cost() < kChoiceMargin * mis->cost()",
     "best->cost() < mis->cost()", "--method auto leaving mis for any method a pilot puts ahead by luck",
     r"^MethodChoice"),
    ("auto-pilot-no-floor", "host/render/method_choice.cpp",
     "p.minPasses = std::max(kNoiseMinPasses, unsigned(std::ceil(kLeastPilotSamples / (double(p.width) * p.height))));",
     "p.minPasses = kNoiseMinPasses;",
     "--method auto's pilots in a short render too small to estimate a heavy-tailed method's noise",
     r"^MethodChoice"),
    ("auto-pilots-always", "host/render/method_choice.h",
     "bool piloted() const { return !alone() && leastPilotSeconds <= kMostPilotShare * renderSeconds; }",
     "bool piloted() const { return !alone(); }",
     "--method auto piloting a render too short for its pilots to pay", r"^MethodChoice"),
    ("auto-cross-check-ignored", "host/render/method_choice.cpp",
     "(!judged || t.crossCost() < kChoiceMargin * mis->crossCost())",
     "(!judged || true)",
     "--method auto choosing by a pilot's own error estimate alone, the other pilots' ignored",
     r"^MethodChoice\.(AnotherMethodMustBeatMisInBoth|APilotMissing)"),
    ("auto-pilots-a-lone-method", "host/render/method_choice.h",
     "bool alone() const { return candidates.size() < 2; }",
     "bool alone() const { return false; }",
     "--method auto timing and piloting mis where it is the only method the settings allow",
     r"^MethodChoiceCli\.WhereMis"),
    ("least-passes-ignored", "host/render/pass_pool.cpp",
     "const bool fewest = next_ - firstNew_ < std::max(1u, settings_.minPasses);",
     "const bool fewest = next_ == firstNew_;", "a time budget cutting a render short of its least passes",
     r"^MethodChoice\.APilot"),
    ("roulette", "kernels/shade_stage.h", "v3_scale(beta, 1.0f / survive)", "v3_scale(beta, 1.0f)",
     "Russian roulette without dividing by survival",
     r"^WhereMethodsFail\.AlbedoNearOneRoulette|^PathTracer/EveryMethod\.ClosedFurnaceBox"),
    ("back-emission", "kernels/shade_stage.h", "const lmask emits = hits && sh->cos_front > 0.0f &&",
     "const lmask emits = hits && sh->cos_front != 0.0f &&", "emission from the back side too",
     r"^WhereMethodsFail\.NoLightsIsBlack|^PathTracer/EveryMethod\.VertexNormalsAgainstTheWinding"),
    ("env-pdf-no-sin", "kernels/environment.h", "density / (FH_ENV_SOLID_ANGLE_PER_UV * sin_theta)",
     "density / FH_ENV_SOLID_ANGLE_PER_UV",
     "environment-map sampling's pdf without the sin(theta) of the lat-long map",
     r"^Environment/EveryMethod\.|^EnvironmentMap\.(BesideATriangleLight|AConstantMap)"),
    # The film and what carries it: adaptive rounds, chunks, checkpoints, MPI ranks.
    ("adaptive-no-offsets", "host/render/pass_rounds.cpp", "offsets.push_back(uint32_t(counts[p]) - begin);",
     "offsets.push_back(0u * (uint32_t(counts[p]) - begin));",
     "adaptive rounds without per-pixel sequence offsets (pass k takes point k: scattered blocks)",
     r"^AdaptiveCli\.EachPixelsSamplesAreTheFirstPoints"),
    ("film-unquantized", "host/render/film.cpp",
     "double quantized(float v) { return std::nearbyint(double(v) / kFilmQuantum) * kFilmQuantum; }",
     "double quantized(float v) { return double(v); }",
     "samples not rounded to the 2^-24 grid (sums depend on how passes are split)", r"^Chunks\."),
    ("checkpoint-no-checksum", "host/render/checkpoint.cpp", "if (checksum(data, n) != h.checksums[section])",
     "if (false && checksum(data, n) != h.checksums[section])",
     "film files read without checking their sections' checksums",
     r"^Checkpoint\.(AFlippedByte|MergeAndResumeRefuse)"),
    ("mpi-reduce-max", "host/distributed/mpi_render.cpp", "MPI_DOUBLE, MPI_SUM, 0,", "MPI_DOUBLE, MPI_MAX, 0,",
     "ranks' films merged by maximum instead of sum", r"^Mpi\.EveryRankCountGivesTheImageOfOneProcess"),
    ("mpi-layers-unmerged", "host/distributed/mpi_render.cpp", "{&film.sum, &film.sumSq, &film.aovSum, &film.oddSum}",
     "{&film.sum, &film.sumSq, &film.oddSum}", "the ranks' first-surface layers left out of the merge",
     r"^Mpi\.EveryRankCountGivesTheImageOfOneProcess"),
]]

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def problem(m, root):
    """What is wrong with mutation m's texts in the source at root, or None."""
    try:
        with open(os.path.join(root, m.path)) as f:
            count = f.read().count(m.original)
    except OSError as e:
        return "cannot read %s (%s)" % (m.path, e.strerror)
    if m.mutated == m.original:
        return "its mutated text is the original"
    if count != 1:
        return "stale: its original text is not in %s" % m.path if count == 0 else \
            "ambiguous: its original text is %d times in %s" % (count, m.path)
    return None


def check(root):
    names = [m.name for m in MUTATIONS]
    bad = [(n, "the name is used %d times" % names.count(n)) for n in sorted(set(names)) if names.count(n) > 1]
    bad += [(m.name, p) for m in MUTATIONS for p in [problem(m, root)] if p]
    for name, why in bad:
        print("%s (%s): %s" % (name, dict((m.name, m.path) for m in MUTATIONS)[name], why))
    if bad:
        print("%d of %d mutations need their text updated (%s)" % (len(bad), len(MUTATIONS), root))
        return 1
    print("%d mutations: each original text occurs exactly once in its file (%s)" % (len(MUTATIONS), root))
    return 0


def run(cmd, cwd):
    return subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


class Planted:
    """Mutation m planted in its file while in the with block; the file is restored on leaving it,
    whatever ends the block (an error, Ctrl-C, SIGTERM), and a copy of the original kept in the build
    tree until then names the file to mend should the process be killed outright."""

    def __init__(self, m, root, build):
        self.m, self.full = m, os.path.join(root, m.path)
        self.backup = os.path.join(build, "mutate-backup", m.path.replace("/", "__"))

    def __enter__(self):
        with open(self.full) as f:
            self.text = f.read()
        self.planted = self.text.replace(self.m.original, self.m.mutated)
        os.makedirs(os.path.dirname(self.backup), exist_ok=True)
        with open(self.backup, "w") as f:
            f.write(self.text)
        with open(self.full, "w") as f:
            f.write(self.planted)
        return self

    def __exit__(self, *exc):
        signals = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
        old = signal.pthread_sigmask(signal.SIG_BLOCK, signals)  # a second Ctrl-C must not cut the restore short
        try:
            with open(self.full) as f:
                now = f.read()
            if now == self.planted:
                restored = self.text
            elif now.count(self.m.mutated) == 1:  # someone else edited the file meanwhile: undo only the mutation
                restored = now.replace(self.m.mutated, self.m.original)
                print("note: %s changed while %s was planted; only the mutation was undone" % (self.m.path, self.m.name))
            else:
                print("ERROR: %s changed while %s was planted, and the mutation is not in it once: replace\n  %s\nby\n  %s"
                      "\nby hand (the original file is in %s)" % (self.m.path, self.m.name, self.m.mutated,
                                                                  self.m.original, self.backup), file=sys.stderr)
                return False
            with open(self.full, "w") as f:
                f.write(restored)
            os.remove(self.backup)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        return False


def failed_tests(ctest_output):
    """The names CTest lists under "The following tests FAILED:"."""
    names, listing = [], False
    for line in ctest_output.splitlines():
        if line.startswith("The following tests FAILED"):
            listing = True
        elif listing:
            found = re.match(r"\s*\d+ - (.*?) \(", line)
            if not found:
                break
            names.append(found.group(1).split("  # ")[0])
    return names


def try_mutation(m, root, opts):
    """Plants m, rebuilds and runs its tests: (status, detail)."""
    why = problem(m, root)
    if why:
        return "stale", why
    listed = run(["ctest", "--test-dir", opts.build, "-N", "-R", m.tests], root).stdout
    if not re.search(r"Total Tests: [1-9]", listed):
        return "no tests", "its regex %s matches no test in %s" % (m.tests, opts.build)
    with Planted(m, root, opts.build):
        build = run(["cmake", "--build", opts.build, "-j%d" % opts.jobs], root)
        if build.returncode != 0:
            return "does not build", ""
        cmd = ["ctest", "--test-dir", opts.build, "-j%d" % opts.jobs, "--no-tests=error"]
        tests = run(cmd + ([] if opts.all_tests else ["-R", m.tests]), root)
    if tests.returncode == 0:
        return "MISSED", m.tests
    failed = failed_tests(tests.stdout)
    return "caught", ("by %s" % failed[0] + (" and %d more" % (len(failed) - 1) if len(failed) > 1 else "")) \
        if failed else ""


def raise_interrupt(signum, frame):
    raise KeyboardInterrupt


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build", help="the build tree (default: build)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="these mutations only")
    parser.add_argument("--all-tests", action="store_true", help="run the whole suite against each mutation")
    parser.add_argument("-j", "--jobs", type=int, default=2, help="build and test jobs (default: 2)")
    parser.add_argument("--list", action="store_true", help="list the mutations and what they model")
    parser.add_argument("--check", action="store_true", help="check every original text occurs once; run nothing")
    parser.add_argument("--root", default=ROOT, help="the source tree (default: this script's)")
    opts = parser.parse_args()
    root = os.path.abspath(opts.root)
    if opts.check:
        sys.exit(check(root))
    if opts.list:
        for m in MUTATIONS:
            print("%-24s %-32s %s" % (m.name, m.path, m.models))
        return
    unknown = [n for n in opts.only or [] if n not in {m.name for m in MUTATIONS}]
    if unknown:
        parser.error("no mutation named %s (see --list)" % ", ".join(unknown))
    opts.build = os.path.join(root, opts.build)
    leftover = os.path.join(opts.build, "mutate-backup")
    if os.path.isdir(leftover) and os.listdir(leftover):
        sys.exit("mutate.py: %s holds originals of files a killed run left mutated (names with / as __): "
                 "mend those files, then remove the directory" % leftover)
    for k, v in {"POCL_CACHE_DIR": "pocl-cache", "FREDHOLM_CACHE_DIR": "program-cache"}.items():
        os.environ.setdefault(k, os.path.join(opts.build, v))
    signal.signal(signal.SIGTERM, raise_interrupt)
    signal.signal(signal.SIGHUP, raise_interrupt)
    results = []
    try:
        for m in MUTATIONS:
            if opts.only and m.name not in opts.only:
                continue
            status, detail = try_mutation(m, root, opts)
            results.append(status)
            print("%-24s %-15s %s%s" % (m.name, status, m.models, " (%s)" % detail if detail else ""), flush=True)
    except KeyboardInterrupt:
        print("interrupted: the source is restored", flush=True)
    finally:
        print("rebuilding %s without mutations" % opts.build, flush=True)
        try:
            rebuilt = run(["cmake", "--build", opts.build, "-j%d" % opts.jobs], root).returncode == 0
        except KeyboardInterrupt:
            rebuilt = False
        if not rebuilt:
            print("the build may still hold the last mutation: run cmake --build %s" % opts.build)
    caught = results.count("caught")
    print("%d of %d mutations caught" % (caught, len(results)))
    sys.exit(0 if results and caught == len(results) else 1)


if __name__ == "__main__":
    main()

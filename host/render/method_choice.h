// --method auto: a short pilot render with each method that can render the scene, each
// one's error per unit of time measured (relMSE estimated from its two replicates, times its
// seconds: at equal time, the image's relMSE is that cost over the time), then the render with
// the cheapest. mis is the default: another method must beat it clearly, by more than a pilot's
// estimate can be off, because mis is never far from the better of pt and nee, and a method
// chosen on a pilot's luck could be far from it.
#pragma once
#include <atomic>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "device/devices.h"
#include "image/image_io.h"
#include "render/settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

// Another method is chosen over mis only where its pilot cost is below this share of mis's.
constexpr double kChoiceMargin = 0.8;
// The pilot: each method renders the same image, the render's scaled down (its aspect kept),
// for the same time, kPilotShare of the render's expected time between them (a short mis
// render gives mis's samples per second; the render's time is its --time, or its samples at
// that speed). Equal times, not equal samples: a slow method's pilot costs no more than a
// fast one's, and the cost compared is error per unit of time either way. The image's size
// is set by mis's samples in its time: from kMinPilotSide to kMaxPilotSide pixels on its
// longer side at kMinPilotSpp passes, then passes up to kMaxPilotSpp. A slower method renders
// fewer passes in its time, but never fewer samples than the smallest pilot's (kMinPilotSpp
// passes of kMinPilotSide²: below that, estimates of a heavy-tailed method's noise came out
// several times off) nor fewer passes than kNoiseMinPasses (its noise estimate's halves).
// A longer pilot sees more of a heavy-tailed method's rare samples: the longer the render,
// the surer its choice.
constexpr double kPilotShare = 0.05;
constexpr int kMinPilotSide = 32, kMaxPilotSide = 128;
constexpr int kMinPilotSpp = 64, kMaxPilotSpp = 1024;
constexpr double kLeastPilotSamples = double(kMinPilotSide) * kMinPilotSide * kMinPilotSpp;
// Pilots that would take more than this share of the render leave it no chance to come
// within 1.25x of the best method's error (1 - 1 / 1.25), however right their choice: where
// even the smallest would, none run and the render is mis's.
constexpr double kMostPilotShare = 0.2;

struct MethodTrial {
  Method method = Method::MIS;
  double seconds = 0.0;  // the pilot's render time (set-up and compiling excluded)
  // The pilot image's relMSE, estimated from its own two replicates: the typical estimate
  // (Film::typicalRelMse), which one firefly in a short pilot does not decide.
  double relMse = 0.0;
  unsigned passes = 0;   // the pilot's passes (samples per pixel)
  double crossRelMse = 0.0;  // the same as the other pilots see it (judgePilots; 0: not judged)
  double meanRelMse = 0.0;   // the own estimate's plain mean (Film::estimatedRelMse), for --stats
  double cost() const { return relMse * seconds; }
  double crossCost() const { return crossRelMse * seconds; }
};

struct MethodChoice {
  Method method = Method::MIS;
  // The methods that can render the scene with these settings (methodsFor). Where mis is the
  // only one, nothing is timed or piloted.
  std::vector<Method> candidates;
  bool alone() const { return candidates.size() < 2; }
  int pilotWidth = 0, pilotHeight = 0;
  double pilotSeconds = 0.0;  // each method's pilot time budget
  double seconds = 0.0;       // the whole pilot, set-up included
  // The render's expected seconds at mis's speed, and what the smallest pilots would take of
  // them at that speed (more than kMostPilotShare: no pilots, `trials` empty).
  double renderSeconds = 0.0, leastPilotSeconds = 0.0;
  bool piloted() const { return !alone() && leastPilotSeconds <= kMostPilotShare * renderSeconds; }
  std::vector<MethodTrial> trials;
  // "mis 8.4e-03 / 9.0e-03 (90 spp), lt 5.5e-03 / 6.1e-03 (41 spp), ...": each trial's cost
  // by its own estimate and by the other pilots', and its passes.
  std::string describeCosts() const;
};

// The methods worth a pilot with these settings: mis always; not nee, which mis contains
// (its light samples, at about its time a sample: nee's error at equal time has been
// 0.86-1.02 of mis's wherever measured, never past kChoiceMargin, so its pilot could win
// only by luck); pt only where nothing can be sampled as a light (no emitting triangle, no
// --env-map: mis is then pt with shadow rays that find nothing); lt where the scene has
// emitting triangles and nothing it cannot do is asked (an environment, adaptive passes,
// first-surface layers); bdpt where light subpaths have somewhere to start (emitting
// triangles or --env-map) and neither adaptive passes nor first-surface layers are asked,
// vcm in its place where the scene has glass or mirrors (render/light_tracer.h
// mergesLightVertices: there vcm also samples the diffuse vertex seen through a delta lobe,
// at about bdpt's time a sample; elsewhere it is bdpt).
std::vector<Method> methodsFor(const Scene& scene, const RenderSettings& s);

// Of the trials, the method the render should use: the cheapest where it beats mis's cost by
// kChoiceMargin, and where the trials were judged by each other (crossRelMse), beats mis's
// cost by the margin in that judgement too; else mis. The two estimates fail apart: a pilot's
// own misses what neither of its halves found, and on a pilot image whose lights are a pixel
// wide it runs high for every method alike, where the others' still ranks them. The own
// estimate is the typical one: its plain mean, in a pilot of a few dozen samples a pixel,
// was decided by one firefly often enough to keep a method at a third of mis's error from
// being chosen (bench/history/method_choice.md).
Method cheapestMethod(const std::vector<MethodTrial>& trials);

// Each pilot's relMSE as the other pilots see it. The pilots are independent unbiased
// renders of one image (each with a seed of its own), so the mean squared relative
// difference of two, d_ij, is about e_i + e_j, the sum of their errors; from three or more,
// each e_i follows from the pairs by least squares (for three, (d_ij + d_ik - d_jk) / 2: the
// "three-cornered hat" of clock comparisons, Grubbs 1948), and from two, what d leaves once
// the other's own estimate is taken off. A pilot's own estimate, from its two halves, cannot
// see what neither half found: a heavy-tailed method's rare bright paths, missing from its
// image, are in the others'. Differences are relative to the pilots' mean image averaged
// over 3x3 pixels, with relMSE's epsilon. `own`: each pilot's own estimate; images of one
// size.
std::vector<double> crossRelMse(const std::vector<Image>& pilots, const std::vector<double>& own);

// Sets each trial's crossRelMse from the pilots' images, in the trials' order.
void judgePilots(std::vector<MethodTrial>& trials, const std::vector<Image>& images);

// The pilot's longer side for `samples` of mis's samples per method: the side at which they
// make kMinPilotSpp passes, within the bounds above and no larger than the image's. (The
// passes are each pilot's own, as many as its time allows.)
int pilotSide(double samples, int imageSide);

// Runs the pilots on the render's devices and chooses. `stop` (as RenderLinks::stop) ends
// the pilot early; the choice is then mis.
MethodChoice chooseMethod(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                          const Camera& camera, const RenderSettings& s, const std::atomic<int>* stop);

}  // namespace fh

// The unit radiance is rendered in. The film keeps sums of whole quanta of 2^-24 (exact
// merges, render/film.h) and light paths' splats are capped at 2^24: at unit brightness
// that spans any image, but a scene lit by emitters of 1e-5 (every sample a fraction of a
// quantum) renders black, and one lit by the sun's 1e9 has its caustics capped. So a scene
// whose brightest emitter lies outside [2^-10, 2^11) has its emission scaled into [1, 2) by
// a power of two before it renders, and the film scales each pass back as it adds it: the
// same arithmetic as for a scene of unit brightness (every estimator is linear in the
// emission), exact, and the film in the scene's own units.
#pragma once
#include "render/settings.h"
#include "scene/scene.h"

namespace fh {

// Scales the scene's emitters (Ke, the lights' power), --env and --env-map into the unit
// and returns it: the radiance the renderer's 1 stands for, a power of two (1 for scenes
// within the band, which render as they always did).
double toRadianceUnit(Scene& scene, RenderSettings& settings);

}  // namespace fh

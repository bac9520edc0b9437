// Flag values that are more than a number: each parser throws fh::Error naming its flag.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "render/render_aov.h"
#include "render/settings.h"

namespace fh {

Method parseMethod(const std::string& name);      // --method pt|nee|mis
Strategy parseStrategy(const std::string& name);  // --strategy auto|scalar|simd8
PixelFilter parseFilter(const std::string& name);  // --filter box|gaussian|blackman-harris
Aov parseAov(const std::string& name);             // --aov albedo|normal|depth
// --aovs LIST: comma-separated layers of albedo, normal, depth, variance, spp; each once,
// in the order given.
std::vector<std::string> parseAovLayers(const std::string& list);
// Whether a layer comes from shade's first-surface records (RenderSettings::surfaceAovs).
bool isSurfaceAov(const std::string& layer);
// "x,y,z": three finite numbers (--eye, --target, --up, --env).
std::array<float, 3> parseVec3Flag(const std::string& flag, const std::string& text);

}  // namespace fh

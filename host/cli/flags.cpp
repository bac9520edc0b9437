// Parsing flag values.
#include "cli/flags.h"

#include <algorithm>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "base/error.h"
#include "base/vec.h"

namespace fh {

Method parseMethod(const std::string& name) {
  if (name == "pt") return Method::PT;
  if (name == "nee") return Method::NEE;
  if (name == "mis") return Method::MIS;
  if (name == "lt") return Method::LT;
  if (name == "bdpt") return Method::BDPT;
  if (name == "vcm") return Method::VCM;
  throw Error("--method '" + name + "': unknown method (use pt, nee, mis, lt, bdpt, vcm or auto)");
}

Strategy parseStrategy(const std::string& name) {
  if (name == "auto") return Strategy::Auto;
  if (name == "scalar") return Strategy::Scalar;
  if (name == "simd8") return Strategy::Simd8;
  if (name == "megakernel") return Strategy::Megakernel;
  if (name == "megakernel8") return Strategy::Megakernel8;
  throw Error("--strategy '" + name + "': unknown strategy (use auto, scalar, simd8, megakernel or megakernel8)");
}

PixelFilter parseFilter(const std::string& name) {
  if (name == "box") return PixelFilter::Box;
  if (name == "gaussian") return PixelFilter::Gaussian;
  if (name == "blackman-harris") return PixelFilter::BlackmanHarris;
  throw Error("--filter '" + name + "': unknown filter (use box, gaussian or blackman-harris)");
}

Aov parseAov(const std::string& name) {
  if (name == "albedo") return Aov::Albedo;
  if (name == "normal") return Aov::Normal;
  if (name == "depth") return Aov::Depth;
  throw Error("--aov '" + name + "': unknown output (use albedo, normal or depth)");
}

std::vector<std::string> parseAovLayers(const std::string& list) {
  static const char* const known[] = {"albedo", "normal", "depth", "variance", "spp"};
  std::vector<std::string> layers;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (std::find(std::begin(known), std::end(known), item) == std::end(known))
      throw Error("--aovs '" + list + "': unknown layer '" + item + "' (use albedo, normal, depth, variance, spp)");
    if (std::find(layers.begin(), layers.end(), item) != layers.end())
      throw Error("--aovs '" + list + "': layer '" + item + "' is named twice");
    layers.push_back(item);
  }
  if (layers.empty() || list.back() == ',') throw Error("--aovs '" + list + "': expected a comma-separated list of layers");
  return layers;
}

bool isSurfaceAov(const std::string& layer) { return layer == "albedo" || layer == "normal" || layer == "depth"; }

std::array<float, 3> parseVec3Flag(const std::string& flag, const std::string& text) {
  std::array<float, 3> v{};
  std::istringstream in(text);
  std::string item;
  int n = 0;
  while (std::getline(in, item, ',')) {
    if (n == 3) throw Error(flag + " '" + text + "': expected three comma-separated numbers");
    try {
      size_t used = 0;
      v[size_t(n)] = std::stof(item, &used);
      if (item.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument(item);
    } catch (const std::out_of_range&) {
      throw Error(flag + " '" + text + "': '" + item + "' is beyond the float range");
    } catch (const std::exception&) {
      throw Error(flag + " '" + text + "': '" + item + "' is not a number");
    }
    ++n;
  }
  if (n != 3) throw Error(flag + " '" + text + "': expected three comma-separated numbers");
  if (!isFinite(v)) throw Error(flag + " '" + text + "': values must be finite");
  return v;
}

}  // namespace fh

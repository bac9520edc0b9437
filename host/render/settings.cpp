// The names of methods and filters, as the command line spells them.
#include "render/settings.h"

#include "base/error.h"

namespace fh {

const char* methodName(Method m) {
  switch (m) {
    case Method::PT: return "pt";
    case Method::NEE: return "nee";
    case Method::MIS: return "mis";
    case Method::LT: return "lt";
    case Method::BDPT: return "bdpt";
    case Method::VCM: return "vcm";
  }
  return "?";
}

const char* strategyName(Strategy s) {
  switch (s) {
    case Strategy::Auto: return "auto";
    case Strategy::Scalar: return "scalar";
    case Strategy::Simd8: return "simd8";
    case Strategy::Megakernel: return "megakernel";
    case Strategy::Megakernel8: return "megakernel8";
  }
  return "?";
}

const char* filterName(PixelFilter f) {
  return f == PixelFilter::Box ? "box" : f == PixelFilter::Gaussian ? "gaussian" : "blackman-harris";
}

}  // namespace fh

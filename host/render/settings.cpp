// The names of methods and filters, as the command line spells them.
#include "render/settings.h"

#include "base/error.h"

namespace fh {

const char* methodName(Method m) { return m == Method::PT ? "pt" : m == Method::NEE ? "nee" : "mis"; }

const char* strategyName(Strategy s) {
  return s == Strategy::Auto ? "auto" : s == Strategy::Scalar ? "scalar" : "simd8";
}

const char* filterName(PixelFilter f) {
  return f == PixelFilter::Box ? "box" : f == PixelFilter::Gaussian ? "gaussian" : "blackman-harris";
}

}  // namespace fh

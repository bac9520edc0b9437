// Open Image Denoise through dlopen: the library, its functions and one CPU device.
#include "image/denoiser.h"

#include <dlfcn.h>

#include <cstdlib>

#include "base/error.h"

#ifndef FREDHOLM_OIDN_LIBRARY
#define FREDHOLM_OIDN_LIBRARY "/opt/oidn/lib/libOpenImageDenoise.so.2"
#endif

namespace fh {
namespace {

constexpr const char* kHowToGetIt =
    "--denoise needs Intel Open Image Denoise 2 (libOpenImageDenoise.so.2), and none was found: ./setup.sh build "
    "installs it (from PyPI's pyoidn wheel into " FREDHOLM_OIDN_LIBRARY "), or set FREDHOLM_OIDN to the library";

// $FREDHOLM_OIDN alone when set (a path the user chose is not second-guessed); else the
// system's search path, then setup.sh's place.
void* openLibrary() {
  if (const char* chosen = std::getenv("FREDHOLM_OIDN"); chosen && *chosen) {
    if (void* library = dlopen(chosen, RTLD_NOW | RTLD_LOCAL)) return library;
    throw Error(std::string("FREDHOLM_OIDN '") + chosen + "': cannot load it (" + dlerror() + "); " + kHowToGetIt);
  }
  for (const char* name : {"libOpenImageDenoise.so.2", FREDHOLM_OIDN_LIBRARY})
    if (void* library = dlopen(name, RTLD_NOW | RTLD_LOCAL)) return library;
  throw Error(kHowToGetIt);
}

// The error OIDN reports for `device` (and clears), or "" for none.
std::string deviceError(const oidn::Api& api, oidn::Device device) {
  const char* message = nullptr;
  if (api.getDeviceError(device, &message) == oidn::kErrorNone) return "";
  return message && *message ? message : "an unknown error";
}

}  // namespace

std::unique_ptr<Denoiser> Denoiser::load() {
  void* library = openLibrary();
  oidn::Api api{};
#define FH_OIDN_LOAD(member, symbol)                                                               \
  api.member = reinterpret_cast<decltype(api.member)>(dlsym(library, symbol));                     \
  if (!api.member) {                                                                               \
    dlclose(library);                                                                              \
    throw Error(std::string("--denoise: the Open Image Denoise library found lacks ") + symbol +   \
                " (version 2 is needed); " + kHowToGetIt);                                         \
  }
  FH_OIDN_FUNCTIONS(FH_OIDN_LOAD)
#undef FH_OIDN_LOAD
  return std::unique_ptr<Denoiser>(new Denoiser(library, api));
}

Denoiser::Denoiser(void* library, const oidn::Api& api) : library_(library), api_(api) {
  device_ = api_.newDevice(oidn::kDeviceTypeCpu);
  if (device_) api_.commitDevice(device_);
  const std::string error = device_ ? deviceError(api_, device_) : "no CPU device";
  if (!error.empty()) {
    if (device_) api_.releaseDevice(device_);
    dlclose(library_);
    throw Error("--denoise: Open Image Denoise cannot start: " + error);
  }
}

Denoiser::~Denoiser() {
  api_.releaseDevice(device_);
  dlclose(library_);
}

std::string Denoiser::describe() const {
  const int v = api_.getDeviceInt(device_, "version");
  return "Intel Open Image Denoise " + std::to_string(v / 10000) + "." + std::to_string(v / 100 % 100) + "." +
         std::to_string(v % 100) + ", RT filter, hdr, albedo and normal";
}

Image Denoiser::denoise(const Image& image, const std::vector<float>& albedo, const std::vector<float>& normal) const {
  const size_t w = size_t(image.width), h = size_t(image.height), floats = 3 * w * h;
  if (image.rgb.size() != floats || albedo.size() != floats || normal.size() != floats)
    throw Error("--denoise: the image and its albedo and normal layers differ in size");
  Image out;
  out.width = image.width;
  out.height = image.height;
  out.rgb.assign(floats, 0.f);
  // OIDN reads the inputs only; its API takes them as non-const pointers.
  auto shared = [&](oidn::Filter f, const char* name, const std::vector<float>& v) {
    api_.setSharedFilterImage(f, name, const_cast<float*>(v.data()), oidn::kFormatFloat3, w, h, 0, 0, 0);
  };
  oidn::Filter filter = api_.newFilter(device_, "RT");
  if (filter) {
    shared(filter, "color", image.rgb);
    shared(filter, "albedo", albedo);
    shared(filter, "normal", normal);
    api_.setSharedFilterImage(filter, "output", out.rgb.data(), oidn::kFormatFloat3, w, h, 0, 0, 0);
    api_.setFilterBool(filter, "hdr", true);
    api_.commitFilter(filter);
    api_.executeFilter(filter);
    api_.releaseFilter(filter);
  }
  const std::string error = deviceError(api_, device_);
  if (!error.empty()) throw Error("--denoise: Open Image Denoise failed: " + error);
  return out;
}

}  // namespace fh

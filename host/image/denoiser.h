// --denoise: Intel Open Image Denoise's RT filter on the radiance, guided by the film's
// first-surface albedo and normal. OIDN is not packaged in Debian: the library is loaded at
// run time (setup.sh installs it from PyPI's pyoidn wheel), so fredholm builds and runs
// without it and only --denoise needs it.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "image/oidn_api.h"

namespace fh {

class Denoiser {
 public:
  // Loads OIDN: $FREDHOLM_OIDN (the library's path) if set, else libOpenImageDenoise.so.2 from
  // the system's library path, else where setup.sh installs it. Throws fh::Error, one line
  // saying how to get it, where none loads.
  static std::unique_ptr<Denoiser> load();
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // The denoised radiance (no layers): high dynamic range input, albedo and normal as
  // auxiliary images (3 floats per pixel each, in the image's pixel order). Throws fh::Error
  // with OIDN's message if it fails.
  Image denoise(const Image& image, const std::vector<float>& albedo, const std::vector<float>& normal) const;
  // For the metadata: "Intel Open Image Denoise 2.5.1, RT filter, hdr, albedo and normal".
  std::string describe() const;

 private:
  Denoiser(void* library, const oidn::Api& api);
  void* library_;
  oidn::Api api_;
  oidn::Device device_ = nullptr;
};

}  // namespace fh

// Images through OpenImageIO: writing the film, and the one way fredholm opens an image it
// reads. The format follows the extension: .exr as linear float with the render settings in
// its metadata, .hdr/.pfm as float, .png/.jpg as sRGB 8-bit. Row 0 is the top of the image.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#ifdef FREDHOLM_HAVE_OIIO
#include <OpenImageIO/oiioversion.h>
OIIO_NAMESPACE_BEGIN
class ImageInput;
OIIO_NAMESPACE_END
#endif

namespace fh {

// Further channels written beside the image's R, G, B (EXR only), named `name.channel`
// as compositors and denoisers expect them (albedo.R, normal.X, depth.Z).
struct ImageLayer {
  std::string name;
  std::vector<std::string> channels;
  std::vector<float> values;  // channels.size() per pixel, in the image's pixel order
};

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear radiance, 3 floats per pixel, row-major from the top-left
  std::vector<ImageLayer> layers;
};

enum class ImageEncoding { LinearFloat, Srgb8 };

// The encoding the path's extension asks for; throws fh::Error naming the flag for an
// unknown extension.
ImageEncoding checkImageExtension(const std::string& path, const std::string& flag);

// The path's extension in lower case (".exr"), which picks the format.
std::string extensionOf(const std::string& path);

// The first of base.ext, base-1.ext, base-2.ext ... that does not exist (numberedName).
std::string firstFreeName(const std::string& path);

// Writes the image whole or not at all (base/atomic_file.h); returns the path written.
std::string writeImage(const std::string& path, const Image& image, const std::map<std::string, std::string>& metadata);

// The most pixels fredholm reads of one image (an 8K image has 2^25): a header claiming more
// is refused before anything is allocated for it.
constexpr uint64_t kMaxImagePixels = uint64_t(1) << 28;

#ifdef FREDHOLM_HAVE_OIIO
// Every image fredholm reads (compare's, textures, environment maps) is opened here: the file
// through the input gate (base/input_file.h: a regular file within the size cap, a PNG's chunks
// within the file), then its header's claim (width x height x channels, a flat image) against
// the file's size and kMaxImagePixels, so that reading its pixels allocates no more than the
// file can hold. `what` is the file's role ("compare", "texture", "--env-map"); errors are one
// line, "WHAT 'PATH': why".
std::unique_ptr<OIIO::ImageInput> openImageInput(const std::string& path, const std::string& what);
#endif

// The image at `path` (opened by openImageInput) as linear float RGB; errors name `what`.
Image readImage(const std::string& path, const std::string& what = "image");

float linearToSrgb(float linear);
float srgbToLinear(float encoded);

}  // namespace fh

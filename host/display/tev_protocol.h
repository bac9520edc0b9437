// The packets of tev's TCP protocol (the HDR viewer's "IPC"; pbrt-v4's --display-server
// speaks it): a little-endian uint32 length of the whole packet, a type byte, then the fields.
// fredholm sends two: CreateImage, and UpdateImage (version 3: a region of some channels,
// each channel at an offset and stride within the region's floats).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/image_io.h"

namespace fh::tev {

constexpr uint16_t kDefaultPort = 14158;
enum PacketType : uint8_t { kCreateImage = 4, kUpdateImageV3 = 6 };

// The image's channels as tev names them: R, G, B, then each layer's (albedo.R, depth.Z).
std::vector<std::string> channelsOf(const Image& image);

// A blank image of that size and those channels (replacing one of the same name).
std::string createImage(const std::string& name, int width, int height, const std::vector<std::string>& channels,
                        bool grabFocus);

// The image's pixels in UpdateImage packets of at most tile x tile pixels each, every channel
// interleaved per pixel.
std::vector<std::string> updateImage(const std::string& name, const Image& image, int tile = 128);

}  // namespace fh::tev

// tev's packets, written field by field in little-endian order.
#include "display/tev_protocol.h"

#include <algorithm>
#include <cstring>

namespace fh::tev {
namespace {

// A packet under construction: its length is filled in last.
class Packet {
 public:
  explicit Packet(uint8_t type) : bytes_(4, '\0') { bytes_.push_back(char(type)); }
  void u8(uint8_t v) { bytes_.push_back(char(v)); }
  void i32(int32_t v) { little(uint64_t(uint32_t(v)), 4); }
  void i64(int64_t v) { little(uint64_t(v), 8); }
  void f32(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    little(bits, 4);
  }
  void text(const std::string& s) {  // NUL-terminated
    bytes_ += s;
    bytes_.push_back('\0');
  }
  std::string done() {
    const uint32_t n = uint32_t(bytes_.size());
    for (int i = 0; i < 4; ++i) bytes_[size_t(i)] = char((n >> (8 * i)) & 0xff);
    return std::move(bytes_);
  }

 private:
  void little(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes_.push_back(char((v >> (8 * i)) & 0xff));
  }
  std::string bytes_;
};

}  // namespace

std::vector<std::string> channelsOf(const Image& image) {
  std::vector<std::string> channels = {"R", "G", "B"};
  for (const ImageLayer& layer : image.layers)
    for (const std::string& c : layer.channels) channels.push_back(layer.name + "." + c);
  return channels;
}

std::string createImage(const std::string& name, int width, int height, const std::vector<std::string>& channels,
                        bool grabFocus) {
  Packet p(kCreateImage);
  p.u8(grabFocus);
  p.text(name);
  p.i32(width);
  p.i32(height);
  p.i32(int32_t(channels.size()));
  for (const std::string& c : channels) p.text(c);
  return p.done();
}

std::vector<std::string> updateImage(const std::string& name, const Image& image, int tile) {
  const std::vector<std::string> channels = channelsOf(image);
  const int64_t n = int64_t(channels.size());
  std::vector<std::string> packets;
  for (int y0 = 0; y0 < image.height; y0 += tile)
    for (int x0 = 0; x0 < image.width; x0 += tile) {
      const int w = std::min(tile, image.width - x0), h = std::min(tile, image.height - y0);
      Packet p(kUpdateImageV3);
      p.u8(0);  // grab focus: only when the image is created
      p.text(name);
      p.i32(int32_t(n));
      for (const std::string& c : channels) p.text(c);
      p.i32(x0);
      p.i32(y0);
      p.i32(w);
      p.i32(h);
      for (int64_t c = 0; c < n; ++c) p.i64(c);  // channel c's first float in the region
      for (int64_t c = 0; c < n; ++c) p.i64(n);  // and the floats from one pixel to the next
      for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x) {
          const size_t pixel = size_t(y) * size_t(image.width) + size_t(x);
          for (size_t c = 0; c < 3; ++c) p.f32(image.rgb[3 * pixel + c]);
          for (const ImageLayer& layer : image.layers)
            for (size_t c = 0; c < layer.channels.size(); ++c)
              p.f32(layer.values[layer.channels.size() * pixel + c]);
        }
      packets.push_back(p.done());
    }
  return packets;
}

}  // namespace fh::tev

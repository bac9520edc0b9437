// --display-server (display/live_view.h): a receiver of tev's protocol, written here from the
// protocol's description (not from fredholm's encoder), takes what a render streams: frames
// while it converges, then the image as written, bit for bit. A viewer that leaves or is not
// there changes nothing in the image.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <thread>

#include "display/live_view.h"
#include "image/image_io.h"
#include "render/film.h"
#include "test_support.h"

namespace fh {
namespace {

// One image as the viewer holds it: each channel's floats, row-major.
struct ViewerImage {
  int width = 0, height = 0;
  std::vector<std::string> channelOrder;
  std::map<std::string, std::vector<float>> channels;
};

// Listens on 127.0.0.1 (a port of its own), takes connections one after another and applies
// CreateImage (type 4) and UpdateImage v3 (type 6) packets. closeAfter > 0: after that many
// packets it closes the connection and stops listening (a viewer that goes away).
class Receiver {
 public:
  explicit Receiver(int closeAfter = 0) : closeAfter_(closeAfter) {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof(a);
    if (bind(listener_, reinterpret_cast<sockaddr*>(&a), len) != 0 || listen(listener_, 4) != 0 ||
        getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      throw std::runtime_error("receiver: cannot listen");
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~Receiver() {
    stop_ = true;
    thread_.join();
    if (listener_ >= 0) close(listener_);
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  // Waits until the sender has closed a connection and every packet on it is applied: what the
  // sender wrote may still be in the socket after it closed. False after ten seconds.
  bool waitForTheSenderToClose() {
    std::unique_lock<std::mutex> lock(mutex);
    return closed_.wait_for(lock, std::chrono::seconds(10), [&] { return connectionsEnded_ > 0; });
  }

  std::mutex mutex;
  std::map<std::string, ViewerImage> images;
  int packets = 0, creates = 0;
  std::vector<std::vector<float>> frameStarts;  // channel R each time a frame began (a tile at 0,0)

 private:
  void run() {
    while (!stop_ && listener_ >= 0) {
      pollfd p{listener_, POLLIN, 0};
      if (poll(&p, 1, 50) != 1) continue;
      const int fd = accept(listener_, nullptr, nullptr);
      if (fd >= 0) serve(fd);
    }
  }
  void serve(int fd) {
    std::string buffer;
    char chunk[1 << 16];
    for (;;) {
      pollfd p{fd, POLLIN, 0};
      if (poll(&p, 1, 50) != 1) {
        if (stop_) break;
        continue;
      }
      const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
      if (n == 0) {  // the sender closed, and everything it sent is applied
        std::lock_guard<std::mutex> lock(mutex);
        ++connectionsEnded_;
        closed_.notify_all();
      }
      if (n <= 0) break;
      buffer.append(chunk, size_t(n));
      while (buffer.size() >= 4) {
        uint32_t length;
        std::memcpy(&length, buffer.data(), 4);
        if (buffer.size() < length) break;
        apply(buffer.substr(4, length - 4));
        buffer.erase(0, length);
        if (closeAfter_ > 0 && packets >= closeAfter_) {
          close(fd);
          close(listener_);
          listener_ = -1;
          return;
        }
      }
    }
    close(fd);
  }
  // Fields in order, little-endian (the test machine's order).
  struct Reader {
    const std::string& s;
    size_t at = 0;
    template <class T> T get() {
      T v;
      std::memcpy(&v, s.data() + at, sizeof(T));
      at += sizeof(T);
      return v;
    }
    std::string text() {
      const size_t end = s.find('\0', at);
      std::string t = s.substr(at, end - at);
      at = end + 1;
      return t;
    }
  };
  void apply(const std::string& packet) {
    std::lock_guard<std::mutex> lock(mutex);
    ++packets;
    Reader r{packet, 1};
    const uint8_t type = uint8_t(packet[0]);
    r.get<uint8_t>();  // grab focus
    const std::string name = r.text();
    if (type == 4) {
      ++creates;
      ViewerImage& image = images[name];
      image = ViewerImage{};
      image.width = r.get<int32_t>();
      image.height = r.get<int32_t>();
      const int n = r.get<int32_t>();
      for (int c = 0; c < n; ++c) {
        image.channelOrder.push_back(r.text());
        image.channels[image.channelOrder.back()].assign(size_t(image.width) * size_t(image.height), 0.f);
      }
    } else if (type == 6) {
      ViewerImage& image = images.at(name);
      const int n = r.get<int32_t>();
      std::vector<std::string> names;
      for (int c = 0; c < n; ++c) names.push_back(r.text());
      const int x = r.get<int32_t>(), y = r.get<int32_t>(), w = r.get<int32_t>(), h = r.get<int32_t>();
      std::vector<int64_t> offsets, strides;
      for (int c = 0; c < n; ++c) offsets.push_back(r.get<int64_t>());
      for (int c = 0; c < n; ++c) strides.push_back(r.get<int64_t>());
      const size_t data = r.at;
      if (x == 0 && y == 0) frameStarts.push_back(image.channels["R"]);
      for (int c = 0; c < n; ++c)
        for (int j = 0; j < h; ++j)
          for (int i = 0; i < w; ++i) {
            float v;
            std::memcpy(&v, packet.data() + data + 4 * size_t(offsets[size_t(c)] + (j * w + i) * strides[size_t(c)]), 4);
            image.channels.at(names[size_t(c)])[size_t(y + j) * size_t(image.width) + size_t(x + i)] = v;
          }
    }
  }

  int listener_ = -1, port_ = 0;
  const int closeAfter_;
  std::condition_variable closed_;
  int connectionsEnded_ = 0;  // under mutex
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Every channel of an EXR, by name.
std::map<std::string, std::vector<float>> channelsOf(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> pixels(spec.image_pixels() * size_t(spec.nchannels));
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
  std::map<std::string, std::vector<float>> out;
  for (int c = 0; c < spec.nchannels; ++c)
    for (size_t p = 0; p < spec.image_pixels(); ++p)
      out[spec.channelnames[size_t(c)]].push_back(pixels[p * size_t(spec.nchannels) + size_t(c)]);
  return out;
}

const std::string kRender = "render --width 96 --height 64 --seed 5";

TEST(LiveView, StreamsFramesAndEndsWithTheWrittenImage) {
  const std::string dir = test::tempDir("display");
  const std::string out = dir + "/live.exr";
  Receiver viewer;
  const auto r = test::runFredholm(kRender + " --spp 2048 --aovs albedo,normal,depth -o " + out +
                                   " --display-server " + viewer.address());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  ASSERT_TRUE(viewer.waitForTheSenderToClose());
  std::lock_guard<std::mutex> lock(viewer.mutex);
  ASSERT_EQ(viewer.images.count(out), 1u) << "tev's image is named after the output";
  const ViewerImage& shown = viewer.images.at(out);
  EXPECT_EQ(shown.width, 96);
  EXPECT_EQ(shown.height, 64);
  EXPECT_EQ(viewer.creates, 1);
  const auto written = channelsOf(out);
  ASSERT_EQ(shown.channels.size(), written.size());
  for (const auto& [name, values] : written) {
    ASSERT_EQ(shown.channels.count(name), 1u) << name;
    EXPECT_EQ(std::memcmp(shown.channels.at(name).data(), values.data(), values.size() * 4), 0)
        << "channel " << name << " differs from the written image";
  }
  // Progressive: frames before the last, and not all of them the final image.
  ASSERT_GE(viewer.frameStarts.size(), 3u) << "frames: " << viewer.frameStarts.size();
  EXPECT_NE(viewer.frameStarts[1], shown.channels.at("R"));
}

TEST(LiveView, AViewerThatLeavesOrIsAbsentChangesNothing) {
  const std::string dir = test::tempDir("display");
  const std::string flags = kRender + " --spp 512 -o " + dir;
  ASSERT_EQ(test::runFredholm(flags + "/alone.exr").exitCode, 0);
  std::string absent;
  {
    Receiver gone(1);  // closed for good once the render started
    absent = gone.address();
  }
  Receiver leaving(3);  // takes the image's creation and two tiles, then goes
  const std::pair<std::string, std::string> cases[] = {{"left", leaving.address()}, {"absent", absent}};
  for (const auto& [name, address] : cases) {
    const auto r = test::runFredholm(flags + "/" + name + ".exr --display-server " + address);
    ASSERT_EQ(r.exitCode, 0) << name << "\n" << r.output;
    EXPECT_NE(r.output.find("fredholm: warning: --display-server " + address), std::string::npos) << r.output;
    EXPECT_EQ(readImage(dir + "/" + name + ".exr").rgb, readImage(dir + "/alone.exr").rgb) << name;
  }
  std::lock_guard<std::mutex> lock(leaving.mutex);
  EXPECT_EQ(leaving.packets, 3);
}

// In one process (the sanitizer builds run this): a merger adding passes as fast as it can and
// offering each to the view, the sender taking frames on its own thread, then the final image.
TEST(LiveView, InProcessFramesFollowTheFilmAndTheFinalImageIsLast) {
  Receiver viewer;
  const int w = 40, h = 30;
  Film film(w, h);
  Image final;
  int offered = 0;
  const auto start = std::chrono::steady_clock::now();
  double seconds = 0;
  {
    LiveView view(parseDisplayAddress(viewer.address()), "in-process", {});
    for (int pass = 0; pass < 300; ++pass) {
      std::vector<float> samples(size_t(w) * size_t(h) * 4, 1.f);
      for (size_t p = 0; p < samples.size(); p += 4) samples[p] = float((p / 4 + size_t(pass)) % 5);
      film.addPass(samples);
      if (view.wantsFrame()) {
        view.show(film);
        ++offered;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    final = film.image();
    view.showFinal(final);
  }  // the view closes once the final image is sent
  ASSERT_TRUE(viewer.waitForTheSenderToClose());
  std::lock_guard<std::mutex> lock(viewer.mutex);
  EXPECT_GE(offered, 2);
  EXPECT_LE(offered, int(seconds / 0.25) + 1) << "frames at most four a second, in " << seconds << " s";
  // Each frame offered is sent, and the final one (which may replace the last offered, not yet taken).
  EXPECT_GE(int(viewer.frameStarts.size()), offered);
  EXPECT_LE(int(viewer.frameStarts.size()), offered + 1);
  const ViewerImage& shown = viewer.images.at("in-process");
  for (size_t p = 0; p < final.rgb.size() / 3; ++p)
    ASSERT_EQ(shown.channels.at("R")[p], final.rgb[3 * p]) << "pixel " << p;
}

TEST(LiveView, AddressesAreCheckedBeforeWork) {
  for (const std::string bad : {"nope", "host:", ":14158", "host:0", "host:65536", "host:14x", "[]:1"}) {
    const auto r = test::runFredholm("render --width 8 --height 8 --spp 1 -o /nonexistent/x.exr --display-server '" +
                                     bad + "'");
    EXPECT_NE(r.exitCode, 0) << bad;
    EXPECT_EQ(r.output, "fredholm: error: --display-server '" + bad +
                            "': expected HOST:PORT, e.g. localhost:14158 (tev's default port)\n");
  }
}

}  // namespace
}  // namespace fh

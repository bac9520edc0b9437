// --display-server HOST:PORT: the render streamed to the tev viewer as it converges. The
// pool's merger hands the film over between passes, a few times a second and only when the
// sender is free (render/film_watcher.h); a thread of its own sends it, so neither the devices
// nor the merger ever wait on the network. A viewer that is not there is looked for again
// every few seconds; one that goes away or stops reading is dropped. Either is a warning,
// never a failed render.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "image/image_io.h"
#include "render/film_watcher.h"

namespace fh {

struct DisplayAddress {
  std::string host, port;
  std::string text() const { return host + ":" + port; }
};
// HOST:PORT ([::1]:PORT for an IPv6 address); throws fh::Error naming --display-server.
DisplayAddress parseDisplayAddress(const std::string& text);

class LiveView final : public FilmWatcher {
 public:
  // `imageName`: what tev calls the image (the output's name); `layers`: the --aovs layers
  // sent beside the radiance, as the written image has them.
  LiveView(DisplayAddress address, std::string imageName, std::vector<std::string> layers);
  // Sends the final image if one was given (bounded by the send timeout), then closes.
  ~LiveView() override;
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  bool wantsFrame() override;
  void show(const Film& film) override;
  // The image as written: the view's last frame.
  void showFinal(const Image& image);

 private:
  void run();
  bool connect();
  bool send(const Image& image);
  void disconnect(const std::string& why);

  const DisplayAddress address_;
  const std::string name_;
  const std::vector<std::string> layers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Image> frame_;  // the newest frame not yet sent
  bool final_ = false, closing_ = false;
  std::atomic<bool> ready_{false};  // connected, idle, and a frame is due
  std::chrono::steady_clock::time_point lastFrame_{};
  int socket_ = -1;
  bool warned_ = false;
  std::string createdFor_;  // the channel list the viewer's image was created with
  std::thread sender_;
};

}  // namespace fh

// The live view's sender thread and its socket.
#include "display/live_view.h"

#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <iostream>

#include "base/error.h"
#include "display/tev_protocol.h"
#include "render/film.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;
// Frames a second at most: a live view, not a video.
constexpr auto kFrameInterval = std::chrono::milliseconds(250);
// How often a viewer that is not there is looked for again.
constexpr auto kRetryInterval = std::chrono::seconds(2);
// A connection attempt, and a send the viewer does not take, give up after this.
constexpr int kTimeoutMs = 2000;

// Connects to host:port within kTimeoutMs; -1 with `why` set where it cannot.
int connectTo(const DisplayAddress& a, std::string& why) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int e = getaddrinfo(a.host.c_str(), a.port.c_str(), &hints, &found); e != 0) {
    why = gai_strerror(e);
    return -1;
  }
  int fd = -1;
  why = "no address";
  for (addrinfo* ai = found; ai && fd < 0; ai = ai->ai_next) {
    fd = socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, ai->ai_protocol);
    if (fd < 0) continue;
    int error = ::connect(fd, ai->ai_addr, ai->ai_addrlen) == 0 ? 0 : errno;
    if (error == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      socklen_t len = sizeof(error);
      error = poll(&p, 1, kTimeoutMs) == 1 ? (getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &len), error) : ETIMEDOUT;
    }
    if (error != 0) {
      why = std::strerror(error);
      close(fd);
      fd = -1;
    }
  }
  freeaddrinfo(found);
  if (fd >= 0) {  // blocking from here on, with a send timeout
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    timeval t{kTimeoutMs / 1000, 0};
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &t, sizeof(t));
  }
  return fd;
}

bool sendAll(int fd, const std::string& bytes) {
  for (size_t sent = 0; sent < bytes.size();) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    sent += size_t(n);
  }
  return true;
}

}  // namespace

DisplayAddress parseDisplayAddress(const std::string& text) {
  const size_t colon = text.rfind(':');
  DisplayAddress a;
  if (colon != std::string::npos) {
    a.host = text.substr(0, colon);
    a.port = text.substr(colon + 1);
  }
  if (a.host.size() >= 2 && a.host.front() == '[' && a.host.back() == ']') a.host = a.host.substr(1, a.host.size() - 2);
  const bool digits = !a.port.empty() && a.port.size() <= 5 && a.port.find_first_not_of("0123456789") == std::string::npos;
  if (a.host.empty() || !digits || std::stoi(a.port) < 1 || std::stoi(a.port) > 65535)
    throw Error("--display-server '" + text + "': expected HOST:PORT, e.g. localhost:" +
                std::to_string(tev::kDefaultPort) + " (tev's default port)");
  return a;
}

LiveView::LiveView(DisplayAddress address, std::string imageName, std::vector<std::string> layers)
    : address_(std::move(address)), name_(std::move(imageName)), layers_(std::move(layers)) {
  sender_ = std::thread([this] { run(); });
}

LiveView::~LiveView() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  wake_.notify_all();
  sender_.join();
  if (socket_ >= 0) close(socket_);
}

bool LiveView::wantsFrame() {
  if (!ready_.load(std::memory_order_relaxed)) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  return !final_ && Clock::now() - lastFrame_ >= kFrameInterval;
}

void LiveView::show(const Film& film) {
  Image image = film.imageWithLayers(layers_);  // outside the lock: the sender may be sending
  std::lock_guard<std::mutex> lock(mutex_);
  if (final_) return;
  frame_ = std::move(image);
  lastFrame_ = Clock::now();
  ready_ = false;
  wake_.notify_all();
}

void LiveView::showFinal(const Image& image) {
  std::lock_guard<std::mutex> lock(mutex_);
  frame_ = image;
  final_ = true;
  ready_ = false;
  wake_.notify_all();
}

// Until closing: connect (again every kRetryInterval), then send each frame handed over. At
// the close, the final frame is sent if there is one, with one more try to connect for it.
void LiveView::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  Clock::time_point lastTry{};
  for (;;) {
    if (socket_ < 0 && (final_ || Clock::now() - lastTry >= kRetryInterval)) {
      lastTry = Clock::now();
      lock.unlock();
      const bool connected = connect();
      lock.lock();
      if (connected) lastFrame_ = Clock::time_point{};  // a frame at once
    }
    if (frame_ && socket_ >= 0) {
      Image image = std::move(*frame_);
      frame_.reset();
      lock.unlock();
      if (!send(image)) disconnect("stopped taking the image");
      lock.lock();
    }
    // The final frame is sent, or there is no viewer to take it: done.
    if (final_ && (!frame_ || socket_ < 0)) return;
    if (closing_ && !final_) return;
    ready_ = socket_ >= 0;
    wake_.wait_for(lock, kRetryInterval, [&] { return closing_ || final_ || frame_.has_value(); });
  }
}

bool LiveView::connect() {
  std::string why;
  socket_ = connectTo(address_, why);
  if (socket_ < 0 && !warned_) {
    std::cerr << "fredholm: warning: --display-server " << address_.text() << ": no viewer there (" << why
              << "); rendering on, and looking for one every few seconds\n";
    warned_ = true;
  }
  return socket_ >= 0;
}

bool LiveView::send(const Image& image) {
  // A new image in the viewer when the channels change (the first frame, or --aovs layers).
  const std::vector<std::string> channels = tev::channelsOf(image);
  std::string key;
  for (const std::string& c : channels) key += c + ",";
  if (key != createdFor_) {
    if (!sendAll(socket_, tev::createImage(name_, image.width, image.height, channels, true))) return false;
    createdFor_ = key;
  }
  for (const std::string& packet : tev::updateImage(name_, image))
    if (!sendAll(socket_, packet)) return false;
  return true;
}

void LiveView::disconnect(const std::string& why) {
  close(socket_);
  socket_ = -1;
  createdFor_.clear();
  std::cerr << "fredholm: warning: --display-server " << address_.text() << ": the viewer " << why
            << "; the render goes on without it\n";
  warned_ = true;
}

}  // namespace fh

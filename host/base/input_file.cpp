// Open without blocking, take the type from the open file, read at most the cap.
#include "base/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>

#include "base/error.h"

namespace fh {
namespace {

std::string named(const std::string& what, const std::string& path) { return what + " '" + path + "': "; }

std::string sizeText(uint64_t bytes) {
  if (bytes >= (uint64_t(1) << 30)) return std::to_string(bytes >> 30) + " GiB";
  if (bytes >= (uint64_t(1) << 20)) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

std::mutex recordMutex;
std::vector<InputRecord> records;

void record(const std::string& path, const std::string& what, const struct stat& st) {
  std::lock_guard<std::mutex> lock(recordMutex);
  for (const InputRecord& r : records)
    if (r.device == uint64_t(st.st_dev) && r.inode == uint64_t(st.st_ino)) return;
  records.push_back({path, what, uint64_t(st.st_dev), uint64_t(st.st_ino)});
}

// An open descriptor that closes itself.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens `path` for reading (O_NONBLOCK: opening a FIFO with no writer would wait forever)
// and checks what it is; returns the size.
uint64_t openChecked(Descriptor& d, const std::string& path, const std::string& what, uint64_t maxBytes) {
  if (path.empty()) throw Error(what + ": no file named");
  d.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (d.fd < 0) {
    const int error = errno;
    if (error == ENOENT) throw Error(named(what, path) + "file not found");
    throw Error(named(what, path) + "cannot open it: " + std::strerror(error));
  }
  struct stat st = {};
  if (::fstat(d.fd, &st) != 0) throw Error(named(what, path) + "cannot read it: " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw Error(named(what, path) + "is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    throw Error(named(what, path) + "is not a regular file (a device, FIFO or socket); give a file");
  record(path, what, st);
  const uint64_t size = uint64_t(st.st_size);
  if (size > maxBytes)
    throw Error(named(what, path) + "is " + sizeText(size) + ", more than the " + sizeText(maxBytes) +
                " fredholm reads as " + what);
  return size;
}

}  // namespace

uint64_t checkInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
  Descriptor d;
  return openChecked(d, path, what, maxBytes);
}

std::string readInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
  Descriptor d;
  const uint64_t size = openChecked(d, path, what, maxBytes);
  std::string text(size_t(size), '\0');
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(d.fd, &text[done], text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(named(what, path) + "cannot read it: " + std::strerror(errno));
    if (n == 0) break;  // shrank while we read: take what is there
    done += size_t(n);
  }
  text.resize(done);
  return text;
}

std::vector<InputRecord> inputsRead() {
  std::lock_guard<std::mutex> lock(recordMutex);
  return records;
}

void checkImageClaim(const std::string& path, const std::string& what, long long width, long long height,
                     long long channels, uint64_t fileBytes, uint64_t maxPixels) {
  const std::string claim = std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels);
  if (width <= 0 || height <= 0 || channels <= 0 || channels > 64)
    throw Error(named(what, path) + "its header claims " + claim + " pixels, which is not an image");
  const uint64_t pixels = uint64_t(width) * uint64_t(height);
  if (pixels > maxPixels)
    throw Error(named(what, path) + "its header claims " + claim + " pixels, more than the " +
                std::to_string(maxPixels) + " fredholm reads");
  if (pixels > 1024 * fileBytes + 65536)
    throw Error(named(what, path) + "its header claims " + claim + " pixels, more than its " +
                std::to_string(fileBytes) + " bytes can hold");
}

}  // namespace fh

// Temporary file, check, fsync, rename.
#include "base/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "base/error.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// .NAME.fredholm-tmp-PID-N.EXT beside the target: hidden, unique per process and call (two
// devices may store the same program at once), and with the target's extension, which image
// writers choose their format by.
std::string temporaryBeside(const std::string& path) {
  static std::atomic<unsigned> calls{0};
  const fs::path p(path);
  const std::string name = "." + p.stem().string() + ".fredholm-tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(calls++) + p.extension().string();
  return (p.parent_path() / name).string();
}

// Forces the file's data to the disk, so that a crash after the rename cannot leave an
// empty target (ext4's delayed allocation).
void syncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw Error(std::string("cannot reopen it: ") + std::strerror(errno));
  const int synced = ::fsync(fd), error = errno;
  ::close(fd);
  if (synced != 0) throw Error(std::string("cannot flush it to disk: ") + std::strerror(error));
}

}  // namespace

void writeAtomically(const std::string& path, const std::string& what,
                     const std::function<void(const std::string&)>& write,
                     const std::function<void(const std::string&)>& check) {
  const std::string temp = temporaryBeside(path);
  try {
    write(temp);
    if (check) check(temp);
    syncFile(temp);
    if (std::rename(temp.c_str(), path.c_str()) != 0)
      throw Error(std::string("cannot rename the temporary file over it: ") + std::strerror(errno));
  } catch (const Error& e) {
    std::error_code ec;
    fs::remove(temp, ec);
    throw Error(what + " '" + path + "': cannot write: " + e.what());
  }
}

void writeTextAtomically(const std::string& path, const std::string& what, const std::string& text) {
  writeAtomically(path, what, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary);
    if (!out) throw Error(std::string("cannot create a file beside it: ") + std::strerror(errno));
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) throw Error("the write failed (disk full?)");
    std::error_code ec;
    if (fs::file_size(temp, ec) != text.size() || ec) throw Error("the file came out short (disk full?)");
  });
}

}  // namespace fh

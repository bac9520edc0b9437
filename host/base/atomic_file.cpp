// Temporary file, check, fsync, commit; the reservations an output plan makes, and the list
// of temporary files a signal handler removes.
#include "base/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include "base/error.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// The temporary files that exist now, in slots a signal handler can read without locks.
constexpr int kTemporarySlots = 64;
constexpr size_t kPathBytes = 4096;
struct TemporarySlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a path
  char path[kPathBytes];
};
TemporarySlot temporaries[kTemporarySlots];

// Lists `path` for removeTemporariesNow; a path too long for a slot, or slots all taken, is
// left to the ordinary clean-up.
void listTemporary(const std::string& path) {
  if (path.size() >= kPathBytes) return;
  for (TemporarySlot& slot : temporaries) {
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot.path, path.c_str(), path.size() + 1);
    slot.state.store(2);
    return;
  }
}

void unlistTemporary(const std::string& path) {
  for (TemporarySlot& slot : temporaries) {
    int expected = 2;
    if (slot.state.load() == 2 && path == slot.path && slot.state.compare_exchange_strong(expected, 1))
      slot.state.store(0);
  }
}

void removeTemporary(const std::string& path) {
  unlistTemporary(path);
  std::error_code ec;
  fs::remove(path, ec);
}

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

// Creates the temporary file, empty, and lists it.
void createTemporary(const std::string& temp) {
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(std::string("cannot create a file beside it: ") + std::strerror(errno));
  ::close(fd);
  listTemporary(temp);
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

struct Reservation {
  std::string path;  // as the user named it
  std::string temp;  // empty once a write has used it
  CommitRule rule = CommitRule::Replace;
  std::string writtenTo;  // where a Keep target was written instead of its path
};
std::mutex reservationMutex;
std::map<std::string, Reservation> reservations;

std::string keyOf(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

// Moves `temp` to `target` unless a file is there; false if one is.
bool renameNoReplace(const std::string& temp, const std::string& target) {
  if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) == 0) return true;
  if (errno == EEXIST) return false;
  if (errno != EINVAL && errno != ENOSYS)
    throw Error(std::string("cannot rename the temporary file to it: ") + std::strerror(errno));
  // A file system without RENAME_NOREPLACE: a hard link is made only where no file is.
  if (::link(temp.c_str(), target.c_str()) != 0) {
    if (errno == EEXIST) return false;
    throw Error(std::string("cannot link the temporary file to it: ") + std::strerror(errno));
  }
  ::unlink(temp.c_str());
  return true;
}

// Commits `temp` to `path` by `rule`; returns the path it now has.
std::string commit(const std::string& temp, const std::string& path, CommitRule rule) {
  if (rule == CommitRule::Replace) {
    if (std::rename(temp.c_str(), path.c_str()) != 0)
      throw Error(std::string("cannot rename the temporary file over it: ") + std::strerror(errno));
    return path;
  }
  for (int i = 0;; ++i) {
    const std::string candidate = numberedName(path, i);
    if (renameNoReplace(temp, candidate)) return candidate;
  }
}

}  // namespace

std::string numberedName(const std::string& path, int n) {
  if (n == 0) return path;
  const fs::path p(path);
  return (p.parent_path() / p.stem()).string() + "-" + std::to_string(n) + p.extension().string();
}

void reserveTarget(const std::string& path, const std::string& what, CommitRule rule) {
  const std::string temp = temporaryBeside(path);
  try {
    createTemporary(temp);
  } catch (const Error& e) {
    throw Error(what + " '" + path + "': cannot write there: " + e.what());
  }
  std::lock_guard<std::mutex> lock(reservationMutex);
  reservations[keyOf(path)] = Reservation{path, temp, rule, ""};
}

void releaseTarget(const std::string& path) {
  std::lock_guard<std::mutex> lock(reservationMutex);
  const auto it = reservations.find(keyOf(path));
  if (it == reservations.end()) return;
  if (!it->second.temp.empty()) removeTemporary(it->second.temp);
  reservations.erase(it);
}

std::vector<std::pair<std::string, std::string>> steppedAside() {
  std::lock_guard<std::mutex> lock(reservationMutex);
  std::vector<std::pair<std::string, std::string>> moved;
  for (const auto& entry : reservations) {
    const Reservation& r = entry.second;
    if (r.rule == CommitRule::Keep && !r.writtenTo.empty()) moved.emplace_back(r.path, r.writtenTo);
  }
  return moved;
}

std::string writeAtomically(const std::string& path, const std::string& what,
                            const std::function<void(const std::string&)>& write,
                            const std::function<void(const std::string&)>& check) {
  // The reservation's temporary file if the plan made one (its first write only), else a new one.
  std::string temp;
  CommitRule rule = CommitRule::Replace;
  {
    std::lock_guard<std::mutex> lock(reservationMutex);
    const auto it = reservations.find(keyOf(path));
    if (it != reservations.end()) {
      rule = it->second.rule;
      temp.swap(it->second.temp);
    }
  }
  try {
    if (temp.empty()) {
      temp = temporaryBeside(path);
      createTemporary(temp);
    }
    write(temp);
    if (check) check(temp);
    syncFile(temp);
    const std::string written = commit(temp, path, rule);
    unlistTemporary(temp);
    if (written != path) {
      std::lock_guard<std::mutex> lock(reservationMutex);
      reservations[keyOf(path)].writtenTo = written;
    }
    return written;
  } catch (const Error& e) {
    removeTemporary(temp);
    throw Error(what + " '" + path + "': cannot write: " + e.what());
  }
}

std::string writeTextAtomically(const std::string& path, const std::string& what, const std::string& text) {
  return writeAtomically(path, what, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(std::string("cannot open the file beside it: ") + std::strerror(errno));
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) throw Error("the write failed (disk full?)");
    std::error_code ec;
    if (fs::file_size(temp, ec) != text.size() || ec) throw Error("the file came out short (disk full?)");
  });
}

void removeTemporariesNow() {
  for (TemporarySlot& slot : temporaries)
    if (slot.state.load() == 2) ::unlink(slot.path);
}

}  // namespace fh

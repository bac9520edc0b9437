// The outputs' checks, their reservations, and the check against the inputs read.
#include "base/output_plan.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/input_file.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// The path with every existing directory and link resolved: two names of one file compare
// equal (x.exr and ./sub/../x.exr, or a link to it).
std::string resolved(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  return ec ? fs::absolute(path).lexically_normal().string() : p.string();
}

bool sameFile(const std::string& path, uint64_t device, uint64_t inode) {
  struct stat st = {};
  return ::stat(path.c_str(), &st) == 0 && uint64_t(st.st_dev) == device && uint64_t(st.st_ino) == inode;
}

std::string named(const std::string& what, const std::string& path) { return what + " '" + path + "': "; }

// A place the output can go: its directory exists, it is not a directory, and an existing
// file there is replaced only where the rule allows.
void checkPlace(const std::string& path, const std::string& what, bool mayExist) {
  const fs::path parent = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  std::error_code ec;
  if (path.empty()) throw Error(what + ": no file named");
  if (!fs::is_directory(parent, ec)) throw Error(named(what, path) + "directory '" + parent.string() + "' does not exist");
  const auto status = fs::status(path, ec);
  if (fs::is_directory(status)) throw Error(named(what, path) + "is a directory");
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw Error(named(what, path) + "is not a regular file (a device, FIFO or socket); name a file to write");
  if (fs::exists(status) && !mayExist) throw Error(named(what, path) + "file exists (pass --force to overwrite it)");
}

}  // namespace

void OutputPlan::add(const std::string& path, const std::string& what, OutputKind kind,
                     const std::string& mayReplace) {
  entries_.push_back({path, what, mayReplace, kind});
}

void OutputPlan::reserve() {
  for (size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    checkPlace(e.path, e.what, force_ || e.kind == OutputKind::Default || !e.mayReplace.empty());
    for (size_t j = 0; j < i; ++j)
      if (resolved(entries_[j].path) == resolved(e.path))
        throw Error(named(e.what, e.path) + "is also the file of " + entries_[j].what +
                    "; give each output its own file");
  }
  for (const Entry& e : entries_) {
    const CommitRule rule = e.kind == OutputKind::Default ? CommitRule::KeepQuiet
                            : e.kind == OutputKind::Owned || force_ ? CommitRule::Replace
                                                                    : CommitRule::Keep;
    reserveTarget(e.path, e.what, rule);
  }
}

void OutputPlan::checkAgainstInputs() const {
  for (const InputRecord& input : inputsRead())
    for (const Entry& e : entries_) {
      const bool allowed = !e.mayReplace.empty() && resolved(e.mayReplace) == resolved(input.path);
      if (!allowed && (sameFile(e.path, input.device, input.inode) || resolved(e.path) == resolved(input.path)))
        throw Error(named(e.what, e.path) + "is the " + input.what + " this command reads" +
                    (input.path == e.path ? "" : " ('" + input.path + "')") + "; write the output elsewhere");
    }
}

void OutputPlan::finish() const {
  std::string moved;
  for (const auto& [path, written] : steppedAside())
    moved += (moved.empty() ? "" : "; ") + std::string("'") + path + "' appeared during the work and was kept, "
             "so the output is in '" + written + "'";
  if (!moved.empty()) throw Error(moved);
}

// Also after a reserve() that failed part-way: the reservations it made go too.
OutputPlan::~OutputPlan() {
  for (const Entry& e : entries_) releaseTarget(e.path);
}

}  // namespace fh

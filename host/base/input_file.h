// The one gate every file fredholm reads goes through: scenes, MTL libraries, textures,
// cameras, environment maps, films, checkpoints and the images `compare` reads. It refuses
// what is not a regular file (a device such as /dev/zero never ends, a FIFO blocks), caps the
// size it will read, and names the file and its role in every refusal.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace fh {

// The most fredholm reads of one file unless a role asks for less: an 8K film with every
// layer fits with room to spare.
constexpr uint64_t kMaxInputBytes = uint64_t(16) << 30;

// Checks that `path` names a regular file of at most `maxBytes` that this process can open,
// and returns its size. `what` is the file's role as the user gave it ("--camera", "texture",
// "scene"); errors read "WHAT 'PATH': why".
uint64_t checkInputFile(const std::string& path, const std::string& what, uint64_t maxBytes = kMaxInputBytes);

// The whole file, read through the same checks (opened without blocking, its type taken from
// the open file, so a path that changes under us cannot slip a device past the check).
std::string readInputFile(const std::string& path, const std::string& what, uint64_t maxBytes = kMaxInputBytes);

// An image header's claim (width x height x channels) against the file that makes it: at most
// `maxPixels` pixels, and no more than a compressed format can pack into `fileBytes` (deflate
// cannot shrink data below about a thousandth). Throws naming the file and the size claimed.
// Every file read through the gate so far in this process (by device and inode), so that an
// output plan can refuse to write over an input (base/output_plan.h).
struct InputRecord {
  std::string path, what;
  uint64_t device = 0, inode = 0;
};
std::vector<InputRecord> inputsRead();

void checkImageClaim(const std::string& path, const std::string& what, long long width, long long height,
                     long long channels, uint64_t fileBytes, uint64_t maxPixels);

}  // namespace fh

// Files written whole or not at all: the content goes to a temporary file beside the
// target (same directory, same extension), which is checked, flushed to disk and renamed
// over the target. A full disk, a killed process or a failed check leaves the target as it
// was and no temporary file behind (short of a kill mid-write, which leaves only a
// hidden .fredholm-tmp file, never a cut-off target).
#pragma once
#include <functional>
#include <string>

namespace fh {

// `write(temp)` writes the file at path `temp` (throwing fh::Error on failure); `check(temp)`,
// if given, reads it back and throws if it is not what was written. Errors name `what`
// (the flag or role of the file) and `path`.
void writeAtomically(const std::string& path, const std::string& what,
                     const std::function<void(const std::string& temp)>& write,
                     const std::function<void(const std::string& temp)>& check = nullptr);

// The common case: text (or bytes) known in full.
void writeTextAtomically(const std::string& path, const std::string& what, const std::string& text);

}  // namespace fh

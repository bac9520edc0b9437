// Files written whole or not at all: the content goes to a temporary file beside the
// target (same directory, same extension), which is checked, flushed to disk and committed
// to the target's name. A full disk, a killed process or a failed check leaves the target as
// it was; no temporary file is left behind, short of SIGKILL (a hidden .fredholm-tmp file,
// never a cut-off target). A target an output plan reserved (base/output_plan.h) is written
// into its reservation and committed by the plan's rule; any other target is replaced.
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace fh {

// `write(temp)` writes the file at path `temp` (throwing fh::Error on failure); `check(temp)`,
// if given, reads it back and throws if it is not what was written. Errors name `what`
// (the flag or role of the file) and `path`. Returns the path written: `path`, or where a
// reservation stepped aside to.
std::string writeAtomically(const std::string& path, const std::string& what,
                            const std::function<void(const std::string& temp)>& write,
                            const std::function<void(const std::string& temp)>& check = nullptr);

// The common case: text (or bytes) known in full.
std::string writeTextAtomically(const std::string& path, const std::string& what, const std::string& text);

// For the output plan (base/output_plan.cpp): how a reserved target is committed.
enum class CommitRule {
  Replace,    // rename over whatever is there
  Keep,       // never replace: a file that appeared meanwhile stays, and the write steps
              // aside to the next free name (NAME-1.EXT, ...), reported by steppedAside()
  KeepQuiet,  // the same, for a name fredholm chose: stepping aside is no news
};
// Creates the target's temporary file now (throws fh::Error naming `what` if it cannot);
// the first write of `path` fills it and commits it by `rule`.
void reserveTarget(const std::string& path, const std::string& what, CommitRule rule);
// Removes the reservation's temporary file if no write used it.
void releaseTarget(const std::string& path);
// Targets reserved with CommitRule::Keep that were written elsewhere: {path, written}.
std::vector<std::pair<std::string, std::string>> steppedAside();

// NAME.EXT for n = 0, NAME-n.EXT otherwise: where an output steps aside to.
std::string numberedName(const std::string& path, int n);

// Removes every temporary file this process has open for writing; async-signal-safe, for
// a signal handler that ends the process at once (the second Ctrl-C).
void removeTemporariesNow();

}  // namespace fh

// One plan for every file a command writes. The command lists its outputs before any work;
// the plan checks them against each other and against the files the command reads, and
// reserves each by creating its temporary file beside it (proving the place writable before a
// render is spent on it). Every write (base/atomic_file.h) then fills its reservation and
// commits it without replacing a file that appeared meanwhile, unless --force said so.
#pragma once
#include <string>
#include <vector>

namespace fh {

enum class OutputKind {
  Named,    // a path the user gave: an existing file is replaced only with --force
  Default,  // a name fredholm chose (fredholm.png): steps aside to the next free name
  Owned,    // a file the command rewrites as it goes (--checkpoint): replaced each time
};

class OutputPlan {
 public:
  explicit OutputPlan(bool force) : force_(force) {}
  ~OutputPlan();  // gives back the reservations no write used
  OutputPlan(const OutputPlan&) = delete;
  OutputPlan& operator=(const OutputPlan&) = delete;

  // An output, named by its flag in errors. `mayReplace`: an input this output may replace
  // (the checkpoint a render resumes from and saves again).
  void add(const std::string& path, const std::string& what, OutputKind kind = OutputKind::Named,
           const std::string& mayReplace = "");
  // Checks the outputs (each writable, not a directory, none twice, none existing unless
  // --force or fredholm's own) and reserves them. Throws fh::Error naming the flag.
  void reserve();
  // After the inputs are read (base/input_file.h records them): no output is one of them.
  void checkAgainstInputs() const;
  // Where an output named by the user had to step aside at its commit (a file appeared at
  // its path during the work), throws fh::Error saying where each was written instead.
  void finish() const;

 private:
  struct Entry {
    std::string path, what, mayReplace;
    OutputKind kind;
  };
  bool force_;
  std::vector<Entry> entries_;
};

}  // namespace fh

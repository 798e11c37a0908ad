// src/sweep/sweep_file_systems.h — the systems a sweep file's `systems` axes
// name: built-in names, and system files read once each (through the
// caller's SystemFileReader), compiled to check them, named by their
// `name`. Internal to the parser.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "phnn/sweep/sweep_file.h"
#include "sweep/sweep_file_source.h"

namespace phnn {

class SweepSystems {
 public:
  SweepSystems(const SweepSource& source, SystemFileReader read)
      : source_(source), read_(std::move(read)) {}

  /// The system's name of a `systems` value written at `line`: a built-in
  /// name as is; a system file's `name`, reading and compiling the file the
  /// first time. Fails at `line` when the file cannot be read or another
  /// system file has its name; a bad file fails at its own FILE:LINE.
  std::string resolve(const std::string& value, int line);

  /// Fails when a system file is named like a built-in system the sweep
  /// also lists: their runs and tables could not be told apart.
  void check_names() const;

  const std::vector<SweepSystemFile>& files() const { return files_; }
  /// The file (system or data-set file) of system `name`, or nullptr.
  const SweepSystemFile* file(const std::string& name) const;

 private:
  std::string load(const std::string& entry, int line);

  const SweepSource& source_;
  SystemFileReader read_;
  std::vector<SweepSystemFile> files_;
  std::vector<int> file_lines_;             // where each file was first named
  std::map<std::string, int> builtin_lines_;  // built-in name -> first line
};

}  // namespace phnn

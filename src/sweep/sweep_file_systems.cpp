// src/sweep/sweep_file_systems.cpp — the systems a sweep file names, and the
// checks of its system files (sweeps/FORMAT.md, "System files in sweeps").
#include "sweep/sweep_file_systems.h"

#include <memory>

#include "phnn/config/run_config.h"
#include "phnn/systems/system_file.h"
#include "sweep/sweep_file_values.h"

namespace phnn {
namespace {

// SystemFileError's what() without its "FILE:LINE: " prefix.
std::string message_of(const SystemFileError& e) {
  const std::string what = e.what();
  const std::string prefix =
      e.file() + (e.line() > 0 ? ":" + std::to_string(e.line()) : std::string()) + ": ";
  return what.compare(0, prefix.size(), prefix) == 0 ? what.substr(prefix.size()) : what;
}

}  // namespace

const SweepSystemFile* SweepSystems::file(const std::string& name) const {
  for (const SweepSystemFile& f : files_) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

std::string SweepSystems::resolve(const std::string& value, int line) {
  if (is_data_file_entry(value)) return load(value, line);
  if (is_system_file_argument(value)) return load(system_file_path(value), line);
  builtin_lines_.emplace(value, line);
  return value;
}

std::string SweepSystems::load(const std::string& entry, int line) {
  for (const SweepSystemFile& f : files_) {
    if (f.entry == entry) return f.name;
  }
  if (!read_) {
    source_.fail(line, "system file " + quoted(entry) +
                           " cannot be read here (no directory to resolve it in); parse the "
                           "sweep from its file");
  }
  SweepSystemFile file;
  file.entry = entry;
  SystemFileText source;
  try {
    source = read_(entry);
  } catch (const std::exception& e) {
    source_.fail(line, "systems value " + quoted(entry) + ": " + e.what());
  }
  file.text = source.text;
  if (is_data_file_entry(entry) && source.data_checksum.empty()) {
    source_.fail(line, "data value " + quoted(entry) + " was read as a system file; it must be a "
                           "data-set file written by `phnn data` or `phnn import`");
  }
  std::unique_ptr<PhSystem> system;
  try {
    system = compile_system(file.text, source.shown_as);
  } catch (const SystemFileError& e) {
    throw SweepFileError(e.file(), e.line(), message_of(e));
  }
  if (!is_data_file_entry(entry) && !source.data_supplied && !system->has_energy()) {
    source_.fail(line, "system file " + quoted(entry) + " defines no energy H (structure only), so "
                           "the sweep cannot generate its data; import recordings with `phnn import "
                           "... --system " + entry + " --out DATA.h5` and list DATA.h5 under data = "
                           "[...], or add H, z, [initial] and [control] to the system file");
  }
  file.name = system->name();
  file.n_x = system->n_x();
  file.n_w = system->n_w();
  file.n_u = system->n_u();
  file.text_hash = hex64(fnv1a64(file.text));
  if (is_data_file_entry(entry)) {
    // Named by the file's stem ("noisy" of "data/noisy.h5"); its runs'
    // identity covers the contents.
    const std::size_t slash = entry.rfind('/');
    file.name = entry.substr(slash == std::string::npos ? 0 : slash + 1);
    file.name.resize(file.name.size() - 3);
    file.data_checksum = source.data_checksum;
    file.data_train_pairs = source.data_train_pairs;
    file.data_inference = source.data_inference;
    file.data_inference_points = source.data_inference_points;
    file.path = source.shown_as;
    file.text_hash = hex64(fnv1a64(file.text + "\n# data " + file.data_checksum));
    if (file.name.empty() || find_system(file.name)) {
      source_.fail(line, "data-set file " + quoted(entry) + " is named " + quoted(file.name) +
                             " by its stem, which " + (file.name.empty() ? "is empty" : "is a built-in system's name") +
                             "; rename the file");
    }
  }
  for (const SweepSystemFile& other : files_) {
    if (other.name == file.name) {
      source_.fail(line, "system files " + quoted(other.entry) + " and " + quoted(entry) +
                             " are both named " + quoted(file.name) +
                             "; give each system file its own `name` (a data-set file is named "
                             "by its file name without .h5)");
    }
  }
  files_.push_back(file);
  file_lines_.push_back(line);
  return file.name;
}

void SweepSystems::check_names() const {
  for (std::size_t i = 0; i < files_.size(); ++i) {
    const auto builtin = builtin_lines_.find(files_[i].name);
    if (builtin == builtin_lines_.end()) continue;
    source_.fail(builtin->second,
                 "the built-in system " + quoted(files_[i].name) + " and the system file " +
                     quoted(files_[i].entry) + " (line " + std::to_string(file_lines_[i]) +
                     ") have the same name, so their runs and tables could not be told apart; "
                     "change the file's `name`, or list only one of them");
  }
}

}  // namespace phnn

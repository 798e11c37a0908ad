// src/sweep/sweep_file.cpp — the sweep-file parser's entry points (format:
// sweeps/FORMAT.md): reading the file safely (regular file, size cap), then
// toml++ (sweep_file_syntax.cpp) and the table walk onto the defaults of
// docs/METHOD.md (sweep_file_tables.cpp, values in sweep_file_values.cpp).
#include "phnn/sweep/sweep_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>

#include "phnn/config/run_config.h"
#include "phnn/integrators/integrator.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"
#include "sweep/sweep_file_source.h"
#include "sweep/sweep_file_tables.h"

namespace phnn {

SweepFileError::SweepFileError(const std::string& file, int line, const std::string& message)
    : std::invalid_argument(line > 0 ? file + ":" + std::to_string(line) + ": " + message
                                     : file + ": " + message),
      file_(file),
      line_(line),
      message_(message) {}

std::string model_key(ModelKind kind, IntegratorKind integrator) {
  return to_string(kind) + "-" + to_string(integrator);
}

std::vector<std::pair<ModelKind, IntegratorKind>> all_model_pairs() {
  return {{ModelKind::kNode, IntegratorKind::kRk2},
          {ModelKind::kPhnnJr, IntegratorKind::kDg},
          {ModelKind::kPhnnJr, IntegratorKind::kRk2},
          {ModelKind::kPhnnS, IntegratorKind::kDg},
          {ModelKind::kPhnnS, IntegratorKind::kRk2}};
}

std::vector<std::pair<ModelKind, IntegratorKind>> known_model_pairs() {
  // The paper's five, then every other model an integrator of the table
  // allows (NODE: no discrete gradient), integrator by integrator.
  auto pairs = all_model_pairs();
  for (const Integrator& in : all_integrators()) {
    for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnJr, ModelKind::kPhnnS}) {
      const std::pair<ModelKind, IntegratorKind> pair{kind, in.kind};
      if ((kind == ModelKind::kNode && in.discrete_gradient) ||
          std::find(pairs.begin(), pairs.end(), pair) != pairs.end()) {
        continue;
      }
      pairs.push_back(pair);
    }
  }
  return pairs;
}

std::vector<std::string> known_model_keys() {
  std::vector<std::string> keys;
  for (const auto& [kind, integrator] : known_model_pairs()) {
    keys.push_back(model_key(kind, integrator));
  }
  return keys;
}

const SweepSystemFile* SweepSpec::system_file(const std::string& system_name) const {
  for (const SweepSystemFile& f : system_files) {
    if (f.name == system_name) return &f;
  }
  return nullptr;
}

std::string sweep_hash(const std::string& text, const std::vector<SweepSystemFile>& files) {
  if (files.empty()) return hex64(fnv1a64(text));  // every sweep made before system files
  std::string all = text;
  for (const SweepSystemFile& f : files) {
    all += '\0' + f.entry + '\0' + f.text;
    if (f.is_data()) all += "\0data " + f.data_checksum;  // a data-set file's contents
  }
  return hex64(fnv1a64(all));
}

SweepSpec parse_sweep_text(const std::string& text, const std::string& display_name,
                           const SystemFileReader& read_system_file) {
  if (text.size() > kMaxSweepFileBytes) {
    throw SweepFileError(display_name, 0, std::to_string(text.size()) + " bytes, more than the " +
                                              std::to_string(kMaxSweepFileBytes) +
                                              " a sweep file may have (its text is stored in "
                                              "the results file)");
  }
  const SweepSource source(display_name, text);
  SweepSpec spec = resolve_sweep_tables(parse_sweep_toml(source), source, read_system_file);
  spec.source_path = display_name;
  spec.text = text;
  spec.text_hash = sweep_hash(text, spec.system_files);
  return spec;
}

namespace {

// A `data` entry read from disk: the system text it stores, the checksum of
// its contents and its training pairs.
SystemFileText read_data_file_entry(const std::string& file) {
  const PhSystemData data = read_ph_dataset_file(file);
  SystemFileText t{file, data.system_text};
  describe_data_file(data, &t);
  return t;
}

}  // namespace

SweepSpec parse_sweep_file(const std::string& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    throw SweepFileError(path, 0,
                         "cannot open the sweep file (" + std::string(std::strerror(errno)) +
                             "); check the path (sweep files live in sweeps/, e.g. "
                             "sweeps/paper.toml)");
  }
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    throw SweepFileError(path, 0, "not a regular file (a FIFO, device, directory or socket); "
                                  "a sweep file is a text file, e.g. sweeps/paper.toml");
  }
  if (static_cast<std::uint64_t>(st.st_size) > kMaxSweepFileBytes) {
    throw SweepFileError(path, 0, std::to_string(st.st_size) + " bytes, more than the " +
                                      std::to_string(kMaxSweepFileBytes) +
                                      " a sweep file may have (its text is stored in the "
                                      "results file); use [study.*] tables and seed ranges");
  }
  std::string text(kMaxSweepFileBytes + 1, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw SweepFileError(path, 0, "cannot read the sweep file: " + std::string(std::strerror(errno)));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  // System files: relative to the sweep file's directory.
  const std::size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  return parse_sweep_text(text, path, [&dir](const std::string& entry) {
    const std::string file = !entry.empty() && entry[0] == '/' ? entry : dir + entry;
    if (is_data_file_entry(entry)) return read_data_file_entry(file);
    return SystemFileText{file, read_system_file_text(file)};
  });
}

}  // namespace phnn

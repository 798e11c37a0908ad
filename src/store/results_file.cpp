// src/store/results_file.cpp — ResultsFile: opening (with the checks that
// name what a path is if it is not our file), closing, file attributes, the
// /data groups; the helpers that make every rank fail together. Creation:
// results_file_create.cpp; rows: results_file_rows.cpp; run times and
// provenance sessions: results_file_sessions.cpp.
#include "phnn/store/results_file.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "phnn/store/ph_dataset_file.h"
#include "store/dataset_file_io.h"
#include "store/results_file_internal.h"

namespace phnn {
namespace results_io {


int comm_rank(MPI_Comm comm) {
  int rank = 0;
  if (comm != MPI_COMM_NULL) MPI_Comm_rank(comm, &rank);
  return rank;
}

int comm_size(MPI_Comm comm) {
  int size = 1;
  if (comm != MPI_COMM_NULL) MPI_Comm_size(comm, &size);
  return size;
}

// Rank `root`'s string on every rank (serial: unchanged).
std::string broadcast(MPI_Comm comm, std::string text, int root) {
  if (comm == MPI_COMM_NULL) return text;
  unsigned long long n = text.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, root, comm);
  text.resize(n);
  if (n > 0) MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, root, comm);
  return text;
}

// Rank 0 runs `check` (which returns an error message or ""); every rank
// throws the same error, so none is left waiting in a collective call
// (docs/DECISIONS.md, "No rank waits forever").
void check_on_rank0(MPI_Comm comm, const std::function<std::string()>& check) {
  std::string error;
  if (comm_rank(comm) == 0) {
    try {
      error = check();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  error = broadcast(comm, error);
  if (!error.empty()) throw std::runtime_error(error);
}

// Message truncated to `length` bytes, ending in "...", not splitting a UTF-8
// character.
std::string truncate_message(const std::string& text, std::size_t length) {
  if (text.size() <= length) return text;
  std::size_t cut = length - 3;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return text.substr(0, cut) + "...";
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// Runs collective HDF5 code. Serial: exceptions propagate. Parallel: an
// exception is printed with the rank prefix and ends the job (docs/DECISIONS.md,
// "No rank waits forever"), since the other ranks would wait for this one forever.
void collective_or_abort(MPI_Comm comm, const std::function<void()>& body) {
  try {
    body();
  } catch (const std::exception& e) {
    if (comm == MPI_COMM_NULL) throw;
    std::fprintf(stderr, "[rank %d/%d] %s\n", comm_rank(comm), comm_size(comm), e.what());
    std::fflush(stderr);
    MPI_Abort(comm, 1);
  }
}

}  // namespace results_io

using namespace results_io;

namespace {

// Why `path` cannot be opened as a results file ("" if it can): missing, not
// HDF5, not ours, another format version, or (if expected_hash is given)
// another sweep.
std::string results_file_problem(const std::string& path, const std::string* expected_hash) {
  if (::access(path.c_str(), F_OK) != 0) {
    return expected_hash != nullptr
               ? path + ": no such results file; check the path, or start a new sweep "
                        "instead of resuming"
               : path + ": no such results file; check the path (results files are written "
                        "by `phnn sweep` and `phnn train --out`)";
  }
  // Resuming (expected_hash): the file is in the way of a new one. Reading:
  // the user named the wrong file; never advise deleting it.
  const std::string fix = expected_hash != nullptr
                              ? "; pass a new --out path or delete the file"
                              : "; give a results file written by `phnn sweep` or `phnn train "
                                "--out`";
  if (!h5::File::is_hdf5(path)) {
    const bool toml = path.size() > 5 && path.compare(path.size() - 5, 5, ".toml") == 0;
    return path + ": not an HDF5 file, so not a phnn results file" +
           (toml && expected_hash == nullptr
                ? "; this looks like a sweep file: give the results file its sweep wrote "
                  "(its `output`, e.g. results/<name>.h5)"
                : fix);
  }
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  const std::string format = file.has_attribute("/", "format")
                                 ? file.string_attribute("/", "format")
                                 : std::string("(missing)");
  if (format != ResultsFile::kFormat) {
    return path + ": not a phnn results file (attribute format = \"" + format +
           "\", expected \"" + ResultsFile::kFormat +
           "\")" + fix;
  }
  const std::int64_t version = file.int_attribute("/", "format_version");
  if (version != ResultsFile::kFormatVersion) {
    return path + ": results format version " + std::to_string(version) +
           ", this program reads version " + std::to_string(ResultsFile::kFormatVersion) +
           "; use the program that wrote it (" +
           file.string_attribute("/", "program_version") + ")";
  }
  if (expected_hash != nullptr) {
    const std::string hash = file.string_attribute("/", "sweep_hash");
    if (hash != *expected_hash) {
      return path + " was written by sweep '" + file.string_attribute("/", "sweep_name") +
             "' (hash " + hash + "), not by this sweep file (hash " + *expected_hash +
             "); pass a new --out path or delete the file";
    }
  }
  return "";
}

}  // namespace

ResultsLayout ResultsLayout::for_runs(const std::vector<RunConfig>& runs) {
  ResultsLayout layout;
  if (runs.empty()) return layout;
  layout.num_inference = layout.trace_points = layout.figure_points = 1;
  for (const RunConfig& run : runs) {
    layout.num_inference =
        std::max({layout.num_inference, run.data.num_inference, run.data_inference});
    if (run.training.eval_every > 0) {
      layout.trace_points =
          std::max(layout.trace_points, run.training.steps / run.training.eval_every + 2);
    }
    layout.figure_points = std::max(
        {layout.figure_points, run.data.num_inference_steps() + 1, run.data_inference_points});
    layout.figure_states = std::max(layout.figure_states, run.n_x);
    layout.checkpoints =
        std::max(layout.checkpoints, static_cast<int>(run.training.checkpoints.size()));
  }
  layout.weights = true;
  return layout;
}

void ResultsLayout::validate() const {
  auto check = [](int value, int lowest, const char* name) {
    require(value >= lowest, "Invalid ResultsLayout: " + std::string(name) + " = " +
                                 std::to_string(value) + "; violated constraint: " + name +
                                 (lowest == 1 ? " > 0." : " >= 0."));
  };
  check(num_inference, 1, "num_inference");
  check(trace_points, 1, "trace_points");
  check(figure_points, 1, "figure_points");
  check(figure_states, 1, "figure_states");
  check(checkpoints, 0, "checkpoints");
}

ResultsFile::ResultsFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ResultsFile::ResultsFile(ResultsFile&& other) noexcept = default;
ResultsFile& ResultsFile::operator=(ResultsFile&& other) noexcept {
  if (this != &other) {
    close();
    impl_ = std::move(other.impl_);
  }
  return *this;
}

ResultsFile::~ResultsFile() {
  if (impl_ && impl_->open) {
    try {
      close();
    } catch (...) {
    }
  }
}

ResultsFile ResultsFile::open(const std::string& path, MPI_Comm comm,
                              const std::string& expected_sweep_hash) {
  check_on_rank0(comm, [&] { return results_file_problem(path, &expected_sweep_hash); });
  std::unique_ptr<Impl> impl;
  collective_or_abort(comm, [&] {
    impl = std::make_unique<Impl>(h5::File::open(path, h5::Access::kReadWrite, comm), comm);
  });
  return ResultsFile(std::move(impl));
}

ResultsFile ResultsFile::open_read_only(const std::string& path) {
  const std::string problem = results_file_problem(path, nullptr);
  if (!problem.empty()) throw std::runtime_error(problem);
  return ResultsFile(
      std::make_unique<Impl>(h5::File::open(path, h5::Access::kReadOnly), MPI_COMM_NULL));
}

const std::string& ResultsFile::path() const { return impl_->file.path(); }
int ResultsFile::num_runs() const { return impl_->num_runs; }
const ResultsLayout& ResultsFile::layout() const { return impl_->layout; }

std::string ResultsFile::sweep_name() const {
  return impl_->independent([&] { return impl_->file.string_attribute("/", "sweep_name"); });
}
std::string ResultsFile::sweep_text() const {
  return impl_->independent([&] { return impl_->file.string_attribute("/", "sweep_text"); });
}
std::string ResultsFile::sweep_hash() const {
  return impl_->independent([&] { return impl_->file.string_attribute("/", "sweep_hash"); });
}
std::string ResultsFile::program_version() const {
  return impl_->independent(
      [&] { return impl_->file.string_attribute("/", "program_version"); });
}
std::string ResultsFile::created() const {
  return impl_->independent([&] { return impl_->file.string_attribute("/", "created"); });
}

namespace {
std::string data_group(const std::string& system_name) {
  require(!system_name.empty() && system_name.find('/') == std::string::npos,
          "ResultsFile: system name \"" + system_name +
              "\" cannot name a group; expected a non-empty name without '/'");
  return "/data/" + system_name;
}
}  // namespace

void ResultsFile::store_data_group(const std::string& system_name,
                                   const std::function<void(const std::string&)>& write) {
  const std::string group = data_group(system_name);
  // Every rank sees the same file state, so all throw together.
  require(!has_system_data(system_name),
          path() + ": " + group + " is already stored; check has_system_data() first");
  impl_->collective([&] {
    impl_->file.remove(group);  // a group left incomplete by a crash
    write(group);
    if (impl_->checksum_version == 2) {
      // Rank 0 reads what it wrote (after the flush every rank could).
      impl_->file.flush();
      const std::string digest =
          broadcast(impl_->comm, impl_->rank == 0 ? group_digest(impl_->file, group) : "");
      impl_->file.set_attribute(group, kDigestAttribute, digest);
    }
    impl_->file.set_attribute(group, "complete", std::int64_t{1});
    impl_->file.flush();
  });
}

bool ResultsFile::has_system_data(const std::string& system_name) const {
  const std::string group = data_group(system_name);
  return impl_->independent([&] { return impl_->file.has_attribute(group, "complete"); });
}

void ResultsFile::store_system_data(const std::string& system_name, const PhSystemData& data,
                                    const std::string& sweep_entry) {
  store_data_group(system_name, [&](const std::string& group) {
    internal::write_ph_system_data(impl_->file, group, data);
    if (!sweep_entry.empty()) impl_->file.set_attribute(group, "sweep_entry", sweep_entry);
  });
}

PhSystemData ResultsFile::read_system_data(const std::string& system_name) const {
  const std::string group = data_group(system_name);
  return impl_->independent([&] { return internal::read_ph_system_data(impl_->file, group); });
}

SystemFileReader ResultsFile::stored_system_files() const {
  std::vector<SystemFileText> texts;
  std::vector<std::string> entries;
  impl_->independent([&] {
    if (!impl_->file.exists("/data")) return 0;
    for (const std::string& name : impl_->file.link_names("/data")) {
      const std::string group = "/data/" + name;
      if (!impl_->file.has_attribute(group, "sweep_entry") ||
          !impl_->file.has_attribute(group, "complete")) {
        continue;
      }
      entries.push_back(impl_->file.string_attribute(group, "sweep_entry"));
      texts.push_back({path() + "@" + group, impl_->file.string_attribute(group, "system_file")});
      texts.back().data_supplied = true;  // the data set is stored beside it
      if (is_data_file_entry(entries.back())) {  // a `data` file: its stored copy
        const PhSystemData data = internal::read_ph_system_data(impl_->file, group);
        describe_data_file(data, &texts.back());
      }
    }
    return 0;
  });
  const std::string file = path();
  return [entries, texts, file](const std::string& entry) {
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (entries[i] == entry) return texts[i];
    }
    throw std::runtime_error(file + " stores no system file " + entry +
                             " (its /data group is missing: the sweep that made it stopped "
                             "before storing it; run the sweep again to complete the file)");
  };
}

void ResultsFile::close() {
  if (!impl_ || !impl_->open) return;
  impl_->open = false;
  impl_->file.close();
}

}  // namespace phnn

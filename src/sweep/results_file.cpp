// src/sweep/results_file.cpp
#include "phnn/sweep/results_file.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>

#include "phnn/common/utc_time.h"
#include "data/dataset_file_io.h"
#include "h5/h5file.h"

namespace phnn {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kIdLength = 16;
constexpr std::size_t kNameLength = 32;
// The root object header holds each attribute in one message of < 64 KiB.
constexpr std::size_t kMaxSweepText = 60000;
constexpr int kTraceColumns = 7;

// Dataset names (docs/RESULTS_FORMAT.md).
const std::string kRuns = "/runs/";
const std::string kId = "/runs/id";
const std::string kCanonical = "/runs/canonical";
const std::string kSystem = "/runs/system";
const std::string kModel = "/runs/model";
const std::string kIntegrator = "/runs/integrator";
const std::string kSize = "/runs/size";
const std::string kRegularizer = "/runs/regularizer";
const std::string kNTrain = "/runs/n_train";
const std::string kSeed = "/runs/seed";
const std::string kStudies = "/runs/studies";
const std::string kStatus = "/runs/status";
const std::string kMessage = "/runs/message";
const std::string kMse = "/runs/mse";
const std::string kTrajectoryErrors = "/runs/trajectory_errors";
const std::string kTrajectoryErrorsLength = "/runs/trajectory_errors_length";
const std::string kDivergedRollouts = "/runs/diverged_rollouts";
const std::string kBestStep = "/runs/best_step";
const std::string kBestValidationLoss = "/runs/best_validation_loss";
const std::string kWallTime = "/runs/wall_time_s";
const std::string kSteps = "/runs/steps";
const std::string kParameterCount = "/runs/parameter_count";
const std::string kNewtonFailures = "/runs/newton_failures";
const std::string kTrace = "/runs/trace";
const std::string kTraceLength = "/runs/trace_length";
const std::string kPrediction05 = "/runs/figure/prediction_05";
const std::string kPrediction075 = "/runs/figure/prediction_075";
const std::string kReference05 = "/runs/figure/reference_05";
const std::string kReference075 = "/runs/figure/reference_075";
const std::string kFigureLength = "/runs/figure/length";
const std::string kCheckpointSteps = "/runs/checkpoint_steps";
const std::string kCheckpointMse = "/runs/checkpoint_mse";
const std::string kCheckpointTrainSeconds = "/runs/checkpoint_train_seconds";
// Added with provenance; files written before them have neither.
const std::string kStartedUtc = "/runs/started_utc";
const std::string kFinishedUtc = "/runs/finished_utc";
const std::string kProvenance = "/provenance";
constexpr std::size_t kUtcLength = 20;  // "2024-05-01T12:00:00Z"

const std::string kStateUnits = "q [m], p [kg m/s]";
const std::string kMseUnits =
    "m^2 and (kg m/s)^2 mixed: mean of ||x - x_hat||^2 over the inference "
    "trajectories and steps (docs/METHOD.md section 5); +inf if a rollout diverged";
const std::string kLossUnits =
    "m/s and kg m/s^2 mixed: L_d = mean |x_{n+1} - x_hat_{n+1}| / h (+ regularizer)";
const std::string kFileUnits =
    "SI units. States q [m], p [kg m/s]; time [s]; energy [J]; mse in m^2 and "
    "(kg m/s)^2 mixed (mean of ||x - x_hat||^2); losses in m/s and kg m/s^2 mixed "
    "(mean |x_{n+1} - x_hat_{n+1}| / h); kappa and rho dimensionless; sigma_max in "
    "1/s. Every dataset of /runs has a units attribute.";

std::string dirname_of(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}


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
std::string broadcast(MPI_Comm comm, std::string text, int root = 0) {
  if (comm == MPI_COMM_NULL) return text;
  unsigned long long n = text.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, root, comm);
  text.resize(n);
  if (n > 0) MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, root, comm);
  return text;
}

// Rank 0 runs `check` (which returns an error message or ""); every rank
// throws the same error, so none is left waiting in a collective call
// (STYLE.md policy 1).
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
  if (!h5::File::is_hdf5(path)) {
    return path + ": not an HDF5 file, so not a phnn results file; pass a new --out "
                  "path or delete the file";
  }
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  const std::string format = file.has_attribute("/", "format")
                                 ? file.string_attribute("/", "format")
                                 : std::string("(missing)");
  if (format != ResultsFile::kFormat) {
    return path + ": not a phnn results file (attribute format = \"" + format +
           "\", expected \"" + ResultsFile::kFormat +
           "\"); pass a new --out path or delete the file";
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

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// Runs collective HDF5 code. Serial: exceptions propagate. Parallel: an
// exception is printed with the rank prefix and ends the job (STYLE.md
// policy 4), since the other ranks would wait for this one forever.
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

}  // namespace

ResultsLayout ResultsLayout::for_runs(const std::vector<RunConfig>& runs) {
  ResultsLayout layout;
  if (runs.empty()) return layout;
  layout.num_inference = layout.trace_points = layout.figure_points = 1;
  for (const RunConfig& run : runs) {
    layout.num_inference = std::max(layout.num_inference, run.data.num_inference);
    if (run.training.eval_every > 0) {
      layout.trace_points =
          std::max(layout.trace_points, run.training.steps / run.training.eval_every + 2);
    }
    layout.figure_points =
        std::max(layout.figure_points, run.data.num_inference_steps() + 1);
    layout.checkpoints =
        std::max(layout.checkpoints, static_cast<int>(run.training.checkpoints.size()));
  }
  return layout;
}

void ResultsLayout::validate() const {
  require(num_inference > 0, "Invalid ResultsLayout: num_inference = " +
                                 std::to_string(num_inference) +
                                 "; violated constraint: num_inference > 0.");
  require(trace_points > 0, "Invalid ResultsLayout: trace_points = " +
                                std::to_string(trace_points) +
                                "; violated constraint: trace_points > 0.");
  require(figure_points > 0, "Invalid ResultsLayout: figure_points = " +
                                 std::to_string(figure_points) +
                                 "; violated constraint: figure_points > 0.");
  require(checkpoints >= 0, "Invalid ResultsLayout: checkpoints = " + std::to_string(checkpoints) +
                                "; violated constraint: checkpoints >= 0.");
}

struct ResultsFile::Impl {
  h5::File file;
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0;
  int size = 1;
  bool open = true;
  int num_runs = 0;
  ResultsLayout layout;
  bool has_run_times = false;  // false in files written before provenance
  std::string session;         // this process's /provenance/session_<k>

  Impl(h5::File f, MPI_Comm c)
      : file(std::move(f)), comm(c), rank(comm_rank(c)), size(comm_size(c)) {
    read_layout();
  }

  void read_layout() {
    num_runs = static_cast<int>(file.dims(kId).at(0));
    layout.num_inference = static_cast<int>(file.dims(kTrajectoryErrors).at(1));
    layout.trace_points = static_cast<int>(file.dims(kTrace).at(1));
    layout.figure_points = static_cast<int>(file.dims(kPrediction05).at(1));
    layout.checkpoints =
        file.exists(kCheckpointMse) ? static_cast<int>(file.dims(kCheckpointMse).at(1)) : 0;
    has_run_times = file.exists(kStartedUtc) && file.exists(kFinishedUtc);
  }

  // "[rank 3/8] " in a parallel file, "" in a serial one.
  std::string prefix() const {
    if (comm == MPI_COMM_NULL) return "";
    return "[rank " + std::to_string(rank) + "/" + std::to_string(size) + "] ";
  }

  // Independent I/O: h5::Error gets the rank prefix.
  template <class F>
  auto independent(F&& body) const -> decltype(body()) {
    if (!open) throw std::logic_error(prefix() + file.path() + ": used after close()");
    try {
      return body();
    } catch (const h5::Error& e) {
      if (comm == MPI_COMM_NULL) throw;
      throw h5::Error(prefix() + e.what());
    }
  }

  void collective(const std::function<void()>& body) {
    if (!open) throw std::logic_error(prefix() + file.path() + ": used after close()");
    collective_or_abort(comm, body);
  }

  std::vector<std::string> strings(const std::string& name) const {
    return independent([&] { return file.read_strings(name); });
  }
  std::vector<std::int64_t> ints(const std::string& name, std::uint64_t row = 0,
                                 std::uint64_t count = 0) const {
    return independent([&] { return file.read_ints(name, row, count); });
  }
  std::vector<double> doubles(const std::string& name, std::uint64_t row = 0,
                              std::uint64_t count = 0) const {
    return independent([&] { return file.read_doubles(name, row, count); });
  }
};

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

namespace {

// The config columns of /runs, one entry per run, validated (policy 1: every
// rank has the same arguments, so these throw everywhere).
struct ConfigColumns {
  std::vector<std::string> ids, canonical, systems, models, integrators, sizes, regularizers;
  std::vector<std::int64_t> n_train, seeds;

  ConfigColumns(const std::vector<RunConfig>& runs, const std::vector<std::string>& run_studies,
                const std::string& where) {
    std::map<std::string, std::size_t> row_of_id;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const RunConfig& run = runs[i];
      canonical.push_back(run.canonical());
      ids.push_back(run.id());
      require(canonical[i].size() <= kCanonicalLength,
              where + "run " + std::to_string(i) + " has a canonical config of " +
                  std::to_string(canonical[i].size()) + " bytes, more than " +
                  std::to_string(kCanonicalLength) + ": " + canonical[i]);
      require(run_studies[i].size() <= kStudiesLength,
              where + "run " + std::to_string(i) + " has studies \"" + run_studies[i] +
                  "\", longer than " + std::to_string(kStudiesLength) + " bytes");
      const auto [it, inserted] = row_of_id.emplace(ids[i], i);
      require(inserted, where + "runs " + std::to_string(it->second) + " and " +
                            std::to_string(i) + " are the same run (id " + ids[i] +
                            "); the grid must list each run once");
      systems.push_back(to_string(run.system));
      models.push_back(to_string(run.model));
      integrators.push_back(to_string(run.integrator));
      sizes.push_back(to_string(run.size));
      regularizers.push_back(to_string(run.regularizer));
      n_train.push_back(run.n_train);
      seeds.push_back(run.seed);
    }
  }
};

// Creates datasets of R rows with their `units` attribute.
struct DatasetMaker {
  h5::File& file;
  std::uint64_t rows;

  void text(const std::string& name, std::size_t length, const std::string& units) const {
    file.create_dataset(name, h5::Type::kString, {rows}, length);
    file.set_attribute(name, "units", units);
  }
  void ints(const std::string& name, std::vector<std::uint64_t> dims,
            const std::string& units) const {
    file.create_dataset(name, h5::Type::kInt64, dims);
    file.set_attribute(name, "units", units);
  }
  // Filled with NaN: a pending row reads as NaN.
  void floats(const std::string& name, std::vector<std::uint64_t> dims,
              const std::string& units) const {
    file.create_dataset(name, h5::Type::kFloat64, dims, /*string_length=*/0, /*fill_value=*/kNaN);
    file.set_attribute(name, "units", units);
  }
};

void create_config_datasets(const DatasetMaker& make) {
  const std::uint64_t R = make.rows;
  make.text(kId, kIdLength, "RunConfig::id(): FNV-1a 64 of canonical, 16 hex digits");
  make.text(kCanonical, kCanonicalLength, "RunConfig::canonical()");
  make.text(kSystem, kNameLength, "harmonic, duffing or self-sustained");
  make.text(kModel, kNameLength, "node, phnn-s or phnn-jr");
  make.text(kIntegrator, kNameLength, "rk2, dg, rk4 or dg4");
  make.text(kSize, kNameLength, "small, medium or large");
  make.text(kRegularizer, kNameLength, "none, cn, sn or sr");
  make.ints(kNTrain, {R}, "training pairs");
  make.ints(kSeed, {R}, "model initialization seed");
  make.text(kStudies, kStudiesLength, "comma-separated studies of the run, e.g. I,II,III");
}

void create_result_datasets(const DatasetMaker& make, const ResultsLayout& layout) {
  const std::uint64_t R = make.rows;
  const auto I = static_cast<std::uint64_t>(layout.num_inference);
  make.ints(kStatus, {R}, "0 pending, 1 done, 2 diverged, 3 failed");
  make.text(kMessage, kMessageLength, "why a run diverged or failed (truncated)");
  make.floats(kMse, {R}, kMseUnits);
  make.floats(kTrajectoryErrors, {R, I}, kMseUnits + "; per inference trajectory");
  make.ints(kTrajectoryErrorsLength, {R}, "valid entries of trajectory_errors");
  make.ints(kDivergedRollouts, {R}, "inference rollouts that diverged");
  make.ints(kBestStep, {R}, "Adam step of the best validation loss");
  make.floats(kBestValidationLoss, {R}, kLossUnits);
  make.floats(kWallTime, {R}, "s");
  make.ints(kSteps, {R}, "Adam steps");
  make.ints(kParameterCount, {R}, "trainable parameters");
  make.ints(kNewtonFailures, {R}, "DG inference steps whose Newton did not converge");
  make.text(kStartedUtc, kUtcLength,
            "UTC, ISO 8601: when training of the run's work item started; empty if pending "
            "or recovered from a journal");
  make.text(kFinishedUtc, kUtcLength, "UTC, ISO 8601: when the run's work item finished");
}

void create_trace_and_figure_datasets(const DatasetMaker& make, const ResultsLayout& layout) {
  const std::uint64_t R = make.rows;
  const auto T = static_cast<std::uint64_t>(layout.trace_points);
  const auto F = static_cast<std::uint64_t>(layout.figure_points);
  make.floats(kTrace, {R, T, kTraceColumns},
              "step [1], elapsed_s [s], train_loss and validation_loss [" + kLossUnits +
                  "], kappa [1], sigma_max [1/s], rho [1]; NaN after trace_length");
  make.file.set_attribute(kTrace, "columns",
                          std::string("step, elapsed_s, train_loss, validation_loss, kappa, "
                                      "sigma_max, rho"));
  make.ints(kTraceLength, {R}, "valid points of trace");
  const std::string figure = kStateUnits + " per point; NaN after figure/length";
  make.floats(kPrediction05, {R, F, 2}, figure + "; model rollout from H(x0) = 0.5 J");
  make.floats(kPrediction075, {R, F, 2}, figure + "; model rollout from H(x0) = 0.75 J");
  make.floats(kReference05, {R, F, 2}, figure + "; reference from H(x0) = 0.5 J");
  make.floats(kReference075, {R, F, 2}, figure + "; reference from H(x0) = 0.75 J");
  make.ints(kFigureLength, {R, 4}, "valid points of each figure trajectory");
  make.file.set_attribute(kFigureLength, "columns",
                          std::string("prediction_05, prediction_075, reference_05, "
                                      "reference_075"));
  if (layout.checkpoints > 0) {
    const auto K = static_cast<std::uint64_t>(layout.checkpoints);
    make.ints(kCheckpointSteps, {R, K}, "step budgets (TrainerOptions::checkpoints); 0 after the "
                                        "run's own count");
    make.floats(kCheckpointMse, {R, K},
                kMseUnits + "; of the best-validation weights up to each budget");
    make.floats(kCheckpointTrainSeconds, {R, K},
                "s; training wall time to each budget, this run's share of its stack, inference "
                "excluded");
  }
}

// Independent raw-data writes of rank 0.
void write_config_columns(h5::File& file, const ConfigColumns& c,
                          const std::vector<std::string>& run_studies) {
  const auto R = static_cast<std::uint64_t>(c.ids.size());
  file.write_string_rows(kId, 0, c.ids);
  file.write_string_rows(kCanonical, 0, c.canonical);
  file.write_string_rows(kSystem, 0, c.systems);
  file.write_string_rows(kModel, 0, c.models);
  file.write_string_rows(kIntegrator, 0, c.integrators);
  file.write_string_rows(kSize, 0, c.sizes);
  file.write_string_rows(kRegularizer, 0, c.regularizers);
  file.write_string_rows(kStudies, 0, run_studies);
  file.write_rows(kNTrain, 0, R, c.n_train.data());
  file.write_rows(kSeed, 0, R, c.seeds.data());
}

}  // namespace

ResultsFile ResultsFile::create(const std::string& path, MPI_Comm comm,
                                const std::vector<RunConfig>& runs,
                                const std::vector<std::string>& run_studies,
                                const std::string& sweep_name,
                                const std::string& sweep_text,
                                const std::string& sweep_hash,
                                const std::string& program_version,
                                const ResultsLayout& layout) {
  // Policy 1: every rank has the same arguments, so these throw everywhere.
  const std::string where = "ResultsFile::create(" + path + "): ";
  layout.validate();
  require(!runs.empty(), where + "the run list is empty; a sweep needs at least one run");
  require(run_studies.size() == runs.size(),
          where + "got " + std::to_string(run_studies.size()) + " study lists for " +
              std::to_string(runs.size()) + " runs; pass one per run");
  require(sweep_text.size() <= kMaxSweepText,
          where + "sweep_text has " + std::to_string(sweep_text.size()) +
              " bytes, more than the " + std::to_string(kMaxSweepText) +
              " an HDF5 attribute can hold; shorten the sweep file");
  const ConfigColumns columns(runs, run_studies, where);

  // Rank 0 checks the directory; all ranks learn the outcome and the
  // creation time together.
  check_on_rank0(comm, [&]() -> std::string {
    const std::string dir = dirname_of(path);
    if (::access(dir.c_str(), W_OK) != 0) {
      return path + ": cannot create the results file: directory " + dir +
             " does not exist or is not writable";
    }
    return "";
  });
  const std::string created = broadcast(comm, utc_now());

  std::unique_ptr<Impl> impl;
  collective_or_abort(comm, [&] {
    h5::File file = h5::File::create(path, comm);
    file.set_attribute("/", "format", std::string(kFormat));
    file.set_attribute("/", "format_version", kFormatVersion);
    file.set_attribute("/", "sweep_name", sweep_name);
    file.set_attribute("/", "sweep_text", sweep_text);
    file.set_attribute("/", "sweep_hash", sweep_hash);
    file.set_attribute("/", "program_version", program_version);
    file.set_attribute("/", "units", kFileUnits);
    file.set_attribute("/", "created", created);
    // Every dataset now, allocated and filled (pending rows: status 0, NaN
    // floats, zero lengths): writing a row later touches raw data only.
    const DatasetMaker make{file, static_cast<std::uint64_t>(runs.size())};
    create_config_datasets(make);
    create_result_datasets(make, layout);
    create_trace_and_figure_datasets(make, layout);
    if (comm_rank(comm) == 0) write_config_columns(file, columns, run_studies);
    // Metadata on disk now: from here on a crash can only lose row data.
    file.flush();
    impl = std::make_unique<Impl>(std::move(file), comm);
  });
  return ResultsFile(std::move(impl));
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

// `values` padded with NaN to `length`.
std::vector<double> padded(const std::vector<double>& values, std::size_t length) {
  std::vector<double> out(length, kNaN);
  std::copy(values.begin(), values.end(), out.begin());
  return out;
}

// The first `length` values of a NaN-padded row.
std::vector<double> unpadded(const std::vector<double>& row, std::int64_t length) {
  const auto n = static_cast<std::size_t>(
      std::clamp<std::int64_t>(length, 0, static_cast<std::int64_t>(row.size())));
  return std::vector<double>(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(n));
}

}  // namespace

void ResultsFile::write_run(int row, const RunResult& r) {
  Impl& impl = *impl_;
  const ResultsLayout& L = impl.layout;
  const std::string where =
      impl.prefix() + path() + ": write_run(row " + std::to_string(row) + "): ";
  require(row >= 0 && row < impl.num_runs,
          where + "row outside [0, " + std::to_string(impl.num_runs) + ")");
  require(r.trajectory_errors.size() <= static_cast<std::size_t>(L.num_inference),
          where + "trajectory_errors has " + std::to_string(r.trajectory_errors.size()) +
              " entries, the file holds " + std::to_string(L.num_inference) +
              " (ResultsLayout::num_inference)");
  require(r.trace.size() <= static_cast<std::size_t>(L.trace_points),
          where + "trace has " + std::to_string(r.trace.size()) +
              " points, the file holds " + std::to_string(L.trace_points) +
              " (ResultsLayout::trace_points)");
  const std::vector<double>* figures[4] = {&r.figure_prediction_05, &r.figure_prediction_075,
                                           &r.figure_reference_05, &r.figure_reference_075};
  const char* figure_names[4] = {"figure_prediction_05", "figure_prediction_075",
                                 "figure_reference_05", "figure_reference_075"};
  std::int64_t figure_length[4];
  for (int k = 0; k < 4; ++k) {
    const std::size_t size = figures[k]->size();
    require(size % 2 == 0 && size / 2 <= static_cast<std::size_t>(L.figure_points),
            where + figure_names[k] + " has " + std::to_string(size) +
                " values; expected an even count of at most 2 * " +
                std::to_string(L.figure_points) + " (ResultsLayout::figure_points)");
    figure_length[k] = static_cast<std::int64_t>(size / 2);
  }

  require(r.checkpoint_steps.size() <= static_cast<std::size_t>(L.checkpoints) &&
              r.checkpoint_mse.size() == r.checkpoint_steps.size() &&
              r.checkpoint_train_seconds.size() == r.checkpoint_steps.size(),
          where + "has " + std::to_string(r.checkpoint_steps.size()) +
              " checkpoints, the file holds " + std::to_string(L.checkpoints) +
              " (ResultsLayout::checkpoints)");
  std::vector<double> trace(static_cast<std::size_t>(L.trace_points) * kTraceColumns, kNaN);
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    const TracePoint& t = r.trace[i];
    const double point[kTraceColumns] = {static_cast<double>(t.step), t.elapsed_s,
                                         t.train_loss, t.validation_loss, t.kappa,
                                         t.sigma_max, t.rho};
    std::copy(point, point + kTraceColumns, trace.begin() + static_cast<std::ptrdiff_t>(i * kTraceColumns));
  }

  impl.independent([&] {
    h5::File& f = impl.file;
    const auto at = static_cast<std::uint64_t>(row);
    auto put_double = [&](const std::string& name, double v) { f.write_rows(name, at, 1, &v); };
    auto put_int = [&](const std::string& name, std::int64_t v) {
      f.write_rows(name, at, 1, &v);
    };
    put_double(kMse, r.mse);
    f.write_rows(kTrajectoryErrors, at, 1,
                 padded(r.trajectory_errors, static_cast<std::size_t>(L.num_inference)).data());
    put_int(kTrajectoryErrorsLength, static_cast<std::int64_t>(r.trajectory_errors.size()));
    put_int(kDivergedRollouts, r.diverged_rollouts);
    put_int(kBestStep, r.best_step);
    put_double(kBestValidationLoss, r.best_validation_loss);
    put_double(kWallTime, r.wall_time_s);
    put_int(kSteps, r.steps);
    put_int(kParameterCount, r.parameter_count);
    put_int(kNewtonFailures, r.newton_failures);
    f.write_rows(kTrace, at, 1, trace.data());
    put_int(kTraceLength, static_cast<std::int64_t>(r.trace.size()));
    const std::string* figure_sets[4] = {&kPrediction05, &kPrediction075, &kReference05,
                                         &kReference075};
    const auto F = static_cast<std::size_t>(L.figure_points) * 2;
    for (int k = 0; k < 4; ++k) f.write_rows(*figure_sets[k], at, 1, padded(*figures[k], F).data());
    f.write_rows(kFigureLength, at, 1, figure_length);
    f.write_string_rows(kMessage, at, {truncate_message(r.message, kMessageLength)});
    if (L.checkpoints > 0) {
      const auto K = static_cast<std::size_t>(L.checkpoints);
      std::vector<std::int64_t> steps(K, 0);
      std::copy(r.checkpoint_steps.begin(), r.checkpoint_steps.end(), steps.begin());
      f.write_rows(kCheckpointSteps, at, 1, steps.data());
      f.write_rows(kCheckpointMse, at, 1, padded(r.checkpoint_mse, K).data());
      f.write_rows(kCheckpointTrainSeconds, at, 1, padded(r.checkpoint_train_seconds, K).data());
    }
    // Last: until this lands the row reads as pending.
    put_int(kStatus, static_cast<std::int64_t>(r.status));
  });
}

namespace {
RunStatus status_from_code(std::int64_t code, const std::string& where) {
  if (code < 0 || code > static_cast<std::int64_t>(RunStatus::kFailed)) {
    throw std::runtime_error(where + " = " + std::to_string(code) +
                             "; expected 0 (pending) to 3 (failed); the file is damaged");
  }
  return static_cast<RunStatus>(code);
}
}  // namespace

std::vector<RunStatus> ResultsFile::read_statuses() const {
  const std::vector<std::int64_t> codes = impl_->ints(kStatus);
  std::vector<RunStatus> out;
  out.reserve(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    out.push_back(status_from_code(
        codes[i], impl_->prefix() + path() + ": " + kStatus + "[" + std::to_string(i) + "]"));
  }
  return out;
}

RunResult ResultsFile::read_run(int row) const {
  const Impl& impl = *impl_;
  require(row >= 0 && row < impl.num_runs,
          impl.prefix() + path() + ": read_run(row " + std::to_string(row) +
              "): row outside [0, " + std::to_string(impl.num_runs) + ")");
  const auto at = static_cast<std::uint64_t>(row);
  auto one_int = [&](const std::string& name) { return impl.ints(name, at, 1).at(0); };
  auto one_double = [&](const std::string& name) { return impl.doubles(name, at, 1).at(0); };
  RunResult r;
  r.status = status_from_code(one_int(kStatus), impl.prefix() + path() + ": " + kStatus +
                                                    "[" + std::to_string(row) + "]");
  r.message = impl.independent([&] { return impl.file.read_strings(kMessage, at, 1).at(0); });
  r.mse = one_double(kMse);
  r.trajectory_errors =
      unpadded(impl.doubles(kTrajectoryErrors, at, 1), one_int(kTrajectoryErrorsLength));
  r.diverged_rollouts = static_cast<int>(one_int(kDivergedRollouts));
  r.best_step = static_cast<int>(one_int(kBestStep));
  r.best_validation_loss = one_double(kBestValidationLoss);
  r.wall_time_s = one_double(kWallTime);
  r.steps = static_cast<int>(one_int(kSteps));
  r.parameter_count = static_cast<long>(one_int(kParameterCount));
  r.newton_failures = one_int(kNewtonFailures);
  const std::vector<double> trace = impl.doubles(kTrace, at, 1);
  const std::int64_t trace_length =
      std::clamp<std::int64_t>(one_int(kTraceLength), 0, impl.layout.trace_points);
  for (std::int64_t i = 0; i < trace_length; ++i) {
    const double* p = trace.data() + i * kTraceColumns;
    TracePoint t;
    t.step = static_cast<int>(p[0]);
    t.elapsed_s = p[1];
    t.train_loss = p[2];
    t.validation_loss = p[3];
    t.kappa = p[4];
    t.sigma_max = p[5];
    t.rho = p[6];
    r.trace.push_back(t);
  }
  const std::vector<std::int64_t> lengths = impl.ints(kFigureLength, at, 1);
  r.figure_prediction_05 = unpadded(impl.doubles(kPrediction05, at, 1), 2 * lengths.at(0));
  r.figure_prediction_075 = unpadded(impl.doubles(kPrediction075, at, 1), 2 * lengths.at(1));
  r.figure_reference_05 = unpadded(impl.doubles(kReference05, at, 1), 2 * lengths.at(2));
  r.figure_reference_075 = unpadded(impl.doubles(kReference075, at, 1), 2 * lengths.at(3));
  if (impl.layout.checkpoints > 0) {
    for (std::int64_t s : impl.ints(kCheckpointSteps, at, 1)) {
      if (s > 0) r.checkpoint_steps.push_back(static_cast<int>(s));
    }
    const auto count = static_cast<std::int64_t>(r.checkpoint_steps.size());
    r.checkpoint_mse = unpadded(impl.doubles(kCheckpointMse, at, 1), count);
    r.checkpoint_train_seconds = unpadded(impl.doubles(kCheckpointTrainSeconds, at, 1), count);
  }
  return r;
}

std::vector<std::string> ResultsFile::read_run_ids() const { return impl_->strings(kId); }
std::vector<std::string> ResultsFile::read_canonical() const {
  return impl_->strings(kCanonical);
}
std::vector<std::string> ResultsFile::read_systems() const { return impl_->strings(kSystem); }
std::vector<std::string> ResultsFile::read_models() const { return impl_->strings(kModel); }
std::vector<std::string> ResultsFile::read_integrators() const {
  return impl_->strings(kIntegrator);
}
std::vector<std::string> ResultsFile::read_sizes() const { return impl_->strings(kSize); }
std::vector<std::string> ResultsFile::read_regularizers() const {
  return impl_->strings(kRegularizer);
}
std::vector<std::string> ResultsFile::read_studies() const { return impl_->strings(kStudies); }
std::vector<std::int64_t> ResultsFile::read_n_train() const { return impl_->ints(kNTrain); }
std::vector<std::int64_t> ResultsFile::read_seeds() const { return impl_->ints(kSeed); }

std::vector<double> ResultsFile::read_double_column(const std::string& column) const {
  return impl_->doubles(kRuns + column);
}
std::vector<std::int64_t> ResultsFile::read_int_column(const std::string& column) const {
  return impl_->ints(kRuns + column);
}
std::vector<std::string> ResultsFile::read_string_column(const std::string& column) const {
  return impl_->strings(kRuns + column);
}

namespace {
std::string data_group(const std::string& system_name) {
  require(!system_name.empty() && system_name.find('/') == std::string::npos,
          "ResultsFile: system name \"" + system_name +
              "\" cannot name a group; expected a non-empty name without '/'");
  return "/data/" + system_name;
}
}  // namespace

void ResultsFile::store_system_data(const std::string& system_name, const SystemData& data) {
  const std::string group = data_group(system_name);
  // Every rank sees the same file state, so all throw together.
  require(!has_system_data(system_name),
          path() + ": " + group + " is already stored; check has_system_data() first");
  impl_->collective([&] {
    impl_->file.remove(group);  // a group left incomplete by a crash
    internal::write_system_data(impl_->file, group, data);
    impl_->file.set_attribute(group, "complete", std::int64_t{1});
    impl_->file.flush();
  });
}

bool ResultsFile::has_system_data(const std::string& system_name) const {
  const std::string group = data_group(system_name);
  return impl_->independent([&] { return impl_->file.has_attribute(group, "complete"); });
}

SystemData ResultsFile::read_system_data(const std::string& system_name) const {
  const std::string group = data_group(system_name);
  return impl_->independent([&] { return internal::read_system_data(impl_->file, group); });
}

void ResultsFile::write_run_times(int row, const std::string& started,
                                  const std::string& finished) {
  Impl& impl = *impl_;
  require(row >= 0 && row < impl.num_runs,
          impl.prefix() + path() + ": write_run_times(row " + std::to_string(row) +
              "): row outside [0, " + std::to_string(impl.num_runs) + ")");
  if (!impl.has_run_times) return;
  impl.independent([&] {
    const auto at = static_cast<std::uint64_t>(row);
    impl.file.write_string_rows(kStartedUtc, at, {started.substr(0, kUtcLength)});
    impl.file.write_string_rows(kFinishedUtc, at, {finished.substr(0, kUtcLength)});
  });
}

bool ResultsFile::has_run_times() const { return impl_->has_run_times; }

std::vector<std::string> ResultsFile::read_started_utc() const {
  if (!impl_->has_run_times) return std::vector<std::string>(static_cast<std::size_t>(num_runs()));
  return impl_->strings(kStartedUtc);
}

std::vector<std::string> ResultsFile::read_finished_utc() const {
  if (!impl_->has_run_times) return std::vector<std::string>(static_cast<std::size_t>(num_runs()));
  return impl_->strings(kFinishedUtc);
}

int ResultsFile::begin_session(const Provenance& provenance) {
  Impl& impl = *impl_;
  // Every rank reads the same metadata, so every rank picks the same k.
  int k = 0;
  impl.independent([&] {
    while (impl.file.exists(kProvenance + "/session_" + std::to_string(k))) ++k;
  });
  impl.session = kProvenance + "/session_" + std::to_string(k);
  impl.collective([&] {
    impl.file.create_group(impl.session);
    for (const auto& [key, value] : provenance) impl.file.set_attribute(impl.session, key, value);
    impl.file.flush();
  });
  return k;
}

void ResultsFile::end_session(const std::string& finished_utc) {
  Impl& impl = *impl_;
  if (impl.session.empty()) return;
  impl.collective([&] { impl.file.set_attribute(impl.session, "finished", finished_utc); });
}

std::vector<Provenance> ResultsFile::read_sessions() const {
  const Impl& impl = *impl_;
  std::vector<Provenance> sessions;
  impl.independent([&] {
    for (int k = 0;; ++k) {
      const std::string group = kProvenance + "/session_" + std::to_string(k);
      if (!impl.file.exists(group)) break;
      Provenance p;
      for (const std::string& name : impl.file.attribute_names(group)) {
        p.emplace_back(name, impl.file.string_attribute(group, name));
      }
      sessions.push_back(std::move(p));
    }
  });
  return sessions;
}

void ResultsFile::flush() {
  impl_->collective([&] { impl_->file.flush(); });
}

void ResultsFile::close() {
  if (!impl_ || !impl_->open) return;
  impl_->collective([&] { impl_->file.close(); });
  impl_->open = false;
}

}  // namespace phnn

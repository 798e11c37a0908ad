// src/store/results_file_create.cpp — ResultsFile::create: every dataset of
// docs/RESULTS_FORMAT.md made up front (allocated and filled, so a row write
// later touches raw data only) and the configuration columns written.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <algorithm>

#include "phnn/common/utc_time.h"
#include "phnn/store/scratch_file.h"
#include "store/results_file_internal.h"

namespace phnn {

using namespace results_io;

namespace {

// Creates datasets of R rows with a `units` attribute (a unit: "s", "1" for
// counts and dimensionless numbers, "m^2 and (kg m/s)^2" where states of
// two units mix, "" for text and codes) and a `description` (prose).
struct DatasetMaker {
  h5::File& file;
  std::uint64_t rows;

  void describe(const std::string& name, const std::string& units,
                const std::string& description) const {
    file.set_attribute(name, "units", units);
    file.set_attribute(name, "description", description);
  }
  void text(const std::string& name, std::size_t length, const std::string& description) const {
    file.create_dataset(name, h5::Type::kString, {rows}, length);
    describe(name, "", description);
  }
  void ints(const std::string& name, std::vector<std::uint64_t> dims,
            const std::string& description, const std::string& units = "1") const {
    file.create_dataset(name, h5::Type::kInt64, dims);
    describe(name, units, description);
  }
  // Filled with NaN: a pending row reads as NaN.
  void floats(const std::string& name, std::vector<std::uint64_t> dims, const std::string& units,
              const std::string& description) const {
    file.create_dataset(name, h5::Type::kFloat64, dims, /*string_length=*/0, /*fill_value=*/kNaN);
    describe(name, units, description);
  }
};

// "a, b or c".
std::string one_of(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return out;
}

void create_config_datasets(const DatasetMaker& make) {
  const std::uint64_t R = make.rows;
  make.text(kId, kIdLength, "RunConfig::id(): FNV-1a 64 of canonical, 16 hex digits");
  make.text(kCanonical, kCanonicalLength, "RunConfig::canonical()");
  make.text(kSystem, kNameLength, "harmonic, duffing or self-sustained");
  make.text(kModel, kNameLength, one_of(kModelNames.names()));
  make.text(kIntegrator, kNameLength, one_of(kIntegratorNames.names()));
  make.text(kSize, kNameLength, one_of(kSizeNames.names()));
  make.text(kRegularizer, kNameLength, one_of(kRegularizerNames.names()));
  make.ints(kNTrain, {R}, "training pairs");
  make.ints(kSeed, {R}, "model initialization seed");
  make.ints(kStates, {R}, "states of the run's system (n_x): the valid columns of /runs/figure/*");
  make.text(kStudies, kStudiesLength, "comma-separated studies of the run, e.g. I,II,III");
}

void create_result_datasets(const DatasetMaker& make, const ResultsLayout& layout) {
  const std::uint64_t R = make.rows;
  const auto I = static_cast<std::uint64_t>(layout.num_inference);
  // An HDF5 enum (h5py shows its names); read and written as int64 codes.
  make.file.create_enum_dataset(kStatus, {R}, {"pending", "done", "diverged", "failed"});
  make.describe(kStatus, "", "0 pending, 1 done, 2 diverged, 3 failed");
  make.ints(kChecksum, {R},
            "FNV-1a 64 of every stored byte of the row (each dataset of /runs but this one, "
            "then the run's weights; checksum rule 2), written after the status; 0: none yet",
            "");
  make.text(kMessage, kMessageLength, "why a run diverged or failed (truncated)");
  make.floats(kTrajectoryErrors, {R, I}, kMseUnit,
              std::string(kMseUnits) + "; per inference trajectory");
  make.ints(kTrajectoryErrorsLength, {R}, "valid entries of trajectory_errors");
  for (const ResultColumn& c : result_columns()) {
    if (c.type == ResultColumn::Type::kInt) {
      make.ints(kRuns + c.name, {R}, c.description, c.units);
    } else {
      make.floats(kRuns + c.name, {R}, c.units, c.description);
    }
  }
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
              std::string("1, s, ") + kLossUnit + ", " + kLossUnit + ", 1, 1/s, 1",
              std::string("per column: step [1], elapsed_s [s], train_loss and validation_loss [") +
                  kLossUnits + "], kappa [1], sigma_max [1/s], rho [1]; NaN after trace_length");
  make.file.set_attribute(kTrace, "columns",
                          std::string("step, elapsed_s, train_loss, validation_loss, kappa, "
                                      "sigma_max, rho"));
  make.ints(kTraceLength, {R}, "valid points of trace");
  const auto W = static_cast<std::uint64_t>(layout.figure_states);
  const std::string figure =
      "the system's states per point (built-in: " + kStateUnits +
      "; a system file's: /data/<system> state_names and state_units), the first /runs/n_x "
      "columns; NaN after figure/length";
  const std::string first = "; model rollout from H(x0) = 0.5 J (built-in) or of inference "
                            "trajectory 0 (system file)";
  const std::string second = "; model rollout from H(x0) = 0.75 J (built-in) or of inference "
                             "trajectory 1 (system file)";
  const std::string state_units = "the states' units (built-in: " + kStateUnits + ")";
  make.floats(kPrediction05, {R, F, W}, state_units, figure + first);
  make.floats(kPrediction075, {R, F, W}, state_units, figure + second);
  make.floats(kReference05, {R, F, W}, state_units, figure + "; the true trajectory of prediction_05");
  make.floats(kReference075, {R, F, W}, state_units,
              figure + "; the true trajectory of prediction_075");
  make.ints(kFigureLength, {R, 4}, "valid points of each figure trajectory");
  make.file.set_attribute(kFigureLength, "columns",
                          std::string("prediction_05, prediction_075, reference_05, "
                                      "reference_075"));
  if (layout.checkpoints > 0) {
    const auto K = static_cast<std::uint64_t>(layout.checkpoints);
    make.ints(kCheckpointSteps, {R, K}, "step budgets (TrainerOptions::checkpoints); 0 after the "
                                        "run's own count");
    make.floats(kCheckpointMse, {R, K}, kMseUnit,
                std::string(kMseUnits) + "; of the best-validation weights up to each budget");
    make.floats(kCheckpointTrainSeconds, {R, K}, "s",
                "training wall time to each budget, this run's share of its stack, inference "
                "excluded");
  }
}

// /weights holds every run's best-validation weights back to back (a run's
// parameter count is known from its model and size), so a file of large
// models is not padded to their size in every row.
void create_weight_datasets(const DatasetMaker& make, std::int64_t total,
                            std::size_t layout_length) {
  const std::uint64_t R = make.rows;
  make.ints(kWeightsOffset, {R}, "index in /weights of the run's first weight");
  make.ints(kWeightsLength, {R}, "weights stored for the run (0: none, e.g. pending or failed)");
  make.text(kWeightsLayout, layout_length,
            "names and shapes of the run's weights in /weights order, e.g. \"l_h.0.weight 2x16; "
            "l_h.0.bias 16; ...\" (weight [fan_in, fan_out] row-major, then bias)");
  const auto n = static_cast<std::uint64_t>(std::max<std::int64_t>(total, 1));
  make.floats(kWeights, {n}, "1",
              "best-validation weights of every run, back to back: DynamicsModel::parameters() "
              "order, each tensor row-major without its member axis; NaN where none stored");
}

struct FileAttributes {
  std::string sweep_name, sweep_text, sweep_hash, program_version, created;
};

// The whole new file, written serially under a scratch name next to `path`
// (<path>.creating), fsynced, then renamed onto `path`: a file at `path` is
// complete or absent, never half-created. On an error the scratch file is
// removed and the error rethrown.
void write_new_file(const std::string& path, const ConfigColumns& columns,
                    const ResultsLayout& layout, const FileAttributes& a, bool in_place) {
  const auto write = [&](const std::string& scratch) {
    h5::File file = h5::File::create(scratch);
    file.set_attribute("/", "format", std::string(ResultsFile::kFormat));
    file.set_attribute("/", "format_version", ResultsFile::kFormatVersion);
    file.set_attribute("/", "sweep_name", a.sweep_name);
    file.set_attribute("/", "sweep_text", a.sweep_text);
    file.set_attribute("/", "sweep_hash", a.sweep_hash);
    file.set_attribute("/", "program_version", a.program_version);
    file.set_attribute("/", "units", kFileUnits);
    file.set_attribute("/", "created", a.created);
    // Every dataset now, allocated and filled (pending rows: status 0, NaN
    // floats, zero lengths): writing a row later touches raw data only.
    const DatasetMaker make{file, static_cast<std::uint64_t>(columns.ids.size())};
    create_config_datasets(make);
    create_result_datasets(make, layout);
    create_trace_and_figure_datasets(make, layout);
    if (layout.weights) {
      create_weight_datasets(make, columns.weights_total, columns.weights_layout_length);
    }
    write_config_columns(file, columns);
    write_setting_columns(file, columns.canonical, /*create=*/true);
    // Checksum rule 2: the rule, then the file digest over what is now
    // written (sweep attributes, configuration columns).
    file.set_attribute("/", kChecksumVersionAttribute, ResultsFile::kChecksumVersion);
    file.set_attribute("/", kDigestAttribute, file_digest(file));
    file.close();  // throws if the metadata cannot be written
  };
  // In place: `path` is already the caller's scratch name (no
  // r.h5.creating.creating in messages).
  if (in_place) {
    write(path);
  } else {
    write_atomically(path, "creating", write);
  }
}

}  // namespace

ResultsFile ResultsFile::create(const std::string& path, MPI_Comm comm,
                                const std::vector<RunConfig>& runs,
                                const std::vector<std::string>& run_studies,
                                const std::string& sweep_name,
                                const std::string& sweep_text,
                                const std::string& sweep_hash,
                                const std::string& program_version,
                                const ResultsLayout& layout, CreateMode mode) {
  // Every rank has the same arguments, so these throw everywhere together.
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
    const std::string dir = parent_directory(path);
    if (::access(dir.c_str(), W_OK) != 0) {
      return path + ": cannot create the results file: directory " + dir +
             " does not exist or is not writable";
    }
    return "";
  });
  const std::string created = broadcast(comm, utc_now());
  const FileAttributes attributes{sweep_name, sweep_text, sweep_hash, program_version, created};
  // Rank 0 alone writes the new file, serially, so an I/O error (a full disk)
  // stays on rank 0 and reaches every rank as one error: no rank is left in a
  // collective HDF5 call (docs/DECISIONS.md, "No rank waits forever").
  check_on_rank0(comm, [&] {
    write_new_file(path, columns, layout, attributes, mode == CreateMode::kInPlace);
    return std::string();
  });
  std::unique_ptr<Impl> impl;
  collective_or_abort(comm, [&] {
    impl = std::make_unique<Impl>(h5::File::open(path, h5::Access::kReadWrite, comm), comm);
  });
  return ResultsFile(std::move(impl));
}

}  // namespace phnn

// src/store/results_file_internal.h — shared by the results_file*.cpp files
// only: the dataset names and units texts of docs/RESULTS_FORMAT.md,
// ResultsFile::Impl (the open h5::File and the layout read from it), the
// configuration columns and digests, and the helpers that make every rank
// fail together. Includes HDF5 only through src/h5.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "h5/h5file.h"
#include "phnn/config/result_columns.h"
#include "phnn/store/results_file.h"

namespace phnn {
namespace results_io {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr std::size_t kIdLength = 16;
inline constexpr std::size_t kNameLength = 32;
// The root object header holds each attribute in one message of < 64 KiB.
inline constexpr std::size_t kMaxSweepText = 60000;
inline constexpr int kTraceColumns = 7;

// Dataset names (docs/RESULTS_FORMAT.md).
inline const std::string kRuns = "/runs/";
inline const std::string kId = "/runs/id";
inline const std::string kCanonical = "/runs/canonical";
inline const std::string kSystem = "/runs/system";
inline const std::string kModel = "/runs/model";
inline const std::string kIntegrator = "/runs/integrator";
inline const std::string kSize = "/runs/size";
inline const std::string kRegularizer = "/runs/regularizer";
inline const std::string kNTrain = "/runs/n_train";
inline const std::string kSeed = "/runs/seed";
// Added with system files; files written before have 2 states per run.
inline const std::string kStates = "/runs/n_x";
inline const std::string kStudies = "/runs/studies";
// One dataset per run setting, named as in the per-run CSV (config/setting_columns.h).
inline const std::string kSettings = "/runs/config";
inline const std::string kStatus = "/runs/status";
inline const std::string kChecksum = "/runs/checksum";
inline const std::string kMessage = "/runs/message";
inline const std::string kTrajectoryErrors = "/runs/trajectory_errors";
inline const std::string kTrajectoryErrorsLength = "/runs/trajectory_errors_length";
inline const std::string kTrace = "/runs/trace";
inline const std::string kTraceLength = "/runs/trace_length";
inline const std::string kPrediction05 = "/runs/figure/prediction_05";
inline const std::string kPrediction075 = "/runs/figure/prediction_075";
inline const std::string kReference05 = "/runs/figure/reference_05";
inline const std::string kReference075 = "/runs/figure/reference_075";
inline const std::string kFigureLength = "/runs/figure/length";
inline const std::string kCheckpointSteps = "/runs/checkpoint_steps";
inline const std::string kCheckpointMse = "/runs/checkpoint_mse";
// Added with the stored weights; files written before them have none.
inline const std::string kWeights = "/weights";
inline const std::string kWeightsOffset = "/runs/weights_offset";
inline const std::string kWeightsLength = "/runs/weights_length";
// Names and shapes of a run's stored weights (weight_layout_text()).
inline const std::string kWeightsLayout = "/runs/weights_layout";
inline const std::string kCheckpointTrainSeconds = "/runs/checkpoint_train_seconds";
// Added with provenance; files written before them have neither.
inline const std::string kStartedUtc = "/runs/started_utc";
inline const std::string kFinishedUtc = "/runs/finished_utc";
inline const std::string kProvenance = "/provenance";
// Checksum rule 2 (2026-11-28): the rule's number on "/", the file digest on
// "/" (sweep attributes, configuration columns) and one on each /data group.
inline const std::string kChecksumVersionAttribute = "checksum_version";
inline const std::string kDigestAttribute = "digest";
inline constexpr std::size_t kUtcLength = 20;  // "2024-05-01T12:00:00Z"

inline const std::string kStateUnits = "q [m], p [kg m/s]";
inline const std::string kFileUnits =
    "SI units. States q [m], p [kg m/s]; time [s]; energy [J]; mse in m^2 and "
    "(kg m/s)^2 mixed (mean of ||x - x_hat||^2); losses in m/s and kg m/s^2 mixed "
    "(mean |x_{n+1} - x_hat_{n+1}| / h); kappa and rho dimensionless; sigma_max in "
    "1/s. Every dataset of /runs outside /runs/config has a units attribute (a unit; "
    "\"1\": counts and dimensionless; empty: text and codes) and a description.";


int comm_rank(MPI_Comm comm);
int comm_size(MPI_Comm comm);
/// Rank `root`'s string on every rank (serial: unchanged).
std::string broadcast(MPI_Comm comm, std::string text, int root = 0);
/// Rank 0 runs `check` (which returns an error message or ""); every rank
/// throws the same error, so none is left waiting in a collective call
/// (docs/DECISIONS.md, "No rank waits forever").
void check_on_rank0(MPI_Comm comm, const std::function<std::string()>& check);
/// Message truncated to `length` bytes, ending in "...", not splitting a
/// UTF-8 character.
std::string truncate_message(const std::string& text, std::size_t length);
/// Throws std::invalid_argument(message) unless ok.
void require(bool ok, const std::string& message);
/// The configuration columns of /runs for a run list, as create() writes
/// them (results_file_config.cpp); the constructor validates them and
/// throws std::invalid_argument prefixed by `where`.
struct ConfigColumns {
  std::vector<std::string> ids, canonical, systems, models, integrators, sizes, regularizers;
  std::vector<std::int64_t> n_train, seeds, states;
  // Where each run's weights start in /weights, and their total count.
  std::vector<std::int64_t> weights_offset;
  std::int64_t weights_total = 0;
  // Names and shapes of each run's weights, and the longest such text.
  std::vector<std::string> weights_layout;
  std::size_t weights_layout_length = 1;
  std::vector<std::string> studies;

  ConfigColumns(const std::vector<RunConfig>& runs, const std::vector<std::string>& run_studies,
                const std::string& where);
};
/// Writes every row of the configuration columns (into datasets that exist).
void write_config_columns(h5::File& file, const ConfigColumns& columns);
/// /runs/config/<name>, one column per run setting: created (and written),
/// or, with create = false, written over the columns that exist.
void write_setting_columns(h5::File& file, const std::vector<std::string>& canonical,
                           bool create);
/// The configuration columns of `file` (written by create, never by
/// write_run): id, canonical, system, ..., weights_layout, /runs/config/*.
std::vector<std::string> configuration_columns(const h5::File& file);
/// Digest lines "<object> <16 hex digits>\n" (results_file_digest.cpp): of
/// the sweep attributes and configuration columns (the file digest), or of
/// every object under a /data group (its data, and the attributes of the
/// group and of each object in it but `digest` and `complete`).
std::string file_digest(const h5::File& file);
std::string group_digest(const h5::File& file, const std::string& group);

/// Runs collective HDF5 code. Serial: exceptions propagate. Parallel: an
/// exception is printed with the rank prefix and ends the job (docs/DECISIONS.md,
/// "No rank waits forever"), since the other ranks would wait for this one forever.
void collective_or_abort(MPI_Comm comm, const std::function<void()>& body);

}  // namespace results_io

struct ResultsFile::Impl {
  h5::File file;
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0;
  int size = 1;
  bool open = true;
  int num_runs = 0;
  ResultsLayout layout;
  std::vector<std::int64_t> run_states;  // /runs/n_x
  bool has_run_times = false;  // false in files written before provenance
  bool has_checksums = false;  // false in files written before row checksums
  // Checksum rule: 0 none, 1 (until 2026-11-28), 2 (checksum_version on "/").
  std::int64_t checksum_version = 0;
  // Rule 2: every dataset of /runs but the checksum, sorted (a row's bytes).
  std::vector<std::string> row_columns;
  // The result columns (config/result_columns.h) the file has: a column
  // added later is missing from files written before it; any other is
  // required, and its absence an HDF5 error where it is read.
  std::vector<const ResultColumn*> result_columns;
  std::string session;         // this process's /provenance/session_<k>

  Impl(h5::File f, MPI_Comm c)
      : file(std::move(f)), comm(c), rank(results_io::comm_rank(c)), size(results_io::comm_size(c)) {
    read_layout();
  }

  void read_layout() {
    num_runs = static_cast<int>(file.dims(results_io::kId).at(0));
    layout.num_inference = static_cast<int>(file.dims(results_io::kTrajectoryErrors).at(1));
    layout.trace_points = static_cast<int>(file.dims(results_io::kTrace).at(1));
    layout.figure_points = static_cast<int>(file.dims(results_io::kPrediction05).at(1));
    layout.figure_states = static_cast<int>(file.dims(results_io::kPrediction05).at(2));
    run_states = file.exists(results_io::kStates) ? file.read_ints(results_io::kStates)
                                                  : std::vector<std::int64_t>(num_runs, 2);
    layout.checkpoints =
        file.exists(results_io::kCheckpointMse) ? static_cast<int>(file.dims(results_io::kCheckpointMse).at(1)) : 0;
    has_run_times = file.exists(results_io::kStartedUtc) && file.exists(results_io::kFinishedUtc);
    has_checksums = file.exists(results_io::kChecksum);
    layout.weights = file.exists(results_io::kWeights);
    // The attribute exists only in files of rule 2 (a damaged value is
    // named by ResultsFile::file_damage).
    checksum_version = file.has_attribute("/", results_io::kChecksumVersionAttribute) ? 2
                       : has_checksums                                               ? 1
                                                                                     : 0;
    result_columns.clear();
    for (const ResultColumn& c : phnn::result_columns()) {
      if (!c.added_later || file.exists(results_io::kRuns + c.name)) result_columns.push_back(&c);
    }
    row_columns.clear();
    if (checksum_version == 2) {
      for (const std::string& name : file.objects_under("/runs")) {
        if (name != results_io::kChecksum && file.is_dataset(name)) row_columns.push_back(name);
      }
    }
  }

  // Row `row`'s n_x, checked against the layout before anything is sized
  // by it.
  std::size_t states_of(std::uint64_t row) const;
  // Row `row`'s slice of /weights (offset, length), checked against its size.
  std::pair<std::uint64_t, std::uint64_t> weights_of(std::uint64_t row) const;

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
    results_io::collective_or_abort(comm, body);
  }

  std::vector<std::string> strings(const std::string& name) const {
    return independent([&] { return file.read_strings(name); });
  }
  std::string strings_at(const std::string& name, std::uint64_t row) const {
    return independent([&] { return file.read_strings(name, row, 1).at(0); });
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

}  // namespace phnn

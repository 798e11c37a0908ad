// src/data/measured_checks.h — what every split of recorded trajectories
// shares (data/measured.cpp, measured_scan.cpp, trajectory_split.cpp,
// recording_split.cpp): the checks (shapes and finite values, increasing
// and uniform time, one sampling rate, unique ids), the first pass that
// keeps what a split needs of each trajectory (RecordingScan), and the
// pieces that copy pairs and inference windows into a data set as their
// trajectories pass by. Private to src/data.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "phnn/data/measured.h"

namespace phnn {
namespace internal {

/// Throws MeasuredDataError(message).
[[noreturn]] void fail(const std::string& message);
/// v with 10 significant digits, for messages.
std::string g(double v);
/// n_x / n_u widths, >= 2 samples, finite values, increasing time.
void check_trajectory(const MeasuredTrajectory& m, int nx, int nu);
/// h of one trajectory, checked uniform against its median step (throws
/// MeasuredDataError naming the sample that jumps).
double uniform_step(const MeasuredTrajectory& m, double tolerance);

/// What the first pass keeps of one trajectory: 24 bytes.
struct ScannedTrajectory {
  std::int64_t id = 0;
  double h = 0.0;             // uniform_step; 0 when it failed or was not asked
  std::uint32_t samples = 0;  // (more are refused)
  std::int32_t line = -1;     // the first sample's line in a text file, else -1
};

/// The first pass of split_measured_stream: add() each trajectory in the
/// source's order. It checks each (check_trajectory, uniform_step) and keeps
/// the messages, to be thrown where split_measured_data of all the
/// trajectories at once throws them (after reading, in its order).
class RecordingScan {
 public:
  RecordingScan(int nx, int nu, double time_tolerance)
      : nx_(nx), nu_(nu), tolerance_(time_tolerance) {}

  void add(const MeasuredTrajectory& m);
  std::size_t size() const { return all_.size(); }
  const ScannedTrajectory& operator[](std::size_t i) const { return all_[i]; }
  /// MeasuredTrajectory::where(0) of trajectory i (in the order read).
  std::string where(std::size_t i) const;
  /// Throws the first check_trajectory error, in the order read.
  void throw_check_error() const;
  /// The order read, sorted by id (stable); a repeated id is refused,
  /// naming both places.
  std::vector<std::uint32_t> sorted_by_id() const;
  /// The common step h = 1 / rate of the trajectories `order` lists (in
  /// that order: the first is the reference; a non-uniform one throws when
  /// reached): given by o.sample_rate, or from t, snapped to an integer
  /// rate within 1e-9.
  double common_step(const std::vector<std::uint32_t>& order, const ImportOptions& o,
                     std::string* summary) const;
  /// The second pass: throws unless trajectory i of it is the one read at
  /// i, and (check_all_seen) unless it saw `count` = size() trajectories.
  void check_same(std::size_t i, const MeasuredTrajectory& m) const;
  void check_all_seen(std::size_t count) const;

 private:
  int nx_, nu_;
  double tolerance_;
  std::vector<ScannedTrajectory> all_;
  /// (first trajectory, source) of each run of trajectories with one
  /// source (a CSV file's are one run; an HDF5 file's one each).
  std::vector<std::pair<std::size_t, std::string>> sources_;
  std::string check_error_;
  std::map<std::size_t, std::string> step_errors_;  // index -> uniform_step's message
};

/// The position read at index i of `order`'s entries: inverse[order[k]] = k.
std::vector<std::uint32_t> inverse(const std::vector<std::uint32_t>& order);

/// Inference windows filled as their trajectories pass by: window q holds
/// `w` samples of a trajectory from `start` (states, the first sample's
/// input, and, when u changes inside any window, every window's inputs per
/// sample: zero-order hold, replayed at inference); each window's first
/// sample in position when `positions`.
class WindowCollector {
 public:
  WindowCollector(int nx, int nu, std::size_t count, std::size_t w, bool positions, double step);
  void add(std::size_t q, const MeasuredTrajectory& m, std::size_t start);
  /// The windows, in the order of q.
  PhInferenceRows finish();

 private:
  bool varying_ = false;
  PhInferenceRows rows_;  // inputs kept until finish() knows whether any varies
};

/// What a recorded data set's options say of its timing: the data seed,
/// the rate 1 / h, nothing generated (generation step h, period 1), and
/// inference trajectories of `samples` samples (beta = h (samples - 1)).
void record_timing(DatasetOptions* o, std::uint64_t data_seed, double h, std::size_t samples);

/// The pair (x_n, u_n, x_n+1) of `m` into row i of `rows`.
void set_pair(PhPairRows* rows, std::size_t i, const MeasuredTrajectory& m, std::size_t n);

/// ImportSplit::kTrajectories and kBlocks of split_measured_stream.
MeasuredDataSet split_by_trajectories(const PhSystem& system, const TrajectorySource& source,
                                      const ImportOptions& options, std::string* summary);
MeasuredDataSet split_recordings_in_blocks(const PhSystem& system, const TrajectorySource& source,
                                           const ImportOptions& options, std::string* summary);

}  // namespace internal
}  // namespace phnn

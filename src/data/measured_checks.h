// src/data/measured_checks.h — what every split of recorded trajectories
// shares (data/measured.cpp): the checks (shapes and finite values,
// increasing and uniform time, one sampling rate, unique ids) and the
// pieces that copy pairs and inference windows into a data set. Private to
// src/data (measured.cpp defines them, recording_split.cpp uses them too).
#pragma once

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
/// The common step h = 1 / rate of every trajectory, each checked uniform
/// (given by o.sample_rate, or from t, snapped to an integer rate within 1e-9).
double common_step(const std::vector<MeasuredTrajectory>& all, const ImportOptions& o,
                   std::string* summary);
/// Sorted by id; a repeated id is refused.
void sort_by_id(std::vector<MeasuredTrajectory>* all);
/// Appends the pair (x_n, u_n, x_n+1) of `m` (trajectory m.id, position n).
void add_pair(const MeasuredTrajectory& m, std::size_t n, PhPairSet* pairs);
/// Appends the windows (trajectory index into `all`, first sample) of `w`
/// samples each as inference trajectories: states, the first sample's
/// input, and, when u changes inside any window, every window's inputs per
/// sample (zero-order hold, replayed at inference); each window's first
/// sample in inference->position when `positions`.
void add_windows(const std::vector<MeasuredTrajectory>& all,
                 const std::vector<std::pair<std::size_t, std::size_t>>& windows, std::size_t w,
                 bool positions, PhInferenceSet* inference);
/// What a recorded data set's options say of its timing: the data seed,
/// the rate 1 / h, nothing generated (generation step h, period 1), and
/// inference trajectories of `samples` samples (beta = h (samples - 1)).
void record_timing(DatasetOptions* o, std::uint64_t data_seed, double h, std::size_t samples);

}  // namespace internal
}  // namespace phnn

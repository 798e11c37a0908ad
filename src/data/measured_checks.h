// src/data/measured_checks.h — the checks every split of recorded
// trajectories makes (data/measured.cpp): shapes and finite values,
// increasing and uniform time, one sampling rate, unique ids. Private to
// src/data (measured.cpp defines them, recording_split.cpp uses them).
#pragma once

#include <string>
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
/// What a recorded data set's options say of its timing: the data seed,
/// the rate 1 / h, nothing generated (generation step h, period 1), and
/// inference trajectories of `samples` samples (beta = h (samples - 1)).
void record_timing(DatasetOptions* o, std::uint64_t data_seed, double h, std::size_t samples);

}  // namespace internal
}  // namespace phnn

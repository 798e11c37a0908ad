// src/data/input_signals.h — the inputs a control design draws (private to
// src/data): constant inputs from ranges, and the time-varying designs
// (sines, chirp, steps) sampled and held per sample of the data
// (docs/METHOD.md "Time-varying inputs"). Drawn from a trajectory's control
// stream only; no files.
#pragma once

#include <array>
#include <vector>

#include "phnn/data/counter_rng.h"
#include "phnn/data/dataset.h"
#include "phnn/systems/ph_system.h"

namespace phnn {
namespace internal {

/// u_i ~ U(range[i]) for each of `nu` inputs, in order.
VecX uniform_in_ranges(const std::vector<std::array<double, 2>>& range, int nu, CounterRng* rng);

/// Time-varying designs (ControlDesign::time_varying): the inputs at the
/// samples k = 0..K (K the inference steps), each held over [t_k, t_{k+1}).
/// Throws std::invalid_argument at the control table for a hold shorter than
/// a sample or a frequency above half the sample rate.
std::vector<VecX> input_samples(const PhSystem& system, const DatasetOptions& options,
                                CounterRng* rng);

}  // namespace internal
}  // namespace phnn

// include/phnn/data/ph_rows.h — a data set's pairs and inference
// trajectories in flat arrays, row after row, as a data-set file stores
// them (what `phnn import` builds and writes: 8 bytes a value, where a VecX
// holds 264 whatever n_x), and the way to and from PhPairSet and
// PhInferenceSet (what training reads). In memory only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "phnn/data/ph_dataset.h"

namespace phnn {

/// Pairs (x_i, u_i, x_next_i) of trajectory[i] at position[i], flat:
///
///   PhPairRows rows(/*states=*/2, /*inputs=*/1, /*count=*/3);
///   rows.set(0, m.id, /*pos=*/n, m.x.data() + 2 * n, m.x.data() + 2 * (n + 1),
///            m.u.data() + n);
///   const PhPairSet pairs = rows.to_pair_set();
struct PhPairRows {
  PhPairRows() = default;
  /// `count` rows of zeros, to be set().
  PhPairRows(int states, int inputs, std::size_t count);

  int n_x = 0, n_u = 0;
  std::vector<double> x, x_next;  // row i: [i n_x, (i+1) n_x)
  std::vector<double> u;          // row i: [i n_u, (i+1) n_u)
  std::vector<std::int64_t> trajectory, position;
  double step = 0.01;

  std::size_t size() const { return trajectory.size(); }
  /// Row i := pair (x, u, x_next) of trajectory `id` at `pos`: n_x, n_u and
  /// n_x values.
  void set(std::size_t i, std::int64_t id, std::int64_t pos, const double* state,
           const double* next_state, const double* input);
  /// The same pairs, one VecX per row and field.
  PhPairSet to_pair_set() const;
  /// The rows of `pairs` (states, inputs: the data set's widths).
  static PhPairRows of(const PhPairSet& pairs, int states, int inputs);
};

/// Inference trajectories of `samples` samples each, flat: trajectory i's
/// sample k is states[(i samples + k) n_x ...] (and inputs[...n_u]).
struct PhInferenceRows {
  PhInferenceRows() = default;
  /// `count` trajectories of `length` samples of zeros; inputs per sample
  /// when `per_sample_inputs`, start samples when `positions`.
  PhInferenceRows(int nx, int nu, std::size_t count, std::size_t length, bool per_sample_inputs,
                  bool positions);

  int n_x = 0, n_u = 0;
  std::size_t samples = 0;
  std::vector<std::int64_t> trajectory;
  std::vector<double> u;       // the input at the first sample: count n_u
  std::vector<double> states;  // count samples n_x
  /// Time-varying inputs, count samples n_u; empty when every input is
  /// constant (PhInferenceSet::inputs).
  std::vector<double> inputs;
  /// Windows of recordings: each one's first sample; empty when all start at 0.
  std::vector<std::int64_t> position;
  double step = 0.01;

  std::size_t size() const { return trajectory.size(); }
  /// The same trajectories, one VecX per sample.
  PhInferenceSet to_inference_set() const;
  /// The rows of `set` (nx, nu: the data set's widths). Throws
  /// std::invalid_argument when `set` is ragged (its inputs or positions
  /// not one per trajectory and sample).
  static PhInferenceRows of(const PhInferenceSet& set, int nx, int nu);
};

}  // namespace phnn

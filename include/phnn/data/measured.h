// include/phnn/data/measured.h — data sets from recorded trajectories (what
// `phnn import` reads from CSV or HDF5, store/trajectory_files.h): the checks
// of uniform sampling, the split into training / validation pairs and
// inference trajectories (docs/METHOD.md "Measured data"), and the way back —
// a generated data set's trajectories, for `phnn data --csv`. In memory only:
// files reach it as a TrajectorySource that store/trajectory_files.h makes.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/data/ph_rows.h"
#include "phnn/systems/measurement_map.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

/// One recorded trajectory: samples (t_k, x_k, u_k), k = 0 .. N-1, with u_k
/// held over [t_k, t_k+1) (zero-order hold). Stored flat, sample after
/// sample, 8 bytes a value (and 4 for a text file's line): a large
/// recording costs its numbers, not an object per value.
///
///   MeasuredTrajectory m(/*n_x=*/2, /*n_u=*/1);
///   m.add(/*t=*/0.0, x0.data(), u0.data());
///   const double p0 = m.x[1];  // sample 0, state 1
struct MeasuredTrajectory {
  MeasuredTrajectory() = default;
  MeasuredTrajectory(int states, int inputs) : n_x(states), n_u(inputs) {}

  /// The `trajectory` column: a non-negative integer, unique in a data set.
  /// It orders the trajectories and keys the draw of its training pair.
  std::int64_t id = 0;
  /// Widths of a sample's state and input.
  int n_x = 0, n_u = 0;
  std::vector<double> t;  // [s], N
  std::vector<double> x;  // x_k = x[k n_x .. (k+1) n_x), N n_x
  std::vector<double> u;  // u_k = u[k n_u .. (k+1) n_u), N n_u
  /// Where it was read ("a.csv", "b.h5:/trajectories/7"), for errors, and
  /// the line of each sample in a text file (empty otherwise).
  std::string source;
  std::vector<int> line;

  std::size_t size() const { return t.size(); }
  /// Appends sample (t, x, u): n_x and n_u values.
  void add(double time, const double* state, const double* input);
  /// u_k == u_ref, value by value.
  bool same_input(std::size_t k, std::size_t ref = 0) const;

  /// "a.csv:14: trajectory 7" (sample k's line) or "b.h5:/trajectories/7,
  /// sample 3".
  std::string where(std::size_t k) const;
};

/// Recorded columns into states ([measurement] of the system file): each
/// trajectory read with map.recorded() as its columns gets the system's
/// n_x states per sample. Throws MeasuredDataError naming the sample where
/// a computed state is not finite.
void apply_measurement(const MeasurementMap& map, std::vector<MeasuredTrajectory>* trajectories);
/// The same for one trajectory: *out = `recorded` with its states computed
/// (*out's arrays are reused, so a loop over trajectories allocates once).
void apply_measurement(const MeasurementMap& map, const MeasuredTrajectory& recorded,
                       MeasuredTrajectory* out);

/// One pass over recorded trajectories: source(visit) calls visit(m) for
/// each, in the same order at every call (a file's rows, a vector's
/// elements); `m` lives until visit returns. What split_measured_stream
/// reads twice instead of holding every trajectory. A source throws
/// MeasuredDataError for what it cannot read.
using TrajectoryVisitor = std::function<void(const MeasuredTrajectory&)>;
using TrajectorySource = std::function<void(const TrajectoryVisitor&)>;

/// The trajectories of `all`, in their order (`all` must outlive it).
TrajectorySource trajectories_of(const std::vector<MeasuredTrajectory>& all);

/// Bad measured data: the message names the file and line (or trajectory
/// and sample) and the fix.
class MeasuredDataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How recorded trajectories become pairs (docs/METHOD.md "Measured data").
enum class ImportSplit {
  /// Each trajectory serves one role and gives one pair (or inference
  /// trajectory): many short trajectories, as generated data are.
  kTrajectories,
  /// Each recording is cut in time into a training, a validation and an
  /// inference block; every sample pair inside a block is a pair, inference
  /// windows lie inside the inference block: a few long recordings.
  kBlocks,
};
/// `phnn import --split`.
inline constexpr EnumNames<ImportSplit, 2> kImportSplitNames{
    "split", {{{ImportSplit::kTrajectories, "trajectories"}, {ImportSplit::kBlocks, "blocks"}}}};

/// How recorded trajectories become a data set.
struct ImportOptions {
  ImportSplit split = ImportSplit::kTrajectories;
  /// kBlocks: the training and validation blocks' shares of each
  /// recording's samples, in this order; the inference block is the rest.
  double train_fraction = 0.6, validation_fraction = 0.2;
  /// kBlocks: inference windows of this duration [s], consecutive and
  /// disjoint inside each inference block (0: the whole block).
  double window = 0.0;
  /// Keys the draw of each training / validation trajectory's pair position:
  /// CounterRng::for_trajectory(data_seed, system.rng_id(), id,
  /// kTrainingPair).below(positions), as for generated data, so a generated
  /// set written to CSV and imported gives back the same pairs.
  std::uint64_t data_seed = 0;
  /// kTrajectories: trajectories for the validation pairs and for
  /// inference; the others (at least one) give the training pairs.
  /// kBlocks: at most this many validation pairs (a uniform draw among the
  /// validation blocks' pairs when they are more) and inference windows.
  int num_validation = 2500;
  int num_inference = 100;
  /// Pairs (x_n, x_n+1) are drawn among n with t_n+1 - t_0 <= pair_window
  /// [s] (the paper's alpha T0: the transient); 0 = the whole trajectory.
  double pair_window = 0.0;
  /// Sampling rate [Hz]; 0 = from the time column (snapped to an integer
  /// when within 1e-9 of one, so t = n / 100 gives h = 1 / 100 exactly).
  double sample_rate = 0.0;
  /// >= 0: the trajectories are shuffled by this seed before the split;
  /// -1: split in the order of their ids.
  std::int64_t split_seed = -1;
  /// Largest |t_k+1 - t_k - h| / h accepted as uniform sampling.
  double time_tolerance = 1e-6;

  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// The data set of `trajectories` for `system` (its names, rng_id and text):
///   1. ids unique; every trajectory has >= 2 samples and finite values,
///      and steps equal to one h within time_tolerance, the same h for all;
///   2. kTrajectories: sorted by id (then shuffled by split_seed when >= 0):
///      the last num_inference are the inference trajectories (cut to the
///      shortest), the num_validation before them give validation pairs,
///      the rest training pairs, one pair per trajectory at the drawn
///      position; kBlocks: split_in_blocks below.
/// `summary` (optional) gets one line per decision (rate, split, cuts).
/// Throws MeasuredDataError.
PhSystemData split_measured_data(const PhSystem& system,
                                 std::vector<MeasuredTrajectory> trajectories,
                                 const ImportOptions& options, std::string* summary = nullptr);

/// A data set of recorded trajectories as `phnn import` writes it: the
/// pairs and inference trajectories as flat rows (`data` holds the rest:
/// names, options, split; its train, validation and inference hold none).
struct MeasuredDataSet {
  PhSystemData data;
  PhPairRows train, validation;
  PhInferenceRows inference;
};

/// split_measured_data of the trajectories `source` visits, in two passes
/// over them, never holding more than the one visited (docs/METHOD.md
/// "Measured data", point 4): the first keeps what the split needs of each
/// (id, sample count, step, first line) and finds every error of
/// split_measured_data, thrown in its order; the second copies each
/// trajectory's pairs and inference samples to their rows. Memory: the
/// rows it returns (8 bytes a value), 28 bytes a trajectory (kTrajectories)
/// or 72 (kBlocks), 4 bytes a training or validation pair of the blocks.
/// The same data set, bit for bit, and the same errors as
/// split_measured_data of all the trajectories at once; MeasuredDataError
/// naming the trajectory when the second pass does not see what the first
/// did (a file changed in between).
MeasuredDataSet split_measured_stream(const PhSystem& system, const TrajectorySource& source,
                                      const ImportOptions& options, std::string* summary = nullptr);

/// `set` with its pairs as PhPairSet and its inference trajectories as
/// PhInferenceSet (what training reads).
PhSystemData to_ph_system_data(MeasuredDataSet set);

/// kBlocks (docs/METHOD.md "Measured data"): recording r of N samples
/// (sorted by id) is cut at b1 = round(train_fraction N) and b2 = b1 +
/// round(validation_fraction N) into the sample ranges [0, b1), [b1, b2),
/// [b2, N), each of >= 2 samples. Training pairs: every (x_n, u_n, x_n+1)
/// with n, n+1 in the first range, of every recording, in an order drawn by
/// CounterRng stream kBlockPairOrder of the data seed (so a run's first
/// n_train pairs are a uniform draw, nested in n_train). Validation pairs:
/// likewise in the second range, at most num_validation (a uniform draw,
/// stream kBlockValidation, kept in time order). Inference: windows of
/// round(window / h) + 1 samples (window 0: the shortest inference block)
/// starting at b2, b2 + W, ... inside [b2, N), taken round-robin over the
/// recordings up to num_inference, each with its start sample in
/// inference.position. No pair or window crosses a block boundary.
PhSystemData split_in_blocks(const PhSystem& system, std::vector<MeasuredTrajectory> recordings,
                             const ImportOptions& options, std::string* summary = nullptr);

/// Measurement noise on a generated data set (docs/METHOD.md "Measured
/// data"): sigma_j = level_j (absolute) or level_j * spread_j (relative;
/// spread_j = standard deviation of state j over the clean validation pairs'
/// x, a split that does not change with n_train), one level per state.
struct NoiseOptions {
  std::vector<double> levels;  // empty: no noise
  bool relative = true;
  /// Throws std::invalid_argument unless empty or n_x levels, each finite >= 0.
  void validate(int n_x) const;
};

/// Adds N(0, sigma_j^2) to state j of every training and validation pair's
/// x and x_next (the inference trajectories stay clean: the MSE measures the
/// learned dynamics against the true system). The draws of trajectory i come
/// from CounterRng::for_trajectory(data_seed, rng_id, i, kMeasurementNoise),
/// x then x_next, component by component (Box-Muller), so a trajectory's
/// noise depends only on (data seed, system, index). Records the levels and
/// sigmas in data->noise. Returns the sigmas.
std::vector<double> add_measurement_noise(PhSystemData* data, int rng_id,
                                          const NoiseOptions& options);

/// The trajectories behind a generated data set `data` of `system`, at its
/// sample rate: each training and validation trajectory over the whole
/// pair window (positions 0 .. num_pair_positions, regenerated by the DG;
/// checked to hold the stored pair bitwise), each inference trajectory as
/// stored; t = n h. Imported with ImportOptions{data_seed,
/// num_validation, num_inference} of `data`, they give `data` back.
std::vector<MeasuredTrajectory> generated_trajectories(const PhSystem& system,
                                                       const PhSystemData& data);

}  // namespace phnn

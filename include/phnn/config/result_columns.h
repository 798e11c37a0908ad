// include/phnn/config/result_columns.h — the scalar result columns of a run
// (one number per run: mse, best_step, wall_time_s, ...), declared once. The
// journal record (store/journal_record.cpp), the results file's /runs
// datasets and their row checksums (store/results_file_*.cpp), the per-run
// CSV (report/per_run.cpp, read by analysis/results.py) and reduce's records
// (apps/reduce_records.cpp) loop over this table. Adding a column: a field
// of RunResult, one row of result_columns(), and the code that computes it.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "phnn/config/run_result.h"

namespace phnn {

// Units of the MSE (Eq. 31) and of the loss L_d: states of two units mix.
inline constexpr char kMseUnit[] = "m^2 and (kg m/s)^2";
inline constexpr char kLossUnit[] = "m/s and kg m/s^2";
inline constexpr char kMseUnits[] =
    "m^2 and (kg m/s)^2 mixed: mean of ||x - x_hat||^2 over the inference "
    "trajectories and steps (docs/METHOD.md section 5); +inf if a rollout diverged";
inline constexpr char kLossUnits[] =
    "m/s and kg m/s^2 mixed: L_d = mean |x_{n+1} - x_hat_{n+1}| / h (+ regularizer)";

/// Where a column sits in a journal record of format version 1 (docs/
/// RESULTS_FORMAT.md, "Journal"): the record's bytes of before stay the
/// same (checksum rule 1 hashes them). A new column goes at the end.
enum class JournalSlot { kAfterMessage, kAfterTrajectoryErrors, kAfterTrace, kAtEnd };

/// One number per run.
struct ResultColumn {
  enum class Type { kDouble, kInt };
  /// Journal key, dataset /runs/<name>.
  const char* name;
  /// Per-run CSV header (the name, or a clearer one: steps -> steps_taken).
  const char* csv_name;
  Type type;
  /// HDF5 `units` ("1": counts and dimensionless) and `description`.
  const char* units;
  const char* description;
  JournalSlot slot;
  /// Added after files and journals were written: where it is missing it
  /// reads NaN (doubles only), and NaN is not journaled, so a record of
  /// before re-encodes to the same bytes.
  bool added_later;
  /// A clock: two trainings of the same run differ in it (same_result).
  bool clock;
  double (*get_double)(const RunResult&);
  void (*set_double)(RunResult&, double);
  std::int64_t (*get_int)(const RunResult&);
  void (*set_int)(RunResult&, std::int64_t);
  /// Integers: the largest valid value (the smallest is 0); a stored value
  /// outside 0..highest is damage.
  std::int64_t highest;
};

/// Every scalar column, in the per-run CSV's order (and the journal's
/// within each slot).
const std::vector<ResultColumn>& result_columns();

/// `r` with every clock column zeroed.
void zero_clock_columns(RunResult* r);

}  // namespace phnn

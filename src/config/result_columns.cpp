// src/config/result_columns.cpp — the table of scalar result columns
// (include/phnn/config/result_columns.h) and its accessors.
#include "phnn/config/result_columns.h"

#include <stdexcept>

namespace phnn {

namespace {

using Type = ResultColumn::Type;

// A double member of RunResult as a column.
template <double RunResult::*M>
ResultColumn double_column(const char* name, const char* units, const char* description,
                           JournalSlot slot, bool added_later = false, bool clock = false) {
  return {name,
          name,
          Type::kDouble,
          units,
          description,
          slot,
          added_later,
          clock,
          [](const RunResult& r) { return r.*M; },
          [](RunResult& r, double v) { r.*M = v; },
          nullptr,
          nullptr,
          0};
}

// An integer member of RunResult (int, long, int64) as a column: valid
// values 0 .. the member type's largest.
template <class T, T RunResult::*M>
ResultColumn int_column(const char* name, const char* csv_name, const char* description,
                        JournalSlot slot) {
  return {name,
          csv_name,
          Type::kInt,
          "1",
          description,
          slot,
          /*added_later=*/false,
          /*clock=*/false,
          nullptr,
          nullptr,
          [](const RunResult& r) { return static_cast<std::int64_t>(r.*M); },
          [](RunResult& r, std::int64_t v) { r.*M = static_cast<T>(v); },
          static_cast<std::int64_t>(std::numeric_limits<T>::max())};
}

std::vector<ResultColumn> make_columns() {
  using S = JournalSlot;
  return {
      double_column<&RunResult::mse>("mse", kMseUnit, kMseUnits, S::kAfterMessage),
      int_column<int, &RunResult::best_step>(
          "best_step", "best_step", "Adam step of the best validation loss", S::kAfterTrace),
      double_column<&RunResult::best_validation_loss>("best_validation_loss", kLossUnit, kLossUnits,
                                                      S::kAfterTrace),
      double_column<&RunResult::wall_time_s>(
          "wall_time_s", "s", "wall time of the run's share of its work item", S::kAfterTrace,
          /*added_later=*/false, /*clock=*/true),
      int_column<int, &RunResult::steps>("steps", "steps_taken", "Adam steps", S::kAfterTrace),
      int_column<long, &RunResult::parameter_count>("parameter_count", "parameter_count",
                                                    "trainable parameters", S::kAfterTrace),
      int_column<int, &RunResult::diverged_rollouts>("diverged_rollouts", "diverged_rollouts",
                                                     "inference rollouts that diverged",
                                                     S::kAfterTrajectoryErrors),
      int_column<std::int64_t, &RunResult::newton_failures>(
          "newton_failures", "newton_failures", "DG inference steps whose Newton did not converge",
          S::kAfterTrace),
      double_column<&RunResult::train_seconds>(
          "train_seconds", "s",
          "training wall time of the run's share of its stack (validation included, inference "
          "and checkpoint inference not); NaN in files written before 2026-11-28",
          S::kAtEnd, /*added_later=*/true, /*clock=*/true),
  };
}

// A column added later reads NaN where it is missing: a double.
std::vector<ResultColumn> checked_columns() {
  std::vector<ResultColumn> columns = make_columns();
  for (const ResultColumn& c : columns) {
    if (c.added_later && c.type != Type::kDouble) {
      throw std::logic_error(std::string("result column ") + c.name +
                             ": only a double can be added later (NaN where it is missing)");
    }
  }
  return columns;
}

}  // namespace

const std::vector<ResultColumn>& result_columns() {
  static const std::vector<ResultColumn> columns = checked_columns();
  return columns;
}

void zero_clock_columns(RunResult* r) {
  for (const ResultColumn& c : result_columns()) {
    if (!c.clock) continue;
    if (c.type == Type::kDouble) {
      c.set_double(*r, 0.0);
    } else {
      c.set_int(*r, 0);
    }
  }
}

}  // namespace phnn

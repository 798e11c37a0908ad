// src/store/results_file_rows.cpp — one row of /runs: ResultsFile::write_run
// (independent raw-data writes, status last) and read_run (every integer
// checked against its range before it sizes or indexes anything). Whole
// columns: results_file_config.cpp; checksums: results_file_checks.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "phnn/config/run_config.h"  // fnv1a64
#include "store/results_file_internal.h"

namespace phnn {

using namespace results_io;

namespace {

// `values` padded with NaN to `length`.
std::vector<double> padded(const std::vector<double>& values, std::size_t length) {
  std::vector<double> out(length, kNaN);
  std::copy(values.begin(), values.end(), out.begin());
  return out;
}

// The first `length` values of a NaN-padded row.
std::vector<double> unpadded(const std::vector<double>& row, std::int64_t length) {
  const auto n = static_cast<std::size_t>(
      std::clamp<std::int64_t>(length, 0, static_cast<std::int64_t>(row.size())));
  return std::vector<double>(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(n));
}

// The run's four figure trajectories, in the order of /runs/figure/length.
std::array<const std::vector<double>*, 4> figures_of(const RunResult& r) {
  return {&r.figure_prediction_05, &r.figure_prediction_075, &r.figure_reference_05,
          &r.figure_reference_075};
}

// Throws (naming the field and the layout limit) unless `r` fits one row of
// a file with layout `L`, its figures being of `states` values per point.
void require_fits(const RunResult& r, const ResultsLayout& L, std::int64_t states,
                  const std::string& where) {
  require(r.trajectory_errors.size() <= static_cast<std::size_t>(L.num_inference),
          where + "trajectory_errors has " + std::to_string(r.trajectory_errors.size()) +
              " entries, the file holds " + std::to_string(L.num_inference) +
              " (ResultsLayout::num_inference)");
  require(r.trace.size() <= static_cast<std::size_t>(L.trace_points),
          where + "trace has " + std::to_string(r.trace.size()) +
              " points, the file holds " + std::to_string(L.trace_points) +
              " (ResultsLayout::trace_points)");
  const char* figure_names[4] = {"figure_prediction_05", "figure_prediction_075",
                                 "figure_reference_05", "figure_reference_075"};
  const auto figures = figures_of(r);
  for (int k = 0; k < 4; ++k) {
    const std::size_t size = figures[k]->size();
    const auto w = static_cast<std::size_t>(states);
    require(size % w == 0 && size / w <= static_cast<std::size_t>(L.figure_points),
            where + figure_names[k] + " has " + std::to_string(size) +
                " values; expected a multiple of the run's " + std::to_string(w) +
                " states of at most " + std::to_string(L.figure_points) +
                " points (ResultsLayout::figure_points)");
  }
  require(r.checkpoint_steps.size() <= static_cast<std::size_t>(L.checkpoints) &&
              r.checkpoint_mse.size() == r.checkpoint_steps.size() &&
              r.checkpoint_train_seconds.size() == r.checkpoint_steps.size(),
          where + "has " + std::to_string(r.checkpoint_steps.size()) +
              " checkpoints, the file holds " + std::to_string(L.checkpoints) +
              " (ResultsLayout::checkpoints)");
}

// The trace as one NaN-padded row of [trace_points, kTraceColumns].
std::vector<double> trace_row(const std::vector<TracePoint>& points, int trace_points) {
  std::vector<double> row(static_cast<std::size_t>(trace_points) * kTraceColumns, kNaN);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TracePoint& t = points[i];
    const double point[kTraceColumns] = {static_cast<double>(t.step), t.elapsed_s,
                                         t.train_loss, t.validation_loss, t.kappa,
                                         t.sigma_max, t.rho};
    std::copy(point, point + kTraceColumns,
              row.begin() + static_cast<std::ptrdiff_t>(i * kTraceColumns));
  }
  return row;
}

// A figure of `states` values per point as a NaN-padded row of
// [figure_points][figure_states].
std::vector<double> figure_row(const std::vector<double>& figure, std::size_t states,
                               const ResultsLayout& L) {
  const auto W = static_cast<std::size_t>(L.figure_states);
  std::vector<double> row(static_cast<std::size_t>(L.figure_points) * W, kNaN);
  for (std::size_t n = 0; n < figure.size() / states; ++n) {
    std::copy(figure.begin() + static_cast<std::ptrdiff_t>(n * states),
              figure.begin() + static_cast<std::ptrdiff_t>((n + 1) * states),
              row.begin() + static_cast<std::ptrdiff_t>(n * W));
  }
  return row;
}

// The first `points` points of a figure row, `states` values each.
std::vector<double> figure_of_row(const std::vector<double>& row, std::int64_t points,
                                  std::size_t states, const ResultsLayout& L) {
  const auto W = static_cast<std::size_t>(L.figure_states);
  const auto n = static_cast<std::size_t>(
      std::clamp<std::int64_t>(points, 0, static_cast<std::int64_t>(L.figure_points)));
  std::vector<double> out;
  out.reserve(n * states);
  for (std::size_t p = 0; p < n; ++p) {
    const auto at = row.begin() + static_cast<std::ptrdiff_t>(p * W);
    out.insert(out.end(), at, at + static_cast<std::ptrdiff_t>(states));
  }
  return out;
}

// Figures and checkpoints of row `at` (raw data only).
void write_figures_and_checkpoints(h5::File& f, std::uint64_t at, const RunResult& r,
                                   std::size_t states, const ResultsLayout& L) {
  const std::string* figure_sets[4] = {&kPrediction05, &kPrediction075, &kReference05,
                                       &kReference075};
  const auto figures = figures_of(r);
  std::int64_t figure_length[4];
  for (int k = 0; k < 4; ++k) {
    f.write_rows(*figure_sets[k], at, 1, figure_row(*figures[k], states, L).data());
    figure_length[k] = static_cast<std::int64_t>(figures[k]->size() / states);
  }
  f.write_rows(kFigureLength, at, 1, figure_length);
  if (L.checkpoints > 0) {
    const auto K = static_cast<std::size_t>(L.checkpoints);
    std::vector<std::int64_t> steps(K, 0);
    std::copy(r.checkpoint_steps.begin(), r.checkpoint_steps.end(), steps.begin());
    f.write_rows(kCheckpointSteps, at, 1, steps.data());
    f.write_rows(kCheckpointMse, at, 1, padded(r.checkpoint_mse, K).data());
    f.write_rows(kCheckpointTrainSeconds, at, 1, padded(r.checkpoint_train_seconds, K).data());
  }
}

// Offset of row `at`'s weights in /weights and the room it has there (to
// the next run's offset: its model's parameter count), both checked against
// the size of /weights.
std::pair<std::int64_t, std::int64_t> weights_slot(const h5::File& f, std::uint64_t at,
                                                   int num_runs, const std::string& where) {
  const auto total = static_cast<std::int64_t>(f.dims(kWeights).at(0));
  const std::int64_t offset = f.read_ints(kWeightsOffset, at, 1).at(0);
  const std::int64_t end = at + 1 < static_cast<std::uint64_t>(num_runs)
                               ? f.read_ints(kWeightsOffset, at + 1, 1).at(0)
                               : total;
  if (offset < 0 || offset > end || end > total) {
    throw std::runtime_error(where + kWeightsOffset + "[" + std::to_string(at) + "] = " +
                             std::to_string(offset) + " (next " + std::to_string(end) +
                             ") outside 0.." + std::to_string(total) +
                             " (the size of /weights); the file is damaged");
  }
  return {offset, end - offset};
}

}  // namespace

std::int64_t ResultsFile::row_fit(int row, const RunResult& r, const std::string& where) const {
  const Impl& impl = *impl_;
  require(row >= 0 && row < impl.num_runs,
          where + "row outside [0, " + std::to_string(impl.num_runs) + ")");
  const auto states = static_cast<std::int64_t>(impl.states_of(static_cast<std::uint64_t>(row)));
  require_fits(r, impl.layout, states, where);
  // A file written before weights were stored drops them.
  if (!impl.layout.weights || r.weights.empty()) return -1;
  const auto [offset, room] = impl.independent([&] {
    return weights_slot(impl.file, static_cast<std::uint64_t>(row), impl.num_runs, where);
  });
  require(static_cast<std::int64_t>(r.weights.size()) <= room,
          where + "has " + std::to_string(r.weights.size()) + " weights, the file holds " +
              std::to_string(room) + " for this run (its model's parameter count)");
  return offset;
}

std::string ResultsFile::rewrite_problem(int row, const RunResult& r) const {
  try {
    row_fit(row, r, "");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

void ResultsFile::write_run(int row, const RunResult& r) {
  Impl& impl = *impl_;
  const ResultsLayout& L = impl.layout;
  const std::string where =
      impl.prefix() + path() + ": write_run(row " + std::to_string(row) + "): ";
  const std::int64_t weights_offset = row_fit(row, r, where);
  const bool store_weights = weights_offset >= 0;
  const std::size_t states = impl.states_of(static_cast<std::uint64_t>(row));
  const std::vector<double> trace = trace_row(r.trace, L.trace_points);

  impl.independent([&] {
    h5::File& f = impl.file;
    const auto at = static_cast<std::uint64_t>(row);
    auto put_double = [&](const std::string& name, double v) { f.write_rows(name, at, 1, &v); };
    auto put_int = [&](const std::string& name, std::int64_t v) {
      f.write_rows(name, at, 1, &v);
    };
    for (const ResultColumn* c : impl.result_columns) {  // not one added after the file
      if (c->type == ResultColumn::Type::kInt) {
        put_int(kRuns + c->name, c->get_int(r));
      } else {
        put_double(kRuns + c->name, c->get_double(r));
      }
    }
    f.write_rows(kTrajectoryErrors, at, 1,
                 padded(r.trajectory_errors, static_cast<std::size_t>(L.num_inference)).data());
    put_int(kTrajectoryErrorsLength, static_cast<std::int64_t>(r.trajectory_errors.size()));
    f.write_rows(kTrace, at, 1, trace.data());
    put_int(kTraceLength, static_cast<std::int64_t>(r.trace.size()));
    write_figures_and_checkpoints(f, at, r, states, L);
    f.write_string_rows(kMessage, at, {truncate_message(r.message, kMessageLength)});
    if (store_weights) {
      f.write_rows(kWeights, static_cast<std::uint64_t>(weights_offset), r.weights.size(),
                   r.weights.data());
    }
    if (L.weights) put_int(kWeightsLength, static_cast<std::int64_t>(store_weights ? r.weights.size() : 0));
    if (impl.has_run_times) {
      f.write_string_rows(kStartedUtc, at, {r.started_utc.substr(0, kUtcLength)});
      f.write_string_rows(kFinishedUtc, at, {r.finished_utc.substr(0, kUtcLength)});
    }
    // Last but the checksum: until this lands the row reads as pending.
    put_int(kStatus, static_cast<std::int64_t>(r.status));
  });
  if (impl.has_checksums) {
    // A pending row holds no checksum (row_damage relies on it).
    const auto checksum = r.status == RunStatus::kPending
                              ? std::int64_t{0}
                              : static_cast<std::int64_t>(row_checksum(row));
    impl.independent([&] { impl.file.write_rows(kChecksum, static_cast<std::uint64_t>(row), 1, &checksum); });
  }
}

namespace {
RunStatus status_from_code(std::int64_t code, const std::string& where) {
  if (code < 0 || code > static_cast<std::int64_t>(RunStatus::kFailed)) {
    throw std::runtime_error(where + " = " + std::to_string(code) +
                             "; expected 0 (pending) to 3 (failed); the file is damaged");
  }
  return static_cast<RunStatus>(code);
}
}  // namespace

std::vector<RunStatus> ResultsFile::read_statuses() const {
  const std::vector<std::int64_t> codes = impl_->ints(kStatus);
  std::vector<RunStatus> out;
  out.reserve(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    out.push_back(status_from_code(
        codes[i], impl_->prefix() + path() + ": " + kStatus + "[" + std::to_string(i) + "]"));
  }
  return out;
}

namespace {

constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
const std::string kDamaged =
    "; the file is damaged (`phnn verify` names the damage and its repair)";

// A value of an integer column, checked before anything is sized or cast
// by it: std::runtime_error naming dataset, row and value unless it lies in
// [lowest, highest].
std::int64_t checked(std::int64_t value, std::int64_t lowest, std::int64_t highest,
                     const std::string& dataset, std::uint64_t row, const std::string& where) {
  if (value < lowest || value > highest) {
    throw std::runtime_error(where + dataset + "[" + std::to_string(row) + "] = " +
                             std::to_string(value) + ", outside " + std::to_string(lowest) +
                             ".." + std::to_string(highest) + kDamaged);
  }
  return value;
}

// The first `length` points of a trace row; each step must be a whole
// number that fits an int.
std::vector<TracePoint> trace_of_row(const std::vector<double>& row, std::int64_t length,
                                     std::uint64_t at, const std::string& where) {
  std::vector<TracePoint> trace;
  for (std::int64_t i = 0; i < length; ++i) {
    const double* p = row.data() + i * kTraceColumns;
    if (!(p[0] >= 0 && p[0] <= static_cast<double>(kIntMax) && p[0] == std::floor(p[0]))) {
      throw std::runtime_error(where + kTrace + "[" + std::to_string(at) + "][" +
                               std::to_string(i) + "] has step " + std::to_string(p[0]) +
                               ", not a step count" + kDamaged);
    }
    trace.push_back({static_cast<int>(p[0]), p[1], p[2], p[3], p[4], p[5], p[6]});
  }
  return trace;
}

}  // namespace

std::size_t ResultsFile::Impl::states_of(std::uint64_t row) const {
  return static_cast<std::size_t>(checked(run_states.at(row), 1, layout.figure_states, kStates,
                                          row, prefix() + file.path() + ": "));
}

std::pair<std::uint64_t, std::uint64_t> ResultsFile::Impl::weights_of(std::uint64_t row) const {
  const std::string where = prefix() + file.path() + ": ";
  const auto total = static_cast<std::int64_t>(file.dims(kWeights).at(0));
  const std::int64_t offset =
      checked(ints(kWeightsOffset, row, 1).at(0), 0, total, kWeightsOffset, row, where);
  const std::int64_t length =
      checked(ints(kWeightsLength, row, 1).at(0), 0, total - offset, kWeightsLength, row, where);
  return {static_cast<std::uint64_t>(offset), static_cast<std::uint64_t>(length)};
}

RunResult ResultsFile::read_run(int row) const {
  const Impl& impl = *impl_;
  const ResultsLayout& L = impl.layout;
  const std::string where = impl.prefix() + path() + ": ";
  require(row >= 0 && row < impl.num_runs, where + "read_run(row " + std::to_string(row) +
                                               "): row outside [0, " +
                                               std::to_string(impl.num_runs) + ")");
  const auto at = static_cast<std::uint64_t>(row);
  auto one_int = [&](const std::string& name, std::int64_t lowest, std::int64_t highest) {
    return checked(impl.ints(name, at, 1).at(0), lowest, highest, name, at, where);
  };
  RunResult r;
  r.status = status_from_code(impl.ints(kStatus, at, 1).at(0),
                              where + kStatus + "[" + std::to_string(row) + "]");
  r.message = impl.strings_at(kMessage, at);
  for (const ResultColumn* c : impl.result_columns) {  // one the file lacks stays NaN
    if (c->type == ResultColumn::Type::kInt) {
      c->set_int(r, one_int(kRuns + c->name, 0, c->highest));
    } else {
      c->set_double(r, impl.doubles(kRuns + c->name, at, 1).at(0));
    }
  }
  r.trajectory_errors = unpadded(impl.doubles(kTrajectoryErrors, at, 1),
                                 one_int(kTrajectoryErrorsLength, 0, L.num_inference));
  r.trace = trace_of_row(impl.doubles(kTrace, at, 1), one_int(kTraceLength, 0, L.trace_points),
                         at, where);
  read_figures_and_checkpoints(row, &r);
  if (L.weights) {
    const auto [offset, length] = impl.independent([&] { return impl.weights_of(at); });
    if (length > 0) r.weights = impl.doubles(kWeights, offset, length);
  }
  if (impl.has_run_times) {
    r.started_utc = impl.strings_at(kStartedUtc, at);
    r.finished_utc = impl.strings_at(kFinishedUtc, at);
  }
  return r;
}

void ResultsFile::read_figures_and_checkpoints(int row, RunResult* r) const {
  const Impl& impl = *impl_;
  const ResultsLayout& L = impl.layout;
  const std::string where = impl.prefix() + path() + ": ";
  const auto at = static_cast<std::uint64_t>(row);
  const std::size_t states = impl.states_of(at);
  const std::vector<std::int64_t> lengths = impl.ints(kFigureLength, at, 1);
  for (std::int64_t length : lengths) checked(length, 0, L.figure_points, kFigureLength, at, where);
  r->figure_prediction_05 = figure_of_row(impl.doubles(kPrediction05, at, 1), lengths.at(0), states, L);
  r->figure_prediction_075 = figure_of_row(impl.doubles(kPrediction075, at, 1), lengths.at(1), states, L);
  r->figure_reference_05 = figure_of_row(impl.doubles(kReference05, at, 1), lengths.at(2), states, L);
  r->figure_reference_075 = figure_of_row(impl.doubles(kReference075, at, 1), lengths.at(3), states, L);
  if (L.checkpoints == 0) return;
  for (std::int64_t s : impl.ints(kCheckpointSteps, at, 1)) {
    if (checked(s, 0, kIntMax, kCheckpointSteps, at, where) > 0) {
      r->checkpoint_steps.push_back(static_cast<int>(s));
    }
  }
  const auto count = static_cast<std::int64_t>(r->checkpoint_steps.size());
  r->checkpoint_mse = unpadded(impl.doubles(kCheckpointMse, at, 1), count);
  r->checkpoint_train_seconds = unpadded(impl.doubles(kCheckpointTrainSeconds, at, 1), count);
}

}  // namespace phnn

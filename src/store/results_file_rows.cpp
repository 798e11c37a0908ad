// src/store/results_file_rows.cpp — one row of /runs: ResultsFile::write_run
// (independent raw-data writes, status last) and read_run, and the column
// readers of the reducer.
#include <algorithm>
#include <array>
#include <set>

#include "phnn/config/run_config.h"  // fnv1a64
#include "phnn/store/journal.h"
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

// Offset of row `at`'s weights in /weights and the room it has there (its
// model's parameter count).
std::pair<std::int64_t, std::int64_t> weights_slot(const h5::File& f, std::uint64_t at,
                                                   int num_runs) {
  const std::int64_t offset = f.read_ints(kWeightsOffset, at, 1).at(0);
  const std::int64_t end = at + 1 < static_cast<std::uint64_t>(num_runs)
                               ? f.read_ints(kWeightsOffset, at + 1, 1).at(0)
                               : static_cast<std::int64_t>(f.dims(kWeights).at(0));
  return {offset, end - offset};
}

}  // namespace

void ResultsFile::write_run(int row, const RunResult& r) {
  Impl& impl = *impl_;
  const ResultsLayout& L = impl.layout;
  const std::string where =
      impl.prefix() + path() + ": write_run(row " + std::to_string(row) + "): ";
  require(row >= 0 && row < impl.num_runs,
          where + "row outside [0, " + std::to_string(impl.num_runs) + ")");
  const std::int64_t states = impl.run_states.at(static_cast<std::size_t>(row));
  require_fits(r, L, states, where);
  // A file written before weights were stored drops them.
  std::int64_t weights_offset = 0;
  const bool store_weights = L.weights && !r.weights.empty();
  if (store_weights) {
    const auto [offset, room] = impl.independent(
        [&] { return weights_slot(impl.file, static_cast<std::uint64_t>(row), impl.num_runs); });
    require(static_cast<std::int64_t>(r.weights.size()) <= room,
            where + "has " + std::to_string(r.weights.size()) + " weights, the file holds " +
                std::to_string(room) + " for this run (its model's parameter count)");
    weights_offset = offset;
  }
  const std::vector<double> trace = trace_row(r.trace, L.trace_points);

  impl.independent([&] {
    h5::File& f = impl.file;
    const auto at = static_cast<std::uint64_t>(row);
    auto put_double = [&](const std::string& name, double v) { f.write_rows(name, at, 1, &v); };
    auto put_int = [&](const std::string& name, std::int64_t v) {
      f.write_rows(name, at, 1, &v);
    };
    put_double(kMse, r.mse);
    f.write_rows(kTrajectoryErrors, at, 1,
                 padded(r.trajectory_errors, static_cast<std::size_t>(L.num_inference)).data());
    put_int(kTrajectoryErrorsLength, static_cast<std::int64_t>(r.trajectory_errors.size()));
    put_int(kDivergedRollouts, r.diverged_rollouts);
    put_int(kBestStep, r.best_step);
    put_double(kBestValidationLoss, r.best_validation_loss);
    put_double(kWallTime, r.wall_time_s);
    put_int(kSteps, r.steps);
    put_int(kParameterCount, r.parameter_count);
    put_int(kNewtonFailures, r.newton_failures);
    f.write_rows(kTrace, at, 1, trace.data());
    put_int(kTraceLength, static_cast<std::int64_t>(r.trace.size()));
    write_figures_and_checkpoints(f, at, r, static_cast<std::size_t>(states), L);
    f.write_string_rows(kMessage, at, {truncate_message(r.message, kMessageLength)});
    if (store_weights) {
      f.write_rows(kWeights, static_cast<std::uint64_t>(weights_offset), r.weights.size(),
                   r.weights.data());
    }
    if (L.weights) put_int(kWeightsLength, static_cast<std::int64_t>(store_weights ? r.weights.size() : 0));
    // Last but the checksum: until this lands the row reads as pending.
    put_int(kStatus, static_cast<std::int64_t>(r.status));
  });
  if (impl.has_checksums) {
    const auto checksum = static_cast<std::int64_t>(row_checksum(row));
    impl.independent([&] { impl.file.write_rows(kChecksum, static_cast<std::uint64_t>(row), 1, &checksum); });
  }
}

// FNV-1a 64 (run_config.h) of the row's id, configuration, seed and result
// as read back (the journal's encoding: every double bit for bit).
std::uint64_t ResultsFile::row_checksum(int row) const {
  const Impl& impl = *impl_;
  const auto at = static_cast<std::uint64_t>(row);
  const std::string id = impl.strings_at(kId, at);
  const std::uint64_t hash = fnv1a64(id + "\n" + impl.strings_at(kCanonical, at) + "\n" +
                                     std::to_string(impl.ints(kSeed, at, 1).at(0)) + "\n" +
                                     internal::encode_journal_record(id, read_run(row), 0));
  return hash == 0 ? 1 : hash;  // 0 means "no checksum"
}

bool ResultsFile::row_damaged(int row) const {
  const Impl& impl = *impl_;
  if (!impl.has_checksums) return false;
  const auto at = static_cast<std::uint64_t>(row);
  try {
    const std::int64_t code = impl.ints(kStatus, at, 1).at(0);
    if (code == static_cast<std::int64_t>(RunStatus::kPending)) return false;
    const std::int64_t stored = impl.ints(kChecksum, at, 1).at(0);
    return !(code > 0 && code <= static_cast<std::int64_t>(RunStatus::kFailed) && stored != 0 &&
             static_cast<std::uint64_t>(stored) == row_checksum(row));
  } catch (const std::exception&) {
    return true;  // unreadable is damaged too
  }
}

std::vector<int> ResultsFile::damaged_rows() const {
  std::vector<int> damaged;
  if (!impl_->has_checksums) return damaged;
  const std::vector<std::int64_t> codes = impl_->ints(kStatus);
  for (int row = 0; row < impl_->num_runs; ++row) {
    if (codes[static_cast<std::size_t>(row)] == static_cast<std::int64_t>(RunStatus::kPending)) {
      continue;
    }
    if (row_damaged(row)) damaged.push_back(row);
  }
  return damaged;
}

std::vector<std::string> ResultsFile::structure_problems() const {
  std::vector<std::string> problems;
  try {
    const std::vector<std::string> ids = read_run_ids();
    std::set<std::string> seen;
    for (std::size_t row = 0; row < ids.size(); ++row) {
      if (ids[row].empty()) {
        problems.push_back("row " + std::to_string(row) + " has no run id");
      } else if (!seen.insert(ids[row]).second) {
        problems.push_back("run id " + ids[row] + " repeats (row " + std::to_string(row) + ")");
      }
      if (problems.size() >= 5) break;
    }
    read_statuses();
    read_canonical();
  } catch (const std::exception& e) {
    problems.push_back(e.what());
  }
  return problems;
}

bool ResultsFile::has_checksums() const { return impl_->has_checksums; }

void ResultsFile::requeue_run(int row) {
  Impl& impl = *impl_;
  const std::int64_t zero = 0;
  impl.independent([&] {
    impl.file.write_rows(kStatus, static_cast<std::uint64_t>(row), 1, &zero);
    if (impl.has_checksums) impl.file.write_rows(kChecksum, static_cast<std::uint64_t>(row), 1, &zero);
  });
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

RunResult ResultsFile::read_run(int row) const {
  const Impl& impl = *impl_;
  require(row >= 0 && row < impl.num_runs,
          impl.prefix() + path() + ": read_run(row " + std::to_string(row) +
              "): row outside [0, " + std::to_string(impl.num_runs) + ")");
  const auto at = static_cast<std::uint64_t>(row);
  auto one_int = [&](const std::string& name) { return impl.ints(name, at, 1).at(0); };
  auto one_double = [&](const std::string& name) { return impl.doubles(name, at, 1).at(0); };
  RunResult r;
  r.status = status_from_code(one_int(kStatus), impl.prefix() + path() + ": " + kStatus +
                                                    "[" + std::to_string(row) + "]");
  r.message = impl.independent([&] { return impl.file.read_strings(kMessage, at, 1).at(0); });
  r.mse = one_double(kMse);
  r.trajectory_errors =
      unpadded(impl.doubles(kTrajectoryErrors, at, 1), one_int(kTrajectoryErrorsLength));
  r.diverged_rollouts = static_cast<int>(one_int(kDivergedRollouts));
  r.best_step = static_cast<int>(one_int(kBestStep));
  r.best_validation_loss = one_double(kBestValidationLoss);
  r.wall_time_s = one_double(kWallTime);
  r.steps = static_cast<int>(one_int(kSteps));
  r.parameter_count = static_cast<long>(one_int(kParameterCount));
  r.newton_failures = one_int(kNewtonFailures);
  const std::vector<double> trace = impl.doubles(kTrace, at, 1);
  const std::int64_t trace_length =
      std::clamp<std::int64_t>(one_int(kTraceLength), 0, impl.layout.trace_points);
  for (std::int64_t i = 0; i < trace_length; ++i) {
    const double* p = trace.data() + i * kTraceColumns;
    TracePoint t;
    t.step = static_cast<int>(p[0]);
    t.elapsed_s = p[1];
    t.train_loss = p[2];
    t.validation_loss = p[3];
    t.kappa = p[4];
    t.sigma_max = p[5];
    t.rho = p[6];
    r.trace.push_back(t);
  }
  const std::vector<std::int64_t> lengths = impl.ints(kFigureLength, at, 1);
  const auto states = static_cast<std::size_t>(impl.run_states.at(at));
  const ResultsLayout& L = impl.layout;
  r.figure_prediction_05 = figure_of_row(impl.doubles(kPrediction05, at, 1), lengths.at(0), states, L);
  r.figure_prediction_075 = figure_of_row(impl.doubles(kPrediction075, at, 1), lengths.at(1), states, L);
  r.figure_reference_05 = figure_of_row(impl.doubles(kReference05, at, 1), lengths.at(2), states, L);
  r.figure_reference_075 = figure_of_row(impl.doubles(kReference075, at, 1), lengths.at(3), states, L);
  if (impl.layout.checkpoints > 0) {
    for (std::int64_t s : impl.ints(kCheckpointSteps, at, 1)) {
      if (s > 0) r.checkpoint_steps.push_back(static_cast<int>(s));
    }
    const auto count = static_cast<std::int64_t>(r.checkpoint_steps.size());
    r.checkpoint_mse = unpadded(impl.doubles(kCheckpointMse, at, 1), count);
    r.checkpoint_train_seconds = unpadded(impl.doubles(kCheckpointTrainSeconds, at, 1), count);
  }
  if (impl.layout.weights) {
    const std::int64_t length = one_int(kWeightsLength);
    if (length > 0) {
      const auto offset = static_cast<std::uint64_t>(one_int(kWeightsOffset));
      r.weights = impl.doubles(kWeights, offset, static_cast<std::uint64_t>(length));
    }
  }
  return r;
}

std::vector<std::string> ResultsFile::read_run_ids() const { return impl_->strings(kId); }
std::vector<std::string> ResultsFile::read_canonical() const {
  return impl_->strings(kCanonical);
}
std::vector<std::string> ResultsFile::read_systems() const { return impl_->strings(kSystem); }
std::vector<std::string> ResultsFile::read_models() const { return impl_->strings(kModel); }
std::vector<std::string> ResultsFile::read_integrators() const {
  return impl_->strings(kIntegrator);
}
std::vector<std::string> ResultsFile::read_sizes() const { return impl_->strings(kSize); }
std::vector<std::string> ResultsFile::read_regularizers() const {
  return impl_->strings(kRegularizer);
}
std::vector<std::string> ResultsFile::read_studies() const { return impl_->strings(kStudies); }
std::vector<std::int64_t> ResultsFile::read_n_train() const { return impl_->ints(kNTrain); }
std::vector<std::int64_t> ResultsFile::read_n_x() const { return impl_->run_states; }
std::vector<std::int64_t> ResultsFile::read_seeds() const { return impl_->ints(kSeed); }

std::vector<double> ResultsFile::read_double_column(const std::string& column) const {
  return impl_->doubles(kRuns + column);
}
std::vector<std::int64_t> ResultsFile::read_int_column(const std::string& column) const {
  return impl_->ints(kRuns + column);
}
std::vector<std::string> ResultsFile::read_string_column(const std::string& column) const {
  return impl_->strings(kRuns + column);
}

}  // namespace phnn

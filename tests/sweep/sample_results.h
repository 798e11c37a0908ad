// tests/sweep/sample_results.h — deterministic runs and results shared by the
// results-file and journal tests (serial and MPI): every value depends only on
// the row, so any rank count must store the same bytes.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "phnn/config/result_columns.h"
#include "phnn/store/results_file.h"

namespace phnn {
namespace testing_util {

inline std::uint64_t bits(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

inline std::vector<std::uint64_t> bits(const std::vector<double>& values) {
  std::vector<std::uint64_t> out;
  for (double v : values) out.push_back(bits(v));
  return out;
}

/// A quiet NaN whose payload says where it came from (HDF5 and the journal
/// must keep it).
inline double tagged_nan(std::uint64_t tag) {
  const std::uint64_t b = 0x7ff8000000000000ULL | (tag & 0xffffULL);
  double v = 0;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

/// Awkward doubles: -0, subnormals, DBL_MAX, non-terminating binary fractions.
inline double sample_value(int row, int k) {
  switch ((row + k) % 11) {
    case 0: return -0.0;
    case 1: return std::numeric_limits<double>::denorm_min() * (k + 1);
    case 2: return std::numeric_limits<double>::max();
    default: return (row + 1) / 3.0 + k * 0.1 - std::ldexp(1.0, -(k % 40));
  }
}

/// `n` distinct runs (seed = row) spread over every axis.
inline std::vector<RunConfig> sample_runs(int n) {
  std::vector<RunConfig> runs;
  for (int i = 0; i < n; ++i) {
    RunConfig c;
    c.system = static_cast<SystemKind>(i % 3);
    c.model = static_cast<ModelKind>((i / 3) % 3);
    c.integrator = c.model == ModelKind::kNode ? IntegratorKind::kRk2
                                               : static_cast<IntegratorKind>(i % 2);
    c.size = static_cast<ModelSize>(i % 3);
    c.regularizer = static_cast<Regularizer>(i % 4);
    c.n_train = i % 3 == 0 ? 25 : (i % 3 == 1 ? 100 : 400);
    c.seed = i;
    c.physics = OscillatorOptions::defaults(c.system);
    runs.push_back(c);
  }
  return runs;
}

inline std::vector<std::string> sample_studies(int n) {
  std::vector<std::string> studies;
  for (int i = 0; i < n; ++i) studies.push_back(i % 3 == 0 ? "I,II,III" : (i % 3 == 1 ? "I" : "II,III"));
  return studies;
}

/// A small layout, so short traces and figures get NaN padding.
inline ResultsLayout sample_layout() {
  ResultsLayout layout;
  layout.num_inference = 5;
  layout.trace_points = 6;
  layout.figure_points = 9;
  return layout;
}

/// Row `row`'s result: done (row % 4 == 0 or 3), diverged (1) or failed (2).
inline RunResult sample_result(int row, const ResultsLayout& layout) {
  RunResult r;
  const int kind = row % 4;
  r.status = kind == 1 ? RunStatus::kDiverged : (kind == 2 ? RunStatus::kFailed : RunStatus::kDone);
  r.diverged_rollouts = kind == 1 ? 1 : 0;
  r.best_step = 500 * row;
  r.best_validation_loss = sample_value(row, 3);
  r.wall_time_s = 12.5 + row / 7.0;
  r.steps = 50000 - row;
  r.parameter_count = 746 + row;
  r.newton_failures = (std::int64_t{1} << 40) + row;
  if (kind != 2) r.train_seconds = 11.0 + row / 3.0;  // a failed run keeps NaN (unknown)
  auto figure = [&](int points, int salt) {
    std::vector<double> f;
    for (int i = 0; i < 2 * points; ++i) f.push_back(sample_value(row + salt, i));
    return f;
  };
  auto trace = [&](int points) {
    std::vector<TracePoint> t(static_cast<std::size_t>(points));
    for (int i = 0; i < points; ++i) {
      t[i] = TracePoint{500 * i, 0.25 * i + row, sample_value(row, i), sample_value(row, i + 1),
                        1e3 + i, 2.0 / (i + 1), sample_value(row, i + 2)};
    }
    return t;
  };
  if (kind == 2) {  // failed: no arrays at all
    r.mse = tagged_nan(static_cast<std::uint64_t>(row));
    r.message = "Newton failed at step 17: \"dg\" 100% stuck\nline two\ttab \xc3\xbc\xc3\xb1";
    return r;
  }
  for (int i = 0; i < layout.num_inference; ++i) r.trajectory_errors.push_back(sample_value(row, i));
  r.figure_reference_05 = figure(layout.figure_points, 1);
  r.figure_reference_075 = figure(layout.figure_points, 2);
  if (kind == 1) {  // diverged: +inf errors, short trace ending in NaN
    r.mse = std::numeric_limits<double>::infinity();
    r.trajectory_errors[1] = std::numeric_limits<double>::infinity();
    r.trace = trace(2);
    r.trace.back().train_loss = tagged_nan(0x123);
    r.figure_prediction_05 = figure(3, 3);
    r.figure_prediction_05.back() = tagged_nan(0x456);
    r.figure_prediction_075 = figure(3, 4);
    r.message = "rollout 1 diverged: ||x|| = 1.2e+06 > 1e+06 at step 42";
    return r;
  }
  r.mse = sample_value(row, 0) + 1e-3;
  r.trace = trace(layout.trace_points - row % 3);
  r.figure_prediction_05 = figure(layout.figure_points, 3);
  r.figure_prediction_075 = figure(layout.figure_points, 4);
  return r;
}

/// Every field equal, doubles bit for bit.
inline void expect_bit_equal(const RunResult& expected, const RunResult& actual) {
  EXPECT_EQ(expected.status, actual.status);
  EXPECT_EQ(expected.message, actual.message);
  EXPECT_EQ(bits(expected.trajectory_errors), bits(actual.trajectory_errors));
  ASSERT_EQ(expected.trace.size(), actual.trace.size());
  for (std::size_t i = 0; i < expected.trace.size(); ++i) {
    const TracePoint& e = expected.trace[i];
    const TracePoint& a = actual.trace[i];
    EXPECT_EQ(e.step, a.step) << "trace point " << i;
    EXPECT_EQ(bits(std::vector<double>{e.elapsed_s, e.train_loss, e.validation_loss, e.kappa,
                                       e.sigma_max, e.rho}),
              bits(std::vector<double>{a.elapsed_s, a.train_loss, a.validation_loss, a.kappa,
                                       a.sigma_max, a.rho}))
        << "trace point " << i;
  }
  for (const ResultColumn& c : result_columns()) {
    if (c.type == ResultColumn::Type::kInt) {
      EXPECT_EQ(c.get_int(expected), c.get_int(actual)) << c.name;
    } else {
      EXPECT_EQ(bits(c.get_double(expected)), bits(c.get_double(actual))) << c.name;
    }
  }
  EXPECT_EQ(bits(expected.figure_prediction_05), bits(actual.figure_prediction_05));
  EXPECT_EQ(bits(expected.figure_prediction_075), bits(actual.figure_prediction_075));
  EXPECT_EQ(bits(expected.figure_reference_05), bits(actual.figure_reference_05));
  EXPECT_EQ(bits(expected.figure_reference_075), bits(actual.figure_reference_075));
  EXPECT_EQ(expected.checkpoint_steps, actual.checkpoint_steps);
  EXPECT_EQ(bits(expected.checkpoint_mse), bits(actual.checkpoint_mse));
  EXPECT_EQ(bits(expected.checkpoint_train_seconds), bits(actual.checkpoint_train_seconds));
  EXPECT_EQ(bits(expected.weights), bits(actual.weights));
  EXPECT_EQ(expected.started_utc, actual.started_utc);
  EXPECT_EQ(expected.finished_utc, actual.finished_utc);
}

}  // namespace testing_util
}  // namespace phnn
